//! Data with a hidden effect: a bundled example, one extension of the
//! measured-data vocabulary added in secret, a simulated noisy experiment.
//!
//! The diagnosis tests need data whose true cause is known. [`baseline`]
//! strips every vocabulary effect from an example (no eddy currents, no
//! drift, no bounce, linear core and gap); [`with_effect`] adds exactly one
//! back with parameters drawn in realistic ranges; [`experiment`] simulates a
//! bench record of the result with Gaussian measurement noise. [`hidden_case`]
//! bundles the three: the baseline as TOML (the example's own text with its
//! comments, rewritten by `description::edit::write_physics`), the data as
//! CSV, and the truth. [`visibility`] says whether the effect stands out of
//! the noise in the current's |φ̇|-weighted NRMSE (jiles-atherton-actuator-
//! model [JA 81]), as the diagnosis needs.
//!
//! The plant is driven by the piecewise-linear interpolation of the clean
//! voltage samples — what a replay of the measured `v` column reconstructs —
//! so a replay of the right model differs from the data by the noise only.

use std::path::{Path, PathBuf};

use designer::description::{parse_str, Core, Description, Gap, JilesAtherton, Reversal};
use designer::model::{Model, Statics, MU0};
use designer::replay::{replay, Replay};
use designer::sim::{EventKind, Limit, Options, PiecewiseLinear};
use reldesign_identify::diagnose::{integrated_autocorrelation, Cause};
use reldesign_identify::edges::{located, replay_input};
use reldesign_identify::edit::write_physics;
use reldesign_identify::wnrmse;

use crate::friction::replay_with_friction;
use crate::{example_path, Rng};

/// Sample period of the records [s] (the semera paper samples at 50 µs).
pub const SAMPLE_PERIOD: f64 = 40e-6;

/// Grid of the least-squares fit of a linear gap to another gap model.
const GAP_FIT_POINTS: usize = 201;

/// A coil-voltage experiment from rest, low level 0 V.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Excitation {
    /// `amplitude` [V] on the first half of each `period` [s], 0 V on the
    /// second half, `cycles` times.
    SquareWave {
        amplitude: f64,
        period: f64,
        cycles: usize,
    },
    /// `amplitude` [V] on `[k·period, k·period + width)`, 0 V on the rest of
    /// each period, `count` times.
    Pulses {
        amplitude: f64,
        width: f64,
        period: f64,
        count: usize,
    },
}

impl Excitation {
    /// Three square-wave cycles that close and open the valve: the amplitude
    /// is twice the pull-in voltage of the example's baseline (within the
    /// supply; the supply's u_max where there is no pull-in voltage), each
    /// half period lasts five electrical time constants of the closed valve
    /// without residual air gap (clamped to 5–100 ms), so that
    /// the flux has decayed below the drop-out level before the next cycle
    /// even when the truth's gap (McLyman) has R_gap(0) = 0.
    pub fn square_wave(desc: &Description) -> Excitation {
        let (amplitude, half) = drive_levels(desc);
        Excitation::SquareWave {
            amplitude,
            period: 2.0 * half,
            cycles: 3,
        }
    }

    /// Three pulses as in the JA paper's measurements ([JA §5.2]): on for one
    /// square-wave half period, off for two.
    pub fn pulses(desc: &Description) -> Excitation {
        let (amplitude, half) = drive_levels(desc);
        Excitation::Pulses {
            amplitude,
            width: half,
            period: 3.0 * half,
            count: 3,
        }
    }

    /// One step to the square wave's amplitude, held for two of its periods
    /// to the end of the record: the flux rises and never turns (no λ–i
    /// loop).
    pub fn step(desc: &Description) -> Excitation {
        let (amplitude, half) = drive_levels(desc);
        Excitation::Pulses {
            amplitude,
            width: 4.0 * half,
            period: 4.0 * half,
            count: 1,
        }
    }

    /// The same excitation at `factor` times its amplitude.
    pub fn scaled(self, factor: f64) -> Excitation {
        let (amplitude, on, period, n) = self.shape();
        self.reshaped(factor * amplitude, on, period, n)
    }

    /// The same excitation repeated `n` times as often (longer records).
    pub fn repeated(self, n: usize) -> Excitation {
        let (amplitude, on, period, periods) = self.shape();
        self.reshaped(amplitude, on, period, periods * n)
    }

    /// The same excitation with its period (and width) rounded to whole
    /// multiples of `sample_period`, so that every edge lies on a sample
    /// instant of a record that starts at 0.
    pub fn on_grid(self, sample_period: f64) -> Excitation {
        let round = |x: f64| (x / sample_period).round().max(1.0) * sample_period;
        let (amplitude, on, period, n) = self.shape();
        self.reshaped(amplitude, round(on), round(period), n)
    }

