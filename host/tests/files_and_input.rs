//! The real binary against a user's files and odd input: an existing file survives every
//! command that writes files unless `--force`/`--append`; a FIFO given as an input never blocks;
//! numbers in any notation; refusals that name what was typed. Every run has a deadline and a
//! hang fails the test (the deadlines are generous: these are not timed tests).

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::Duration;

use kapitza_test_support::binary::Binary;

const KAPITZA: Binary = Binary(env!("CARGO_BIN_EXE_kapitza"));

/// Far longer than any of these runs takes; reaching it is a hang.
const DEADLINE: Duration = Duration::from_secs(60);

fn run_in(args: &[&str], env: &[(&str, &str)], dir: Option<&Path>) -> Output {
    KAPITZA
        .run_within(args, env, dir, DEADLINE)
        .unwrap_or_else(|| panic!("hung past {DEADLINE:?}: kapitza {}", args.join(" ")))
}

fn run(args: &[&str]) -> Output {
    run_in(args, &[], None)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts exit status `code` and that stderr holds every one of `wants`.
fn refused(o: &Output, code: i32, wants: &[&str]) -> String {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(code), "{e}");
    for w in wants {
        assert!(e.contains(w), "{w:?} missing from: {e}");
    }
    e
}

fn repo(p: &str) -> String {
    format!("{}/../{p}", env!("CARGO_MANIFEST_DIR"))
}

/// A file holding an earlier measurement.
fn earlier(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, b"earlier measurement\n").unwrap();
    p
}

#[cfg(unix)]
fn fifo(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo on a path in this test's own folder.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    p
}

