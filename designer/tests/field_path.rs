//! `model::FieldPath`, H_c of the Jiles–Atherton core along a flux path,
//! against the hybrid simulation of the valve, which integrates H_c in time
//! ([JA 33] with the input through φ̇): the core is rate independent, so the
//! field the simulation reaches at each sample is the one the path reaches
//! at the simulated flux. The pulses stay below pull-in (the armature rests
//! on z_max) and swing the flux up, through 0 to negative and back: minor
//! loops and remanence.

use designer::description::parse_file;
use designer::model::{FieldPath, Model, ModelPlant};
use designer::sim::{simulate, Mode, Options, PiecewiseLinear};
use support::example_path;

#[test]
fn field_path_follows_the_simulated_core() {
    let d = parse_file(&example_path("jiles-atherton-valve.toml")).unwrap();
    let mut model = Model::build(&d);
    let plant = ModelPlant::new(&mut model);
    // 6 V (the valve pulls in near 12 V), −6 V, 3 V, 0 V
    let (t, u) = (
        vec![
            0.0, 1e-3, 1.05e-3, 10e-3, 10.05e-3, 18e-3, 18.05e-3, 24e-3, 24.05e-3, 30e-3,
        ],
        vec![0.0, 0.0, 6.0, 6.0, -6.0, -6.0, 3.0, 3.0, 0.0, 0.0],
    );
    let input = PiecewiseLinear::new(t, u).unwrap();
    let times: Vec<f64> = (0..=3000).map(|k| k as f64 * 1e-5).collect();
    let mut x0 = [0.0; 4];
    x0[0] = d.mechanics.z_max;
    let tr = simulate(
        &plant,
        &input,
        x0,
        Mode::StuckMax,
        &times,
        &Options::default(),
    )
    .unwrap();
    assert!(
        tr.events.is_empty(),
        "the armature must stay on z_max: {:?}",
        tr.events
    );
    let mut path = FieldPath::anhysteretic(&model, 0.0).expect("a JA core has a field path");
    assert!(path.field().abs() < 1e-30, "{}", path.field());
    let (mut worst, mut scale, mut phi_min, mut phi_max) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    for x in &tr.x {
        let hc = path.advance(x[2]);
        worst = worst.max((hc - x[3]).abs());
        scale = scale.max(x[3].abs());
        (phi_min, phi_max) = (phi_min.min(x[2]), phi_max.max(x[2]));
    }
    // the excursion: both signs of flux, a field of hundreds of A/m
    assert!(phi_min < -2e-6 && phi_max > 5e-6, "{phi_min:e} {phi_max:e}");
    assert!(scale > 300.0, "{scale}");
    eprintln!(
        "max |ΔH_c| = {worst:.3e} A/m of {scale:.1} A/m ({:.4} %)",
        100.0 * worst / scale
    );
    // measured: 0.0031 % of the largest field (0.014 of 449 A/m)
    assert!(
        worst < 1e-3 * scale,
        "max |ΔH_c| = {worst} A/m of {scale} A/m"
    );
    // remanence: back at zero volts the core keeps a field
    let last = tr.x.last().unwrap();
    assert!(last[3].abs() > 1.0, "H_c at the end {}", last[3]);
}

#[test]
fn cores_without_the_field_state_have_no_path() {
    let d = parse_file(&example_path("perfect-tracking-valve.toml")).unwrap();
    assert!(FieldPath::anhysteretic(&Model::build(&d), 0.0).is_none());
}
