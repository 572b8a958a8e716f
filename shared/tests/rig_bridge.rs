//! The H-bridge's fault lines through the rig loop (`kapitza_core::rig::bridge`): nFAULT and
//! TIM1's break latched as `Fault::Bridge` at the control tick that sees them, ignored while
//! the bridge sleeps and wakes, `ClearFault` refused while nFAULT is low and re-arming the
//! outputs once it is high; then the same against the simulated rig, whose e-stop relay cuts
//! the bridge's supply: "press e-stop, release, clear, run". And the pendulum sensor's MISO
//! stuck low mid-run, a sensor fault while driving.

use kapitza_core::link::frame::{encode, receive_response, Header};
use kapitza_core::link::message::{BridgeLine, Check, Fault, Mode};
use kapitza_core::link::{FrameReader, Reason, Request, Response, MAX_REQUEST_FRAME};
use kapitza_core::link::{Status, MAX_RESPONSE_FRAME};
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::rig::as5047::Diagnostics;
use kapitza_core::rig::bridge::{Lines, WAKE_IGNORE_US};
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::fixed::{Angle, Duty};
use kapitza_core::simrig::sensor::Line;
use kapitza_core::simrig::Params;
use kapitza_core::station::drive::Drive;
use kapitza_core::station::{RigLoop, Sample};
use kapitza_test_support::sim_bench::Bench;

const CFG: RigConfig = RigConfig::REFERENCE;

/// A crank that turns at the speed the duty asks for (500 rad/s at full duty), behind a bridge
/// whose nFAULT the test drives; TIM1's break sets BIF and clears MOE while nFAULT is low, as
/// the hardware does, and the outputs turn the crank only while MOE is set.
struct Rig {
    angle: Angle,
    duty: f64,
    nfault_low: bool,
    bif: bool,
    moe: bool,
    rearms: u32,
}

impl Drive for Rig {
    fn crank_raw(&mut self) -> Angle {
        self.angle
    }
    fn current_counts(&mut self) -> u16 {
        0
    }
    fn set_duty(&mut self, d: Duty) {
        self.duty = d.to_num();
    }
    fn bridge_lines(&mut self) -> Lines {
        Lines {
            nfault_low: self.nfault_low,
            break_flag: self.bif,
        }
    }
    fn rearm(&mut self) {
        self.rearms += 1;
        self.bif = self.nfault_low;
        self.moe = !self.nfault_low;
    }
}

struct Loop {
    rig: RigLoop,
    hw: Rig,
    t_us: u32,
    /// Control ticks so far, and each tick's nSLEEP.
    ticks: u32,
    awake: Vec<bool>,
    seq: u8,
}

impl Loop {
    fn new() -> Self {
        Self {
            rig: RigLoop::new(CFG, ConfigOrigin::Stored, Angle::ZERO, 0, [0, 1, 0]),
            hw: Rig {
                angle: Angle::ZERO,
                duty: 0.0,
                nfault_low: false,
                bif: false,
                moe: true,
                rearms: 0,
            },
            t_us: 0,
            ticks: 0,
            awake: Vec::new(),
            seq: 0,
        }
    }

    /// One control tick (10 samples of 100 µs at the reference 10 kHz / 1 kHz).
    fn tick(&mut self) {
        for _ in 0..10 {
            self.t_us = self.t_us.wrapping_add(100);
            if self.hw.nfault_low {
                self.hw.bif = true;
                self.hw.moe = false;
            }
            let due = self.rig.sample(Sample {
                t_us: self.t_us,
                count: 0,
                failed: false,
                late: false,
                sensor_failed: false,
                diagnostics: Some(Diagnostics::HEALTHY),
            });
            if due {
                let tick = self.rig.control(self.t_us, &mut self.hw, Some(false));
                self.ticks += 1;
                self.awake.push(tick.bridge);
                if self.hw.moe && tick.bridge {
                    self.hw.angle += Angle::from_rad(self.hw.duty * 500.0 * 1e-3);
                }
            }
        }
    }

    fn run_ms(&mut self, ms: u32) {
        for _ in 0..ms {
            self.tick();
        }
    }

