//! The calibration in use: the simulated rig's sensor has its own zero and direction (its
//! truth), read through the configured calibration, as a real bench's would be.

use kapitza_core::link::message::Telemetry;
use kapitza_core::link::{Request, Response};
use kapitza_core::math;
use kapitza_core::simrig::Params;
use kapitza_test_support::sim_bench::Bench;

/// The pendulum angle (degrees) in the first telemetry frame after 40 ms.
fn theta_deg(p: Params, zero: u16, sign: i8) -> f64 {
    let mut cfg = p.configured();
    cfg.calibration.pendulum_zero = zero;
    cfg.calibration.pendulum_sign = sign;
    let mut b = Bench::new(p, cfg);
    assert_eq!(b.ask(Request::Telemetry { period_ms: 20 }), Response::Ok);
    b.run(0.04);
    let t: Vec<Telemetry> = b
        .streamed
        .iter()
        .filter_map(|r| match r {
            Response::Telemetry(t) => Some(*t),
            _ => None,
        })
        .collect();
    kapitza_core::math::wrap_deg(f64::from(t[0].theta) * 360.0 / 4_294_967_296.0)
}

#[test]
fn the_pendulum_sensor_is_read_through_the_configured_zero_and_sign() {
    // The sensor mounted 10° off: hanging at rest it reads −10° until its zero is calibrated
    // to the count it reads at rest, 2^14 − 455 (10° = 455.1 counts of 2^14 a turn; 0.02° of
    // noise; a count is 0.022°).
    let mut p = Params::DEMO;
    p.sensor_zero = math::to_rad(10.0);
    let off = theta_deg(p, 0, 1);
    assert!((off + 10.0).abs() < 0.1, "{off}");
    let zeroed = theta_deg(p, 16_384 - 455, 1);
    assert!(zeroed.abs() < 0.1, "{zeroed}");
    // Mounted the other way round, the pendulum released at 30°: read with the wrong sign it
    // swings on the other side; with the calibrated sign on the right one (≈ 30° cos(ω0 t)).
    let mut p = Params::DEMO;
    p.sensor_sign = -1.0;
    p.theta0 = math::to_rad(30.0);
    let wrong = theta_deg(p, 0, 1);
    let right = theta_deg(p, 0, -1);
    assert!(wrong < -20.0 && right > 20.0, "{wrong} {right}");
    assert!((wrong + right).abs() < 0.1, "{wrong} {right}");
}
