//! Plant inputs: piecewise-linear signals and the [`Input`] interface.
//!
//! The simulator must never step across a jump or a kink of the input (the
//! Runge–Kutta error estimate assumes a smooth right-hand side), so an input
//! tells where its breakpoints are and hands out the affine piece in force
//! between two of them. Inside a segment the simulator evaluates that piece
//! only, so a stage at the segment's right end sees the left limit of a jump.

// `!(a > b)` comparisons are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use thiserror::Error;

/// An affine function of time `u(t) = u0 + slope·(t − t0)`: one smooth piece
/// of an input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    pub t0: f64,
    pub u0: f64,
    pub slope: f64,
}

impl Affine {
    /// A constant piece.
    pub fn constant(u: f64) -> Self {
        Self {
            t0: 0.0,
            u0: u,
            slope: 0.0,
        }
    }

    #[inline]
    pub fn value(&self, t: f64) -> f64 {
        if self.slope == 0.0 {
            self.u0
        } else {
            self.u0 + self.slope * (t - self.t0)
        }
    }
}

/// A piecewise-affine input signal, right-continuous at jumps.
pub trait Input {
    /// Value at `t` (the right limit at a jump).
    fn value(&self, t: f64) -> f64;
    /// First breakpoint strictly after `t`, `f64::INFINITY` if none.
    fn next_breakpoint(&self, t: f64) -> f64;
    /// The affine piece in force on `[t, next_breakpoint(t))`.
    fn piece(&self, t: f64) -> Affine;
}

/// A constant input.
impl Input for f64 {
    fn value(&self, _t: f64) -> f64 {
        *self
    }
    fn next_breakpoint(&self, _t: f64) -> f64 {
        f64::INFINITY
    }
    fn piece(&self, _t: f64) -> Affine {
        Affine::constant(*self)
    }
}

/// Why a piecewise-linear input was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum InputError {
    #[error("an input needs at least one sample")]
    Empty,
    #[error("{t} sample times but {u} values")]
    LengthMismatch { t: usize, u: usize },
    #[error("sample {index} is not finite")]
    NonFinite { index: usize },
    #[error("sample time {index} is smaller than the previous one (times must not decrease)")]
    Decreasing { index: usize },
    #[error("invalid parameter: {0}")]
    Parameter(&'static str),
}

/// Linear interpolation between samples `(t[i], u[i])`, constant beyond the
/// first and last sample. Equal consecutive times encode a jump; the value at
/// the jump time is the last sample given for it (right-continuous).
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLinear {
    t: Vec<f64>,
    u: Vec<f64>,
    breakpoints: Vec<f64>,
    /// Where the last searches of `t` and of `breakpoints` ended: a
    /// simulation asks at times that mostly stay in one segment or move to
    /// the next ([`Hint`]).
    hints: [Hint; 2],
}

/// The index a search of a sorted slice last returned, tried first (then
/// the next one) before a binary search: the same answer as
/// `partition_point`, without its ~16 cache-missing probes per call on a
/// 40 000-sample record. Atomic (relaxed) so that threads may share an
/// input; any stored value is only a guess, checked before it is used.
#[derive(Default)]
struct Hint(std::sync::atomic::AtomicUsize);

impl Hint {
    /// `sorted.partition_point(|&s| s <= t)`.
    fn partition_after(&self, sorted: &[f64], t: f64) -> usize {
        use std::sync::atomic::Ordering::Relaxed;
        let is_it = |i: usize| {
            i <= sorted.len()
                && (i == 0 || sorted[i - 1] <= t)
                && sorted.get(i).is_none_or(|&s| !(s <= t))
        };
        let h = self.0.load(Relaxed);
        let i = match (is_it(h), is_it(h + 1)) {
            (true, _) => h,
            (false, true) => h + 1,
            _ => sorted.partition_point(|&s| s <= t),
        };
        // (not written when unchanged: threads sharing an input then share
        // the cache line without writing it)
        if i != h {
            self.0.store(i, Relaxed);
        }
        i
    }
}

/// A hint is not part of the signal (and its value depends on the lookups
/// before).
impl std::fmt::Debug for Hint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Hint")
    }
}

impl Clone for Hint {
    fn clone(&self) -> Self {
        Hint(self.0.load(std::sync::atomic::Ordering::Relaxed).into())
    }
}

