//! How well the coil current can place the armature near each stop of the
//! self-calibrating valve, on its own model (the guide's "what bounds the
//! landings", docs/guide/self-calibration.md).
//!
//! At a position z the forces balance at one flux φ_b(z). Held at a flux 1 %
//! off φ_b the armature settles Δz = −(∂a/∂φ · 0.01·φ_b)/(∂a/∂z) away, and
//! the current tells z apart from φ only through ∂i/∂z at constant φ. Both
//! by central differences of the plant's own right-hand side and current.

use designer::description::parse_str;
use designer::model::{Model, ModelPlant};
use designer::sim::{Plant, State, MAX_DIM};

const EXAMPLE: &str = include_str!("../../examples/self-calibrating-valve.toml");

/// What the current and the forces say at z with the forces in balance.
struct Balance {
    phi: f64,
    /// |∂a/∂φ| [m/s²/Wb] at constant z.
    accel_per_flux: f64,
    /// Δz [m] at which a flux 1 % high settles.
    shift_per_percent: f64,
    /// |∂i/∂z| [A/m] at constant φ.
    current_per_metre: f64,
}

fn balance(plant: &ModelPlant, z: f64) -> Balance {
    let state = |z: f64, phi: f64| {
        let mut x: State = [0.0; MAX_DIM];
        x[0] = z;
        x[2] = phi;
        x
    };
    let accel = |z: f64, phi: f64| {
        let mut dx: State = [0.0; MAX_DIM];
        plant.deriv(0.0, &state(z, phi), 0.0, &mut dx);
        dx[1]
    };
    let current = |z: f64, phi: f64| plant.current_and_voltage(0.0, &state(z, phi), 0.0).0;
    // φ_b by bisection: the magnet pulls towards z_min as φ grows
    let (mut lo, mut hi) = (1e-9, 30e-6);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if accel(z, mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let phi = 0.5 * (lo + hi);
    let (h, hz) = (phi * 1e-6, 1e-8);
    let da_dphi = (accel(z, phi + h) - accel(z, phi - h)) / (2.0 * h);
    let da_dz = (accel(z + hz, phi) - accel(z - hz, phi)) / (2.0 * hz);
    let di_dz = (current(z + hz, phi) - current(z - hz, phi)) / (2.0 * hz);
    Balance {
        phi,
        accel_per_flux: da_dphi.abs(),
        shift_per_percent: (da_dphi * 0.01 * phi / da_dz).abs(),
        current_per_metre: di_dz.abs(),
    }
}

/// The open stop is ill-conditioned: a flux 1 % off moves the balance
/// ~56 µm there against ~3 µm at the closed stop, and at the opening's
/// standoff (50 µm short) the current moves 0.12 mA per µm against
/// σ_i = 2.5 mA. A force error of 1 % of the flux, acting over the 50 µm
/// standoff, meets the stop at v = √(2·|∂a/∂φ|·0.01·φ_b·δ) ≈ 26 mm/s:
/// ~29× softer than the opening's switching impact (0.758 m/s), the
/// opening's median on the design's own valve.
#[test]
fn the_open_stop_is_where_the_current_places_the_armature_worst() {
    let d = parse_str(EXAMPLE, "examples/self-calibrating-valve.toml")
        .unwrap_or_else(|e| panic!("{e}"));
    let mut model = Model::build(&d);
    let plant = ModelPlant::new(&mut model);
    let standoff = 50e-6;
    let at = |z: f64| balance(&plant, z);
    let (closed, open, approach) = (at(0.0), at(1e-3), at(1e-3 - standoff));
    for (name, b) in [
        ("closed stop", &closed),
        ("open stop", &open),
        ("opening's standoff", &approach),
    ] {
        println!(
            "{name}: φ_b {:.2} µWb, Δz per 1 % of φ {:.1} µm, ∂i/∂z {:.3} mA/µm",
            b.phi * 1e6,
            b.shift_per_percent * 1e6,
            b.current_per_metre * 1e-3,
        );
    }
    assert!(
        (50e-6..62e-6).contains(&open.shift_per_percent),
        "{}",
        open.shift_per_percent
    );
    assert!(open.shift_per_percent > 15.0 * closed.shift_per_percent);
    assert!((0.10e3..0.13e3).contains(&approach.current_per_metre));
    let impact = (2.0 * approach.accel_per_flux * 0.01 * approach.phi * standoff).sqrt();
    println!(
        "a 1 % flux error over the standoff meets the stop at {:.1} mm/s",
        impact * 1e3
    );
    assert!((20e-3..32e-3).contains(&impact), "{impact}");
}
