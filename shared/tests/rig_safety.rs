//! The safety supervisor as a state machine under random command and input sequences (proptest):
//! no sequence pushes the rig past its limits, and a refused request changes nothing.

use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::dds::{word_from_omega, Dds};
use kapitza_core::rig::fixed::{Amps, Angle, RadPerSec};
use kapitza_core::rig::safety::{Fault, Inputs, Mode, Request, Supervisor};
use proptest::prelude::*;

#[derive(Debug, Clone)]
enum Event {
    Req(Request),
    /// Control ticks with these inputs; `link` sends a message first.
    Ticks {
        n: u32,
        estop: bool,
        amps: f64,
        crank_frac: f64,
        link: bool,
    },
}

fn request() -> impl Strategy<Value = Request> {
    prop_oneof![
        (-50.0f64..600.0).prop_map(|omega| Request::Start { omega }),
        (-50.0f64..600.0).prop_map(|omega| Request::SetOmega { omega }),
        (-90.0f64..300.0).prop_map(|deg| Request::SetDriveAngle { deg }),
        Just(Request::Stop),
        Just(Request::ClearFault),
        Just(Request::Start { omega: f64::NAN }),
    ]
}

fn event() -> impl Strategy<Value = Event> {
    prop_oneof![
        request().prop_map(Event::Req),
        (
            1u32..2_000,
            prop::bool::weighted(0.05),
            0.0f64..4.0,
            0.0f64..1.2,
            prop::bool::weighted(0.8)
        )
            .prop_map(|(n, estop, amps, crank_frac, link)| Event::Ticks {
                n,
                estop,
                amps,
                crank_frac,
                link
            }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn limits_hold_and_refusals_change_nothing(events in prop::collection::vec(event(), 1..40)) {
        let cfg = RigConfig::REFERENCE;
        let d = cfg.derived();
        let omega_max_word = word_from_omega(cfg.limits.omega_max).unwrap();
        let theta_step = (cfg.limits.drive_angle_rate_max_deg / 1000.0 / 360.0 * 4_294_967_296.0) as i64 + 1;
        let mut sup = Supervisor::new(&cfg, Angle::from_deg(90.0), 0);
        let mut dds = Dds::new(cfg.sample_hz, d.dds_step);
        let mut t: u32 = 0;
        let mut last_link: u32 = 0;
        for ev in events {
            match ev {
                Event::Req(r) => {
                    let before = sup;
                    if let Err(why) = sup.request(r) {
                        prop_assert_eq!(sup, before, "refused {:?} ({}) changed state", r, why);
                    }
                }
                Event::Ticks { n, estop, amps, crank_frac, link } => {
                    for _ in 0..n {
                        t = t.wrapping_add(1000);
                        if link {
                            sup.heard_from_link(t);
                            last_link = t;
                        }
                        let theta_before = sup.theta_d();
                        let inp = Inputs {
                            estop,
                            current: Amps::from_num(amps),
                            crank_speed: RadPerSec::saturating_from_num(dds.omega().to_num::<f64>() * crank_frac),
                            ref_omega: dds.omega(),
                            drive_stopped: dds.is_stopped(),
                        };
                        let out = sup.check(t, &inp);
                        if out.halt { dds.halt() } else { dds.set_target(out.target_word) }
                        let w_before = dds.word();
                        for _ in 0..d.samples_per_control { dds.tick(); }
                        // ω never above its limit; its change per tick never above the rate limit.
                        prop_assert!(out.target_word <= omega_max_word);
                        prop_assert!(dds.word() <= omega_max_word.max(w_before));
                        prop_assert!(u64::from(dds.word().abs_diff(w_before)) <= u64::from(d.dds_step) * u64::from(d.samples_per_control) || out.halt);
                        // θd slews at most one step per tick and stays in the mount's travel.
                        let dth = i64::from((out.theta_d - theta_before).to_bits()).abs();
                        prop_assert!(dth <= theta_step, "θd jumped {}", dth);
                        let deg = out.theta_d.to_deg();
                        let deg = if deg < cfg.limits.drive_angle_min_deg - 1e-6 { deg + 360.0 } else { deg };
                        prop_assert!(deg >= cfg.limits.drive_angle_min_deg - 1e-6 && deg <= cfg.limits.drive_angle_max_deg + 1e-6, "θd {}", deg);
                        // The e-stop halts at once, and the drive may not run while it is pressed.
                        if estop {
                            prop_assert!(out.halt && !out.active);
                            prop_assert_eq!(sup.mode(), Mode::Faulted(Fault::EStop));
                        }
                        // Silent link: never running more than the timeout after the last message.
                        if t.wrapping_sub(last_link) > cfg.limits.link_timeout_ms * 1000 {
                            prop_assert!(sup.mode() != Mode::Running);
                        }
                    }
                }
            }
        }
    }
}
