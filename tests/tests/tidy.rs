//! House rules checked by test (rust-analyzer's `tidy.rs`): every source file
//! says what it is in a `//!` module doc, and ARCHITECTURE.md's module maps
//! list every source file, so the map cannot fall behind the code.

use std::path::{Path, PathBuf};

/// The crates whose `src/` the module maps cover.
const CRATES: [&str; 8] = [
    "sym", "designer", "identify", "codegen", "runtime", "cli", "macros", "tests",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// (crate, path relative to its `src/`) of every source file.
fn sources() -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    for krate in CRATES {
        let src = root().join(krate).join("src");
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        files.sort();
        for f in files {
            let rel = f
                .strip_prefix(&src)
                .expect("under src")
                .to_string_lossy()
                .replace('\\', "/");
            out.push((krate, rel));
        }
    }
    out
}

#[test]
fn every_source_file_starts_with_a_module_doc() {
    let missing: Vec<String> = sources()
        .into_iter()
        .filter(|(krate, rel)| {
            let text = std::fs::read_to_string(root().join(krate).join("src").join(rel))
                .expect("readable source");
            !text.trim_start().starts_with("//!")
        })
        .map(|(krate, rel)| format!("{krate}/src/{rel}"))
        .collect();
    assert!(missing.is_empty(), "no `//!` module doc: {missing:?}");
}

#[test]
fn architecture_lists_every_source_file() {
    let map = std::fs::read_to_string(root().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let missing: Vec<String> = sources()
        .into_iter()
        .filter(|(_, rel)| rel != "lib.rs" && rel != "main.rs")
        .filter(|(krate, rel)| {
            let full = format!("`{krate}/src/{rel}`");
            let short = format!("`{rel}`");
            !map.contains(&full) && !map.contains(&short)
        })
        .map(|(krate, rel)| format!("{krate}/src/{rel}"))
        .collect();
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md's module maps do not list: {missing:#?}"
    );
}
