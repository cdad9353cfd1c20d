//! How softly a sensorless design lands on a set of plants over noise
//! seeds, against the plants' own switching: the figures of the sensorless
//! studies (`tests/tests/sensorless_rates.rs` on the valve's mismatched
//! plants, `tests/tests/sensorless_devices.rs` on generated devices). A run
//! is one operation (closing or opening) of one loop.

use std::ops::Range;

use designer::closed_loop::{run_loop, switching_baseline, Noise};
use designer::description::Description;
use designer::design::Design;
use designer::sim::Options;

/// Over plants and noise seeds, per operation (closing, opening): how many
/// times softer than the switching the first impact is, worst and best (0
/// where the armature never lands within t₀ after t_f; ∞ where it lands and
/// the switching never does, as remanence can hold a hysteretic armature at
/// 0 V: those runs are also counted in `unscored`); the runs below 10×; the
/// most bounces within that window and the runs with more than one; the
/// highest bounce [m].
#[derive(Debug, Clone, Copy)]
pub struct Landings {
    pub worst: [f64; 2],
    pub best: [f64; 2],
    pub below_ten: usize,
    pub bounces: usize,
    pub bouncing: usize,
    pub highest: f64,
    /// Runs whose switching never lands (no ratio; a hover still counts
    /// below 10×).
    pub unscored: usize,
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
            unscored: 0,
            runs: 0,
        }
    }

    /// The table cells "closing × (worst–best) | opening × (worst–best) |
    /// runs < 10×" of the sensorless studies' tables.
    pub fn softness_cells(&self) -> String {
        format!(
            "{:.1}–{:.0} | {:.1}–{:.0} | {} of {}",
            self.worst[0], self.best[0], self.worst[1], self.best[1], self.below_ten, self.runs
        )
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
            unscored: self.unscored + other.unscored,
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
                // where the switching never lands, any landing is infinitely softer
                let hard = hard.map_or(f64::INFINITY, f64::abs);
                row.unscored += usize::from(hard.is_infinite());
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
