//! The monitor: the dashboard's snapshots (TestBackend), its keys as a state machine, the
//! plain JSON records and the CSV log from the simulated rig, a rig of another protocol, and
//! the demo's script on the simulated demo rod. (A lost and regained line is the port owner's,
//! tested end to end in `rig_e2e.rs`.)
//!
//! Snapshots are text fixtures in `tests/fixtures/`; after a deliberate change to the
//! dashboard, regenerate them with `KAPITZA_BLESS=1 cargo test -p kapitza --test monitor` and
//! review the diff.

use kapitza::monitor::draw::draw;
use kapitza::monitor::{Command, Event, Key, State};
use kapitza_core::link::convert::to_q16;
use kapitza_core::link::message::{Counters, Fault, Mode, RMethod, StopReason, Turns};
use kapitza_core::link::{Status, Telemetry};
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::simrig::Params;
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use serde_json::Value;

fn turns(deg: f64) -> Turns {
    (deg / 360.0 * 4_294_967_296.0).round() as i64 as u32 as i32
}

fn status(mode: Mode, omega_target: f64, theta_d_target: f64, commands: u32) -> Status {
    Status {
        mode,
        last_stop: None,
        estop: false,
        omega: to_q16(omega_target),
        omega_target: to_q16(omega_target),
        theta_d_deg: to_q16(theta_d_target),
        theta_d_target_deg: to_q16(theta_d_target),
        config: ConfigOrigin::Stored,
        uptime_ms: 0,
        counters: Counters {
            commands,
            ..Counters::default()
        },
        reset: kapitza_core::link::message::ResetInfo::POWER_ON,
        check: None,
        bring_up: None,
    }
}

/// A settled frame at φ = `phi_deg` under ω, θd.
fn frame(t_s: f64, phi_deg: f64, omega: f64, theta_d: f64, commands: u32) -> Telemetry {
    Telemetry {
        t_us: (t_s * 1e6) as u32,
        mode: Mode::Running,
        theta: turns(phi_deg + 3.0),
        phi: turns(phi_deg),
        phi_rate: 0,
        omega_p: Some(to_q16(6.13)),
        sigma: Some(to_q16(0.15)),
        settled: t_s >= 20.0,
        equilibrium: (t_s >= 20.0).then(|| turns(phi_deg)),
        r: (t_s >= 20.0).then(|| (to_q16(1.752), RMethod::EquilibriumAngle)),
        periods: 1000,
        omega: to_q16(omega),
        crank_speed: to_q16(omega - 0.2),
        phase_error: 0,
        duty: 0,
        current: 0,
        theta_d_deg: to_q16(theta_d),
        steady: true,
        commands,
        wobble: 0,
    }
}

/// The demo rod running at R = 1.75, θd = 90°, the slow angle decaying onto φ0 over 30 s.
fn running_state() -> State {
    let cfg = Params::DEMO.configured();
    let omega = cfg.omega_for_r(1.75).unwrap();
    let mut s = State::new();
    s.on_event(Event::Linked {
        protocol: 2,
        firmware: [0, 1, 0],
        config: Box::new(cfg),
    });
    s.on_event(Event::Status(status(Mode::Running, omega, 90.0, 1)));
    for k in 0..=300 {
        let t = f64::from(k) * 0.1;
        let phi = 55.15 + 20.0 * (-0.15 * t).exp() * (6.1 * t).cos();
        s.on_event(Event::Telemetry(frame(t, phi, omega, 90.0, 1)));
    }
    s
}

/// The screen's text, one line per row, trailing blanks trimmed.
fn screen(state: &State, w: u16, h: u16) -> String {
    let mut term = Terminal::new(TestBackend::new(w, h)).unwrap();
    term.draw(|f| draw(f, state)).unwrap();
    let buf = term.backend().buffer();
    (0..h)
        .map(|y| {
            let row: String = (0..w).map(|x| buf[(x, y)].symbol()).collect();
            row.trim_end().to_string() + "\n"
        })
        .collect()
}

