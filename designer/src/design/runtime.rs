//! A design as the runtime runs it: the runtime's `Plan`, `Law` and `Surface`
//! traits implemented on a [`ControllerDesign`], so that the designer's closed
//! loops (`reldesign loop`, `sweep`) run the very operation logic the emitted
//! code runs (`reldesign_runtime::control`, `::sliding`), with the model's
//! functions evaluated from tapes where the emitted file has code.
//!
//! The emitted and the run-time plans share everything but the law's
//! arithmetic (tape vs emitted expressions); the tests compare the two.

use std::cell::RefCell;

use reldesign_runtime::control::{Landing, Law, Motion, Plan, Settings, SoftLanding};
use reldesign_runtime::sliding::{SlidingMode, Surface, SurfaceSettings};

use crate::description::Operation;
use crate::model::Model;
use crate::sym::Tape;

use super::decisions::{ControllerDesign, LawDesign};

/// The design's plan, with the feedback-linearizing law's tape where that is
/// the law.
pub struct RuntimePlan<'a> {
    design: &'a ControllerDesign,
    /// (z, v, φ, u, t) → [α, β, a(x)] [PT 32], [PT 41], with its scratch.
    law: Option<(Tape, RefCell<Vec<f64>>)>,
}

/// One of the two controllers, ready to step.
pub enum RuntimeController<'a> {
    FeedbackLinearization(SoftLanding<RuntimePlan<'a>, f64>),
    SlidingMode(SlidingMode<RuntimePlan<'a>, f64>),
}

impl<'a> RuntimePlan<'a> {
    /// The plan of `design` on `model` (the model the design was made on).
    pub fn new(model: &mut Model, design: &'a ControllerDesign) -> RuntimePlan<'a> {
        let lin = &design.linearization;
        let law = match design.law {
            LawDesign::FeedbackLinearization { .. } => {
                let tape = model.compile(&[lin.alpha, lin.beta, lin.transform[2]]);
                let scratch = RefCell::new(tape.scratch());
                Some((tape, scratch))
            }
            LawDesign::SlidingMode { .. } => None,
        };
        RuntimePlan { design, law }
    }

    /// The controller of `operation`, started at t = 0.
    pub fn controller(self, operation: Operation) -> RuntimeController<'a> {
        match self.design.law {
            LawDesign::FeedbackLinearization { .. } => {
                RuntimeController::FeedbackLinearization(SoftLanding::with(self, operation))
            }
            LawDesign::SlidingMode { .. } => {
                RuntimeController::SlidingMode(SlidingMode::with(self, operation))
            }
        }
    }
}

impl RuntimeController<'_> {
    /// Starts the operation at `t_start` [s].
    pub fn start(&mut self, t_start: f64) {
        match self {
            RuntimeController::FeedbackLinearization(c) => c.start(t_start),
            RuntimeController::SlidingMode(c) => c.start(t_start),
        }
    }

    /// [z_r, v_r, a_r, j_r] at `t`.
    pub fn reference(&mut self, t: f64) -> [f64; 4] {
        match self {
            RuntimeController::FeedbackLinearization(c) => c.reference(t),
            RuntimeController::SlidingMode(c) => c.reference(t),
        }
    }

    /// The input at `t` for the state [z, v, φ] and the acceleration a
    /// (which only the sliding mode reads; `phi` is the current where the
    /// sliding mode keeps it non-negative).
    pub fn step(&mut self, t: f64, z: f64, v: f64, a: f64, phi: f64) -> f64 {
        match self {
            RuntimeController::FeedbackLinearization(c) => c.step(t, z, v, phi),
            RuntimeController::SlidingMode(c) => c.step(t, z, v, a, phi),
        }
    }
}

impl Plan<f64> for RuntimePlan<'_> {
    type Operation = Operation;

    fn settings(&self) -> Settings<f64> {
        let d = self.design;
        Settings {
            u_min: d.u_min,
            u_max: d.u_max,
            takeoff: d.takeoff,
            landing: d.landing,
            phi_guard: d.phi_guard,
            landed_band: d.landed_band,
            press: d.press,
            creep: d.creep,
            creep_max: d.creep_max,
        }
    }

    fn motion(&self, operation: Operation) -> Motion<'_, f64> {
        let landing = match operation {
            Operation::Closing => Landing::Closing,
            Operation::Opening => Landing::Opening,
        };
        match self
            .design
            .operations
            .iter()
            .find(|o| o.operation == operation)
        {
            Some(o) => Motion {
                landing,
                z0: o.z0,
                zf: o.zf,
                table: &o.table.segments,
            },
            // not designed: rest where the armature is (an empty table)
            None => Motion {
                landing,
                z0: f64::NAN,
                zf: f64::NAN,
                table: &[],
            },
        }
    }
}

impl Law<f64> for RuntimePlan<'_> {
    /// [PT 50] u = α + β·(K·(ξ_r − T(x)) + j_r), T(x) = [z, v, a(x)].
    fn law(&self, [z, v, phi]: [f64; 3], [zr, vr, ar, jr]: [f64; 4]) -> f64 {
        let (
            Some((tape, scratch)),
            LawDesign::FeedbackLinearization {
                gains: [k1, k2, k3],
            },
        ) = (&self.law, self.design.law)
        else {
            return f64::NAN;
        };
        let mut out = [0.0; 3];
        tape.eval(&[z, v, phi, 0.0, 0.0], &mut scratch.borrow_mut(), &mut out);
        let [alpha, beta, a] = out;
        let w = k1 * (zr - z) + k2 * (vr - v) + k3 * (ar - a) + jr;
        alpha + beta * w
    }
}

impl Surface<f64> for RuntimePlan<'_> {
    fn surface(&self) -> SurfaceSettings<f64> {
        match self.design.law {
            LawDesign::SlidingMode {
                lambda1,
                lambda2,
                nonnegative_current,
            } => SurfaceSettings {
                lambda1,
                lambda2,
                nonnegative_current,
            },
            LawDesign::FeedbackLinearization { .. } => SurfaceSettings {
                lambda1: f64::NAN,
                lambda2: f64::NAN,
                nonnegative_current: false,
            },
        }
    }
}
