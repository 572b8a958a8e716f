//! Deterministic scenarios of the rig logic with a digest of everything they compute, run by
//! the host tests (`shared/tests/rig_selftest.rs`) and, compiled for `thumbv7em-none-eabihf`,
//! by the on-target harness on the emulated Cortex-M4F (`qemu/`). Both compare against the same
//! [`Case::expected`] digests, so passing on both proves the results bit-identical.
//!
//! Inputs are generated inside each scenario from integers and libm (pure software, the same
//! bits on every machine); the digest is FNV-1a (64-bit) over the little-endian bytes of every
//! output. To regenerate the expected digests after a deliberate change:
//! `cargo test -p kapitza-core --test rig_selftest -- --nocapture` prints them.

use crate::rig::config::RigConfig;
use crate::rig::dds::{word_from_omega, Dds};
use crate::rig::estimator::{Estimate, Estimator, Tuning};
use crate::rig::fixed::{approx, trig, Angle, RadPerSec};
use crate::rig::phase_lock::PhaseLock;
use crate::rig::safety::{Fault, Inputs, Mode, Request, Supervisor};

/// FNV-1a, 64-bit (Fowler–Noll–Vo; offset basis and prime from the published parameters).
#[derive(Debug, Clone, Copy)]
pub struct Digest(u64);

impl Default for Digest {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Digest {
    pub fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= u64::from(x);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    pub fn u32(&mut self, x: u32) {
        self.bytes(&x.to_le_bytes());
    }
    pub fn i32(&mut self, x: i32) {
        self.bytes(&x.to_le_bytes());
    }
    pub fn u64(&mut self, x: u64) {
        self.bytes(&x.to_le_bytes());
    }
    pub fn f32(&mut self, x: f32) {
        self.u32(x.to_bits());
    }
    pub fn finish(&self) -> u64 {
        self.0
    }

    fn opt_i32(&mut self, x: Option<i32>) {
        match x {
            Some(v) => {
                self.u32(1);
                self.i32(v);
            }
            None => self.u32(0),
        }
    }

    /// Every field of an estimate.
    pub fn estimate(&mut self, e: &Estimate) {
        self.u32(e.periods);
        self.i32(e.phi.to_bits());
        self.i32(e.phi_rate.to_bits());
        self.opt_i32(e.omega_d.map(|x| x.to_bits()));
        self.opt_i32(e.omega_p.map(|x| x.to_bits()));
        self.opt_i32(e.sigma.map(|x| x.to_bits()));
        self.u32(u32::from(e.settled));
        self.opt_i32(e.equilibrium.map(|x| x.to_bits()));
        self.opt_i32(e.r.map(|x| x.0.to_bits()));
        self.opt_i32(e.r.map(|x| x.1 as i32));
        self.opt_i32(e.wobble.map(|x| x.to_bits()));
        self.opt_i32(e.amplitude.map(|x| x.to_bits()));
    }
}

/// One scenario: its name, the function that runs it, and its expected digest.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    pub name: &'static str,
    pub run: fn() -> u64,
    pub expected: u64,
}

/// sin/cos five ways over 4099 angles (an odd step covers every octant and edge).
fn trig_sweep() -> u64 {
    let mut d = Digest::default();
    for k in 0..4099u32 {
        let a = Angle::from_turns_u32(k.wrapping_mul(1_047_811));
        let (s, c) = trig::sin_cos(a);
        d.i32(s.to_bits());
        d.i32(c.to_bits());
        let (s, c) = trig::sin_cos_table(a);
        d.i32(s.to_bits());
        d.i32(c.to_bits());
        let (s, c) = trig::sin_cos_f32_poly(a);
        d.f32(s);
        d.f32(c);
        let (s, c) = trig::sin_cos_f32_micromath(a);
        d.f32(s);
        d.f32(c);
        let (s, c) = trig::sin_cos_cordic_model(a);
        d.i32(s.to_bits());
        d.i32(c.to_bits());
    }
    d.finish()
}

/// ln of ratios, fixed and micromath square roots, rounded division, angle conversions.
fn approximations() -> u64 {
    let mut d = Digest::default();
    let mut x: u64 = 1;
    for k in 0..500u64 {
        x = x
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let (a, b) = ((x >> 40) + 1, (x & 0xFFFF_FFFF) + 1);
        d.i32(approx::ln_ratio(a, b).to_bits());
        d.i32(approx::sqrt(RadPerSec::from_bits((x >> 33) as i32)).to_bits());
        d.f32(approx::sqrt_micromath((x >> 40) as f32 * 1e-3));
        d.u64(approx::div_round(x as i64 >> 1, (k as i64) - 250 + i64::from(k == 250)) as u64);
        let ang = Angle::from_bits((x >> 32) as i32);
        d.i32(ang.to_rad_q().to_bits());
        d.i32(Angle::from_rad_q(ang.to_rad_q()).to_bits());
        d.i32(Angle::from_rad(k as f64 * 0.731 - 100.0).to_bits());
    }
    d.finish()
}

