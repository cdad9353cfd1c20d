//! A design as the runtime runs it: the runtime's `Plan`, `Law` and `Surface`
//! traits implemented on a [`ControllerDesign`] (and `Hold` on a
//! [`HoldDesign`]), so that the designer's closed
//! loops (`reldesign loop`, `sweep`) run the very operation logic the emitted
//! code runs (`reldesign_runtime::control`, `::sliding`), with the model's
//! functions evaluated from tapes where the emitted file has code.
//!
//! The emitted and the run-time plans share everything but the law's
//! arithmetic (tape vs emitted expressions); the tests compare the two.

use std::cell::RefCell;

use reldesign_runtime::backstepping::{
    self, Backstepping, BacksteppingSettings, SwitchedBackstepping,
};
use reldesign_runtime::control::{Landing, Law, Motion, Plan, Settings, SoftLanding};
use reldesign_runtime::hold::{Hold, HoldSettings, PositionHold};
use reldesign_runtime::sliding::{SlidingMode, Surface, SurfaceSettings};

use crate::description::{Operation, SetPoint, Switching};
use crate::model::Model;
use crate::sym::Tape;

use super::derive::linearization::Linearization;
use super::law::backstepping::design::BacksteppingDesign;
use super::law::decisions::{ControllerDesign, LawDesign};
use super::law::hold::HoldDesign;

/// The tracking law [PT 50] from a tape: (x, u, t) → [α, β, a(x)] [PT 32],
/// [PT 41], x the model's states (H_c too on the Jiles–Atherton core).
struct LawTape {
    tape: Tape,
    scratch: RefCell<Vec<f64>>,
    /// The model's number of states (3, or 4 with H_c).
    dim: usize,
}

impl LawTape {
    fn new(model: &mut Model, lin: &Linearization) -> LawTape {
        let tape = model.compile(&[lin.alpha, lin.beta, lin.transform[2]]);
        let scratch = RefCell::new(tape.scratch());
        LawTape {
            tape,
            scratch,
            dim: model.dim(),
        }
    }

    /// [PT 50] u = α + β·(K·(ξ_r − T(x)) + j_r), T(x) = [z, v, a(x)].
    fn law(&self, gains: [f64; 3], x: [f64; 4], [zr, vr, ar, jr]: [f64; 4]) -> f64 {
        let mut inputs = [0.0; 6];
        inputs[..self.dim].copy_from_slice(&x[..self.dim]);
        let mut out = [0.0; 3];
        let n = self.dim + 2;
        (self.tape).eval(&inputs[..n], &mut self.scratch.borrow_mut(), &mut out);
        let [alpha, beta, a] = out;
        let [k1, k2, k3] = gains;
        let [z, v, ..] = x;
        let w = k1 * (zr - z) + k2 * (vr - v) + k3 * (ar - a) + jr;
        alpha + beta * w
    }
}

/// The design's plan, with the tracking law's tape where the law is one
/// (feedback linearization, the model-based sliding mode).
pub struct RuntimePlan<'a> {
    design: &'a ControllerDesign,
    law: Option<LawTape>,
}