    /// Length of the record [s].
    pub fn duration(&self) -> f64 {
        let (_, _, period, n) = self.shape();
        period * n as f64
    }

    /// The same kind of excitation with the shape `(amplitude, on-time,
    /// period, periods)` of [`Excitation::shape`]; a square wave's period is
    /// twice its on-time.
    fn reshaped(self, amplitude: f64, on: f64, period: f64, n: usize) -> Excitation {
        match self {
            Excitation::SquareWave { .. } => Excitation::SquareWave {
                amplitude,
                period: 2.0 * on,
                cycles: n,
            },
            Excitation::Pulses { .. } => Excitation::Pulses {
                amplitude,
                width: on,
                period,
                count: n,
            },
        }
    }

    /// (amplitude [V], on-time [s], period [s], periods).
    fn shape(&self) -> (f64, f64, f64, usize) {
        match *self {
            Excitation::SquareWave {
                amplitude,
                period,
                cycles,
            } => (amplitude, 0.5 * period, period, cycles),
            Excitation::Pulses {
                amplitude,
                width,
                period,
                count,
            } => (amplitude, width, period, count),
        }
    }

    /// The voltage at `t` (right-continuous at the edges).
    pub fn value(&self, t: f64) -> f64 {
        let (amplitude, on, period, n) = self.shape();
        let k = (t / period).floor();
        let within = k >= 0.0 && (k as usize) < n && t - k * period < on;
        if within {
            amplitude
        } else {
            0.0
        }
    }

    /// The voltage's steps `(t, value)` from 0, in order.
    pub fn steps(&self) -> Vec<(f64, f64)> {
        let (amplitude, on, period, n) = self.shape();
        (0..n)
            .flat_map(|k| {
                let start = k as f64 * period;
                [(start, amplitude), (start + on, 0.0)]
            })
            .collect()
    }

    /// The voltage as the supply applies it, every step `delay` later than
    /// in [`Excitation::value`] (0 V before the first).
    pub fn input(&self, delay: f64) -> PiecewiseLinear {
        let mut points = vec![(0.0, 0.0)];
        points.extend(self.steps().into_iter().map(|(t, v)| (t + delay, v)));
        PiecewiseLinear::steps(&points).unwrap_or_else(|e| panic!("{self:?}: {e}"))
    }

    /// Sample times k·Δ on [0, duration] and the clean voltage there.
    pub fn samples(&self, sample_period: f64) -> (Vec<f64>, Vec<f64>) {
        let n = (self.duration() / sample_period).round() as usize + 1;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * sample_period).collect();
        let v = t.iter().map(|&t| self.value(t)).collect();
        (t, v)
    }
}

/// (amplitude [V], half period [s]) of the presets, from the baseline:
/// twice the pull-in voltage (at most the supply's u_max), and five
/// time constants τ = (N² + R·k_e)/(R·R_core0) of the gap-less circuit.
fn drive_levels(desc: &Description) -> (f64, f64) {
    let base = baseline(desc);
    let mut model = Model::build(&base);
    let u_max = base.supply.u_max;
    // (No pull-in voltage, e.g. no spring: the armature moves at any flux;
    // the supply's own voltage then.)
    let amplitude = match Statics::of(&mut model).pull_in {
        Ok(p) if p.voltage > 0.0 => (2.0 * p.voltage).min(u_max),
        _ => u_max,
    };
    let coil = &base.coil;
    let r_closed = linear_r0(&base.core);
    let tau =
        (coil.turns * coil.turns + coil.resistance * coil.eddy) / (coil.resistance * r_closed);
    (amplitude, (5.0 * tau).clamp(5e-3, 100e-3))
}

/// Standard deviations of the measurement noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// σ_v [V]
    pub voltage: f64,
    /// σ_i [A]
    pub current: f64,
    /// σ_z [m]
    pub position: f64,
}

impl Default for Noise {
    /// σ_v = 15 mV, σ_i = 1 mA (semera paper, [SE Table II]), σ_z = 1 µm.
    fn default() -> Self {
        Noise {
            voltage: 15e-3,
            current: 1e-3,
            position: 1e-6,
        }
    }
}

impl Noise {
    /// σ_v = 15 mV, σ_i = 0.1 % of the steady current amplitude/R of
    /// `excitation` (the semera paper's 1 mA at about 1 A), within
    /// 0.05–1 mA (a relay's probe resolves 0.05 mA), σ_z = 1 µm.
    pub fn for_device(desc: &Description, excitation: &Excitation) -> Noise {
        let amplitude = excitation
            .steps()
            .iter()
            .map(|s| s.1.abs())
            .fold(0.0, f64::max);
        let steady = amplitude / desc.coil.resistance;
        Noise {
            current: (1e-3 * steady).clamp(0.05e-3, 1e-3),
            ..Noise::default()
        }
    }

