//! HC09 for the rig logic: configuration, safety, controller.

use kapitza_core::math;
use kapitza_core::model::Geometry;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::controller::Rig;
use kapitza_core::rig::estimator::Tuning;
use kapitza_core::rig::fixed::{Amps, Angle, Duty};
use kapitza_core::rig::phase_lock::Motor;
use kapitza_core::rig::safety::Request;
use proptest::prelude::*;

use super::*;

/// An ideal motor: the crank turns at duty × ω_full; no current.
struct IdealMotor {
    crank: f64,
    omega_full: f64,
    dt: f64,
    duty: f64,
}

impl Motor for IdealMotor {
    fn crank_angle(&mut self) -> Angle {
        self.crank += self.duty * self.omega_full * self.dt;
        self.crank = math::wrap_pi(self.crank);
        Angle::from_rad(self.crank)
    }
    fn current(&mut self) -> Amps {
        Amps::ZERO
    }
    fn set_duty(&mut self, duty: Duty) {
        self.duty = duty.to_num();
    }
}

/// Starts the rig at half its speed limit and runs it for 4 s (at most 100 000 samples): long
/// enough for the reference rig's ramp (60 rad/s²) to reach 210 rad/s, where the duty conversion
/// and the stall test multiply the largest numbers.
fn run_rig(cfg: &RigConfig) {
    let mut rig = Rig::new(cfg, &Tuning::DEFAULT, Angle::from_deg(90.0), 0);
    let fc = cfg.control_hz;
    let spc = cfg.sample_hz / fc;
    let _ = rig.request(Request::Start {
        omega: 0.5 * cfg.limits.omega_max,
    });
    let mut motor = IdealMotor {
        crank: 0.0,
        omega_full: cfg.motor.omega_per_duty,
        dt: 1.0 / f64::from(fc),
        duty: 0.0,
    };
    let dt_us = 1_000_000 / fc;
    let dt_sample = (dt_us / spc.max(1)).max(1);
    let ticks = (100_000 / spc.max(1)).clamp(1, 4 * fc);
    let mut t = 0u32;
    for _ in 0..ticks {
        for _ in 0..spc {
            t = t.wrapping_add(dt_sample);
            rig.sample(t, Angle::from_deg(90.0));
        }
        rig.link_message(t);
        rig.control(t, &mut motor, false);
    }
}

/// One number of a rig configuration.
fn rig_field() -> impl Strategy<Value = (&'static str, usize)> {
    const NAMES: [&str; 17] = [
        "amplitude",
        "length",
        "gravity",
        "omega_max",
        "omega_rate_max",
        "drive_angle_min_deg",
        "drive_angle_max_deg",
        "drive_angle_rate_max_deg",
        "current_max",
        "stall_min_omega",
        "stall_fraction",
        "omega_per_duty",
        "lag",
        "kp",
        "ki",
        "max_correction",
        "control_hz",
    ];
    (0..NAMES.len()).prop_map(|i| (NAMES[i], i))
}

fn rig_with(i: usize, x: f64) -> RigConfig {
    let mut c = RigConfig::REFERENCE;
    let (l, m) = (&mut c.limits, &mut c.motor);
    match i {
        0 => c.amplitude = x,
        1 => c.geometry = Geometry::Rod { length: x },
        2 => c.gravity = x,
        3 => l.omega_max = x,
        4 => l.omega_rate_max = x,
        5 => l.drive_angle_min_deg = x,
        6 => l.drive_angle_max_deg = x,
        7 => l.drive_angle_rate_max_deg = x,
        8 => l.current_max = x,
        9 => l.stall_min_omega = x,
        10 => l.stall_fraction = x,
        11 => m.omega_per_duty = x,
        12 => m.lag = x,
        13 => m.kp = x,
        14 => m.ki = x,
        15 => m.max_correction = x,
        _ => {
            // Integers: the control rate from the float's magnitude (0, huge, or plausible).
            c.control_hz = if x.is_finite() && x > 0.0 {
                x.min(4e9) as u32
            } else {
                0
            };
        }
    }
    c
}

