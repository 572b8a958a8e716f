//! End to end over real pseudo-terminals, as a user would type it: `kapitza rig serve` in one
//! process, `set`, `status`, `attach` in others. Simulated time runs fast (`--speed 20`), and the
//! deadlines are generous: these are not timed tests.

use std::io::{Read, Write};
use std::process::Output;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use kapitza_core::math;
use kapitza_core::model::slider_crank::{equilibrium_near, SliderCrank};
use kapitza_test_support::binary::{json, Binary, Running};
use serde_json::Value;
use serialport::SerialPort;

const KAPITZA: Binary = Binary(env!("CARGO_BIN_EXE_kapitza"));

fn kapitza(args: &[&str]) -> Output {
    KAPITZA.run(args)
}

fn start(args: &[&str]) -> Running {
    KAPITZA.start(args)
}

/// A simulated rig at 20 times real time.
fn serve(extra: &[&str]) -> Running {
    KAPITZA.serve("20", extra)
}

/// The full equation's period-mean rest angle (degrees) for the demo rod at ω, θd = 90°, from
/// `kapitza simulate` (DOP853, 3000 drive periods, started at `start_deg`, near the
/// equilibrium), with a slider-crank of `rod` (m) if given.
fn full_model_rest_deg(omega: f64, rod: Option<f64>, start_deg: f64) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("rod.toml");
    std::fs::write(
        &scene,
        format!(
            "[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\n\
             omega = {omega}\nangle_deg = 90.0\n[initial]\nangle_deg = {start_deg}\n[run]\n\
             periods = 3000\nfidelity = \"full\"\n[effects]\nviscous = {{ q = 10.0 }}\n{}",
            rod.map_or(String::new(), |b| format!(
                "slider_crank = {{ rod_length = {b} }}\n"
            ))
        ),
    )
    .unwrap();
    let o = kapitza(&["simulate", scene.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = json(&o);
    assert_eq!(v["outcome"]["kind"], "rest", "{v}");
    v["outcome"]["angle_deg"].as_f64().unwrap()
}

#[test]
fn settles_where_the_model_says() {
    let rig = serve(&[]);
    let port = rig.first_line.as_str();
    let o = kapitza(&[
        "set",
        "--port",
        port,
        "--r",
        "1.75",
        "--angle",
        "90",
        "--wait",
        "--timeout",
        "60",
        "--json",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v = json(&o);
    assert_eq!(v["mode"], "running");
    assert_eq!(v["settled"], true);
    // The rig's own estimate against the full equation's period-mean angle at the ω the drive
    // generator actually runs (0.5°), and R in situ against R requested (2 %).
    let phi = v["slow_angle_deg"].as_f64().unwrap();
    let reference = full_model_rest_deg(v["omega"].as_f64().unwrap(), None, 50.0);
    assert!(
        (phi - reference).abs() < 0.5,
        "φ0 {phi} vs full model {reference}"
    );
    let r = v["r_estimate"].as_f64().unwrap();
    assert!((r / 1.75 - 1.0).abs() < 0.02, "R in situ {r}");
    // The averaged theory's closed form, arccos(1/R) = 55.15° (physics §3), as `predicted`.
    let p = v["predicted"]["phi0_deg"].as_f64().unwrap();
    assert!((p - 55.150).abs() < 0.01, "{p}");
    eprintln!("settled at {phi:.3}° (full model {reference:.3}°), R in situ {r:.4}");
}

#[test]
fn a_refused_command_changes_nothing() {
    let rig = serve(&[]);
    let port = rig.first_line.as_str();
    let before = json(&kapitza(&["status", "--port", port, "--json"]));
    // R = 9 needs ω = ωc √9 = 3 × 146.1 = 438 rad/s for the demo rod, above the 420 rad/s limit.
    let o = kapitza(&["set", "--port", port, "--r", "9", "--angle", "90"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("above the limit"));
    // Outside the mount's travel [−10°, 190°].
    let o = kapitza(&["set", "--port", port, "--r", "1", "--angle", "200"]);
    assert_eq!(o.status.code(), Some(1));
    let after = json(&kapitza(&["status", "--port", port, "--json"]));
    for key in [
        "mode",
        "commands",
        "r_target",
        "omega_target",
        "drive_angle_target_deg",
    ] {
        assert_eq!(before[key], after[key], "{key}");
    }
}

#[test]
fn a_silent_host_soft_stops_the_rig() {
    let rig = serve(&[]);
    let port = rig.first_line.as_str();
    let o = kapitza(&[
        "set", "--port", port, "--r", "1.2", "--angle", "0", "--wait",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // Nobody owns the port now: after the rig's 1 s link timeout (wall time, whatever the
    // speed) the drive ramps down; at 60 rad/s² from ≈ 124 rad/s that is ≈ 2 s rig time.
    std::thread::sleep(Duration::from_millis(2500));
    let v = json(&kapitza(&["status", "--port", port, "--json"]));
    assert_eq!(v["mode"], "idle", "{v}");
    assert_eq!(v["last_stop"], "link_silent", "{v}");
}

#[test]
fn an_owner_keeps_the_drive_and_relays_commands() {
    let rig = serve(&[]);
    let port = rig.first_line.clone();
    let owner = start(&["attach", "--port", &port]);
    assert!(
        owner.first_line.starts_with("attached"),
        "{}",
        owner.first_line
    );
    // Through the owner, `set` returns once the rig has taken the command.
    let o = kapitza(&["set", "--port", &port, "--r", "1.75", "--angle", "90"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("through its owner"));
    // Well past the link timeout, the drive still runs: the owner keeps the link alive.
    std::thread::sleep(Duration::from_millis(2500));
    let v = json(&kapitza(&["status", "--port", &port, "--json"]));
    assert_eq!(v["mode"], "running", "{v}");
    // Ctrl-C on the owner stops the drive, and the rig confirms it.
    let printed = owner.interrupt();
    assert!(
        printed.contains("detached; the rig confirmed the stop"),
        "{printed}"
    );
    std::thread::sleep(Duration::from_millis(300));
    let v = json(&kapitza(&["status", "--port", &port, "--json"]));
    assert_ne!(v["mode"], "running", "{v}");
}

#[test]
fn a_restarted_rig_is_found_again_on_its_symlink() {
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("rig");
    let link = link.to_str().unwrap();
    let first = serve(&["--link", link]);
    let owner = start(&["attach", "--port", link]);
    assert!(owner.first_line.starts_with("attached"));
    drop(first);
    std::thread::sleep(Duration::from_millis(500));
    let second = serve(&["--link", link]);
    // The owner reopens the same path, checks the version again and serves its socket again
    // (while the line is lost it has none, so commands then reach the rig directly).
    let deadline = Instant::now() + Duration::from_secs(20);
    let mut ok = false;
    while Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(300));
        let o = kapitza(&["status", "--port", link]);
        if o.status.success() && String::from_utf8_lossy(&o.stdout).contains("through its owner") {
            ok = true;
            break;
        }
    }
    let printed = owner.interrupt();
    assert!(ok, "status never answered through the owner again");
    assert!(printed.contains("line lost"), "{printed}");
    assert!(printed.contains("line back"), "{printed}");
    drop(second);
}

#[test]
fn version_skew_names_both_versions() {
    let rig = serve(&["--protocol", "9"]);
    let o = kapitza(&["status", "--port", &rig.first_line]);
    assert_eq!(o.status.code(), Some(3));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("v9") && e.contains(&format!("v{}", kapitza_core::link::PROTOCOL_VERSION)),
        "{e}"
    );
    assert!(e.contains("flash"), "{e}");
}

#[test]
fn no_rig_gives_a_hint() {
    let o = kapitza(&["status", "--port", "/dev/kapitza-no-such-port"]);
    assert_eq!(o.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no such device"));
}

/// A line that damages what crosses it: flips bits, drops bytes, injects garbage. Between a
/// pty the client opens and the rig's pty.
struct NoisyLine {
    path: String,
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl NoisyLine {
    /// Each byte is damaged with probability 3/`one_in` (dropped, flipped or followed by garbage).
    fn new(rig_path: &str, seed: u64, one_in: u64) -> Self {
        let (master, slave) = serialport::TTYPort::pair().unwrap();
        let path = slave.name().unwrap();
        // The client's end stays open here too, so the master never sees a hang-up.
        let slave = Arc::new(slave);
        let rig = serialport::new(rig_path, 115_200)
            .timeout(Duration::from_millis(2))
            .open_native()
            .unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let mut threads = Vec::new();
        let mut m = master;
        m.set_timeout(Duration::from_millis(2)).unwrap();
        let pairs = [
            (
                m.try_clone_native().unwrap(),
                rig.try_clone_native().unwrap(),
                seed,
            ),
            (rig, m, seed ^ 0xA5A5),
        ];
        for (mut from, mut to, seed) in pairs {
            let stop = stop.clone();
            let slave = slave.clone();
            threads.push(std::thread::spawn(move || {
                let _keep_open = slave;
                let mut x = seed.max(1);
                let mut rnd = move || {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    x
                };
                let mut buf = [0u8; 256];
                while !stop.load(Ordering::Relaxed) {
                    let n = match from.read(&mut buf) {
                        Ok(n) => n,
                        Err(_) => continue,
                    };
                    let mut out = Vec::with_capacity(n + 4);
                    for &b in &buf[..n] {
                        match rnd() % one_in {
                            0 => {}                                         // dropped
                            1 => out.push(b ^ (1 << (rnd() % 8))),          // a bit flipped
                            2 => out.extend([b, rnd() as u8, rnd() as u8]), // garbage injected
                            _ => out.push(b),
                        }
                    }
                    let _ = to.write_all(&out);
                }
            }));
        }
        Self {
            path,
            stop,
            threads,
        }
    }
}

impl Drop for NoisyLine {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// One setting a `--truth` log says the rig applied: the rig's command count after it, R
/// requested, θd target.
fn applied(truth: &std::path::Path) -> Vec<(u64, f64, f64)> {
    std::fs::read_to_string(truth)
        .unwrap()
        .lines()
        .map(|l| {
            let v: Value = serde_json::from_str(l).unwrap();
            (
                v["commands"].as_u64().unwrap(),
                v["r_target"].as_f64().unwrap(),
                v["drive_angle_target_deg"].as_f64().unwrap(),
            )
        })
        .collect()
}

/// What a run of `kapitza set` through a noisy line came to, against the rig's truth log.
#[derive(Debug, Default)]
struct Tally {
    sent: usize,
    /// Exit 0, or 4 (the wait timed out: the command was carried out).
    carried_out: usize,
    /// Exit 1 with the refusal the command asked for (R = 9 is above ω_max).
    refused: usize,
    /// Exit 1 for another reason.
    refused_otherwise: usize,
    /// Any other exit (3: the line failed, said so).
    failed: usize,
    /// A setting the rig applied that no command asked for, or a command reported carried out
    /// that the rig did not apply.
    wrong: usize,
    /// Commands the rig carried out more than once.
    twice: usize,
    minutes: f64,
}

impl std::fmt::Display for Tally {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "sent {}: carried out {}, refused for their own reason {}, refused otherwise {}, \
             failed clearly {}, wrong {}, carried out twice {}; {:.1} min",
            self.sent,
            self.carried_out,
            self.refused,
            self.refused_otherwise,
            self.failed,
            self.wrong,
            self.twice,
            self.minutes
        )
    }
}

/// Sends `commands` through a noisy line with `kapitza set` and checks what the rig says it
/// applied (its `--truth` log: one line, with the rig's command count, whenever the count moves).
fn noisy_run(commands: usize, seed: u64, one_in: u64) -> Tally {
    let started = Instant::now();
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.jsonl");
    let rig = serve(&["--truth", truth.to_str().unwrap()]);
    let line = NoisyLine::new(&rig.first_line, seed, one_in);
    let mut sent = Vec::new();
    let mut claimed = Vec::new();
    let mut t = Tally {
        sent: commands,
        ..Tally::default()
    };
    let mut checks_failed = 0;
    for i in 0..commands {
        // Every fifth asks for more than the rig allows (R = 9 is above ω_max).
        let too_much = i % 5 == 4;
        let r = if too_much {
            9.0
        } else {
            0.5 + (i % 7) as f64 * 0.25
        };
        let angle = (i % 13) as f64 * 15.0;
        let o = kapitza(&[
            "set",
            "--port",
            &line.path,
            "--r",
            &r.to_string(),
            "--angle",
            &angle.to_string(),
            "--wait",
            "--timeout",
            "0.001",
        ]);
        sent.push((r, angle));
        let e = String::from_utf8_lossy(&o.stderr);
        match o.status.code() {
            // Taken (the wait itself times out at once: exit 4 means it was carried out).
            Some(0) | Some(4) if !too_much => {
                t.carried_out += 1;
                claimed.push(i);
            }
            Some(1) if too_much && e.contains("above the limit") => t.refused += 1,
            Some(0) | Some(4) => t.wrong += 1,
            Some(1) => {
                eprintln!("command {i} (R = {r}, θd = {angle}) refused otherwise: {e}");
                checks_failed += usize::from(e.contains("pre-run check failed"));
                t.refused_otherwise += 1
            }
            _ => {
                eprintln!("command {i} (R = {r}, θd = {angle}) failed: {e}");
                t.failed += 1
            }
        }
    }
    drop(line);
    std::thread::sleep(Duration::from_millis(100));
    drop(rig);
    // Each command carries out at most one setting, and two in a row never ask for the same
    // one (θd differs), so the truth log's entries belong to increasing command numbers: an
    // entry for the same command as the one before is that command carried out again, and so
    // is a count that moved by more than one per entry (a start whose pre-run check failed
    // moves it without an entry, and says so).
    let matches = |k: usize, r: f64, a: f64| {
        let (sr, sa) = sent[k];
        (r / sr - 1.0).abs() < 5e-3 && (a - sa).abs() < 1e-2
    };
    let (mut count, mut last, mut extra) = (0u64, None::<usize>, 0usize);
    let mut done = Vec::new();
    for (c, r, a) in applied(&truth) {
        extra += (c - count).saturating_sub(1) as usize;
        count = c;
        match last {
            Some(k) if matches(k, r, a) => t.twice += 1,
            _ => match (last.map_or(0, |k| k + 1)..sent.len()).find(|&k| matches(k, r, a)) {
                Some(k) => {
                    last = Some(k);
                    done.push(k);
                }
                None => t.wrong += 1,
            },
        }
    }
    t.twice += extra.saturating_sub(checks_failed);
    // Reported carried out, yet not applied.
    t.wrong += claimed.iter().filter(|k| !done.contains(k)).count();
    t.minutes = started.elapsed().as_secs_f64() / 60.0;
    t
}

#[test]
fn a_corrupting_line_never_gives_a_wrong_setting() {
    let t = noisy_run(20, 7, 1000);
    eprintln!("{t}");
    assert_eq!((t.wrong, t.twice), (0, 0), "{t}");
    assert_eq!(
        t.carried_out + t.refused + t.refused_otherwise + t.failed,
        t.sent
    );
    // Three bytes in 1000 damaged: a 170-byte configuration answer arrives whole 60 % of the
    // time, and 25 tries fail a call with probability 0.4^25; all 20 get through.
    assert_eq!(t.carried_out + t.refused, t.sent, "{t}");
}

/// Thousands of commands through the noisy line (minutes): `cargo test -p kapitza --test
/// rig_e2e -- --ignored --nocapture soak`.
#[test]
#[ignore]
fn soak_noisy_line() {
    let t = noisy_run(2000, 11, 400);
    println!("soak: {t}");
    assert_eq!((t.wrong, t.twice), (0, 0), "{t}");
    // Issue 23: at least 99 % carried out or refused for their own reason.
    assert!((t.carried_out + t.refused) * 100 >= t.sent * 99, "{t}");
}

#[test]
fn no_port_and_none_found_gives_the_hint() {
    // No --port, no KAPITZA_PORT, and (on a machine without a board) no ST-LINK port.
    let ports = json(&kapitza(&["ports", "--json"]));
    if ports
        .as_array()
        .unwrap()
        .iter()
        .any(|p| p["stlink"] == true)
    {
        return;
    }
    let o = kapitza(&["status"]);
    assert_eq!(o.status.code(), Some(3));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("--port sim") && e.contains("kapitza ports"),
        "{e}"
    );
}

#[test]
fn the_monitor_prints_records_from_a_served_rig() {
    let rig = serve(&[]);
    let o = kapitza(&[
        "monitor",
        "--port",
        &rig.first_line,
        "--plain",
        "--duration",
        "1",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = String::from_utf8_lossy(&o.stdout);
    let records: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    // 1 s of rig time at a frame every 20 ms is about 50 records (the first ones as the link
    // comes up may be fewer).
    assert!(records.len() >= 40, "{} records", records.len());
    assert!(records
        .iter()
        .all(|r| r["mode"] == "idle" && r["settled"].is_boolean()));
}

/// Issue 23's configurations that switched a safety limit off: each is refused by `config set`
/// with exit 1, naming the key typed and its range with its unit (the safety table,
/// `kapitza_core::rig::fields`), and `config get` is unchanged afterwards.
#[test]
fn a_limit_switched_off_is_refused_and_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let rig = serve(&[]);
    let port = rig.first_line.as_str();
    let before = kapitza(&["config", "get", "--port", port]);
    assert!(before.status.success());
    for (text, key, range) in [
        (
            "[limits]\nlink_timeout_ms = 0\n",
            "limits.link_timeout_ms = 0",
            "[500, 10000] ms",
        ),
        (
            "[limits]\nlink_timeout_ms = 4294967295\n",
            "limits.link_timeout_ms = 4294967295",
            "[500, 10000] ms",
        ),
        (
            "[limits]\novercurrent_ms = 4294967295\n",
            "limits.overcurrent_ms = 4294967295",
            "[1, 1000] ms",
        ),
        (
            "control_hz = 5\n[limits]\nomega_max = 15\nstall_min_omega = 10\n",
            "control_hz = 5",
            "[100, 12000] Hz",
        ),
    ] {
        let file = dir.path().join("bad.toml");
        std::fs::write(&file, text).unwrap();
        let o = kapitza(&["config", "set", "--port", port, file.to_str().unwrap()]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{text}: {e}");
        assert!(e.contains(key) && e.contains(range), "{text}: {e}");
        assert!(e.contains("nothing was sent"), "{e}");
        let after = kapitza(&["config", "get", "--port", port]);
        assert_eq!(after.stdout, before.stdout, "{text}");
    }
    let s = json(&kapitza(&["status", "--port", port, "--json"]));
    assert_eq!(s["config"], "stored");
    assert_eq!(s["config_fallbacks"], serde_json::json!([]));
}

#[test]
fn configuration_round_trip_and_refusal_by_field() {
    let dir = tempfile::tempdir().unwrap();
    let rig = serve(&[]);
    let port = rig.first_line.as_str();
    let got = kapitza(&["config", "get", "--port", port]);
    assert!(got.status.success());
    let toml = String::from_utf8_lossy(&got.stdout).to_string();
    // The demo rod's configuration (rigs/demo.toml): A = 12.7 mm on a 0.25 m rod.
    assert!(
        toml.contains("amplitude = 0.0127") && toml.contains("length = 0.25"),
        "{toml}"
    );
    // A value out of range: refused here with its field and range, nothing sent.
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[limits]\nstall_fraction = 3.0\n").unwrap();
    let o = kapitza(&["config", "set", "--port", port, bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    // The safety table's row (kapitza_core::rig::fields): stall_fraction in [0.05, 0.9].
    assert!(
        e.contains("limits.stall_fraction = 3") && e.contains("[0.05, 0.9]"),
        "{e}"
    );
    // A partial file: only the amplitude changes.
    let new = dir.path().join("new.toml");
    std::fs::write(&new, "amplitude = 0.012\n").unwrap();
    let o = kapitza(&["config", "set", "--port", port, new.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v = json(&kapitza(&["config", "get", "--port", port, "--json"]));
    assert_eq!(v["amplitude"], 0.012);
    assert_eq!(v["pendulum"]["length"], 0.25);
    let s = json(&kapitza(&["status", "--port", port, "--json"]));
    assert_eq!(s["config"], "received, saved");
    // While the drive runs (an owner keeps it running), another configuration is refused by
    // the rig and nothing changes.
    let owner = start(&["attach", "--port", port]);
    let o = kapitza(&["set", "--port", port, "--r", "1", "--angle", "0"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let other = dir.path().join("other.toml");
    std::fs::write(&other, "amplitude = 0.011\n").unwrap();
    let o = kapitza(&["config", "set", "--port", port, other.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("refused") && e.contains("Running"), "{e}");
    let v = json(&kapitza(&["config", "get", "--port", port, "--json"]));
    assert_eq!(v["amplitude"], 0.012);
    owner.interrupt();
}

#[test]
fn a_reversed_crank_fails_the_pre_run_check_and_set_exits_1_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("reversed.toml");
    std::fs::write(
        &file,
        "[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\n\
         [effects]\nviscous = { q = 10.0 }\n[crank]\nreversed = true\n",
    )
    .unwrap();
    let rig = serve(&["--sim", file.to_str().unwrap()]);
    let port = rig.first_line.as_str();
    let o = kapitza(&[
        "set", "--port", port, "--r", "1.5", "--angle", "0", "--json",
    ]);
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("pre-run check failed") && e.contains("backwards"),
        "{e}"
    );
    let v = json(&o);
    assert_eq!(v["check"], "failed");
    assert!(
        v["check_reason"].as_str().unwrap().contains("crank_sign"),
        "{v}"
    );
    assert_eq!(v["mode"], "idle");
    // Calibrated for it (the encoder's sign), the same bench starts.
    let cal = dir.path().join("cal.toml");
    std::fs::write(&cal, "[calibration]\ncrank_sign = -1\n").unwrap();
    let o = kapitza(&["config", "set", "--port", port, cal.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let owner = start(&["attach", "--port", port]);
    let o = kapitza(&["set", "--port", port, "--r", "1.5", "--angle", "0"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let s = json(&kapitza(&["status", "--port", port, "--json"]));
    assert_eq!(
        (s["mode"].as_str(), s["check"].as_str()),
        (Some("running"), Some("passed"))
    );
    assert_eq!(s["calibration"]["crank_sign"], -1);
    owner.interrupt();
}

/// `set --r 1.75 --angle 90 --wait --json` on `port`: the settled angle and the averaged
/// model's (deg), and the drive's ω.
fn settle_at_1_75(port: &str) -> (f64, f64, f64) {
    let o = kapitza(&[
        "set",
        "--port",
        port,
        "--r",
        "1.75",
        "--angle",
        "90",
        "--wait",
        "--timeout",
        "120",
        "--json",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v = json(&o);
    assert_eq!(v["settled"], true, "{v}");
    (
        v["slow_angle_deg"].as_f64().unwrap(),
        v["predicted"]["phi0_deg"].as_f64().unwrap(),
        v["omega"].as_f64().unwrap(),
    )
}

/// What `calibrate --json` wrote in `step` under `key`.
fn wrote(v: &Value, step: &str, key: &str) -> f64 {
    v["steps"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["step"] == step)
        .unwrap_or_else(|| panic!("no step {step}: {v}"))["wrote"][key]
        .as_f64()
        .unwrap_or_else(|| panic!("{step}.{key}: {v}"))
}

fn measured(v: &Value, step: &str, key: &str) -> f64 {
    v["steps"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["step"] == step)
        .unwrap()["measured"][key]
        .as_f64()
        .unwrap_or_else(|| panic!("{step}.{key}: {v}"))
}

/// `kapitza calibrate --yes --json` on `port` (one `step`, or all), its backup in `dir`.
fn calibrate(port: &str, dir: &std::path::Path, step: Option<&str>) -> (Value, std::path::PathBuf) {
    let backup = dir.join(format!("before-{}.toml", step.unwrap_or("all")));
    let mut args = vec!["calibrate", "--port", port, "--yes", "--json"];
    args.extend(["--backup", backup.to_str().unwrap()]);
    if let Some(s) = step {
        args.extend(["--step", s]);
    }
    let o = kapitza(&args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    (json(&o), backup)
}

#[test]
fn calibration_recovers_the_mistyped_rig_and_fixes_its_settle_angle() {
    // rigs/mistyped.toml. Truth: L = 0.25 m (typed 0.26), A = 12.7 mm (typed 12.5), the sensor
    // reads 1.5° low (zero count −1.5/360·16384 = −68.3 → 16315.7), Q = 10, Coulomb μ = 0.3
    // rad/s², the servo's mount 2° past what it is told.
    let dir = tempfile::tempdir().unwrap();
    let rig = serve(&[
        "--sim",
        concat!(env!("CARGO_MANIFEST_DIR"), "/../rigs/mistyped.toml"),
    ]);
    let port = rig.first_line.as_str();
    // Before: R 7.4 % high ((12.7/12.5)²·0.26/0.25), the mount 2° and the zero 1.5° off.
    let (before, model, _) = settle_at_1_75(port);

    let (v, backup) = calibrate(port, dir.path(), None);
    // Tolerances: docs/calibration.md (kapitza_core::calib::tolerance).
    let length = wrote(&v, "ringdown", "pendulum.length");
    let a = wrote(&v, "stroke", "amplitude");
    let q = measured(&v, "ringdown", "q");
    let mu = measured(&v, "ringdown", "coulomb");
    let zero = wrote(&v, "sensor", "pendulum_zero");
    let mount = measured(&v, "stroke", "mount_deg");
    assert!((length / 0.25 - 1.0).abs() < 0.004, "L {length}");
    assert!((a / 0.0127 - 1.0).abs() < 0.004, "A {a}");
    assert!((q / 10.0 - 1.0).abs() < 0.10, "Q {q}");
    assert!((mu / 0.3 - 1.0).abs() < 0.10, "μ {mu}");
    assert!(
        ((zero - 16_315.7) * 360.0 / 16_384.0).abs() < 0.2,
        "zero count {zero}"
    );
    assert_eq!(wrote(&v, "sensor", "pendulum_sign"), 1.0);
    assert_eq!(wrote(&v, "crank", "crank_sign"), 1.0);
    // The lean gives the mount, with the slider-crank's push taken out (calib::plumb): within
    // the 0.3° the zero's 0.2° allows at R ≈ 0.5 (docs/calibration.md).
    assert!((mount - 92.0).abs() < 0.3, "mount {mount}");

    let (after, model_after, omega) = settle_at_1_75(port);
    // Calibrated, the rig is the demo rod (L = 0.25 m, A = 12.7 mm, Q = 10) on its 60 mm
    // connecting rod at the ω it runs: the full equation's rest angle on the branch it settled
    // on is the reference (at θd = 90° the rod rests on either side; the rod's second harmonic
    // makes the two differ by 0.6°).
    let full = full_model_rest_deg(omega, Some(0.06), 50.0f64.copysign(after));
    // The rig's prediction on that branch: the averaged balance with the rod's terms for the
    // calibrated pendulum and stroke (what `set` prints as `predicted` on the positive one).
    let crank = SliderCrank {
        amplitude: a,
        rod: 0.06,
        ell: 2.0 * length / 3.0,
    };
    let r1 = 1.75 / crank.strength_gain();
    let predicted = math::to_deg(
        equilibrium_near(
            (1.0f64 / 1.75).acos().copysign(after),
            math::FRAC_PI_2,
            r1,
            Some(&crank),
        )
        .unwrap(),
    );
    if after > 0.0 {
        assert!(
            (predicted - model_after).abs() < 1e-3,
            "{predicted} vs {model_after}"
        );
    }
    eprintln!(
        "calibrated: L {length:.5} m, A {a:.6} m, Q {q:.2}, μ {mu:.3}, zero count {zero}, \
         mount {mount:.2}°; settled at R = 1.75, θd = 90°: before {before:.2}° (model \
         {model:.2}°), after {after:.2}° (predicted {predicted:.2}°, full equation {full:.2}°)"
    );
    assert!((before - model).abs() > 1.5, "before {before} vs {model}");
    // Issue 15's goal: within 0.5° of the prediction after calibration; and of the full
    // equation, which holds the averaged theory's own error apart.
    assert!(
        (after - predicted).abs() < 0.5,
        "after {after} vs predicted {predicted}"
    );
    assert!((after - full).abs() < 0.5, "after {after} vs full {full}");

    // The backup puts the configuration back (the rig stopped first: only while idle).
    assert!(kapitza(&["stop", "--port", port]).status.success());
    let deadline = Instant::now() + Duration::from_secs(30);
    while json(&kapitza(&["status", "--port", port, "--json"]))["mode"] != "idle" {
        assert!(Instant::now() < deadline, "never idle");
        std::thread::sleep(Duration::from_millis(100));
    }
    let o = kapitza(&["config", "set", "--port", port, backup.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let got = String::from_utf8(kapitza(&["config", "get", "--port", port]).stdout).unwrap();
    assert!(got.contains("length = 0.26"), "{got}");
}

#[test]
fn calibration_finds_reversed_directions() {
    // rigs/mistyped.toml with its sensor and crank encoder wired backwards: the sensor then
    // reads −(θ − 1.5°), +1.5° hanging, count 68.3.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("rig.toml");
    let base = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../rigs/mistyped.toml"
    ))
    .unwrap();
    let text = base
        .replace("zero_deg = 1.5", "zero_deg = 1.5\nreversed = true")
        .replace("[servo]", "[crank]\nreversed = true\n\n[servo]");
    std::fs::write(&file, text).unwrap();
    let rig = serve(&["--sim", file.to_str().unwrap()]);
    let port = rig.first_line.as_str();
    let (v, _) = calibrate(port, dir.path(), Some("crank"));
    assert_eq!(wrote(&v, "crank", "crank_sign"), -1.0);
    let (v, _) = calibrate(port, dir.path(), Some("sensor"));
    assert_eq!(wrote(&v, "sensor", "pendulum_sign"), -1.0);
    let zero = wrote(&v, "sensor", "pendulum_zero");
    assert!(
        ((zero - 68.27) * 360.0 / 16_384.0).abs() < 0.2,
        "zero count {zero}"
    );
}

/// `rig serve --estop-at-power-up`: the rig boots as a board powered up with its e-stop held,
/// on the safe defaults, and says so.
#[test]
fn a_rig_powered_up_with_the_estop_held_runs_on_defaults_and_says_so() {
    let rig = serve(&["--estop-at-power-up"]);
    let port = rig.first_line.as_str();
    let s = json(&kapitza(&["status", "--port", port, "--json"]));
    assert_eq!(s["config"], "defaults_by_estop", "{s}");
    assert_eq!(s["estop"], false, "released after power-up: {s}");
}
