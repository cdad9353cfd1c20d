//! The record classes the diagnosis got wrong on blind records (issue 36 §1),
//! drawn as classes, not as single records: a device of the generator's
//! family [`FAMILY`] (never used to tune anything before), an effect or a
//! pair of effects drawn as [`crate::hidden`] draws them, a noisy record.
//! A seed gives one record; [`TUNING`] seeds were looked at while the
//! diagnosis was changed, [`HELD_OUT`] seeds only to measure it, [`FRESH`],
//! [`ROUND_4`] and [`ROUND_5`] seeds each drawn first after a round of
//! changes (some of their misses then led to the next round).

use std::ops::Range;

use designer::description::{Core, Description};
use designer::model::MU0;
use reldesign_identify::diagnose::Cause;
use reldesign_identify::edit::write_physics;
use reldesign_identify::{fit, FitOptions, FitParam};

use crate::devices::{device, Device};
use crate::hidden::{
    baseline_of, case_of, errors_on, experiment, measured, noise_free, simulate, with_effect_for,
    Excitation, HiddenCase, Noise, Sampling, SAMPLE_PERIOD,
};
use crate::Rng;

/// The device family the classes are drawn from.
pub const FAMILY: u64 = 36;
/// Seeds looked at while the diagnosis was changed.
pub const TUNING: Range<u64> = 0..10;
/// Seeds kept out of every change: they measure it. (The misses of the
/// first two rounds were looked at to make the next change.)
pub const HELD_OUT: Range<u64> = 100..110;
/// Seeds first drawn after the third round (2026-12-02), to measure it on
/// records nobody had looked at: 200–209 after the bounce threshold's scan
/// (seed 209's miss then led to the joint drift fit), 210–219 after that.
pub const FRESH: Range<u64> = 200..220;
/// Seeds first drawn after the fourth round (2026-12-02: the impact
/// windows and the drift fitted on the whole fitted part after its own
/// step, which fresh seeds 213 and 217 led to). Seeds 226 and 239 then led
/// to the fifth round.
pub const ROUND_4: Range<u64> = 220..240;
/// Seeds first drawn after the fifth round (2026-12-02: the earlier causes'
/// own starting points as further starts of a later step).
pub const ROUND_5: Range<u64> = 240..260;

/// A class of records and the answer it must get.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Blind {
    /// A Jiles–Atherton core under unipolar pulses below pull-in (no
    /// motion), against a description whose core saturates: `hysteresis`.
    HysteresisBelowPullIn,
    /// Fringing and eddy currents on a valve: both.
    FringingWithEddy,
    /// A warming relay (resistance drift) that bounces, over 12 cycles:
    /// both.
    DriftWithBounce,
    /// Fringing alone on a relay: fringing, and nothing besides.
    LoneFringing,
}

impl Blind {
    pub const ALL: [Blind; 4] = [
        Blind::HysteresisBelowPullIn,
        Blind::FringingWithEddy,
        Blind::DriftWithBounce,
        Blind::LoneFringing,
    ];

