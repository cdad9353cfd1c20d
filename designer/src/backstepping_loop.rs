//! The backstepping position controller (switched-force-backstepping [SB])
//! in a sampled loop on a plant: the library call behind `reldesign loop` for
//! `law = "backstepping"`.
//!
//! The controller is the runtime's `backstepping::SwitchedBackstepping` on the
//! run-time design (`design::RuntimeBackstepping`), called every sample period
//! with the plant's state (or, where `[controller] estimator` names one, the
//! observer's estimate), its output held until the next sample. The loop
//! starts at rest on the spring's stop without flux unless told otherwise
//! (the paper's three kinds of initial condition are states, see
//! [`run_backstepping`]). Besides the trajectory it records, per sample, the
//! switching mode, whether Z ∈ D, F_d and the Lyapunov function
//! V = ZᵀPZ + ½·(F − F_d)² of the proof of [SB Theorem 2].

use reldesign_runtime::backstepping::Backstepping;
pub use reldesign_runtime::backstepping::Mode;

use crate::closed_loop::{check_plant, LoopError, LoopRun, Noise, Sensing};
use crate::description::{Description, SetPoint};
use crate::design::{Design, RuntimeBackstepping};
use crate::model::{Model, ModelPlant};
use crate::sim::{simulate_sampled, Measurement, Mode as Contact, Options, State};

/// A backstepping run and what its controller saw at every sample.
#[derive(Debug, Clone)]
pub struct BacksteppingRun {
    pub run: LoopRun,
    /// At every sample: the mode after the step.
    pub modes: Vec<Mode>,
    /// At every sample: ZᵀPZ ≤ C (the state in D).
    pub inside: Vec<bool>,
    /// At every sample: F_d [N] [SB Theorem 1].
    pub desired_force: Vec<f64>,
    /// At every sample: V = ZᵀPZ + ½·(F − F_d)², on the state read.
    pub lyapunov: Vec<f64>,
}

/// Default length of a backstepping loop [s]: 50 ms at a constant position,
/// two periods of a square reference (up to the last sample before the
/// reference's next change).
pub fn default_duration(reference: &SetPoint, sample_period: f64) -> f64 {
    match *reference {
        SetPoint::Position(_) => 50e-3,
        SetPoint::Square { period, .. } => 2.0 * period - 0.5 * sample_period,
    }
}

/// Runs `design`'s backstepping controller at `sample_period` for `duration`
/// (default [`default_duration`]) on the model of `plant` (default: the
/// design's own), from `initial` = [z, v, φ] (default: at rest on the spring's
/// stop without flux; v ≠ 0 or z inside the stroke start in free motion).
pub fn run_backstepping(
    design: &Design,
    plant: Option<&Description>,
    sample_period: f64,
    duration: Option<f64>,
    noise: Noise,
    initial: Option<[f64; 3]>,
    options: &Options,
) -> Result<BacksteppingRun, LoopError> {
    let Some(b) = &design.backstepping else {
        return Err(LoopError::NoController);
    };
    let plant_description = plant.unwrap_or(&design.description);
    let mut plant_model = Model::build(plant_description);
    check_plant(design, &plant_model)?;
    let model_plant = ModelPlant::new(&mut plant_model);
    let mut design_model = design.model.clone();
    let mut controller = RuntimeBackstepping::new(&mut design_model, b).controller();
    let mut sensing = Sensing::new(design, &model_plant, sample_period, noise, false)?;
    let settings = controller.plan().settings();
    let mut z_ref = Vec::new();
    let (mut modes, mut inside, mut desired, mut lyapunov) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut control = |_t: f64, m: &Measurement| {
        let (x, _) = sensing.read(m);
        let u = controller.step(m.t, x[0], x[1], x[2], x[3]);
        let target = controller.target(m.t);
        let y_r = target.position;
        z_ref.push((m.t, y_r));
        modes.push(controller.mode());
        let mechanical = reldesign_runtime::backstepping::lyapunov(&settings, x[0], x[1], y_r);
        inside.push(mechanical <= target.level);
        desired.push(controller.plan().desired_force(x[0], x[1], y_r));
        lyapunov.push(controller.plan().lyapunov(x, y_r));
        sensing.apply(u)
    };
    let (x0, mode0) = start(&plant_model, b.rest, initial);
    let t_end = duration.unwrap_or_else(|| default_duration(&b.reference, sample_period));
    let trajectory = simulate_sampled(
        &model_plant,
        &mut control,
        sample_period,
        t_end,
        x0,
        mode0,
        options,
    )?;
    let first_target = b.reference.positions().first().copied().unwrap_or(f64::NAN);
    let (current, z_ref, estimates) = sensing.record(&trajectory, &z_ref, first_target);
    Ok(BacksteppingRun {
        run: LoopRun {
            trajectory,
            current,
            z_ref,
            operations: Vec::new(),
            operation_length: t_end,
            estimates,
            stops: crate::closed_loop::end_stops(plant_description),
            measured: sensing.take_measured(),
            flagged_late: Vec::new(),
        },
        modes,
        inside,
        desired_force: desired,
        lyapunov,
    })
}

