//! What to design: `[trajectory]` (the soft-landing references and the input
//! they may use) and `[controller]` with its law, the feedback-linearizing
//! gains [PT 48] or the sliding surface [SM 17], and the float types to emit.

use super::checks::check_u_bound;
use super::physics::input_unit;
use super::sect::{Res, Sect};
use crate::description::schema;
use crate::description::{
    BacksteppingKeys, Controller, Estimator, FloatType, Gains, Law, ModelSurface, Operation,
    SetPoint, Shape, SlidingSurface, Supply, Switching, Trajectory,
};

pub(super) fn parse_trajectory(s: &Sect, supply: &Supply) -> Res<Trajectory> {
    s.check_keys(None, "in [trajectory]")?;
    let operations = s
        .names("operations", "operation", "at least one operation")?
        .ok_or_else(|| {
            s.missing(
                "operations",
                "a non-empty array of \"closing\", \"opening\"",
            )
        })?
        .into_iter()
        .map(|op| match op {
            "closing" => Operation::Closing,
            _ => Operation::Opening,
        })
        .collect();
    let takeoff = s.req("takeoff")?;
    let landing = s.req_above("landing", takeoff)?;
    let shape = match s.choice("shape", "trajectory shape")? {
        "energy-optimal" => Shape::EnergyOptimal,
        _ => Shape::Polynomial,
    };
    let unit = input_unit(supply.drive);
    let u_bound = s.req_in("u_bound", unit)?;
    check_u_bound(s, u_bound, supply, unit)?;
    let contact_uncertainty = s.or_default("contact_uncertainty")?;
    let standoff = s.or_default("standoff")?;
    let approach_speed = s.opt("approach_speed")?;
    Ok(Trajectory {
        operations,
        takeoff,
        landing,
        shape,
        u_bound,
        contact_uncertainty,
        standoff,
        approach_speed,
    })
}

pub(super) fn parse_controller(s: &Sect) -> Res<Controller> {
    if s.entry("law").is_none() {
        // an unknown key is the likelier mistake (`kind = …` for `law = …`)
        s.check_keys_any_variant("in [controller]")?;
    }
    let name = s.choice("law", "control law")?;
    s.check_keys(Some(name), &format!("in [controller] with law \"{name}\""))?;
    let law = match name {
        "feedback-linearization" => Law::FeedbackLinearization(parse_gains(s)?),
        "sliding-mode" => Law::SlidingMode(parse_surface(s)?),
        "backstepping" => Law::Backstepping(parse_backstepping(s)?),
        _ => Law::ModelSlidingMode(ModelSurface {
            p: s.req("p")?,
            k: s.req("k")?,
            position: s.opt("position")?,
        }),
    };
    let sample_period = s.req("sample_period")?;
    let floats = parse_floats(s)?;
    let creep_speed = s.opt("creep_speed")?;
    let landed_band = s.opt("landed_band")?;
    let estimator = s.opt_choice("estimator", "estimator")?.map(|e| match e {
        "ekf" => Estimator::Ekf,
        _ => Estimator::Ukf,
    });
    let compensate_resistance = s.opt_bool("compensate_resistance")?.unwrap_or(false);
    let self_calibration = s.opt_bool("self_calibration")?.unwrap_or(false);
    Ok(Controller {
        law,
        sample_period,
        floats,
        creep_speed,
        landed_band,
        estimator,
        compensate_resistance,
        self_calibration,
    })
}

/// K of [PT 48]: exactly one of `settling_time` and `poles`.
fn parse_gains(s: &Sect) -> Res<Gains> {
    let settling = s.opt("settling_time")?;
    let poles = s.opt_numbers("poles")?;
    match (settling, poles) {
        (Some(t), None) => Ok(Gains::SettlingTime(t)),
        (None, Some(p)) => match <[f64; 3]>::try_from(p.as_slice()) {
            Ok(poles) => Ok(Gains::Poles(poles)),
            Err(_) => {
                let msg = format!(
                    "expected exactly 3 real closed-loop poles [1/s] (the error dynamics of \
                     z, v, a is of order 3), found {}",
                    p.len()
                );
                Err(s.err("poles", msg, "needs 3 poles"))
            }
        },
        (Some(_), Some(_)) => Err(s.err(
            "poles",
            "give either controller.settling_time or controller.poles, not both \
             (both define the gains K)",
            "conflicts with `settling_time`",
        )),
        (None, None) => Err(s.missing(
            "settling_time",
            "exactly one of controller.settling_time [s] (5 % settling time of a triple \
             real pole) or controller.poles = [p1, p2, p3] [1/s] (each < 0)",
        )),
    }
}

