//! Atomic file output: write next to the target, then rename, so a failed or
//! interrupted command never leaves a half-written file behind.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes several files together: each goes to a temporary next to its target
/// first (missing directories are created); only when every temporary is
/// complete are they renamed into place. A failure leaves every existing
/// target as it was and removes the temporaries.
pub fn write_all(files: &[(&Path, &[u8])]) -> Result<(), String> {
    let mut staged: Vec<(PathBuf, &Path)> = Vec::new();
    let cleanup = |staged: &[(PathBuf, &Path)]| {
        for (tmp, _) in staged {
            let _ = std::fs::remove_file(tmp);
        }
    };
    for &(path, bytes) in files {
        match stage(path, bytes) {
            Ok(tmp) => staged.push((tmp, path)),
            Err(e) => {
                cleanup(&staged);
                return Err(e);
            }
        }
    }
    for (k, (tmp, path)) in staged.iter().enumerate() {
        if let Err(e) = std::fs::rename(tmp, path) {
            cleanup(&staged[k..]);
            return Err(format!("{}: cannot write: {e}", path.display()));
        }
    }
    Ok(())
}

/// Writes `bytes` to a temporary next to `path`; returns the temporary's path.
fn stage(path: &Path, bytes: &[u8]) -> Result<PathBuf, String> {
    if path.is_dir() {
        return Err(format!(
            "{}: cannot write: it is a directory",
            path.display()
        ));
    }
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .ok_or_else(|| format!("{}: not a file path", path.display()))?;
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("{}: cannot create the directory: {e}", dir.display()))?;
    let tmp = dir.join(format!(
        ".{}.tmp{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })();
    match result {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(format!("{}: cannot write: {e}", path.display()))
        }
    }
}
