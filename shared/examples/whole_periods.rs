//! RKN 8(6) and RKN 12(10) with a fixed step of P/N drive periods (N steps every P periods) on
//! the bench's settling scene (scenes/tilted-135.toml: rod 0.20 m, A = 8.9 mm, ω = 330 rad/s,
//! θd = 135°, Q = 20, from 100°, 4000 periods): each ratio's final error against DOP853 at
//! rtol = atol = 1e-13 and its evaluations. It shows where whole steps per drive period leave
//! the settling scene's 1e-6 target (docs/accuracy.md, "Ours against the peer").
//!
//! Run: `cargo run --release -p kapitza-core --example whole_periods`.

use kapitza_core::integrate::rkn::{Damped, Pair, RKN1210, RKN86};
use kapitza_core::math;
use kapitza_core::model::{DriveAngle, Geometry};
use kapitza_core::sim::eom::{FullEom, NoExtra};
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::scene::{
    DriveFrequency, DriveSpec, Effects, Fidelity, FidelityChoice, RunLength, Viscous,
};
use kapitza_core::sim::signal::{DriveSignal, Steady};
use kapitza_core::sim::{simulate, Method, Options, Scene};

const PERIODS: u32 = 4000;

fn scene() -> Scene {
    Scene {
        pendulum: Geometry::rod(0.20).unwrap(),
        drive: DriveSpec {
            amplitude: 0.0089,
            frequency: DriveFrequency::Omega(330.0),
            angle: DriveAngle::from_deg(135.0).unwrap(),
        },
        gravity: 9.81,
        initial_angle: math::to_rad(100.0),
        initial_rate: 0.0,
        length: RunLength::Periods(f64::from(PERIODS)),
        fidelity: FidelityChoice::Fixed(Fidelity::Full),
        effects: Effects {
            viscous: Some(Viscous::Q(20.0)),
            ..Effects::default()
        },
    }
}

/// The end state after `PERIODS` drive periods by `pair` with N steps every P periods, and the
/// evaluations (the start's one, S − 1 per step and, for a pair without first-same-as-last,
/// one more at every step's end).
fn run<const S: usize>(pair: &'static Pair<S>, (n, p): (u32, u32)) -> ((f64, f64), u64) {
    let s = scene();
    let phys = s.physical().unwrap();
    let drive = Steady::<f64>::new(phys.amplitude / phys.ell, phys.omega);
    let eom = FullEom::<f64, _, _>::new(phys.omega0.powi(2), s.drive.angle, drive, NoExtra);
    let period = math::TAU / phys.omega;
    let h = period * f64::from(p) / f64::from(n);
    let m = Damped::of(pair, h, phys.c, true);
    let (mut y, mut g0, mut evals) = (
        (s.initial_angle, 0.0),
        eom.conservative(0.0, s.initial_angle),
        1,
    );
    for block in 0..PERIODS / p {
        let t_block = f64::from(block * p) * period;
        for k in 0..n {
            let t0 = t_block + f64::from(k) * h;
            let out = m.step(y.0, y.1, g0, |i, th| {
                eom.conservative_with(eom.drive.accel(t0 + m.tau[i]), th)
            });
            evals += S as u64 - 1;
            y = (out.theta, out.rate);
            g0 = if pair.fsal {
                out.g1
            } else {
                evals += 1;
                eom.conservative(t_block + f64::from(k + 1) * h, y.0)
            };
        }
    }
    (y, evals)
}

fn main() {
    let options = Options {
        method: Method::Dop853 {
            rtol: 1e-13,
            atol: 1e-13,
        },
        classify: false,
        ..Options::default()
    };
    let r = simulate(&scene(), &options, &mut Discard).unwrap();
    let error = |y: (f64, f64)| {
        math::wrap_pi(y.0 - r.end.theta)
            .abs()
            .max((y.1 - r.end.rate).abs() / 330.0)
    };
    println!("pair        N/P    steps/period  final error  evaluations");
    for np in [(3, 1), (31, 10), (16, 5), (13, 4), (4, 1)] {
        let (y, evals) = run(&RKN86, np);
        let spp = f64::from(np.0) / f64::from(np.1);
        println!(
            "RKN 8(6)   {:>2}/{:<2}  {spp:>5.2}         {:.2e}     {evals}",
            np.0,
            np.1,
            error(y)
        );
    }
    for np in [
        (1, 1),
        (11, 10),
        (6, 5),
        (5, 4),
        (13, 10),
        (7, 5),
        (3, 2),
        (8, 5),
        (17, 10),
        (2, 1),
    ] {
        let (y, evals) = run(&RKN1210, np);
        let spp = f64::from(np.0) / f64::from(np.1);
        println!(
            "RKN 12(10) {:>2}/{:<2}  {spp:>5.2}         {:.2e}     {evals}",
            np.0,
            np.1,
            error(y)
        );
    }
}
