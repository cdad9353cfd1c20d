//! Scalar parameters of a [`Description`] addressed by their TOML key path
//! (`coil.resistance`, `core.m_sat`, …), so that a fit can name what it
//! varies exactly as the user's file does.
//!
//! Only the keys of the description's current model variants exist: `core.b`
//! needs `core.model = "jiles-atherton"`, `gap.k1` needs `"mclyman-fit"`.
//! The keys and their domains are the description schema's
//! (`description::schema`), the ones the parser enforces (mass > 0,
//! c in [0, 1), …), so a fit never builds a model the parser would reject.

use crate::description::{schema, Core, Description, Gap};

pub use crate::description::schema::Domain;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    #[error("unknown parameter `{path}`: {model} has these: {available}")]
    Unknown {
        path: String,
        model: String,
        available: String,
    },
    #[error("parameter `{path}`: expected {expected}, found {value:e}")]
    OutOfDomain {
        path: String,
        value: f64,
        expected: String,
    },
}

/// The parameters of `d`'s model variants, with their domains: the schema's
/// fittable keys of the physics sections.
pub fn table(d: &Description) -> Vec<(&'static str, Domain)> {
    schema::KEYS
        .iter()
        .filter(|k| k.fittable)
        .filter(|k| match k.section() {
            "gap" => k.in_variant(Some(gap_model(d))),
            "core" => k.in_variant(Some(core_model(d))),
            _ => true,
        })
        .map(|k| (k.path, k.domain))
        .collect()
}

/// The paths valid for `d`'s model variants.
pub fn available(d: &Description) -> Vec<&'static str> {
    table(d).into_iter().map(|(p, _)| p).collect()
}

/// The domain of `path` in `d`, or an error naming the path and the model.
pub fn domain(d: &Description, path: &str) -> Result<Domain, ParamError> {
    table(d)
        .into_iter()
        .find(|(p, _)| *p == path)
        .map(|(_, dom)| dom)
        .ok_or_else(|| unknown(d, path))
}

/// The value of `path` in `d`.
pub fn get(d: &Description, path: &str) -> Result<f64, ParamError> {
    domain(d, path)?;
    let mut copy = d.clone();
    slot(&mut copy, path)
        .map(|x| *x)
        .ok_or_else(|| unknown(d, path))
}

/// Sets `path` in `d` to `value`, checked against its domain.
pub fn set(d: &mut Description, path: &str, value: f64) -> Result<(), ParamError> {
    let dom = domain(d, path)?;
    if !dom.contains(value) {
        return Err(ParamError::OutOfDomain {
            path: path.to_owned(),
            value,
            expected: dom.text(),
        });
    }
    let err = unknown(d, path);
    *slot(d, path).ok_or(err)? = value;
    Ok(())
}

fn unknown(d: &Description, path: &str) -> ParamError {
    ParamError::Unknown {
        path: path.to_owned(),
        model: model_name(d),
        available: available(d).join(", "),
    }
}

/// "gap.model = "…", core.model = "…"" for messages.
fn model_name(d: &Description) -> String {
    let (gap, core) = (gap_model(d), core_model(d));
    format!("the model with gap.model = \"{gap}\" and core.model = \"{core}\"")
}

/// `gap.model` of `d`.
fn gap_model(d: &Description) -> &'static str {
    match d.gap {
        Gap::Linear { .. } => "linear",
        Gap::McLyman { .. } => "mclyman",
        Gap::McLymanFit { .. } => "mclyman-fit",
        Gap::Table { .. } => "table",
    }
}

/// `core.model` of `d`.
fn core_model(d: &Description) -> &'static str {
    match d.core {
        Core::Linear { .. } => "linear",
        Core::Saturating { .. } => "saturating",
        Core::JilesAtherton(_) => "jiles-atherton",
    }
}

/// The field behind `path`, for the description's current variants.
fn slot<'a>(d: &'a mut Description, path: &str) -> Option<&'a mut f64> {
    let (section, key) = path.split_once('.')?;
    match section {
        "coil" => coil_slot(d, key),
        "gap" => gap_slot(&mut d.gap, key),
        "core" => core_slot(&mut d.core, key),
        "mechanics" => mechanics_slot(d, key),
        _ => None,
    }
}