    fn ask(&mut self, req: Request) -> Response {
        self.seq = self.seq % 250 + 1;
        let mut f = [0u8; MAX_REQUEST_FRAME];
        let n = encode(Header::new(self.seq), &req, &mut f).unwrap();
        self.rig.receive(&f[..n], self.t_us);
        let mut reader = FrameReader::<MAX_RESPONSE_FRAME>::new();
        let mut buf = [0u8; 256];
        let mut last = None;
        loop {
            let n = self.rig.transmit(&mut buf);
            if n == 0 {
                break;
            }
            for &b in &buf[..n] {
                if let Some(Ok(stuffed)) = reader.push(b) {
                    let (h, r) = receive_response(stuffed).unwrap();
                    if h.seq == self.seq {
                        last = Some(r);
                    }
                }
            }
        }
        last.expect("an answer")
    }

    fn status(&mut self) -> Status {
        match self.ask(Request::GetStatus) {
            Response::Status(s) => s,
            r => panic!("{r:?}"),
        }
    }

    /// A start at R = 1, through its 600 ms pre-run check.
    fn start(&mut self) -> Status {
        let r = self.ask(Request::SetDrive {
            r: 1 << 16,
            theta_d_deg: 0,
        });
        assert_eq!(r, Response::Ok);
        self.run_ms(650);
        self.status()
    }
}

const NFAULT: Fault = Fault::Bridge(BridgeLine::NFault);

#[test]
fn nfault_latches_at_the_tick_that_sees_it_and_clear_waits_for_it() {
    let mut l = Loop::new();
    let s = l.start();
    assert_eq!((s.mode, s.check), (Mode::Running, Some(Check::Passed)));
    l.run_ms(100);
    // nFAULT falls between ticks: the next tick latches it.
    l.hw.nfault_low = true;
    let before = l.ticks;
    l.tick();
    assert_eq!(l.ticks, before + 1);
    assert_eq!(l.status().mode, Mode::Faulted(NFAULT));
    assert!(
        !l.awake.last().unwrap(),
        "the bridge sleeps at the fault's tick"
    );
    // Still low: the clear is refused and changes nothing; nothing is re-armed.
    l.run_ms(10);
    assert_eq!(
        l.ask(Request::ClearFault),
        Response::Refused(Reason::BridgeFaultActive)
    );
    l.run_ms(10);
    assert_eq!(l.status().mode, Mode::Faulted(NFAULT));
    assert_eq!(l.hw.rearms, 0);
    assert!(l.hw.bif && !l.hw.moe);
    // High again: a break the loop saw stays until a clear (no silent re-arm while latched).
    l.hw.nfault_low = false;
    l.run_ms(10);
    assert_eq!((l.hw.rearms, l.hw.moe), (0, false));
    // The clear is taken and the next tick re-arms: BIF cleared, MOE set.
    assert_eq!(l.ask(Request::ClearFault), Response::Ok);
    l.tick();
    assert_eq!(l.hw.rearms, 1);
    assert!(!l.hw.bif && l.hw.moe);
    assert_eq!(l.status().mode, Mode::Idle);
    // And the drive runs again.
    let s = l.start();
    assert_eq!((s.mode, s.check), (Mode::Running, Some(Check::Passed)));
}

#[test]
fn a_break_between_ticks_is_a_fault_of_its_own() {
    let mut l = Loop::new();
    l.start();
    l.run_ms(50);
    // The bridge faulted and recovered between two ticks (its over-current retry): BIF set,
    // MOE cleared, nFAULT high again.
    l.hw.bif = true;
    l.hw.moe = false;
    l.tick();
    assert_eq!(
        l.status().mode,
        Mode::Faulted(Fault::Bridge(BridgeLine::Break))
    );
    assert_eq!(l.ask(Request::ClearFault), Response::Ok);
    l.tick();
    assert!(l.hw.moe && !l.hw.bif);
}

