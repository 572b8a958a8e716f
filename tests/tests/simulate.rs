//! `kapitza simulate`, run in-process as a user would call it: small scenes end to end with
//! `--json`, and `--set` overrides. Loading errors are in `simulate_scene_errors.rs`.

use serde_json::Value;

fn data(name: &str) -> String {
    format!("{}/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn simulate(scene: &str, extra: &[&str]) -> Value {
    let path = data(scene);
    let mut argv = vec!["kapitza", "simulate", path.as_str(), "--json"];
    argv.extend_from_slice(extra);
    let mut out = Vec::new();
    kapitza::run(argv, &mut out).unwrap_or_else(|e| panic!("{scene} {extra:?}: {e}"));
    serde_json::from_slice(&out).unwrap()
}

fn wrap_deg(x: f64) -> f64 {
    let r = (x + 180.0).rem_euclid(360.0) - 180.0;
    if r == -180.0 {
        180.0
    } else {
        r
    }
}

/// The classifier's resting tolerance, 2e-3 rad (kapitza_core::sim::classify::TOL), in degrees.
const TOL_DEG: f64 = 0.115;

fn f(v: &Value, key: &str) -> f64 {
    v.pointer(key)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("{key} missing or not a number in {v:#}"))
}

#[test]
fn json_has_the_documented_keys() {
    let v = simulate("sim_averaged_rest.toml", &[]);
    for key in [
        "/scene",
        "/title",
        "/outcome/kind",
        "/fidelity/requested",
        "/fidelity/used",
        "/fidelity/reason",
        "/method",
        "/rtol",
        "/atol",
        "/steps_per_period",
        "/format",
        "/r",
        "/r_effective",
        "/omega",
        "/omega0",
        "/drive_angle_deg",
        "/amplitude",
        "/equivalent_length",
        "/gravity_effective",
        "/damping_c",
        "/duration_s",
        "/periods",
        "/wall_s",
        "/real_time_factor",
        "/work/steps",
        "/work/rhs_evals",
        "/work/rejected",
        "/work/lyapunov_steps",
        "/work/lyapunov_rhs_evals",
        "/work/lyapunov_rejected",
        "/end/t",
        "/end/angle_deg",
        "/end/turns",
        "/end/rate",
        "/sticks",
        "/predicted",
        "/expect/kind",
        "/expect/met",
        "/expect/why_not",
    ] {
        assert!(v.pointer(key).is_some(), "{key} missing from {v:#}");
    }
    assert_eq!(v["method"], "dop853");
    assert_eq!(v["format"], "f64");
    assert_eq!(v["fidelity"]["used"], "averaged");
    // The scene gives R = 3 directly (tolerance: rounding through ω and back).
    assert!((f(&v, "/r") - 3.0).abs() < 1e-12);
    // 600 periods asked for, 600 strobes taken (no ramp, so the drive phase is ωt).
    assert_eq!(v["periods"], 600);
    assert!((f(&v, "/duration_s") - 600.0 * std::f64::consts::TAU / f(&v, "/omega")).abs() < 1e-9);
    assert!(v["work"]["steps"].as_u64().unwrap() > 0);
    assert!(f(&v, "/wall_s") > 0.0 && f(&v, "/real_time_factor") > 0.0);
}

#[test]
fn averaged_rod_rests_at_the_predicted_equilibrium() {
    // R = 3 at θd = 135°, start 100°: the averaged theory's stable equilibrium within 90° of the
    // drive is 116.728° (kapitza predict --r 3 --angle 135, the root of
    // sin φ + (R/2) sin 2(φ − θd) = 0, physics §3). The averaged run converges to it exactly, so
    // the classifier's resolution is the tolerance.
    let v = simulate("sim_averaged_rest.toml", &[]);
    assert_eq!(v["outcome"]["kind"], "rest");
    let got = f(&v, "/outcome/angle_deg");
    let stable: Vec<f64> = v["predicted"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["stable"] == true && e["within_90_of_drive"] == true)
        .map(|e| e["angle_deg"].as_f64().unwrap())
        .collect();
    assert_eq!(stable.len(), 1);
    assert!((got - stable[0]).abs() < TOL_DEG, "{got} vs {}", stable[0]);
    assert!((got - 116.728).abs() < TOL_DEG);
    assert_eq!(v["expect"]["met"], true);
    assert!(v["expect"]["why_not"].is_null());
}

