//! Stops that stop, and exit statuses that tell the truth, end to end over real
//! pseudo-terminals: `kapitza rig serve --truth FILE` in one process records every setting the
//! rig applied; `calibrate`, `set`, `attach`, `stop` in others are sent signals as a user's
//! Ctrl-C, `kill` or a closed terminal would. Every wait is on a condition (the truth file, a
//! process's end) with a generous deadline: these are not timed tests.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use kapitza_test_support::binary::{interrupt_then_kill, json, Binary};
use serde_json::Value;

const KAPITZA: Binary = Binary(env!("CARGO_BIN_EXE_kapitza"));
const BIN: &str = env!("CARGO_BIN_EXE_kapitza");

fn kapitza(args: &[&str]) -> Output {
    KAPITZA.run(args)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A running `kapitza` with both of its streams read as they come (a full pipe never blocks
/// it); its stdout line by line. Killed when dropped.
struct Proc {
    child: Child,
    out: Receiver<String>,
    err: Option<JoinHandle<String>>,
}

/// What a process printed and how it ended.
struct Ended {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

impl Proc {
    fn start(args: &[&str]) -> Self {
        let mut child = Command::new(BIN)
            .args(args)
            .env_remove("KAPITZA_PORT")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let stdout = BufReader::new(child.stdout.take().unwrap());
        let (tx, out) = mpsc::channel();
        std::thread::spawn(move || {
            for l in stdout.lines().map_while(Result::ok) {
                if tx.send(l).is_err() {
                    return;
                }
            }
        });
        let mut err = child.stderr.take().unwrap();
        let err = std::thread::spawn(move || {
            let mut s = String::new();
            let _ = err.read_to_string(&mut s);
            s
        });
        Self {
            child,
            out,
            err: Some(err),
        }
    }

    /// The next line of stdout (at most 60 s of wall time; a panic after that).
    fn first_line(&mut self) -> String {
        let l = self.out.recv_timeout(Duration::from_secs(60)).unwrap();
        l.trim().to_string()
    }

    fn signal(&self, sig: i32) {
        // SAFETY: kill(2) on our own child's pid.
        unsafe { libc::kill(self.child.id() as i32, sig) };
    }

    /// Waits for its end (at most `secs` of wall time; a panic after that).
    fn wait(mut self, secs: u64) -> Ended {
        let deadline = Instant::now() + Duration::from_secs(secs);
        let status = loop {
            if let Some(s) = self.child.try_wait().unwrap() {
                break s;
            }
            assert!(Instant::now() < deadline, "still running after {secs} s");
            std::thread::sleep(Duration::from_millis(10));
        };
        let stdout: String = self.out.iter().map(|l| l + "\n").collect();
        Ended {
            code: status.code(),
            stdout,
            stderr: self.err.take().unwrap().join().unwrap(),
        }
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        interrupt_then_kill(&mut self.child);
    }
}

/// A simulated rig at `speed` times real time whose truth log is `truth`; its device path.
fn serve(speed: &str, truth: &Path) -> (Proc, String) {
    let mut rig = Proc::start(&[
        "rig",
        "serve",
        "--speed",
        speed,
        "--truth",
        truth.to_str().unwrap(),
    ]);
    let port = rig.first_line();
    assert!(port.starts_with('/'), "device path: {port:?}");
    (rig, port)
}

/// The truth log's complete lines.
fn applied(truth: &Path) -> Vec<Value> {
    std::fs::read_to_string(truth)
        .unwrap_or_default()
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect()
}

/// Waits until the truth log's last line satisfies `cond` (at most `secs`).
fn await_truth(truth: &Path, secs: u64, what: &str, cond: impl Fn(&Value) -> bool) -> Value {
    let deadline = Instant::now() + Duration::from_secs(secs);
    loop {
        if let Some(last) = applied(truth).last() {
            if cond(last) {
                return last.clone();
            }
        }
        assert!(
            Instant::now() < deadline,
            "{what} not seen within {secs} s: {:?}",
            applied(truth).last()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// The drive is off: no target ω and not in bring-up mode.
fn stopped(v: &Value) -> bool {
    v["omega_target"].as_f64() == Some(0.0) && v["bring_up_duty"].is_null()
}

fn running_at(r: f64) -> impl Fn(&Value) -> bool {
    // R as the rig reports it: its Q16 ω target back through the configuration (1e-3).
    move |v| v["mode"] == "running" && (v["r_target"].as_f64().unwrap() - r).abs() < 1e-3
}

/// Bring-up mode at this duty: the Q15 duty the link carries (1/32768).
fn bring_up_at(duty: f64) -> impl Fn(&Value) -> bool {
    move |v| {
        v["bring_up_duty"]
            .as_f64()
            .is_some_and(|d| (d - duty).abs() < 1.0 / 32_768.0)
    }
}

fn config_get(port: &str) -> String {
    let o = kapitza(&["config", "get", "--port", port]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    String::from_utf8(o.stdout).unwrap()
}

fn calibrate(port: &str, step: &str, backup: &Path) -> Proc {
    Proc::start(&[
        "calibrate",
        "--port",
        port,
        "--yes",
        "--json",
        "--step",
        step,
        "--backup",
        backup.to_str().unwrap(),
    ])
}

/// A calibration step with its drive on, ended by `sig`: the drive stopped (the rig's own
/// record), the signal's exit status, the stop confirmed, nothing from the step stored.
fn interrupt_step(step: &str, speed: &str, on: impl Fn(&Value) -> bool, sig: i32, code: i32) {
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.jsonl");
    let (_rig, port) = serve(speed, &truth);
    let before = config_get(&port);
    let backup: PathBuf = dir.path().join("before.toml");
    let cal = calibrate(&port, step, &backup);
    let seen = await_truth(&truth, 60, &format!("the {step} step's drive"), on);
    let sent = Instant::now();
    cal.signal(sig);
    let end = cal.wait(30);
    let took = sent.elapsed();
    assert_eq!(
        end.code,
        Some(code),
        "{step}: {}\n{}",
        end.stderr,
        end.stdout
    );
    assert!(
        end.stderr.contains("the rig confirmed the stop")
            && end.stderr.contains("nothing from this step was written"),
        "{step}: {}",
        end.stderr
    );
    // Issue 23: stopped and confirmed in well under a second of wall time (one request, its
    // answer within the client's 300 ms); 2 s leaves room for a loaded machine.
    assert!(took < Duration::from_secs(2), "{step}: {took:?}");
    // The rig's record: stopped, after the drive was seen on.
    let last = await_truth(&truth, 10, "the stop", stopped);
    assert_eq!(
        config_get(&port),
        before,
        "{step}: the configuration changed"
    );
    // No JSON summary: the calibration did not finish.
    assert!(end.stdout.trim().is_empty(), "{step}: {}", end.stdout);
    eprintln!(
        "{step}: signal {sig} at rig t = {:.2} s ({}), exit {code} after {:.0} ms wall, \
         stopped at rig t = {:.2} s",
        seen["t_s"].as_f64().unwrap(),
        seen["mode"],
        took.as_secs_f64() * 1e3,
        last["t_s"].as_f64().unwrap()
    );
}

// The steps' drives (host/src/calibrate/steps.rs): the ring-downs and the servo's rest in
// bring-up mode with the motor off (duty 0), the crank's pulse at duty 0.15 for 0.3 rig seconds
// (the rig slowed to 0.2× so it lasts 1.5 s of wall time), the stroke at R = 0.5. Statuses:
// 128 + the signal's number (SIGHUP 1, SIGINT 2, SIGTERM 15).

#[test]
fn sigint_in_the_sensor_step_stops_the_ring_down() {
    interrupt_step("sensor", "5", bring_up_at(0.0), libc::SIGINT, 130);
}

#[test]
fn sigterm_in_the_crank_step_stops_the_pulse() {
    interrupt_step("crank", "0.2", bring_up_at(0.15), libc::SIGTERM, 143);
}

#[test]
fn sigint_in_the_servo_step_leaves_bring_up() {
    interrupt_step("servo", "0.5", bring_up_at(0.0), libc::SIGINT, 130);
}

#[test]
fn sigterm_in_the_ringdown_step_stops_the_ring_down() {
    interrupt_step("ringdown", "5", bring_up_at(0.0), libc::SIGTERM, 143);
}

#[test]
fn sigint_in_the_stroke_step_stops_the_drive() {
    interrupt_step("stroke", "5", running_at(0.5), libc::SIGINT, 130);
}

#[test]
fn sigterm_and_sighup_in_the_stroke_step_stop_the_drive() {
    interrupt_step("stroke", "5", running_at(0.5), libc::SIGTERM, 143);
    interrupt_step("stroke", "5", running_at(0.5), libc::SIGHUP, 129);
}

#[test]
fn calibrate_owns_the_port_stop_and_status_work_set_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.jsonl");
    let (_rig, port) = serve("5", &truth);
    let before = config_get(&port);
    let cal = calibrate(&port, "stroke", &dir.path().join("before.toml"));
    await_truth(&truth, 60, "the stroke's drive", running_at(0.5));

    let o = kapitza(&["status", "--port", &port, "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(json(&o)["mode"], "running");
    for (args, what) in [
        (
            vec!["set", "--port", &port, "--r", "1", "--angle", "90"],
            "set",
        ),
        (
            vec![
                "config",
                "set",
                "--port",
                &port,
                concat!(env!("CARGO_MANIFEST_DIR"), "/../rigs/demo.toml"),
            ],
            "config set",
        ),
    ] {
        let o = kapitza(&args);
        assert_eq!(o.status.code(), Some(1), "{what}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("calibration in progress"),
            "{what}: {}",
            stderr(&o)
        );
    }
    // Still the calibration's drive: nothing above changed it.
    assert!(running_at(0.5)(applied(&truth).last().unwrap()));

    let o = kapitza(&["stop", "--port", &port]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let end = cal.wait(30);
    assert_eq!(end.code, Some(1), "{}", end.stderr);
    assert!(
        end.stderr.contains("stopped from elsewhere")
            && end.stderr.contains("nothing from this step was written"),
        "{}",
        end.stderr
    );
    await_truth(&truth, 10, "the stop", stopped);
    assert_eq!(config_get(&port), before);
}

#[test]
fn through_an_owner_a_signal_and_a_stop_reach_the_rig() {
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.jsonl");
    let (_rig, port) = serve("5", &truth);
    let mut owner = Proc::start(&["attach", "--port", &port]);
    assert!(owner.first_line().starts_with("attached"));
    let before = config_get(&port);

    // A signal: the stop goes through the owner.
    let cal = calibrate(&port, "stroke", &dir.path().join("a.toml"));
    await_truth(&truth, 60, "the stroke's drive", running_at(0.5));
    cal.signal(libc::SIGTERM);
    let end = cal.wait(30);
    assert_eq!(end.code, Some(143), "{}", end.stderr);
    await_truth(&truth, 10, "the stop", stopped);

    // A stop sent to the owner (as the monitor's s does): the calibration sees its drive end.
    let cal = calibrate(&port, "stroke", &dir.path().join("b.toml"));
    await_truth(&truth, 60, "the stroke's drive", running_at(0.5));
    let o = kapitza(&["stop", "--port", &port]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let end = cal.wait(30);
    assert_eq!(end.code, Some(1), "{}", end.stderr);
    assert!(
        end.stderr.contains("stopped from elsewhere"),
        "{}",
        end.stderr
    );
    await_truth(&truth, 10, "the stop", stopped);
    assert_eq!(config_get(&port), before);

    // The owner's own end: SIGTERM, the stop confirmed, exit 0.
    owner.signal(libc::SIGTERM);
    let end = owner.wait(10);
    assert_eq!(end.code, Some(0), "{}", end.stderr);
    assert!(
        end.stdout.contains("detached; the rig confirmed the stop"),
        "{}",
        end.stdout
    );
}

#[test]
fn a_superseded_wait_exits_5_naming_the_new_target() {
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.jsonl");
    // A quarter of real time: the drive ramps and settles for tens of seconds of wall time, so
    // the second command comes first however loaded the machine.
    let (_rig, port) = serve("0.25", &truth);
    let mut owner = Proc::start(&["attach", "--port", &port]);
    assert!(owner.first_line().starts_with("attached"));
    let wait = Proc::start(&[
        "set", "--port", &port, "--r", "1.75", "--angle", "90", "--wait",
    ]);
    await_truth(&truth, 30, "the first target", running_at(1.75));
    let o = kapitza(&["set", "--port", &port, "--r", "1.2", "--angle", "60"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let end = wait.wait(30);
    assert_eq!(end.code, Some(5), "{}\n{}", end.stderr, end.stdout);
    assert!(
        end.stderr
            .contains("superseded by another command's R = 1.200 at θd = 60.0°"),
        "{}",
        end.stderr
    );
    assert!(!end.stdout.contains("settled"), "{}", end.stdout);
}

#[test]
fn an_interrupted_wait_stops_the_drive_and_exits_130() {
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.jsonl");
    let (_rig, port) = serve("1", &truth);
    let wait = Proc::start(&[
        "set", "--port", &port, "--r", "1.75", "--angle", "90", "--wait",
    ]);
    await_truth(&truth, 30, "the target", running_at(1.75));
    wait.signal(libc::SIGINT);
    let end = wait.wait(30);
    assert_eq!(end.code, Some(130), "{}\n{}", end.stderr, end.stdout);
    assert!(
        end.stderr.contains("the rig confirmed the stop"),
        "{}",
        end.stderr
    );
    await_truth(&truth, 10, "the stop", stopped);
}

#[test]
fn rig_serve_on_sigterm_and_sighup_removes_its_link_and_prints_its_summary() {
    for sig in [libc::SIGTERM, libc::SIGHUP] {
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("rig");
        let mut rig = Proc::start(&[
            "rig",
            "serve",
            "--speed",
            "20",
            "--link",
            link.to_str().unwrap(),
        ]);
        assert!(rig.first_line().starts_with('/'));
        assert!(std::fs::symlink_metadata(&link).is_ok());
        rig.signal(sig);
        let end = rig.wait(10);
        assert_eq!(end.code, Some(0), "signal {sig}: {}", end.stderr);
        assert!(
            std::fs::symlink_metadata(&link).is_err(),
            "signal {sig}: the link is still there"
        );
        assert!(
            end.stderr.contains("rig serve:") && end.stderr.contains("rig seconds"),
            "signal {sig}: {}",
            end.stderr
        );
    }
}

#[test]
fn the_monitor_on_sigterm_stops_the_drive_and_exits_0() {
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.jsonl");
    let (_rig, port) = serve("20", &truth);
    let mut monitor = Proc::start(&["monitor", "--port", &port, "--plain"]);
    // A record line: the monitor owns the port and streams.
    assert!(monitor.first_line().starts_with('{'));
    let o = kapitza(&["set", "--port", &port, "--r", "1.2", "--angle", "90"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    await_truth(&truth, 30, "the target", running_at(1.2));
    monitor.signal(libc::SIGTERM);
    let end = monitor.wait(10);
    assert_eq!(end.code, Some(0), "{}", end.stderr);
    assert!(
        end.stderr.contains("the rig confirmed the stop"),
        "{}",
        end.stderr
    );
    await_truth(&truth, 10, "the stop", stopped);
}

/// Whether `pid` catches `sig` (Linux: the SigCgt mask in /proc): its handlers are installed.
fn catches(pid: u32, sig: i32) -> bool {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("SigCgt:"))
        .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
        .is_some_and(|m| m & (1 << (sig - 1)) != 0)
}

#[test]
fn a_model_command_ends_at_once_with_the_signals_status() {
    // 10⁷ drive periods of the full model: about a minute of work (10⁵ take 0.7 s), never
    // finished here.
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/horizontal-r1.75.toml"
    );
    for (sig, code) in [
        (libc::SIGINT, 130),
        (libc::SIGTERM, 143),
        (libc::SIGHUP, 129),
    ] {
        let p = Proc::start(&["simulate", scene, "--set", "run.periods=10000000", "--json"]);
        let deadline = Instant::now() + Duration::from_secs(30);
        while !catches(p.child.id(), sig) {
            assert!(Instant::now() < deadline, "no handler for {sig}");
            std::thread::sleep(Duration::from_millis(5));
        }
        p.signal(sig);
        let end = p.wait(10);
        assert_eq!(end.code, Some(code), "signal {sig}: {}", end.stderr);
        assert!(!end.stdout.contains("outcome"), "{}", end.stdout);
    }
}
