//! Scene files: TOML text → the core's [`Scene`], the run options and the `[expect]` table.
//!
//! Reading goes in three steps, each with errors that name the file and the key:
//! 1. the text parses as TOML into a table (syntax errors carry the line);
//! 2. `--set KEY=VALUE` overrides are written into that table at their dotted paths;
//! 3. the table deserialises into raw structs (`deny_unknown_fields` everywhere, so a misspelt key
//!    or an unknown effect is an error listing the allowed ones), which are converted to SI units
//!    and radians and checked: by hand where two keys interact, by [`Scene::check`] for ranges,
//!    and by the fidelity decision, so that nothing runs on a bad scene.
//!
//! The keys, their units, defaults and ranges are documented in `docs/scenes.md`.
//!
//! | module | step |
//! |---|---|
//! | [`set`] | `--set KEY=VALUE` written into the parsed table |
//! | [`raw`] | the file as written: serde structs mirroring the TOML |
//! | [`convert`] | raw → SI units, radians, the core's types, checked |

mod convert;
mod raw;
mod set;

pub(crate) use convert::{out_of_range, pendulum};
pub(crate) use raw::{RawEnvironment, RawPendulum};
pub use set::apply_set;

use anyhow::{anyhow, Context, Result};
use std::path::Path;

use crate::outcome::Expect;
use convert::convert;
use kapitza_core::sim::{Controller, Format, Method, Scene};
use raw::RawScene;
use set::within;

/// RK4 steps per drive period when `run.steps_per_period` is not given.
pub const DEFAULT_RK4_STEPS: f64 = 200.0;

/// A loaded, checked scene file.
#[derive(Debug, Clone)]
pub struct SceneFile {
    /// `title`, or the file's stem when the file has none.
    pub title: String,
    pub scene: Scene,
    pub method: Method,
    /// The adaptive method's step controller (`run.controller`).
    pub controller: Controller,
    pub format: Format,
    /// Seed of the sensor noise.
    pub seed: u64,
    pub expect: Option<Expect>,
}

/// Reads, overrides (`sets`: `KEY=VALUE` strings) and checks a scene file.
pub fn load(path: &Path, sets: &[String]) -> Result<SceneFile> {
    let name = path.display().to_string();
    let text = crate::files::read_input("the scene file", path)?;
    let stem = path
        .file_stem()
        .map_or_else(|| name.clone(), |s| s.to_string_lossy().into_owned());
    parse(&text, &name, &stem, sets)
}

/// [`load`] on text already read: `name` prefixes every error, `stem` is the default title.
pub fn parse(text: &str, name: &str, stem: &str, sets: &[String]) -> Result<SceneFile> {
    let mut table: toml::Table = toml::from_str(text)
        .map_err(|e| anyhow!("{}", e.to_string().trim_end()))
        .with_context(|| format!("{name}: not valid TOML"))?;
    let mut set_keys = Vec::new();
    for s in sets {
        set_keys.push(apply_set(&mut table, s).with_context(|| name.to_string())?);
    }
    let raw: RawScene =
        serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
            let path = e.path().to_string();
            let origin = set_keys
                .iter()
                .find(|(k, _)| within(&path, k) || within(k, &path))
                .map_or(String::new(), |(_, s)| format!(" (from --set {s})"));
            let at = if path == "." {
                String::new()
            } else {
                format!("{path}: ")
            };
            anyhow!("{name}: {at}{}{origin}", e.inner().message().trim_end())
        })?;
    convert(raw, stem).with_context(|| name.to_string())
}