fn coil_slot<'a>(d: &'a mut Description, key: &str) -> Option<&'a mut f64> {
    let c = &mut d.coil;
    Some(match key {
        "turns" => &mut c.turns,
        "resistance" => &mut c.resistance,
        "eddy" => &mut c.eddy,
        "resistance_drift" => &mut c.resistance_drift,
        _ => return None,
    })
}

fn gap_slot<'a>(gap: &'a mut Gap, key: &str) -> Option<&'a mut f64> {
    Some(match (gap, key) {
        (Gap::Linear { slope, .. }, "slope") => slope,
        (Gap::Linear { offset, .. }, "offset") => offset,
        (Gap::McLyman { area, .. }, "area") => area,
        (Gap::McLyman { winding_length, .. }, "winding_length") => winding_length,
        (Gap::McLymanFit { r0, .. }, "r0") => r0,
        (Gap::McLymanFit { r0_prime, .. }, "r0_prime") => r0_prime,
        (Gap::McLymanFit { k1, .. }, "k1") => k1,
        (Gap::McLymanFit { k2, .. }, "k2") => k2,
        _ => return None,
    })
}

fn core_slot<'a>(core: &'a mut Core, key: &str) -> Option<&'a mut f64> {
    Some(match (core, key) {
        (Core::Linear { r0 } | Core::Saturating { r0, .. }, "r0") => r0,
        (Core::Saturating { phi_sat, .. }, "phi_sat") => phi_sat,
        (Core::JilesAtherton(ja), key) => match key {
            "length" => &mut ja.length,
            "area" => &mut ja.area,
            "m_sat" => &mut ja.m_sat,
            "b" => &mut ja.b,
            "c" => &mut ja.c,
            "kappa" => &mut ja.kappa,
            "alpha" => &mut ja.alpha,
            _ => return None,
        },
        _ => return None,
    })
}

fn mechanics_slot<'a>(d: &'a mut Description, key: &str) -> Option<&'a mut f64> {
    let m = &mut d.mechanics;
    Some(match key {
        "mass" => &mut m.mass,
        "stiffness" => &mut m.stiffness,
        "damping" => &mut m.damping,
        "preload" => &mut m.preload,
        "restitution" => &mut m.restitution,
        "bounce_threshold" => &mut m.bounce_threshold,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::parse_file;
    use std::path::Path;

    fn example(name: &str) -> Description {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples")
            .join(name);
        parse_file(&path).unwrap()
    }

    #[test]
    fn every_available_path_round_trips() {
        for name in ["semera-valve.toml", "jiles-atherton-valve.toml"] {
            let mut d = example(name);
            for path in available(&d) {
                let x = get(&d, path).unwrap();
                let new = if path == "core.c" || path == "mechanics.restitution" {
                    0.5 * x + 0.1
                } else {
                    1.5 * x + 1e-3
                };
                set(&mut d, path, new).unwrap();
                assert_eq!(get(&d, path).unwrap(), new, "{name}: {path}");
            }
        }
    }

    #[test]
    fn setting_changes_the_description_field() {
        let mut d = example("jiles-atherton-valve.toml");
        set(&mut d, "core.m_sat", 2e6).unwrap();
        set(&mut d, "gap.k2", 0.02).unwrap();
        match (&d.core, &d.gap) {
            (Core::JilesAtherton(ja), Gap::McLymanFit { k2, .. }) => {
                assert_eq!((ja.m_sat, *k2), (2e6, 0.02));
            }
            _ => panic!("variants changed"),
        }
    }

    #[test]
    fn wrong_variant_and_domain_are_named() {
        let mut d = example("semera-valve.toml");
        let e = get(&d, "core.b").unwrap_err().to_string();
        assert!(
            e.contains("`core.b`") && e.contains("saturating") && e.contains("core.phi_sat"),
            "{e}"
        );
        let e = set(&mut d, "mechanics.mass", -1.0).unwrap_err().to_string();
        assert!(e.contains("mechanics.mass") && e.contains("> 0"), "{e}");
        assert!(set(&mut d, "nonsense", 1.0).is_err());
    }
}
