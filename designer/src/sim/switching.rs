//! Discontinuity locking: integrating a switching field one smooth branch at
//! a time.
//!
//! A field such as the Jiles–Atherton core's, which contains δ = sign(φ̇), has
//! a kink where φ̇ changes sign: the solution's second derivative jumps there,
//! a Runge–Kutta step across it is only low-order accurate, and its error
//! estimate no longer predicts the error, so the step-size control rejects
//! step after step (or accepts a poor one). A [`Plant`] with switching
//! functions `s_j` is therefore integrated as follows:
//!
//! 1. at every (re)start, the branch of each `s_j` is its sign there — or, if
//!    `s_j = 0`, its sign on an explicit-Euler probe one step ahead (0 if still
//!    0) — and is held during the following steps ([`Plant::deriv_branch`]);
//! 2. after every accepted step, a function whose sign at the step's end
//!    disagrees with its branch has crossed zero: the crossing is located on
//!    the dense output (Illinois, like the guards), the step is cut there and
//!    the integrator restarted (keeping its step size) with the new branch.
//!
//! The held branch's field continues smoothly beyond the crossing, so the cut
//! step is as accurate as any other. Only the step's end is checked: a
//! function that crosses zero and back within one step keeps its branch.
//! When a switching function is a component of the field itself
//! ([`Plant::switching_component`], φ̇ here), its value there is read from
//! the derivative the integrator has at the step's end anyway. On the
//! Jiles–Atherton valve this took the largest current errors, at the input
//! edges where φ̇ reverses, down about tenfold at the same tolerance, and
//! most rejected steps there disappeared.
//!
//! Should switching degenerate into chattering (a sliding motion along
//! `s = 0`, each branch driving `s` to the other side), steps would become
//! vanishingly short: after [`MAX_CHATTER`] consecutive switches each at most
//! one step after the previous restart, locking is dropped for the rest of
//! the input piece and the field is evaluated with the live signs.

// `!(a >= b)` comparisons are deliberate: they also catch NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::input::Affine;
use super::locate::locate;
use super::{Branches, Plant, State, MAX_SWITCHES};

/// Consecutive quick switches after which locking is dropped (see the module docs).
pub const MAX_CHATTER: usize = 16;

/// The branches held for a plant's switching functions.
#[derive(Debug, Clone)]
pub(crate) struct Locking {
    n: usize,
    branch: Branches,
    /// Locking is in force (the plant has switching functions and has not
    /// chattered during the current input piece).
    active: bool,
    chatter: usize,
}

impl Locking {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            n,
            branch: [0.0; MAX_SWITCHES],
            active: false,
            chatter: 0,
        }
    }

    /// A new input piece begins: locking is (re-)enabled.
    pub(crate) fn start_piece(&mut self) {
        self.active = self.n > 0;
        self.chatter = 0;
    }

    /// The branches held, or `None` when the field uses the live signs.
    pub(crate) fn held(&self) -> Option<Branches> {
        self.active.then_some(self.branch)
    }

    /// The values of the switching functions at the end `(tb, x_end)` of a
    /// step, `dx_end` being the derivative there (see
    /// [`Plant::switching_component`]); `None` when locking is off.
    pub(crate) fn values_at<P: Plant>(
        &self,
        plant: &P,
        tb: f64,
        x_end: &State,
        dx_end: &[f64],
        u: f64,
    ) -> Option<Branches> {
        if !self.active {
            return None;
        }
        let mut s = [0.0; MAX_SWITCHES];
        for (j, sj) in s.iter_mut().enumerate().take(self.n) {
            match plant.switching_component(j) {
                Some(i) if i >= 2 && i < plant.dim() => *sj = dx_end[i],
                _ => {
                    plant.switching(tb, x_end, u, &mut s);
                    break;
                }
            }
        }
        Some(s)
    }

    /// Chooses the branches for a (re)start at `(t, x)`; `probe` is the time
    /// step of the look-ahead for functions that are 0 at `t`.
    pub(crate) fn choose<P: Plant>(
        &mut self,
        plant: &P,
        t: f64,
        x: &State,
        piece: Affine,
        probe: f64,
    ) {
        if !self.active {
            return;
        }
        let mut s = [0.0; MAX_SWITCHES];
        plant.switching(t, x, piece.value(t), &mut s);
        let mut ahead = None;
        for j in 0..self.n {
            self.branch[j] = if s[j] == 0.0 {
                let s_ahead = ahead.get_or_insert_with(|| look_ahead(plant, t, x, piece, probe));
                sign(s_ahead[j])
            } else {
                sign(s[j])
            };
        }
    }

    /// The earliest switch inside the step `[ta, tb]`, given the switching
    /// functions' values `s_end` at its end, if any, located to `tol` on its
    /// far side: (time, which function). `dense` is the step's dense output.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn find<P: Plant, D: Fn(f64) -> State>(
        &self,
        plant: &P,
        ta: f64,
        tb: f64,
        s_end: &Branches,
        dense: D,
        piece: Affine,
        tol: f64,
    ) -> Option<(f64, usize)> {
        let mut first: Option<(f64, usize)> = None;
        for j in 0..self.n {
            let b = self.branch[j];
            // > 0 once s_j has left the side of its branch.
            let past = move |s: f64| if b == 0.0 { s.abs() } else { -b * s };
            let gb = past(s_end[j]);
            if !(gb > 0.0) {
                continue;
            }
            let g = |t: f64| {
                let mut s = [0.0; MAX_SWITCHES];
                plant.switching(t, &dense(t), piece.value(t), &mut s);
                past(s[j])
            };
            let ga = g(ta);
            let te = if ga > 0.0 {
                ta
            } else {
                locate(g, ta, ga, tb, gb, tol)
            };
            if first.is_none_or(|(tf, _)| te < tf) {
                first = Some((te, j));
            }
        }
        first
    }

    /// Records a switch that came `steps` accepted steps after the previous
    /// (re)start, and drops locking when switching chatters.
    pub(crate) fn switched(&mut self, steps: usize) {
        self.chatter = if steps <= 1 { self.chatter + 1 } else { 0 };
        if self.chatter >= MAX_CHATTER {
            self.active = false;
        }
    }
}

/// The switching functions at `t + h` on the explicit-Euler extrapolation of
/// the live field from `(t, x)`.
fn look_ahead<P: Plant>(plant: &P, t: f64, x: &State, piece: Affine, h: f64) -> Branches {
    let mut dx = [0.0; super::MAX_DIM];
    plant.deriv(t, x, piece.value(t), &mut dx);
    let mut xp = *x;
    for (xi, di) in xp.iter_mut().zip(&dx).take(plant.dim()) {
        *xi += h * di;
    }
    let mut s = [0.0; MAX_SWITCHES];
    plant.switching(t + h, &xp, piece.value(t + h), &mut s);
    s
}

/// sign with sign(0) = 0 (and NaN for NaN).
fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        x * 0.0
    }
}