/// A hint is not part of the signal.
impl PartialEq for Hint {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl PiecewiseLinear {
    /// Validates the samples: same length, at least one, finite, times
    /// non-decreasing.
    pub fn new(t: Vec<f64>, u: Vec<f64>) -> Result<Self, InputError> {
        if t.len() != u.len() {
            return Err(InputError::LengthMismatch {
                t: t.len(),
                u: u.len(),
            });
        }
        if t.is_empty() {
            return Err(InputError::Empty);
        }
        for i in 0..t.len() {
            if !t[i].is_finite() || !u[i].is_finite() {
                return Err(InputError::NonFinite { index: i });
            }
            if i > 0 && t[i] < t[i - 1] {
                return Err(InputError::Decreasing { index: i });
            }
        }
        let breakpoints = find_breakpoints(&t, &u);
        Ok(Self {
            t,
            u,
            breakpoints,
            hints: Default::default(),
        })
    }

    /// A constant signal.
    pub fn constant(u: f64) -> Result<Self, InputError> {
        Self::new(vec![0.0], vec![u])
    }

    /// Piecewise constant: `u_k` on `[t_k, t_{k+1})`, `u_0` before `t_0`, the
    /// last value after the last time.
    pub fn steps(points: &[(f64, f64)]) -> Result<Self, InputError> {
        let mut t = Vec::with_capacity(2 * points.len());
        let mut u = Vec::with_capacity(2 * points.len());
        for (k, &(tk, uk)) in points.iter().enumerate() {
            if k > 0 {
                let prev = u[u.len() - 1];
                if uk == prev {
                    continue;
                }
                t.push(tk);
                u.push(prev);
            }
            t.push(tk);
            u.push(uk);
        }
        Self::new(t, u)
    }

    /// `base` everywhere except during the pulses `(start, width, amplitude)`,
    /// where the value is `amplitude` on `[start, start + width)`. Pulses must
    /// be sorted and must not overlap (touching is fine).
    pub fn pulses(base: f64, pulses: &[(f64, f64, f64)]) -> Result<Self, InputError> {
        let mut pts = Vec::with_capacity(2 * pulses.len() + 1);
        let mut end = f64::NEG_INFINITY;
        for &(start, width, amp) in pulses {
            if !(width >= 0.0) {
                return Err(InputError::Parameter("pulse width must be ≥ 0"));
            }
            if start < end {
                return Err(InputError::Parameter(
                    "pulses must be sorted and must not overlap",
                ));
            }
            if pts.is_empty() {
                pts.push((start, base));
            }
            pts.push((start, amp));
            pts.push((start + width, base));
            end = start + width;
        }
        if pts.is_empty() {
            pts.push((0.0, base));
        }
        Self::steps(&pts)
    }

    /// A square wave on `[0, t_end]`: `amplitude_on` on `[kP, kP + duty·P)`,
    /// `amplitude_off` on the rest of each period `P`; constant beyond the
    /// ends (the value at 0 before 0, the value at `t_end` after it; an edge
    /// at exactly `t_end` is kept).
    pub fn square_wave(
        amplitude_on: f64,
        amplitude_off: f64,
        period: f64,
        duty: f64,
        t_end: f64,
    ) -> Result<Self, InputError> {
        if !(period > 0.0 && period.is_finite()) {
            return Err(InputError::Parameter("period must be positive and finite"));
        }
        if !(0.0..=1.0).contains(&duty) {
            return Err(InputError::Parameter("duty must lie in [0, 1]"));
        }
        if !(t_end >= 0.0 && t_end.is_finite()) {
            return Err(InputError::Parameter("t_end must be ≥ 0 and finite"));
        }
        let mut pts = Vec::new();
        let mut k = 0u64;
        loop {
            let t_on = k as f64 * period;
            if t_on > t_end {
                break;
            }
            let t_off = t_on + duty * period;
            if duty > 0.0 {
                pts.push((t_on, amplitude_on));
            }
            if duty < 1.0 && t_off <= t_end {
                pts.push((t_off, amplitude_off));
            }
            k += 1;
        }
        Self::steps(&pts)
    }

    /// Sample times.
    pub fn times(&self) -> &[f64] {
        &self.t
    }

    /// Sample values.
    pub fn values(&self) -> &[f64] {
        &self.u
    }

    /// Times where the value or the slope jumps: exactly where the slope on
    /// the left differs from the slope on the right (up to rounding of the
    /// slopes), or the left and right limits differ. Sample times inside a
    /// straight stretch are not breakpoints; the first and last sample times
    /// are if the signal is not flat next to them.
    pub fn breakpoints(&self) -> &[f64] {
        &self.breakpoints
    }

    /// Index of the last sample with `t[j] ≤ t` (`None` before the first).
    fn last_at_or_before(&self, t: f64) -> Option<usize> {
        self.hints[0].partition_after(&self.t, t).checked_sub(1)
    }

    /// Value on segment `j` (`t[j] ≤ t < t[j+1]`, or the constant ends).
    fn eval_at(&self, j: Option<usize>, t: f64) -> f64 {
        match j {
            None => self.u[0],
            Some(j) if j + 1 >= self.t.len() => self.u[j],
            Some(j) => {
                let (t0, t1, u0, u1) = (self.t[j], self.t[j + 1], self.u[j], self.u[j + 1]);
                u0 + (u1 - u0) * ((t - t0) / (t1 - t0))
            }
        }
    }

