//! The rig's side of the link: commands applied all or nothing, refusals with their reasons,
//! status and telemetry in the wire formats.

use kapitza_core::link::convert::{deg_along_travel, from_q16, to_q16};
use kapitza_core::link::message::{Counters, Fault, Mode};
use kapitza_core::link::{Reason, Request};
use kapitza_core::persist::{ConfigOrigin, Fallback};
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::controller::Rig;
use kapitza_core::rig::estimator::Tuning;
use kapitza_core::rig::fixed::{Amps, Angle, Duty};
use kapitza_core::rig::phase_lock::Motor;
use kapitza_core::rig::safety;
use kapitza_core::station::serve::{
    apply, config_change_allowed, status, Clock, Command, RigServer,
};

const CFG: RigConfig = RigConfig::REFERENCE;

fn rig() -> Rig {
    Rig::new(&CFG, &Tuning::DEFAULT, Angle::ZERO, 0)
}

fn q(x: f64) -> i32 {
    to_q16(x)
}

/// A motor that follows the duty exactly enough for the supervisor: the crank stands still
/// unless driven; the current is whatever the test sets.
struct Still {
    current: Amps,
}

impl Motor for Still {
    fn crank_angle(&mut self) -> Angle {
        Angle::ZERO
    }
    fn current(&mut self) -> Amps {
        self.current
    }
    fn set_duty(&mut self, _duty: Duty) {}
}

#[test]
fn set_drive_starts_then_changes_omega() {
    let mut r = rig();
    apply(
        &mut r,
        &CFG,
        Command::SetDrive {
            r: q(3.0),
            theta_d_deg: q(180.0),
        },
    )
    .unwrap();
    let sup = r.supervisor();
    assert_eq!(sup.mode(), safety::Mode::Running);
    // ω = ωc √3 (physics §3; 313.2 rad/s for the reference rig, RigConfig's own test).
    let w = kapitza_core::rig::dds::omega_of_word(sup.target_word());
    assert!((w - CFG.omega_for_r(3.0).unwrap()).abs() < 1e-3, "{w}");
    assert_eq!(sup.theta_d_target(), Angle::HALF_TURN);
    // Running: a new R changes ω.
    apply(
        &mut r,
        &CFG,
        Command::SetDrive {
            r: q(2.0),
            theta_d_deg: q(190.0),
        },
    )
    .unwrap();
    let w2 = kapitza_core::rig::dds::omega_of_word(r.supervisor().target_word());
    assert!((w2 - CFG.omega_for_r(2.0).unwrap()).abs() < 1e-3);
    // R = 0 is a soft stop.
    apply(
        &mut r,
        &CFG,
        Command::SetDrive {
            r: 0,
            theta_d_deg: q(190.0),
        },
    )
    .unwrap();
    assert_eq!(
        r.supervisor().mode(),
        safety::Mode::Stopping(safety::StopReason::Requested)
    );
}

#[test]
fn refusals_change_nothing_and_say_why() {
    let r0 = rig();
    // R = 6 needs ω = ωc √6 ≈ 443 rad/s > ω_max = 420 rad/s.
    let w6 = CFG.omega_for_r(6.0).unwrap();
    let cases = [
        (
            Command::SetDrive {
                r: q(6.0),
                theta_d_deg: q(90.0),
            },
            Reason::OmegaAboveLimit {
                requested: q(w6),
                limit: q(420.0),
            },
        ),
        (
            Command::SetDrive {
                r: q(1.0),
                theta_d_deg: q(200.0),
            },
            Reason::DriveAngleOutOfRange {
                requested: q(200.0),
                min: q(-10.0),
                max: q(190.0),
            },
        ),
        (
            Command::SetDrive {
                r: -1,
                theta_d_deg: q(90.0),
            },
            Reason::RInvalid { requested: -1 },
        ),
    ];
    for (cmd, want) in cases {
        let mut r = r0;
        assert_eq!(apply(&mut r, &CFG, cmd), Err(want), "{cmd:?}");
        // The θd half of the first case was valid: it must not have been applied either.
        assert_eq!(r, r0, "{cmd:?} changed the rig");
    }
    // Start needs Idle, SetOmega needs Running: while stopping, a new R is refused whole.
    let mut r = r0;
    apply(
        &mut r,
        &CFG,
        Command::SetDrive {
            r: q(3.0),
            theta_d_deg: q(0.0),
        },
    )
    .unwrap();
    apply(&mut r, &CFG, Command::Stop).unwrap();
    let before = r;
    let got = apply(
        &mut r,
        &CFG,
        Command::SetDrive {
            r: q(3.0),
            theta_d_deg: q(45.0),
        },
    );
    assert_eq!(
        got,
        Err(Reason::WrongMode(Mode::Stopping(
            kapitza_core::link::message::StopReason::Requested
        )))
    );
    assert_eq!(r, before);
    assert_eq!(
        config_change_allowed(&r),
        Err(Reason::WrongMode(Mode::Stopping(
            kapitza_core::link::message::StopReason::Requested
        )))
    );
    assert_eq!(config_change_allowed(&r0), Ok(()));
}

