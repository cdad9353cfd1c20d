//! The design figures of `reldesign build --report-json` as JSON (per
//! operation: J, max |u|, saturation switches, mesh size, residuals, table
//! size; the law and its gains; the backstepping law's certified region):
//! written once here for the command line and the Python package.

use crate::description::SetPoint;
use crate::design::{BacksteppingDesign, Design, LawDesign, Level};

/// The backstepping law's keys and design values.
fn backstepping_json(b: &BacksteppingDesign) -> serde_json::Value {
    let switching = b.switching.name();
    let reference = match b.reference {
        SetPoint::Position(z) => serde_json::json!({ "position": z }),
        SetPoint::Square { low, high, period } => {
            serde_json::json!({ "square": [low, high, period] })
        }
    };
    serde_json::json!({
        "law": "backstepping",
        "gains": b.gains,
        "switching": switching,
        "reference": reference,
        "rest_position": b.rest,
        "phi_guard": b.phi_guard,
        "holding": b.holding.iter().map(|&(flux, input)| serde_json::json!({"flux": flux, "input": input})).collect::<Vec<_>>(),
    })
}

/// The certified region [SB lemma 1], [SB Theorem 3]: A, P, C and whether
/// the spring's rest is in D, for the design's P and the paper's P = ½I; per
/// target where there are two (a square reference): `c` is the first
/// target's, `contains_rest` holds for every target.
fn region_json(b: &BacksteppingDesign) -> serde_json::Value {
    let r = &b.region;
    let [p11, p12, p22] = r.p;
    let level = |l: Option<&Level>| {
        l.map_or(
            serde_json::json!({ "c": null, "contains_rest": false }),
            |l| serde_json::json!({ "c": l.c, "contains_rest": l.contains_rest }),
        )
    };
    let targets: Vec<serde_json::Value> = (r.targets.iter().zip(&r.levels).zip(&r.identity))
        .map(|((t, l), i)| {
            serde_json::json!({
                "position": t.position,
                "holding_force": t.holding_force,
                "rest": t.rest,
                "c": l.c,
                "contains_rest": l.contains_rest,
                "identity": { "c": i.c, "contains_rest": i.contains_rest },
            })
        })
        .collect();
    let first = level(r.levels.first());
    let all = |levels: &[Level]| levels.iter().all(|l| l.contains_rest);
    let mut identity = level(r.identity.first());
    identity["contains_rest"] = all(&r.identity).into();
    serde_json::json!({
        "a": r.a,
        "p": [[p11, p12], [p12, p22]],
        "c": first["c"],
        "decay": r.decay,
        "contains_rest": all(&r.levels),
        "identity": identity,
        "extended": r.extended,
        "force_gradient": r.force_gradient,
        "trace": p11 + p22,
        "targets": targets,
    })
}

/// The design figures, for scripts and oracles.
pub fn report_json(design: &Design) -> String {
    // a loop that cannot run states no precision; the design still reports
    let precision = crate::precision::at_approaches(design).unwrap_or_default();
    report_json_with(design, &precision)
}

/// [`report_json`] with the sensorless precision already stated
/// ([`crate::precision::at_approaches`]).
pub fn report_json_with(
    design: &Design,
    precision: &[crate::precision::ApproachPrecision],
) -> String {
    let no_operations = Vec::new();
    let operations: serde_json::Map<String, serde_json::Value> = design
        .controller
        .as_ref()
        .map_or(&no_operations, |c| &c.operations)
        .iter()
        .map(|o| {
            let mut entry = serde_json::json!({
                "z0": o.z0,
                "zf": o.zf,
                "segments": o.table.segments.len(),
                "feasible": o.feasibility.is_feasible(),
                "max_input": o.feasibility.max_input,
                "min_input": o.feasibility.min_input,
            });
            if let (Some(opt), Some(map)) = (&o.optimal, entry.as_object_mut()) {
                map.insert("optimal".into(), opt.summary_json());
            }
            let approach = (design.description.trajectory.as_ref()).and_then(|t| t.approach());
            if let (Some(a), Some(map)) = (approach, entry.as_object_mut()) {
                let approach = serde_json::json!({
                    "standoff": a.standoff,
                    "speed": a.speed,
                    "duration": a.duration(),
                });
                map.insert("approach".into(), approach);
            }
            let stated = precision.iter().find(|p| p.operation == o.operation);
            if let (Some(p), Some(map)) = (stated, entry.as_object_mut()) {
                let precision = serde_json::json!({
                    "at": p.at,
                    "sigma_z": p.sigma_z,
                    "sigma_phi": p.sigma_phi,
                    "phi": p.phi,
                    "accel_per_flux": p.accel_per_flux,
                    "impact": p.impact,
                });
                map.insert("sensorless_precision".into(), precision);
            }
            (o.operation.name().to_string(), entry)
        })
        .collect();
    let law = design.controller.as_ref().map(|c| match c.law {
        LawDesign::FeedbackLinearization { gains } => {
            serde_json::json!({ "law": "feedback-linearization", "gains": gains })
        }
        LawDesign::SlidingMode {
            lambda1,
            lambda2,
            nonnegative_current,
        } => serde_json::json!({
            "law": "sliding-mode",
            "lambda1": lambda1,
            "lambda2": lambda2,
            "nonnegative_current": nonnegative_current,
        }),
        LawDesign::ModelSlidingMode { p, k } => serde_json::json!({
            "law": "model-sliding-mode",
            "p": p,
            "k": k,
            "gains": c.law.tracking_gains(),
        }),
    });
    let law = law.or_else(|| {
        design.hold.as_ref().map(|h| {
            serde_json::json!({
                "law": "model-sliding-mode",
                "p": h.p,
                "k": h.k,
                "gains": h.gains(),
                "position": h.position,
                "holding_flux": h.holding_flux,
                "holding_input": h.holding_input,
                "phi_guard": h.phi_guard,
            })
        })
    });
    let law = law.or_else(|| design.backstepping.as_ref().map(backstepping_json));
    let gains = (design.controller.as_ref())
        .and_then(|c| c.law.tracking_gains())
        .or_else(|| design.hold.as_ref().map(|h| h.gains()));
    let mut value = serde_json::json!({ "name": design.description.name, "controller": law, "gains": gains, "operations": operations });
    if let (Some(b), Some(map)) = (&design.backstepping, value.as_object_mut()) {
        map.insert("region".into(), region_json(b));
    }
    serde_json::to_string_pretty(&value).unwrap_or_default() + "\n"
}
