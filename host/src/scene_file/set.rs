//! `--set KEY=VALUE`: an override written into the parsed table at its dotted path, before the
//! table is read, so an override is checked exactly like the file's own keys.

use anyhow::{bail, Result};

/// Whether the dotted path `inner` is `outer` or lies under it.
pub(super) fn within(inner: &str, outer: &str) -> bool {
    inner
        .strip_prefix(outer)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with('.'))
}

/// Writes one `--set KEY=VALUE` into the table; returns the key and the assignment.
///
/// VALUE is a TOML value (`120`, `1e-3`, `true`, `"quoted string"`, `{ q = 50 }`); a bare word
/// that is not a TOML value (`full`, `dop853`) is taken as a string; an empty VALUE removes the
/// key (if it is there).
pub fn apply_set(table: &mut toml::Table, assignment: &str) -> Result<(String, String)> {
    let Some((key, text)) = assignment.split_once('=') else {
        bail!("--set {assignment}: expected KEY=VALUE, e.g. --set drive.angle_deg=120");
    };
    let (key, text) = (key.trim(), text.trim());
    let parts: Vec<&str> = key.split('.').collect();
    let bare = |s: &str| {
        !s.is_empty()
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    };
    if !parts.iter().all(|p| bare(p)) {
        bail!("--set {assignment}: key `{key}` is not a dotted path of bare keys (like effects.viscous.q)");
    }
    let (last, path) = parts.split_last().expect("split yields at least one part");
    if text.is_empty() {
        // KEY= removes the key, e.g. to give omega in a scene that gives r.
        let mut here = Some(&mut *table);
        for part in path {
            here = here
                .and_then(|t| t.get_mut(*part))
                .and_then(|v| v.as_table_mut());
        }
        if let Some(t) = here {
            t.remove(*last);
        }
        return Ok((key.to_string(), assignment.to_string()));
    }
    let value = match toml::from_str::<toml::Table>(&format!("v = {text}")) {
        Ok(mut t) if t.len() == 1 => t.remove("v").expect("the one key is v"),
        _ if bare(text) => toml::Value::String(text.to_string()),
        _ => bail!(
            "--set {assignment}: `{text}` is not a TOML value (numbers, true/false, \"quoted strings\", {{ inline = tables }}; a bare word is a string)"
        ),
    };
    let mut here = table;
    for (i, part) in path.iter().enumerate() {
        let entry = here
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        here = match entry {
            toml::Value::Table(t) => t,
            other => bail!(
                "--set {assignment}: `{}` is a {}, not a table, so it has no key `{}`",
                parts[..=i].join("."),
                other.type_str(),
                parts[i + 1]
            ),
        };
    }
    here.insert(last.to_string(), value);
    Ok((key.to_string(), assignment.to_string()))
}
