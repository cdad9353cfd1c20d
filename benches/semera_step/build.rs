//! Generates the estimators of `examples/semera-valve.toml` (the file
//! `reldesign build` emits) into `OUT_DIR/semera.rs`, and the bench input
//! `OUT_DIR/record.csv`: two 20 ms cycles of the 0/30 V square wave through
//! the valve (designer's hybrid simulator), sampled every Δ = 50 µs with the
//! description's noise σ_v, σ_i (fixed seed), as `v i` lines.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use designer::description::parse_file;
use designer::model::Model;
use designer::replay::replay;
use designer::sim::{Options, PiecewiseLinear};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let toml = root.join("examples/semera-valve.toml");
    println!("cargo:rerun-if-changed={}", toml.display());
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    let d = parse_file(&toml).unwrap_or_else(|e| panic!("{e}"));
    // the whole file `reldesign build` writes: `params!`, then `pub mod estimators`
    let design = designer::design::Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let code = reldesign_build::emit(&design).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out.join("semera.rs"), code).unwrap();

    let o = d.observer.as_ref().unwrap();
    let dt = o.sample_period;
    let n = (40e-3 / dt).round() as usize;
    let t: Vec<f64> = (0..=n).map(|k| k as f64 * dt).collect();
    let wave = PiecewiseLinear::square_wave(30.0, 0.0, 20e-3, 0.5, 40e-3).unwrap();
    let run = replay(&mut Model::build(&d), &wave, &t, &Options::default()).unwrap();
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut uniform = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        ((state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut gauss = move || {
        let (a, b) = (uniform(), uniform());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    };
    let mut csv = String::new();
    for k in 0..t.len() {
        let mid = t[k] - 0.5 * dt;
        let v = if mid >= 0.0 && (mid / 20e-3).fract() < 0.5 {
            30.0
        } else {
            0.0
        };
        let _ = writeln!(
            csv,
            "{:?} {:?}",
            v + o.voltage_noise * gauss(),
            run.current[k] + o.current_noise * gauss()
        );
    }
    std::fs::write(out.join("record.csv"), csv).unwrap();
}
