//! Scene loading: every class of bad scene is refused before anything runs, with a message that
//! names the file, the key, the bad value and what is allowed (docs/scenes.md).

use kapitza::scene_file::parse;
use kapitza_core::sim::scene::Viscous;

const GOOD: &str = r#"
title = "good"
[pendulum]
geometry = "rod"
length = 0.2
[drive]
amplitude = 0.0089
r = 3.0
angle_deg = 135.0
[run]
periods = 300
"#;

/// The error message for `text` with `sets`, which must fail.
fn error(text: &str, sets: &[&str]) -> String {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    match parse(text, "scene.toml", "scene", &sets) {
        Ok(s) => panic!("accepted: {s:?}"),
        Err(e) => format!("{e:#}"),
    }
}

fn has(msg: &str, wants: &[&str]) {
    for w in wants {
        assert!(msg.contains(w), "{w:?} missing from: {msg}");
    }
    assert!(msg.starts_with("scene.toml: "), "no file name in: {msg}");
}

#[test]
fn the_good_scene_loads() {
    let s = parse(GOOD, "scene.toml", "scene", &[]).unwrap();
    assert_eq!(s.title, "good");
    assert!(s.expect.is_none());
    // No [effects]: every effect absent.
    assert_eq!(s.scene.effects, Default::default());
    // Degrees become radians at this boundary.
    assert!((s.scene.drive.angle.rad() - 135f64.to_radians()).abs() < 1e-15);
}

#[test]
fn unknown_key_lists_the_allowed_ones() {
    let msg = error(&GOOD.replace("amplitude", "amplitdue"), &[]);
    has(
        &msg,
        &[
            "drive.amplitdue",
            "unknown field",
            "`amplitude`",
            "`omega`",
            "`r`",
        ],
    );
    let msg = error(&format!("colour = \"red\"\n{GOOD}"), &[]);
    has(
        &msg,
        &[
            "colour",
            "unknown field",
            "`pendulum`",
            "`effects`",
            "`expect`",
        ],
    );
}

#[test]
fn unknown_effect_lists_the_effects() {
    let msg = error(
        &format!("{GOOD}\n[effects]\nmagnetism = {{ strength = 1.0 }}\n"),
        &[],
    );
    has(
        &msg,
        &[
            "effects.magnetism",
            "`viscous`",
            "`coulomb`",
            "`tilt`",
            "`slider_crank`",
            "`ramp`",
            "`sensor`",
            "`actuator`",
        ],
    );
    // A misspelt field inside a known effect.
    let msg = error(
        &format!("{GOOD}\n[effects]\nviscous = {{ Q = 1.0 }}\n"),
        &[],
    );
    has(&msg, &["effects.viscous.Q", "`q`", "`gamma`"]);
}

#[test]
fn missing_fields_and_tables() {
    let msg = error(&GOOD.replace("amplitude = 0.0089\n", ""), &[]);
    has(&msg, &["drive", "missing field `amplitude`"]);
    let msg = error(&GOOD.replace("[run]\nperiods = 300\n", ""), &[]);
    has(&msg, &["missing field `run`"]);
    let msg = error(&GOOD.replace("length = 0.2\n", ""), &[]);
    has(
        &msg,
        &["pendulum", "missing field `length`", "geometry = \"rod\""],
    );
    let general = GOOD.replace(
        "geometry = \"rod\"\nlength = 0.2",
        "geometry = \"general\"\ninertia = 0.001\nmass = 0.1",
    );
    has(&error(&general, &[]), &["missing field `com`", "general"]);
    let msg = error(
        &format!("{GOOD}\n[effects]\nsensor = {{ bits = 12 }}\n"),
        &[],
    );
    has(&msg, &["effects.sensor", "missing field `rate_hz`"]);
}

#[test]
fn wrong_types() {
    let msg = error(
        &GOOD.replace("amplitude = 0.0089", "amplitude = \"big\""),
        &[],
    );
    has(&msg, &["drive.amplitude", "\"big\"", "f64"]);
    let msg = error(&GOOD.replace("title = \"good\"", "title = 3"), &[]);
    has(&msg, &["title", "integer `3`", "string"]);
    let msg = error(
        &format!("run = 300\n{}", GOOD.replace("[run]\nperiods = 300\n", "")),
        &[],
    );
    has(&msg, &["run", "integer `300`", "a table: [run]"]);
    let msg = error(
        &format!("{GOOD}\n[effects]\nsensor = {{ bits = 12.5, rate_hz = 100 }}\n"),
        &[],
    );
    has(&msg, &["effects.sensor.bits", "12.5", "u32"]);
}

