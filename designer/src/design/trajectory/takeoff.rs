//! The shortest pre-movement stage the supply allows, and what a shorter
//! one costs the tracking.
//!
//! Every soft-landing reference rests at z₀ until t₀ (`trajectory.takeoff`)
//! and assumes the flux has reached takeoff by the instant it starts to move
//! (t₀, or later where an energy-optimal motion rests first: its arc's start).
//! Whether it can depends on the coil: strong eddy currents or a large
//! inductance need longer than the design's pre-movement stage to build (or
//! drain) the flux even at full supply. The model is driven at the supply's
//! limit from the rest the operation starts at, and the instant its armature
//! would leave the stop is the shortest takeoff t_s:
//!
//! - closing, from z_max without flux, at u_max;
//! - opening, at the lowest input, from the hold the design's own cycle
//!   leaves: landed at rest on z_min with the forces balanced (the
//!   reference's end), then held for t₀ at u_max (the expert rule on
//!   contact [SM 43] from t_f until the operation ends at t_f + t₀ [SM 45],
//!   `operation_end`, where the next one starts). A longer hold builds more
//!   flux, up to the steady flux at u_max, and needs a longer stage than
//!   this: that is outside the timing the design is made for, and not
//!   checked (the 12 V relay would need 3.54 ms from there).
//!
//! No input does better: until lift-off the armature is stuck, and where the
//! flux is the only electrical state (saturating and eddy-current coils) it
//! obeys a first-order equation whose rate grows with the input, so by
//! comparison the flux driven at the limit is above (closing) or below
//! (opening) any other input's at every instant, and lift-off is the first
//! instant its force overcomes the stop's. (With a hysteretic core's H_c as
//! a fourth state this is the natural candidate, not a proven minimum.)
//!
//! # When is a takeoff "too short"?
//!
//! Not simply when t_s exceeds the planned lift-off t_p. The controller's
//! pre-movement stage is a closed loop (the tracking law towards ξ_r = [z₀,
//! 0, 0]) that only approaches the takeoff flux, so t_p is not met to the
//! microsecond even with time to spare (the perfect-tracking valve's nominal
//! loop, 0.17 ms ahead, lifts off 1 µs after t₀). And every motion starts
//! from rest with zero acceleration, so a lift-off late by δ leaves velocity
//! and acceleration errors that grow from zero (as δ² and δ for the
//! polynomial, likewise for the energy-optimal arc). What a late
//! lift-off does is start the motion with a tracking error: on [t_p, t_s]
//! the armature is necessarily at rest on its stop, so its velocity and
//! acceleration errors are at least |v_r| and |a_r| there. The design
//! already states which errors its law is assumed to keep: the robustness
//! analysis's bounds [SM 52], |ṽ| ≤ 20 % max|v_r| and |ã| ≤ 20 % max|a_r|
//! (`ErrorBounds::default`, the paper's conservative choice, the bounds the
//! sliding mode's supply check [SM 49–50] certifies). So:
//!
//! - t_s ≤ t_p: in time;
//! - t_s > t_p with max|v_r| and max|a_r| over [t_p, t_s] within those
//!   bounds: late, but inside the errors the design assumes: a warning in
//!   the report, not a refusal (the 12 V relay of `tests/data/relay-12v.toml`
//!   needs 1.0143 ms of its 1 ms: by then its closing reference has 0.01 %
//!   of its top speed and 3 % of its largest acceleration, and its closed
//!   loop, `closed_loop::run_loop` at 10 µs, lands at 13 µm/s);
//! - beyond them: refused, with t_s and the key to change. A lift-off at or
//!   after t_f (the device needing 22 ms of a 4 ms stage) is 100 %
//!   of both whatever the reference, and is refused before the reference is
//!   designed.
//!
//! The rule asks nothing of the sample period or of a tuned percentage: the
//! bounds are the ones the robustness analysis already uses (and, on the
//! safe side, tighter than what the nominal loop survives: the
//! perfect-tracking valve at t₀ = 0.5 ms, 27 % of max|a_r|, is refused
//! though its nominal loop still lands at 0.4 mm/s; the relay at
//! t₀ = 0.2 ms, 97 %, bounces twice). It bounds errors the supply forces,
//! it does not guarantee a landing: `reldesign loop` simulates that.

