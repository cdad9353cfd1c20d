//! What to design: `[trajectory]` (the soft-landing references and the input
//! they may use) and `[controller]` with its law, the feedback-linearizing
//! gains [PT 48] or the sliding surface [SM 17], and the float types to emit.

use super::checks::check_u_bound;
use super::physics::input_unit;
use super::sect::{Res, Sect};
use crate::description::schema;
use crate::description::{
    Controller, Estimator, FloatType, Gains, Law, ModelSurface, Operation, Shape, SlidingSurface,
    Supply, Trajectory,
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
    Ok(Trajectory {
        operations,
        takeoff,
        landing,
        shape,
        u_bound,
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
    Ok(Controller {
        law,
        sample_period,
        floats,
        creep_speed,
        landed_band,
        estimator,
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