#[test]
fn rig_serve_keeps_an_existing_truth_file_unless_forced_or_appended() {
    let dir = tempfile::tempdir().unwrap();
    let truth = earlier(dir.path(), "truth.jsonl");
    let t = truth.to_str().unwrap();
    let o = run(&["rig", "serve", "--truth", t, "--duration", "0.2"]);
    refused(&o, 1, &["--truth", "exists", "--force", "--append"]);
    // Refused before the pseudo-terminal: no device path printed.
    assert!(
        o.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert_eq!(std::fs::read(&truth).unwrap(), b"earlier measurement\n");

    let o = run(&[
        "rig",
        "serve",
        "--truth",
        t,
        "--append",
        "--duration",
        "0.2",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(std::fs::read(&truth)
        .unwrap()
        .starts_with(b"earlier measurement\n"));

    let o = run(&["rig", "serve", "--truth", t, "--force", "--duration", "0.2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!std::fs::read(&truth)
        .unwrap()
        .starts_with(b"earlier measurement"));
}

#[test]
fn monitor_keeps_an_existing_csv_unless_forced_or_appended() {
    let dir = tempfile::tempdir().unwrap();
    let csv = earlier(dir.path(), "log.csv");
    let c = csv.to_str().unwrap();
    let base = [
        "monitor", "--port", "sim", "--speed", "0", "--plain", "--csv", c,
    ];
    let with = |extra: &[&'static str]| {
        let mut a: Vec<&str> = base.to_vec();
        a.extend_from_slice(extra);
        a.extend(["--duration", "0.5"]);
        run(&a)
    };
    let o = with(&[]);
    refused(&o, 1, &["--csv", "exists", "--force", "--append"]);
    assert!(o.stdout.is_empty(), "no record before the refusal");
    assert_eq!(std::fs::read(&csv).unwrap(), b"earlier measurement\n");

    let o = with(&["--append"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("earlier measurement\n"), "{text}");
    // Rows under the log's own header: none written again.
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert!(!rows.is_empty(), "rows appended");
    assert!(rows.iter().all(|r| !r.starts_with("t_s")), "{text}");

    let o = with(&["--force"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(!text.contains("earlier measurement"), "{text}");
    assert!(text.lines().count() >= 2, "a header and rows: {text}");
}

#[test]
fn calibrate_keeps_an_existing_backup_and_writes_its_own_outside_the_current_folder() {
    let dir = tempfile::tempdir().unwrap();
    let backup = earlier(dir.path(), "before.toml");
    let b = backup.to_str().unwrap();
    let cal = [
        "calibrate",
        "--port",
        "sim",
        "--speed",
        "0",
        "--yes",
        "--plain",
    ];
    let with = |extra: &[&str], env: &[(&str, &str)], cwd: Option<&Path>| {
        let mut a: Vec<&str> = cal.to_vec();
        a.extend_from_slice(extra);
        a.extend(["--step", "crank"]);
        run_in(&a, env, cwd)
    };
    let o = with(&["--backup", b], &[], None);
    refused(&o, 1, &["--backup", "exists", "--force"]);
    assert_eq!(std::fs::read(&backup).unwrap(), b"earlier measurement\n");

    let o = with(&["--backup", b, "--force"], &[], None);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let saved = std::fs::read_to_string(&backup).unwrap();
    assert!(
        saved.contains("[calibration]"),
        "the configuration as TOML: {saved}"
    );

    // Without --backup: a new file in $XDG_STATE_HOME/kapitza/backups, none in the folder
    // the command ran in.
    let state = tempfile::tempdir().unwrap();
    let cwd = tempfile::tempdir().unwrap();
    let env = [("XDG_STATE_HOME", state.path().to_str().unwrap())];
    let o = with(&[], &env, Some(cwd.path()));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(cwd.path()).unwrap().count(), 0);
    let folder = state.path().join("kapitza/backups");
    let files: Vec<_> = std::fs::read_dir(&folder).unwrap().flatten().collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let out = String::from_utf8_lossy(&o.stdout);
    let name = files[0].path();
    assert!(out.contains(name.to_str().unwrap()), "says where: {out}");
}

#[test]
fn output_directories_are_checked_before_any_work() {
    // --out under a regular file cannot be created: the bench refuses before it measures.
    let dir = tempfile::tempdir().unwrap();
    let blocker = earlier(dir.path(), "file");
    let out = blocker.join("bench");
    let o = run(&["bench", "--quick", "--out", out.to_str().unwrap()]);
    refused(&o, 1, &["--out", "cannot create the output directory"]);
    assert!(o.stdout.is_empty());
}

#[cfg(unix)]
#[test]
fn a_fifo_given_as_an_input_never_blocks() {
    // Nobody writes to these FIFOs: reading one would wait forever.
    let dir = tempfile::tempdir().unwrap();
    let f = fifo(dir.path(), "input.toml");
    let f = f.to_str().unwrap();
    let charts = dir.path().join("charts");
    let charts = charts.to_str().unwrap();
    let cases: [&[&str]; 6] = [
        &["simulate", f],
        &[
            "chart",
            "outcomes",
            f,
            "--x",
            "drive.angle_deg=0..180",
            "--y",
            "drive.r=1..2",
            "--out",
            charts,
        ],
        &["rig", "serve", "--sim", f, "--duration", "1"],
        &["status", "--port", "sim", "--sim", f],
        &["config", "set", "--port", "sim", f],
        &[
            "monitor",
            "--port",
            "sim",
            "--sim",
            f,
            "--plain",
            "--duration",
            "1",
        ],
    ];
    for args in cases {
        let o = run(args);
        refused(&o, 1, &[f, "a FIFO", "not a regular file"]);
    }
    // A directory, too.
    let d = dir.path().to_str().unwrap();
    refused(
        &run(&["simulate", d]),
        1,
        &["a directory, not a regular file"],
    );
}

#[test]
fn a_scene_file_given_as_a_rig_file_says_so() {
    let scene = repo("scenes/tilted-135.toml");
    let o = run(&["status", "--port", "sim", "--sim", &scene]);
    refused(&o, 1, &["is a scene file", "not a rig file", "docs/rig.md"]);
}

#[test]
fn sim_options_beside_a_real_port_are_refused() {
    let rig = repo("rigs/demo.toml");
    let o = run(&["status", "--port", "/dev/ttyKAPITZA-none", "--sim", &rig]);
    refused(&o, 1, &["--sim", "acts only with --port sim"]);
    let o = run(&["status", "--port", "/dev/ttyKAPITZA-none", "--speed", "5"]);
    refused(&o, 1, &["--speed 5", "acts only with --port sim"]);
    // Restating the default is no combination that cannot act.
    let o = run(&[
        "status", "--port", "sim", "--speed", "1", "--sim", &rig, "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[cfg(unix)]
#[test]
fn a_device_that_is_not_a_terminal_is_not_a_serial_port() {
    let o = run(&["set", "--port", "/dev/null", "--r", "1", "--angle", "90"]);
    let e = refused(&o, 1, &["--port /dev/null", "not a serial port"]);
    assert!(!e.contains("typewriter"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let p = earlier(dir.path(), "notes.txt");
    let o = run(&["status", "--port", p.to_str().unwrap()]);
    refused(&o, 1, &["not a serial port (a file)"]);
    assert_eq!(std::fs::read(&p).unwrap(), b"earlier measurement\n");
}

#[test]
fn negative_numbers_in_e_notation_are_numbers() {
    for args in [
        &["predict", "--r", "1.75", "--angle", "-1e-3"][..],
        &["predict", "--r", "1.75", "--angle", "-2.5E-1"],
        &["boundary", "--k", "-2.5e-1"],
        &["boundary", "--k", "-1e-3"],
    ] {
        let o = run(args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    }
    // Out of range, a negative is refused by the option that took it, not as a flag.
    let e = refused(
        &run(&["boundary", "--k", "-3e1"]),
        1,
        &["--k -30", "|k| <= 25"],
    );
    assert!(!e.contains("unexpected argument"), "{e}");
    let e = refused(
        &run(&["boundary", "--k", "-0.1", "--tol", "-1e-9"]),
        1,
        &["--tol"],
    );
    assert!(!e.contains("unexpected argument"), "{e}");
}

#[test]
fn a_tiny_quality_factor_is_blamed_on_q() {
    // It blamed "delta = 3.16e299", an internal quantity.
    let e = refused(
        &run(&["boundary", "--k", "-0.1", "--q", "1e-300"]),
        1,
        &["--q 1e-300", "out of range", "at least"],
    );
    assert!(!e.contains("delta ="), "{e}");
}

#[test]
fn degenerate_settings_are_refused_by_name() {
    let full = repo("scenes/tilted-135.toml");
    // A fixed step of a thousand drive periods on the full model: refused, not "chaos".
    let o = run(&[
        "simulate",
        &full,
        "--set",
        "run.method=rk4",
        "--set",
        "run.steps_per_period=1e-3",
    ]);
    refused(&o, 1, &["run.steps_per_period", "at least 1 on the full"]);
    // The same fraction on the averaged model is what the docs allow.
    let averaged = repo("tests/data/sim_averaged_rest.toml");
    let o = run(&[
        "simulate",
        &averaged,
        "--set",
        "run.method=rk4",
        "--set",
        "run.steps_per_period=0.5",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // Tolerances of 0.
    let o = run(&[
        "simulate",
        &full,
        "--set",
        "run.rtol=0",
        "--set",
        "run.atol=0",
    ]);
    refused(&o, 1, &["run.rtol"]);
    refused(
        &run(&["boundary", "--k", "-0.1", "--tol", "0"]),
        1,
        &["--tol 0"],
    );
    // Step counts past 1e8.
    let o = run(&[
        "boundary",
        "--k",
        "-0.1",
        "--q",
        "5",
        "--steps",
        "1000000000",
    ]);
    refused(&o, 1, &["--steps 1000000000", "1e8"]);
}

#[test]
fn work_past_the_budget_is_refused_with_its_estimate_before_it_runs() {
    // 1e9 drive periods of RK4 at 1e6 steps each: 1e15 steps, years of CPU.
    let full = repo("scenes/tilted-135.toml");
    let args = [
        "simulate",
        full.as_str(),
        "--set",
        "run.method=rk4",
        "--set",
        "run.steps_per_period=1e6",
        "--set",
        "run.periods=1e9",
    ];
    let o = run(&args);
    refused(
        &o,
        1,
        &[
            "would take about",
            "of CPU",
            "--no-budget",
            "nothing was run",
        ],
    );
    assert!(o.stdout.is_empty());
}
