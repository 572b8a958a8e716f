//! `kapitza chart`, run in-process: each chart's `--json` data against independent values —
//! closed forms, `kapitza boundary`, and the published numbers of docs/stability.md.

use serde_json::Value;

fn run_json(args: &[&str]) -> Value {
    let dir = tempfile::tempdir().unwrap();
    let mut argv = vec!["kapitza", "chart"];
    argv.extend_from_slice(args);
    let out_dir = dir.path().to_str().unwrap().to_string();
    argv.extend_from_slice(&["--json", "--out", &out_dir]);
    let mut out = Vec::new();
    kapitza::run(argv, &mut out).unwrap_or_else(|e| panic!("{args:?}: {e}"));
    // The pictures and the data were written beside the JSON.
    let stem = args[0];
    for ext in ["png", "svg"] {
        let f = dir.path().join(format!("{stem}.{ext}"));
        assert!(f.metadata().unwrap().len() > 1000, "{}", f.display());
    }
    serde_json::from_slice(&out).unwrap()
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Closed form of the saddle-node curve (physics §3).
fn r_sn(deg: f64) -> f64 {
    let (s, c) = deg.to_radians().sin_cos();
    (s.abs().powf(2.0 / 3.0) + c.abs().powf(2.0 / 3.0)).powf(1.5)
}

#[test]
fn regions_band_ends_lie_on_the_saddle_node_curve() {
    // For 1 < R < 2 the band without a reachable stable equilibrium is found by scanning the
    // equilibria; its ends must be the roots of the closed form R_sn(θd) = R (to 1e-8 in R:
    // the ends are bisected to 1e-10°) and symmetric about 135° (R_sn(270° − θ) = R_sn(θ)).
    let v = run_json(&[
        "regions",
        "--r",
        "0.5,1,1.2,1.75,1.99,2,3",
        "--size",
        "37x31",
    ]);
    for b in v["bands"].as_array().unwrap() {
        let r = num(&b["r"]);
        if r <= 1.0 || r >= 2.0 {
            assert!(b["from_deg"].is_null() && b["to_deg"].is_null(), "{b}");
            continue;
        }
        let (f, t) = (num(&b["from_deg"]), num(&b["to_deg"]));
        assert!(90.0 < f && f < 135.0 && 135.0 < t && t < 180.0, "{b}");
        assert!((r_sn(f) - r).abs() < 1e-8, "R {r}: R_sn({f}) = {}", r_sn(f));
        assert!((r_sn(t) - r).abs() < 1e-8, "R {r}: R_sn({t}) = {}", r_sn(t));
        assert!((f + t - 270.0).abs() < 1e-8, "{b}");
    }
    // The saddle-node samples are the closed form (1e-10: the plain cos 90° here is 6e-17, and
    // its 2/3 power 1.5e-11, where the model reduces quadrants exactly).
    for p in v["saddle_node"].as_array().unwrap() {
        let (th, r) = (num(&p[0]), num(&p[1]));
        assert!((r - r_sn(th)).abs() < 1e-10 * r, "{p}");
    }
}

#[test]
fn equilibria_chart_matches_the_closed_forms() {
    // physics §3: θd = 90°, R > 1: stable φ0 = ±arccos(1/R), +55.15° within 90° of the drive;
    // θd = 180°, R > 1: inverted stable; θd = 0°: hanging stable.
    let v = run_json(&["equilibria", "--r", "1.75", "--samples", "9"]);
    let at = |th: f64| -> Vec<(f64, String, bool)> {
        v["equilibria"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|p| num(&p["drive_angle_deg"]) == th)
            .map(|p| {
                (
                    num(&p["angle_deg"]),
                    p["stability"].as_str().unwrap().to_string(),
                    p["within_90_of_drive"].as_bool().unwrap(),
                )
            })
            .collect()
    };
    let want = (1.0f64 / 1.75).acos().to_degrees();
    let stable90: Vec<_> = at(90.0).into_iter().filter(|e| e.1 == "stable").collect();
    assert_eq!(stable90.len(), 2);
    assert!(stable90.iter().any(|e| (e.0 - want).abs() < 1e-9 && e.2));
    assert!(stable90.iter().any(|e| (e.0 + want).abs() < 1e-9 && !e.2));
    assert!(at(180.0).iter().any(|e| e.0 == 180.0 && e.1 == "stable"));
    assert!(at(0.0).iter().any(|e| e.0 == 0.0 && e.1 == "stable"));
    // The pendulum form converts to R (physics §4.5: the demo rod gives R = 1.7433).
    let v = run_json(&[
        "equilibria",
        "--rod",
        "0.25",
        "--amplitude",
        "0.0127",
        "--omega",
        "188",
        "--samples",
        "5",
    ]);
    assert!((num(&v["r"][0]) - 1.7433).abs() < 5e-5);
}

fn record<'a>(v: &'a Value, k: f64, criterion: &str, window: u64) -> &'a Value {
    v["boundaries"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| num(&b["k"]) == k && b["criterion"] == criterion && b["window"] == window)
        .unwrap_or_else(|| panic!("no record k {k} {criterion} {window}"))
}

