//! The `--json` key tables of `docs/cli.md`, compared with what a command prints, so the
//! reference cannot drift from the code.
//!
//! A table belongs to the `### ` heading above it that names a `--json` command. Its first
//! column lists keys in backticks:
//!
//! ```text
//! `r`, `position`        top-level keys; each becomes the context for the rows below it
//! `equilibria[]`         an array ([] is a hint for the reader; arrays are looked through)
//! `.angle_deg`           a key of the context's objects (here equilibria[].angle_deg)
//! `outcome.kind`         a path written out
//! ```
//!
//! Printed and listed are compared both ways: every listed path must be printed by at least one
//! of the runs given, and every printed key must be listed where its parent is the top level or
//! an object with keys listed. An object listed without keys of its own (a simulator outcome
//! inside a bench row, say) is described in prose and is not looked into.

use std::collections::BTreeSet;
use std::path::Path;

use serde_json::Value;

/// `docs/cli.md` as it is in the repository.
pub fn read() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/cli.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// One heading's key table: the paths it lists, dot-separated, arrays looked through.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyTable {
    pub heading: String,
    pub paths: BTreeSet<String>,
}

/// Every `### … --json …` heading's table, in the order of the document.
pub fn key_tables(doc: &str) -> Vec<KeyTable> {
    let mut tables = Vec::new();
    let mut current: Option<KeyTable> = None;
    let mut context = String::new();
    for line in doc.lines() {
        if let Some(h) = line.strip_prefix("### ") {
            tables.extend(current.take());
            if h.contains("--json") {
                current = Some(KeyTable {
                    heading: h.trim().to_string(),
                    paths: BTreeSet::new(),
                });
            }
            continue;
        }
        if line.starts_with("## ") {
            tables.extend(current.take());
            continue;
        }
        let Some(table) = current.as_mut() else {
            continue;
        };
        let Some(first) = first_cell(line) else {
            continue;
        };
        if first == "key" || first.starts_with("---") {
            continue;
        }
        for key in backticked(first) {
            let key = key.replace("[]", "");
            let path = match key.strip_prefix('.') {
                Some(child) => format!("{context}.{child}"),
                None => {
                    context = key.clone();
                    key
                }
            };
            table.paths.insert(path);
        }
    }
    tables.extend(current);
    tables
}

/// The first cell of a table row, or `None` for a line that is not one.
fn first_cell(line: &str) -> Option<&str> {
    let rest = line.trim().strip_prefix('|')?;
    let end = rest.find('|')?;
    Some(rest[..end].trim())
}

fn backticked(cell: &str) -> impl Iterator<Item = &str> {
    cell.split('`').skip(1).step_by(2)
}

/// Every key path `v` prints, with arrays looked through.
pub fn printed(v: &Value) -> BTreeSet<String> {
    fn walk(v: &Value, prefix: &str, out: &mut BTreeSet<String>) {
        match v {
            Value::Object(map) => {
                for (k, child) in map {
                    let path = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    out.insert(path.clone());
                    walk(child, &path, out);
                }
            }
            Value::Array(items) => {
                for item in items {
                    walk(item, prefix, out);
                }
            }
            _ => {}
        }
    }
    let mut out = BTreeSet::new();
    walk(v, "", &mut out);
    out
}

fn parent(path: &str) -> &str {
    path.rfind('.').map_or("", |i| &path[..i])
}

/// What is listed and not printed by any of `runs`, and what is printed and not listed.
pub fn mismatches(table: &KeyTable, runs: &[Value]) -> Vec<String> {
    let printed: BTreeSet<String> = runs.iter().flat_map(printed).collect();
    let mut listed = table.paths.clone();
    let mut looked_into = BTreeSet::from([String::new()]);
    for path in &table.paths {
        let mut p = path.as_str();
        while !p.is_empty() {
            p = parent(p);
            listed.insert(p.to_string());
            looked_into.insert(p.to_string());
        }
    }
    let mut out = Vec::new();
    for path in &table.paths {
        if !printed.contains(path) {
            out.push(format!("listed, not printed: {path}"));
        }
    }
    for path in &printed {
        if looked_into.contains(parent(path)) && !listed.contains(path) {
            out.push(format!("printed, not listed: {path}"));
        }
    }
    out
}

/// Panics with every mismatch between the table under `heading` and `runs`.
pub fn assert_documented(heading: &str, runs: &[Value]) {
    let tables = key_tables(&read());
    let table = tables
        .iter()
        .find(|t| t.heading == heading)
        .unwrap_or_else(|| panic!("docs/cli.md has no key table under ### {heading}"));
    assert!(!table.paths.is_empty(), "### {heading}: an empty table");
    let m = mismatches(table, runs);
    assert!(
        m.is_empty(),
        "docs/cli.md, ### {heading}:\n{}",
        m.join("\n")
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    const DOC: &str = "\
## `tool`

### `tool --json`

| key | meaning |
|---|---|
| `r`, `items[]` | a number; a list |
| `.a`, `.b` | two keys of each item, with a \\| bar |
| `outer.inner` | a path |
| `loose` | an object not looked into |

### `tool other`

| key | meaning |
|---|---|
| `not_json` | ignored: the heading names no --json |
";

    fn table() -> KeyTable {
        let t = key_tables(DOC);
        assert_eq!(t.len(), 1);
        t[0].clone()
    }

    #[test]
    fn rows_become_paths_under_their_context() {
        let want = ["r", "items", "items.a", "items.b", "outer.inner", "loose"];
        assert_eq!(
            table().paths,
            want.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>()
        );
    }

    #[test]
    fn both_directions_are_reported() {
        let v = serde_json::json!({
            "r": 1.0,
            "items": [{"a": 1}, {"a": 2, "c": 3}],
            "outer": {"inner": null},
            "loose": {"anything": 1},
            "extra": true,
        });
        let mut m = mismatches(&table(), &[v]);
        m.sort();
        assert_eq!(
            m,
            [
                "listed, not printed: items.b",
                "printed, not listed: extra",
                "printed, not listed: items.c",
            ]
        );
    }

    #[test]
    fn a_key_printed_by_any_run_counts() {
        let runs = [
            serde_json::json!({"r": 1, "items": [{"a": 1}], "outer": {"inner": 1}, "loose": 1}),
            serde_json::json!({"r": 1, "items": [{"b": 1}], "outer": {"inner": 1}, "loose": 1}),
        ];
        assert!(mismatches(&table(), &runs).is_empty());
    }
}
