//! The rules between sections, checked once both sides are read: the gap
//! over the stroke, the drive against the coil, the trajectory's input
//! against the supply, the controller against its trajectory and core, and
//! the controller's estimator against `[observer]`; and one warning: the
//! tracking law's steady error where the spring differs from the description.

use super::sect::{Res, Sect};
use crate::description::{
    settling_time_within, BacksteppingKeys, Gains, Law, ModelSurface, Operation, SetPoint, Shape,
    Supply, Trajectory,
};
use crate::description::{Coil, Controller, Core, Drive, Estimator, Gap, Mechanics, Observer};

/// Grid size of the fringing-denominator check on (0, z_max].
const DENOMINATOR_GRID: usize = 1000;

/// R_gap(z) is defined and positive on the stroke: a fringing denominator
/// stays > 0, a table covers [z_min, z_max].
pub(super) fn check_gap_range(s: &Sect, gap: &Gap, m: &Mechanics) -> Res<()> {
    match gap {
        Gap::Linear { .. } => Ok(()),
        Gap::McLyman {
            area,
            winding_length,
        } => {
            let sqrt_a = area.sqrt();
            let f = |z: f64| 1.0 + z / sqrt_a * (2.0 * winding_length / z).ln();
            check_denominator(s, "winding_length", "1 + z/√A·ln(2·l_w/z)", m.z_max, f)
        }
        Gap::McLymanFit { k1, k2, .. } => {
            let f = |z: f64| 1.0 + k1 * z * (k2 / z).ln();
            check_denominator(s, "k2", "1 + k1·z·ln(k2/z)", m.z_max, f)
        }
        Gap::Table { z, .. } => check_coverage(s, z, m),
    }
}

/// The fringing denominator must stay > 0 on (0, z_max]. It is concave in z
/// with limit 1 at 0⁺, so a uniform grid that ends at z_max finds any failure.
fn check_denominator(
    s: &Sect,
    key: &str,
    formula: &str,
    z_max: f64,
    f: impl Fn(f64) -> f64,
) -> Res<()> {
    for k in 1..=DENOMINATOR_GRID {
        let z = z_max * k as f64 / DENOMINATOR_GRID as f64;
        let d = f(z);
        if d.is_nan() || d <= 0.0 {
            let msg = format!(
                "the gap denominator {formula} must stay > 0 on (0, z_max = {z_max:e} m], \
                 but it is {d:.4} at z = {z:.4e} m (R_gap would be singular or negative)"
            );
            return Err(s.err(key, msg, "makes the gap denominator <= 0"));
        }
    }
    Ok(())
}

/// A gap table spans [z_min, z_max].
fn check_coverage(s: &Sect, z: &[f64], m: &Mechanics) -> Res<()> {
    let last = z.len() - 1;
    if z[0] > m.z_min {
        let msg = format!(
            "expected a number <= z_min = {} [m] (the table must cover [z_min, z_max]), found {}",
            m.z_min, z[0]
        );
        return Err(s.elem_err("z", 0, msg, "table starts above z_min"));
    }
    if z[last] < m.z_max {
        let msg = format!(
            "expected a number >= z_max = {} [m] (the table must cover [z_min, z_max]), found {}",
            m.z_max, z[last]
        );
        return Err(s.elem_err("z", last, msg, "table ends below z_max"));
    }
    Ok(())
}

/// A current drive needs the flux as a state, i.e. eddy currents.
pub(super) fn check_drive(s: &Sect, supply: &Supply, coil: &Coil) -> Res<()> {
    if supply.drive == Drive::Current && coil.eddy <= 0.0 {
        let msg = "drive \"current\" requires coil.eddy > 0: with k_e = 0 the flux is an \
                   algebraic function of the current, not a state, so a current-driven model \
                   has no flux dynamics; use drive = \"voltage\" or give coil.eddy > 0";
        return Err(s.err("drive", msg, "needs coil.eddy > 0"));
    }
    Ok(())
}

