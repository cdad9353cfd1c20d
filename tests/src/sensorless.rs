//! The mismatched plants of the sensorless studies (`tests/tests/sensorless.rs`,
//! `tests/tests/sensorless_rates.rs`): the perfect-tracking valve with a
//! Jiles–Atherton core fitted to its saturating one, and k_s, R scaled.

use designer::description::{parse_str, Description};

use crate::example_path;

const VALVE: &str = "perfect-tracking-valve.toml";

/// Inverse Jiles–Atherton core whose anhysteretic curve follows the design's
/// Fröhlich–Kennelly core (r0 = 3e6 H⁻¹, φ_sat = 25 µWb) within ±8 % of the
/// MMF for φ ≤ 21 µWb (least squares of m_sat, b, α at l_c = 40 mm, A_c =
/// 20 mm²), with hysteresis added (c = 0.5, κ = 60 A/m: a coercive MMF of
/// ~2.4 A·turn, 5 % of the holding MMF).
pub const JA_CORE: &str = "model = \"jiles-atherton\"
length = 0.04
area = 20e-6
m_sat = 1.0715e6
b = 4.6685e-3
c = 0.5
kappa = 60.0
alpha = 8.3174e-3";

const SATURATING_CORE: &str = "model = \"saturating\"
r0 = 3e6                    # R_core0 = 3·10⁶ H⁻¹, Table 1
phi_sat = 25e-6             # φ_sat = 25 µWb, Table 1";

/// The perfect-tracking valve with the JA core and k_s, R scaled: physics
/// only (the design sections need the design model, not the plant).
pub fn mismatched_plant(ks_factor: f64, r_factor: f64) -> Description {
    let text = std::fs::read_to_string(example_path(VALVE)).expect("example");
    let physics = text
        .split("[trajectory]")
        .next()
        .expect("text before [trajectory]");
    let mut plant = physics.replacen(SATURATING_CORE, JA_CORE, 1);
    for (from, to) in [
        (
            "stiffness = 50.0",
            format!("stiffness = {}", 50.0 * ks_factor),
        ),
        (
            "resistance = 75.0",
            format!("resistance = {}", 75.0 * r_factor),
        ),
    ] {
        assert!(plant.contains(from), "{from}");
        plant = plant.replacen(from, &to, 1);
    }
    assert!(plant.contains("jiles-atherton"));
    parse_str(&plant, "mismatched-plant.toml").unwrap_or_else(|e| panic!("{e}"))
}