use crate::description::{Description, Operation};
use crate::model::{Model, ModelPlant, Statics};
use crate::sim::{simulate, EventKind, Mode, Options, PiecewiseLinear, MAX_DIM};

use super::reference::Reference;

/// How many times t_f (`trajectory.landing`) the model is driven looking for
/// the lift-off: beyond that the answer is "longer than this".
const HORIZON: f64 = 50.0;

/// Reference samples over the motion and over [t_p, t_s] for the maxima.
const SAMPLES: usize = 2000;

/// The shortest takeoff of `operation`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shortest {
    /// The armature leaves its stop this long [s] after the supply's limit is applied.
    After(f64),
    /// Not within `horizon` [s].
    Longer(f64),
}

impl Shortest {
    /// The shortest takeoff [s], or the horizon it is longer than.
    pub fn at_least(self) -> f64 {
        match self {
            Shortest::After(t) | Shortest::Longer(t) => t,
        }
    }

    /// "after 1.0143 ms", "after more than 550.0 ms".
    pub fn text(self) -> String {
        match self {
            Shortest::After(t) => format!("after {:.4} ms", t * 1e3),
            Shortest::Longer(h) => format!("after more than {:.1} ms", h * 1e3),
        }
    }
}

/// The shortest pre-movement stage of `operation` on `model`, driven at
/// `input` [V or A] from its starting rest (module docs; the opening's after
/// the hold at `hold_input` the design's cycle gives it, `timing` = (t₀,
/// t_f) [s], t_f also sizing the horizon). Simulated on a copy of `model`:
/// compiling a plant adds to the model's expression graph, which the
/// design's later derivations would then evaluate in another order, and the
/// emitted tables must keep their bits.
pub fn shortest_takeoff(
    description: &Description,
    model: &Model,
    operation: Operation,
    input: f64,
    hold_input: f64,
    (takeoff, landing): (f64, f64),
) -> Result<Shortest, String> {
    let mut model = model.clone();
    let model = &mut model;
    let m = &description.mechanics;
    let mut x0 = [0.0; MAX_DIM];
    let balance = match operation {
        Operation::Closing => None,
        Operation::Opening => Some(Statics::of(model).drop_out.map_or(0.0, |p| p.flux)),
    };
    let plant = ModelPlant::new(model);
    let constant = |u: f64, end: f64| {
        PiecewiseLinear::new(vec![0.0, end], vec![u, u]).map_err(|e| e.to_string())
    };
    let mode = match balance {
        None => {
            x0[0] = m.z_max;
            Mode::StuckMax
        }
        Some(flux) => {
            // landed at rest (the reference's end, forces balanced), then
            // held at hold_input for t₀ [SM 45]
            x0[0] = m.z_min;
            x0[2] = flux;
            let held = simulate(
                &plant,
                &constant(hold_input, takeoff)?,
                x0,
                Mode::StuckMin,
                &[0.0, takeoff],
                &Options::default(),
            )
            .map_err(|e| e.to_string())?;
            let (Some(x), Some(&mode)) = (held.x.last(), held.mode.last()) else {
                return Err("the hold before the opening has no state".to_string());
            };
            x0 = *x;
            mode
        }
    };
    let horizon = HORIZON * landing;
    let trajectory = simulate(
        &plant,
        &constant(input, horizon)?,
        x0,
        mode,
        &[0.0, horizon],
        &Options::default(),
    )
    .map_err(|e| e.to_string())?;
    Ok(trajectory
        .events
        .iter()
        .find_map(|e| matches!(e.kind, EventKind::LiftOff { .. }).then_some(e.t))
        .map_or(Shortest::Longer(horizon), Shortest::After))
}

/// One operation's takeoff against its reference (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Takeoff {
    /// The supply key that sets `input`: "u_max" (closing) or "u_min".
    pub key: &'static str,
    /// The input the model was driven at [V or A].
    pub input: f64,
    pub shortest: Shortest,
    /// t₀ [s]: `trajectory.takeoff`.
    pub t0: f64,
    /// t_p [s]: where the reference starts to move, t₀ or an energy-optimal
    /// arc's later start.
    pub planned: f64,
    /// max |v_r| and max |a_r| over [t_p, t_s] (over the whole motion where
    /// t_s is past it), as fractions of their maxima over the motion: the
    /// velocity and acceleration errors a lift-off at t_s starts with; 0 in
    /// time.
    pub velocity_error: f64,
    pub acceleration_error: f64,
    /// The bounds they are held to, as fractions ([SM 52]).
    pub bounds: (f64, f64),
}

