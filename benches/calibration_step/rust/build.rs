//! Emits `examples/self-calibrating-valve.toml` twice into `$OUT_DIR`:
//! `adaptive.rs` as it is (θ read at run time, the update) and `fixed.rs` with
//! `self_calibration = false` (every parameter a const the compiler folds);
//! and `record.rs`: one run (closing, then opening, the design's windows) of the
//! design on a plant 15 % more resistive with a 10 % softer spring, simulated by
//! the designer with the example's measurement noise: what the firmware's
//! `Record` keeps, (commanded u, measured u, measured i) per sample.
//! Likewise `examples/self-calibrating-sensor-valve.toml` (the replay update, a
//! law on measured states): `sensor_adaptive.rs`, `sensor_fixed.rs` and
//! `sensor_record.rs`, its closing on a plant 10 % more resistive with φ_sat
//! 8 % lower, (commanded u, measured u, measured i, z, v, φ) per sample.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use designer::calibrate::run_runs;
use designer::closed_loop::Noise;
use designer::description::parse_str;
use designer::design::Design;

fn design(text: &str) -> Design {
    let d = parse_str(text, "self-calibrating-valve.toml").unwrap_or_else(|e| panic!("{e}"));
    Design::new(&d).unwrap_or_else(|e| panic!("{e}"))
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../..");
    let toml = root.join("examples/self-calibrating-valve.toml");
    println!("cargo:rerun-if-changed={}", toml.display());
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    let text = std::fs::read_to_string(&toml).expect("the example");
    let fixed_text = text.replace("self_calibration = true", "self_calibration = false");
    assert_ne!(text, fixed_text, "the example sets self_calibration = true");
    let adaptive = design(&text);
    let fixed = design(&fixed_text);
    let emit = |d: &Design| reldesign_build::emit(d).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out.join("adaptive.rs"), emit(&adaptive)).unwrap();
    std::fs::write(out.join("fixed.rs"), emit(&fixed)).unwrap();

    let plant_text = text
        .replace("resistance = 75.0", "resistance = 86.25")
        .replace("stiffness = 50.0", "stiffness = 45.0");
    assert_ne!(plant_text, text);
    let plant = parse_str(&plant_text, "plant.toml").unwrap_or_else(|e| panic!("{e}"));
    let ts = adaptive
        .controller
        .as_ref()
        .expect("controller")
        .sample_period;
    let runs = run_runs(&adaptive, None, Some(&plant), 1, ts, Noise::seeded(7), &Default::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let measured = &runs[0].run_loop.measured;
    let mut rec = format!(
        "/// (commanded u [V], measured u [V], measured i [A]) per sample, T_s = {ts:e} s.\n\
         pub const RECORD: [[f64; 3]; {}] = [\n",
        measured.len()
    );
    for m in measured {
        writeln!(
            rec,
            "    [{:?}, {:?}, {:?}],",
            m.commanded, m.voltage, m.current
        )
        .unwrap();
    }
    rec.push_str("];\n");
    std::fs::write(out.join("record.rs"), rec).unwrap();
    sensor(&root, &out);
}

/// The replay example's files (see the module docs).
fn sensor(root: &Path, out: &Path) {
    let toml = root.join("examples/self-calibrating-sensor-valve.toml");
    println!("cargo:rerun-if-changed={}", toml.display());
    let text = std::fs::read_to_string(&toml).expect("the example");
    let fixed_text = text.replace("self_calibration = true", "self_calibration = false");
    assert_ne!(text, fixed_text, "the example sets self_calibration = true");
    let adaptive = design(&text);
    let emit = |d: &Design| reldesign_build::emit(d).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out.join("sensor_adaptive.rs"), emit(&adaptive)).unwrap();
    std::fs::write(out.join("sensor_fixed.rs"), emit(&design(&fixed_text))).unwrap();
    let plant_text = text
        .replace("resistance = 75.0", "resistance = 82.5")
        .replace("phi_sat = 25e-6", "phi_sat = 23e-6");
    assert_ne!(plant_text, text);
    let plant = parse_str(&plant_text, "plant.toml").unwrap_or_else(|e| panic!("{e}"));
    let ts = adaptive.controller.as_ref().expect("controller").sample_period;
    let runs = run_runs(&adaptive, None, Some(&plant), 1, ts, Noise::seeded(7), &Default::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let looped = &runs[0].run_loop;
    let (_, start) = looped.operations[0];
    let end = start + looped.operation_length;
    let tolerance = 1e-9 * looped.operation_length;
    let closing: Vec<usize> = (0..looped.measured.len())
        .filter(|&k| {
            let t = looped.measured[k].t;
            t >= start - tolerance && t < end - tolerance
        })
        .collect();
    let mut rec = format!(
        "/// (commanded u [V], measured u [V], measured i [A], z [m], v [m/s], φ [Wb]) per\n\
         /// sample of the closing, T_s = {ts:e} s.\n\
         pub const SENSOR_RECORD: [[f64; 6]; {}] = [\n",
        closing.len()
    );
    for k in closing {
        let m = &looped.measured[k];
        // the trajectory's sample at the measurement's time
        let j = looped.trajectory.t.partition_point(|t| *t < m.t - tolerance);
        let x = &looped.trajectory.x[j.min(looped.trajectory.x.len() - 1)];
        writeln!(
            rec,
            "    [{:?}, {:?}, {:?}, {:?}, {:?}, {:?}],",
            m.commanded, m.voltage, m.current, x[0], x[1], x[2]
        )
        .unwrap();
    }
    rec.push_str("];\n");
    std::fs::write(out.join("sensor_record.rs"), rec).unwrap();
}
