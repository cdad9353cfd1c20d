//! The designed controller in a sampled loop on a plant: the library call
//! behind `reldesign loop` (and `sweep`).
//!
//! The controller is the runtime's own operation logic on the run-time
//! design (`design::RuntimePlan`), called every sample period with the
//! plant's state, its output held until the next sample (zero-order hold,
//! `sim::simulate_sampled`). The plant is the hybrid model of a description:
//! the design's own or another one (a mismatched device). The operations of
//! `[trajectory]` run one after the other, each for takeoff + landing
//! (model-free-sliding-mode [SM 45]: as long a rest after landing as before
//! takeoff); the loop starts at rest at the first operation's z₀: at z_max
//! without flux, or held at z_min with 1.2× the flux that balances the spring.
//! Where `[controller] estimator` names an observer, it drives the controller
//! from the measured voltage and current, with the noise of `[observer]`
//! (seeded); otherwise the controller reads the plant's state.

use crate::description::{Description, Operation};
use crate::design::{operation_end, Design, RuntimeController, RuntimeHold, RuntimePlan};
use crate::model::{Model, ModelPlant, Statics};
use crate::observe::discrete::Estimate;
use crate::observe::ekf::Ekf;
use crate::observe::ukf::Ukf;
use crate::random::SplitMix64;
use crate::sim::{
    simulate, simulate_sampled, EventKind, Limit, Measurement, Mode, Options, PiecewiseLinear,
    Plant, SimError, State, Trajectory,
};
use reldesign_runtime::resistance::compensate_resistance;

/// Why a loop could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LoopError {
    #[error("the description designs no controller: add [trajectory] and [controller]")]
    NoController,
    #[error("{0} positions the armature and has no soft landing to sweep: run it with `reldesign loop --sample-period`")]
    Positions(&'static str),
    #[error("the design's law reads the core's field H_c, which a plant without a Jiles–Atherton core does not have: feed it an observer's estimate ([controller] estimator) or use a Jiles–Atherton plant")]
    PlantMismatch { plant: usize, design: usize },
    #[error("the design at T_s = {sample_period:e} s: {message}")]
    Design { sample_period: f64, message: String },
    #[error("the loop's observer: {0}")]
    Observer(String),
    #[error("the switching input: {0}")]
    Input(String),
    #[error("the loop's simulation failed: {0}")]
    Sim(#[from] SimError),
}

/// The measurement noise a loop's observer reads: seeded, with the σ_v and
/// σ_i of `[observer]` unless given (a bench whose noise differs from what
/// the filter assumes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    pub seed: u64,
    /// [σ_v, σ_i]; `None`: `observer.voltage_noise`, `observer.current_noise`.
    pub sigma: Option<[f64; 2]>,
}

impl Noise {
    /// The observer's own noise, seeded by `seed`.
    pub fn seeded(seed: u64) -> Noise {
        Noise { seed, sigma: None }
    }
}

/// One closed-loop run.
#[derive(Debug, Clone)]
pub struct LoopRun {
    /// At every sample: time, held input, state, mode.
    pub trajectory: Trajectory,
    /// The coil current at every sample.
    pub current: Vec<f64>,
    /// The reference position at every sample.
    pub z_ref: Vec<f64>,
    /// Each operation and its start time [s].
    pub operations: Vec<(Operation, f64)>,
    /// The length of one operation [s].
    pub operation_length: f64,
    /// The observer's estimate at every sample, where one drives the controller.
    pub estimates: Option<Vec<Estimate>>,
    /// The plant's end stops [z_min, z_max] [m].
    pub stops: [f64; 2],
    /// At every sample: the voltage commanded over the last sample period,
    /// the voltage and the current measured (with the observer's noise where
    /// one drives the controller): what a firmware's calibration records.
    pub measured: Vec<Measured>,
    /// Per operation, the controller's own verdict: whether it pushed an
    /// armature it read neither held at its stop nor within the arrival band
    /// (`SoftLanding::finished_late`, what a firmware reports). Empty for a
    /// position hold.
    pub flagged_late: Vec<bool>,
}

/// What a firmware reads at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    pub t: f64,
    /// The voltage the controller commanded over the last sample period.
    pub commanded: f64,
    /// That voltage and the current now, as measured.
    pub voltage: f64,
    pub current: f64,
}

/// The observer that drives the controller from the measured voltage and
/// current (`[controller] estimator`), with the seeded measurement noise of
/// `[observer]`.
struct Observer {
    filter: Filter,
    noise: SplitMix64,
    sigma_v: f64,
    sigma_i: f64,
}

enum Filter {
    Ekf(Box<Ekf>),
    Ukf(Box<Ukf>),
}

impl Observer {
    /// The estimate after measuring the current `i` now and the voltage
    /// `held` over the last sample, and the measured voltage and current.
    fn step(&mut self, held: f64, i: f64) -> (Estimate, f64, f64) {
        let u = held + self.sigma_v * self.noise.normal();
        let i = i + self.sigma_i * self.noise.normal();
        let e = match &mut self.filter {
            Filter::Ekf(f) => f.step(u, i),
            Filter::Ukf(f) => f.step(u, i),
        };
        (e, u, i)
    }
}