/// Compares with the fixture, or writes it with `KAPITZA_BLESS=1`.
fn snapshot(name: &str, text: &str) {
    let path = format!("{}/tests/fixtures/{name}.txt", env!("CARGO_MANIFEST_DIR"));
    if std::env::var_os("KAPITZA_BLESS").is_some() {
        std::fs::write(&path, text).unwrap();
    }
    let want = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        want == text,
        "{name}: the dashboard changed (KAPITZA_BLESS=1 to accept):\n{text}"
    );
}

#[test]
fn dashboard_running_snapshot() {
    let s = running_state();
    let text = screen(&s, 100, 32);
    snapshot("monitor_running", &text);
    // What the snapshot must show, whatever the layout: predicted φ0 = arccos(1/1.75) =
    // 55.15° (physics §3), the settled flag, and the stop key.
    assert!(text.contains("55.15"), "{text}");
    assert!(text.contains("settled"), "{text}");
    assert!(text.contains("STOP the drive"), "{text}");
}

#[test]
fn dashboard_faulted_link_lost_snapshot() {
    let mut s = running_state();
    s.on_event(Event::Status(status(
        Mode::Faulted(Fault::Stall),
        0.0,
        90.0,
        1,
    )));
    s.on_event(Event::LinkLost("serial line: broken pipe".into()));
    let text = screen(&s, 100, 32);
    snapshot("monitor_faulted_lost", &text);
    assert!(text.contains("LOST"), "{text}");
    assert!(text.contains("stall"), "{text}");
    assert!(text.contains("STOP the drive"), "{text}");
    // A screen too small for the panels still shows the stop key on its last line.
    let small = screen(&s, 60, 12);
    assert!(small.lines().last().unwrap().contains("STOP"), "{small}");
}

#[test]
fn keys_as_a_state_machine() {
    let mut s = State::new();
    // Nothing heard yet: stop is still sent (the rig accepts it in every mode), a clear is not.
    assert_eq!(s.on_key(Key::Char('s')), Some(Command::Stop));
    assert_eq!(s.on_key(Key::Char('c')), None);
    assert!(s.log.back().unwrap().1.contains("no fault"));
    // Idle and running: the same.
    s.on_event(Event::Status(status(Mode::Idle, 0.0, 0.0, 0)));
    assert_eq!(s.on_key(Key::Char(' ')), Some(Command::Stop));
    assert_eq!(s.on_key(Key::Char('c')), None);
    s.on_event(Event::Status(status(Mode::Running, 188.0, 90.0, 1)));
    assert_eq!(s.on_key(Key::Char('c')), None);
    // Stopping because of a fault is not yet faulted: nothing to clear.
    let stopping = Mode::Stopping(StopReason::Fault(Fault::OverCurrent));
    s.on_event(Event::Status(status(stopping, 0.0, 90.0, 1)));
    assert_eq!(s.on_key(Key::Char('c')), None);
    // Faulted: c clears, s still stops; unknown keys do nothing.
    s.on_event(Event::Status(status(
        Mode::Faulted(Fault::OverCurrent),
        0.0,
        90.0,
        1,
    )));
    assert_eq!(s.on_key(Key::Char('c')), Some(Command::ClearFault));
    assert_eq!(s.on_key(Key::Char('s')), Some(Command::Stop));
    assert_eq!(s.on_key(Key::Char('x')), None);
    assert!(!s.quit);
    // A frame saying the fault is gone: c is refused again.
    s.on_event(Event::Status(status(Mode::Idle, 0.0, 90.0, 2)));
    assert_eq!(s.on_key(Key::Char('c')), None);
    // The link lost: keys still work (the feed answers that the link is down).
    s.on_event(Event::LinkLost("gone".into()));
    assert_eq!(s.on_key(Key::Char('s')), Some(Command::Stop));
    // Each way out quits without sending anything.
    for k in [Key::Char('q'), Key::Esc, Key::CtrlC] {
        let mut s = State::new();
        assert_eq!(s.on_key(k), None);
        assert!(s.quit);
    }
}

