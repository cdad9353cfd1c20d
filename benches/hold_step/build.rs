//! Generates the file `reldesign build` emits for
//! `examples/jiles-atherton-valve.toml` (`params!`, `kalman!`, `law!`, the
//! hold's `f32`/`f64` modules, the `ukf` module) into
//! `OUT_DIR/jiles_atherton_valve.rs`, and the bench input `OUT_DIR/record.rs`:
//! the designed closed loop (`designer::closed_loop::run_hold`: the runtime's
//! hold on the run-time design, driven by the designer's UKF from the noisy
//! voltage and current, T_s = 50 µs, the plant started at rest at z_max with
//! H_c = 250 A/m as in [JA §6.3], 50 ms), one row per sample:
//! [u, i, ẑ, v̂, φ̂, Ĥ_c] with u the voltage held over the sample ending
//! there and i the current then (σ_v = 15 mV, σ_i = 1 mA, seeded), and the
//! loop's estimate there (what its hold read).
//!
//! Also the sensorless design at 20 kHz (`tests/data/sensorless-ja-valve.toml`:
//! its UKF with the exponential flux step) into `OUT_DIR/sensorless_ja_valve.rs`,
//! and its own closed loop's (`run_loop`, 1001 samples: a closing, an opening,
//! the hold after it) measured voltage and current into `OUT_DIR/record_ja.rs`;
//! and the same design with `flux_substeps = 1` into
//! `OUT_DIR/sensorless_ja_valve_1.rs`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use designer::closed_loop::{run_hold, run_loop};
use designer::description::parse_file;
use designer::design::Design;
use designer::model::{Model, ModelPlant};
use designer::random::SplitMix64;
use designer::sim::Options;

const TS: f64 = 50e-6;
const DURATION: f64 = 50e-3;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let toml = root.join("examples/jiles-atherton-valve.toml");
    println!("cargo:rerun-if-changed={}", toml.display());
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    let d = parse_file(&toml).unwrap_or_else(|e| panic!("{e}"));
    let design = Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let code = reldesign_build::emit(&design).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out.join("jiles_atherton_valve.rs"), code).unwrap();

    let run = run_hold(
        &design,
        None,
        TS,
        Some(DURATION),
        designer::closed_loop::Noise::seeded(0),
        250.0,
        &Options::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let estimates = run
        .estimates
        .as_ref()
        .expect("the example's hold reads the UKF");
    let mut model = Model::build(&d);
    let plant = ModelPlant::new(&mut model);
    let tr = &run.trajectory;
    let mut noise = SplitMix64::new(0x4A_0B5E);
    let mut text = format!(
        "/// [u [V], i [A], ẑ [m], v̂ [m/s], φ̂ [Wb], Ĥ_c [A/m]] at k·T_s, T_s = {TS:e} s.\n\
         pub const RECORD: [[f64; 6]; {}] = [\n",
        tr.t.len()
    );
    let mut held = 0.0;
    for (k, e) in estimates.iter().enumerate() {
        // the ADC samples i just before the new voltage is applied
        let (i, _) = plant.current_and_voltage(tr.t[k], &tr.x[k], held);
        let u = held + 15e-3 * noise.normal();
        let i = i + 1e-3 * noise.normal();
        let hc = e.hc.unwrap_or(0.0);
        assert!(
            [u, i, e.z, e.v, e.phi, hc].iter().all(|x| x.is_finite()),
            "sample {k}: {e:?}"
        );
        writeln!(
            text,
            "    [{u:?}, {i:?}, {:?}, {:?}, {:?}, {hc:?}],",
            e.z, e.v, e.phi
        )
        .unwrap();
        held = tr.u[k];
    }
    text.push_str("];\n");
    std::fs::write(out.join("record.rs"), text).unwrap();
    sensorless(&root, &out);
}

/// The sensorless design's file and the record of its own loop.
fn sensorless(root: &Path, out: &Path) {
    let toml = root.join("tests/data/sensorless-ja-valve.toml");
    println!("cargo:rerun-if-changed={}", toml.display());
    let d = parse_file(&toml).unwrap_or_else(|e| panic!("{e}"));
    let design = Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let code = reldesign_build::emit(&design).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out.join("sensorless_ja_valve.rs"), code).unwrap();
    // the same design with one exponential substep per sample
    let text = std::fs::read_to_string(&toml).unwrap();
    let one = text.replacen("flux_substeps = 4", "flux_substeps = 1", 1);
    assert_ne!(one, text, "the design's flux_substeps");
    let d1 = designer::description::parse_str(&one, "one-substep.toml")
        .unwrap_or_else(|e| panic!("{e}"));
    let design1 = Design::new(&d1).unwrap_or_else(|e| panic!("{e}"));
    let code = reldesign_build::emit(&design1).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out.join("sensorless_ja_valve_1.rs"), code).unwrap();
    let noise = designer::closed_loop::Noise::seeded(0);
    let run = run_loop(&design, None, TS, Some(1000.0 * TS), noise, &Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let mut model = Model::build(&d);
    let plant = ModelPlant::new(&mut model);
    let tr = &run.trajectory;
    assert_eq!(tr.t.len(), 1001, "the record's length");
    let mut noise = SplitMix64::new(0x4A_5E45);
    let mut text = format!(
        "/// [u [V], i [A], 0, 0, 0, 0] at k·T_s, T_s = {TS:e} s.\n\
         pub const RECORD: [[f64; 6]; {}] = [\n",
        tr.t.len()
    );
    let mut held = 0.0;
    for k in 0..tr.t.len() {
        let (i, _) = plant.current_and_voltage(tr.t[k], &tr.x[k], held);
        let u = held + 15e-3 * noise.normal();
        let i = i + 1e-3 * noise.normal();
        writeln!(text, "    [{u:?}, {i:?}, 0.0, 0.0, 0.0, 0.0],").unwrap();
        held = tr.u[k];
    }
    text.push_str("];\n");
    std::fs::write(out.join("record_ja.rs"), text).unwrap();
}