    /// Noise-free records (for tests of the simulation itself).
    pub const NONE: Noise = Noise {
        voltage: 0.0,
        current: 0.0,
        position: 0.0,
    };
}

// ------------------------------------------------------------------ baseline

/// The same actuator without any effect of the vocabulary: k_e = 0, no
/// resistance drift, no bounce (γ = 0), a linear core (R_core0 = r0; for a
/// Jiles–Atherton core see [`ja_linear_r0`]) and a linear gap (the original
/// one when linear, else the least-squares line through R_gap on
/// [z_min, z_max], [`fit_linear_gap`]). Design sections are kept.
pub fn baseline(desc: &Description) -> Description {
    let mut b = desc.clone();
    b.coil.eddy = 0.0;
    b.coil.resistance_drift = 0.0;
    b.mechanics.restitution = 0.0;
    b.core = Core::Linear {
        r0: linear_r0(&desc.core),
    };
    if !matches!(desc.gap, Gap::Linear { .. }) {
        let m = &desc.mechanics;
        b.gap = fit_linear_gap(&desc.gap, m.z_min, m.z_max);
    }
    b
}

/// R_core0 of the core's linear equivalent.
fn linear_r0(core: &Core) -> f64 {
    match core {
        Core::Linear { r0 } | Core::Saturating { r0, .. } => *r0,
        Core::JilesAtherton(ja) => ja_linear_r0(ja),
    }
}

/// The linear core of a Jiles–Atherton core: R = l_c/(μ0·(1 + χ)·A_c) with
/// the initial anhysteretic susceptibility of the mean-field model,
/// χ = χ_an/(1 − α·χ_an), χ_an = μ0·M_sat/(3b) (the slope of M_an(B_e) =
/// M_sat·L(B_e/b), [JA 21–23], at the origin; L'(0) = 1/3). The mean-field
/// gain is capped at 20 (α·χ_an ≤ 0.95) where the model is near its
/// instability.
pub fn ja_linear_r0(ja: &JilesAtherton) -> f64 {
    let chi_an = MU0 * ja.m_sat / (3.0 * ja.b);
    let chi = chi_an / (1.0 - ja.alpha * chi_an).max(0.05);
    ja.length / (MU0 * (1.0 + chi) * ja.area)
}

/// The line offset + slope·z fitted to R_gap by least squares on a uniform
/// grid of [z_min, z_max]; when the fitted offset is negative (not allowed),
/// the best line through the origin.
pub fn fit_linear_gap(gap: &Gap, z_min: f64, z_max: f64) -> Gap {
    let n = GAP_FIT_POINTS;
    let z: Vec<f64> = (0..n)
        .map(|k| z_min + (z_max - z_min) * k as f64 / (n - 1) as f64)
        .collect();
    let r: Vec<f64> = z.iter().map(|&z| gap_reluctance(gap, z)).collect();
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let (zm, rm) = (mean(&z), mean(&r));
    let szz: f64 = z.iter().map(|z| (z - zm) * (z - zm)).sum();
    let szr: f64 = z.iter().zip(&r).map(|(z, r)| (z - zm) * (r - rm)).sum();
    let slope = szr / szz;
    let offset = rm - slope * zm;
    if offset >= 0.0 {
        return Gap::Linear { slope, offset };
    }
    let sz2: f64 = z.iter().map(|z| z * z).sum();
    let szr0: f64 = z.iter().zip(&r).map(|(z, r)| z * r).sum();
    Gap::Linear {
        slope: szr0 / sz2,
        offset: 0.0,
    }
}

/// R_gap(z) as the model computes it.
fn gap_reluctance(gap: &Gap, z: f64) -> f64 {
    match gap {
        Gap::Linear { slope, offset } => offset + slope * z,
        Gap::Table { z: zs, r, r_prime } => {
            designer::model::Spline::fit(zs, r, r_prime.as_deref())
                .eval(z)
                .0
        }
        // [PT 6] McLyman and its fitted form, with the z → 0⁺ limit.
        Gap::McLyman {
            area,
            winding_length,
        } if z > 0.0 => {
            (z / (MU0 * area)) / (1.0 + z / area.sqrt() * (2.0 * winding_length / z).ln())
        }
        Gap::McLymanFit {
            r0,
            r0_prime,
            k1,
            k2,
        } if z > 0.0 => r0 + r0_prime * z / (1.0 + k1 * z * (k2 / z).ln()),
        Gap::McLymanFit { r0, .. } => *r0,
        Gap::McLyman { .. } => 0.0,
    }
}

// ------------------------------------------------------------------- effects