#[test]
fn exactly_one_of_r_and_omega() {
    let msg = error(&GOOD.replace("r = 3.0", "r = 3.0\nomega = 330.0"), &[]);
    has(&msg, &["drive", "omega = 330", "r = 3", "exactly one"]);
    let msg = error(&GOOD.replace("r = 3.0\n", ""), &[]);
    has(&msg, &["drive", "neither omega nor r", "exactly one"]);
}

#[test]
fn exactly_one_of_periods_and_duration() {
    let msg = error(
        &GOOD.replace("periods = 300", "periods = 300\nduration = 2.0"),
        &[],
    );
    has(
        &msg,
        &["run", "periods = 300", "duration = 2", "exactly one"],
    );
    let msg = error(&GOOD.replace("periods = 300", "fidelity = \"full\""), &[]);
    has(&msg, &["run", "neither periods nor duration"]);
}

#[test]
fn bad_names() {
    let msg = error(&GOOD.replace("\"rod\"", "\"rdo\""), &[]);
    has(
        &msg,
        &[
            "pendulum.geometry",
            "`rdo`",
            "`rod`",
            "`point`",
            "`general`",
        ],
    );
    let msg = error(
        &GOOD.replace("periods = 300", "periods = 300\nfidelity = \"exact\""),
        &[],
    );
    has(
        &msg,
        &[
            "run.fidelity",
            "`exact`",
            "`full`",
            "`averaged`",
            "`linearised`",
            "`auto`",
        ],
    );
    let msg = error(
        &GOOD.replace("periods = 300", "periods = 300\nmethod = \"euler\""),
        &[],
    );
    has(&msg, &["run.method", "`euler`", "`dop853`", "`rk4`"]);
    let msg = error(&format!("{GOOD}\n[expect]\nkind = \"resting\"\n"), &[]);
    has(
        &msg,
        &[
            "expect.kind",
            "`resting`",
            "`rest`",
            "`flutter`",
            "`chaotic`",
        ],
    );
}

#[test]
fn non_finite_numbers() {
    // TOML has nan and inf literals; every number is checked.
    let msg = error(&GOOD.replace("amplitude = 0.0089", "amplitude = nan"), &[]);
    has(&msg, &["drive.amplitude = NaN", "finite"]);
    let msg = error(&GOOD.replace("angle_deg = 135.0", "angle_deg = inf"), &[]);
    has(&msg, &["drive.angle_deg = inf", "finite"]);
    let msg = error(&format!("{GOOD}\n[environment]\ngravity = -inf\n"), &[]);
    has(&msg, &["environment.gravity = -inf", "> 0"]);
    let msg = error(&format!("{GOOD}\n[initial]\nangle_deg = nan\n"), &[]);
    has(&msg, &["initial.angle_deg = NaN", "finite"]);
    let msg = error(
        &format!("{GOOD}\n[effects]\ncoulomb = {{ torque = inf }}\n"),
        &[],
    );
    has(&msg, &["effects.coulomb.torque = inf", ">= 0"]);
}

#[test]
fn out_of_range_numbers() {
    let msg = error(
        &format!("{GOOD}\n[effects]\ntilt = {{ angle_deg = 95.0 }}\n"),
        &[],
    );
    has(&msg, &["effects.tilt.angle_deg = 95", "(-90, 90)"]);
    let msg = error(&GOOD.replace("length = 0.2", "length = -0.2"), &[]);
    has(&msg, &["pendulum.length = -0.2", "> 0"]);
    let msg = error(&GOOD.replace("periods = 300", "periods = 0"), &[]);
    has(&msg, &["run.periods = 0", "(0, 1e9]"]);
    let msg = error(
        &format!("{GOOD}\n[effects]\nsensor = {{ bits = 30, rate_hz = 100 }}\n"),
        &[],
    );
    has(&msg, &["effects.sensor.bits = 30", "[4, 24]"]);
    let msg = error(
        &format!("{GOOD}\n[effects]\nviscous = {{ q = 1.0, gamma = 2.0 }}\n"),
        &[],
    );
    has(
        &msg,
        &["effects.viscous", "q = 1", "gamma = 2", "exactly one"],
    );
    let msg = error(
        &GOOD.replace("periods = 300", "periods = 300\nrtol = 0"),
        &[],
    );
    has(&msg, &["run.rtol = 0", "> 0"]);
}