#[test]
fn faults_refuse_commands_but_stop_is_always_fine() {
    let mut r = rig();
    let mut m = Still {
        current: Amps::ZERO,
    };
    // E-stop pressed: faulted.
    r.control(1000, &mut m, true);
    assert_eq!(
        r.supervisor().mode(),
        safety::Mode::Faulted(safety::Fault::EStop)
    );
    let before = r;
    assert_eq!(
        apply(
            &mut r,
            &CFG,
            Command::SetDrive {
                r: q(1.0),
                theta_d_deg: q(0.0)
            }
        ),
        Err(Reason::Faulted(Fault::EStop))
    );
    assert_eq!(apply(&mut r, &CFG, Command::Stop), Ok(()));
    assert_eq!(
        apply(&mut r, &CFG, Command::ClearFault),
        Err(Reason::EStopStillActive)
    );
    assert_eq!(r, before);
    // Released: the fault clears.
    r.control(2000, &mut m, false);
    assert_eq!(apply(&mut r, &CFG, Command::ClearFault), Ok(()));
    assert_eq!(r.supervisor().mode(), safety::Mode::Idle);
}

#[test]
fn commands_are_recognised() {
    assert_eq!(Command::of(&Request::Stop), Some(Command::Stop));
    assert_eq!(Command::of(&Request::GetStatus), None);
    assert_eq!(
        Command::of(&Request::SetDrive {
            r: 1,
            theta_d_deg: 2
        }),
        Some(Command::SetDrive {
            r: 1,
            theta_d_deg: 2
        })
    );
}

#[test]
fn status_and_telemetry_in_wire_units() {
    let mut r = rig();
    apply(
        &mut r,
        &CFG,
        Command::SetDrive {
            r: q(3.0),
            theta_d_deg: q(190.0),
        },
    )
    .unwrap();
    let after_watchdog = kapitza_core::link::message::ResetInfo {
        cause: kapitza_core::link::message::ResetCause::Watchdog,
        last_fault: Some(kapitza_core::link::message::Fault::Stall),
        fault_pc: None,
    };
    let s = status(
        &r,
        &CFG,
        false,
        ConfigOrigin::Defaults(Fallback::Missing),
        42,
        Counters::default(),
        after_watchdog,
    );
    assert_eq!(s.mode, Mode::Running);
    assert_eq!(s.reset, after_watchdog);
    // θd targets are degrees along the travel [−10°, 190°]: 190° stays 190°, not −170°.
    assert!((from_q16(s.theta_d_target_deg) - 190.0).abs() < 1e-4);
    assert!((from_q16(s.omega_target) - CFG.omega_for_r(3.0).unwrap()).abs() < 1e-3);
    assert_eq!(s.theta_d_deg, 0);
    let mut m = Still {
        current: Amps::from_num(1.5),
    };
    let rep = r.control(1000, &mut m, false);
    let mut srv = RigServer::new(
        CFG,
        ConfigOrigin::Stored,
        Angle::ZERO,
        Clock::single(0, 0),
        [0, 1, 0],
    );
    srv.rig = r;
    srv.counters.commands = 5;
    let t = srv.telemetry(1000, &rep, Angle::QUARTER_TURN, Amps::from_num(1.5));
    assert_eq!(t.commands, 5);
    assert_eq!(t.t_us, 1000);
    assert_eq!(t.theta, 1 << 30);
    assert_eq!(t.current, 3 << 15);
    assert_eq!(t.mode, Mode::Running);
    // Degrees along the travel, to the angle's resolution (2^-32 turn = 8.4e-8°).
    assert!((deg_along_travel(Angle::from_deg(-10.0), -10.0) + 10.0).abs() < 1e-6);
    assert!((deg_along_travel(Angle::HALF_TURN, -10.0) - 180.0).abs() < 1e-6);
    assert!((deg_along_travel(Angle::from_deg(190.0), -10.0) - 190.0).abs() < 1e-6);
    // The conversions at the edges: saturating, NaN to 0.
    assert_eq!(to_q16(1e12), i32::MAX);
    assert_eq!(to_q16(-1e12), i32::MIN);
    assert_eq!(to_q16(f64::NAN), 0);
}

