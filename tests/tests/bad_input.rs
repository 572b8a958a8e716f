//! Input a new user might type that used to run and print a wrong or misleading answer: each is
//! refused with a message naming the input and its allowed range, and nothing runs.

use kapitza::scene_file::parse;

const GOOD: &str = r#"
[pendulum]
geometry = "rod"
length = 0.2
[drive]
amplitude = 0.0089
omega = 330.0
angle_deg = 90.0
[run]
periods = 300
"#;

/// The message for the scene above with `set`, which must be refused.
fn refused(set: &str) -> String {
    match parse(GOOD, "scene.toml", "scene", &[set.to_string()]) {
        Ok(s) => panic!("{set} accepted: {s:?}"),
        Err(e) => format!("{e:#}"),
    }
}

fn has(msg: &str, wants: &[&str]) {
    for w in wants {
        assert!(msg.contains(w), "{w:?} missing from: {msg}");
    }
}

#[test]
fn a_huge_initial_angle_is_refused() {
    // 1e17° has an f64 spacing of 16°: it ran and rested at "62.73°" on a horizontal drive.
    let msg = refused("initial.angle_deg=1e17");
    has(&msg, &["initial.angle_deg = 1e17", "[-1e6, 1e6] degrees"]);
    // The limit itself is accepted.
    assert!(parse(GOOD, "s", "s", &["initial.angle_deg=-1e6".to_string()]).is_ok());
}

#[test]
fn a_huge_drive_frequency_names_its_limit_in_a_few_digits() {
    // It printed 1e300 as 301 digits and blamed an overflow instead of the 1e6 rad/s limit.
    let msg = refused("drive.omega=1e300");
    has(&msg, &["drive.omega = 1e300", "(0, 1e6]"]);
    assert!(msg.len() < 200, "{msg}");
    let msg = refused("drive.omega=2e6");
    has(&msg, &["drive.omega = 2000000", "(0, 1e6]"]);
}

#[test]
fn a_huge_initial_rate_is_blamed_on_itself() {
    // It was blamed on run.periods (the run's count of its fastest time scale).
    let msg = refused("initial.rate=1e300");
    has(&msg, &["initial.rate = 1e300", "[-1e6, 1e6] (rad/s)"]);
    assert!(!msg.contains("run.periods"), "{msg}");
}

#[test]
fn predict_refuses_a_huge_drive_angle() {
    let mut out = Vec::new();
    let err = kapitza::run(
        ["kapitza", "predict", "--r", "1.75", "--angle", "1e20"],
        &mut out,
    )
    .expect_err("must fail")
    .to_string();
    has(
        &err,
        &["--angle 1e20", "out of range", "[-1e6, 1e6] degrees"],
    );
    assert!(out.is_empty(), "nothing printed on error");
}

#[test]
fn negative_samples_per_period_names_the_flag_and_range() {
    // It read "-3" as an unknown flag ("unexpected argument").
    let path = format!("{}/../scenes/tilted-135.toml", env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    let err = kapitza::run(
        [
            "kapitza",
            "simulate",
            path.as_str(),
            "--samples-per-period",
            "-3",
        ],
        &mut out,
    )
    .expect_err("must fail")
    .to_string();
    has(&err, &["--samples-per-period", "-3", "1.."]);
    assert!(!err.contains("unexpected argument"), "{err}");
}
