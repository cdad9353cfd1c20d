//! Plants that differ from a design the way a production batch and a warm
//! afternoon make them (the self-calibration studies,
//! `tests/tests/self_calibration.rs`): every physics parameter of the
//! description scaled by 1 ± u, u uniform in [10 %, 20 %] and the sign at
//! random, seeded; every fourth plant with a Jiles–Atherton core in place of
//! the saturating one (the core of `sensorless::JA_CORE`, its magnetisation
//! scaled alike). The stops stay where they are (the references' frame).

use designer::description::{params, parse_str, Description};
use designer::random::SplitMix64;

use crate::sensorless::JA_CORE;

/// Keys never varied: the turns (counted, not toleranced) and the stops.
const FIXED: [&str; 3] = ["coil.turns", "mechanics.z_min", "mechanics.z_max"];

/// One plant of the batch: its description and what was drawn.
#[derive(Debug, Clone)]
pub struct Variant {
    pub seed: u64,
    pub description: Description,
    /// (key, factor) of every varied parameter.
    pub factors: Vec<(&'static str, f64)>,
    pub hysteretic: bool,
}

/// Plant `seed` of the batch around `physics` (a description's physics
/// sections as TOML text, without design sections).
pub fn variant(physics: &str, seed: u64) -> Variant {
    let mut rng = SplitMix64::for_stream(0x5e1f_ca1b, seed);
    let hysteretic = seed % 4 == 3;
    let text = if hysteretic {
        with_ja_core(physics)
    } else {
        physics.to_owned()
    };
    let mut d = parse_str(&text, &format!("plant-{seed}.toml")).unwrap_or_else(|e| panic!("{e}"));
    let mut factors = Vec::new();
    for key in params::available(&d) {
        if FIXED.contains(&key) {
            continue;
        }
        let u = 0.10 + 0.10 * rng.uniform();
        let factor = if rng.uniform() < 0.5 {
            1.0 - u
        } else {
            1.0 + u
        };
        let value = params::get(&d, key).unwrap_or_else(|e| panic!("{e}"));
        let scaled = if key == "mechanics.restitution" {
            (value * factor).min(0.95)
        } else {
            value * factor
        };
        if params::set(&mut d, key, scaled).is_ok() {
            factors.push((key, factor));
        }
    }
    Variant {
        seed,
        description: d,
        factors,
        hysteretic,
    }
}

/// `physics` with its `[core]` section replaced by the Jiles–Atherton core.
fn with_ja_core(physics: &str) -> String {
    let start = physics.find("[core]").expect("a [core] section");
    let end = physics[start..]
        .find("\n[")
        .map_or(physics.len(), |k| start + k + 1);
    format!(
        "{}[core]\n{JA_CORE}\n\n{}",
        &physics[..start],
        &physics[end..]
    )
}

/// The physics sections of a description's TOML text (everything before
/// `[trajectory]`).
pub fn physics_of(text: &str) -> &str {
    text.split("[trajectory]").next().unwrap_or(text)
}