/// The verdict of [`Takeoff`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// t_s ≤ t_p.
    InTime,
    /// t_s > t_p, the errors within the bounds: reported, not refused.
    Late,
    /// The errors beyond the bounds: refused.
    TooShort,
}

impl Takeoff {
    /// Compares `shortest` with `reference` on its motion [t₀, t_f], planned
    /// to lift off at `planned`, against the error bounds `bounds` =
    /// (velocity, acceleration) as fractions of max|v_r| and max|a_r|.
    pub fn assess(
        key: &'static str,
        input: f64,
        shortest: Shortest,
        reference: &dyn Reference,
        planned: f64,
        bounds: (f64, f64),
    ) -> Takeoff {
        let (t0, tf) = reference.motion();
        let t_s = shortest.at_least();
        let (velocity_error, acceleration_error) = if t_s <= planned {
            (0.0, 0.0)
        } else if t_s >= tf {
            (1.0, 1.0)
        } else {
            let late = maxima(reference, planned, t_s);
            let whole = maxima(reference, t0, tf);
            let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
            (ratio(late.0, whole.0), ratio(late.1, whole.1))
        };
        Takeoff {
            key,
            input,
            shortest,
            t0,
            planned,
            velocity_error,
            acceleration_error,
            bounds,
        }
    }

    /// In time, late within the bounds, or too short (module docs).
    pub fn verdict(&self) -> Verdict {
        if matches!(self.shortest, Shortest::After(t) if t <= self.planned) {
            Verdict::InTime
        } else if matches!(self.shortest, Shortest::After(_))
            && self.velocity_error <= self.bounds.0
            && self.acceleration_error <= self.bounds.1
        {
            Verdict::Late
        } else {
            Verdict::TooShort
        }
    }

    /// The report's line: "takeoff: needs X ms at the supply limit, has Y ms
    /// (…)", Y the planned lift-off t_p.
    pub fn report_line(&self) -> String {
        let needs = match self.shortest {
            Shortest::After(t) => format!("{:.4} ms", t * 1e3),
            Shortest::Longer(h) => format!("more than {:.1} ms", h * 1e3),
        };
        let rest = if self.planned > self.t0 {
            format!(
                "; the motion rests from trajectory.takeoff = {:.4} ms until then",
                self.t0 * 1e3
            )
        } else {
            String::new()
        };
        format!(
            "takeoff: needs {needs} at the supply limit, has {:.4} ms (supply.{} = {}{rest})",
            self.planned * 1e3,
            self.key,
            self.input,
        )
    }

    /// The report's warning where the takeoff is late but within the bounds.
    pub fn warning(&self) -> Option<String> {
        (self.verdict() == Verdict::Late).then(|| {
            format!(
                "warning: the armature can leave its stop only {:.4} ms after the reference \
                 starts to move: it starts with velocity and acceleration errors of {:.2} % of \
                 max|v_r| and {:.2} % of max|a_r|, within the bounds the design assumes \
                 [SM 52] ({:.0} % and {:.0} %), so not refused; a trajectory.takeoff ≥ {:.4} ms \
                 (trajectory.landing moved with it) removes them",
                (self.shortest.at_least() - self.planned) * 1e3,
                self.velocity_error * 1e2,
                self.acceleration_error * 1e2,
                self.bounds.0 * 1e2,
                self.bounds.1 * 1e2,
                self.shortest.at_least() * 1e3,
            )
        })
    }
}

/// max |v_r| and max |a_r| of `reference` on [a, b] (b included).
fn maxima(reference: &dyn Reference, a: f64, b: f64) -> (f64, f64) {
    (0..=SAMPLES)
        .map(|k| reference.at(a + (b - a) * k as f64 / SAMPLES as f64))
        .fold((0.0_f64, 0.0_f64), |(v, acc), f| {
            (v.max(f.v.abs()), acc.max(f.a.abs()))
        })
}
