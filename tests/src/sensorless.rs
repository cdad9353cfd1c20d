//! The mismatched plants of the sensorless studies (`tests/tests/sensorless.rs`,
//! `tests/tests/sensorless_rates.rs`): the perfect-tracking valve with a
//! Jiles–Atherton core fitted to its saturating one, and k_s, R scaled; and
//! how softly a sensorless design lands on such plants.

use std::ops::Range;

use designer::closed_loop::{run_loop, switching_baseline, Noise};
use designer::description::{parse_str, Description};
use designer::design::Design;
use designer::sim::Options;

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

/// Over plants and noise seeds, per operation (closing, opening): how many
/// times softer than the switching the first impact is (0 where the
/// armature never lands within t₀ after t_f), worst and best; the runs below
/// 10×; the most bounces within that window and the runs with more than
/// one; the highest bounce [m].
#[derive(Debug, Clone, Copy)]
pub struct Landings {
    pub worst: [f64; 2],
    pub best: [f64; 2],
    pub below_ten: usize,
    pub bounces: usize,
    pub bouncing: usize,
    pub highest: f64,
    pub runs: usize,
}

impl Landings {
    /// No runs yet.
    pub fn none() -> Landings {
        Landings {
            worst: [f64::INFINITY; 2],
            best: [0.0; 2],
            below_ten: 0,
            bounces: 0,
            bouncing: 0,
            highest: 0.0,
            runs: 0,
        }
    }

    /// The figures over the runs of both.
    pub fn merged(self, other: Landings) -> Landings {
        Landings {
            worst: [0, 1].map(|k| self.worst[k].min(other.worst[k])),
            best: [0, 1].map(|k| self.best[k].max(other.best[k])),
            below_ten: self.below_ten + other.below_ten,
            bounces: self.bounces.max(other.bounces),
            bouncing: self.bouncing + other.bouncing,
            highest: self.highest.max(other.highest),
            runs: self.runs + other.runs,
        }
    }
}

/// The sensorless loop of `d` at its `controller.sample_period`, on each of
/// `plants` for each noise seed of `seeds` (measurement noise σ = [σ_v, σ_i],
/// default the observer's own), scored against the u_max / 0 V switching of
/// the same plant, simulated with `options`.
pub fn landings(
    d: &Description,
    plants: &[Description],
    sigma: Option<[f64; 2]>,
    seeds: Range<u64>,
    options: &Options,
) -> Landings {
    let design = Design::new(d).unwrap_or_else(|e| panic!("{e}"));
    let t = d.trajectory.as_ref().expect("a [trajectory]");
    let ts = d.controller.as_ref().expect("a [controller]").sample_period;
    let mut row = Landings::none();
    for plant in plants {
        let switching =
            switching_baseline(d, Some(plant), options).unwrap_or_else(|e| panic!("{e}"));
        for seed in seeds.clone() {
            let noise = Noise { seed, sigma };
            let run =
                run_loop(&design, Some(plant), ts, None, noise, options).unwrap_or_else(|e| {
                    panic!("{} on {} seed {seed}: {e}", d.name, plant_label(d, plant))
                });
            let outcomes = run.outcomes(t.takeoff, t.landing);
            for (k, (o, (_, hard))) in outcomes.iter().zip(&switching).enumerate() {
                // where the switching never lands (remanence holds a
                // hysteretic armature at 0 V), any landing is infinitely softer
                let hard = hard.map_or(f64::INFINITY, f64::abs);
                let softer = o.impact_velocity.map_or(0.0, |v| hard / v.abs().max(1e-12));
                row.worst[k] = row.worst[k].min(softer);
                row.best[k] = row.best[k].max(softer);
                row.below_ten += usize::from(softer < 10.0);
                row.bounces = row.bounces.max(o.bounces);
                row.bouncing += usize::from(o.bounces > 1);
                row.highest = row.highest.max(o.highest_bounce);
                row.runs += 1;
            }
        }
    }
    row
}

/// k_s and R of `plant` relative to `d`'s, for messages.
fn plant_label(d: &Description, plant: &Description) -> String {
    format!(
        "k_s ×{:.2}, R ×{:.2}",
        plant.mechanics.stiffness / d.mechanics.stiffness,
        plant.coil.resistance / d.coil.resistance
    )
}