#[test]
fn nfault_is_ignored_asleep_and_while_waking() {
    let mut l = Loop::new();
    // Asleep (idle): nFAULT low for a second is no fault; the break it caused is undone once
    // nFAULT reads high, so the drive is not left dead.
    l.hw.nfault_low = true;
    l.run_ms(1000);
    assert_eq!(l.status().mode, Mode::Idle);
    assert!(l.hw.bif && !l.hw.moe);
    l.hw.nfault_low = false;
    l.tick();
    assert!(!l.hw.bif && l.hw.moe);
    // The pre-run check wakes the bridge after its 100 ms rest. nFAULT low through the
    // wake-up (WAKE_IGNORE_US = 2 ms: the first two ticks awake) is ignored; the break it
    // caused is undone once it rises; the check passes.
    assert_eq!(WAKE_IGNORE_US, 2_000);
    assert_eq!(
        l.ask(Request::SetDrive {
            r: 1 << 16,
            theta_d_deg: 0
        }),
        Response::Ok
    );
    while !l.awake.last().copied().unwrap_or(false) {
        l.tick();
    }
    // The tick that woke it is 0 µs into the wake-up, the next 1 000 µs.
    l.hw.nfault_low = true;
    l.tick();
    assert_eq!(l.status().mode, Mode::Checking);
    l.hw.nfault_low = false;
    l.tick();
    assert!(l.hw.moe);
    l.run_ms(600);
    let s = l.status();
    assert_eq!((s.mode, s.check), (Mode::Running, Some(Check::Passed)));
    // Woken and past 2 ms, the same line is a fault at once.
    l.hw.nfault_low = true;
    l.tick();
    assert_eq!(l.status().mode, Mode::Faulted(NFAULT));
}

#[test]
fn nfault_low_past_the_wake_up_aborts_the_check() {
    let mut l = Loop::new();
    assert_eq!(
        l.ask(Request::SetDrive {
            r: 1 << 16,
            theta_d_deg: 0
        }),
        Response::Ok
    );
    while !l.awake.last().copied().unwrap_or(false) {
        l.tick();
    }
    // No supply: nFAULT stays low after the wake-up. Ticks at 1, 2 ms into it: the second is
    // the first one listened to.
    l.hw.nfault_low = true;
    l.tick();
    assert_eq!(l.status().mode, Mode::Checking);
    l.tick();
    let s = l.status();
    assert_eq!(s.mode, Mode::Faulted(NFAULT));
    l.tick();
    assert_eq!(
        l.status().check,
        Some(Check::Failed(kapitza_core::link::message::Verdict::Aborted))
    );
}

// ---- against the simulated rig

/// Keeps the link alive (the reference link timeout is 1 s) while `secs` of rig time pass.
fn run_heard(b: &mut Bench, secs: f64) {
    let n = (secs / 0.1).round() as usize;
    for _ in 0..n {
        b.run(0.1);
        b.status();
    }
}

/// The last telemetry's measured crank speed and drive reference (rad/s).
fn crank_speed(b: &Bench) -> (f64, f64) {
    b.streamed
        .iter()
        .rev()
        .find_map(|r| match r {
            Response::Telemetry(t) => Some((
                f64::from(t.crank_speed) / 65_536.0,
                f64::from(t.omega) / 65_536.0,
            )),
            _ => None,
        })
        .expect("telemetry")
}

#[test]
fn press_estop_release_clear_run() {
    let mut b = Bench::healthy(Params::DEMO);
    let s = b.start();
    assert_eq!((s.mode, s.check), (Mode::Running, Some(Check::Passed)));
    run_heard(&mut b, 1.0);
    // Pressed while running: the relay cuts VM, the awake bridge's nFAULT falls, TIM1's break
    // cuts the outputs; the e-stop line (3 ms debounce) names the fault.
    b.sim.estop = true;
    b.run(0.05);
    let s = b.status();
    assert_eq!((s.mode, s.estop), (Mode::Faulted(Fault::EStop), true));
    assert!(b.sim.bridge.break_flag(), "the break tripped");
    // Released: VM is back, the bridge asleep, but the break holds the outputs off; the
    // release needs 50 ms of agreement before the clear is taken.
    b.sim.estop = false;
    b.run(0.1);
    assert!(b.sim.bridge.break_flag() && !b.sim.bridge.driving());
    assert_eq!(b.ask(Request::ClearFault), Response::Ok);
    b.run(0.01);
    assert!(!b.sim.bridge.break_flag(), "ClearFault re-armed TIM1");
    assert_eq!(b.status().mode, Mode::Idle);
    // Run: the pre-run check's pulse turns the crank and the drive ramps up.
    let s = b.start();
    assert_eq!((s.mode, s.check), (Mode::Running, Some(Check::Passed)));
    assert_eq!(b.ask(Request::Telemetry { period_ms: 20 }), Response::Ok);
    run_heard(&mut b, 2.0);
    assert_eq!(b.status().mode, Mode::Running);
    // The crank follows the drive reference again (the phase lock holds it; 5 % covers its
    // transient while ω ramps), and the reference is under way.
    let (crank, reference) = crank_speed(&b);
    assert!(reference > 50.0, "{reference}");
    assert!(
        (crank - reference).abs() < 0.05 * reference,
        "{crank} vs {reference}"
    );
}

