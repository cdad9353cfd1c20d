//! Data with an effect outside the measured-data vocabulary (issue 17 §2):
//! what a bench or a valve does that no cause of `diagnose` represents, for
//! tests that the answer is `unexplained` and not a vocabulary cause with a
//! high gain. The measurement chain's effects go through
//! [`hidden::experiment_through`], and so does Coulomb friction (a plant
//! of its own, [`friction`](crate::friction)); a wrong spring changes the
//! description's plant itself.

use designer::description::Description;
use reldesign_identify::diagnose::Cause;

use crate::hidden::{self, experiment_through, Chain, Excitation, HiddenCase, Noise, Sampling};
use crate::Rng;

/// An effect no extension of the vocabulary holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outside {
    /// The current probe reads this times the coil current.
    ProbeGain(f64),
    /// The driver applies the recorded voltage this late [s].
    DriverDelay(f64),
    /// The current probe lags by a first-order time constant [s].
    ProbeLag(f64),
    /// The spring (stiffness and preload) is this times the description's.
    Spring(f64),
    /// Coulomb friction on the armature, this times the spring's force
    /// over the stroke, k_s·(z_max − z_min) ([`friction`](crate::friction)).
    Friction(f64),
}

impl Outside {
    /// The measurement chain the effect puts between plant and record (and
    /// the friction the plant meets), for the description `d`.
    fn chain(self, d: &Description) -> Chain {
        match self {
            Outside::ProbeGain(g) => Chain {
                probe_gain: g,
                ..Chain::IDEAL
            },
            Outside::DriverDelay(d) => Chain {
                driver_delay: d,
                ..Chain::IDEAL
            },
            Outside::ProbeLag(tau) => Chain {
                probe_tau: tau,
                ..Chain::IDEAL
            },
            Outside::Friction(f) => Chain {
                coulomb: f * d.mechanics.stiffness * (d.mechanics.z_max - d.mechanics.z_min),
                ..Chain::IDEAL
            },
            Outside::Spring(_) => Chain::IDEAL,
        }
    }
}

/// The record of `examples/<example_file>`'s baseline with `effect` under
/// `excitation` (sampled as [`hidden::hidden_case`] samples), reproducible
/// from `seed`. Its `cause` is [`Cause::Unexplained`]; `drawn` is empty.
pub fn outside_case(
    example_file: &str,
    effect: Outside,
    excitation: &Excitation,
    with_z: bool,
    seed: u64,
) -> HiddenCase {
    let text = hidden::example_text(example_file);
    outside_case_of(&text, example_file, effect, excitation, with_z, seed)
}

/// [`outside_case`] for the description `text` (an example's or a generated
/// device's) named `file_name`.
pub fn outside_case_of(
    text: &str,
    file_name: &str,
    effect: Outside,
    excitation: &Excitation,
    with_z: bool,
    seed: u64,
) -> HiddenCase {
    let (base, baseline_toml) = hidden::baseline_of(text, file_name);
    let mut truth = base.clone();
    if let Outside::Spring(factor) = effect {
        truth.mechanics.stiffness *= factor;
        truth.mechanics.preload *= factor;
    }
    let mut rng = Rng::new(seed ^ 0x0075_1DE);
    let sampling = Sampling::daq(&mut rng);
    let noise = Noise::for_device(&base, excitation);
    let data_csv = experiment_through(
        &truth,
        excitation,
        sampling,
        noise,
        with_z,
        effect.chain(&base),
        &mut rng,
    );
    HiddenCase {
        baseline_toml,
        data_csv,
        cause: Cause::Unexplained,
        drawn: Vec::new(),
        truth,
        sampling,
        excitation: *excitation,
    }
}