fn boundary(args: &[&str]) -> Value {
    let mut argv = vec!["kapitza", "boundary", "--json"];
    argv.extend_from_slice(args);
    let mut out = Vec::new();
    kapitza::run(argv, &mut out).unwrap();
    serde_json::from_slice(&out).unwrap()
}

#[test]
fn stability_chart_agrees_with_boundary_and_the_published_values() {
    // Both spellings of a negative range parse.
    let v = run_json(&[
        "stability",
        "--k-range=-0.5..0.5",
        "--m-range",
        "0..2",
        "--size",
        "11x21",
    ]);
    let _ = run_json(&["stability", "--k-range", "-0.5..0.5", "--size", "3x3"]);
    let ks: Vec<f64> = v["boundaries"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| num(&b["k"]))
        .collect();
    // Every sampled k has a record from each criterion.
    for k in &ks {
        for c in ["averaging", "mathieu", "harmonic_balance", "floquet"] {
            record(&v, *k, c, 0);
        }
    }
    for want_k in [-0.5, -0.3, 0.0, 0.1] {
        let k = *ks.iter().find(|k| (**k - want_k).abs() < 1e-12).unwrap();
        let b = boundary(&["--k", &k.to_string()]);
        for c in b["criteria"].as_array().unwrap() {
            let r = record(&v, k, c["name"].as_str().unwrap(), 0);
            for end in ["lower_m", "upper_m"] {
                match (c[end].as_f64(), r[end].as_f64()) {
                    // boundary bisects to its --tol 1e-7; the chart to 1e-9.
                    (Some(a), Some(b)) => assert!((a - b).abs() < 2e-7, "k {k} {c} {r}"),
                    (a, b) => assert_eq!(a.is_some(), b.is_some(), "k {k} {c} {r}"),
                }
            }
        }
    }
    // docs/stability.md (Floquet, 6 decimals): k = −0.3: 0.868094, 0.928677; k = −0.5:
    // 1.191816, 1.222613; k = 0: upper 0.454023. Tolerance: half the last printed unit.
    for (k, lo, up) in [
        (-0.3, Some(0.868094), 0.928677),
        (-0.5, Some(1.191816), 1.222613),
        (0.0, None, 0.454023),
    ] {
        let k = *ks.iter().find(|x| (**x - k).abs() < 1e-12).unwrap();
        let r = record(&v, k, "floquet", 0);
        if let Some(lo) = lo {
            assert!((num(&r["lower_m"]) - lo).abs() < 5e-7, "{r}");
        }
        assert!((num(&r["upper_m"]) - up).abs() < 5e-7, "{r}");
        // Averaging is the closed form √(−2k).
        if k < 0.0 {
            let a = record(&v, k, "averaging", 0);
            assert!((num(&a["lower_m"]) - (-2.0 * k).sqrt()).abs() < 1e-15);
        }
    }
    // Order-8 threshold at k = −0.3: Floquet 0.877173 (docs/stability.md), harmonic balance
    // 0.8773 (physics §4.5).
    let k = *ks.iter().find(|x| (**x + 0.3).abs() < 1e-12).unwrap();
    for (criterion, want, tol) in [
        ("floquet", 0.877173, 5e-7),
        ("harmonic_balance", 0.8773, 5e-5),
    ] {
        let s = v["subharmonics"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| num(&s["k"]) == k && s["order"] == 8 && s["criterion"] == criterion)
            .unwrap();
        assert!((num(&s["m"]) - want).abs() < tol, "{s}");
    }
}