#[test]
fn reasons_read_well() {
    let r = Reason::DriveAngleOutOfRange {
        requested: q(200.0),
        min: q(-10.0),
        max: q(190.0),
    };
    assert_eq!(
        r.to_string(),
        "[19] drive angle 200 deg is outside the mount's travel [-10, 190] deg"
    );
    assert_eq!(
        Reason::VersionMismatch { rig: 1, frame: 2 }.to_string(),
        "[5] protocol version 2 in the frame, but the rig speaks version 1"
    );
    // A configuration refusal names its field.
    let mut c = CFG;
    c.sample_hz = 10_001;
    let w: kapitza_core::link::WireConfig = c.into();
    assert_eq!(
        w.to_valid().unwrap_err().to_string(),
        "[23] configuration value sample_hz out of range"
    );
    assert_eq!(
        kapitza_core::link::WireConfig::from(CFG).to_valid(),
        Ok(CFG)
    );
}

mod server {
    use super::*;
    use kapitza_core::link::{Response, VersionInfo, WireConfig};
    use kapitza_core::station::serve::Effect;

    fn server() -> RigServer {
        RigServer::new(
            CFG,
            ConfigOrigin::Defaults(Fallback::Missing),
            Angle::ZERO,
            Clock::single(0, 0),
            [1, 2, 3],
        )
    }

    #[test]
    fn answers_every_request() {
        let mut s = server();
        assert_eq!(
            s.respond(Request::GetVersion, Clock::single(10, 0), false),
            (
                Response::Version(VersionInfo {
                    protocol: kapitza_core::link::PROTOCOL_VERSION,
                    firmware: [1, 2, 3]
                }),
                Effect::None
            )
        );
        assert_eq!(
            s.respond(
                Request::Telemetry { period_ms: 50 },
                Clock::single(20, 0),
                false
            ),
            (Response::Ok, Effect::Telemetry { period_ms: 50 })
        );
        assert_eq!(
            s.respond(Request::GetConfig, Clock::single(30, 0), false).0,
            Response::Config(CFG.into())
        );
        let (r, _) = s.respond(Request::GetStatus, Clock::single(40, 77), true);
        let Response::Status(st) = r else {
            panic!("{r:?}")
        };
        assert_eq!(st.uptime_ms, 77);
        assert!(st.estop);
        assert_eq!(st.config, ConfigOrigin::Defaults(Fallback::Missing));
        let set = Request::SetDrive {
            r: q(2.0),
            theta_d_deg: q(45.0),
        };
        assert_eq!(
            s.respond(set, Clock::single(50, 0), false),
            (Response::Ok, Effect::None)
        );
        // A start from idle waits for its pre-run check (run by the rig loop's control tick).
        assert_eq!(s.rig.supervisor().mode(), safety::Mode::Idle);
        assert_eq!(s.check, Some(kapitza_core::link::message::Check::Running));
        // Anything but a stop is refused meanwhile; a stop aborts it.
        assert_eq!(
            s.respond(set, Clock::single(60, 0), false).0,
            Response::Refused(Reason::CheckRunning)
        );
        assert_eq!(
            s.respond(Request::Stop, Clock::single(70, 0), false).0,
            Response::Ok
        );
        assert_eq!(
            s.check,
            Some(kapitza_core::link::message::Check::Failed(
                kapitza_core::link::message::Verdict::Aborted
            ))
        );
    }