/// The trajectory is designed with inputs in [max(u_min, −u_bound), u_bound]:
/// that interval must lie within the supply and contain positive inputs
/// (closing needs them), i.e. max(0, u_min) < u_bound ≤ u_max.
pub(super) fn check_u_bound(s: &Sect, u_bound: f64, supply: &Supply, unit: &str) -> Res<()> {
    let (u_min, u_max) = (supply.u_min, supply.u_max);
    let lower = u_min.max(0.0);
    if u_bound > lower && u_bound <= u_max {
        return Ok(());
    }
    let found = s.found("u_bound", u_bound);
    let design = "the trajectory is designed with inputs in [max(u_min, -u_bound), u_bound], \
                  which must lie within the supply and include positive inputs (closing needs \
                  them)";
    let msg = if u_max <= 0.0 {
        format!(
            "found {found}, but no u_bound can work: supply.u_max = {u_max} gives no positive \
             input; {design}"
        )
    } else if u_bound > u_max {
        format!(
            "expected a number in ({lower}, supply.u_max = {u_max}] [{unit}], found {found}: \
             it exceeds supply.u_max; {design}, leaving the rest to the feedback"
        )
    } else {
        format!(
            "expected a number in (supply.u_min = {u_min}, {u_max}] [{unit}], found {found}: \
             with u_bound <= supply.u_min no input is left to design with; {design}"
        )
    };
    Err(s.err("u_bound", msg, "outside the supply"))
}

/// A trajectory on the Jiles–Atherton core is a polynomial: the
/// energy-optimal design (Pontryagin) needs a costate for H_c, whose branch
/// sign(dφ/dt) depends on the input.
pub(super) fn check_trajectory_core(
    trajectory_sect: &Sect,
    trajectory: &Trajectory,
    core: &Core,
) -> Res<()> {
    if let (Core::JilesAtherton(_), Shape::EnergyOptimal) = (core, trajectory.shape) {
        let msg = "the energy-optimal trajectory (Pontryagin) needs a costate for every \
                   state, and the \"jiles-atherton\" core's field H_c switches branch with \
                   sign(dφ/dt), which depends on the input, so the Hamiltonian is not \
                   differentiable there; use shape = \"polynomial\" (tracked through H_c by \
                   the controller), or design the energy-optimal reference on a \"saturating\" \
                   core fitted to the same valve";
        return Err(trajectory_sect.err("shape", msg, "not with a hysteretic core"));
    }
    Ok(())
}

/// `contact_uncertainty` (σ of the stops' positions) only with the
/// energy-optimal shape (the probability-based design is a Pontryagin
/// problem), and at most a tenth of the stroke: 3σ of the half-normal, where
/// 99.7 % of the stops lie, within a third of it.
pub(super) fn check_contact_uncertainty(
    trajectory_sect: &Sect,
    trajectory: &Trajectory,
    mechanics: &Mechanics,
) -> Res<()> {
    let sigma = trajectory.contact_uncertainty;
    if sigma <= 0.0 {
        return Ok(());
    }
    let key = "contact_uncertainty";
    let found = trajectory_sect.found(key, sigma);
    if trajectory.shape != Shape::EnergyOptimal {
        let msg = format!(
            "found {found} [m] with shape = \"polynomial\": the probability-based reference \
             (the expected contact speed over the stop's distribution) is an energy-optimal \
             design; set shape = \"energy-optimal\", or contact_uncertainty = 0"
        );
        return Err(trajectory_sect.err(key, msg, "needs the energy-optimal shape"));
    }
    let stroke = mechanics.z_max - mechanics.z_min;
    let most = 0.1 * stroke;
    if sigma > most {
        let msg = format!(
            "expected a number in [0, {most:e}] [m] (a tenth of the stroke \
             mechanics.z_max − mechanics.z_min = {stroke:e} m), found {found}: a stop that \
             uncertain is outside what a soft-landing reference can be designed for"
        );
        return Err(trajectory_sect.err(key, msg, "more than a tenth of the stroke"));
    }
    Ok(())
}