/// What a drawn effect is scaled to: the baseline's run of the experiment.
struct Context {
    /// Peak |φ| [Wb] and the gap length when it is reached.
    peak_flux: f64,
    z_at_peak: f64,
    /// Record length [s].
    duration: f64,
    /// Slowest impact speed at z_min [m/s] (∞ without impacts).
    impact_speed: f64,
}

impl Context {
    fn of(baseline: &Description, excitation: &Excitation) -> Context {
        let (t, v) = excitation.samples(SAMPLE_PERIOD);
        let run = simulate(baseline, &t, &v);
        let (k, peak_flux) = run
            .trajectory
            .x
            .iter()
            .map(|x| x[2].abs())
            .enumerate()
            .fold(
                (0, 0.0),
                |best, (k, f)| if f > best.1 { (k, f) } else { best },
            );
        let impact_speed = run
            .trajectory
            .events
            .iter()
            .filter_map(|e| match e.kind {
                EventKind::Impact {
                    limit: Limit::Min,
                    v_before,
                    ..
                } => Some(v_before.abs()),
                _ => None,
            })
            .fold(f64::INFINITY, f64::min);
        Context {
            peak_flux,
            z_at_peak: run.trajectory.x[k][0],
            duration: excitation.duration(),
            impact_speed,
        }
    }
}

/// [`with_effect_for`] scaled to the baseline's square-wave preset
/// ([`Excitation::square_wave`]).
pub fn with_effect(
    baseline: &Description,
    cause: Cause,
    rng: &mut Rng,
) -> (Description, Vec<(String, f64)>) {
    with_effect_for(baseline, cause, &Excitation::square_wave(baseline), rng)
}

/// The baseline with the one extension `cause` added, its parameters drawn
/// in realistic ranges scaled to the baseline's run of `excitation`, and the
/// drawn values by their description keys (`coil.eddy`, …). `Cause::None`
/// and `Cause::Unexplained` return the baseline unchanged.
pub fn with_effect_for(
    baseline: &Description,
    cause: Cause,
    excitation: &Excitation,
    rng: &mut Rng,
) -> (Description, Vec<(String, f64)>) {
    let mut d = baseline.clone();
    let ctx = Context::of(baseline, excitation);
    let drawn = match cause {
        Cause::EddyCurrents => draw_eddy(&mut d, rng),
        Cause::Saturation => draw_saturation(&mut d, &ctx, rng),
        Cause::Hysteresis => draw_hysteresis(&mut d, &ctx, rng),
        Cause::Fringing => draw_fringing(&mut d, rng),
        Cause::ResistanceDrift => draw_drift(&mut d, &ctx, rng),
        Cause::Bouncing => draw_bounce(&mut d, &ctx, rng),
        // effects outside the vocabulary: `crate::outside`
        Cause::None | Cause::Unexplained => vec![],
    };
    let drawn = drawn.into_iter().map(|(k, v)| (k.to_string(), v)).collect();
    (d, drawn)
}

