//! Paths of the workspace: its root, the bundled examples, the sorted
//! `*.toml` files of a directory. Paths only; parsing is the caller's.

use std::path::{Path, PathBuf};

/// The workspace root (`examples/`, `tests/data/`, `generated/` live there).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("support/ lies in the workspace")
        .to_path_buf()
}

/// The bundled example `examples/FILE`.
pub fn example_path(file: &str) -> PathBuf {
    root().join("examples").join(file)
}

/// Every bundled example, sorted by file name.
pub fn example_paths() -> Vec<PathBuf> {
    toml_files(&root().join("examples"))
}

/// The `*.toml` files of `dir`, sorted. Panics when the directory cannot be
/// read or holds none: a test over an empty list could not fail.
pub fn toml_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no *.toml in {}", dir.display());
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_root_holds_the_workspace_manifest_and_the_examples() {
        assert!(root().join("Cargo.toml").is_file());
        let examples = example_paths();
        assert!(examples.windows(2).all(|w| w[0] < w[1]), "{examples:?}");
        assert!(examples.contains(&example_path("semera-valve.toml")));
    }

    #[test]
    fn toml_files_keeps_only_toml_files() {
        let dir = crate::TempDir::new("paths");
        dir.write("b.toml", "");
        dir.write("a.toml", "");
        dir.write("c.csv", "");
        dir.write("toml", "");
        assert_eq!(
            toml_files(dir.path()),
            [dir.join("a.toml"), dir.join("b.toml")]
        );
    }

    #[test]
    #[should_panic(expected = "no *.toml")]
    fn an_empty_list_of_toml_files_fails() {
        let dir = crate::TempDir::new("paths-empty");
        toml_files(dir.path());
    }
}