/// `standoff` and `approach_speed` come together; δ is at most a tenth of the
/// stroke, and the approach (5·δ/(4·v_c)) leaves at least half of the motion
/// t_f − t₀ to the move.
pub(super) fn check_approach(
    trajectory_sect: &Sect,
    trajectory: &Trajectory,
    mechanics: &Mechanics,
) -> Res<()> {
    let found = |key: &str, value: f64| trajectory_sect.found(key, value);
    let standoff = trajectory.standoff;
    let Some(speed) = trajectory.approach_speed else {
        if standoff > 0.0 {
            let msg = format!(
                "standoff = {} [m] needs the speed of the approach to the stop: add \
                 approach_speed [m/s] (e.g. 5e-3)",
                found("standoff", standoff)
            );
            return Err(trajectory_sect.err("standoff", msg, "without approach_speed"));
        }
        return Ok(());
    };
    if standoff <= 0.0 {
        let msg = format!(
            "found approach_speed = {} [m/s] without a standoff > 0: the reference lands at \
             rest on the stop; set standoff [m] too, or remove approach_speed",
            found("approach_speed", speed)
        );
        return Err(trajectory_sect.err("approach_speed", msg, "without standoff"));
    }
    if trajectory.contact_uncertainty > 0.0 {
        let msg = format!(
            "found standoff = {} [m] with contact_uncertainty > 0: the two are different answers \
             to an uncertain stop (a bounded approach speed within δ, or the expected contact \
             speed over a distribution); set one of them",
            found("standoff", standoff)
        );
        return Err(trajectory_sect.err("standoff", msg, "with contact_uncertainty"));
    }
    let stroke = mechanics.z_max - mechanics.z_min;
    if standoff > 0.1 * stroke {
        let msg = format!(
            "expected a number in [0, {:e}] [m] (a tenth of the stroke {stroke:e} m), found {}",
            0.1 * stroke,
            found("standoff", standoff)
        );
        return Err(trajectory_sect.err("standoff", msg, "more than a tenth of the stroke"));
    }
    let approach = crate::description::Approach { standoff, speed };
    let motion = trajectory.landing - trajectory.takeoff;
    if approach.duration() > 0.5 * motion {
        let msg = format!(
            "the approach takes 5·standoff/(4·approach_speed) = {:e} s, more than half of the \
             motion trajectory.landing − trajectory.takeoff = {motion:e} s: a faster approach, \
             a smaller standoff or a later landing leaves the move its time",
            approach.duration()
        );
        return Err(trajectory_sect.err("approach_speed", msg, "the approach is too long"));
    }
    Ok(())
}

/// A controller tracks a `[trajectory]` sampled at least 10 times per
/// motion, or (the model-based sliding mode) holds a constant `position`
/// within the stroke.
pub(super) fn check_controller(
    root: &Sect,
    s: &Sect,
    c: &Controller,
    trajectory: Option<&Trajectory>,
    mechanics: &Mechanics,
) -> Res<()> {
    if let Law::ModelSlidingMode(ModelSurface {
        position: Some(z_ref),
        ..
    }) = c.law
    {
        return check_position(root, s, z_ref, trajectory.is_some(), mechanics);
    }
    if let Law::Backstepping(keys) = c.law {
        return check_set_point(root, s, c, &keys, trajectory.is_some(), mechanics);
    }
    let Some(t) = trajectory else {
        let hold = if let Law::ModelSlidingMode(_) = c.law {
            " (or, with this law, controller.position = z_ref to hold a constant position)"
        } else {
            ""
        };
        let msg = format!(
            "section [controller] requires a [trajectory] section: the controller tracks \
             a reference trajectory, so give [trajectory] (operations, takeoff, landing, \
             shape, u_bound){hold}"
        );
        return Err(root.err("controller", msg, "needs [trajectory]"));
    };
    let limit = t.longest_sample_period();
    if c.sample_period > limit {
        let found = s.found("sample_period", c.sample_period);
        let msg = format!(
            "expected a number <= (trajectory.landing - trajectory.takeoff)/10 = {limit:e} [s], \
             found {found}: the motion must span at least 10 sample periods for the sampled \
             controller to track it"
        );
        return Err(s.err("sample_period", msg, "too long for the motion"));
    }
    Ok(())
}

/// `controller.position`: within the stroke, and the one reference.
fn check_position(
    root: &Sect,
    s: &Sect,
    z_ref: f64,
    with_trajectory: bool,
    m: &Mechanics,
) -> Res<()> {
    if with_trajectory {
        let msg = "controller.position holds a constant position, and [trajectory] gives \
                   references to track: give one of them";
        return Err(root.err("trajectory", msg, "conflicts with controller.position"));
    }
    if !(m.z_min..=m.z_max).contains(&z_ref) {
        let found = s.found("position", z_ref);
        let msg = format!(
            "expected a number in [mechanics.z_min, mechanics.z_max] = [{}, {}] [m], found \
             {found}: the armature can only be held within its stroke",
            m.z_min, m.z_max
        );
        return Err(s.err("position", msg, "outside the stroke"));
    }
    if s.entry("creep_speed").is_some() {
        let msg = "controller.creep_speed shapes the reference after a trajectory's landing; \
                   a constant position has none: remove it";
        return Err(s.err("creep_speed", msg, "not with controller.position"));
    }
    Ok(())
}

