//! A fresh directory per test under the system temp dir, removed on drop,
//! so that parallel tests never share files and a run leaves nothing behind.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// `$TMPDIR/reldesign-TAG-PID-N`, created empty, removed with its contents
/// when dropped.
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("reldesign-{tag}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir)
            .unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
        TempDir(dir)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }

    pub fn join(&self, name: impl AsRef<Path>) -> PathBuf {
        self.0.join(name)
    }

    /// Writes `contents` to `NAME` in the directory; returns its path.
    pub fn write(&self, name: impl AsRef<Path>, contents: impl AsRef<[u8]>) -> PathBuf {
        let path = self.join(name);
        std::fs::write(&path, contents)
            .unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
        path
    }

    /// Names of the files in the directory, sorted (see [`files_in`]).
    pub fn files(&self) -> Vec<String> {
        files_in(&self.0)
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Names of the files in `dir`, sorted; hidden ones included, so that the
/// leftover temporary file of an atomic write shows up.
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| {
            e.expect("directory entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_temp_dir_is_fresh_and_removed_on_drop() {
        let (a, b) = (TempDir::new("temp"), TempDir::new("temp"));
        assert_ne!(a.path(), b.path());
        assert!(a.files().is_empty());
        let file = a.write(".hidden", "x");
        a.write("sub", [0u8, 1]);
        assert_eq!(a.files(), [".hidden", "sub"]);
        assert_eq!(std::fs::read_to_string(file).unwrap(), "x");
        let path = a.path().to_path_buf();
        drop(a);
        assert!(!path.exists(), "{} survived the drop", path.display());
        assert!(b.path().is_dir());
    }
}
