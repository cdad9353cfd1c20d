//! Emits the EKF and UKF of examples/perfect-tracking-valve.toml (T_s = 50 µs,
//! σ_v = 15 mV, σ_i = 1 mA, the process noise of the observer tests) with
//! `reldesign_build::emit_ekf` / `reldesign_build::emit_ukf` (and the file's `params!` and
//! `kalman!` they invoke) into one file, and a noisy record of the valve
//! driven open loop (24 V on [0, 6 ms), 0 V, −24 V on [10, 10.4 ms), 0 V
//! until 20 ms; 400 samples) simulated by the designer's hybrid simulator.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use reldesign_build::{
    emit_ekf, emit_kalman_macro, emit_observer_params, emit_ukf, wrap_module, Float, ObserverInput,
};
use designer::description::parse_file;
use designer::model::Model;
use designer::observe::discrete::{DiscreteModel, FluxStep, KalmanSettings};
use designer::replay::replay;
use designer::sim::{Options, PiecewiseLinear};

const TS: f64 = 50e-6;
const SAMPLES: usize = 400;

/// SplitMix64 + Box–Muller.
struct Rng(u64, Option<f64>);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) + 1) as f64 / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        if let Some(s) = self.1.take() {
            return s;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = 2.0 * std::f64::consts::PI * u2;
        self.1 = Some(r * a.sin());
        r * a.cos()
    }
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../..");
    let toml = root.join("examples/perfect-tracking-valve.toml");
    println!("cargo:rerun-if-changed={}", toml.display());
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    let d = parse_file(&toml).unwrap_or_else(|e| panic!("{e}"));
    let mut model = Model::build(&d);
    let settings = KalmanSettings {
        sample_period: TS,
        voltage_noise: 15e-3,
        current_noise: 1e-3,
        process_z: 5e-9,
        process_phi: 1.5e-8,
        process_hc: None,
        initial_z_std: 1e-5,
        initial_phi_std: 1e-7,
        initial_hc_std: None,
        ukf_alpha: 1.0,
        ukf_beta: 2.0,
        ukf_kappa: 0.0,
        flux_step: FluxStep::Euler,
    };
    let dm = DiscreteModel::new(&model, &settings).unwrap_or_else(|e| panic!("{e}"));
    let input = ObserverInput {
        name: &d.name,
        discrete: &dm,
        floats: vec![Float::F64, Float::F32],
        calibration: None,
    };
    let ok = |r: Result<String, reldesign_build::ObserverError>| r.unwrap_or_else(|e| panic!("{e}"));
    let code = ok(emit_observer_params(&input))
        + &ok(emit_kalman_macro(&input))
        + &wrap_module("ekf", "The EKF.", &ok(emit_ekf(&input)))
        + &wrap_module("ukf", "The UKF.", &ok(emit_ukf(&input)));
    std::fs::write(out.join("valve_observers.rs"), code).unwrap();

    let k = |t: f64| (t / TS).round() * TS;
    let signal = PiecewiseLinear::steps(&[
        (0.0, 24.0),
        (k(6e-3), 0.0),
        (k(10e-3), -24.0),
        (k(10.4e-3), 0.0),
    ])
    .unwrap();
    let times: Vec<f64> = (0..SAMPLES).map(|k| k as f64 * TS).collect();
    let opts = Options {
        rtol: 1e-10,
        ..Options::default()
    };
    let r = replay(&mut model, &signal, &times, &opts).unwrap_or_else(|e| panic!("{e}"));
    let mut rng = Rng(0xBE4C_0000, None);
    let mut text = format!("/// (u [V], i [A]) at k·T_s, T_s = {TS:e} s.\npub const RECORD: [[f64; 2]; {SAMPLES}] = [\n");
    for (u, i) in r.trajectory.u.iter().zip(&r.current) {
        let (u, i) = (u + 15e-3 * rng.normal(), i + 1e-3 * rng.normal());
        writeln!(text, "    [{u:?}, {i:?}],").unwrap();
    }
    text.push_str("];\n");
    std::fs::write(out.join("record.rs"), text).unwrap();
}