/// What a loop's controller reads at each sample: the plant's state, or the
/// observer's estimate from the measured voltage and current; and the input
/// held since the last sample.
pub(crate) struct Sensing<'a> {
    plant: &'a ModelPlant,
    observer: Option<Observer>,
    /// φ is read as the coil current ([SM §5]'s non-negative current).
    nonnegative_current: bool,
    /// The input held over the last sample period (the current depends on it
    /// through the eddy-current term).
    held: f64,
    estimates: Vec<(f64, Estimate)>,
    measured: Vec<Measured>,
    /// `controller.compensate_resistance`: the design's R and the supply's
    /// limits, with the current measured at the last sample.
    compensation: Option<Compensation>,
}

/// The law's voltage corrected to the observer's resistance estimate.
struct Compensation {
    resistance: f64,
    limits: (f64, f64),
    current: f64,
}

impl<'a> Sensing<'a> {
    /// What `design`'s controller reads on `plant` at `sample_period`: the
    /// observer of `[controller] estimator` (noise seeded by `noise`) or the
    /// plant's state; nothing held yet.
    pub(crate) fn new(
        design: &Design,
        plant: &'a ModelPlant,
        sample_period: f64,
        noise: Noise,
        nonnegative_current: bool,
    ) -> Result<Sensing<'a>, LoopError> {
        Ok(Sensing {
            plant,
            observer: observer(design, sample_period, noise)?,
            nonnegative_current,
            held: 0.0,
            estimates: Vec::new(),
            measured: Vec::new(),
            compensation: compensation(design),
        })
    }

    /// Applies the controller's `u` from this sample on: corrected to the
    /// observer's resistance estimate (`controller.compensate_resistance`,
    /// [`reldesign_runtime::resistance`]), held until the next sample.
    pub(crate) fn apply(&mut self, u: f64) -> f64 {
        let estimate = self.estimates.last().and_then(|(_, e)| e.r);
        let u = match (&self.compensation, estimate) {
            (Some(c), Some(r)) => compensate_resistance(u, r, c.resistance, c.current, c.limits),
            _ => u,
        };
        self.held = u;
        u
    }

    /// [z, v, φ, H_c] and the acceleration a at the sample `m` (H_c is 0
    /// where neither the plant nor the observer has it).
    pub(crate) fn read(&mut self, m: &Measurement) -> ([f64; 4], f64) {
        let x = &m.x;
        match &mut self.observer {
            Some(o) => {
                // the ADC samples i just before the new voltage is applied
                let (i, _) = self.plant.current_and_voltage(m.t, x, self.held);
                let (e, u, i) = o.step(self.held, i);
                self.measured.push(Measured {
                    t: m.t,
                    commanded: self.held,
                    voltage: u,
                    current: i,
                });
                if let Some(c) = &mut self.compensation {
                    c.current = i;
                }
                self.estimates.push((m.t, e));
                let phi = if self.nonnegative_current { i } else { e.phi };
                ([e.z, e.v, phi, e.hc.unwrap_or(0.0)], e.a)
            }
            None => {
                let (i, _) = self.plant.current_and_voltage(m.t, x, self.held);
                self.measured.push(Measured {
                    t: m.t,
                    commanded: self.held,
                    voltage: self.held,
                    current: i,
                });
                let mut dx: State = [0.0; crate::sim::MAX_DIM];
                self.plant.deriv(m.t, x, 0.0, &mut dx);
                // a: the free-motion acceleration, 0 against a stop
                let a = if m.mode == Mode::Free { dx[1] } else { 0.0 };
                let phi = if self.nonnegative_current {
                    self.plant.current_and_voltage(m.t, x, self.held).0
                } else {
                    x[2]
                };
                // H_c: the plant's, where it has the state (x[3] is 0 otherwise)
                ([x[0], x[1], phi, x[3]], a)
            }
        }
    }

    /// What was measured at every sample (taken: the log is left empty).
    pub(crate) fn take_measured(&mut self) -> Vec<Measured> {
        std::mem::take(&mut self.measured)
    }

    /// The run's current at every sample, its records at the samples (the
    /// reference `z_ref` starting from `z_ref_before`), and the estimates.
    pub(crate) fn record(
        &self,
        trajectory: &Trajectory,
        z_ref: &[(f64, f64)],
        z_ref_before: f64,
    ) -> (Vec<f64>, Vec<f64>, Option<Vec<Estimate>>) {
        let t = &trajectory.t;
        let (current, _) = self
            .plant
            .currents_and_voltages(t, &trajectory.x, &trajectory.u);
        let estimates =
            (self.observer.is_some()).then(|| at_samples(t, &self.estimates, NO_ESTIMATE));
        (current, at_samples(t, z_ref, z_ref_before), estimates)
    }
}

/// The controller and where the loop stands.
struct Sequencer<'a> {
    plan: Vec<RuntimeController<'a>>,
    operations: Vec<(Operation, f64)>,
    current: usize,
    sensing: Sensing<'a>,
    z_ref: Vec<(f64, f64)>,
}

impl Sequencer<'_> {
    /// The input at the sample `m`: the operation it falls in, its controller.
    fn control(&mut self, m: &Measurement) -> f64 {
        let next = self
            .operations
            .iter()
            .rposition(|(_, start)| *start <= m.t)
            .unwrap_or(0);
        if next != self.current {
            self.current = next;
            if let (Some(c), Some((_, start))) =
                (self.plan.get_mut(next), self.operations.get(next))
            {
                c.start(*start);
            }
        }
        let Some(c) = self.plan.get_mut(self.current) else {
            return 0.0;
        };
        let (state, a) = self.sensing.read(m);
        self.z_ref.push((m.t, c.reference(m.t)[0]));
        let u = c.step(m.t, state, a);
        self.sensing.apply(u)
    }
}