#[test]
fn a_supply_sag_below_uvlo_is_a_bridge_fault() {
    let mut b = Bench::healthy(Params::DEMO);
    b.start();
    run_heard(&mut b, 0.5);
    // 12 V sagging to 4 V under a stall: no e-stop, the bridge's own under-voltage lockout.
    b.sim.bridge.supply_v = 4.0;
    b.run(0.01);
    let s = b.status();
    assert_eq!((s.mode, s.estop), (Mode::Faulted(NFAULT), false));
    assert_eq!(
        s.reset.cause,
        kapitza_core::link::message::ResetCause::PowerOn
    );
    // Asleep, nFAULT is released: the clear is taken, but the next start's pulse wakes the
    // bridge on a supply still too low, and the check ends in the same fault.
    b.run(0.1);
    assert_eq!(b.ask(Request::ClearFault), Response::Ok);
    b.run(0.01);
    assert_eq!(
        b.ask(Request::SetDrive {
            r: 2 << 16,
            theta_d_deg: 0
        }),
        Response::Ok
    );
    b.run(0.5);
    let s = b.status();
    assert_eq!(s.mode, Mode::Faulted(NFAULT));
    assert_eq!(
        s.check,
        Some(Check::Failed(kapitza_core::link::message::Verdict::Aborted))
    );
    // The supply back: clear, run.
    b.sim.bridge.supply_v = 12.0;
    assert_eq!(b.ask(Request::ClearFault), Response::Ok);
    b.run(0.01);
    let s = b.start();
    assert_eq!((s.mode, s.check), (Mode::Running, Some(Check::Passed)));
}

// ---- the pendulum sensor after the start

#[test]
fn miso_stuck_low_mid_run_is_a_sensor_fault() {
    let mut b = Bench::healthy(Params::DEMO);
    let s = b.start();
    assert_eq!(s.mode, Mode::Running);
    // A healthy run of 5 s never trips it.
    run_heard(&mut b, 5.0);
    assert_eq!(b.status().mode, Mode::Running);
    // MISO stuck low: every frame 0x0000, which passes parity and the error flag as angle 0;
    // the next diagnostics read (every DIAG_EVERY = 1000 samples: 0.1 s at 10 kHz) reads
    // DIAAGC 0 — AGC 0, LF clear — and the next control tick latches the fault.
    b.sim.sensor().line = Line::CutPulledDown;
    let mut took = None;
    for ms in 1..=150 {
        b.sim.run(0.001);
        if matches!(
            b.sim.rig().server().rig.supervisor().mode(),
            kapitza_core::rig::safety::Mode::Faulted(_)
        ) {
            took = Some(ms);
            break;
        }
    }
    let ms = took.expect("a fault within 150 ms");
    assert!(ms <= 101, "{ms} ms");
    let s = b.status();
    assert_eq!(s.mode, Mode::Faulted(Fault::Sensor));
    // The frames passed as angles all along: no read failed.
    assert_eq!(s.counters.sensor_errors, 0);
}

#[test]
fn a_sensor_never_ready_refuses_the_start_but_idle_is_no_fault() {
    let mut b = Bench::healthy(Params::DEMO);
    b.sim.sensor().line = Line::CutPulledDown;
    run_heard(&mut b, 0.5);
    // Idle: not a fault (nothing moves); the pre-run check refuses the start.
    assert_eq!(b.status().mode, Mode::Idle);
    let s = b.start();
    assert_eq!(
        s.check,
        Some(Check::Failed(
            kapitza_core::link::message::Verdict::SensorNotReady
        ))
    );
    assert_eq!(s.mode, Mode::Idle);
}
