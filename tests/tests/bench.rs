//! `kapitza bench --quick`, run in-process as CI runs it: the output is sane and has the
//! documented shape.
//!
//! "Sane" is checked on evaluation counts, never on seconds (times depend on the machine):
//! along each method's work-precision curve (one family and number format on one scene, points
//! in order of evaluations), every pair of points whose evaluations differ by a factor 4 or more
//! must have the error fall, unless the cheaper point's error is already at the curve's floor:
//!
//! ```text
//! floor = max(1e-12, 10 × the scene's reference check)        f64, full model
//!       = max(that,  10 × the least f32 error on the scene)   f32 (its rounding plateau)
//!       = max(that,  10 × the least error of the curve)        averaged model (its model error)
//! ```
//! The peer's Dop853 as published is exempt: on our time-dependent equation it does not
//! converge (its stage-12 node is wrong), which the bench reports.

use serde_json::Value;
use std::path::PathBuf;
use std::sync::OnceLock;

/// The quick run's JSON and its output directory, made once for all tests here.
fn quick() -> &'static (Value, PathBuf) {
    static RUN: OnceLock<(Value, PathBuf)> = OnceLock::new();
    RUN.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("kapitza-bench-test-{}", std::process::id()));
        let mut out = Vec::new();
        kapitza::run(
            [
                "kapitza",
                "bench",
                "--quick",
                "--json",
                "--out",
                dir.to_str().expect("a UTF-8 temporary directory"),
            ],
            &mut out,
        )
        .unwrap_or_else(|e| panic!("kapitza bench --quick: {e}"));
        (serde_json::from_slice(&out).expect("JSON on stdout"), dir)
    })
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn arr(v: &Value) -> &Vec<Value> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}"))
}

/// Scene, family and number format.
type Curve = (String, String, String);

#[test]
fn errors_fall_as_evaluations_rise() {
    let (v, _) = quick();
    let points = arr(&v["measurements"]);
    let check = |scene: &str| {
        arr(&v["scenes"])
            .iter()
            .find(|s| s["name"] == scene)
            .map(|s| num(&s["reference"]["check_difference"]))
            .unwrap()
    };
    let mut curves: Vec<(Curve, Vec<&Value>)> = Vec::new();
    for p in points {
        let key = (
            p["scene"].as_str().unwrap().to_string(),
            p["family"].as_str().unwrap().to_string(),
            p["format"].as_str().unwrap().to_string(),
        );
        match curves.iter_mut().find(|(k, _)| *k == key) {
            Some((_, c)) => c.push(p),
            None => curves.push((key, vec![p])),
        }
    }
    let mut checked = 0;
    for ((scene, family, format), mut curve) in curves {
        if family == "peer-dop853" {
            continue;
        }
        curve.sort_by_key(|p| p["rhs_evals"].as_u64().unwrap());
        let least = |pred: &dyn Fn(&Value) -> bool| {
            points
                .iter()
                .filter(|p| p["scene"] == scene.as_str() && pred(p))
                .map(|p| num(&p["error"]))
                .fold(f64::INFINITY, f64::min)
        };
        let mut floor = (10.0 * check(&scene)).max(1e-12);
        if format == "f32" {
            floor = floor.max(10.0 * least(&|p| p["format"] == "f32"));
        }
        if family.starts_with("averaged-") {
            floor = floor.max(10.0 * least(&|p| p["fidelity"] == "averaged"));
        }
        for (i, a) in curve.iter().enumerate() {
            for b in &curve[i + 1..] {
                let (ea, eb) = (num(&a["error"]), num(&b["error"]));
                let (na, nb) = (num(&a["rhs_evals"]), num(&b["rhs_evals"]));
                if nb >= 4.0 * na && ea > floor {
                    checked += 1;
                    assert!(
                        eb < ea,
                        "{scene} {family} {format}: {na} evaluations give error {ea:e}, {nb} give {eb:e} (floor {floor:e})"
                    );
                }
            }
        }
    }
    assert!(checked >= 40, "only {checked} pairs checked");
}