/// The `--plain` and `--csv` contract: the keys `kapitza status --json` shares.
const CONTRACT: [&str; 13] = [
    "mode",
    "fault",
    "r_target",
    "omega",
    "omega_target",
    "drive_angle_deg",
    "drive_angle_target_deg",
    "slow_angle_deg",
    "omega_p",
    "r_estimate",
    "settled",
    "commands",
    "t_s",
];

#[test]
fn plain_records_and_csv() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("frames.csv");
    let mut out = Vec::new();
    kapitza::run(
        [
            "kapitza",
            "monitor",
            "--port",
            "sim",
            "--speed",
            "0",
            "--plain",
            "--duration",
            "2",
            "--csv",
            csv.to_str().unwrap(),
        ],
        &mut out,
    )
    .unwrap();
    let text = String::from_utf8(out).unwrap();
    let records: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    // 2 s of rig time at one frame per 20 ms (the telemetry period the feed asks for) is
    // about 100 frames.
    assert!((95..=105).contains(&records.len()), "{}", records.len());
    for r in &records {
        for k in CONTRACT {
            assert!(r.get(k).is_some(), "{k} missing from {r}");
        }
        // The demo rod at rest: idle, hanging (within the 0.02° sensor noise and its 14-bit
        // step of 0.022°, Params::DEMO), no fault, nothing requested.
        assert_eq!(r["mode"], "idle");
        assert!(r["fault"].is_null());
        assert!(r["theta_deg"].as_f64().unwrap().abs() < 0.2, "{r}");
        assert_eq!(r["commands"], 0);
    }
    // Rig time advances one telemetry period per frame.
    let t: Vec<f64> = records.iter().map(|r| r["t_s"].as_f64().unwrap()).collect();
    assert!(
        t.windows(2).all(|w| (w[1] - w[0] - 0.02).abs() < 1e-3),
        "{t:?}"
    );
    // The CSV: a header of the same names, and one row per frame.
    let csv = std::fs::read_to_string(&csv).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keys: Vec<&String> = records[0].as_object().unwrap().keys().collect();
    assert_eq!(header.len(), keys.len());
    for k in keys {
        assert!(header.contains(&k.as_str()), "{k} not in the CSV header");
    }
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), records.len());
    assert!(rows.iter().all(|r| r.split(',').count() == header.len()));
}