#[test]
fn full_equation_keeps_the_inverted_position() {
    // θd = 180°, R = 2 > 1: θ = π is an exact fixed point of the full equation and stable
    // (physics §3), so the run rests at 180° to the classifier's resolution.
    let v = simulate("sim_full_sensor.toml", &[]);
    assert_eq!(v["outcome"]["kind"], "rest");
    assert!(wrap_deg(f(&v, "/outcome/angle_deg") - 180.0).abs() < TOL_DEG);
    assert_eq!(v["fidelity"]["used"], "full");
    assert_eq!(v["method"], "rk4");
    assert_eq!(v["steps_per_period"], 40.0);
    assert!(v["rtol"].is_null());
    // Fixed-step RK4: exactly 40 steps in each of the 600 periods, none rejected.
    assert_eq!(v["work"]["steps"], 600 * 40);
    assert_eq!(v["work"]["rejected"], 0);
    // Under the 20° tilt R and ω0 use g cos β (physics §5); R stays as given, ω follows.
    let g_eff = 9.81 * 20f64.to_radians().cos();
    assert!((f(&v, "/gravity_effective") - g_eff).abs() < 1e-12);
    assert!((f(&v, "/omega0") - (g_eff / (2.0 * 0.2 / 3.0)).sqrt()).abs() < 1e-12);
    assert!((f(&v, "/r") - 2.0).abs() < 1e-12);
}

#[test]
fn set_overrides_a_key() {
    // At θd = 90° the stable tilted equilibria are ±arccos(1/R) (closed form, physics §3); from
    // 100° the pendulum settles at +arccos(1/3) = 70.53°.
    let v = simulate("sim_averaged_rest.toml", &["--set", "drive.angle_deg=90"]);
    assert_eq!(v["drive_angle_deg"], 90.0);
    assert_eq!(v["outcome"]["kind"], "rest");
    let want = (1.0f64 / 3.0).acos().to_degrees();
    assert!((f(&v, "/outcome/angle_deg") - want).abs() < TOL_DEG);
    // The scene's [expect] (116.73°) is no longer met, and the JSON says why.
    assert_eq!(v["expect"]["met"], false);
    assert!(v["expect"]["why_not"].as_str().unwrap().contains("116.73"));
}

#[test]
fn set_adds_an_effect() {
    // The averaged scene has no tilt; --set adds one. R is given, so ω follows from
    // R = A²ω²/(2 g cos β ℓ): ω scales with √cos β (physics §5, closed form).
    let plain = simulate("sim_averaged_rest.toml", &[]);
    let tilted = simulate(
        "sim_averaged_rest.toml",
        &["--set", "effects.tilt.angle_deg=30"],
    );
    let cos = 30f64.to_radians().cos();
    assert!((f(&tilted, "/gravity_effective") - 9.81 * cos).abs() < 1e-12);
    assert!((f(&tilted, "/omega") / f(&plain, "/omega") - cos.sqrt()).abs() < 1e-12);
    // Same R and θd, so the same averaged equilibrium.
    assert!((f(&tilted, "/outcome/angle_deg") - 116.728).abs() < TOL_DEG);
    // A slider-crank adds the second harmonic (A²/4b) cos 2ϕ; the averaged theory's R becomes
    // R (1 + A²/(4b²)) (closed form, kapitza_core::sim::eom) and the prediction follows it.
    let crank = simulate(
        "sim_averaged_rest.toml",
        &["--set", "effects.slider_crank.rod_length=0.05"],
    );
    let want = 3.0 * (1.0 + 0.0089f64.powi(2) / (4.0 * 0.05f64.powi(2)));
    assert!((f(&crank, "/r_effective") - want).abs() < 1e-12);
    assert!((f(&plain, "/r_effective") - 3.0).abs() < 1e-12);
    // A whole inline table works too, and a bare word is a string.
    let v = simulate(
        "sim_averaged_rest.toml",
        &[
            "--set",
            "effects.viscous={ gamma = 3.0 }",
            "--set",
            "run.fidelity=auto",
        ],
    );
    // c = 2γ (physics §3).
    assert!((f(&v, "/damping_c") - 6.0).abs() < 1e-12);
    assert_eq!(v["fidelity"]["requested"], "auto");
    // ω/ω0 ≈ 37 ≥ 10 and A/ℓ = 0.067 ≤ 0.1: auto picks the averaged model and says why.
    assert_eq!(v["fidelity"]["used"], "averaged");
    assert!(v["fidelity"]["reason"].as_str().unwrap().contains("ω/ω0"));
}

#[test]
fn human_summary_names_the_outcome_and_the_cost() {
    let path = data("sim_averaged_rest.toml");
    let mut out = Vec::new();
    kapitza::run(["kapitza", "simulate", path.as_str()], &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    for want in [
        "R = 3 at 135 degrees, averaged",
        "fidelity: averaged",
        "method: DOP853",
        "outcome: rest at 116.7",
        "— met",
        "predicted equilibria (averaged theory)",
        "116.73° stable",
        "work: ",
        "real-time factor",
    ] {
        assert!(text.contains(want), "{want:?} missing from:\n{text}");
    }
}
