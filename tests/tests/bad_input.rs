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

// Sweeps of the bad-input classes: 0 panics, 0 silent acceptances, and numbers taken in every
// notation a person types. Everything here runs in-process and is refused (or parsed) before
// any long work, so a sweep cannot hang.

use kapitza::cli::{Cli, Command};
use kapitza_core::sim::{Options, PlannedRun};
use proptest::prelude::*;

/// `x` as a person may type it: plain, e-notation, capital E, or with a leading plus.
fn typed(x: f64, style: u8) -> String {
    match style % 4 {
        0 => format!("{x}"),
        1 => format!("{x:e}"),
        2 => format!("{x:E}"),
        _ if x >= 0.0 => format!("+{x:e}"),
        _ => format!("{x:e}"),
    }
}

/// Runs `kapitza ARGS…` in-process: the error's text, or `None` when it succeeded.
fn outcome(args: &[&str]) -> Option<String> {
    let mut all = vec!["kapitza"];
    all.extend_from_slice(args);
    let mut out = Vec::new();
    kapitza::run(all, &mut out).err().map(|e| e.to_string())
}

/// Command lines with one numeric option left as `{}`: every option that takes a number, of
/// the commands that parse without a rig.
const NUMERIC: &[&str] = &[
    "predict --r {} --angle 90",
    "predict --r 1.75 --angle {}",
    "predict --rod {} --amplitude 0.01 --omega 200 --angle 90",
    "predict --rod 0.25 --amplitude {} --omega 200 --angle 90",
    "predict --rod 0.25 --amplitude 0.01 --omega {} --angle 90",
    "predict --rod 0.25 --amplitude 0.01 --omega 200 --angle 90 --gravity {}",
    "predict --rest-angle {}",
    "boundary --k {}",
    "boundary --k -0.1 --q {}",
    "boundary --k -0.1 --tol {}",
    "boundary --point {} --omega 200",
    "boundary --rod 0.25 --omega {}",
    "boundary --rod 0.25 --omega 200 --damping {}",
    "boundary --rod 0.25 --amplitude {}",
    "boundary --rod 0.25 --omega 200 --gravity {}",
    "set --port sim --r {} --angle 90",
    "set --port sim --r 1 --angle {}",
    "set --port sim --r 1 --angle 90 --wait --timeout {}",
    "monitor --port sim --duration {}",
    "attach --port sim --duration {}",
    "demo --speed {}",
    "status --port sim --speed {}",
    "rig serve --speed {}",
    "rig serve --duration {}",
    "chart stability --q {}",
    "chart stability --rod 0.25 --omega {} --amplitude 0.01",
    "chart stability --rod 0.25 --omega 200 --amplitude {}",
    "chart stability --rod 0.25 --omega 200 --amplitude 0.01 --gravity {}",
    "chart equilibria --r {}",
    "chart equilibria --rod 0.25 --amplitude {} --omega 200",
    "chart equilibria --rod 0.25 --amplitude 0.01 --omega {}",
    "chart equilibria --gravity {}",
    "chart regions --r {}",
];

/// `line` with `{}` replaced by `value`, split as a shell would.
fn with_value(line: &str, value: &str) -> Vec<String> {
    line.split(' ')
        .map(|w| {
            if w == "{}" {
                value.to_string()
            } else {
                w.to_string()
            }
        })
        .collect()
}