/// A soft start, a ramped change, a jump of 10¹¹ ticks, a soft stop.
fn dds_ramps() -> u64 {
    let mut d = Digest::default();
    let mut g = Dds::new(10_000, 62);
    g.start_at(Angle::from_deg(12.5), word_from_omega(313.0).unwrap_or(0));
    for k in 0..60_000u32 {
        let p = g.tick();
        if k % 97 == 0 {
            d.i32(p.to_bits());
            d.i32(g.omega().to_bits());
            d.i32(g.accel().to_bits());
        }
    }
    g.set_target(word_from_omega(200.0).unwrap_or(0));
    g.advance(100_000_000_000);
    d.i32(g.phase().to_bits());
    d.u32(g.remainder());
    g.stop();
    for _ in 0..60_000 {
        d.i32(g.tick().to_bits());
    }
    d.u32(u32::from(g.is_stopped()));
    d.finish()
}

/// The phase lock against a crank that lags and is 10 % slow (integer motor model).
fn phase_lock_track() -> u64 {
    let cfg = RigConfig::REFERENCE;
    let mut pl = PhaseLock::new(&cfg);
    let mut g = Dds::new(10_000, 62);
    g.start_at(Angle::ZERO, word_from_omega(250.0).unwrap_or(0));
    let mut crank = Angle::ZERO;
    let mut speed_q16: i64 = 0;
    let mut d = Digest::default();
    for tick in 0..8_000u32 {
        for _ in 0..10 {
            g.tick();
        }
        let out = pl.update(true, g.phase(), g.omega(), g.accel(), crank);
        // speed' = (0.9·500·duty − speed)/τ, τ = 50 ms, 1 ms steps: speed += (target − speed)/50
        let target = i64::from(out.duty.to_bits()) * 450 * 2; // Q15·450 → Q16
        speed_q16 += (target - speed_q16) / 50;
        // crank += speed·1 ms, in 2^-32 turn: speed(Q16 rad/s)·2^32/(2π·2^16·1000)
        crank += Angle::from_bits(((speed_q16 * 10_430) / 1_000_000) as i32);
        if tick % 7 == 0 {
            d.i32(out.duty.to_bits().into());
            d.i32(out.error.to_bits());
            d.i32(out.crank_speed.to_bits());
        }
    }
    d.finish()
}

/// A scripted command and input sequence through the safety supervisor.
fn safety_script() -> u64 {
    let cfg = RigConfig::REFERENCE;
    let mut s = Supervisor::new(&cfg, Angle::from_deg(90.0), 4_294_000_000);
    let mut d = Digest::default();
    let reqs = [
        Request::Start { omega: 500.0 },
        Request::Start { omega: 300.0 },
        Request::SetDriveAngle { deg: 135.0 },
        Request::SetDriveAngle { deg: 250.0 },
        Request::SetOmega { omega: 100.0 },
        Request::Stop,
        Request::ClearFault,
        Request::Start { omega: 50.0 },
    ];
    let mut t: u32 = 4_294_000_000; // the µs tick wraps during the script
    for (i, r) in reqs.iter().enumerate() {
        d.u32(u32::from(s.request(*r).is_ok()));
        for k in 0..700u32 {
            t = t.wrapping_add(1000);
            if i != 4 {
                s.heard_from_link(t);
            }
            let inp = Inputs {
                estop: i == 6 && k < 10,
                current: RadPerSec::from_bits((k as i32) << 10),
                crank_speed: RadPerSec::from_num(if i == 7 { 5 } else { 100 }),
                ref_omega: RadPerSec::from_num(100),
                drive_stopped: k > 600,
                sensor_failed: false,
                phase_error: RadPerSec::ZERO,
                duty_saturated: false,
                ramping: false,
                link_us: t,
                nfault_low: false,
                bridge: None,
                sensor_not_ready: false,
            };
            let o = s.check(t, &inp);
            d.u32(u32::from(o.active) | (u32::from(o.halt) << 1));
            d.u32(o.target_word);
            d.i32(o.theta_d.to_bits());
        }
    }
    d.finish()
}

