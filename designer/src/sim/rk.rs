//! Adaptive Dormand–Prince 5(4) integrator with continuous (dense) output.
//!
//! This is the DOPRI5 method of Hairer, Nørsett & Wanner (Solving ODEs I,
//! §II.4–II.6): FSAL stages, an embedded 4th-order error estimate, Hairer's
//! initial-step heuristic and the 4th-order continuous extension valid
//! anywhere inside the last accepted step. The hybrid simulator needs exactly
//! this: it integrates up to a hard limit (an input breakpoint), locates
//! guards on the dense output and restarts after every discontinuity.
//!
//! **Step-size control.** The elementary controller (`h·(1/err)^(1/5)` with
//! a safety factor) combined with Gustafsson's predictive one (as in Hairer's
//! RADAU5): after an accepted step the smaller of the two proposals is taken.
//! The predictive one extrapolates the trend of the error over the last two
//! accepted steps, which matters where the error per step keeps growing (an
//! armature accelerating towards a stop): there the elementary controller
//! alone alternates rejected and accepted steps. Hairer's PI controller
//! (β = 0.04) was measured too, and needed more evaluations for the same
//! accuracy on the Jiles–Atherton valve. After a step shortened to land on a
//! limit the earlier proposal is kept ([`Dopri5::step`]), except at an input
//! breakpoint ([`Dopri5::step_to_breakpoint`]), where the solution changes
//! character and the shortened step's own proposal is the better guess.
//!
//! States are fixed-size arrays `[f64; N]` of which the first `dim` entries are
//! used, so a step never allocates. The right-hand side is any
//! `FnMut(t, &x, &mut dx)`; an optional domain predicate rejects (and retries
//! smaller) any step whose stages or end point leave the model's domain.

// `!(a > b)` comparisons are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use thiserror::Error;

/// Counters of the integrator's work.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepStats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (error too large, domain left or non-finite values).
    pub rejected: usize,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
}

impl StepStats {
    /// Steps attempted, accepted and rejected: what the hybrid simulator's
    /// `max_steps` bounds.
    pub fn attempted(&self) -> usize {
        self.accepted + self.rejected
    }
}

impl std::ops::AddAssign for StepStats {
    fn add_assign(&mut self, o: Self) {
        self.accepted += o.accepted;
        self.rejected += o.rejected;
        self.evaluations += o.evaluations;
    }
}

/// Why the integrator gave up.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum RkError {
    /// The controller asked for a step below the minimum step size.
    #[error("step size {h:e} fell below the minimum step at t = {t} (tolerance too tight or the solution blows up)")]
    StepTooSmall { t: f64, h: f64 },
    /// Steps keep leaving the domain (or produce non-finite values) down to the
    /// minimum step size: the solution itself leaves the domain at `t`.
    #[error("the solution leaves the model's domain at t = {t} (step size {h:e} cannot be reduced further)")]
    LeftDomain { t: f64, h: f64 },
}

// Dormand–Prince 5(4) tableau.
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// Error coefficients b − b̂.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Dense output (Hairer's CONTD5).
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Adaptive Dormand–Prince 5(4) integrator over `[f64; N]` (first `dim` used).
///
/// Usage: [`Dopri5::init`] (or [`Dopri5::restart`] to keep the step size) at
/// `(t0, x0)`, then repeated [`Dopri5::step`] calls, each taking one accepted
/// step that never passes the given limit; [`Dopri5::dense`] interpolates
/// inside the last accepted step `[t_prev, t]`.
#[derive(Debug, Clone)]
pub struct Dopri5<const N: usize> {
    dim: usize,
    rtol: f64,
    atol: [f64; N],
    max_step: f64,
    min_step: f64,
    first_step: Option<f64>,
    safety: f64,
    t: f64,
    x: [f64; N],
    /// Stage derivatives; `k[0]` is `f(t, x)` (FSAL).
    k: [[f64; N]; 7],
    /// Proposed size of the next step.
    h: f64,
    /// Size and err^(1/5) of the previous accepted step (predictive
    /// controller; `h_acc = 0` when there is none since the last `init`).
    h_acc: f64,
    err5_acc: f64,
    last_rejected: bool,
    t_prev: f64,
    h_last: f64,
    rcont: [[f64; N]; 5],
    stats: StepStats,
}