/// The backstepping law's reference: `position` (as the hold's) or `square`,
/// within the stroke and sampled at least 10 times per half period.
fn check_set_point(
    root: &Sect,
    s: &Sect,
    c: &Controller,
    keys: &BacksteppingKeys,
    with_trajectory: bool,
    m: &Mechanics,
) -> Res<()> {
    let (low, high, period) = match keys.reference {
        SetPoint::Position(z) => return check_position(root, s, z, with_trajectory, m),
        SetPoint::Square { low, high, period } => (low, high, period),
    };
    // the conflicts first, then the range of both positions
    check_position(root, s, low.clamp(m.z_min, m.z_max), with_trajectory, m)?;
    if !(m.z_min..=m.z_max).contains(&low) || !(m.z_min..=m.z_max).contains(&high) {
        let msg = format!(
            "expected z_low and z_high in [mechanics.z_min, mechanics.z_max] = [{}, {}] [m], \
             found [{low}, {high}]: the armature can only be held within its stroke",
            m.z_min, m.z_max
        );
        return Err(s.err("square", msg, "outside the stroke"));
    }
    let limit = period / 20.0;
    if c.sample_period > limit {
        let msg = format!(
            "expected controller.sample_period <= period/20 = {limit:e} [s] for \
             controller.square's period {period:e} s, found {:e}: each half period must span at \
             least 10 samples",
            c.sample_period
        );
        return Err(s.err("sample_period", msg, "too long for the square reference"));
    }
    Ok(())
}

/// The stiffness error the spring warning assumes (the sensorless studies'
/// plants: ±10 % on k_s).
pub const STIFFNESS_ERROR: f64 = 0.1;
/// The steady error, as a fraction of the stroke, above which it warns: on
/// the 30 generated devices of tests/tests/sensorless_devices.rs the
/// perfectly observed loop opened ≥ 10× softer than switching on every
/// device up to 1.8 % and below 10× on 8 of the 11 above 2 % (the others
/// 16×, 10.7× and one whose switching never lands).
pub const STEADY_ERROR_FRACTION: f64 = 0.02;

/// `[controller]` feedback linearization whose gains leave the armature
/// far from its stop at rest where the spring differs from the description
/// by [`STIFFNESS_ERROR`]: the law's model then misses the acceleration by
/// Δk_s·z/m at the stop z, and the gains turn that into a steady position
/// error ((k3 − c/m)/k1)·Δk_s·z/m ([`Gains::steady_position_error`]): short
/// of the stop (a stiffer spring at the opening's z_max) or ahead of the
/// reference into it (a softer one). The creep after t_f has to close the
/// first (and cannot beyond its 5 % of the stroke); above
/// [`STEADY_ERROR_FRACTION`] of the stroke the armature hovers short of the
/// stop or lands hard. On four generated devices of
/// tests/tests/sensorless_devices.rs the formula gives 23–142 µm where the
/// perfectly observed loop stood 21–127 µm short of z_max at t_f on the
/// plant with k_s ×1.1. The other laws are not checked (the model-based
/// sliding mode [JA 89] is [PT 50] with other gains and would be too).
///
/// [`Gains::steady_position_error`]: crate::description::Gains::steady_position_error
pub(super) fn spring_warning(
    s: &Sect,
    c: &Controller,
    trajectory: Option<&Trajectory>,
    m: &Mechanics,
) -> Option<crate::description::DescriptionError> {
    let Law::FeedbackLinearization(gains) = c.law else {
        return None;
    };
    let stroke = m.z_max - m.z_min;
    let damping_rate = m.damping / m.mass;
    let ends = trajectory.map_or(&[Operation::Closing, Operation::Opening][..], |t| {
        &t.operations[..]
    });
    // the stop farthest from the spring's z = 0: the largest force error
    let (stop, name) = ends
        .iter()
        .map(|op| match op {
            Operation::Closing => (m.z_min, "z_min"),
            Operation::Opening => (m.z_max, "z_max"),
        })
        .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))?;
    let acceleration_error = STIFFNESS_ERROR * m.stiffness * stop.abs() / m.mass;
    let error = gains
        .steady_position_error(damping_rate, acceleration_error)
        .abs();
    let bound = STEADY_ERROR_FRACTION * stroke;
    // (a NaN error: no warning)
    if !(error > bound) {
        return None;
    }
    let within = format!("within {} % of the stroke", STEADY_ERROR_FRACTION * 100.0);
    let (key, faster) = match gains {
        Gains::SettlingTime(_) => (
            "settling_time",
            match settling_time_within(bound, damping_rate, acceleration_error) {
                Some(ts) => format!("a settling time ≤ {ts:e} s keeps it {within}"),
                None => format!("no settling time keeps it {within}"),
            },
        ),
        Gains::Poles(_) => ("poles", "faster poles make it smaller".to_string()),
    };
    let msg = format!(
        "a {} % error in mechanics.stiffness leaves the armature about {:.3e} m ({:.1} % of \
         the stroke) from {name} = {stop:e} m at rest: the gains' steady error \
         ((k3 − c/m)/k1)·Δk_s·z/m, derived from [PT 48–50]. Short of the stop, the creep \
         after t_f must close it (up to 5 % of the stroke) or the armature hovers; ahead, \
         it lands harder. {faster}; a faster loop amplifies a sensorless observer's noise \
         (docs/validation/sensorless.md, \"On devices nobody tuned it for\")",
        STIFFNESS_ERROR * 100.0,
        error,
        100.0 * error / stroke,
    );
    Some(s.err(key, msg, "a spring mismatch leaves a steady error"))
}

