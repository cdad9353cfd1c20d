//! Designs `data/sensorless-valve.toml` and `data/sensorless-ja-valve.toml`
//! into `$OUT_DIR/sensorless_valve.rs` and `$OUT_DIR/sensorless_ja_valve.rs`
//! (the build.rs way in, prost-build style) for `tests/sensorless.rs` and
//! `tests/ja_ukf_long_run.rs`.

fn main() {
    for file in [
        "data/sensorless-valve.toml",
        "data/sensorless-ja-valve.toml",
    ] {
        if let Err(e) = reldesign_build::compile(file) {
            eprintln!("{e}");
            std::process::exit(1);
        }
    }
}
