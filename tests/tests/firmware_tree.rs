//! A firmware build compiles only what designing and emitting need: the
//! designer's analyses run on rayon's threads only with its `parallel`
//! feature, and its tapes are compiled to machine code only with its `jit`
//! feature, which the CLI and the diagnosis turn on and the build crate does
//! not, so `cargo tree -p firmware-example -e normal,build` (the firmware's
//! own resolution, as `cargo build -p firmware-example` sees it) has neither
//! rayon nor Cranelift.

use std::path::Path;
use std::process::Command;

/// The package names of the firmware example's normal and build dependencies.
fn firmware_packages() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = Command::new(env!("CARGO"))
        .current_dir(&root)
        .args(["tree", "--offline", "-p", "firmware-example"])
        .args(["-e", "normal,build", "--prefix", "none"])
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo tree: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_owned)
        .collect()
}

/// Asserts that the firmware's build (whose tree holds `known`) compiles
/// no package whose name starts with one of `prefixes`.
fn compiles_none_of(known: &str, prefixes: &[&str]) {
    let packages = firmware_packages();
    assert!(
        packages.iter().any(|p| p == known),
        "the tree was not read: {packages:?}"
    );
    let found: Vec<&String> = (packages.iter())
        .filter(|p| prefixes.iter().any(|x| p.starts_with(x)))
        .collect();
    assert!(found.is_empty(), "the firmware's build compiles {found:?}");
}

#[test]
fn a_firmware_build_compiles_no_thread_pool() {
    compiles_none_of("reldesign-designer", &["rayon", "crossbeam"]);
}

#[test]
fn a_firmware_build_compiles_no_code_generator() {
    compiles_none_of("reldesign-sym", &["cranelift", "regalloc"]);
}