proptest! {
    #![proptest_config(cases(512))]

    #[test]
    fn hc09_rig_config_names_the_bad_field((name, i) in rig_field(), x in bad()) {
        let cfg = rig_with(i, x);
        match cfg.validate() {
            Err(e) => {
                // ℓ takes part in the limits on A/ℓ and g/ℓ; the drive-angle range and the
                // rates are checked as pairs.
                let also: &[&str] = match name {
                    "length" => &["amplitude", "gravity"],
                    "drive_angle_min_deg" => &["drive_angle_max_deg"],
                    "control_hz" => &["sample_hz", "omega_max"],
                    _ => &[],
                };
                let mut all = vec![name];
                all.extend_from_slice(also);
                names(&e, &all)?;
            }
            Ok(cfg) => {
                finite("rig", &[cfg.ell(), cfg.omega0(), cfg.r_for_omega(cfg.limits.omega_max)])?;
                for r in [0.5, 1.0, 3.0] {
                    if let Ok(w) = cfg.omega_for_r(r) {
                        finite("omega_for_r", &[w])?;
                    }
                }
                // Any configuration that validates runs without a panic (overflow checks are on).
                run_rig(&cfg);
            }
        }
    }

    #[test]
    fn hc09_rig_requests_refuse_bad_numbers(omega in or_good(0.0..400.0), deg in or_good(0.0..180.0),
                                            r in or_good(0.1..5.0)) {
        let cfg = RigConfig::REFERENCE;
        let mut rig = Rig::new(&cfg, &Tuning::DEFAULT, Angle::from_deg(90.0), 0);
        let before = *rig.supervisor();
        match rig.request(Request::Start { omega }) {
            Err(e) => {
                names(&e, &["omega"])?;
                prop_assert_eq!(*rig.supervisor(), before, "a refusal changed the supervisor");
            }
            Ok(()) => prop_assert!(omega.is_finite() && (0.0..=cfg.limits.omega_max).contains(&omega)),
        }
        if let Err(e) = rig.request(Request::SetOmega { omega }) {
            names(&e, &["omega", "mode"])?;
        }
        match rig.request(Request::SetDriveAngle { deg }) {
            Err(e) => names(&e, &["drive angle"])?,
            Ok(()) => prop_assert!(deg.is_finite()),
        }
        match cfg.omega_for_r(r) {
            Err(e) => names(&e, &["R", "omega"])?,
            Ok(w) => prop_assert!(w.is_finite() && w > 0.0),
        }
    }
}

#[test]
fn hc09_rig_examples() {
    let name = |i: usize, x: f64| -> &'static str { rig_with(i, x).validate().unwrap_err().name };
    // Zero-length rod, NaN gravity, a 1 km stroke on a 25 cm rod.
    assert_eq!(name(1, 0.0), "length");
    assert_eq!(name(2, f64::NAN), "gravity");
    assert_eq!(name(0, 1e3), "amplitude");
    // Each of these would validate and then panic in the control loop: ki below one LSB of
    // I16F16 (0: division by zero in the anti-windup limit), a stall fraction of 1e300 (i64
    // overflow in the stall test), a motor too slow for the duty conversion (i64 overflow).
    assert_eq!(name(14, 1e-9), "ki");
    assert_eq!(name(10, 1e300), "stall_fraction");
    assert_eq!(name(11, 1e-3), "omega_per_duty");
    // Bad requests are refused with the number in the reason.
    let mut rig = Rig::new(
        &RigConfig::REFERENCE,
        &Tuning::DEFAULT,
        Angle::from_deg(90.0),
        0,
    );
    let e = rig.request(Request::Start { omega: f64::NAN }).unwrap_err();
    assert!(e.to_string().contains("omega = NaN"), "{e}");
    let e = rig
        .request(Request::SetDriveAngle { deg: 1e300 })
        .unwrap_err();
    assert!(e.to_string().contains("drive angle"), "{e}");
    assert_eq!(RigConfig::REFERENCE.omega_for_r(0.0).unwrap_err().name, "R");
}
