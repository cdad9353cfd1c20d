//! Generates the file `reldesign build` emits for
//! `examples/backstepping-valve.toml` (`params!`, `law!`, the `f32`/`f64`
//! modules with `law`, `desired_force` and the `Controller`) into
//! `OUT_DIR/backstepping_valve.rs`, and the bench input `OUT_DIR/record.rs`:
//! the designed closed loop itself
//! (`designer::backstepping_loop::run_backstepping`: the runtime's switched
//! backstepping on the run-time design, T_s = 10 µs, the plant started at rest
//! on the spring's stop z_max without flux, the square reference over its
//! default length, two periods, 0.4 s, 40 000 samples), of which `RECORD`
//! samples evenly picked: [t, z, v, φ, y_r] (the loop's state at the sample
//! and the reference its controller held there), and beside it the loop's
//! own input there and its mode after the step (`LOOP`, for the dump only).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use designer::backstepping_loop::run_backstepping;
use designer::closed_loop::Noise;
use designer::description::{parse_file, SetPoint};
use designer::design::Design;
use designer::sim::Options;

const TS: f64 = 1e-5;
const RECORD: usize = 1001;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let toml = root.join("examples/backstepping-valve.toml");
    println!("cargo:rerun-if-changed={}", toml.display());
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    let d = parse_file(&toml).unwrap_or_else(|e| panic!("{e}"));
    let design = Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let code = reldesign_build::emit(&design).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out.join("backstepping_valve.rs"), code).unwrap();

    let b = design
        .backstepping
        .as_ref()
        .expect("the example designs a backstepping law");
    assert_eq!(b.sample_period, TS, "the example's T_s");
    let SetPoint::Square { period, .. } = b.reference else {
        panic!("the example tracks a square reference");
    };
    let run = run_backstepping(
        &design,
        None,
        TS,
        None,
        Noise::seeded(1),
        None,
        &Options::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let tr = &run.run.trajectory;
    let len = tr.t.len();
    assert!(len > RECORD, "{len} samples");
    assert_eq!(run.modes.len(), len);
    assert_eq!(run.run.z_ref.len(), len);
    // the record is cycled with t advanced by two periods: it must lie in them
    assert!(
        tr.t[len - 1] < 2.0 * period,
        "the loop outlasts two periods"
    );
    let mut text = format!(
        "/// [t [s], z [m], v [m/s], φ [Wb], y_r [m]]: {RECORD} samples evenly picked from the \
         {len} of the designed loop (T_s = {TS:e} s, {:e} s).\n\
         pub const RECORD: [[f64; 5]; {RECORD}] = [\n",
        tr.t[len - 1]
    );
    let mut loop_text = format!(
        "/// The loop's input [V] at each sample of `RECORD` and its mode after the step \
         (0 Start, 1 Approaching, 2 Waiting, 3 Inside).\n\
         pub const LOOP: [(f64, u8); {RECORD}] = [\n"
    );
    for j in 0..RECORD {
        let k = (j * (len - 1) + (RECORD - 1) / 2) / (RECORD - 1);
        let (t, x, y_r) = (tr.t[k], &tr.x[k], run.run.z_ref[k]);
        let row = [t, x[0], x[1], x[2], y_r];
        assert!(row.iter().all(|x| x.is_finite()), "sample {k}: {row:?}");
        writeln!(
            text,
            "    [{:?}, {:?}, {:?}, {:?}, {:?}],",
            row[0], row[1], row[2], row[3], row[4]
        )
        .unwrap();
        writeln!(loop_text, "    ({:?}, {}),", tr.u[k], run.modes[k] as u8).unwrap();
    }
    text.push_str("];\n");
    loop_text.push_str("];\n");
    text.push_str(&loop_text);
    std::fs::write(out.join("record.rs"), text).unwrap();
}