    /// The causes the answer must name (in any order), and nothing else.
    pub fn expected(self) -> &'static [Cause] {
        match self {
            Blind::HysteresisBelowPullIn => &[Cause::Hysteresis],
            Blind::FringingWithEddy => &[Cause::Fringing, Cause::EddyCurrents],
            Blind::DriftWithBounce => &[Cause::ResistanceDrift, Cause::Bouncing],
            Blind::LoneFringing => &[Cause::Fringing],
        }
    }

    /// Whether `answer` (the named causes, or `unexplained`) is right.
    pub fn right(self, answer: &[Cause]) -> bool {
        let expected = self.expected();
        answer.len() == expected.len() && expected.iter().all(|c| answer.contains(c))
    }

    /// The generated device of `seed`: a relay (`index % 3 == 0`) or a
    /// valve, every gap model in turn.
    fn device(self, seed: u64) -> Device {
        let valve = 1 + seed % 2;
        let index = match self {
            Blind::DriftWithBounce | Blind::LoneFringing => 3 * seed,
            Blind::HysteresisBelowPullIn | Blind::FringingWithEddy => 3 * seed + valve,
        };
        device(FAMILY, index, false)
    }

    /// The record of `seed` (with its truth and the description to diagnose
    /// it against).
    pub fn case(self, seed: u64) -> HiddenCase {
        self.case_of_length(seed, 0)
    }

    /// [`Blind::case`] with its excitation repeated until the record has at
    /// least `samples` samples.
    pub fn case_of_length(self, seed: u64, samples: usize) -> HiddenCase {
        let device = self.device(seed);
        let file = format!("{}.toml", device.name);
        let (base, _) = baseline_of(&device.toml, &file);
        let square = at_least(Excitation::square_wave(&base), samples);
        let seed = seed ^ 0x36_0000;
        let draw = |causes: &[Cause], excitation: &Excitation| {
            // a draw that leaves a cause without evidence is drawn again
            (0..MOST_DRAWS)
                .map(|attempt| {
                    let seed = seed ^ (attempt << 32);
                    case_of(&device.toml, &file, causes, excitation, false, seed)
                })
                .find(|case| evidence(self, case).iter().all(|&b| b > 0.0))
                .unwrap_or_else(|| panic!("{file}: no draw of {causes:?} shows every cause"))
        };
        match self {
            Blind::HysteresisBelowPullIn => hysteresis_below_pull_in(&device, &file, seed, samples),
            Blind::FringingWithEddy => draw(&[Cause::Fringing, Cause::EddyCurrents], &square),
            Blind::DriftWithBounce => draw(
                &[Cause::ResistanceDrift, Cause::Bouncing],
                &at_least(Excitation::square_wave(&base).repeated(4), samples),
            ),
            Blind::LoneFringing => draw(&[Cause::Fringing], &square),
        }
    }
}

/// Draws of a record before its class is given up: one is enough unless a
/// cause leaves no evidence (see [`evidence`]).
const MOST_DRAWS: u64 = 8;

/// `truth` without `cause`: the fields its draw sets back to `base`'s.
pub fn without(truth: &Description, base: &Description, cause: Cause) -> Description {
    let mut d = truth.clone();
    match cause {
        Cause::Fringing => d.gap = base.gap.clone(),
        Cause::EddyCurrents => d.coil.eddy = base.coil.eddy,
        Cause::ResistanceDrift => d.coil.resistance_drift = base.coil.resistance_drift,
        Cause::Bouncing => d.mechanics.restitution = base.mechanics.restitution,
        Cause::Hysteresis | Cause::Saturation => d.core = base.core.clone(),
        Cause::None | Cause::Unexplained => {}
    }
    d
}

/// The evidence each of the class's causes leaves in `case`: the truth
/// without that cause against the truth itself (whose error is the floor),
/// n·ln(e_without²/e_truth²) − ln n, the BIC by which the record prefers
/// the cause at the price of one parameter (the diagnosis's criterion,
/// `rank::bic`; n the independent samples, the weights' effective count
/// over the truth's residual's autocorrelation time, as its held-out test
/// counts them, [`errors_on`]). Where it is ≤ 0 the record carries no
/// evidence of the cause and is not a record of the class: it is drawn
/// again. Held-out seed 105 of the warming relay drew a
/// first impact of 0.09 m/s at γ = 0.45, bounces of a few µm: the truth
/// without them replayed the record 0.003 % *better* than the truth itself.
/// Its redraw has +15.5 (the bounce lowers the error by 0.025 %); every
/// other record of seeds 0–9 and 100–109 keeps its first draw, the least
/// evidence among them 155.
pub fn evidence(class: Blind, case: &HiddenCase) -> Vec<f64> {
    let (base, _) = case.inputs();
    class
        .expected()
        .iter()
        .map(|&c| {
            let less = without(&case.truth, &base, c);
            let ([e, floor], n) = errors_on(case, [&less, &case.truth]);
            n * (e * e / (floor * floor)).ln() - n.ln()
        })
        .collect()
}

/// Pulses at most this fraction of the stroke of motion count as "no motion".
const STILL: f64 = 0.01;

