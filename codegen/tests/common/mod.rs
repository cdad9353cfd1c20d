//! Helpers shared by the tests that compile emitted code in a scratch crate.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace's target directory (scratch crates build under it, so they
/// reuse compiled dependencies).
pub fn workspace_target() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(t) => PathBuf::from(t),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../target"),
    }
}

/// Writes `text` unless the file already holds it (keeps cargo's fingerprints).
pub fn write_if_changed(path: &Path, text: &str) {
    if std::fs::read_to_string(path).ok().as_deref() != Some(text) {
        std::fs::write(path, text).unwrap();
    }
}

/// Runs cargo in the scratch crate `dir`; panics with stderr on failure.
pub fn cargo(dir: &Path, args: &[&str]) -> std::process::Output {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(args)
        .current_dir(dir)
        .env(
            "CARGO_TARGET_DIR",
            workspace_target().join("codegen-check-target"),
        )
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "cargo {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The lints that define "panic-free" for emitted code: clippy on the
/// scratch crate's library with these denied.
pub const PANIC_FREE_LINTS: [&str; 6] = [
    "warnings",
    "clippy::unwrap_used",
    "clippy::expect_used",
    "clippy::indexing_slicing",
    "clippy::panic",
    "clippy::as_conversions",
];

/// Runs clippy on the scratch crate `dir` with [`PANIC_FREE_LINTS`] denied.
pub fn clippy_panic_free(dir: &Path) {
    let mut args = vec!["clippy", "--offline", "--lib", "--"];
    for lint in PANIC_FREE_LINTS {
        args.extend(["-D", lint]);
    }
    cargo(dir, &args);
}
