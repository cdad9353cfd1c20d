//! The physics sections: `[coil]`, `[gap]` (with its table), `[core]`,
//! `[mechanics]` and `[supply]`, each key read with the schema's domain,
//! unit and default; the keys a section allows follow its `model`.

use super::sect::{Res, Sect};
use crate::description::{Coil, Core, Drive, Gap, JilesAtherton, Mechanics, Reversal, Supply};

pub(super) fn parse_coil(s: &Sect) -> Res<Coil> {
    s.check_keys(None, "in [coil]")?;
    Ok(Coil {
        turns: s.req("turns")?,
        resistance: s.req("resistance")?,
        eddy: s.req("eddy")?,
        resistance_drift: s.or_default("resistance_drift")?,
    })
}

pub(super) fn parse_gap(s: &Sect) -> Res<Gap> {
    let model = s.choice("model", "gap model")?;
    s.check_keys(Some(model), &format!("in [gap] with model \"{model}\""))?;
    Ok(match model {
        "linear" => Gap::Linear {
            slope: s.req("slope")?,
            offset: s.or_default("offset")?,
        },
        "mclyman" => Gap::McLyman {
            area: s.req("area")?,
            winding_length: s.req("winding_length")?,
        },
        "mclyman-fit" => Gap::McLymanFit {
            r0: s.req("r0")?,
            r0_prime: s.req("r0_prime")?,
            k1: s.req("k1")?,
            k2: s.req("k2")?,
        },
        _ => parse_table(s)?,
    })
}

/// `model = "table"`: at least 4 points, z and R_gap strictly increasing,
/// `r_prime` (if given) as long as `z`.
fn parse_table(s: &Sect) -> Res<Gap> {
    let z = s.req_array("z")?;
    let r = s.req_array("r")?;
    let r_prime = s.opt_numbers("r_prime")?;
    if z.len() < 4 {
        let msg = format!("expected at least 4 points, found {}", z.len());
        return Err(s.err("z", msg, "too few points"));
    }
    s.same_length("r", &r, z.len())?;
    if let Some(rp) = &r_prime {
        s.same_length("r_prime", rp, z.len())?;
    }
    s.strictly_increasing("z", &z, "")?;
    let why = " (R_gap' > 0: the magnetic force must pull towards z_min)";
    s.strictly_increasing("r", &r, why)?;
    Ok(Gap::Table { z, r, r_prime })
}

pub(super) fn parse_core(s: &Sect) -> Res<Core> {
    let model = s.choice("model", "core model")?;
    s.check_keys(Some(model), &format!("in [core] with model \"{model}\""))?;
    Ok(match model {
        "linear" => Core::Linear { r0: s.req("r0")? },
        "saturating" => Core::Saturating {
            r0: s.req("r0")?,
            phi_sat: s.req("phi_sat")?,
        },
        _ => Core::JilesAtherton(JilesAtherton {
            length: s.req("length")?,
            area: s.req("area")?,
            m_sat: s.req("m_sat")?,
            b: s.req("b")?,
            c: s.req("c")?,
            kappa: s.req("kappa")?,
            alpha: s.req("alpha")?,
            epsilon: s.or_default("epsilon")?,
            reversal: match s.opt_choice("reversal", "reversal rule")? {
                Some("reversible") => Reversal::Reversible,
                _ => Reversal::Clamp,
            },
        }),
    })
}

pub(super) fn parse_mechanics(s: &Sect) -> Res<Mechanics> {
    s.check_keys(None, "in [mechanics]")?;
    let mass = s.req("mass")?;
    let stiffness = s.req("stiffness")?;
    let damping = s.req("damping")?;
    let preload = resolve_preload(s, stiffness)?;
    let z_min = s.req("z_min")?;
    let z_max = s.req_above("z_max", z_min)?;
    Ok(Mechanics {
        mass,
        stiffness,
        damping,
        preload,
        z_min,
        z_max,
        restitution: s.req("restitution")?,
        bounce_threshold: s.req("bounce_threshold")?,
    })
}

/// F0: `preload`, or −k_s·`rest_position`; exactly one of them.
fn resolve_preload(s: &Sect, stiffness: f64) -> Res<f64> {
    let preload = s.opt("preload")?;
    let rest = s.opt("rest_position")?;
    match (preload, rest) {
        (Some(f0), None) => Ok(f0),
        (None, Some(z_s)) => Ok(-stiffness * z_s),
        (Some(_), Some(_)) => Err(s.err(
            "rest_position",
            "give either mechanics.preload or mechanics.rest_position, not both \
             (F0 = preload, or F0 = −stiffness·rest_position)",
            "conflicts with `preload`",
        )),
        (None, None) => Err(s.missing(
            "preload",
            "exactly one of mechanics.preload [N] or mechanics.rest_position [m] \
             (F0 = preload, or F0 = −stiffness·rest_position)",
        )),
    }
}

/// `[supply]`: `u_min` and `u_max` are in V or A as `drive` says.
pub(super) fn parse_supply(s: &Sect) -> Res<Supply> {
    s.check_keys(None, "in [supply]")?;
    let drive = match s.choice("drive", "drive")? {
        "voltage" => Drive::Voltage,
        _ => Drive::Current,
    };
    let unit = input_unit(drive);
    let u_min = s.req_in("u_min", unit)?;
    let u_max = s.req_above_in("u_max", u_min, unit)?;
    Ok(Supply {
        drive,
        u_min,
        u_max,
    })
}

/// The unit of the input u: V for a voltage drive, A for a current drive.
pub(super) fn input_unit(drive: Drive) -> &'static str {
    if drive == Drive::Voltage {
        "V"
    } else {
        "A"
    }
}
