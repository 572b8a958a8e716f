//! Every shipped scene in `scenes/` gives the outcome its `[expect]` table states.
//!
//! The expectations name their sources in each file (closed forms of physics §3, the physics §4.5,
//! Floquet boundaries from `kapitza boundary`); this test runs them exactly as a user would,
//! `kapitza simulate FILE --check`.

use std::path::PathBuf;

fn scenes() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_shipped_scene_meets_its_expectation() {
    let files = scenes();
    // One per outcome kind and per simulable claim of docs/physics.md: guard against the directory emptying.
    assert!(files.len() >= 15, "{} scenes", files.len());
    let mut kinds = std::collections::BTreeSet::new();
    for f in &files {
        let mut out = Vec::new();
        let path = f.to_str().unwrap();
        let result = kapitza::run(["kapitza", "simulate", path, "--check", "--json"], &mut out);
        let v: serde_json::Value =
            serde_json::from_slice(&out).unwrap_or_else(|e| panic!("{path}: {e}"));
        assert!(
            result.is_ok(),
            "{path}: {:?}\n{}",
            result.err().map(|e| e.to_string()),
            v["expect"]
        );
        assert_eq!(v["expect"]["met"], true, "{path}");
        kinds.insert(v["outcome"]["kind"].as_str().unwrap().to_string());
    }
    for kind in ["rest", "flutter", "subharmonic", "rotation", "chaotic"] {
        assert!(kinds.contains(kind), "no shipped scene shows {kind}");
    }
}

/// The example in docs/scenes.md is a scene too, and meets its own `[expect]`.
#[test]
fn the_documented_example_meets_its_expectation() {
    let doc = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/scenes.md"),
    )
    .unwrap();
    let start = doc.find("```toml\n").expect("a toml example") + "```toml\n".len();
    let end = start + doc[start..].find("```").unwrap();
    let dir = std::env::temp_dir().join(format!("kapitza-doc-example-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("example.toml");
    std::fs::write(&file, &doc[start..end]).unwrap();
    let mut out = Vec::new();
    let result = kapitza::run(
        [
            "kapitza",
            "simulate",
            file.to_str().unwrap(),
            "--check",
            "--json",
        ],
        &mut out,
    );
    let _ = std::fs::remove_dir_all(&dir);
    assert!(result.is_ok(), "{}", String::from_utf8_lossy(&out));
}

/// The canonical tilted scene that tests and benchmarks build in code is the shipped file.
#[test]
fn tilted_case_is_the_shipped_file() {
    use kapitza_core::cases::TILTED_135;
    use kapitza_core::sim::scene::{Fidelity, RunLength};
    use kapitza_core::sim::Scene;
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let file = kapitza::scene_file::load(&dir.join("tilted-135.toml"), &[]).unwrap();
    let built = Scene::from_case(&TILTED_135, file.scene.length, Fidelity::Full).unwrap();
    assert_eq!(built, file.scene);
    assert_eq!(file.scene.length, RunLength::Periods(4000.0));
}