/// The compensation `design`'s `controller.compensate_resistance` asks for
/// (the parser checked that its estimator estimates R).
fn compensation(design: &Design) -> Option<Compensation> {
    let d = &design.description;
    d.controller
        .as_ref()?
        .compensate_resistance
        .then(|| Compensation {
            resistance: d.coil.resistance,
            limits: (crate::design::lowest_input(d), d.supply.u_max),
            current: f64::NAN,
        })
}

/// Runs `design`'s controller at `sample_period` for `duration` (default: every
/// operation once) on the model of `plant` (default: the design's own); where
/// `[controller] estimator` names one, its observer drives the controller from
/// the voltage and current measured with the noise of `[observer]` (seeded by
/// `seed`).
pub fn run_loop(
    design: &Design,
    plant: Option<&Description>,
    sample_period: f64,
    duration: Option<f64>,
    noise: Noise,
    options: &Options,
) -> Result<LoopRun, LoopError> {
    run_spaced_loop(design, plant, sample_period, duration, None, noise, options)
}

/// The time [s] between two operations' starts in a run-to-run study (and
/// the window a record covers): twice takeoff + landing and a motion time,
/// so that an operation the runtime had to finish ([`reldesign_runtime::control::finish_stroke`])
/// ends before the next one starts.
pub fn operation_window(t: &crate::description::Trajectory) -> f64 {
    // the push comes at 2·t_f − t₀; the window leaves as long again
    2.0 * operation_end(t.takeoff, t.landing) + (t.landing - t.takeoff)
}

/// The spacing of `reldesign loop`'s operations: [SM 45]'s takeoff + landing
/// where the controller reads the position on the description's own plant,
/// and the run-to-run study's window ([`operation_window`]) where a landing
/// later than t_f is to be expected (the controller reads an estimate, or a
/// plant is given): the runtime pushes an armature not at its stop by t_f +
/// the arrival margin, and the operation's window must still hold that push.
pub fn loop_spacing(design: &Design, plant: Option<&Description>) -> Option<f64> {
    let estimated = (design.description.controller.as_ref()).is_some_and(|c| c.estimator.is_some());
    let other_plant = plant.is_some();
    let t = design.description.trajectory.as_ref()?;
    (estimated || other_plant).then(|| operation_window(t))
}

/// [`run_loop`] with the operations `spacing` [s] apart (default: takeoff +
/// landing, [SM 45]): a run-to-run study leaves a late landing time to end.
pub fn run_spaced_loop(
    design: &Design,
    plant: Option<&Description>,
    sample_period: f64,
    duration: Option<f64>,
    spacing: Option<f64>,
    noise: Noise,
    options: &Options,
) -> Result<LoopRun, LoopError> {
    let (Some(c), Some(t)) = (&design.controller, &design.description.trajectory) else {
        return Err(LoopError::NoController);
    };
    let plant_description = plant.unwrap_or(&design.description);
    let stops = end_stops(plant_description);
    let mut plant_model = Model::build(plant_description);
    check_plant(design, &plant_model)?;
    let model_plant = ModelPlant::new(&mut plant_model);
    let length = spacing.unwrap_or_else(|| operation_end(t.takeoff, t.landing));
    let operations: Vec<(Operation, f64)> = t
        .operations
        .iter()
        .enumerate()
        .map(|(k, &op)| (op, k as f64 * length))
        .collect();
    let mut design_model = design.model.clone();
    let controllers = operations
        .iter()
        .map(|&(op, _)| RuntimePlan::new(&mut design_model, c).controller(op))
        .collect();
    let nonnegative_current = matches!(
        c.law,
        crate::design::LawDesign::SlidingMode {
            nonnegative_current: true,
            ..
        }
    );
    let mut sequencer = Sequencer {
        plan: controllers,
        operations: operations.clone(),
        current: 0,
        sensing: Sensing::new(
            design,
            &model_plant,
            sample_period,
            noise,
            nonnegative_current,
        )?,
        z_ref: Vec::new(),
    };
    let (x0, mode0) = start_state(&mut plant_model, operations.first().map(|o| o.0));
    let t_end = duration.unwrap_or(length * operations.len() as f64);
    let mut control = |_t: f64, m: &Measurement| sequencer.control(m);
    let trajectory = simulate_sampled(
        &model_plant,
        &mut control,
        sample_period,
        t_end,
        x0,
        mode0,
        options,
    )?;
    let (current, z_ref, estimates) =
        (sequencer.sensing).record(&trajectory, &sequencer.z_ref, f64::NAN);
    let flagged_late = sequencer.plan.iter().map(|c| c.finished_late()).collect();
    Ok(LoopRun {
        trajectory,
        current,
        z_ref,
        operations,
        operation_length: length,
        estimates,
        stops,
        measured: sequencer.sensing.take_measured(),
        flagged_late,
    })
}