    /// Issue 23's configurations that switched a safety limit off, sent as `SetConfig` straight
    /// to the rig (no host check): each is refused naming its field, and nothing changes.
    #[test]
    fn the_rig_refuses_a_limit_switched_off_by_name() {
        use kapitza_core::link::reason::ConfigField as F;
        type Spoil = fn(&mut WireConfig);
        let cases: [(F, Spoil); 6] = [
            (F::LinkTimeoutMs, |w| w.link_timeout_ms = 0),
            (F::LinkTimeoutMs, |w| w.link_timeout_ms = u32::MAX),
            (F::OvercurrentMs, |w| w.overcurrent_ms = u32::MAX),
            (F::ControlHz, |w| {
                // 5 Hz with an ω_max below π·5 (the aliasing bound) and a stall speed below it.
                w.control_hz = 5;
                w.omega_max = 15.0;
                w.stall_min_omega = 10.0;
            }),
            (F::StallMs, |w| w.stall_ms = u32::MAX),
            (F::DutyMax, |w| w.duty_max = 0.0),
        ];
        for (field, spoil) in cases {
            let mut s = server();
            let mut w: WireConfig = CFG.into();
            spoil(&mut w);
            let before = s;
            let (r, e) = s.respond(Request::SetConfig(w), Clock::single(10, 0), false);
            assert_eq!(
                r,
                Response::Refused(Reason::ConfigInvalid { field }),
                "{w:?}"
            );
            assert_eq!(e, Effect::None);
            assert_eq!((s.cfg, s.origin), (before.cfg, before.origin));
            assert_eq!(s.counters.commands, before.counters.commands);
            let (r, _) = s.respond(Request::GetConfig, Clock::single(20, 0), false);
            assert_eq!(r, Response::Config(CFG.into()));
        }
    }

    #[test]
    fn configuration_changes_only_when_idle_and_valid() {
        let mut s = server();
        let mut new = CFG;
        new.amplitude = 0.012;
        // Out of range: refused, nothing changes.
        let mut bad: WireConfig = new.into();
        bad.control_hz = 0;
        let before = s;
        let (r, e) = s.respond(Request::SetConfig(bad), Clock::single(10, 0), false);
        assert!(
            matches!(r, Response::Refused(Reason::ConfigInvalid { .. })),
            "{r:?}"
        );
        assert_eq!(e, Effect::None);
        // Only the link keep-alive moved.
        assert_eq!((s.cfg, s.origin), (before.cfg, before.origin));
        // Starting (its pre-run check running): refused.
        s.respond(
            Request::SetDrive {
                r: q(1.0),
                theta_d_deg: 0,
            },
            Clock::single(20, 0),
            false,
        );
        let (r, _) = s.respond(Request::SetConfig(new.into()), Clock::single(30, 0), false);
        assert_eq!(r, Response::Refused(Reason::CheckRunning));
        assert_eq!(s.cfg, CFG);
        // Running: refused.
        apply(
            &mut s.rig,
            &CFG,
            Command::SetDrive {
                r: q(1.0),
                theta_d_deg: 0,
            },
        )
        .unwrap();
        s.activity = kapitza_core::station::serve::Activity::None;
        let (r, _) = s.respond(Request::SetConfig(new.into()), Clock::single(30, 0), false);
        assert_eq!(r, Response::Refused(Reason::WrongMode(Mode::Running)));
        assert_eq!(s.cfg, CFG);
        // Idle: accepted, to be stored; the status follows the store's outcome.
        let mut s = server();
        assert_eq!(
            s.respond(Request::SetConfig(new.into()), Clock::single(40, 0), false),
            (Response::Ok, Effect::StoreConfig(new))
        );
        assert_eq!(s.cfg, new);
        assert_eq!(s.origin, ConfigOrigin::Received { saved: false });
        s.config_saved(true);
        assert_eq!(s.origin, ConfigOrigin::Received { saved: true });
    }
}
