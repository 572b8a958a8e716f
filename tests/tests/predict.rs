//! `kapitza predict`, run in-process as a user would call it, checked against physics §3–4.

use serde_json::Value;

fn predict(args: &[&str]) -> Value {
    let mut argv = vec!["kapitza", "predict", "--json"];
    argv.extend_from_slice(args);
    let mut out = Vec::new();
    kapitza::run(argv, &mut out).unwrap_or_else(|e| panic!("{args:?}: {e}"));
    serde_json::from_slice(&out).unwrap()
}

fn stable_angles(v: &Value) -> Vec<f64> {
    v["equilibria"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["stable"].as_bool().unwrap())
        .map(|e| e["angle_deg"].as_f64().unwrap())
        .collect()
}

#[test]
fn horizontal_drive_lists_both_tilts() {
    // physics §4.5: R = 1.75, θd = 90° → stable φ0 = ±arccos(1/R) = ±55.15° (closed form;
    // 1e-9° is rounding), both listed; only +55.15° is within 90° of the drive.
    let v = predict(&["--r", "1.75", "--angle", "90"]);
    let want = (1.0f64 / 1.75).acos().to_degrees();
    let s = stable_angles(&v);
    assert_eq!(s.len(), 2);
    assert!(s.iter().any(|a| (a - want).abs() < 1e-9) && s.iter().any(|a| (a + want).abs() < 1e-9));
    for e in v["equilibria"].as_array().unwrap() {
        let a = e["angle_deg"].as_f64().unwrap();
        assert!(a > -180.0 && a <= 180.0);
        if e["stable"].as_bool().unwrap() {
            // ωp/ω0 = √(cos φ0 + R cos 2(φ0 − θd)) = √(R − 1/R) at θd = 90° (closed form).
            let w = e["omega_p_over_omega0"].as_f64().unwrap();
            assert!((w - (1.75 - 1.0 / 1.75f64).sqrt()).abs() < 1e-12);
            assert_eq!(e["within_90_of_drive"].as_bool().unwrap(), a > 0.0);
        } else {
            assert!(e["omega_p_over_omega0"].is_null());
        }
    }
}

#[test]
fn inverted_needs_r_above_one() {
    // physics §3: θd = 180° → inverted stable iff R > 1, ωp = ω0 √(R − 1).
    let v = predict(&["--r", "1.5", "--angle", "180"]);
    let inv = v["equilibria"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["angle_deg"] == 180.0)
        .unwrap();
    assert_eq!(inv["stability"], "stable");
    assert!((inv["omega_p_over_omega0"].as_f64().unwrap() - 0.5f64.sqrt()).abs() < 1e-12);
    let v = predict(&["--r", "0.8", "--angle", "180"]);
    assert_eq!(stable_angles(&v), vec![0.0]);
}

#[test]
fn rod_geometry_matches_spec_r() {
    // physics §4.5: rod L = 0.25 m, A = 0.0127 m, ω = 188 rad/s, g = 9.81 → R = 1.7433 (4 d.p.).
    let v = predict(&[
        "--rod",
        "0.25",
        "--amplitude",
        "0.0127",
        "--omega",
        "188",
        "--angle",
        "90",
    ]);
    assert!((v["r"].as_f64().unwrap() - 1.7433).abs() < 5e-5);
    // ωp in rad/s is ωp/ω0 · √(g/ℓ), ℓ = 2L/3.
    let w0 = (9.81f64 / (2.0 * 0.25 / 3.0)).sqrt();
    assert!((v["physical"]["omega0"].as_f64().unwrap() - w0).abs() < 1e-12);
}

#[test]
fn saddle_node_point_is_marginal() {
    // physics §4.5: at R = 2, θd = 135° the equilibrium within 90° of the drive is marginal.
    let v = predict(&["--r", "2", "--angle", "135"]);
    let m: Vec<&Value> = v["equilibria"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["marginal"] == true)
        .collect();
    assert_eq!(m.len(), 1);
    assert_eq!(m[0]["within_90_of_drive"], true);
    assert!(m[0]["omega_p_over_omega0"].is_null());
    // Just above R_sn it becomes a stable/unstable pair, one of them reachable and stable.
    let v = predict(&["--r", "2.001", "--angle", "135"]);
    assert_eq!(v["equilibria"].as_array().unwrap().len(), 4);
}

#[test]
fn bad_input_names_the_argument() {
    for (args, flag) in [
        (vec!["--r", "-1", "--angle", "0"], "--r"),
        (vec!["--r", "nan", "--angle", "0"], "--r"),
        (vec!["--r", "1", "--angle", "inf"], "--angle"),
        (
            vec![
                "--point",
                "0",
                "--amplitude",
                "0.01",
                "--omega",
                "50",
                "--angle",
                "0",
            ],
            "--point",
        ),
        (
            vec![
                "--rod",
                "0.2",
                "--amplitude",
                "0.01",
                "--omega",
                "-5",
                "--angle",
                "0",
            ],
            "--omega",
        ),
        (
            vec![
                "--rod",
                "0.2",
                "--amplitude",
                "0.01",
                "--omega",
                "50",
                "--angle",
                "0",
                "--gravity",
                "0",
            ],
            "--gravity",
        ),
    ] {
        let mut argv = vec!["kapitza", "predict"];
        argv.extend_from_slice(&args);
        let mut out = Vec::new();
        let err = kapitza::run(argv, &mut out)
            .expect_err("must fail")
            .to_string();
        assert!(
            err.contains(flag) && err.contains("out of range"),
            "{args:?}: {err}"
        );
        assert!(out.is_empty(), "nothing printed on error");
    }
}

#[test]
fn rest_angle_answers_which_drive_angle() {
    // Closed forms (physics §3 solved for θd): a rest at φ0 needs |sin 2(φ0 − θd)| = 2|sin φ0|/R
    // ≤ 1, so R ≥ 2 sin φ0, reached at φ0 − θd = −45° where the margin cos φ0 > 0 for
    // φ0 = 60°; R is unbounded above (θd → φ0). Tolerance 1e-8: the scan over φ0 − θd is
    // flat (quadratic) at its minimum.
    let v = predict(&["--rest-angle", "60"]);
    assert!((v["r_min"].as_f64().unwrap() - 2.0 * 60f64.to_radians().sin()).abs() < 1e-8);
    assert!(v["r_max"].is_null());
    // R = 1.75: the equilibrium at arccos(1/R) = 55.15° needs θd = 90° (physics §4.5); the
    // other root of sin 2x (θd = 110.3°) is unstable there, and the x + 180° roots unreachable.
    let phi = (1.0f64 / 1.75).acos().to_degrees();
    let v = predict(&["--rest-angle", &phi.to_string(), "--r", "1.75"]);
    let angles: Vec<f64> = v["drive_angles_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_f64().unwrap())
        .collect();
    assert_eq!(angles.len(), 1, "{v}");
    assert!((angles[0] - 90.0).abs() < 1e-9, "{v}");
    // Too weak a drive: none, and the reason says how strong it must be.
    let v = predict(&["--rest-angle", "60", "--r", "0.5"]);
    assert!(v["drive_angles_deg"].as_array().unwrap().is_empty());
    assert!(v["reason"].as_str().unwrap().contains("at least 1.73"));
}
