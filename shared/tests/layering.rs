//! The crate's written layering holds: every module imports only from modules listed above it in
//! the module map of `src/lib.rs` (so there is no cycle between modules). Comments and doc links
//! are not imports; test code counts, since a test that reaches up a layer ties the layers too.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

const SRC: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/src");

/// The module map's rows, top to bottom, as `lib.rs` lists them: "| [`name`] | … |".
fn rows() -> Vec<String> {
    let lib = fs::read_to_string(Path::new(SRC).join("lib.rs")).unwrap();
    lib.lines()
        .filter_map(|l| l.strip_prefix("//! | [`"))
        .filter_map(|l| l.split_once("`]"))
        .map(|(name, _)| name.to_string())
        .collect()
}

fn files_of(module: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let file = Path::new(SRC).join(format!("{module}.rs"));
    if file.exists() {
        out.push(file);
    }
    let mut dirs = vec![Path::new(SRC).join(module)];
    while let Some(dir) = dirs.pop() {
        let Ok(entries) = fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out
}

/// The top-level modules a source file's code (not its comments) names as `crate::<module>`.
fn imports(source: &str) -> Vec<String> {
    let mut found = Vec::new();
    for line in source.lines() {
        let code = match line.find("//") {
            Some(at) => &line[..at],
            None => line,
        };
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            let tail = &rest[at + "crate::".len()..];
            let name: String = tail
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                found.push(name);
            }
            rest = tail;
        }
    }
    found
}

#[test]
fn every_module_imports_only_from_rows_above_it() {
    let rows = rows();
    assert!(
        rows.len() >= 10,
        "the module map of lib.rs was not found: {rows:?}"
    );
    let mut rank: BTreeMap<String, usize> = rows
        .iter()
        .enumerate()
        .map(|(i, m)| (m.clone(), i))
        .collect();
    // The crate root's re-exports (`pub use error::ParamError;`) rank as their module.
    let lib = fs::read_to_string(Path::new(SRC).join("lib.rs")).unwrap();
    for line in lib.lines() {
        if let Some((module, name)) = line
            .strip_prefix("pub use ")
            .and_then(|l| l.trim_end_matches(';').split_once("::"))
        {
            let r = rank[module];
            rank.insert(name.to_string(), r);
        }
    }
    let mut violations = Vec::new();
    for (row, module) in rows.iter().enumerate() {
        let files = files_of(module);
        assert!(
            !files.is_empty(),
            "module map lists `{module}`, which has no source"
        );
        for file in files {
            let source = fs::read_to_string(&file).unwrap();
            for used in imports(&source) {
                if used == *module {
                    continue;
                }
                match rank.get(used.as_str()) {
                    Some(&r) if r < row => {}
                    Some(_) => violations.push(format!(
                        "{} (row `{module}`) imports `{used}`, which is not above it",
                        file.strip_prefix(SRC).unwrap().display()
                    )),
                    None => violations.push(format!(
                        "{} imports `{used}`, which the module map does not list",
                        file.strip_prefix(SRC).unwrap().display()
                    )),
                }
            }
        }
    }
    assert!(
        violations.is_empty(),
        "layering broken:\n{}",
        violations.join("\n")
    );
}

#[test]
fn the_module_map_lists_every_module() {
    let lib = fs::read_to_string(Path::new(SRC).join("lib.rs")).unwrap();
    let declared: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod "))
        .map(|l| l.trim_end_matches(';'))
        .collect();
    let mut listed = rows();
    listed.sort();
    let mut declared: Vec<String> = declared.iter().map(|s| s.to_string()).collect();
    declared.sort();
    assert_eq!(
        listed, declared,
        "lib.rs's module map and its `pub mod` lines differ"
    );
}