/// `controller.estimator = "ekf"` on a soft-landing law: accepted (the
/// emitted code has both filters), with the evidence against it.
pub(super) fn estimator_warning(
    s: &Sect,
    c: &Controller,
) -> Option<crate::description::DescriptionError> {
    let holds = matches!(
        c.law,
        Law::ModelSlidingMode(ModelSurface {
            position: Some(_),
            ..
        })
    );
    (c.estimator == Some(Estimator::Ekf) && !holds).then(|| {
        let msg = "the EKF drives a soft-landing loop less reliably than the UKF: on the \
                   mismatched plants of the sensorless study it hovers short of the stop or \
                   bounces more than once in far more runs than the UKF at every sample period \
                   (docs/validation/sensorless.md, tests/tests/sensorless_rates.rs); prefer \
                   estimator = \"ukf\"";
        s.err("estimator", msg, "hovers in the study")
    })
}

/// `compensate_resistance = true` needs a voltage-driven coil and an
/// estimator that estimates R.
pub(super) fn check_compensation(
    s: &Sect,
    c: &Controller,
    observer: Option<&Observer>,
    drive: Drive,
) -> Res<()> {
    const KEY: &str = "compensate_resistance";
    if !c.compensate_resistance {
        return Ok(());
    }
    if drive != Drive::Voltage {
        let msg = "compensate_resistance = true corrects a voltage for the coil resistance; \
                   with supply.drive = \"current\" the law commands the current, which R \
                   does not enter";
        return Err(s.err(KEY, msg, "not a voltage drive"));
    }
    let estimates_r = observer
        .and_then(|o| o.kalman.as_ref())
        .is_some_and(|k| k.resistance.is_some());
    if c.estimator.is_some() && estimates_r {
        return Ok(());
    }
    let msg = "compensate_resistance = true corrects the law's voltage to the estimated coil \
               resistance: it needs controller.estimator (\"ekf\" or \"ukf\") and \
               observer.kalman.estimate_resistance = true";
    Err(s.err(KEY, msg, "no resistance estimate"))
}

/// `controller.estimator` names an observer that `[observer]` designs.
pub(super) fn check_estimator(s: &Sect, c: &Controller, observer: Option<&Observer>) -> Res<()> {
    let Some(wanted) = c.estimator else {
        return Ok(());
    };
    let name = if wanted == Estimator::Ekf {
        "ekf"
    } else {
        "ukf"
    };
    match observer {
        Some(o) if o.estimators.contains(&wanted) => Ok(()),
        Some(_) => {
            let msg = format!(
                "controller.estimator = \"{name}\" needs \"{name}\" in observer.estimators: the \
                 loop runs the observer that [observer] designs"
            );
            Err(s.err("estimator", msg, "not in observer.estimators"))
        }
        None => {
            let msg = format!(
                "controller.estimator = \"{name}\" needs an [observer] section listing \
                 \"{name}\" in estimators (with [observer.kalman])"
            );
            Err(s.err("estimator", msg, "no [observer]"))
        }
    }
}