#[test]
fn combinations_that_cannot_run() {
    // The linearised model exists only about an exact fixed point (θd = 0° or 180°, physics §5).
    let msg = error(
        &GOOD.replace("periods = 300", "periods = 300\nfidelity = \"linearised\""),
        &[],
    );
    has(&msg, &["run.fidelity", "135"]);
    let msg = error(
        &GOOD.replace(
            "periods = 300",
            "periods = 300\nmethod = \"rk4\"\nrtol = 1e-6",
        ),
        &[],
    );
    has(&msg, &["run.rtol", "rk4"]);
    let msg = error(
        &format!("{GOOD}\n[expect]\nkind = \"rest\"\norder = 3\n"),
        &[],
    );
    has(&msg, &["expect.order = 3", "subharmonic"]);
    let msg = error(
        &format!("{GOOD}\n[expect]\nkind = \"rotation\"\ndirection = 2\n"),
        &[],
    );
    has(&msg, &["expect.direction = 2", "-1"]);
}

#[test]
fn toml_syntax_errors_name_the_line() {
    let msg = error(&GOOD.replace("length = 0.2", "length = = 0.2"), &[]);
    has(&msg, &["not valid TOML", "line 5"]);
}

#[test]
fn set_overrides_and_adds() {
    let sets = [
        "drive.angle_deg=120".to_string(),
        "effects.viscous.q=50".to_string(),
        "run.fidelity=full".to_string(),
        "title=\"overridden\"".to_string(),
    ];
    let s = parse(GOOD, "scene.toml", "scene", &sets).unwrap();
    assert!((s.scene.drive.angle.deg() - 120.0).abs() < 1e-12);
    assert_eq!(s.scene.effects.viscous, Some(Viscous::Q(50.0)));
    assert_eq!(s.title, "overridden");
    assert_eq!(
        s.scene.fidelity,
        kapitza_core::sim::scene::FidelityChoice::Fixed(kapitza_core::sim::scene::Fidelity::Full)
    );
    // An empty value removes a key: switch the scene from R to ω.
    let sets = ["drive.r=".to_string(), "drive.omega=300".to_string()];
    let switched = parse(GOOD, "scene.toml", "scene", &sets).unwrap();
    assert_eq!(
        switched.scene.drive.frequency,
        kapitza_core::sim::scene::DriveFrequency::Omega(300.0)
    );
}

#[test]
fn set_errors_name_the_key() {
    has(
        &error(GOOD, &["title.x=1"]),
        &["--set title.x=1", "`title` is a string"],
    );
    has(
        &error(GOOD, &["drive.omega"]),
        &["--set drive.omega", "KEY=VALUE"],
    );
    has(
        &error(GOOD, &["drive.omega=1..2"]),
        &["drive.omega=1..2", "not a TOML value"],
    );
    has(
        &error(GOOD, &["drive..omega=1"]),
        &["drive..omega", "dotted path"],
    );
    // A key the scene does not know is refused like one in the file, and blamed on --set.
    has(
        &error(GOOD, &["effects.drag.q=1"]),
        &[
            "effects.drag",
            "unknown field",
            "(from --set effects.drag.q=1)",
        ],
    );
    // Setting ω on a scene that gives R is the "both r and omega" error.
    has(
        &error(GOOD, &["drive.omega=300"]),
        &["both omega = 300 and r = 3"],
    );
}

#[test]
fn a_bad_file_does_not_run() {
    let path = format!("{}/data/sim_bad_effect.toml", env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    let err = kapitza::run(["kapitza", "simulate", path.as_str(), "--json"], &mut out).unwrap_err();
    assert!(matches!(err, kapitza::cli::Error::Run(_)));
    let msg = err.to_string();
    assert!(
        msg.contains("sim_bad_effect.toml") && msg.contains("effects.magnetism"),
        "{msg}"
    );
    assert!(
        out.is_empty(),
        "something ran: {}",
        String::from_utf8_lossy(&out)
    );
}