/// The name of a law that positions the armature rather than landing it
/// (backstepping, the model-based sliding mode's hold), if `description`'s is one.
fn design_positions(description: &Description) -> Option<&'static str> {
    use crate::description::Law;
    match description.controller.as_ref()?.law {
        Law::Backstepping(_) => Some("law = \"backstepping\""),
        Law::ModelSlidingMode(m) if m.position.is_some() => {
            Some("law = \"model-sliding-mode\" with controller.position")
        }
        _ => None,
    }
}

/// Default length of a position-hold loop [s].
pub const HOLD_DURATION: f64 = 40e-3;

/// Runs `design`'s position hold ([JA §6.3]) at `sample_period` for
/// `duration` (default [`HOLD_DURATION`]) on the model of `plant` (default:
/// the design's own), from rest at z_max without flux and with the core's
/// field at `initial_field` [A/m] (a Jiles–Atherton plant; the paper starts
/// at 250 A/m); the observer of `[controller] estimator`, where named,
/// drives it from the measured voltage and current (noise seeded by `seed`),
/// starting from its own initial guess [z_max, z_max, 0, 0].
pub fn run_hold(
    design: &Design,
    plant: Option<&Description>,
    sample_period: f64,
    duration: Option<f64>,
    noise: Noise,
    initial_field: f64,
    options: &Options,
) -> Result<LoopRun, LoopError> {
    let Some(h) = &design.hold else {
        return Err(LoopError::NoController);
    };
    let plant_description = plant.unwrap_or(&design.description);
    let mut plant_model = Model::build(plant_description);
    check_plant(design, &plant_model)?;
    let model_plant = ModelPlant::new(&mut plant_model);
    let mut design_model = design.model.clone();
    let hold = RuntimeHold::new(&mut design_model, h).controller();
    let mut sensing = Sensing::new(design, &model_plant, sample_period, noise, false)?;
    let mut z_ref = Vec::new();
    let mut control = |_t: f64, m: &Measurement| {
        let ([z, v, phi, hc], _) = sensing.read(m);
        z_ref.push((m.t, h.position));
        let u = hold.step(z, v, phi, hc);
        sensing.apply(u)
    };
    let (mut x0, mode0) = start_state(&mut plant_model, None);
    if plant_model.dim() == 4 {
        x0[3] = initial_field;
    }
    let t_end = duration.unwrap_or(HOLD_DURATION);
    let trajectory = simulate_sampled(
        &model_plant,
        &mut control,
        sample_period,
        t_end,
        x0,
        mode0,
        options,
    )?;
    let (current, z_ref, estimates) = sensing.record(&trajectory, &z_ref, h.position);
    Ok(LoopRun {
        trajectory,
        current,
        z_ref,
        operations: Vec::new(),
        operation_length: t_end,
        estimates,
        stops: end_stops(plant_description),
        measured: sensing.take_measured(),
        flagged_late: Vec::new(),
    })
}

/// What a position hold did ([JA §6.3], the paper's Fig. 10).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoldOutcome {
    /// The first time [s] after which the error z − z_ref, averaged over
    /// [`SETTLING_WINDOW`], stays within [`SETTLED_FRACTION`] of the initial
    /// error (a noisy loop ripples about the position: the average settles);
    /// `None`: never within the run.
    pub settling_time: Option<f64>,
    /// Mean of z − z_ref over the run's last fifth [m].
    pub steady_error: f64,
    /// The largest |z − z_ref| over the last fifth [m]: the ripple.
    pub steady_band: f64,
    /// Where an observer drives the hold: its errors, see [`ObserverErrors`].
    pub observer: Option<ObserverErrors>,
}

/// The observer's errors in a hold: the largest |ẑ − z| [m] and |Ĥ_c − H_c|
/// [A/m] before settling (the transient), and their RMS over the last fifth
/// (the steady state).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObserverErrors {
    pub transient_z: f64,
    pub transient_hc: Option<f64>,
    pub steady_z: f64,
    pub steady_hc: Option<f64>,
}

/// Settled: the averaged error within this fraction of the initial error.
pub const SETTLED_FRACTION: f64 = 0.05;
/// The averaging window of the settling criterion [s].
pub const SETTLING_WINDOW: f64 = 1e-3;