#[test]
fn demo_settles_where_the_model_says() {
    let mut out = Vec::new();
    kapitza::run(["kapitza", "demo", "--speed", "0", "--json"], &mut out).unwrap();
    let v: Value = serde_json::from_slice(&out).unwrap();
    let steps = v["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 4, "{v}");
    // Independent references (physics §3): R = 1.75 at θd = 90° settles at arccos(1/1.75) =
    // 55.15°; at θd = 180° with R > 1 the rod stands inverted, φ0 = 180°. The rest step hangs
    // at 0°.
    let want = [0.0, (1.0f64 / 1.75).acos().to_degrees(), 180.0, 180.0];
    for (s, want) in steps.iter().zip(want) {
        println!(
            "R = {} at θd = {}°: settled after {} s, {}",
            s["r"], s["drive_angle_deg"], s["settle_s"], s["measured"]
        );
        assert_eq!(s["settled"], true, "{s}");
        let pred = s["predicted"]["phi0_deg"].as_f64().unwrap();
        assert!((pred.abs() - want).abs() < 1e-6, "{s}");
        let meas = s["measured"]["phi0_deg"].as_f64().unwrap();
        // Measured within 0.5° of predicted (the demo's acceptance bound; the averaged theory
        // itself differs from the full motion by O((A/ℓ)², (ω0/ω)²) ≈ 0.4 % here).
        let d = (meas - pred + 180.0).rem_euclid(360.0) - 180.0;
        assert!(d.abs() < 0.5, "φ0 {meas} against {pred}: {s}");
    }
    for s in &steps[1..3] {
        // R in situ within 2 % of R requested (the demo's acceptance bound), and ωp within 2 %
        // of ω0 √(cos φ0 + R cos 2(φ0 − θd)) (physics §3).
        let r = s["r"].as_f64().unwrap();
        let est = s["measured"]["r"].as_f64().expect("R in situ");
        assert!((est / r - 1.0).abs() < 0.02, "R {est} against {r}: {s}");
        let wp = s["measured"]["omega_p"].as_f64().expect("ωp");
        let pred = s["predicted"]["omega_p"].as_f64().unwrap();
        assert!(
            (wp / pred - 1.0).abs() < 0.02,
            "ωp {wp} against {pred}: {s}"
        );
    }
    // Lowered gently from R = 2.2 to 1.75 at θd = 180°, the rod stays at the top without a slow
    // swing; there R comes only from ωp (the equilibrium formula is 0/0, physics §7), so the rig
    // has neither to report.
    assert!(steps[3]["measured"]["omega_p"].is_null(), "{}", steps[3]);
    assert!(steps[3]["measured"]["r"].is_null(), "{}", steps[3]);
}

#[test]
fn a_rig_of_another_protocol_is_named_not_monitored() {
    use kapitza::rig::file::RigFile;
    use kapitza::rig::port::Target;
    use kapitza::rig::simhost::SimOptions;
    use kapitza_core::link::PROTOCOL_VERSION;
    let mut sim = SimOptions::new(RigFile::demo(), f64::INFINITY);
    sim.protocol = Some(PROTOCOL_VERSION + 1);
    let why = match kapitza::cmd::monitor::open_feed(&Target::Sim, &sim) {
        Ok(_) => panic!("linked to a v+1 rig"),
        Err(e) => format!("{e:#}"),
    };
    // Both versions and the fix, named.
    assert!(
        why.contains(&format!("v{}", PROTOCOL_VERSION + 1))
            && why.contains(&format!("v{PROTOCOL_VERSION}")),
        "{why}"
    );
    assert!(why.contains("flash the firmware"), "{why}");
}

/// Feeds `frames` (with the demo rod's configuration) to the script; returns the commands it
/// sent, each answered `Ok`.
fn drive_script(
    script: &mut kapitza::demo::Script,
    s: &mut State,
    frames: &[Telemetry],
) -> Vec<Command> {
    use kapitza::monitor::Driver;
    let mut sent = Vec::new();
    for f in frames {
        s.on_event(Event::Telemetry(*f));
        if let Some(c) = script.next(s) {
            script.sent(s, c, &Ok(()));
            sent.push(c);
        }
    }
    sent
}

#[test]
fn demo_script_waits_for_frames_after_its_command() {
    use kapitza::demo::Script;
    let cfg = Params::DEMO.configured();
    let mut s = State::new();
    s.on_event(Event::Linked {
        protocol: 2,
        firmware: [0, 1, 0],
        config: Box::new(cfg),
    });
    let mut script = Script::new();
    let rest = |t: f64| Telemetry {
        mode: Mode::Idle,
        steady: false,
        ..frame(t, 0.0, 0.0, 0.0, 0)
    };
    // 3 s at rest, then the first step.
    let frames: Vec<Telemetry> = (0..=151).map(|k| rest(f64::from(k) * 0.02)).collect();
    let sent = drive_script(&mut script, &mut s, &frames);
    assert_eq!(
        sent,
        [Command::SetDrive {
            r: 1.75,
            theta_d_deg: 90.0
        }]
    );
    assert_eq!(script.outcomes.len(), 1);
    // Settled frames still carrying the old command count (taken before the command arrived)
    // never end the step, however many.
    let omega = cfg.omega_for_r(1.75).unwrap();
    let stale: Vec<Telemetry> = (0..100)
        .map(|k| frame(30.0 + f64::from(k) * 0.02, 55.2, omega, 90.0, 0))
        .collect();
    assert!(drive_script(&mut script, &mut s, &stale).is_empty());
    assert_eq!(script.outcomes.len(), 1);
    // Frames after the command: the first starts the clock, a settled one ends the step.
    let fresh: Vec<Telemetry> = (0..3)
        .map(|k| frame(40.0 + f64::from(k) * 0.02, 55.2, omega, 90.0, 1))
        .collect();
    let sent = drive_script(&mut script, &mut s, &fresh);
    assert_eq!(
        sent,
        [Command::SetDrive {
            r: 2.2,
            theta_d_deg: 180.0
        }]
    );
    let o = &script.outcomes[1];
    assert!(o.settled && o.measured.phi0_deg.is_some());
    // Settled on the second fresh frame: one telemetry period (20 ms) after the first.
    assert!((o.settle_s.unwrap() - 0.02).abs() < 1e-6, "{o:?}");
    // The drive stopped under the script (the stop key, a fault): the demo ends, saying why.
    let stopped = Telemetry {
        mode: Mode::Stopping(StopReason::Requested),
        ..frame(41.0, 60.0, omega, 120.0, 3)
    };
    assert!(drive_script(&mut script, &mut s, &[stopped]).is_empty());
    assert!(script.aborted.is_some());
    assert!(!script.outcomes[2].settled);
}

#[test]
fn dashboard_fits_80_by_24() {
    // A running rod settled at 55.15° (the predicted φ0 = arccos(1/1.75), physics §3), with
    // the other stable one (−55.15°), ωp measured 6.130 against ω0 √(R − 1/R) = 8.329
    // (physics §3, θd = 90°), and a long event line from the demo.
    let mut s = running_state();
    s.note("R = 1.75 at θd = 90°: settled after 12.3 s");
    s.note("  φ0 55.20° (model 55.15°), ωp 5.800 (5.813), R 1.752 — and a tail that must wrap");
    let text = screen(&s, 80, 24);
    snapshot("monitor_80x24", &text);
    // Every number a lecturer reads, whole: both panels' values, the prediction, the other
    // stable equilibrium, the settled flag, the event's tail and the keys.
    for want in [
        "R",
        "1.750",
        "188.",
        "90.0",
        "55.15°",
        "-55.15°",
        "6.130",
        "8.329",
        "1.752",
        "settled",
        "must wrap",
        "STOP the drive",
        "clear fault",
        "quit",
    ] {
        assert!(
            text.contains(want),
            "{want} cut from the 80×24 screen:\n{text}"
        );
    }
    // The keys on the last row, the title on the first.
    assert!(text.lines().last().unwrap().contains("STOP"), "{text}");
    assert!(
        text.lines().next().unwrap().contains("mode: running"),
        "{text}"
    );
}

#[test]
fn idle_shows_the_live_angle_not_a_stale_one_nor_drive_changing() {
    // The rig's last slow angle from a run (179.998°, an inverted rod that has since fallen)
    // in an idle frame hanging at 0.0°.
    let mut s = running_state();
    s.on_event(Event::Status(status(Mode::Idle, 0.0, 90.0, 2)));
    let idle = Telemetry {
        mode: Mode::Idle,
        theta: turns(0.0),
        phi: turns(179.998),
        steady: false,
        ..frame(40.0, 179.998, 0.0, 90.0, 2)
    };
    s.on_event(Event::Telemetry(idle));
    let r = s.readings().unwrap();
    assert_eq!(r.slow_angle_deg, None);
    assert_eq!(
        (r.omega_p, r.r_estimate, r.equilibrium_deg),
        (None, None, None)
    );
    assert!(!r.settled);
    let text = screen(&s, 80, 24);
    assert!(!text.contains("drive changing"), "{text}");
    assert!(text.contains("drive idle"), "{text}");
    assert!(
        !text.contains("179.998") && !text.contains("180.00"),
        "{text}"
    );
    // --plain's record: null, not the stale value.
    let v = serde_json::to_value(&r).unwrap();
    assert!(v["slow_angle_deg"].is_null(), "{v}");
}