/// One of the two controllers, ready to step.
pub enum RuntimeController<'a> {
    FeedbackLinearization(SoftLanding<RuntimePlan<'a>, f64>),
    SlidingMode(SlidingMode<RuntimePlan<'a>, f64>),
}

impl<'a> RuntimePlan<'a> {
    /// The plan of `design` on `model` (the model the design was made on).
    pub fn new(model: &mut Model, design: &'a ControllerDesign) -> RuntimePlan<'a> {
        let law = (design.law.tracking_gains()).map(|_| LawTape::new(model, &design.linearization));
        RuntimePlan { design, law }
    }

    /// The controller of `operation`, started at t = 0.
    pub fn controller(self, operation: Operation) -> RuntimeController<'a> {
        match self.design.law {
            LawDesign::FeedbackLinearization { .. } | LawDesign::ModelSlidingMode { .. } => {
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

    /// Whether the controller pushed an armature it read neither held at
    /// its stop nor within the arrival band (`finished_late`).
    pub fn finished_late(&self) -> bool {
        match self {
            RuntimeController::FeedbackLinearization(c) => c.finished_late(),
            RuntimeController::SlidingMode(c) => c.finished_late(),
        }
    }

    /// [z_r, v_r, a_r, j_r] at `t`.
    pub fn reference(&mut self, t: f64) -> [f64; 4] {
        match self {
            RuntimeController::FeedbackLinearization(c) => c.reference(t),
            RuntimeController::SlidingMode(c) => c.reference(t),
        }
    }

    /// The input at `t` for the state [z, v, φ, H_c] and the acceleration a
    /// (which only the model-free sliding mode reads; `phi` is the current
    /// where it keeps the current non-negative; H_c only a law on a
    /// Jiles–Atherton core reads).
    pub fn step(&mut self, t: f64, [z, v, phi, hc]: [f64; 4], a: f64) -> f64 {
        match self {
            RuntimeController::FeedbackLinearization(c) => c.step_with_field(t, z, v, phi, hc),
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
            arrival_margin: d.arrival_margin,
            arrival_band: d.arrival_band,
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
    fn law(&self, x: [f64; 4], reference: [f64; 4]) -> f64 {
        match (&self.law, self.design.law.tracking_gains()) {
            (Some(tape), Some(gains)) => tape.law(gains, x, reference),
            _ => f64::NAN,
        }
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
            LawDesign::FeedbackLinearization { .. } | LawDesign::ModelSlidingMode { .. } => {
                SurfaceSettings {
                    lambda1: f64::NAN,
                    lambda2: f64::NAN,
                    nonnegative_current: false,
                }
            }
        }
    }
}

/// A position hold as the runtime runs it: the runtime's `Hold` on a
/// [`HoldDesign`], the law [JA 89] from a tape.
pub struct RuntimeHold<'a> {
    design: &'a HoldDesign,
    law: LawTape,
}

impl<'a> RuntimeHold<'a> {
    /// The hold of `design` on `model` (the model the design was made on).
    pub fn new(model: &mut Model, design: &'a HoldDesign) -> RuntimeHold<'a> {
        let law = LawTape::new(model, &design.linearization);
        RuntimeHold { design, law }
    }

    /// The runtime's controller over this plan.
    pub fn controller(self) -> PositionHold<RuntimeHold<'a>, f64> {
        PositionHold::with(self)
    }
}

impl Hold<f64> for RuntimeHold<'_> {
    fn settings(&self) -> HoldSettings<f64> {
        let d = self.design;
        HoldSettings {
            position: d.position,
            z_min: d.z_min,
            z_max: d.z_max,
            u_max: d.u_max,
            phi_guard: d.phi_guard,
            landed_band: d.landed_band,
        }
    }

    /// [JA 89] as [PT 50] with K = [K·p², p² + 2pK, 2p + K].
    fn law(&self, x: [f64; 4], reference: [f64; 4]) -> f64 {
        self.law.law(self.design.gains(), x, reference)
    }
}

/// F_d [SB Theorem 1], u [SB 19] and the force F from one tape: (x, u = 0,
/// t = 0, y_r) → [F_d, u, F], the gains and P bound to the design's values.
struct BacksteppingTape {
    tape: Tape,
    scratch: RefCell<Vec<f64>>,
    dim: usize,
}

impl BacksteppingTape {
    fn new(model: &mut Model, design: &BacksteppingDesign) -> BacksteppingTape {
        let law = &design.law;
        let map = (design.bound_symbols().iter())
            .map(|&(_, symbol, value)| (symbol, model.graph.constant(value)))
            .collect();
        let exprs = (model.graph).substitute_all(&[law.desired_force, law.law, law.force], &map);
        let bound = model.bind_params(&exprs);
        let mut inputs = model.tape_inputs();
        inputs.push(law.target);
        let tape = Tape::compile(&model.graph, &inputs, &bound)
            .unwrap_or_else(|e| unreachable!("the law reads states, u, t, y_r only: {}", e.0));
        BacksteppingTape {
            scratch: RefCell::new(tape.scratch()),
            tape,
            dim: model.dim(),
        }
    }

    fn eval(&self, x: [f64; 4], y_r: f64) -> [f64; 3] {
        let mut inputs = [0.0; 7];
        inputs[..self.dim].copy_from_slice(&x[..self.dim]);
        inputs[self.dim + 2] = y_r;
        let mut out = [0.0; 3];
        (self.tape).eval(
            &inputs[..self.dim + 3],
            &mut self.scratch.borrow_mut(),
            &mut out,
        );
        out
    }
}

/// A [`BacksteppingDesign`] as the runtime's `backstepping::Backstepping`,
/// F_d and the law from a tape.
pub struct RuntimeBackstepping<'a> {
    design: &'a BacksteppingDesign,
    tape: BacksteppingTape,
}

impl<'a> RuntimeBackstepping<'a> {
    /// The controller of `design` on `model` (the model the design was made on).
    pub fn new(model: &mut Model, design: &'a BacksteppingDesign) -> RuntimeBackstepping<'a> {
        let tape = BacksteppingTape::new(model, design);
        RuntimeBackstepping { design, tape }
    }

    /// The runtime's controller over this plan.
    pub fn controller(self) -> SwitchedBackstepping<RuntimeBackstepping<'a>, f64> {
        SwitchedBackstepping::with(self)
    }

    /// V = ZᵀPZ + ½·(F − F_d)² at x for y_r [SB 21], [SB 18]: non-increasing
    /// wherever the law is applied unsaturated.
    pub fn lyapunov(&self, x: [f64; 4], y_r: f64) -> f64 {
        let [desired, _, force] = self.tape.eval(x, y_r);
        let [z, v, ..] = x;
        let mechanical = backstepping::lyapunov(&self.settings(), z, v, y_r);
        mechanical + 0.5 * (force - desired) * (force - desired)
    }
}

/// The runtime's switching strategy of the description's.
pub fn runtime_switching(s: Switching) -> backstepping::Switching {
    match s {
        Switching::None => backstepping::Switching::None,
        Switching::Intuitive => backstepping::Switching::Intuitive,
        Switching::Hybrid => backstepping::Switching::Hybrid,
    }
}

impl BacksteppingDesign {
    /// The reference with each target's level C, as the runtime reads it.
    pub fn set_point(&self) -> backstepping::SetPoint<f64> {
        let target = |i: usize| backstepping::Target {
            position: self.region.targets.get(i).map_or(f64::NAN, |t| t.position),
            level: self.region.levels.get(i).map_or(f64::NAN, |l| l.c),
        };
        match self.reference {
            SetPoint::Position(_) => backstepping::SetPoint::Position(target(0)),
            SetPoint::Square { period, .. } => backstepping::SetPoint::Square {
                low: target(0),
                high: target(1),
                period,
            },
        }
    }
}

impl Backstepping<f64> for RuntimeBackstepping<'_> {
    fn settings(&self) -> BacksteppingSettings<f64> {
        let d = self.design;
        BacksteppingSettings {
            u_min: d.u_min,
            u_max: d.u_max,
            phi_guard: d.phi_guard,
            alpha1: d.gains[0],
            p: d.region.p,
            switching: runtime_switching(d.switching),
            reference: d.set_point(),
        }
    }

    fn desired_force(&self, z: f64, v: f64, y_r: f64) -> f64 {
        self.tape.eval([z, v, 0.0, 0.0], y_r)[0]
    }

    fn law(&self, x: [f64; 4], y_r: f64) -> f64 {
        self.tape.eval(x, y_r)[1]
    }
}