#[test]
fn json_has_the_documented_keys() {
    let (v, _) = quick();
    // docs/cli.md lists exactly the keys printed (kapitza_test_support::cli_doc).
    kapitza_test_support::cli_doc::assert_documented(
        "`kapitza bench --json`",
        std::slice::from_ref(v),
    );
    assert_eq!(v["quick"], true);
    let scenes: Vec<&str> = arr(&v["scenes"])
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(scenes, ["settling", "flutter", "chaotic", "undamped"]);
    for s in arr(&v["scenes"]) {
        // The reference is converged far below the targets it judges (1e-9).
        assert!(num(&s["reference"]["check_difference"]) < 1e-10, "{s}");
        assert_eq!(num(&s["reference"]["rtol"]), 1e-13);
    }
    let m = &arr(&v["measurements"])[0];
    for key in [
        "scene",
        "family",
        "who",
        "fidelity",
        "format",
        "setting_name",
        "setting",
        "error",
        "wall_s",
        "cpu_s",
        "rhs_evals",
        "steps",
        "rejected",
    ] {
        assert!(m.get(key).is_some(), "measurements[0] lacks {key}: {m}");
    }
    for key in [
        "stability_criteria",
        "floquet_convergence",
        "physical",
        "averaged_validity",
        "chaotic_fate",
        "peer_as_published_ratios",
    ] {
        assert!(!arr(&v[key]).is_empty(), "{key} is empty");
    }
}

#[test]
fn peer_ratios_present_for_every_scene_and_target() {
    let (v, _) = quick();
    let ratios = arr(&v["peer_ratios"]);
    for scene in ["settling", "flutter", "chaotic", "undamped"] {
        for target in [1e-6, 1e-9] {
            let r = ratios
                .iter()
                .find(|r| r["scene"] == scene && num(&r["target_error"]) == target)
                .unwrap_or_else(|| panic!("no peer ratio for {scene} at {target:e}"));
            for key in ["time_ratio", "evals_ratio", "cpu_ratio"] {
                let x = num(&r[key]);
                assert!(x.is_finite() && x > 0.0, "{scene} {target:e} {key} = {x}");
            }
        }
    }
}

#[test]
fn physical_question_and_ladders_are_answered() {
    let (v, _) = quick();
    for p in arr(&v["physical"]) {
        assert!(p["reference"]["kind"].is_string(), "{p}");
        assert!(p["auto"]["fidelity"].is_string(), "{p}");
        assert!(!p["cheapest"].is_null(), "no right answer at all: {p}");
    }
    // Floquet's own error falls as its steps per period grow (evaluation counts, not seconds).
    let f = arr(&v["floquet_convergence"]);
    for w in f.windows(2) {
        if w[0]["k"] == w[1]["k"] && num(&w[0]["error"]) > 1e-12 {
            assert!(
                num(&w[1]["error"]) < num(&w[0]["error"]),
                "{} {}",
                w[0],
                w[1]
            );
        }
    }
    // At k = −0.3 the ladder is ordered as physics §4 says: each cheaper level less accurate.
    let err = |name: &str| {
        arr(&v["stability_criteria"])
            .iter()
            .find(|c| c["k"] == -0.3 && c["criterion"] == name)
            .map(|c| num(&c["error"]))
            .unwrap()
    };
    assert!(err("harmonic_balance") < err("mathieu"));
    assert!(err("mathieu") < err("averaging"));
}

#[test]
fn files_are_written() {
    let (v, dir) = quick();
    let mut names = vec![
        "bench.json".to_string(),
        "report.md".into(),
        "measurements.csv".into(),
        "peer_ratios.csv".into(),
        "stability_criteria.csv".into(),
        "floquet_convergence.csv".into(),
        "physical.csv".into(),
        "averaged_validity.csv".into(),
        "stability-error.png".into(),
        "stability-cost.png".into(),
    ];
    for s in arr(&v["scenes"]) {
        let n = s["name"].as_str().unwrap();
        names.push(format!("wp-time-{n}.png"));
        names.push(format!("wp-evals-{n}.png"));
    }
    for n in &names {
        let len = std::fs::metadata(dir.join(n))
            .unwrap_or_else(|e| panic!("{n}: {e}"))
            .len();
        assert!(len > 100, "{n} is {len} bytes");
    }
    let csv = std::fs::read_to_string(dir.join("measurements.csv")).unwrap();
    assert_eq!(csv.lines().count(), arr(&v["measurements"]).len() + 1);
    // Only this test reads the files.
    let _ = std::fs::remove_dir_all(dir);
}