type Drawn = Vec<(&'static str, f64)>;

/// The eddy time constant k_e/R_total is 5–30 % of the coil's N²/(R·R_total)
/// (the bundled valves have 6–8 %): k_e = ratio·N²/R.
fn draw_eddy(d: &mut Description, rng: &mut Rng) -> Drawn {
    let ratio = rng.uniform(0.05, 0.30);
    let c = &mut d.coil;
    c.eddy = ratio * c.turns * c.turns / c.resistance;
    vec![("coil.eddy", c.eddy)]
}

/// The experiment's steady peak flux reaches a fraction f ∈ [0.5, 0.8] of
/// φ_sat. The baseline's peak ampere-turns N·i = (R_gap + r0)·φ_b stay, so
/// with saturation (R_gap + r0/(1 − f))·f·φ_sat = (R_gap + r0)·φ_b.
fn draw_saturation(d: &mut Description, ctx: &Context, rng: &mut Rng) -> Drawn {
    let f = rng.uniform(0.5, 0.8);
    let r0 = linear_r0(&d.core);
    let r_gap = gap_reluctance(&d.gap, ctx.z_at_peak);
    let phi_sat = ctx.peak_flux * (r_gap + r0) / (f * (r_gap + r0 / (1.0 - f)));
    d.core = Core::Saturating { r0, phi_sat };
    vec![("core.phi_sat", phi_sat)]
}

/// A steel like the JA paper's ([JA Table 2]: μ0·M_sat = 1.822 T, b = 2.45 mT,
/// c = 0.736, κ = 943 A/m, α·χ_an = 0.907) on this actuator: c ∈ [0.6, 0.85],
/// κ ∈ [700, 1200] A/m, b/(μ0·M_sat) within ×[0.8, 1.25] of the paper's,
/// α·χ_an ∈ [0.85, 0.93]; the pole area is the linear gap's
/// A_c = 1/(μ0·slope); M_sat puts the baseline's peak flux density at
/// 60–90 % of μ0·M_sat, and l_c makes the initial reluctance
/// ([`ja_linear_r0`]) the baseline's r0.
fn draw_hysteresis(d: &mut Description, ctx: &Context, rng: &mut Rng) -> Drawn {
    let area = match d.gap {
        Gap::Linear { slope, .. } => 1.0 / (MU0 * slope),
        _ => 1e-5,
    };
    let r0 = linear_r0(&d.core);
    let b_sat = ctx.peak_flux / area / rng.uniform(0.6, 0.9);
    let m_sat = b_sat / MU0;
    let b = 2.45e-3 / 1.822 * b_sat * rng.uniform(0.8, 1.25);
    let chi_an = b_sat / (3.0 * b);
    let alpha = rng.uniform(0.85, 0.93) / chi_an;
    let mut ja = JilesAtherton {
        length: 1.0,
        area,
        m_sat,
        b,
        c: rng.uniform(0.6, 0.85),
        kappa: rng.uniform(700.0, 1200.0),
        alpha,
        epsilon: 1e-3,
        reversal: Reversal::Clamp,
    };
    ja.length = r0 / ja_linear_r0(&ja);
    d.core = Core::JilesAtherton(ja.clone());
    vec![
        ("core.length", ja.length),
        ("core.area", ja.area),
        ("core.m_sat", ja.m_sat),
        ("core.b", ja.b),
        ("core.c", ja.c),
        ("core.kappa", ja.kappa),
        ("core.alpha", ja.alpha),
    ]
}

/// McLyman's gap with A = 1/(μ0·slope) (the linear gap's slope at z → 0) and
/// l_w such that fringing lowers R_gap at z_max by a fraction r ∈ [0.15, 0.4]
/// (the perfect-tracking valve's [PT Table 1] gives 43 %):
/// 1 + z_max/√A·ln(2·l_w/z_max) = 1/(1 − r). Below 15 % the semera valve's
/// baseline misses its data by less than 3× the noise.
fn draw_fringing(d: &mut Description, rng: &mut Rng) -> Drawn {
    let slope = match d.gap {
        Gap::Linear { slope, .. } => slope,
        _ => gap_reluctance(&d.gap, d.mechanics.z_max) / d.mechanics.z_max,
    };
    let area = 1.0 / (MU0 * slope);
    let r = rng.uniform(0.15, 0.4);
    let z_max = d.mechanics.z_max;
    let winding_length = 0.5 * z_max * ((1.0 / (1.0 - r) - 1.0) * area.sqrt() / z_max).exp();
    d.gap = Gap::McLyman {
        area,
        winding_length,
    };
    vec![("gap.area", area), ("gap.winding_length", winding_length)]
}

/// Self-heating: R rises by 3–10 % over the record (copper warms by
/// 8–25 K).
fn draw_drift(d: &mut Description, ctx: &Context, rng: &mut Rng) -> Drawn {
    let c = &mut d.coil;
    c.resistance_drift = rng.uniform(0.03, 0.10) * c.resistance / ctx.duration;
    vec![("coil.resistance_drift", c.resistance_drift)]
}

/// γ ∈ [0.4, 0.7] (steel on steel is 0.3–0.7; below 0.4 the bounces of a
/// three-cycle record hide in the noise: the baseline's wNRMSE is then less
/// than 3× the floor), v_ε 5–20 % of the slowest closing impact speed, so
/// that every closing impact bounces at least once.
fn draw_bounce(d: &mut Description, ctx: &Context, rng: &mut Rng) -> Drawn {
    let m = &mut d.mechanics;
    m.restitution = rng.uniform(0.4, 0.7);
    let speed = if ctx.impact_speed.is_finite() {
        ctx.impact_speed
    } else {
        0.1
    };
    m.bounce_threshold = rng.uniform(0.05, 0.2) * speed;
    vec![
        ("mechanics.restitution", m.restitution),
        ("mechanics.bounce_threshold", m.bounce_threshold),
    ]
}

// ---------------------------------------------------------------- experiment

/// The plant driven by the piecewise-linear interpolation of `(t, v)`,
/// recorded at `t`.
pub fn simulate(desc: &Description, t: &[f64], v: &[f64]) -> Replay {
    let input = PiecewiseLinear::new(t.to_vec(), v.to_vec())
        .unwrap_or_else(|e| panic!("{}: input samples: {e}", desc.name));
    let mut model = Model::build(desc);
    replay(&mut model, &input, t, &Options::default())
        .unwrap_or_else(|e| panic!("{}: simulation failed: {e}", desc.name))
}

/// How a record is sampled: every `period`, with the supply's steps
/// `delay` after the excitation's nominal instants (0: every edge on a
/// sample instant, as `reldesign simulate` writes; a fraction of the period:
/// edges between samples, as on a real DAQ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sampling {
    pub period: f64,
    pub delay: f64,
}