impl LoopRun {
    /// The hold's figures.
    pub fn hold_outcome(&self) -> HoldOutcome {
        let tr = &self.trajectory;
        let n = tr.t.len();
        let error: Vec<f64> = (0..n).map(|k| tr.x[k][0] - self.z_ref[k]).collect();
        let initial = error.first().map_or(0.0, |e| e.abs());
        let settled_from = settled_from(&tr.t, &error, SETTLED_FRACTION * initial);
        let tail = n - n / 5;
        let tail_len = (n - tail).max(1) as f64;
        let steady_error = error[tail..].iter().sum::<f64>() / tail_len;
        let steady_band = error[tail..].iter().fold(0.0, |m: f64, e| m.max(e.abs()));
        let observer = self.estimates.as_ref().map(|e| {
            let transient_end = settled_from.unwrap_or(n);
            let z_err = |k: usize| e[k].z - tr.x[k][0];
            let hc_err = |k: usize| e[k].hc.map(|h| h - tr.x[k][3]);
            let finite_max = |it: &mut dyn Iterator<Item = f64>| {
                it.filter(|x| x.is_finite())
                    .fold(0.0, |a: f64, b| a.max(b.abs()))
            };
            let rms = |it: &mut dyn Iterator<Item = f64>| {
                let v: Vec<f64> = it.filter(|x| x.is_finite()).collect();
                (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
            };
            let has_field = e.iter().any(|x| x.hc.is_some());
            ObserverErrors {
                transient_z: finite_max(&mut (0..transient_end).map(z_err)),
                transient_hc: has_field
                    .then(|| finite_max(&mut (0..transient_end).filter_map(hc_err))),
                steady_z: rms(&mut (tail..n).map(z_err)),
                steady_hc: has_field.then(|| rms(&mut (tail..n).filter_map(hc_err))),
            }
        });
        HoldOutcome {
            settling_time: settled_from.map(|k| tr.t[k]),
            steady_error,
            steady_band,
            observer,
        }
    }
}

/// The first sample from which the [`SETTLING_WINDOW`] average of `error`
/// (trailing) stays within `band`.
fn settled_from(t: &[f64], error: &[f64], band: f64) -> Option<usize> {
    let n = error.len();
    let mut averaged = vec![f64::NAN; n];
    let (mut sum, mut start) = (0.0, 0);
    for k in 0..n {
        sum += error[k];
        while t[k] - t[start] > SETTLING_WINDOW {
            sum -= error[start];
            start += 1;
        }
        averaged[k] = sum / (k + 1 - start) as f64;
    }
    let outside = averaged.iter().rposition(|a| a.is_nan() || a.abs() > band);
    match outside {
        None => Some(0),
        Some(k) if k + 1 < n => Some(k + 1),
        Some(_) => None,
    }
}

/// A plant the design's controller can read: the state of the plant feeds
/// the law where no observer does, and a law on a Jiles–Atherton design
/// reads H_c, which only a Jiles–Atherton plant has. (A reluctance design on
/// a Jiles–Atherton plant is the mismatch study of the sensorless loops.)
pub(crate) fn check_plant(design: &Design, plant: &Model) -> Result<(), LoopError> {
    let observed = (design.description.controller.as_ref()).is_some_and(|c| c.estimator.is_some());
    if design.model.dim() > plant.dim() && !observed {
        return Err(LoopError::PlantMismatch {
            plant: plant.dim(),
            design: design.model.dim(),
        });
    }
    Ok(())
}

/// The value recorded at or last before each output time (both in time
/// order), `before` ahead of the first record: one walk, not a search per time.
fn at_samples<T: Copy>(times: &[f64], records: &[(f64, T)], before: T) -> Vec<T> {
    let mut k = 0;
    let mut value = before;
    times
        .iter()
        .map(|&t| {
            while let Some(&(tr, v)) = records.get(k) {
                if tr > t {
                    break;
                }
                value = v;
                k += 1;
            }
            value
        })
        .collect()
}

/// Before the first sample.
const NO_ESTIMATE: Estimate = Estimate {
    z: f64::NAN,
    v: f64::NAN,
    a: f64::NAN,
    phi: f64::NAN,
    hc: None,
    r: None,
    mode: Mode::Free,
};

/// The observer `[controller] estimator` names, at the loop's sample period.
fn observer(
    design: &Design,
    sample_period: f64,
    noise: Noise,
) -> Result<Option<Observer>, LoopError> {
    let d = &design.description;
    let Some(wanted) = d.controller.as_ref().and_then(|c| c.estimator) else {
        return Ok(None);
    };
    let (Some(o), Some(discrete)) = (&d.observer, &design.kalman) else {
        return Err(LoopError::Observer(
            "controller.estimator needs [observer] with [observer.kalman]".into(),
        ));
    };
    if (o.sample_period - sample_period).abs() > 1e-12 * sample_period {
        return Err(LoopError::Observer(format!(
            "the observer runs every observer.sample_period = {:e} s, the loop every {sample_period:e} s: \
             they must be equal (`sweep` sets both)",
            o.sample_period
        )));
    }
    let filter = match wanted {
        crate::description::Estimator::Ekf => Filter::Ekf(Box::new(Ekf::new(discrete))),
        _ => Filter::Ukf(Box::new(Ukf::new(discrete))),
    };
    Ok(Some(Observer {
        filter,
        noise: SplitMix64::new(noise.seed),
        sigma_v: noise.sigma.map_or(o.voltage_noise, |s| s[0]),
        sigma_i: noise.sigma.map_or(o.current_noise, |s| s[1]),
    }))
}

/// At rest at the first operation's z₀: z_max without flux, or z_min held by
/// 1.2× the flux that balances the passive force there.
fn start_state(model: &mut Model, first: Option<Operation>) -> (State, Mode) {
    let mut x0: State = [0.0; crate::sim::MAX_DIM];
    let (z_min, z_max) = (
        model.description.mechanics.z_min,
        model.description.mechanics.z_max,
    );
    match first {
        Some(Operation::Opening) => {
            let balance = Statics::of(model).drop_out.map_or(0.0, |p| p.flux);
            x0[0] = z_min;
            x0[2] = 1.2 * balance;
            (x0, Mode::StuckMin)
        }
        _ => {
            x0[0] = z_max;
            (x0, Mode::StuckMax)
        }
    }
}

/// What one operation of a loop did, in the figures of the papers' sampling
/// studies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OperationOutcome {
    pub operation: Operation,
    /// The velocity [m/s] of the first impact at the operation's end stop
    /// after its takeoff (signed; 0 where the armature arrives at rest and
    /// sticks); `None`: it never got there in time.
    pub impact_velocity: Option<f64>,
    /// perfect-tracking-soft-landing [PT 69] (with the errata's square root):
    /// the RMS of z − z_r over the samples of the motion [t₀, t_f]; `None`
    /// when no sample falls there (a run cut short).
    pub rmse_z: Option<f64>,
    /// The time [s from the operation's start] of the first impact (or
    /// arrival at rest) at the end stop after takeoff; `None` with
    /// `impact_velocity`. Later than t_f + the arrival margin, the runtime
    /// pushed the armature there (the controller's own verdict, from the
    /// position it reads, is [`OperationOutcome::flagged_late`]).
    pub arrival: Option<f64>,
    /// Impacts at the end stop within the operation that bounced.
    pub bounces: usize,
    /// The highest bounce [m]: the largest distance from the end stop, at
    /// the samples, between an impact there that bounced and the next
    /// impact or stick there (or the operation's end); 0 without a bounce.
    pub highest_bounce: f64,
    /// The controller's own verdict ([`LoopRun::flagged_late`]): what the
    /// firmware reports, from the position it reads.
    pub flagged_late: bool,
}

