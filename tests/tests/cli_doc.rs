//! `docs/cli.md` against the commands: every `--json` key table lists exactly the keys its
//! command prints (`kapitza_test_support::cli_doc` says how a table is read). `kapitza bench`'s
//! table is checked beside its quick run in `bench.rs`.

use kapitza::outcome::OutcomeOut;
use kapitza_test_support::cli_doc::{assert_documented, key_tables, read};
use serde_json::{json, Value};

/// `kapitza ARGS…` in-process; its stdout as JSON.
fn run(args: &[&str]) -> Value {
    let mut out = Vec::new();
    kapitza::run(
        std::iter::once("kapitza").chain(args.iter().copied()),
        &mut out,
    )
    .unwrap_or_else(|e| panic!("{args:?}: {e}"));
    serde_json::from_slice(&out).unwrap_or_else(|e| panic!("{args:?}: {e}"))
}

fn data(name: &str) -> String {
    format!("{}/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// The headings checked here and in `bench.rs`: every key table of the document is one of them.
const HEADINGS: [&str; 10] = [
    "`kapitza predict --json`",
    "`kapitza predict --rest-angle DEG --json`",
    "`kapitza boundary --json`",
    "`kapitza boundary --amplitude A --json`",
    "`kapitza chart equilibria --json`",
    "`kapitza chart regions --json`",
    "`kapitza chart stability --json`",
    "`kapitza chart outcomes --json`",
    "`kapitza simulate --json`",
    "`kapitza bench --json`",
];

#[test]
fn every_key_table_is_checked() {
    let doc: Vec<String> = key_tables(&read()).into_iter().map(|t| t.heading).collect();
    assert_eq!(doc, HEADINGS);
}

#[test]
fn predict() {
    assert_documented(
        HEADINGS[0],
        &[
            run(&["predict", "--r", "1.75", "--angle", "90", "--json"]),
            // With a pendulum: `physical` and ωp in rad/s.
            run(&[
                "predict",
                "--rod",
                "0.25",
                "--amplitude",
                "0.0127",
                "--omega",
                "188",
                "--angle",
                "90",
                "--json",
            ]),
        ],
    );
    assert_documented(
        HEADINGS[1],
        &[
            run(&["predict", "--rest-angle", "60", "--json"]),
            run(&["predict", "--rest-angle", "55.15", "--r", "1.75", "--json"]),
        ],
    );
}

#[test]
fn boundary() {
    assert_documented(
        HEADINGS[2],
        &[
            run(&["boundary", "--k", "-0.3", "--json"]),
            // With a pendulum: the ends as amplitudes.
            run(&["boundary", "--rod", "0.25", "--omega", "188", "--json"]),
        ],
    );
    assert_documented(
        HEADINGS[3],
        &[
            // m = A/ℓ = 0.0127/0.1667 = 0.076: no flutter; 0.09/0.1667 = 0.54 > 0.454 flutters.
            run(&[
                "boundary",
                "--rod",
                "0.25",
                "--amplitude",
                "0.0127",
                "--json",
            ]),
            run(&["boundary", "--rod", "0.25", "--amplitude", "0.09", "--json"]),
        ],
    );
}

#[test]
fn charts() {
    let dir = tempfile_dir("charts");
    let out = dir.to_str().unwrap();
    assert_documented(
        HEADINGS[4],
        &[run(&["chart", "equilibria", "--json", "--out", out])],
    );
    assert_documented(
        HEADINGS[5],
        &[run(&[
            "chart", "regions", "--size", "9x5", "--json", "--out", out,
        ])],
    );
    assert_documented(
        HEADINGS[6],
        &[
            run(&[
                "chart",
                "stability",
                "--size",
                "8x6",
                "--json",
                "--out",
                out,
            ]),
            run(&[
                "chart",
                "stability",
                "--rod",
                "0.25",
                "--omega",
                "188",
                "--amplitude",
                "0.0127",
                "--size",
                "8x6",
                "--json",
                "--out",
                out,
            ]),
        ],
    );
    let scene = data("sim_averaged_rest.toml");
    let outcomes = |extra: &[&str]| {
        let mut args = vec![
            "chart",
            "outcomes",
            scene.as_str(),
            "--x",
            "drive.angle_deg=120..150",
            "--y",
            "drive.r=2.5..3",
            "--size",
            "2x2",
            "--json",
            "--out",
            out,
        ];
        args.extend_from_slice(extra);
        run(&args)
    };
    assert_documented(HEADINGS[7], &[outcomes(&[]), outcomes(&["--shard", "1/2"])]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn simulate() {
    // One real run (an averaged rest with an `[expect]`), and the outcome of every kind as the
    // command serialises it, since no one cheap scene ends in all seven.
    let real = run(&["simulate", &data("sim_averaged_rest.toml"), "--json"]);
    let kinds = [
        OutcomeOut::Rest { angle_deg: 1.0 },
        OutcomeOut::Flutter { angle_deg: 1.0 },
        OutcomeOut::Subharmonic {
            order: 4,
            angle_deg: 1.0,
        },
        OutcomeOut::Rotation {
            direction: 1,
            turns: 1,
            periods: 2,
        },
        OutcomeOut::Chaotic { lyapunov: 1.0 },
        OutcomeOut::Oscillation {
            angle_deg: 1.0,
            amplitude_deg: 1.0,
        },
        OutcomeOut::Undecided {
            reason: "why".into(),
            lyapunov: None,
        },
    ];
    let mut runs = vec![real];
    runs.extend(kinds.iter().map(|k| json!({ "outcome": k })));
    assert_documented(HEADINGS[8], &runs);
}

fn tempfile_dir(what: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("kapitza-cli-doc-{what}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