/// The plant's start: `initial` = [z, v, φ] in free motion (at a stop if it
/// lies there at rest), or at rest at `rest` without flux.
fn start(plant: &Model, rest: f64, initial: Option<[f64; 3]>) -> (State, Contact) {
    let m = &plant.description.mechanics;
    let mut x0: State = [0.0; crate::sim::MAX_DIM];
    let [z, v, phi] = initial.unwrap_or([rest, 0.0, 0.0]);
    x0[0] = z.clamp(m.z_min, m.z_max);
    x0[1] = v;
    x0[2] = phi;
    let mode = if v == 0.0 && x0[0] >= m.z_max {
        Contact::StuckMax
    } else if v == 0.0 && x0[0] <= m.z_min {
        Contact::StuckMin
    } else {
        Contact::Free
    };
    if mode != Contact::Free {
        x0[1] = 0.0;
    }
    (x0, mode)
}

/// How one step of a square reference was tracked (the paper's Fig. 9–11).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    /// When the step began [s] and the position it went to [m].
    pub start: f64,
    pub target: f64,
    /// From `start` until |z − y_r| stays within 5 % of the step [s]; `None`:
    /// not within the step.
    pub settling_time: Option<f64>,
    /// The largest excursion beyond the target, as a fraction of the step.
    pub overshoot: f64,
}

/// What happened after the law first took over (the state first in D):
/// the region D = {ZᵀPZ ≤ C} is invariant under the law only while F = F_d
/// (z₃ = 0), and at the entry z₃ = −F_d (no flux yet), so these count what
/// the proof does not cover.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AfterEntry {
    /// Samples with the state outside D.
    pub outside: usize,
    /// Samples with F_d < 0 (the magnet asked to push).
    pub pushing: usize,
    /// Samples at which the input jumped between the supply's bounds (a
    /// bang-bang chatter: u_max at one sample, u_min at the next, or back).
    pub bang_bang: usize,
}

/// Settled: within this fraction of the step.
pub const STEP_BAND: f64 = 0.05;

impl BacksteppingRun {
    /// Each constant stretch of the reference after the first change, and how
    /// it was tracked.
    pub fn steps(&self) -> Vec<StepOutcome> {
        let tr = &self.run.trajectory;
        let r = &self.run.z_ref;
        let changes: Vec<usize> = (1..r.len()).filter(|&k| r[k] != r[k - 1]).collect();
        let mut out = Vec::new();
        for (i, &k0) in changes.iter().enumerate() {
            let k1 = changes.get(i + 1).copied().unwrap_or(r.len());
            if k1 < k0 + 2 {
                continue; // the run ended on the change
            }
            let (from, to) = (r[k0 - 1], r[k0]);
            let step = to - from;
            let band = STEP_BAND * step.abs();
            let last_out = (k0..k1).rev().find(|&k| (tr.x[k][0] - to).abs() > band);
            let settling_time = match last_out {
                None => Some(0.0),
                Some(k) if k + 1 < k1 => Some(tr.t[k + 1] - tr.t[k0]),
                Some(_) => None,
            };
            let beyond = (k0..k1)
                .map(|k| (tr.x[k][0] - to) * step.signum())
                .fold(0.0, f64::max);
            out.push(StepOutcome {
                start: tr.t[k0],
                target: to,
                settling_time,
                overshoot: beyond / step.abs(),
            });
        }
        out
    }

    /// After the law first took over (`None`: it never did), within each
    /// constant stretch of the reference: see [`AfterEntry`].
    pub fn after_entry(&self, u_min: f64, u_max: f64) -> Option<AfterEntry> {
        let first = self.modes.iter().position(|&m| m == Mode::Inside)?;
        let u = &self.run.trajectory.u;
        let r = &self.run.z_ref;
        let same_stretch = |k: usize| r.get(k) == r.get(k - 1);
        let mut out = AfterEntry {
            outside: 0,
            pushing: 0,
            bang_bang: 0,
        };
        for k in first..self.modes.len() {
            out.outside += usize::from(!self.inside[k]);
            out.pushing += usize::from(self.desired_force[k] < 0.0);
            if k > first && same_stretch(k) {
                let jump =
                    (u[k - 1] >= u_max && u[k] <= u_min) || (u[k - 1] <= u_min && u[k] >= u_max);
                out.bang_bang += usize::from(jump);
            }
        }
        Some(out)
    }

    /// How often the input law switched on or off (modes `Waiting` ↔ others).
    pub fn switches(&self) -> usize {
        self.modes
            .windows(2)
            .filter(|w| (w[0] == Mode::Waiting) != (w[1] == Mode::Waiting))
            .count()
    }
}