impl OperationOutcome {
    /// The plant's verdict: the armature reached its stop only after
    /// `late_after` ([`late_after`]), i.e. the runtime pushed it there.
    pub fn arrived_late(&self, late_after: f64) -> bool {
        self.arrival.is_some_and(|t| t > late_after)
    }

    /// The plant's and the controller's verdicts, as `loop`'s summaries
    /// state them ("" where it arrived in time, unflagged).
    pub fn verdict(&self, late_after: f64) -> &'static str {
        match (
            self.arrival.is_some(),
            self.arrived_late(late_after),
            self.flagged_late,
        ) {
            (false, _, true) => " (flagged late by the controller)",
            (false, _, false) => " (not flagged late by the controller)",
            (true, true, true) => " (late: pushed to its stop)",
            (true, true, false) => {
                " (late: pushed to its stop; the controller read it there in time)"
            }
            (true, false, true) => {
                " (on time, but the controller read it short and flagged it late)"
            }
            (true, false, false) => "",
        }
    }
}

/// When the runtime pushes an armature not yet at its stop [s from the
/// operation's start]: t_f + the design's arrival margin (∞ without a
/// soft-landing controller).
pub fn late_after(design: &Design) -> f64 {
    (design.controller.as_ref()).map_or(f64::INFINITY, |c| c.landing + c.arrival_margin)
}

impl LoopRun {
    /// The outcome of each operation, with `takeoff` and `landing` of `[trajectory]`.
    pub fn outcomes(&self, takeoff: f64, landing: f64) -> Vec<OperationOutcome> {
        self.operations
            .iter()
            .enumerate()
            .map(|(k, &(operation, start))| {
                let end = start + self.operation_length;
                let (impact_velocity, bounces) =
                    impacts(&self.trajectory, operation, start + takeoff, end);
                let highest_bounce = self.highest_bounce(operation, start + takeoff, end);
                let tr = &self.trajectory;
                let (mut sum, mut n) = (0.0, 0usize);
                for ((t, x), zr) in tr.t.iter().zip(&tr.x).zip(&self.z_ref) {
                    if (start + takeoff..=start + landing).contains(t) {
                        sum += (x[0] - zr).powi(2);
                        n += 1;
                    }
                }
                OperationOutcome {
                    operation,
                    impact_velocity,
                    arrival: first_arrival(&self.trajectory, operation, start + takeoff, end)
                        .map(|t| t - start),
                    rmse_z: (n > 0).then(|| (sum / n as f64).sqrt()),
                    bounces,
                    highest_bounce,
                    flagged_late: self.flagged_late.get(k).copied().unwrap_or(false),
                }
            })
            .collect()
    }

    /// [`OperationOutcome::highest_bounce`] of `operation` within (from, to].
    fn highest_bounce(&self, operation: Operation, from: f64, to: f64) -> f64 {
        let destination = destination(operation);
        let stop = match destination {
            Limit::Min => self.stops[0],
            Limit::Max => self.stops[1],
        };
        highest_bounce(&self.trajectory, destination, stop, from, to)
    }
}

/// The largest |z − `stop`| at the samples of `tr` between an impact at
/// `destination` within (from, to] that bounced and the next event there
/// (impact or stick; else `to`); 0 without a bounce.
fn highest_bounce(tr: &Trajectory, destination: Limit, stop: f64, from: f64, to: f64) -> f64 {
    let at_destination: Vec<(f64, bool)> = tr
        .events
        .iter()
        .filter(|e| e.t > from && e.t <= to)
        .filter_map(|e| match e.kind {
            EventKind::Impact { limit, v_after, .. } if limit == destination => {
                Some((e.t, v_after != 0.0))
            }
            EventKind::Stick { limit } if limit == destination => Some((e.t, false)),
            _ => None,
        })
        .collect();
    let mut highest = 0.0_f64;
    for (k, &(t, bounced)) in at_destination.iter().enumerate() {
        if !bounced {
            continue;
        }
        let next = at_destination.get(k + 1).map_or(to, |&(t, _)| t);
        let (first, last) = (
            tr.t.partition_point(|&s| s <= t),
            tr.t.partition_point(|&s| s < next),
        );
        for x in tr.x.get(first..last).unwrap_or_default() {
            highest = highest.max((x[0] - stop).abs());
        }
    }
    highest
}