/// The estimator on a synthetic pendulum: damped slow oscillation about 0.9 rad plus the fast
/// wobble, at 10 kHz for 12 s, stamped across the µs wrap; digest of every estimate.
fn estimator_synthetic() -> u64 {
    let cfg = RigConfig::REFERENCE;
    let mut est = Estimator::new(&cfg, &Tuning::DEFAULT, Angle::from_deg(90.0));
    let omega = 313.0;
    let mut g = Dds::new(10_000, u32::MAX);
    g.set_target(word_from_omega(omega).unwrap_or(0));
    let mut d = Digest::default();
    let t0: u32 = u32::MAX - 4_000_000;
    for k in 0..120_000u32 {
        let psi = g.tick();
        let t = f64::from(k) * 1e-4;
        let slow = 0.9 + 0.12 * libm::exp(-0.4 * t) * libm::cos(8.0 * t);
        let theta = slow + 0.03 * libm::cos(omega * t) + 1e-4 * libm::sin(f64::from(k) * 1.7);
        if let Some(e) = est.push(t0.wrapping_add(k * 100), Angle::from_rad(theta), psi) {
            d.estimate(e);
        }
    }
    d.finish()
}

/// A crank motor for [`rig_controller`]: first-order speed lag in integers, 10 % weak.
struct IntMotor {
    crank: Angle,
    speed_q16: i64,
    duty: i64,
}

impl crate::rig::phase_lock::Motor for IntMotor {
    fn crank_angle(&mut self) -> Angle {
        self.crank
    }
    fn current(&mut self) -> crate::rig::fixed::Amps {
        crate::rig::fixed::Amps::from_bits((self.duty * 6) as i32) // 12 V/2 Ω at full duty, no EMF
    }
    fn set_duty(&mut self, d: crate::rig::fixed::Duty) {
        self.duty = i64::from(d.to_bits());
    }
}

impl IntMotor {
    /// 1 ms of motion: speed += (0.9·500·duty − speed)/60, crank += speed·1 ms.
    fn step(&mut self) {
        let target = self.duty * 450 * 2;
        self.speed_q16 += (target - self.speed_q16) / 60;
        self.crank += Angle::from_bits(((self.speed_q16 * 10_430) / 1_000_000) as i32);
    }
}

/// The composed rig — safety, drive generator, phase lock, estimator — through a start, a
/// ramped change, a refused request, a tilt, an e-stop and a restart, with a synthetic pendulum.
fn rig_controller() -> u64 {
    let cfg = RigConfig::REFERENCE;
    let mut rig =
        crate::rig::controller::Rig::new(&cfg, &Tuning::DEFAULT, Angle::from_deg(135.0), 0);
    let mut m = IntMotor {
        crank: Angle::from_deg(40.0),
        speed_q16: 0,
        duty: 0,
    };
    let mut d = Digest::default();
    let mut t: u32 = 0;
    for ms in 0..20_000u32 {
        let req = match ms {
            1 => Some(Request::Start { omega: 313.0 }),
            7_000 => Some(Request::SetOmega { omega: 280.0 }),
            7_001 => Some(Request::SetOmega { omega: 9_000.0 }),
            9_000 => Some(Request::SetDriveAngle { deg: 120.0 }),
            14_000 => Some(Request::ClearFault),
            14_001 => Some(Request::Start { omega: 200.0 }),
            _ => None,
        };
        if let Some(r) = req {
            d.u32(u32::from(rig.request(r).is_ok()));
        }
        rig.link_message(t);
        let rep = rig.control(t, &mut m, (12_000..13_000).contains(&ms));
        d.i32(rep.duty.to_bits().into());
        d.i32(rep.phase_error.to_bits());
        d.i32(rep.theta_d.to_bits());
        for s in 0..10u32 {
            let tt = t + s * 100;
            let x = f64::from(ms * 10 + s) * 1e-4;
            let th = 2.0
                + 0.1 * libm::exp(-0.3 * x) * libm::cos(9.0 * x)
                + 0.02 * libm::cos(m.crank.to_rad());
            rig.sample(tt, Angle::from_rad(th));
        }
        m.step();
        t = t.wrapping_add(1000);
    }
    d.estimate(rig.estimate());
    d.finish()
}

