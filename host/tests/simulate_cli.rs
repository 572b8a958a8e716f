//! `kapitza simulate` through the real binary: exit statuses, `--check`, a quiet stderr when it
//! is not a terminal, and the files `--out` writes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use kapitza_test_support::binary::Binary;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data")
        .join(name)
}

const KAPITZA: Binary = Binary(env!("CARGO_BIN_EXE_kapitza"));

fn kapitza(args: &[&str]) -> Output {
    KAPITZA.run(args)
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn statuses() {
    let good = data("sim_averaged_rest.toml");
    let good = good.to_str().unwrap();
    let ok = kapitza(&["simulate", good]);
    assert_eq!(ok.status.code(), Some(0), "{}", text(&ok.stderr));
    assert!(text(&ok.stdout).contains("outcome: rest at 116.7"));
    // No progress bar (or anything else) on a stderr that is not a terminal.
    assert!(ok.stderr.is_empty(), "stderr: {}", text(&ok.stderr));

    // A bad scene: status 1, and the message names the file and the key.
    let bad = data("sim_bad_effect.toml");
    let out = kapitza(&["simulate", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("sim_bad_effect.toml") && err.contains("effects.magnetism"),
        "{err}"
    );
    assert!(out.stdout.is_empty());

    // A missing file is a run error too; a bad --set names the key.
    assert_eq!(
        kapitza(&["simulate", "no-such-scene.toml"]).status.code(),
        Some(1)
    );
    let out = kapitza(&["simulate", good, "--set", "drive.angle_deg=inf"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("drive.angle_deg = inf"));

    // Malformed command lines: status 2.
    assert_eq!(kapitza(&["simulate"]).status.code(), Some(2));
    assert_eq!(
        kapitza(&["simulate", good, "--samples-per-period", "0"])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        kapitza(&["simulate", good, "--frobnicate"]).status.code(),
        Some(2)
    );
}

#[test]
fn check_fails_only_when_the_expectation_is_not_met() {
    let good = data("sim_averaged_rest.toml");
    let good = good.to_str().unwrap();
    assert_eq!(
        kapitza(&["simulate", good, "--check"]).status.code(),
        Some(0)
    );
    // Without --check an unmet expectation still exits 0, but says so.
    let moved = ["simulate", good, "--set", "expect.angle_deg=-34.04"];
    let out = kapitza(&moved);
    assert_eq!(out.status.code(), Some(0));
    assert!(text(&out.stdout).contains("NOT MET"));
    let mut checked = moved.to_vec();
    checked.push("--check");
    let out = kapitza(&checked);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("expectation not met"));
    assert!(
        text(&out.stdout).contains("outcome: rest"),
        "the summary still prints"
    );
    // --check on a scene without [expect] fails.
    let bare = data("sim_bare.toml");
    let out = kapitza(&["simulate", bare.to_str().unwrap(), "--check"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("[expect]"));
}

fn is_png(path: &Path) -> bool {
    let bytes = std::fs::read(path).unwrap();
    bytes.len() > 1000 && bytes.starts_with(b"\x89PNG\r\n\x1a\n")
}

fn rows(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

#[test]
fn out_writes_csv_json_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("run");
    let scene = data("sim_full_sensor.toml");
    let out = kapitza(&[
        "simulate",
        scene.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
        "--json",
        "--samples-per-period",
        "10",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let printed: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(printed, saved);

    assert!(is_png(&out_dir.join("angle.png")));
    assert!(is_png(&out_dir.join("phase.png")));

    // series.csv: 10 samples per drive period from t = 0 to the end of the 600 periods.
    let series = rows(&out_dir.join("series.csv"));
    assert_eq!(series[0], "t,theta_rad,theta_deg_wrapped,rate");
    assert_eq!(series.len() - 1, 600 * 10 + 1);
    let first: Vec<f64> = series[1].split(',').map(|x| x.parse().unwrap()).collect();
    // The scene starts at 170°, at rest, at t = 0.
    assert_eq!(first[0], 0.0);
    assert!((first[2] - 170.0).abs() < 1e-12 && first[3] == 0.0);

    // strobes.csv: one row per drive period, k = 1…600.
    let strobes = rows(&out_dir.join("strobes.csv"));
    assert_eq!(strobes[0], "k,t,theta,rate,period_mean");
    assert_eq!(strobes.len() - 1, 600);
    assert!(strobes[600].starts_with("600,"));

    // sensed.csv: the sensor's 2000 samples per second from t = 0 on, on its 12-bit grid.
    let sensed = rows(&out_dir.join("sensed.csv"));
    assert_eq!(sensed[0], "t,angle_rad,angle_deg");
    let duration = saved["duration_s"].as_f64().unwrap();
    assert_eq!(sensed.len() - 1, (duration * 2000.0).floor() as usize + 1);
    let lsb = std::f64::consts::TAU / 4096.0;
    for row in &sensed[1..50] {
        let a: f64 = row.split(',').nth(1).unwrap().parse().unwrap();
        let counts = a / lsb;
        assert!(
            (counts - counts.round()).abs() < 1e-6,
            "{a} is off the 12-bit grid"
        );
    }
}

#[test]
fn out_without_a_sensor_writes_no_sensed_csv() {
    let dir = tempfile::tempdir().unwrap();
    let scene = data("sim_averaged_rest.toml");
    let out = kapitza(&[
        "simulate",
        scene.to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(!dir.path().join("sensed.csv").exists());
    for f in [
        "series.csv",
        "strobes.csv",
        "summary.json",
        "angle.png",
        "phase.png",
    ] {
        assert!(dir.path().join(f).exists(), "{f} missing");
        assert!(text(&out.stdout).contains(&format!("wrote {}", dir.path().join(f).display())));
    }
}

#[test]
fn unwritable_out_is_refused_before_the_run_and_set_is_flagged() {
    // --out under a regular file cannot be created: refused in plain words, before any output
    // of a run (no summary on stdout).
    let scene = data("sim_averaged_rest.toml");
    let scene = scene.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("file");
    std::fs::write(&blocker, b"").unwrap();
    let out_dir = blocker.join("out");
    let r = kapitza(&["simulate", scene, "--out", out_dir.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(1));
    assert!(
        text(&r.stderr).contains("cannot create the output directory"),
        "{}",
        text(&r.stderr)
    );
    assert!(r.stdout.is_empty(), "{}", text(&r.stdout));
    // --set keeps the file's title and [expect]: the summary says so.
    let r = kapitza(&["simulate", scene, "--set", "drive.angle_deg=120"]);
    assert!(
        text(&r.stdout).contains("the title and [expect] are the file's"),
        "{}",
        text(&r.stdout)
    );
    // Piping into a reader that stops early is not an error.
    let mut child = Command::new(env!("CARGO_BIN_EXE_kapitza"))
        .args(["chart", "regions", "--size", "5x5", "--json", "--out"])
        .arg(dir.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let done = child.wait_with_output().unwrap();
    assert_eq!(done.status.code(), Some(0), "{}", text(&done.stderr));
}

/// Width and height from a PNG's IHDR chunk.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap();
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

#[test]
fn window_in_periods_or_seconds_writes_both_plots() {
    let scene = data("sim_full_sensor.toml");
    let scene = scene.to_str().unwrap();
    for window in ["8", "1.5s"] {
        let dir = tempfile::tempdir().unwrap();
        let out = kapitza(&[
            "simulate",
            scene,
            "--out",
            dir.path().to_str().unwrap(),
            "--window",
            window,
        ]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        for f in ["angle.png", "phase.png"] {
            let p = dir.path().join(f);
            assert!(is_png(&p), "{window}: {f}");
            // Slide-sized: 1600 × 1000 pixels.
            assert_eq!(png_size(&p), (1600, 1000), "{window}: {f}");
        }
    }
    // Not a window: a usage error. A window too long to hold in memory: refused before the run.
    assert_eq!(
        kapitza(&["simulate", scene, "--window", "0"]).status.code(),
        Some(2)
    );
    assert_eq!(
        kapitza(&["simulate", scene, "--window", "2x"])
            .status
            .code(),
        Some(2)
    );
    let dir = tempfile::tempdir().unwrap();
    let out = kapitza(&[
        "simulate",
        scene,
        "--out",
        dir.path().to_str().unwrap(),
        "--window",
        "500",
        "--samples-per-period",
        "10000",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("--window"),
        "{}",
        text(&out.stderr)
    );
    assert!(out.stdout.is_empty());
}
