//! Shared helpers of the end-to-end tests: locating the bundled examples,
//! loading models, deterministic pseudo-random states.

pub mod blind;
pub mod devices;
pub mod friction;
pub mod hidden;
pub mod landings;
pub mod outside;
pub mod sensorless;
pub mod variants;

use designer::description::{parse_file, parse_str, Description};
use designer::model::Model;
use designer::sim::{Event, EventKind, Limit};
pub use support::{example_path, root};

/// Every bundled example description, sorted by file name.
pub fn examples() -> Vec<(String, Description)> {
    support::example_paths()
        .into_iter()
        .map(|p| {
            let d = parse_file(&p).unwrap_or_else(|e| panic!("{e}"));
            (
                p.file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                d,
            )
        })
        .collect()
}

/// One bundled example by file name.
pub fn example(file: &str) -> Description {
    parse_file(&example_path(file)).unwrap_or_else(|e| panic!("{e}"))
}

/// A bundled example with some lines of its TOML text replaced.
pub fn example_with(file: &str, replacements: &[(&str, &str)]) -> Description {
    let mut text = std::fs::read_to_string(example_path(file)).expect("example exists");
    for (from, to) in replacements {
        assert!(text.contains(from), "`{from}` not found in {file}");
        text = text.replacen(from, to, 1);
    }
    parse_str(&text, file).unwrap_or_else(|e| panic!("{e}"))
}

pub fn model(d: &Description) -> Model {
    Model::build(d)
}

/// A small deterministic generator (SplitMix64) for reproducible test points.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A random state inside the model's domain: z in [z_min, z_max], |φ| below
/// saturation, H_c in a realistic range.
pub fn random_state(d: &Description, rng: &mut Rng) -> [f64; 4] {
    let m = &d.mechanics;
    let phi_max = match &d.core {
        designer::description::Core::Saturating { phi_sat, .. } => 0.9 * phi_sat,
        _ => 2.5e-5,
    };
    [
        rng.uniform(m.z_min, m.z_max),
        rng.uniform(-2.0, 2.0),
        rng.uniform(-phi_max, phi_max),
        rng.uniform(-2000.0, 2000.0),
    ]
}

/// The impacts at `limit` with `after < t < before`, as (speed before, speed
/// after) — `v_after = 0` when the armature sticks.
pub fn impacts(
    events: &[Event],
    limit: Limit,
    after: f64,
    before: f64,
) -> impl Iterator<Item = (f64, f64)> + '_ {
    events.iter().filter_map(move |e| match e.kind {
        EventKind::Impact {
            limit: at,
            v_before,
            v_after,
            ..
        } if at == limit && e.t > after && e.t < before => Some((v_before.abs(), v_after.abs())),
        _ => None,
    })
}

/// "min … median … max" of the finite values of `x` (a study's distribution
/// over plants; a plant that gives no value, e.g. a valve whose switching
/// misses a stop, is left out).
pub fn quantiles(mut x: Vec<f64>) -> String {
    x.retain(|v| v.is_finite());
    x.sort_by(f64::total_cmp);
    if x.is_empty() {
        return "—".to_string();
    }
    let q = |p: f64| x[((x.len() - 1) as f64 * p).round() as usize];
    format!(
        "min {:6.1}  median {:6.1}  max {:6.1}",
        q(0.0),
        q(0.5),
        q(1.0)
    )
}