/// The end stops [z_min, z_max] of `description`'s armature [m].
pub(crate) fn end_stops(description: &Description) -> [f64; 2] {
    [description.mechanics.z_min, description.mechanics.z_max]
}

/// The end stop `operation` lands on.
fn destination(operation: Operation) -> Limit {
    match operation {
        Operation::Closing => Limit::Min,
        Operation::Opening => Limit::Max,
    }
}

/// The impacts and sticks at `operation`'s end stop in (from, to], in time
/// order.
fn arrivals(
    tr: &Trajectory,
    operation: Operation,
    from: f64,
    to: f64,
) -> impl Iterator<Item = &crate::sim::Event> {
    let destination = destination(operation);
    tr.events.iter().filter(move |e| {
        e.t > from
            && e.t <= to
            && matches!(e.kind, EventKind::Impact { limit, .. } | EventKind::Stick { limit }
                if limit == destination)
    })
}

/// The time of the first impact or stick at `operation`'s end stop in
/// (from, to].
fn first_arrival(tr: &Trajectory, operation: Operation, from: f64, to: f64) -> Option<f64> {
    arrivals(tr, operation, from, to).next().map(|e| e.t)
}

/// The first impact's velocity at `operation`'s end stop in (from, to], and
/// the number of bouncing impacts there.
fn impacts(tr: &Trajectory, operation: Operation, from: f64, to: f64) -> (Option<f64>, usize) {
    let mut first = None;
    let mut bounces = 0;
    for e in arrivals(tr, operation, from, to) {
        match e.kind {
            EventKind::Impact {
                v_before, v_after, ..
            } => {
                first = first.or(Some(v_before));
                bounces += usize::from(v_after != 0.0);
            }
            // arriving at rest: the softest landing there is
            _ => first = first.or(Some(0.0)),
        }
    }
    (first, bounces)
}

/// The uncontrolled switching the papers compare with: u_max over each
/// closing operation, 0 over each opening one, on the plant (default: the
/// description's own), from the loop's start state. The first impact of each
/// within its window; the last window is open-ended (up to
/// `BASELINE_TAIL` operation lengths), since a coil left at 0 V may release
/// long after the motion time the design was given.
pub fn switching_baseline(
    description: &Description,
    plant: Option<&Description>,
    options: &Options,
) -> Result<Vec<(Operation, Option<f64>)>, LoopError> {
    let Some(t) = &description.trajectory else {
        return Err(LoopError::NoController);
    };
    let mut model = Model::build(plant.unwrap_or(description));
    let length = operation_end(t.takeoff, t.landing);
    let u_max = description.supply.u_max;
    let (mut times, mut values) = (Vec::new(), Vec::new());
    for (k, op) in t.operations.iter().enumerate() {
        let u = match op {
            Operation::Closing => u_max,
            Operation::Opening => 0.0,
        };
        times.extend([k as f64 * length, (k + 1) as f64 * length]);
        values.extend([u, u]);
    }
    let input = PiecewiseLinear::new(times, values).map_err(|e| LoopError::Input(e.to_string()))?;
    let (x0, mode0) = start_state(&mut model, t.operations.first().copied());
    let plant = ModelPlant::new(&mut model);
    let n = t.operations.len();
    let end = length * (n as f64 - 1.0 + BASELINE_TAIL);
    let tr = simulate(&plant, &input, x0, mode0, &[0.0, end], options)?;
    Ok(t.operations
        .iter()
        .enumerate()
        .map(|(k, &op)| {
            let start = k as f64 * length;
            let to = if k + 1 == n { end } else { start + length };
            (op, impacts(&tr, op, start, to).0)
        })
        .collect())
}

/// The observer at the sample period `ts`: the process noise per step of
/// `[observer.kalman]` (tuned at the description's period) scaled ∝ T_s, the
/// convention the bundled descriptions were tuned with (a white-noise random
/// walk would scale ∝ √T_s; the filters here are tuned, not identified).
pub fn resample_observer(o: &mut crate::description::Observer, ts: f64) {
    let scale = ts / o.sample_period;
    o.sample_period = ts;
    if let Some(k) = &mut o.kalman {
        k.process_z *= scale;
        k.process_phi *= scale;
        k.process_hc = k.process_hc.map(|q| q * scale);
    }
}

/// A sample period the description's motion allows (the parser's rule for
/// `controller.sample_period`, [`Trajectory::longest_sample_period`]).
///
/// [`Trajectory::longest_sample_period`]: crate::description::Trajectory::longest_sample_period
pub fn check_sample_period(description: &Description, ts: f64) -> Result<(), LoopError> {
    let Some(t) = &description.trajectory else {
        return Err(LoopError::NoController);
    };
    let limit = t.longest_sample_period();
    if ts.is_finite() && ts > 0.0 && ts <= limit {
        Ok(())
    } else {
        Err(LoopError::Design {
            sample_period: ts,
            message: format!(
                "a sample period must be > 0 and at most (trajectory.landing − trajectory.takeoff)/10 \
                 = {limit:e} s: the motion must span at least 10 samples"
            ),
        })
    }
}

