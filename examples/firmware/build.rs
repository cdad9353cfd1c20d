//! The prost-build-style route: design the valve's controllers while building
//! and write them to `$OUT_DIR/perfect_tracking_valve.rs` and
//! `$OUT_DIR/backstepping_valve.rs` and `$OUT_DIR/self_calibrating_valve.rs`
//! (included by `src/lib.rs`, modules `via_build_script`,
//! `positioner_via_build_script` and `sensorless_via_build_script`). `compile` prints
//! `cargo:rerun-if-changed` for the description, so this only re-runs when
//! the TOML (or this script) changes.

fn main() {
    // Relative to this crate's directory (the build script's working directory).
    for description in [
        "../perfect-tracking-valve.toml",
        "../backstepping-valve.toml",
        "../self-calibrating-valve.toml",
    ] {
        if let Err(error) = reldesign_build::compile(description) {
            eprintln!("error: {error}");
            std::process::exit(1);
        }
    }
}