/// A Jiles–Atherton truth under the pulse preset scaled below pull-in (the
/// largest of 0.45, 0.36, … of the preset's twice-pull-in amplitude at which
/// the truth's armature moves over at most [`STILL`] of the stroke), against
/// the baseline with the saturating core an engineer would write for that
/// steel: R_core0 the same, φ_sat = μ0·M_sat·A_c from its data sheet (even
/// seeds), or both calibrated on the truth's own noise-free run of the same
/// pulses (odd seeds: the best single-valued core, so that only the loop is
/// left to find).
fn hysteresis_below_pull_in(device: &Device, file: &str, seed: u64, samples: usize) -> HiddenCase {
    let (base, _) = baseline_of(&device.toml, file);
    let mut rng = Rng::new(seed);
    let pulses = Excitation::pulses(&base);
    let mut factor = 0.45;
    let (excitation, truth, drawn) = loop {
        let excitation = pulses.scaled(factor);
        let mut draw = Rng::new(seed);
        let (truth, drawn) = with_effect_for(&base, Cause::Hysteresis, &excitation, &mut draw);
        if stroke_covered(&truth, &excitation) <= STILL || factor < 0.05 {
            break (at_least(excitation, samples), truth, drawn);
        }
        factor *= 0.8;
    };
    let Core::JilesAtherton(ja) = &truth.core else {
        panic!("{file}: the hysteresis draw gave {:?}", truth.core)
    };
    let r0 = match base.core {
        Core::Linear { r0 } | Core::Saturating { r0, .. } => r0,
        Core::JilesAtherton(_) => unreachable!("baselines are linear"),
    };
    let mut described = base.clone();
    described.core = Core::Saturating {
        r0,
        phi_sat: MU0 * ja.m_sat * ja.area,
    };
    if seed % 2 == 1 {
        described = calibrated(&described, &truth, &excitation);
    }
    let text = support::without_design_sections(&device.toml);
    let baseline_toml = write_physics(&text, file, &described)
        .unwrap_or_else(|e| panic!("{file}: writing the description: {e}"));
    let sampling = Sampling::daq(&mut rng);
    let noise = Noise::for_device(&described, &excitation);
    let data_csv = experiment(&truth, &excitation, sampling, noise, false, &mut rng);
    HiddenCase {
        baseline_toml,
        data_csv,
        cause: Cause::Hysteresis,
        drawn,
        truth,
        sampling,
        excitation,
    }
}

/// `described` with its saturating core (R_core0, φ_sat) and R fitted to
/// `truth`'s noise-free record of `excitation`.
fn calibrated(
    described: &Description,
    truth: &Description,
    excitation: &Excitation,
) -> Description {
    let data = measured(&noise_free(truth, excitation), "calibration.csv");
    let Core::Saturating { r0, phi_sat } = described.core else {
        unreachable!("a saturating core")
    };
    let r = described.coil.resistance;
    let param = |path: &str, lower: f64, upper: f64| FitParam {
        path: path.to_owned(),
        lower,
        upper,
    };
    let params = [
        param("coil.resistance", 0.8 * r, 1.2 * r),
        param("core.r0", 0.1 * r0, 10.0 * r0),
        param("core.phi_sat", 0.1 * phi_sat, 10.0 * phi_sat),
    ];
    let options = FitOptions::default();
    fit(described, &data, &params, &options, &|_| {})
        .unwrap_or_else(|e| panic!("{}: calibrating the saturating core: {e}", described.name))
        .description
}

/// `excitation` repeated until it lasts at least `samples` samples of
/// [`SAMPLE_PERIOD`] (as it is when it does already).
pub fn at_least(excitation: Excitation, samples: usize) -> Excitation {
    let once = excitation.duration() / SAMPLE_PERIOD;
    let repeats = (samples as f64 / once).ceil().max(1.0) as usize;
    if repeats > 1 {
        excitation.repeated(repeats)
    } else {
        excitation
    }
}

/// The fraction of the stroke the armature of `d` covers under `excitation`.
pub fn stroke_covered(d: &Description, excitation: &Excitation) -> f64 {
    let (t, v) = excitation.samples(SAMPLE_PERIOD);
    let run = simulate(d, &t, &v);
    let z = run.trajectory.x.iter().map(|x| x[0]);
    let (lo, hi) = z.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
        (a.min(z), b.max(z))
    });
    let m = &d.mechanics;
    (hi - lo) / (m.z_max - m.z_min)
}