impl<const N: usize> Dopri5<N> {
    /// A new integrator for `dim` states with scalar relative and per-component
    /// absolute tolerances. Call [`init`](Self::init) before stepping.
    ///
    /// # Panics
    /// If `dim` is 0 or exceeds `N`, or a tolerance is negative or non-finite.
    pub fn new(dim: usize, rtol: f64, atol: [f64; N]) -> Self {
        assert!(dim >= 1 && dim <= N, "Dopri5: dim {dim} outside 1..={N}");
        assert!(rtol.is_finite() && rtol >= 0.0, "Dopri5: bad rtol {rtol}");
        assert!(
            atol[..dim].iter().all(|a| a.is_finite() && *a >= 0.0),
            "Dopri5: bad atol"
        );
        Self {
            dim,
            rtol,
            atol,
            max_step: f64::INFINITY,
            min_step: 0.0,
            first_step: None,
            safety: 0.9,
            t: 0.0,
            x: [0.0; N],
            k: [[0.0; N]; 7],
            h: 0.0,
            h_acc: 0.0,
            err5_acc: 1.0,
            last_rejected: false,
            t_prev: 0.0,
            h_last: 0.0,
            rcont: [[0.0; N]; 5],
            stats: StepStats::default(),
        }
    }

    /// Largest step size (default: unbounded).
    pub fn with_max_step(mut self, h: f64) -> Self {
        assert!(h > 0.0, "Dopri5: max_step must be positive");
        self.max_step = h;
        self
    }

    /// Smallest step size before [`RkError::StepTooSmall`] (default 0; a step
    /// is in any case refused below 16 ulp of `t`). Steps shortened to land
    /// exactly on the `t_limit` of [`step`](Self::step) are exempt.
    pub fn with_min_step(mut self, h: f64) -> Self {
        assert!(h >= 0.0, "Dopri5: min_step must be non-negative");
        self.min_step = h;
        self
    }

    /// Initial step used by [`init`](Self::init) instead of Hairer's heuristic.
    pub fn with_first_step(mut self, h: Option<f64>) -> Self {
        if let Some(h) = h {
            assert!(h > 0.0, "Dopri5: first_step must be positive");
        }
        self.first_step = h;
        self
    }

    pub fn dim(&self) -> usize {
        self.dim
    }
    /// Current time (end of the last accepted step).
    pub fn t(&self) -> f64 {
        self.t
    }
    /// Current state.
    pub fn x(&self) -> &[f64; N] {
        &self.x
    }
    /// `f(t, x)` at the current point.
    pub fn dx(&self) -> &[f64; N] {
        &self.k[0]
    }
    /// Start of the last accepted step (the dense output is valid on `[t_prev, t]`).
    pub fn t_prev(&self) -> f64 {
        self.t_prev
    }
    /// Size of the next step the controller proposes.
    pub fn step_size(&self) -> f64 {
        self.h
    }
    pub fn stats(&self) -> StepStats {
        self.stats
    }

    /// Starts (or restarts) at `(t, x)`: evaluates `f` there and chooses the
    /// first step by Hairer's heuristic (or the configured first step).
    pub fn init<F, D>(&mut self, t: f64, x: &[f64; N], f: &mut F, domain: &mut D)
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        D: FnMut(&[f64; N]) -> bool,
    {
        self.set_point(t, x, f);
        self.h = match self.first_step {
            Some(h) => h.min(self.max_step),
            None => self.initial_step(f, domain),
        };
        self.h_acc = 0.0;
        self.last_rejected = false;
    }

    /// Restarts at `(t, x)` keeping the proposed step size and the
    /// controller's history (FSAL reset only): for a discontinuity of the
    /// right-hand side that does not change its time scale (an input
    /// breakpoint, a switch, most events). Falls back to [`init`](Self::init)'s
    /// heuristic if no step size is known yet.
    pub fn restart<F, D>(&mut self, t: f64, x: &[f64; N], f: &mut F, domain: &mut D)
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        D: FnMut(&[f64; N]) -> bool,
    {
        if !(self.h > 0.0) {
            return self.init(t, x, f, domain);
        }
        self.set_point(t, x, f);
        self.h = self.h.min(self.max_step);
        self.last_rejected = false;
    }

