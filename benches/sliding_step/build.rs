//! Generates the controller of `examples/sliding-mode-valve.toml` (the file
//! `reldesign build` emits) into `OUT_DIR/sliding_mode_valve.rs`, and the
//! bench input `OUT_DIR/record.csv`: the designed closed loop
//! (`designer::closed_loop::run_loop`, the runtime's law on the run-time
//! design, T_s = 10 µs, closing then opening, 6 ms each) on the valve's
//! hybrid model, one `t z v a phi` line per sample: the loop's state there
//! (what its controller measures, up to events the new input causes at that
//! very sample), with a the free-motion acceleration (0 against a stop), as
//! the loop computes it. The operations' start times reach the
//! driver as the environment variables `CLOSING_START` and `OPENING_START`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use designer::closed_loop::run_loop;
use designer::description::{parse_file, Operation};
use designer::model::{Model, ModelPlant};
use designer::sim::{Mode, Options, Plant, State, MAX_DIM};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let toml = root.join("examples/sliding-mode-valve.toml");
    println!("cargo:rerun-if-changed={}", toml.display());
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    let d = parse_file(&toml).unwrap_or_else(|e| panic!("{e}"));
    // the whole file `reldesign build` writes: `params!`, then `pub mod f32`, `pub mod f64`
    let design = designer::design::Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let code = reldesign_build::emit(&design).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out.join("sliding_mode_valve.rs"), code).unwrap();

    let run = run_loop(&design, None, 1e-5, None, designer::closed_loop::Noise::seeded(0), &Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let starts = &run.operations;
    assert!(
        matches!(
            starts.as_slice(),
            [(Operation::Closing, _), (Operation::Opening, _)]
        ),
        "closing then opening: {starts:?}"
    );
    println!("cargo:rustc-env=CLOSING_START={:?}", starts[0].1);
    println!("cargo:rustc-env=OPENING_START={:?}", starts[1].1);

    // a as the loop's controller reads it (closed_loop.rs): the plant's
    // acceleration in free motion (it does not depend on u), 0 at a stop
    let mut model = Model::build(&d);
    let plant = ModelPlant::new(&mut model);
    let tr = &run.trajectory;
    let mut csv = String::new();
    for k in 0..tr.t.len() {
        let x = &tr.x[k];
        let mut dx: State = [0.0; MAX_DIM];
        plant.deriv(tr.t[k], x, 0.0, &mut dx);
        let a = if tr.mode[k] == Mode::Free { dx[1] } else { 0.0 };
        let _ = writeln!(
            csv,
            "{:?} {:?} {:?} {:?} {:?}",
            tr.t[k], x[0], x[1], a, x[2]
        );
    }
    std::fs::write(out.join("record.csv"), csv).unwrap();
}
