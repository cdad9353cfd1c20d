//! The prost-build-style route: design the valve's controller while building
//! and write it to `$OUT_DIR/perfect_tracking_valve.rs` (included by
//! `src/lib.rs`, module `via_build_script`). `compile` prints
//! `cargo:rerun-if-changed` for the description, so this only re-runs when
//! the TOML (or this script) changes.

fn main() {
    // Relative to this crate's directory (the build script's working directory).
    if let Err(error) = reldesign_build::compile("../perfect-tracking-valve.toml") {
        eprintln!("error: {error}");
        std::process::exit(1);
    }
}
