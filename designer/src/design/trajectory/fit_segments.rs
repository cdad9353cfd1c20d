//! Fitting a reference with a [`Segments`] table: adaptive knots.
//!
//! The knots start at the motion ends and the forced breaks (e.g. the
//! switching times of the energy-optimal reference, where its jerk has kinks)
//! and every segment whose error exceeds [`ACCEPT`] × the tolerance on a fine
//! sample is bisected, pass by pass, until all segments pass or the segment
//! budget is exhausted. The knot values are the source's own: z, v, a and jerk at t_k,
//! a and jerk at t_{k+1}. Inside a segment z and v are the exact integrals of
//! the Hermite acceleration from the knot values, so errors do not accumulate
//! across segments; the remaining discontinuities of z and v at the knots are
//! reported (they are bounded by the checked end-of-segment error).
//!
//! **One-sided values.** A `Reference` rests outside its motion, so at t₀ and
//! t_f its jerk is that of the rest (0), not the motion's. At the motion ends
//! the knot jerk is therefore the one-sided limit from inside the motion, and
//! at forced breaks all four values are one-sided limits from each side (the
//! table jumps there only if the source does). One-sided limits are quadratic
//! extrapolations 3·f(t ± δ) − 3·f(t ± 2δ) + f(t ± 3δ), δ = 10⁻⁶ of the
//! neighbouring gap (error O(δ³); exact for a quintic position). z, v and a
//! at the ends are the source's rest values (the soft-landing conditions
//! v = a = 0 at t₀ and t_f).
//!
//! **Error measure.** |Δz| ≤ `tol.z` (metres, absolute); |Δv|, |Δa|, |Δjerk|
//! relative to max |v|, |a|, |jerk| of the source over the motion (from a
//! uniform pre-scan). On each segment, a and jerk are compared at `samples − 1`
//! interior points, z and v at those and at the segment end (the jump into
//! the next knot). A segment is accepted at [`ACCEPT`] = 90 % of the
//! tolerance on its samples, a margin for the error between samples.

use std::fmt;

use super::reference::{Flat, Reference};
use super::segments::{Segment, Segments};

/// A segment passes when its sampled errors are within this fraction of the
/// tolerance (the error between samples is then still within tolerance).
pub const ACCEPT: f64 = 0.9;

/// Which signal of the reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Signal {
    Z,
    V,
    A,
    Jerk,
}

impl fmt::Display for Signal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Signal::Z => "z",
            Signal::V => "v",
            Signal::A => "a",
            Signal::Jerk => "jerk",
        })
    }
}

/// Tolerances of a table against its source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentTolerance {
    /// Position error [m], absolute.
    pub z: f64,
    /// Velocity error relative to max |v| of the source.
    pub v: f64,
    /// Acceleration error relative to max |a| of the source.
    pub a: f64,
    /// Jerk error relative to max |jerk| of the source.
    pub jerk: f64,
    /// Error if more segments would be needed.
    pub max_segments: usize,
    /// Check points per segment (the error is sampled at τ = h·i/samples).
    pub samples: usize,
    /// Uniform points of the pre-scan for max |v|, |a|, |jerk|.
    pub scan: usize,
}

impl Default for SegmentTolerance {
    /// z ≤ 0.1 nm (negligible against the 5 nm closed-loop RMSE target),
    /// v ≤ 10⁻⁵, a and jerk ≤ 10⁻⁴ of their maxima; at most 2000 segments.
    fn default() -> Self {
        SegmentTolerance {
            z: 1e-10,
            v: 1e-5,
            a: 1e-4,
            jerk: 1e-4,
            max_segments: 2000,
            samples: 32,
            scan: 4000,
        }
    }
}

/// Four per-signal figures (errors, times, scales).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Signals {
    pub z: f64,
    pub v: f64,
    pub a: f64,
    pub jerk: f64,
}

impl Signals {
    fn of(f: &Flat) -> Signals {
        Signals {
            z: f.z,
            v: f.v,
            a: f.a,
            jerk: f.jerk,
        }
    }

    fn get(&self, s: Signal) -> f64 {
        match s {
            Signal::Z => self.z,
            Signal::V => self.v,
            Signal::A => self.a,
            Signal::Jerk => self.jerk,
        }
    }

    fn get_mut(&mut self, s: Signal) -> &mut f64 {
        match s {
            Signal::Z => &mut self.z,
            Signal::V => &mut self.v,
            Signal::A => &mut self.a,
            Signal::Jerk => &mut self.jerk,
        }
    }
}