    fn set_point<F>(&mut self, t: f64, x: &[f64; N], f: &mut F)
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        self.t = t;
        self.t_prev = t;
        self.h_last = 0.0;
        self.x = *x;
        f(t, &self.x, &mut self.k[0]);
        self.stats.evaluations += 1;
        self.rcont = [[0.0; N]; 5];
        self.rcont[0] = *x;
    }

    /// Weighted RMS norm of `e` with scales `atol + rtol·max(|a|, |b|)`.
    fn norm(&self, e: &[f64; N], a: &[f64; N], b: &[f64; N]) -> f64 {
        let d = self.dim;
        let mut s = 0.0;
        for i in 0..d {
            let sk = self.atol[i] + self.rtol * a[i].abs().max(b[i].abs());
            let r = e[i] / sk;
            s += r * r;
        }
        (s / d as f64).sqrt()
    }

    /// Hairer's HINIT: a step such that an explicit Euler step's error is
    /// about the tolerance, limited by the second derivative estimate;
    /// unbounded (`max_step`) where the field vanishes at the start and one
    /// probe ahead.
    fn initial_step<F, D>(&mut self, f: &mut F, domain: &mut D) -> f64
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        D: FnMut(&[f64; N]) -> bool,
    {
        let (d, x0, f0) = (self.dim, self.x, self.k[0]);
        let zero = [0.0; N];
        let dnf = self.norm(&f0, &x0, &x0);
        let dny = self.norm(&x0, &x0, &x0);
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            0.01 * dny / dnf
        };
        h = h.min(self.max_step);
        let mut x1 = [0.0; N];
        let mut f1 = [0.0; N];
        for _ in 0..60 {
            for i in 0..d {
                x1[i] = x0[i] + h * f0[i];
            }
            if domain(&x1) {
                break;
            }
            h *= 0.5;
        }
        f(self.t + h, &x1, &mut f1);
        self.stats.evaluations += 1;
        let mut df = [0.0; N];
        for i in 0..d {
            df[i] = f1[i] - f0[i];
        }
        let der2 = self.norm(&df, &x0, &zero) / h;
        let der12 = der2.max(dnf);
        if der12 == 0.0 {
            // The field vanishes here and one probe ahead (a plant at rest
            // until its input changes): the step is bounded by the limit it
            // is taken towards only, and the error estimate checks it.
            return self.max_step;
        }
        let h1 = if !(der12 > 1e-15) {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(0.2)
        };
        let h = (100.0 * h).min(h1).min(self.max_step);
        if h.is_finite() && h > 0.0 {
            h
        } else {
            1e-6f64.min(self.max_step)
        }
    }

    /// Takes one accepted step, never beyond `t_limit` (> current t); the step
    /// lands exactly on `t_limit` when it reaches it. Rejected attempts are
    /// retried with a smaller step. Returns the size of the accepted step.
    ///
    /// A step shortened to land on `t_limit` says nothing against the step
    /// size proposed before it, which is kept for the next step.
    pub fn step<F, D>(&mut self, f: &mut F, domain: &mut D, t_limit: f64) -> Result<f64, RkError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        D: FnMut(&[f64; N]) -> bool,
    {
        self.step_impl(f, domain, t_limit, true)
    }

    /// [`step`](Self::step) towards a limit at which the right-hand side
    /// changes (an input breakpoint): a step shortened to land on it keeps
    /// the controller's own proposal, which reflects the solution just before
    /// the change better than the (larger) one from before the shortened step.
    /// (On the Jiles–Atherton valve's input ramps, restoring the earlier
    /// proposal got the first steps after most ramps rejected.)
    pub fn step_to_breakpoint<F, D>(
        &mut self,
        f: &mut F,
        domain: &mut D,
        t_limit: f64,
    ) -> Result<f64, RkError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        D: FnMut(&[f64; N]) -> bool,
    {
        self.step_impl(f, domain, t_limit, false)
    }

    fn step_impl<F, D>(
        &mut self,
        f: &mut F,
        domain: &mut D,
        t_limit: f64,
        keep_proposal: bool,
    ) -> Result<f64, RkError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        D: FnMut(&[f64; N]) -> bool,
    {
        debug_assert!(t_limit > self.t, "Dopri5::step: t_limit must lie ahead");
        let floor = self.min_step.max(16.0 * f64::EPSILON * self.t.abs());
        loop {
            let proposed = self.h;
            let clipped = self.t + 1.01 * proposed >= t_limit;
            let (h, t_new) = if clipped {
                (t_limit - self.t, t_limit)
            } else {
                (proposed, self.t + proposed)
            };
            if !clipped && h < floor {
                return Err(RkError::StepTooSmall { t: self.t, h });
            }
            let mut y = [0.0; N];
            match self.attempt(f, domain, h, t_new, &mut y) {
                Some(err) if err <= 1.0 => {
                    self.accept(&y, h, t_new, err);
                    if keep_proposal && clipped && self.h < proposed {
                        self.h = proposed;
                    }
                    return Ok(h);
                }
                Some(err) => {
                    self.h = h / (err.powf(0.2) / self.safety).min(5.0);
                    self.reject();
                }
                None => {
                    self.h = 0.5 * h;
                    self.reject();
                    if self.h < floor {
                        return Err(RkError::LeftDomain {
                            t: self.t,
                            h: self.h,
                        });
                    }
                }
            }
        }
    }

    fn reject(&mut self) {
        self.stats.rejected += 1;
        self.last_rejected = true;
    }

    /// Computes stages 2–7 for step `h`; `y` receives the 5th-order solution.
    /// Returns the scaled error norm, or `None` if a stage left the domain or
    /// the values are not finite.
    fn attempt<F, D>(
        &mut self,
        f: &mut F,
        domain: &mut D,
        h: f64,
        t_new: f64,
        y: &mut [f64; N],
    ) -> Option<f64>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        D: FnMut(&[f64; N]) -> bool,
    {
        let (d, t, x) = (self.dim, self.t, self.x);
        let k = &mut self.k;
        let mut ev = 0;
        let mut stage =
            |c: &[f64], ts: f64, out: usize, k: &mut [[f64; N]; 7], y: &mut [f64; N]| {
                for i in 0..d {
                    let mut s = 0.0;
                    for (j, cj) in c.iter().enumerate() {
                        s += cj * k[j][i];
                    }
                    y[i] = x[i] + h * s;
                }
                if !domain(y) {
                    return false;
                }
                f(ts, y, &mut k[out]);
                ev += 1;
                true
            };
        let ok = stage(&[A21], t + C2 * h, 1, k, y)
            && stage(&[A31, A32], t + C3 * h, 2, k, y)
            && stage(&[A41, A42, A43], t + C4 * h, 3, k, y)
            && stage(&[A51, A52, A53, A54], t + C5 * h, 4, k, y)
            && stage(&[A61, A62, A63, A64, A65], t_new, 5, k, y)
            && stage(&[A71, 0.0, A73, A74, A75, A76], t_new, 6, k, y);
        self.stats.evaluations += ev;
        if !ok {
            return None;
        }
        let mut e = [0.0; N];
        for i in 0..d {
            e[i] = h
                * (E1 * k[0][i]
                    + E3 * k[2][i]
                    + E4 * k[3][i]
                    + E5 * k[4][i]
                    + E6 * k[5][i]
                    + E7 * k[6][i]);
        }
        let err = self.norm(&e, &x, y);
        err.is_finite().then_some(err)
    }

    /// Accepts the attempted step: dense-output coefficients, FSAL, new `h`.
    fn accept(&mut self, y: &[f64; N], h: f64, t_new: f64, err: f64) {
        let d = self.dim;
        let k = &self.k;
        let r = &mut self.rcont;
        for i in 0..d {
            let ydiff = y[i] - self.x[i];
            let bspl = h * k[0][i] - ydiff;
            r[0][i] = self.x[i];
            r[1][i] = ydiff;
            r[2][i] = bspl;
            r[3][i] = ydiff - h * k[6][i] - bspl;
            r[4][i] = h
                * (D1 * k[0][i]
                    + D3 * k[2][i]
                    + D4 * k[3][i]
                    + D5 * k[4][i]
                    + D6 * k[5][i]
                    + D7 * k[6][i]);
        }
        let err5 = err.powf(0.2);
        let mut h_new = (h / self.shrink_factor(h, err5)).min(self.max_step);
        if self.last_rejected {
            h_new = h_new.min(h);
        }
        self.h_acc = h;
        // (1e-2)^(1/5): a tiny error says nothing about the trend
        self.err5_acc = err5.max(0.398_107_170_553_497_3);
        self.last_rejected = false;
        self.k[0] = self.k[6];
        self.x = *y;
        self.t_prev = self.t;
        self.t = t_new;
        self.h_last = h;
        self.h = h_new;
        self.stats.accepted += 1;
    }

    /// By how much to divide the accepted step `h` (`err5` = err^(1/5)): the
    /// larger of the elementary controller's factor and Gustafsson's
    /// predictive one, each limited to [0.1, 5].
    fn shrink_factor(&self, h: f64, err5: f64) -> f64 {
        let elementary = (err5 / self.safety).clamp(0.1, 5.0);
        if self.h_acc > 0.0 {
            let trend = err5 / self.err5_acc;
            let predictive = (self.h_acc / h) * err5 * trend / self.safety;
            elementary.max(predictive.clamp(0.1, 5.0))
        } else {
            elementary
        }
    }

    /// Dense output of all components at `t ∈ [t_prev, t]` (4th order).
    pub fn dense(&self, t: f64, out: &mut [f64; N]) {
        if t == self.t {
            *out = self.x;
            return;
        }
        if self.h_last == 0.0 {
            *out = self.rcont[0];
            return;
        }
        let s = (t - self.t_prev) / self.h_last;
        for (i, o) in out.iter_mut().enumerate().take(self.dim) {
            *o = self.interpolate(i, s);
        }
    }

    /// The continuous extension of component `i` at `t_prev + s·h_last`.
    #[inline(always)]
    fn interpolate(&self, i: usize, s: f64) -> f64 {
        let (r, s1) = (&self.rcont, 1.0 - s);
        r[0][i] + s * (r[1][i] + s1 * (r[2][i] + s * (r[3][i] + s1 * r[4][i])))
    }

    /// Dense output of the first `M ≤ N` components at `t ∈ [t_prev, t]`
    /// (those beyond `dim` are meaningless): a fixed-size loop, for the hot
    /// path of recording outputs.
    #[inline]
    pub fn dense_head<const M: usize>(&self, t: f64) -> [f64; M] {
        let head = |v: &[f64; N]| -> [f64; M] { std::array::from_fn(|i| v[i]) };
        if t == self.t {
            return head(&self.x);
        }
        let r = &self.rcont;
        if self.h_last == 0.0 {
            return head(&r[0]);
        }
        let s = (t - self.t_prev) / self.h_last;
        std::array::from_fn(|i| self.interpolate(i, s))
    }

    /// Dense output of component `i` at `t ∈ [t_prev, t]`.
    pub fn dense_component(&self, i: usize, t: f64) -> f64 {
        if t == self.t {
            return self.x[i];
        }
        if self.h_last == 0.0 {
            return self.rcont[0][i];
        }
        self.interpolate(i, (t - self.t_prev) / self.h_last)
    }

    /// Integrates to exactly `t_end` (convenience for plain ODEs).
    pub fn integrate_to<F, D>(
        &mut self,
        f: &mut F,
        domain: &mut D,
        t_end: f64,
    ) -> Result<(), RkError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
        D: FnMut(&[f64; N]) -> bool,
    {
        while self.t < t_end {
            self.step(f, domain, t_end)?;
        }
        Ok(())
    }
}
