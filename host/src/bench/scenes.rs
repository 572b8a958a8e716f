//! The scenes the bench measures: shipped scene files, embedded at compile time so the command
//! runs from any directory, with the horizon (and for the long run, the damping) changed through
//! the same `--set` overrides `kapitza simulate` accepts.

use anyhow::{Context, Result};
use kapitza_core::sim::scene::{Fidelity, FidelityChoice, RunLength};
use kapitza_core::sim::Scene;

use crate::scene_file;

/// One scene of the bench.
#[derive(Debug, Clone)]
pub struct BenchScene {
    /// Short name used in files and tables.
    pub name: &'static str,
    /// The shipped file it comes from.
    pub file: &'static str,
    /// What it tests, for the report.
    pub what: &'static str,
    /// The `--set` overrides applied to the file for the error and time measurements.
    pub sets: Vec<String>,
    /// The scene of the error and time measurements (full model, the bench horizon).
    pub scene: Scene,
    /// The scene of the physical question (outcome kind and resting angle): as shipped, except
    /// the chaotic scene's length (see [`Horizons::chaotic_physical`]) and the undamped run's.
    pub physical: Scene,
    /// The scene exactly as shipped.
    pub shipped: Scene,
    /// The `--set` overrides of `physical`.
    pub physical_sets: Vec<String>,
    /// Whether the scene has no damping (symplectic methods apply).
    pub undamped: bool,
}

impl BenchScene {
    /// The measurement scene with another fidelity.
    pub fn with_fidelity(&self, fidelity: Fidelity) -> Scene {
        Scene {
            fidelity: FidelityChoice::Fixed(fidelity),
            ..self.scene
        }
    }

    /// Simulated seconds of the measurement scene.
    pub fn horizon(&self) -> f64 {
        let omega = self.scene.physical().map_or(1.0, |p| p.omega);
        self.scene.duration(omega)
    }

    /// Drive periods of the measurement scene.
    pub fn periods(&self) -> f64 {
        match self.scene.length {
            RunLength::Periods(p) => p,
            RunLength::Duration(s) => {
                let omega = self.scene.physical().map_or(1.0, |p| p.omega);
                s * omega / std::f64::consts::TAU
            }
        }
    }
}

const TILTED: &str = include_str!("../../../scenes/tilted-135.toml");
const FLUTTER: &str = include_str!("../../../scenes/flutter.toml");
const CHAOTIC: &str = include_str!("../../../scenes/chaotic.toml");

/// How long each scene runs for the error and time measurements.
#[derive(Debug, Clone, Copy)]
pub struct Horizons {
    /// Drive periods of the settling scene (shipped: 4000).
    pub settling: u32,
    /// Drive periods of the flutter scene (shipped: 3000).
    pub flutter: u32,
    /// Seconds of the chaotic scene: well inside the predictability time (see the report).
    pub chaotic_s: f64,
    /// Drive periods of the long undamped run.
    pub undamped: u32,
    /// Drive periods of the undamped run's physical question (classification).
    pub undamped_physical: u32,
    /// Drive periods of the chaotic scene's physical question: short enough that converged runs
    /// agree on the kind (at the shipped 4000 the tumbling may lock into rotation, and when
    /// depends on the tolerance: see `physical::chaotic_fate`).
    pub chaotic_physical: u32,
}

fn load(text: &str, file: &'static str, sets: &[String]) -> Result<Scene> {
    let stem = file
        .rsplit('/')
        .next()
        .and_then(|f| f.strip_suffix(".toml"))
        .unwrap_or(file);
    let loaded = scene_file::parse(text, file, stem, sets)
        .with_context(|| format!("bench scene from {file}"))?;
    Ok(loaded.scene)
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// The four scenes of the bench: settling, flutter, chaotic, long undamped.
pub fn scenes(h: Horizons) -> Result<Vec<BenchScene>> {
    let full = "run.fidelity=full";
    let mut out = Vec::new();

    let sets = strings(&[full, &format!("run.periods={}", h.settling)]);
    out.push(BenchScene {
        name: "settling",
        file: "scenes/tilted-135.toml",
        what: "smooth settling to the tilted equilibrium (R ≈ 3.3 at θd = 135°, Q = 20)",
        scene: load(TILTED, "scenes/tilted-135.toml", &sets)?,
        physical: load(TILTED, "scenes/tilted-135.toml", &[])?,
        shipped: load(TILTED, "scenes/tilted-135.toml", &[])?,
        physical_sets: Vec::new(),
        sets,
        undamped: false,
    });

    let sets = strings(&[full, &format!("run.periods={}", h.flutter)]);
    out.push(BenchScene {
        name: "flutter",
        file: "scenes/flutter.toml",
        what: "the flutter (period-2) mode about the inverted position (m = 0.475, Q = 20)",
        scene: load(FLUTTER, "scenes/flutter.toml", &sets)?,
        physical: load(FLUTTER, "scenes/flutter.toml", &[])?,
        shipped: load(FLUTTER, "scenes/flutter.toml", &[])?,
        physical_sets: Vec::new(),
        sets,
        undamped: false,
    });

    let sets = strings(&[
        full,
        "run.periods=",
        &format!("run.duration={}", h.chaotic_s),
    ]);
    let physical_sets = strings(&[&format!("run.periods={}", h.chaotic_physical)]);
    out.push(BenchScene {
        name: "chaotic",
        file: "scenes/chaotic.toml",
        what: "chaotic tumbling (k = −0.3, m = 0.875, Q = 200), over a horizon shorter than the predictability time",
        scene: load(CHAOTIC, "scenes/chaotic.toml", &sets)?,
        physical: load(CHAOTIC, "scenes/chaotic.toml", &physical_sets)?,
        shipped: load(CHAOTIC, "scenes/chaotic.toml", &[])?,
        physical_sets,
        sets,
        undamped: false,
    });

    let undamped = |periods: u32| {
        strings(&[
            full,
            "effects.viscous=",
            "expect=",
            &format!("run.periods={periods}"),
        ])
    };
    let sets = undamped(h.undamped);
    let physical_sets = undamped(h.undamped_physical);
    out.push(BenchScene {
        name: "undamped",
        file: "scenes/tilted-135.toml",
        what: "an undamped run: the tilted scene without damping, oscillating ±16° about 117.5° for hundreds of drive periods",
        scene: load(TILTED, "scenes/tilted-135.toml", &sets)?,
        physical: load(TILTED, "scenes/tilted-135.toml", &physical_sets)?,
        shipped: load(TILTED, "scenes/tilted-135.toml", &[])?,
        physical_sets,
        sets,
        undamped: true,
    });
    Ok(out)
}