const ALL: [Signal; 4] = [Signal::Z, Signal::V, Signal::A, Signal::Jerk];

/// Maximum absolute errors of a table and where they occur.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TableErrors {
    /// max |table − source| of z [m], v [m/s], a [m/s²], jerk [m/s³].
    pub max: Signals,
    /// The times of the maxima.
    pub at: Signals,
}

impl TableErrors {
    fn record(&mut self, s: Signal, err: f64, t: f64) {
        if err > self.max.get(s) || err.is_nan() {
            *self.max.get_mut(s) = err;
            *self.at.get_mut(s) = t;
        }
    }

    fn merge(&mut self, other: &TableErrors) {
        for s in ALL {
            self.record(s, other.max.get(s), other.at.get(s));
        }
    }
}

/// A fitted table with its figures.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentFit {
    pub table: Segments,
    /// Errors on the fitting samples (use [`table_errors`] for an independent check).
    pub errors: TableErrors,
    /// max |v|, |a|, |jerk| of the source (pre-scan); `z` is the stroke |z_f − z₀|.
    pub scales: Signals,
    /// The absolute tolerances used: z as given, v, a, jerk scaled.
    pub allowed: Signals,
    /// Largest jumps at the knots: z and v including the final rest
    /// (z_end, v = 0), a and jerk between segments (non-zero only where the
    /// source jumps at a forced break).
    pub jumps: Signals,
    /// Bisection passes.
    pub passes: usize,
}

/// Why no table was fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    #[error("invalid segment fit: {0}")]
    Invalid(String),
    #[error("the source reference is not finite at t = {t:e}")]
    NonFinite { t: f64 },
    #[error("the table does not meet the tolerance with {segments} segments (limit {max_segments}): worst {signal} error {error:e} (allowed {allowed:e}) at t = {t:e}")]
    TooManySegments {
        segments: usize,
        max_segments: usize,
        t: f64,
        signal: Signal,
        error: f64,
        allowed: f64,
    },
    #[error("a segment at t = {t:e} cannot be bisected further (length {length:e} s): {signal} error {error:e} (allowed {allowed:e}); the source is not smooth there — add a forced break")]
    Unresolved {
        t: f64,
        length: f64,
        signal: Signal,
        error: f64,
        allowed: f64,
    },
}

/// A knot: the source's values as limits from the left and from the right
/// (equal except at forced knots).
#[derive(Debug, Clone, Copy)]
struct Knot {
    t: f64,
    left: Flat,
    right: Flat,
}

fn finite(f: &Flat, t: f64) -> Result<(), FitError> {
    if [f.z, f.v, f.a, f.jerk].iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(FitError::NonFinite { t })
    }
}

/// The limit at t from direction `dir` (±1), by quadratic extrapolation
/// from t + dir·δ, t + dir·2δ, t + dir·3δ (exact for a quadratic jerk, i.e.
/// a quintic position).
fn one_sided(source: &dyn Reference, t: f64, dir: f64, delta: f64) -> Result<Flat, FitError> {
    let mut f = [Flat {
        z: 0.0,
        v: 0.0,
        a: 0.0,
        jerk: 0.0,
    }; 3];
    for (i, fi) in f.iter_mut().enumerate() {
        let ti = t + dir * (i + 1) as f64 * delta;
        *fi = source.at(ti);
        finite(fi, ti)?;
    }
    let x = |g: fn(&Flat) -> f64| 3.0 * g(&f[0]) - 3.0 * g(&f[1]) + g(&f[2]);
    Ok(Flat {
        z: x(|f| f.z),
        v: x(|f| f.v),
        a: x(|f| f.a),
        jerk: x(|f| f.jerk),
    })
}

/// The table segment from knot `k` to knot `n`.
fn segment(k: &Knot, n: &Knot) -> Segment {
    Segments::segment(k.t, n.t - k.t, k.right, n.left.a, n.left.jerk)
}