/// The sliding surface [SM 17], η and the non-negative current of the
/// sliding-mode law.
fn parse_surface(s: &Sect) -> Res<SlidingSurface> {
    Ok(SlidingSurface {
        lambda1: s.req("lambda1")?,
        lambda2: s.req("lambda2")?,
        eta: s.req("eta")?,
        nonnegative_current: s.opt_bool("nonnegative_current")?.unwrap_or(false),
    })
}

/// The backstepping law's keys [SB]: three gains, the switching strategy,
/// the decay, and exactly one of `position` and `square`.
fn parse_backstepping(s: &Sect) -> Res<BacksteppingKeys> {
    let gains = exactly::<3>(s, "gains", "α₁, α₂, α₃ [1/s], each > 0")?
        .ok_or_else(|| s.missing("gains", "controller.gains = [α₁, α₂, α₃] [1/s], each > 0"))?;
    let switching = match s.opt_choice("switching", "switching strategy")? {
        Some("none") => Switching::None,
        Some("intuitive") => Switching::Intuitive,
        _ => Switching::Hybrid,
    };
    let decay = s.opt("decay")?;
    let position = s.opt("position")?;
    let square = exactly::<3>(s, "square", "[z_low, z_high, period] ([m], [m], [s])")?;
    let reference = match (position, square) {
        (Some(z), None) => SetPoint::Position(z),
        (None, Some([low, high, period])) => {
            if !(period > 0.0) {
                let msg = format!(
                    "expected a period > 0 [s] in controller.square = [z_low, z_high, period], \
                     found {period}"
                );
                return Err(s.err("square", msg, "needs a positive period"));
            }
            if low >= high {
                let msg = format!(
                    "expected z_low < z_high in controller.square = [z_low, z_high, period], \
                     found z_low = {low}, z_high = {high}"
                );
                return Err(s.err("square", msg, "z_low must be below z_high"));
            }
            SetPoint::Square { low, high, period }
        }
        (Some(_), Some(_)) => {
            return Err(s.err(
                "square",
                "give either controller.position or controller.square, not both (each is the \
                 reference y_r)",
                "conflicts with `position`",
            ))
        }
        (None, None) => {
            return Err(s.missing(
                "position",
                "exactly one of controller.position = z_ref [m] or controller.square = \
                 [z_low, z_high, period]",
            ))
        }
    };
    Ok(BacksteppingKeys {
        gains,
        switching,
        decay,
        reference,
    })
}

/// An optional array of exactly `N` numbers.
fn exactly<const N: usize>(s: &Sect, key: &str, what: &str) -> Res<Option<[f64; N]>> {
    let Some(found) = s.opt_numbers(key)? else {
        return Ok(None);
    };
    match <[f64; N]>::try_from(found.as_slice()) {
        Ok(values) => Ok(Some(values)),
        Err(_) => {
            let msg = format!(
                "expected exactly {N} numbers, {what}; found {}",
                found.len()
            );
            Err(s.err(key, msg, &format!("needs {N} numbers")))
        }
    }
}

/// `float` of `[controller]` and `[observer]`: optional, default both;
/// sorted, no duplicates.
pub(super) fn parse_floats(s: &Sect) -> Res<Vec<FloatType>> {
    let mut floats: Vec<FloatType> = s
        .names("float", "float type", "at least one float type")?
        .unwrap_or(schema::values("controller.float").to_vec())
        .into_iter()
        .map(|f| match f {
            "f32" => FloatType::F32,
            _ => FloatType::F64,
        })
        .collect();
    floats.sort();
    Ok(floats)
}
