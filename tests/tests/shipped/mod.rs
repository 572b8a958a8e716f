//! Runs a shipped scene as a user would, `kapitza simulate scenes/FILE --set … --json`.

use serde_json::Value;

/// The `--json` summary of `scenes/{file}` with each of `sets` given as `--set`.
pub fn simulate(file: &str, sets: &[&str]) -> Value {
    let path = format!("{}/../scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    let mut argv = vec!["kapitza", "simulate", path.as_str(), "--json"];
    for s in sets {
        argv.extend(["--set", s]);
    }
    let mut out = Vec::new();
    kapitza::run(argv, &mut out).unwrap_or_else(|e| panic!("{file} {sets:?}: {e}"));
    serde_json::from_slice(&out).unwrap()
}
