//! Designs `data/sensorless-valve.toml` into `$OUT_DIR/sensorless_valve.rs`
//! (the build.rs way in, prost-build style) for `tests/sensorless.rs`.

fn main() {
    if let Err(e) = reldesign_build::compile("data/sensorless-valve.toml") {
        eprintln!("{e}");
        std::process::exit(1);
    }
}