/// The segment's errors on its samples, and its worst (error / allowed).
fn check(
    source: &dyn Reference,
    k: &Knot,
    n: &Knot,
    samples: usize,
    allowed: &Signals,
) -> Result<(TableErrors, f64, Signal, f64), FitError> {
    let seg = segment(k, n);
    let h = n.t - k.t;
    let mut errs = TableErrors::default();
    for i in 1..=samples {
        let (t, tau) = if i == samples {
            (n.t, h)
        } else {
            let tau = h * i as f64 / samples as f64;
            (k.t + tau, tau)
        };
        let got = Segments::eval_segment(&seg, tau);
        if i == samples {
            // continuity into the next knot (a, jerk match by construction)
            errs.record(Signal::Z, (got.z - n.left.z).abs(), t);
            errs.record(Signal::V, (got.v - n.left.v).abs(), t);
        } else {
            let want = source.at(t);
            finite(&want, t)?;
            errs.record(Signal::Z, (got.z - want.z).abs(), t);
            errs.record(Signal::V, (got.v - want.v).abs(), t);
            errs.record(Signal::A, (got.a - want.a).abs(), t);
            errs.record(Signal::Jerk, (got.jerk - want.jerk).abs(), t);
        }
    }
    let (mut worst, mut which, mut when) = (0.0, Signal::Z, k.t);
    for s in ALL {
        let e = errs.max.get(s);
        let ratio = if e == 0.0 { 0.0 } else { e / allowed.get(s) };
        if ratio > worst || ratio.is_nan() {
            (worst, which, when) = (ratio, s, errs.at.get(s));
        }
    }
    if worst.is_nan() {
        worst = f64::INFINITY;
    }
    Ok((errs, worst, which, when))
}

/// Fits `source` on its motion interval with knots at the motion ends, the
/// forced `breaks` (inside the motion) and as many bisection knots as the
/// tolerance needs.
pub fn fit_segments(
    source: &dyn Reference,
    breaks: &[f64],
    tol: &SegmentTolerance,
) -> Result<SegmentFit, FitError> {
    let (t0, tf) = source.motion();
    if !(t0.is_finite() && tf.is_finite() && t0 < tf) {
        return Err(FitError::Invalid(format!(
            "the motion [{t0:e}, {tf:e}] is not a finite non-empty interval"
        )));
    }
    let positive = |x: f64| x > 0.0 && !x.is_nan();
    if !(positive(tol.z) && positive(tol.v) && positive(tol.a) && positive(tol.jerk)) {
        return Err(FitError::Invalid(format!(
            "tolerances must be positive: {tol:?}"
        )));
    }
    if tol.max_segments == 0 || tol.samples < 2 || tol.scan < 2 {
        return Err(FitError::Invalid(format!(
            "max_segments ≥ 1, samples ≥ 2, scan ≥ 2 needed: {tol:?}"
        )));
    }
    let duration = tf - t0;
    // forced knots: the ends and the breaks strictly inside, merged when closer than 1e-12·T
    let mut forced = vec![t0, tf];
    for &b in breaks {
        if !(b >= t0 && b <= tf) {
            return Err(FitError::Invalid(format!(
                "break {b:e} outside the motion [{t0:e}, {tf:e}]"
            )));
        }
        forced.push(b);
    }
    forced.sort_by(f64::total_cmp);
    let mut times: Vec<f64> = vec![t0];
    for &b in &forced[1..forced.len() - 1] {
        if b - times.last().unwrap() > 1e-12 * duration && tf - b > 1e-12 * duration {
            times.push(b);
        }
    }
    times.push(tf);
    if times.len() - 1 > tol.max_segments {
        return Err(FitError::Invalid(format!(
            "{} forced segments exceed max_segments = {}",
            times.len() - 1,
            tol.max_segments
        )));
    }

    // scales: a uniform pre-scan inside the motion
    let mut scales = Signals::default();
    let (start, end) = (source.at(t0), source.at(tf));
    finite(&start, t0)?;
    finite(&end, tf)?;
    scales.z = (end.z - start.z).abs();
    for i in 0..tol.scan {
        let t = t0 + duration * (i as f64 + 0.5) / tol.scan as f64;
        let f = source.at(t);
        finite(&f, t)?;
        scales.v = scales.v.max(f.v.abs());
        scales.a = scales.a.max(f.a.abs());
        scales.jerk = scales.jerk.max(f.jerk.abs());
    }
    let allowed = Signals {
        z: tol.z,
        v: tol.v * scales.v,
        a: tol.a * scales.a,
        jerk: tol.jerk * scales.jerk,
    };

    // the forced knots, with one-sided values
    let mut knots = Vec::with_capacity(times.len());
    for (i, &t) in times.iter().enumerate() {
        let f = source.at(t);
        finite(&f, t)?;
        let gap_left = if i > 0 {
            t - times[i - 1]
        } else {
            f64::INFINITY
        };
        let gap_right = times.get(i + 1).map_or(f64::INFINITY, |&n| n - t);
        let delta = 1e-6 * gap_left.min(gap_right);
        let last = i + 1 == times.len();
        let mut left = if i > 0 {
            one_sided(source, t, -1.0, delta)?
        } else {
            f
        };
        let mut right = if !last {
            one_sided(source, t, 1.0, delta)?
        } else {
            f
        };
        // the ends: the source's rest z, v, a (soft landing), jerk from inside
        if i == 0 {
            right = Flat {
                jerk: right.jerk,
                ..f
            };
            left = right;
        }
        if last {
            left = Flat {
                jerk: left.jerk,
                ..f
            };
            right = left;
        }
        knots.push(Knot { t, left, right });
    }

    // bisection passes: `done[i]` holds the errors of accepted segment i
    let mut done: Vec<Option<TableErrors>> = vec![None; knots.len() - 1];
    let mut passes = 0;
    loop {
        passes += 1;
        let mut next_knots = vec![knots[0]];
        let mut next_done = Vec::with_capacity(done.len());
        let mut worst: Option<(f64, Signal, f64, f64)> = None; // ratio, signal, t, error
        let mut split = false;
        for i in 0..done.len() {
            let (k, n) = (knots[i], knots[i + 1]);
            if let Some(e) = done[i] {
                next_done.push(Some(e));
                next_knots.push(n);
                continue;
            }
            let (errs, ratio, signal, t) = check(source, &k, &n, tol.samples, &allowed)?;
            if ratio <= ACCEPT {
                next_done.push(Some(errs));
                next_knots.push(n);
                continue;
            }
            let error = errs.max.get(signal);
            match worst {
                Some(w) if w.0 >= ratio => {}
                _ => worst = Some((ratio, signal, t, error)),
            }
            let mid = 0.5 * (k.t + n.t);
            if !(mid > k.t && mid < n.t) || n.t - k.t <= 1e-12 * duration {
                return Err(FitError::Unresolved {
                    t,
                    length: n.t - k.t,
                    signal,
                    error,
                    allowed: allowed.get(signal),
                });
            }
            let f = source.at(mid);
            finite(&f, mid)?;
            next_knots.push(Knot {
                t: mid,
                left: f,
                right: f,
            });
            next_knots.push(n);
            next_done.push(None);
            next_done.push(None);
            split = true;
        }
        knots = next_knots;
        done = next_done;
        if !split {
            break;
        }
        if done.len() > tol.max_segments {
            let (_, signal, t, error) = worst.expect("a split has a worst segment");
            return Err(FitError::TooManySegments {
                segments: done.len(),
                max_segments: tol.max_segments,
                t,
                signal,
                error,
                allowed: allowed.get(signal),
            });
        }
    }

    let mut errors = TableErrors::default();
    for e in done.iter().flatten() {
        errors.merge(e);
    }
    let segments: Vec<Segment> = knots.windows(2).map(|w| segment(&w[0], &w[1])).collect();
    let table = Segments {
        segments,
        end: tf,
        z_start: start.z,
        z_end: end.z,
    };
    let jumps = knot_jumps(&table);
    Ok(SegmentFit {
        table,
        errors,
        scales,
        allowed,
        jumps,
        passes,
    })
}