    /// A cursor for fast evaluation at non-decreasing times.
    pub fn cursor(&self) -> Cursor<'_> {
        Cursor { pl: self, j: None }
    }
}

impl Input for PiecewiseLinear {
    fn value(&self, t: f64) -> f64 {
        self.eval_at(self.last_at_or_before(t), t)
    }

    fn next_breakpoint(&self, t: f64) -> f64 {
        let i = self.hints[1].partition_after(&self.breakpoints, t);
        self.breakpoints.get(i).copied().unwrap_or(f64::INFINITY)
    }

    fn piece(&self, t: f64) -> Affine {
        match self.last_at_or_before(t) {
            None => Affine::constant(self.u[0]),
            Some(j) if j + 1 >= self.t.len() => Affine::constant(self.u[j]),
            Some(j) => Affine {
                t0: self.t[j],
                u0: self.u[j],
                slope: (self.u[j + 1] - self.u[j]) / (self.t[j + 1] - self.t[j]),
            },
        }
    }
}

/// Evaluates a [`PiecewiseLinear`] at non-decreasing times in amortised O(1)
/// (any order works; going backwards costs a binary search).
#[derive(Debug, Clone)]
pub struct Cursor<'a> {
    pl: &'a PiecewiseLinear,
    j: Option<usize>,
}

impl Cursor<'_> {
    pub fn value(&mut self, t: f64) -> f64 {
        let ts = &self.pl.t;
        let behind = match self.j {
            None => false,
            Some(j) => t < ts[j],
        };
        if behind {
            self.j = self.pl.last_at_or_before(t);
        } else {
            let mut next = self.j.map_or(0, |j| j + 1);
            while next < ts.len() && ts[next] <= t {
                next += 1;
            }
            self.j = next.checked_sub(1);
        }
        self.pl.eval_at(self.j, t)
    }
}

/// Slope of the segment `(j, j+1)` (with distinct times).
fn slope(t: &[f64], u: &[f64], j: usize) -> f64 {
    (u[j + 1] - u[j]) / (t[j + 1] - t[j])
}

/// Whether two computed slopes differ by more than their rounding errors.
fn slopes_differ(sl: f64, sr: f64, err_scale: f64) -> bool {
    sl != sr && (sl - sr).abs() > 8.0 * f64::EPSILON * (sl.abs() + sr.abs() + err_scale)
}

fn find_breakpoints(t: &[f64], u: &[f64]) -> Vec<f64> {
    let n = t.len();
    let mut out = Vec::new();
    let mut a = 0;
    while a < n {
        // Samples a..=b share one time.
        let mut b = a;
        while b + 1 < n && t[b + 1] == t[a] {
            b += 1;
        }
        let (sl, el) = if a == 0 {
            (0.0, 0.0)
        } else {
            (
                slope(t, u, a - 1),
                (u[a - 1].abs() + u[a].abs()) / (t[a] - t[a - 1]),
            )
        };
        let (sr, er) = if b + 1 == n {
            (0.0, 0.0)
        } else {
            (
                slope(t, u, b),
                (u[b].abs() + u[b + 1].abs()) / (t[b + 1] - t[b]),
            )
        };
        if u[a] != u[b] || slopes_differ(sl, sr, el + er) {
            out.push(t[a]);
        }
        a = b + 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::Hint;
    use crate::random::SplitMix64;

    /// `partition_after` is `partition_point` whatever the hint holds
    /// (stale, out of range) and whatever the query (duplicates, ±0, ±∞,
    /// NaN): a pseudo-random sweep.
    #[test]
    fn a_hinted_search_is_partition_point() {
        let mut rng = SplitMix64::new(17);
        let mut next = || rng.next_u64();
        let specials = [0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::NAN];
        for _ in 0..2_000 {
            let n = (next() % 12) as usize;
            let mut sorted: Vec<f64> = (0..n).map(|_| (next() % 7) as f64 - 3.0).collect();
            sorted.sort_by(f64::total_cmp);
            let hint = Hint::default();
            for _ in 0..20 {
                if next() % 3 == 0 {
                    // a stale or out-of-range guess
                    hint.0
                        .store((next() % 20) as usize, std::sync::atomic::Ordering::Relaxed);
                }
                let t = match next() % 4 {
                    0 => specials[(next() % 5) as usize],
                    _ => (next() % 17) as f64 * 0.5 - 4.0,
                };
                let want = sorted.partition_point(|&s| s <= t);
                assert_eq!(hint.partition_after(&sorted, t), want, "{sorted:?} at {t}");
            }
        }
    }
}