/// The last operation of the switching baseline runs for this many operation
/// lengths.
const BASELINE_TAIL: f64 = 10.0;

/// One row of a sampling-period sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRow {
    pub sample_period: f64,
    pub outcomes: Vec<OperationOutcome>,
}

/// The description's design redone at each sample period (controller, and
/// the observer's period with it, its process noise per step ∝ T_s), each in
/// closed loop on the plant; rows in the order of `periods` (run in parallel
/// with the `parallel` feature).
pub fn sweep(
    description: &Description,
    plant: Option<&Description>,
    periods: &[f64],
    options: &Options,
) -> Result<Vec<SweepRow>, LoopError> {
    if let Some(law) = design_positions(description) {
        return Err(LoopError::Positions(law));
    }
    let Some(t) = &description.trajectory else {
        return Err(LoopError::NoController);
    };
    for &ts in periods {
        check_sample_period(description, ts)?;
    }
    let rows: Vec<Result<SweepRow, LoopError>> = crate::parallel::map(periods, |&ts| {
        let mut d = description.clone();
        if let Some(c) = &mut d.controller {
            c.sample_period = ts;
        }
        if let Some(o) = &mut d.observer {
            resample_observer(o, ts);
        }
        let design = Design::new(&d).map_err(|e| LoopError::Design {
            sample_period: ts,
            message: e.to_string(),
        })?;
        let run = run_loop(&design, plant, ts, None, Noise::seeded(0), options)?;
        Ok(SweepRow {
            sample_period: ts,
            outcomes: run.outcomes(t.takeoff, t.landing),
        })
    });
    // the first failing period in the order given, whatever the threads did
    rows.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::Event;

    /// The height counts from a bouncing impact to the next event at the
    /// stop: not before it, not after a stick (a lift-off and a drift then
    /// are no bounce), not for an impact at the other stop or outside the
    /// window.
    #[test]
    fn the_highest_bounce_is_measured_between_a_bounce_and_the_next_event_at_the_stop() {
        let impact = |t, limit, v_after| Event {
            t,
            kind: EventKind::Impact {
                limit,
                v_before: -0.01,
                v_after,
                zeno: false,
            },
            mode_after: Mode::Free,
        };
        let stop = 1e-4;
        // z − stop at t = 0, 1, …, 9: the approach, a bounce of 7 µm
        // (impact at 2.5, stick at 5.5), then a lift-off and a 50 µm drift
        let heights = [
            90e-6, 40e-6, 0.0, 3e-6, 7e-6, 2e-6, 0.0, 20e-6, 50e-6, 60e-6,
        ];
        let tr = Trajectory {
            t: (0..10).map(f64::from).collect(),
            x: heights.iter().map(|h| [stop + h, 0.0, 0.0, 0.0]).collect(),
            events: vec![
                impact(2.5, Limit::Min, 0.005),
                Event {
                    t: 5.5,
                    kind: EventKind::Stick { limit: Limit::Min },
                    mode_after: Mode::StuckMin,
                },
                impact(8.5, Limit::Max, 0.005),
            ],
            ..Trajectory::default()
        };
        let close = |a: f64, b: f64| (a - b).abs() < 1e-15;
        assert!(close(highest_bounce(&tr, Limit::Min, stop, 0.0, 9.0), 7e-6));
        // outside the window, and at the other stop: none
        assert_eq!(highest_bounce(&tr, Limit::Min, stop, 3.0, 9.0), 0.0);
        assert_eq!(highest_bounce(&tr, Limit::Max, stop, 0.0, 8.0), 0.0);
        // a bounce that never comes back counts up to the window's end
        let mut tr = tr;
        tr.events.remove(1);
        assert!(close(
            highest_bounce(&tr, Limit::Min, stop, 0.0, 7.5),
            20e-6
        ));
    }

    fn trajectory(events: Vec<Event>) -> Trajectory {
        Trajectory {
            events,
            ..Trajectory::default()
        }
    }

    /// Arriving at the stop at rest (a stick, no impact) is a landing at
    /// 0 m/s, not "never"; impacts elsewhere or outside the window do not count.
    #[test]
    fn a_stick_at_the_destination_is_a_landing_at_rest() {
        let stick = |t, limit| Event {
            t,
            kind: EventKind::Stick { limit },
            mode_after: Mode::StuckMin,
        };
        let impact = |t, limit, v_before, v_after| Event {
            t,
            kind: EventKind::Impact {
                limit,
                v_before,
                v_after,
                zeno: false,
            },
            mode_after: Mode::Free,
        };
        let tr = trajectory(vec![stick(2e-3, Limit::Min)]);
        assert_eq!(impacts(&tr, Operation::Closing, 1e-3, 6e-3), (Some(0.0), 0));
        assert_eq!(impacts(&tr, Operation::Opening, 1e-3, 6e-3), (None, 0));
        let tr = trajectory(vec![
            impact(0.5e-3, Limit::Min, -1.0, 0.3),
            impact(2e-3, Limit::Min, -0.02, 0.006),
            stick(2.1e-3, Limit::Min),
        ]);
        assert_eq!(
            impacts(&tr, Operation::Closing, 1e-3, 6e-3),
            (Some(-0.02), 1)
        );
    }
}