/// Largest jumps at the knots of a table: z and v between segments and into
/// the final rest (z_end, 0); a and jerk between segments.
pub fn knot_jumps(table: &Segments) -> Signals {
    let mut jumps = Signals::default();
    let s = &table.segments;
    for k in 0..s.len() {
        let t_next = s.get(k + 1).map_or(table.end, |n| n[0]);
        let f = Segments::eval_segment(&s[k], t_next - s[k][0]);
        let (z, v) = s.get(k + 1).map_or((table.z_end, 0.0), |n| (n[1], n[2]));
        jumps.z = jumps.z.max((f.z - z).abs());
        jumps.v = jumps.v.max((f.v - v).abs());
        if let Some(n) = s.get(k + 1) {
            jumps.a = jumps.a.max((f.a - n[3]).abs());
            jumps.jerk = jumps.jerk.max((f.jerk - n[4]).abs());
        }
    }
    jumps
}

/// max |table − source| on `n` uniform points strictly inside the motion of
/// `source` (midpoints of n equal cells, so the rest values at t₀, t_f are
/// never compared with the motion's one-sided jerk).
pub fn table_errors(source: &dyn Reference, table: &Segments, n: usize) -> TableErrors {
    let (t0, tf) = source.motion();
    let mut errs = TableErrors::default();
    for i in 0..n {
        let t = t0 + (tf - t0) * (i as f64 + 0.5) / n as f64;
        let (got, want) = (table.at(t), source.at(t));
        let got = Signals::of(&got);
        let want = Signals::of(&want);
        for s in ALL {
            errs.record(s, (got.get(s) - want.get(s)).abs(), t);
        }
    }
    errs
}