#[test]
fn stability_chart_hanging_windows_are_numbered() {
    // k = 0.6 (a = 2.4): several stable windows in m ∈ [0, 4], numbered from 0 upward; the
    // first starts at m = 0 (the hanging position is stable without drive).
    let v = run_json(&[
        "stability",
        "--k-range",
        "0.5..0.6",
        "--m-range",
        "0..4",
        "--size",
        "2x3",
    ]);
    let w0 = record(&v, 0.6, "floquet", 0);
    assert_eq!(num(&w0["lower_m"]), 0.0);
    let w1 = record(&v, 0.6, "floquet", 1);
    assert!(num(&w1["lower_m"]) > num(&w0["upper_m"]));
}

#[test]
fn stability_chart_pendulum_form_matches_boundary() {
    // physics §4 (Landau): point mass l = 1 m, ω = 9 rad/s: Floquet's lower end A = 0.5173 m
    // (docs/stability.md); the chart's record at ω = 9 equals `boundary --point 1 --omega 9`.
    let v = run_json(&[
        "stability",
        "--point",
        "1",
        "--omega-range",
        "5..15",
        "--amplitude-range",
        "0..1",
        "--size",
        "11x11",
        "--omega",
        "9",
        "--amplitude",
        "0.6",
    ]);
    let r = v["boundaries"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| num(&b["omega"]) == 9.0 && b["criterion"] == "floquet")
        .unwrap();
    let b = boundary(&["--point", "1", "--omega", "9"]);
    let f = b["criteria"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "floquet")
        .unwrap();
    assert!((num(&r["lower_amplitude"]) - num(&f["lower_amplitude"])).abs() < 2e-7);
    assert!((num(&r["lower_amplitude"]) - 0.5173).abs() < 5e-5);
}

#[test]
fn outcome_shards_merge_into_the_whole_map() {
    // Three shards of a 5×4 outcome map, merged, give exactly the cells (outcomes, angles,
    // orders) of the map computed in one run; only the measured wall times differ.
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/sim_averaged_rest.toml"
    );
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let base = [
        "kapitza",
        "chart",
        "outcomes",
        scene,
        "--x",
        "drive.angle_deg=0..180",
        "--y",
        "drive.r=0.5..3",
        "--size",
        "5x4",
        "--json",
        "--out",
    ];
    let run = |extra: &[&str], out_dir: &str| -> Value {
        let mut argv: Vec<&str> = base.to_vec();
        argv.push(out_dir);
        argv.extend_from_slice(extra);
        let mut out = Vec::new();
        kapitza::run(argv, &mut out).unwrap();
        serde_json::from_slice(&out).unwrap()
    };
    let whole = run(&[], &format!("{d}/whole"));
    for i in 0..3 {
        run(&["--shard", &format!("{i}/3")], &format!("{d}/shards"));
    }
    let shard = |i: usize| format!("{d}/shards/outcomes-shard-{i}-of-3.json");
    let (s0, s1, s2) = (shard(0), shard(1), shard(2));
    let mut out = Vec::new();
    kapitza::run(
        [
            "kapitza",
            "chart",
            "merge",
            &s2,
            &s0,
            &s1,
            "--json",
            "--out",
            &format!("{d}/merged"),
        ],
        &mut out,
    )
    .unwrap();
    let merged: Value = serde_json::from_slice(&out).unwrap();
    let strip = |v: &Value| -> Vec<Value> {
        v["cells"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                let mut c = c.clone();
                c.as_object_mut().unwrap().remove("wall_s");
                c
            })
            .collect()
    };
    assert_eq!(strip(&whole).len(), 20);
    assert_eq!(strip(&whole), strip(&merged));
    assert!(std::path::Path::new(&format!("{d}/merged/outcomes.png")).exists());
    // A missing shard is refused, naming it.
    let err = kapitza::run(
        [
            "kapitza",
            "chart",
            "merge",
            &s0,
            &s2,
            "--out",
            &format!("{d}/bad"),
        ],
        &mut Vec::new(),
    )
    .expect_err("must refuse")
    .to_string();
    assert!(err.contains("shard 1/3 is missing"), "{err}");
}