/// The subcommand `line` parsed to (its arguments are what was typed).
fn parsed(line: &[String]) -> Result<Command, clap::Error> {
    let mut all = vec!["kapitza".to_string()];
    all.extend_from_slice(line);
    clap::Parser::try_parse_from(all).map(|c: Cli| c.command)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn every_numeric_option_takes_a_negative_number_in_any_notation(
        which in 0..NUMERIC.len(),
        x in -1e6f64..-1e-9,
        style in 0u8..4,
    ) {
        // Taken as the option's value, never as a flag ("unexpected argument '-1'"); the
        // range check that follows names the option (the sweeps below).
        let line = with_value(NUMERIC[which], &typed(x, style));
        prop_assert!(parsed(&line).is_ok(), "{line:?}: {}", parsed(&line).unwrap_err());
    }

    #[test]
    fn predict_takes_every_in_range_number_in_any_notation(
        r in 0.0f64..50.0,
        angle in -1e6f64..1e6,
        sr in 0u8..4,
        sa in 0u8..4,
    ) {
        let (r, angle) = (typed(r, sr), typed(angle, sa));
        let e = outcome(&["predict", "--r", &r, "--angle", &angle]);
        prop_assert!(e.is_none(), "--r {r} --angle {angle}: {e:?}");
    }

    #[test]
    fn predict_refuses_out_of_range_numbers_by_the_option_typed(
        r in -1e300f64..-1e-300,
        angle in 1.000_001e6f64..1e300,
        negative in any::<bool>(),
        style in 0u8..4,
    ) {
        let r = typed(r, style);
        let e = outcome(&["predict", "--r", &r, "--angle", "90"]);
        prop_assert!(e.as_deref().is_some_and(|e| e.contains("--r ") && e.contains("out of range")), "--r {r}: {e:?}");
        let angle = typed(if negative { -angle } else { angle }, style);
        let e = outcome(&["predict", "--r", "1", "--angle", &angle]);
        prop_assert!(e.as_deref().is_some_and(|e| e.contains("--angle ") && e.contains("out of range")), "--angle {angle}: {e:?}");
    }

    #[test]
    fn boundary_refuses_k_past_its_range_and_q_past_its_damping_by_name(
        k in 25.000_001f64..1e300,
        q in 1e-300f64..1e-3,
        negative in any::<bool>(),
        style in 0u8..4,
    ) {
        let k = typed(if negative { -k } else { k }, style);
        let e = outcome(&["boundary", "--k", &k]);
        prop_assert!(e.as_deref().is_some_and(|e| e.contains("--k ") && e.contains("|k| <= 25")), "--k {k}: {e:?}");
        // δ = √|k|/Q past 25 at |k| = 1.
        let q = typed(q, style);
        let e = outcome(&["boundary", "--k", "-1", "--q", &q]);
        prop_assert!(
            e.as_deref().is_some_and(|e| e.contains("--q ") && !e.contains("delta =")),
            "--q {q}: {e:?}"
        );
    }

    #[test]
    fn a_fixed_step_spanning_drive_periods_is_refused_on_the_full_model(
        spp in 1e-9f64..0.999_999,
        method in prop::sample::select(vec!["rk4", "verlet", "yoshida4", "yoshida6"]),
        style in 0u8..4,
    ) {
        let sets = |fidelity: &str| {
            vec![
                format!("run.method={method}"),
                format!("run.steps_per_period={}", typed(spp, style)),
                format!("run.fidelity={fidelity}"),
            ]
        };
        let plan = |fidelity: &str| -> Result<(), String> {
            let f = parse(GOOD, "scene.toml", "scene", &sets(fidelity)).map_err(|e| format!("{e:#}"))?;
            let o = Options { method: f.method, format: f.format, ..Options::default() };
            PlannedRun::new(&f.scene, &o).map(|_| ()).map_err(|e| e.to_string())
        };
        let e = plan("full");
        prop_assert!(e.as_ref().is_err_and(|e| e.contains("run.steps_per_period")), "{e:?}");
        // Fractions stay allowed where the docs allow them: on the averaged model.
        prop_assert!(plan("averaged").is_ok(), "{:?}", plan("averaged"));
    }

    #[test]
    fn any_text_as_a_rig_or_scene_file_is_refused_or_read_never_a_panic(text in "\\PC{0,200}") {
        let _ = kapitza::rig::file::parse(&text);
        let _ = parse(&text, "x.toml", "x", &[]);
    }

    #[test]
    fn rig_file_tables_with_stray_keys_are_refused_by_name(
        table in prop::sample::select(vec!["motor", "sensor", "servo", "crank", "current"]),
        key in "[a-z]{3,12}_zz",
    ) {
        // A key no table has: named in the refusal, never ignored.
        let text = format!(
            "[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\n[{table}]\n{key} = 1\n"
        );
        let e = kapitza::rig::file::parse(&text).map(|_| ()).map_err(|e| format!("{e:#}"));
        prop_assert!(e.as_ref().is_err_and(|e| e.contains(&key)), "{text}: {e:?}");
    }
}