/// The bench-fault logic: the AS5047P driver against the simulated chip (glitched commands, a
/// cut cable, magnet loss), the e-stop debounce on a noisy line, the sample clock's skip rule,
/// and the supervisor's wrong-direction and sensor faults.
fn bench_faults() -> u64 {
    use crate::rig::as5047::As5047;
    use crate::rig::estop::EStop;
    use crate::simrig::sensor::{Chip, Line, DIAAGC_NO_MAGNET, DIAAGC_OK};
    let mut d = Digest::default();
    let mut chip = Chip::default();
    let mut drv = As5047::new();
    for k in 0..5000u32 {
        chip.angle = ((k * 37) & 0x3FFF) as u16;
        chip.glitch_next_command = k % 97 == 13;
        chip.line = if (2000..2050).contains(&k) {
            Line::CutPulledUp
        } else {
            Line::Connected
        };
        chip.diagnostics = if (3000..4200).contains(&k) {
            DIAAGC_NO_MAGNET
        } else {
            DIAAGC_OK
        };
        let r = drv.sample(k * 100, |w| Ok::<u16, ()>(chip.frame(w)));
        d.u32(r.t_us);
        match r.count {
            Ok(c) => d.u32(u32::from(c)),
            Err(e) => d.u32(0x1_0000 + e as u32),
        }
        d.u32(u32::from(drv.health().bad_run));
        d.u32(u32::from(drv.health().failed()));
    }
    let mut e = EStop::new();
    for k in 0..2000u32 {
        let x = k.wrapping_mul(2_654_435_761) >> 27;
        let reading = match k {
            0..=9 => None,
            500..=900 => Some(x != 0),
            _ => Some(x == 0),
        };
        d.u32(u32::from(e.update(reading)));
    }
    // A sample clock of 100 ticks a sample, run late by up to 3.5 periods.
    let mut clock = crate::station::clock::SampleClock::new(0, 100, 1);
    for k in 0..300u64 {
        let now = clock.due() + (k * k * 7919) % 350;
        let (n, skipped) = clock.advance(now);
        d.u64(n);
        d.u64(skipped);
    }
    let cfg = RigConfig::REFERENCE;
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    let mut t = 0u32;
    for (i, speed) in [-100i32, -20, 100, 100, 100].into_iter().enumerate() {
        d.u32(u32::from(s.request(Request::ClearFault).is_ok()));
        d.u32(u32::from(
            s.request(Request::Start { omega: 300.0 }).is_ok(),
        ));
        for k in 0..800u32 {
            t = t.wrapping_add(1000);
            s.heard_from_link(t);
            let inp = Inputs {
                estop: false,
                // Segment 3 slips a cycle every 150 ticks; segment 4 draws 2.5 A (I²t).
                current: RadPerSec::from_num(if i == 4 { 2.5 } else { 0.0 }),
                crank_speed: RadPerSec::from_num(speed),
                ref_omega: RadPerSec::from_num(100),
                drive_stopped: false,
                sensor_failed: i == 2 && k == 799,
                phase_error: RadPerSec::from_num(match (i, k % 150) {
                    (3, 0) => 3.0,
                    (3, 1) => -3.0,
                    _ => 0.0,
                }),
                duty_saturated: false,
                ramping: false,
                link_us: t,
                nfault_low: false,
                bridge: None,
                sensor_not_ready: false,
            };
            let o = s.check(t, &inp);
            d.u32(u32::from(o.halt));
            d.u32(match s.mode() {
                Mode::Idle => 0,
                Mode::Running => 1,
                Mode::Stopping(_) => 2,
                Mode::Faulted(f) => 10 + fault_index(f),
            });
        }
    }
    d.finish()
}

/// A fault's number in the digest: its place in [`Fault`]'s declaration.
fn fault_index(f: Fault) -> u32 {
    use crate::rig::bridge::Line;
    match f {
        Fault::EStop => 0,
        Fault::OverCurrent => 1,
        Fault::Stall => 2,
        Fault::Sensor => 3,
        Fault::WrongDirection => 4,
        Fault::PhaseLockLost => 5,
        Fault::OverCurrentRms => 6,
        Fault::DutyCeiling => 7,
        Fault::Bridge(Line::NFault) => 8,
        Fault::Bridge(Line::Break) => 9,
    }
}

/// Every scenario, in order.
pub const CASES: &[Case] = &[
    Case {
        name: "trig_sweep",
        run: trig_sweep,
        expected: 0x957d_7127_d61e_5a92,
    },
    Case {
        name: "approximations",
        run: approximations,
        expected: 0xacec_ec80_d292_69e3,
    },
    Case {
        name: "dds_ramps",
        run: dds_ramps,
        expected: 0x1f16_19fa_8393_4e62,
    },
    Case {
        name: "phase_lock_track",
        run: phase_lock_track,
        expected: 0x4829_3a2b_0d4a_04ee,
    },
    Case {
        name: "safety_script",
        run: safety_script,
        expected: 0xa756_8795_bd66_5c26,
    },
    Case {
        name: "rig_controller",
        run: rig_controller,
        expected: 0x0f1b_05ef_c276_7cbf,
    },
    Case {
        name: "estimator_synthetic",
        run: estimator_synthetic,
        expected: 0x0fa2_367a_4f61_e566,
    },
    Case {
        name: "bench_faults",
        run: bench_faults,
        expected: 0x6296_a4a2_a9d5_b4f5,
    },
];