impl Sampling {
    /// Every [`SAMPLE_PERIOD`], the edges at a random point between samples.
    pub fn daq(rng: &mut Rng) -> Sampling {
        Sampling {
            period: SAMPLE_PERIOD,
            delay: rng.uniform(0.0, SAMPLE_PERIOD),
        }
    }
}

/// A simulated bench record of `truth` under `excitation`, as CSV text: a
/// `#` comment line (which names neither the cause nor the parameters), the
/// header `t,v,i` (`t,v,i,z` with `with_z`), then one row per sample in
/// shortest round-trip notation. The plant sees the supply's exact steps
/// (delayed by `sampling.delay`); the samples are the instantaneous values
/// at k·period, with noise added to the measured columns only.
pub fn experiment(
    truth: &Description,
    excitation: &Excitation,
    sampling: Sampling,
    noise: Noise,
    with_z: bool,
    rng: &mut Rng,
) -> String {
    experiment_through(
        truth,
        excitation,
        sampling,
        noise,
        with_z,
        Chain::IDEAL,
        rng,
    )
}

/// The measurement chain between the plant and the record: what a bench
/// adds that no actuator description holds (issue 17 §2 hides these).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chain {
    /// The current probe reads this times the coil current.
    pub probe_gain: f64,
    /// The current probe's first-order time constant [s] (0: ideal).
    pub probe_tau: f64,
    /// The driver applies the recorded voltage this late [s].
    pub driver_delay: f64,
    /// A Coulomb friction force on the armature [N] (of the bench's valve,
    /// not of its instruments, but no description holds it either:
    /// [`friction`](crate::friction)).
    pub coulomb: f64,
}

impl Chain {
    /// An ideal probe and driver.
    pub const IDEAL: Chain = Chain {
        probe_gain: 1.0,
        probe_tau: 0.0,
        driver_delay: 0.0,
        coulomb: 0.0,
    };
}

/// [`experiment`] through the measurement chain `chain`: the plant runs on
/// the supply's steps `chain.driver_delay` later than the recorded voltage
/// shows them, and the recorded current is the coil current through the
/// probe's gain and first-order lag (exact for the piecewise-linear current
/// between samples).
pub fn experiment_through(
    truth: &Description,
    excitation: &Excitation,
    sampling: Sampling,
    noise: Noise,
    with_z: bool,
    chain: Chain,
    rng: &mut Rng,
) -> String {
    let input = excitation.input(sampling.delay + chain.driver_delay);
    let n = ((excitation.duration() + sampling.delay) / sampling.period).floor() as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * sampling.period).collect();
    let mut model = Model::build(truth);
    let run = if chain.coulomb > 0.0 {
        replay_with_friction(&mut model, chain.coulomb, &input, &t, &Options::default())
    } else {
        replay(&mut model, &input, &t, &Options::default())
    }
    .unwrap_or_else(|e| panic!("{}: simulation failed: {e}", truth.name));
    let commanded = excitation.input(sampling.delay);
    let probed = probe(&run.current, chain, sampling.period);
    let mut out = format!(
        "# simulated bench record of {}: {excitation:?}, sigma_v = {} V, sigma_i = {} A\n",
        truth.name, noise.voltage, noise.current
    );
    out.push_str(if with_z { "t,v,i,z\n" } else { "t,v,i\n" });
    for k in 0..t.len() {
        let v = if chain.driver_delay > 0.0 {
            designer::sim::Input::value(&commanded, t[k])
        } else {
            run.voltage[k]
        };
        let vm = v + noise.voltage * gaussian(rng);
        let im = probed[k] + noise.current * gaussian(rng);
        out.push_str(&format!("{:e},{vm:e},{im:e}", t[k]));
        if with_z {
            let zm = run.trajectory.x[k][0] + noise.position * gaussian(rng);
            out.push_str(&format!(",{zm:e}"));
        }
        out.push('\n');
    }
    out
}

/// The current as `chain`'s probe reads it, sampled every `period`: the gain,
/// then the first-order lag y' = (i − y)/τ solved exactly for an input linear
/// between samples.
fn probe(current: &[f64], chain: Chain, period: f64) -> Vec<f64> {
    let gained = current.iter().map(|i| chain.probe_gain * i);
    if !(chain.probe_tau > 0.0) {
        return gained.collect();
    }
    let a = (-period / chain.probe_tau).exp();
    // the response to a unit ramp's share over one step
    let b = 1.0 - chain.probe_tau / period * (1.0 - a);
    let mut out = Vec::with_capacity(current.len());
    let mut prev: Option<(f64, f64)> = None; // (input, output) at the last sample
    for x in gained {
        let y = match prev {
            None => x,
            Some((x0, y0)) => a * y0 + (1.0 - a) * x0 + b * (x - x0),
        };
        out.push(y);
        prev = Some((x, y));
    }
    out
}

