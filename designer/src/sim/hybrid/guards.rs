//! The guards, checked on the dense output of every accepted step, and the
//! earliest crossing located inside it (Illinois root finder, `locate.rs`).
//!
//! Guards (all fire when strictly positive):
//! - Free: `z_min − z` (impact at the lower limit), `z − z_max` (upper limit);
//! - StuckMin: the free acceleration `a = deriv(t, (z_min, 0, …), u)[1]` (lift-off);
//! - StuckMax: `−a`.
//!
//! A plant's switching functions are watched alike (see `switching.rs`).

use super::field::free_accel;
use super::quadrature::{head_state, plant_state, Quadrature, EXT};
use super::Engine;
use crate::sim::input::Affine;
use crate::sim::locate::locate;
use crate::sim::{Mode, Plant};

impl<P: Plant, Q: Quadrature> Engine<'_, P, Q> {
    /// Earliest guard crossing inside the last accepted step up to `tb`, if any.
    pub(super) fn find_event(&mut self, piece: Affine, tb: f64) -> Option<f64> {
        let ta = self.rk.t_prev();
        let tol = self.opts.event_tol * tb.abs().max(1.0);
        match self.mode {
            Mode::Free => self.find_impact(ta, tb, tol),
            Mode::StuckMin => self.find_lift_off(ta, tb, tol, 1.0, piece),
            Mode::StuckMax => self.find_lift_off(ta, tb, tol, -1.0, piece),
        }
    }

    /// Earliest sign change of a switching function inside the last accepted
    /// step, if any: (time, which function) (see `switching.rs`).
    pub(super) fn find_switch(&self, piece: Affine) -> Option<(f64, usize)> {
        let (rk, pd) = (&self.rk, self.pd);
        let (ta, tb) = (rk.t_prev(), rk.t());
        let tol = self.opts.event_tol * tb.abs().max(1.0);
        let x_end = plant_state(rk.x(), pd);
        let s_end = self
            .lock
            .values_at(self.plant, tb, &x_end, rk.dx(), piece.value(tb))?;
        let dense = |t: f64| head_state(rk.dense_head(t), pd);
        self.lock
            .find(self.plant, ta, tb, &s_end, dense, piece, tol)
    }

    /// Position guards, checked at 4 points of the step (cheap: dense output
    /// of `z` only) so that a brief excursion inside the step is not missed.
    fn find_impact(&self, ta: f64, tb: f64, tol: f64) -> Option<f64> {
        let (rk, lim) = (&self.rk, self.lim);
        let g = |t: f64| {
            let z = rk.dense_component(0, t);
            (lim.z_min - z, z - lim.z_max)
        };
        let (mut tp, mut gp) = (ta, g(ta));
        for j in 1..=4 {
            let tj = if j == 4 {
                tb
            } else {
                ta + (tb - ta) * (j as f64 / 4.0)
            };
            let gj = g(tj);
            if gj.0 > 0.0 || gj.1 > 0.0 {
                let mut te = tj;
                if gj.0 > 0.0 {
                    te = te.min(locate(|t| g(t).0, tp, gp.0, tj, gj.0, tol));
                }
                if gj.1 > 0.0 {
                    te = te.min(locate(|t| g(t).1, tp, gp.1, tj, gj.1, tol));
                }
                return Some(te);
            }
            (tp, gp) = (tj, gj);
        }
        None
    }

    /// Lift-off guard `sign·a(t) > 0`, checked at the middle and end of the step.
    fn find_lift_off(
        &mut self,
        ta: f64,
        tb: f64,
        tol: f64,
        sign: f64,
        piece: Affine,
    ) -> Option<f64> {
        let mut evals = 0;
        let branch = self.lock.held();
        let mut g = |t: f64| {
            evals += 1;
            let mut x = [0.0; EXT];
            self.rk.dense(t, &mut x);
            sign * free_accel(self.plant, self.pd, branch, t, &x, piece)
        };
        let (mut tp, mut gp) = (ta, f64::NEG_INFINITY);
        let mut found = None;
        for tj in [ta + 0.5 * (tb - ta), tb] {
            let gj = g(tj);
            if gj > 0.0 {
                if gp == f64::NEG_INFINITY {
                    gp = g(tp);
                }
                found = Some(locate(&mut g, tp, gp, tj, gj, tol));
                break;
            }
            (tp, gp) = (tj, gj);
        }
        self.extra_evals += evals;
        found
    }
}
