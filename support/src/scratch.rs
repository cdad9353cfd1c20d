//! Scratch crates, for tests that compile emitted code: a package under the
//! workspace's target directory that depends on `reldesign-runtime` by path
//! and starts from the workspace's `Cargo.lock` (the same `libm`, offline).
//! All of them build into one shared target directory, so the runtime and
//! its dependencies compile once; files are written only when they change,
//! so cargo's fingerprints survive a rerun.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::paths::root;

/// The target directory every scratch crate builds into, under
/// [`workspace_target`] (the name predates this crate; kept so that
/// existing builds are reused).
pub const SHARED_TARGET: &str = "codegen-check-target";

/// The lints that define "panic-free" for emitted code (house rules).
pub const PANIC_FREE_LINTS: [&str; 6] = [
    "warnings",
    "clippy::unwrap_used",
    "clippy::expect_used",
    "clippy::indexing_slicing",
    "clippy::panic",
    "clippy::as_conversions",
];

/// The workspace's target directory: `$CARGO_TARGET_DIR` or `target/`.
pub fn workspace_target() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(t) => PathBuf::from(t),
        None => root().join("target"),
    }
}

/// Writes `text` to `path` unless the file already holds it.
pub fn write_if_changed(path: &Path, text: &str) {
    if std::fs::read_to_string(path).ok().as_deref() != Some(text) {
        std::fs::write(path, text)
            .unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
    }
}

/// The manifest of scratch crate `name`: the runtime by path, and an empty
/// `[workspace]` so that cargo does not look for the enclosing one.
pub fn manifest(name: &str) -> String {
    let runtime = root().join("runtime");
    let runtime = runtime
        .canonicalize()
        .unwrap_or_else(|e| panic!("{}: {e}", runtime.display()));
    format!(
        "[package]\nname = \"{name}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
         [dependencies]\nreldesign-runtime = {{ path = {:?} }}\n\n[workspace]\n",
        runtime.display().to_string()
    )
}

/// Runs cargo in `dir` (a scratch crate, or a package of the workspace to
/// build beside them) into [`SHARED_TARGET`], without the caller's
/// `RUSTFLAGS`; panics with stderr unless it succeeds.
pub fn cargo(dir: &Path, args: &[&str]) -> Output {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(args)
        .current_dir(dir)
        .env("CARGO_TARGET_DIR", workspace_target().join(SHARED_TARGET))
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .output()
        .expect("cannot run cargo");
    assert!(
        out.status.success(),
        "cargo {args:?} in {} failed:\n{}",
        dir.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A scratch crate in `target/NAME/`.
pub struct ScratchCrate {
    dir: PathBuf,
}

impl ScratchCrate {
    /// Creates (or refreshes) `target/NAME/` with its manifest, `src/`, and
    /// the workspace's `Cargo.lock` unless it has one already.
    pub fn new(name: &str) -> ScratchCrate {
        let dir = workspace_target().join(name);
        std::fs::create_dir_all(dir.join("src"))
            .unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
        write_if_changed(&dir.join("Cargo.toml"), &manifest(name));
        let lock = dir.join("Cargo.lock");
        if !lock.exists() {
            if let Ok(text) = std::fs::read_to_string(root().join("Cargo.lock")) {
                std::fs::write(&lock, text)
                    .unwrap_or_else(|e| panic!("cannot write {}: {e}", lock.display()));
            }
        }
        ScratchCrate { dir }
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes `file` (relative to the crate, e.g. `src/lib.rs`) unless it
    /// already holds `text`; returns its path.
    pub fn write(&self, file: &str, text: &str) -> PathBuf {
        let path = self.dir.join(file);
        write_if_changed(&path, text);
        path
    }

    /// Runs cargo in the crate, into [`SHARED_TARGET`]; panics with stderr
    /// unless it succeeds.
    pub fn cargo(&self, args: &[&str]) -> Output {
        cargo(&self.dir, args)
    }

    /// Clippy on the crate's library with [`PANIC_FREE_LINTS`] denied.
    pub fn clippy_panic_free(&self) {
        let mut args = vec!["clippy", "--offline", "--lib", "--"];
        for lint in PANIC_FREE_LINTS {
            args.extend(["-D", lint]);
        }
        self.cargo(&args);
    }

    /// [`ScratchCrate::clippy_panic_free`], then `cargo run` with `args`
    /// for the program: its standard output.
    pub fn run_panic_free(&self, args: &[&str]) -> String {
        self.clippy_panic_free();
        let mut run = vec!["run", "--offline", "--quiet"];
        if !args.is_empty() {
            run.push("--");
            run.extend(args);
        }
        let out = self.cargo(&run);
        String::from_utf8(out.stdout)
            .unwrap_or_else(|e| panic!("{}: stdout: {e}", self.dir.display()))
    }
}

/// Values in every input's odd corners, written as Rust expressions of a
/// scratch crate's float type `F`: the inputs a totality test of emitted code
/// steps through.
pub const ODD_FLOATS: [&str; 9] = [
    "0.0",
    "-0.0",
    "1e-12",
    "-1e-3",
    "1e30",
    "-1e30",
    "F::INFINITY",
    "F::NEG_INFINITY",
    "F::NAN",
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scratch_crate_is_a_package_on_the_runtime_and_rewrites_nothing_unchanged() {
        let name = format!("support-scratch-{}", std::process::id());
        let krate = ScratchCrate::new(&name);
        let manifest = std::fs::read_to_string(krate.dir().join("Cargo.toml")).unwrap();
        assert!(
            manifest.contains(&format!("name = \"{name}\"")),
            "{manifest}"
        );
        assert!(
            manifest.contains("reldesign-runtime = { path = "),
            "{manifest}"
        );
        assert!(krate.dir().join("Cargo.lock").is_file());
        let lib = krate.write("src/lib.rs", "#![no_std]\n");
        let modified = || std::fs::metadata(&lib).unwrap().modified().unwrap();
        let before = modified();
        std::thread::sleep(std::time::Duration::from_millis(20));
        krate.write("src/lib.rs", "#![no_std]\n");
        assert_eq!(modified(), before, "an unchanged file was rewritten");
        // cargo reads the manifest (no build: that is the callers' business)
        let out = krate.cargo(&[
            "metadata",
            "--offline",
            "--no-deps",
            "--format-version",
            "1",
        ]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains(&format!("\"name\":\"{name}\"")), "{text}");
        std::fs::remove_dir_all(krate.dir()).unwrap();
    }
}