/// The candidates' fitted errors, best first: `cause:wNRMSE%` each.
pub fn ranking_summary(d: &reldesign_identify::diagnose::Diagnosis) -> String {
    d.ranking
        .iter()
        .map(|s| format!("{}:{:.3}%", s.cause, 100.0 * s.wnrmse_fit))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A standard normal sample (Box–Muller).
pub fn gaussian(rng: &mut Rng) -> f64 {
    let u1 = 1.0 - rng.uniform(0.0, 1.0); // in (0, 1]
    let u2 = rng.uniform(0.0, 1.0);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

// -------------------------------------------------------------- hidden cases

/// A diagnosis exercise: the baseline model, data with one hidden effect,
/// and the answer.
#[derive(Debug, Clone)]
pub struct HiddenCase {
    /// The example's text with the baseline physics (comments kept).
    pub baseline_toml: String,
    /// The noisy record (`t,v,i[,z]`).
    pub data_csv: String,
    pub cause: Cause,
    /// The drawn parameters of the extension by description key.
    pub drawn: Vec<(String, f64)>,
    /// The model the data was simulated with.
    pub truth: Description,
    /// How the record was sampled (where its voltage edges really are).
    pub sampling: Sampling,
    /// The excitation applied.
    pub excitation: Excitation,
}

/// The case for `cause` on `examples/<example_file>` under `excitation`
/// (sampled every [`SAMPLE_PERIOD`] with the edges between samples,
/// default [`Noise`]), reproducible from `seed`. For `Cause::None` the data
/// comes from the baseline itself.
pub fn hidden_case(
    example_file: &str,
    cause: Cause,
    excitation: &Excitation,
    with_z: bool,
    seed: u64,
) -> HiddenCase {
    let text = example_text(example_file);
    hidden_case_of(&text, example_file, cause, excitation, with_z, seed)
}

/// [`hidden_case`] for the description `text` (an example's or a generated
/// device's) named `file_name`; the noise as [`Noise::for_device`].
pub fn hidden_case_of(
    text: &str,
    file_name: &str,
    cause: Cause,
    excitation: &Excitation,
    with_z: bool,
    seed: u64,
) -> HiddenCase {
    case_of(text, file_name, &[cause], excitation, with_z, seed)
}

/// The case with the extensions `causes` drawn one on top of the other (the
/// first is the case's `cause`), on the description `text` named `file_name`.
pub fn case_of(
    text: &str,
    file_name: &str,
    causes: &[Cause],
    excitation: &Excitation,
    with_z: bool,
    seed: u64,
) -> HiddenCase {
    let (base, baseline_toml) = baseline_of(text, file_name);
    let mut rng = Rng::new(seed);
    let mut truth = base.clone();
    let mut drawn = Vec::new();
    for &cause in causes {
        let (next, values) = with_effect_for(&truth, cause, excitation, &mut rng);
        truth = next;
        drawn.extend(values);
    }
    let sampling = Sampling::daq(&mut rng);
    let noise = Noise::for_device(&base, excitation);
    let data_csv = experiment(&truth, excitation, sampling, noise, with_z, &mut rng);
    HiddenCase {
        baseline_toml,
        data_csv,
        cause: causes.first().copied().unwrap_or(Cause::None),
        drawn,
        truth,
        sampling,
        excitation: *excitation,
    }
}

/// The description `text`'s [`baseline`], and as TOML: the text rewritten
/// (comments kept), its design sections left out (a bench recording needs
/// no controller; a truth such as a Jiles–Atherton core may not admit the
/// design's [trajectory]).
pub fn baseline_of(text: &str, file_name: &str) -> (Description, String) {
    let text = &support::without_design_sections(text);
    let desc = parse_str(text, file_name).unwrap_or_else(|e| panic!("{e}"));
    let base = baseline(&desc);
    let toml = write_physics(text, file_name, &base)
        .unwrap_or_else(|e| panic!("writing the baseline: {e}"));
    (base, toml)
}

impl HiddenCase {
    /// The description and the record as the CLI reads the two files.
    pub fn inputs(&self) -> (Description, reldesign_identify::Measured) {
        let model =
            parse_str(&self.baseline_toml, "baseline.toml").unwrap_or_else(|e| panic!("{e}"));
        (model, measured(&self.data_csv, "data.csv"))
    }
}

/// The record `csv` (named `file_name`) as the diagnosis reads it.
pub fn measured(csv: &str, file_name: &str) -> reldesign_identify::Measured {
    let record = designer::record::Record::parse(csv, file_name).unwrap_or_else(|e| panic!("{e}"));
    reldesign_identify::Measured::from_record(&record).unwrap_or_else(|e| panic!("{e}"))
}

/// [`experiment`] without noise, every edge on a sample instant: the
/// simulation of `truth` under `excitation`, digit for digit.
pub fn noise_free(truth: &Description, excitation: &Excitation) -> String {
    let sampling = Sampling {
        period: SAMPLE_PERIOD,
        delay: 0.0,
    };
    experiment(
        truth,
        excitation,
        sampling,
        Noise::NONE,
        false,
        &mut Rng::new(0),
    )
}

/// [`hidden_case`] with two effects at once (issue 17 §1): `causes[0]`'s
/// extension drawn on the baseline, then `causes[1]`'s on top of it; the
/// case's `cause` is the first, `drawn` holds both draws.
pub fn hidden_pair(
    example_file: &str,
    causes: [Cause; 2],
    excitation: &Excitation,
    with_z: bool,
    seed: u64,
) -> HiddenCase {
    let text = example_text(example_file);
    case_of(&text, example_file, &causes, excitation, with_z, seed)
}

/// The text of `examples/<example_file>`.
pub fn example_text(example_file: &str) -> String {
    let path = example_path(example_file);
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: cannot read: {e}", path.display()))
}

/// Writes `baseline.toml` and `data.csv` into `dir` (created if needed).
pub fn write_case(dir: &Path, case: &HiddenCase) -> (PathBuf, PathBuf) {
    std::fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let model = dir.join("baseline.toml");
    let data = dir.join("data.csv");
    for (path, text) in [(&model, &case.baseline_toml), (&data, &case.data_csv)] {
        std::fs::write(path, text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
    (model, data)
}

// ---------------------------------------------------------------- visibility

/// How far the baseline misses the data, against what noise alone gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Visibility {
    /// wNRMSE of the baseline's current replayed on the measured voltage.
    pub baseline_wnrmse: f64,
    /// wNRMSE of the truth's current replayed the same way: the floor any
    /// extended model can reach.
    pub noise_wnrmse: f64,
}

impl Visibility {
    /// baseline / floor.
    pub fn ratio(&self) -> f64 {
        self.baseline_wnrmse / self.noise_wnrmse
    }
}

/// Replays the baseline and the truth on the measured voltage (as the
/// diagnosis does: its edges placed by the baseline) and compares their
/// currents with the measured one by [JA 81], weighted by |φ̇| estimated from
/// the data as (v − R·i)/N (the coil equation, baseline R and N).
pub fn visibility(case: &HiddenCase) -> Visibility {
    let (base, _) = case.inputs();
    let ([baseline_wnrmse, noise_wnrmse], _) = errors_on(case, [&base, &case.truth]);
    Visibility {
        baseline_wnrmse,
        noise_wnrmse,
    }
}

/// The wNRMSE of each of `models`' currents replayed on `case`'s measured
/// voltage, as [`visibility`] weighs them, and the independent samples
/// behind them: the weights' effective count (Kish, (Σw)²/Σw², as the
/// diagnosis's BIC counts them) over the integrated autocorrelation time of
/// the last model's weighted residual (as its held-out test counts them).
pub fn errors_on<const K: usize>(case: &HiddenCase, models: [&Description; K]) -> ([f64; K], f64) {
    let (base, data) = case.inputs();
    let data = reldesign_identify::Measured {
        edges: Some(located(&base, &data)),
        ..data
    };
    let input = replay_input(&data).unwrap_or_else(|e| panic!("{e}"));
    let (n, r) = (base.coil.turns, base.coil.resistance);
    let w: Vec<f64> = data
        .v
        .iter()
        .zip(&data.i)
        .map(|(v, i)| ((v - r * i) / n).abs())
        .collect();
    let currents = models.map(|d| {
        let mut model = Model::build(d);
        replay(&mut model, &input, &data.t, &Options::default())
            .unwrap_or_else(|e| panic!("{}: simulation failed: {e}", d.name))
            .current
    });
    let errors = currents.each_ref().map(|c| wnrmse(c, &data.i, &w));
    let residual: Vec<f64> = (currents.last().into_iter().flatten())
        .zip(&data.i)
        .zip(&w)
        .map(|((c, i), w)| w.sqrt() * (c - i))
        .collect();
    let (sum, squares) = w.iter().fold((0.0, 0.0), |(s, q), x| (s + x, q + x * x));
    (
        errors,
        sum * sum / squares / integrated_autocorrelation(&residual),
    )
}
