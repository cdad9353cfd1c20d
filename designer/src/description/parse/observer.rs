//! `[observer]` and its sub-sections `[observer.semera]`,
//! `[observer.integral]`, `[observer.kalman]`: each sub-section is required
//! exactly when one of its estimators is listed (and refused otherwise), and
//! the Kalman filters' keys follow the core model's state.

use super::design::parse_floats;
use super::sect::{Res, Sect};
use crate::description::{
    Core, Drive, Estimator, FluxStep, IntegralSettings, KalmanSection, Observer,
    ResistanceEstimate, SemeraSettings, Supply, MAX_FLUX_SUBSTEPS,
};

pub(super) fn parse_observer(
    s: &Sect,
    supply: &Supply,
    core_sect: &Sect,
    core: &Core,
) -> Res<Observer> {
    s.check_keys(None, "in [observer]")?;
    let estimators = parse_estimators(s)?;
    let sample_period = s.req("sample_period")?;
    let floats = parse_floats(s)?;
    let voltage_noise = s.req("voltage_noise")?;
    let current_noise = s.req("current_noise")?;
    let has = |e: Estimator| estimators.contains(&e);
    let semera = s
        .sub_section(
            "semera",
            "observer.semera",
            has(Estimator::Semera),
            "\"semera\"",
        )?
        .map(|t| parse_semera(&t))
        .transpose()?;
    let integral = s
        .sub_section(
            "integral",
            "observer.integral",
            has(Estimator::Integral),
            "\"integral\"",
        )?
        .map(|t| parse_integral(&t, supply))
        .transpose()?;
    let kalman = s
        .sub_section(
            "kalman",
            "observer.kalman",
            has(Estimator::Ekf) || has(Estimator::Ukf),
            "\"ekf\" or \"ukf\"",
        )?
        .map(|t| parse_kalman(&t, core_sect, core))
        .transpose()?;
    Ok(Observer {
        estimators,
        sample_period,
        floats,
        voltage_noise,
        current_noise,
        semera,
        integral,
        kalman,
    })
}

/// `estimators`: required, non-empty, distinct.
fn parse_estimators(s: &Sect) -> Res<Vec<Estimator>> {
    let names = s
        .names("estimators", "estimator", "at least one estimator")?
        .ok_or_else(|| {
            s.missing(
                "estimators",
                "a non-empty array of \"semera\", \"integral\", \"ekf\", \"ukf\"",
            )
        })?;
    let estimators = names.into_iter().map(|e| match e {
        "semera" => Estimator::Semera,
        "integral" => Estimator::Integral,
        "ekf" => Estimator::Ekf,
        _ => Estimator::Ukf,
    });
    Ok(estimators.collect())
}

/// `[observer.semera]`: [SE Table II] / [SE Table V].
fn parse_semera(s: &Sect) -> Res<SemeraSettings> {
    s.check_keys(None, "in [observer.semera]")?;
    Ok(SemeraSettings {
        initial_resistance: s.req("initial_resistance")?,
        initial_resistance_std: s.req("initial_resistance_std")?,
        initial_inductance: s.req("initial_inductance")?,
        initial_inductance_std: s.req("initial_inductance_std")?,
        resistance_rate_std: s.req("resistance_rate_std")?,
        inductance_accel_std: s.req("inductance_accel_std")?,
        ci_sigmas: s.req("ci_sigmas")?,
    })
}

/// `[observer.integral]`: what [SE Alg. 2] needs.
fn parse_integral(s: &Sect, supply: &Supply) -> Res<IntegralSettings> {
    s.check_keys(None, "in [observer.integral]")?;
    let initial_resistance = s.req("initial_resistance")?;
    let initial_inductance = s.req("initial_inductance")?;
    let initial_flux_linkage = s.or_default("initial_flux_linkage")?;
    let ci_sigmas = s.req("ci_sigmas")?;
    let energize_threshold = parse_energize_threshold(s, supply)?;
    Ok(IntegralSettings {
        initial_resistance,
        initial_inductance,
        initial_flux_linkage,
        ci_sigmas,
        energize_threshold,
    })
}

/// `energize_threshold` [V]: u_max/2 by default with a positive voltage
/// supply, required otherwise.
fn parse_energize_threshold(s: &Sect, supply: &Supply) -> Res<f64> {
    const KEY: &str = "energize_threshold";
    let default =
        (supply.drive == Drive::Voltage && supply.u_max > 0.0).then_some(0.5 * supply.u_max);
    match (s.opt(KEY)?, default) {
        (Some(threshold), _) => Ok(threshold),
        (None, Some(default)) => Ok(default),
        (None, None) => Err(s.missing(
            KEY,
            "a number > 0 [V]: the coil voltage above which an energizing operation \
             starts (it has no default unless supply.drive = \"voltage\" with \
             supply.u_max > 0, where it is u_max/2)",
        )),
    }
}

/// `[observer.kalman]`: `process_hc` and `initial_hc_std` exist exactly with a
/// Jiles–Atherton core (whose state has H_c).
fn parse_kalman(s: &Sect, core_sect: &Sect, core: &Core) -> Res<KalmanSection> {
    s.check_keys(None, "in [observer.kalman]")?;
    let process_z = s.req("process_z")?;
    let process_phi = s.req("process_phi")?;
    let ja = matches!(core, Core::JilesAtherton(_));
    let process_hc = parse_hc(s, "process_hc", ja, core_sect)?;
    let initial_z_std = s.req("initial_z_std")?;
    let initial_phi_std = s.req("initial_phi_std")?;
    let initial_hc_std = parse_hc(s, "initial_hc_std", ja, core_sect)?;
    let resistance = parse_resistance_estimate(s)?;
    let flux_step = parse_flux_step(s)?;
    Ok(KalmanSection {
        process_z,
        process_phi,
        process_hc,
        initial_z_std,
        initial_phi_std,
        initial_hc_std,
        ukf_alpha: s.or_default("ukf_alpha")?,
        ukf_beta: s.or_default("ukf_beta")?,
        ukf_kappa: s.or_default("ukf_kappa")?,
        resistance,
        flux_step,
    })
}

/// `flux_step` ("euler" by default, or "exponential") and `flux_substeps`
/// (an integer in 1..=[`MAX_FLUX_SUBSTEPS`], default 1, only with "exponential").
fn parse_flux_step(s: &Sect) -> Res<FluxStep> {
    const KEY: &str = "flux_substeps";
    let exponential = s.opt_choice("flux_step", "flux step")? == Some("exponential");
    let Some(m) = s.opt(KEY)? else {
        return Ok(if exponential {
            FluxStep::Exponential { substeps: 1 }
        } else {
            FluxStep::Euler
        });
    };
    if !exponential {
        let msg = "only allowed with flux_step = \"exponential\" (the Euler step [JA 84c] \
                   takes one step per sample); add flux_step = \"exponential\" or remove it";
        return Err(s.err(KEY, msg, "the flux step is Euler's"));
    }
    let max = MAX_FLUX_SUBSTEPS;
    if m.fract() != 0.0 || !(1.0..=f64::from(max)).contains(&m) {
        let msg = format!("expected an integer in 1..={max} (substeps per sample), found {m}");
        return Err(s.err(KEY, msg, "not a substep count"));
    }
    Ok(FluxStep::Exponential { substeps: m as u32 })
}

/// A key of the state H_c [A/m]: required with a Jiles–Atherton core (`ja`),
/// refused with the other models.
fn parse_hc(s: &Sect, key: &str, ja: bool, core_sect: &Sect) -> Res<Option<f64>> {
    if ja {
        let what = "a number > 0 [A/m] (the \"jiles-atherton\" core adds the state H_c)";
        return s.opt(key)?.map(Some).ok_or_else(|| s.missing(key, what));
    }
    if s.entry(key).is_some() {
        let model = core_sect
            .entry("model")
            .and_then(|(_, v)| v.get_ref().as_str().map(str::to_owned))
            .unwrap_or_default();
        let msg = format!(
            "only allowed with core.model = \"jiles-atherton\" \
             (the state has no H_c with core.model = \"{model}\"); remove it"
        );
        return Err(s.err(key, msg, "no H_c in this model"));
    }
    Ok(None)
}

/// `estimate_resistance` (a boolean, default false) of `[observer.kalman]`
/// with `resistance_rate_std` [Ω/s] and `initial_resistance_std` [Ω], both
/// required with it and refused without it (with a Jiles–Atherton core the
/// state is [z, z_prev, φ, H_c, R]).
fn parse_resistance_estimate(s: &Sect) -> Res<Option<ResistanceEstimate>> {
    const KEY: &str = "estimate_resistance";
    let on = s.opt_bool(KEY)?.unwrap_or(false);
    let keys = ["resistance_rate_std", "initial_resistance_std"];
    if !on {
        if let Some(key) = keys.into_iter().find(|k| s.entry(k).is_some()) {
            let msg = "only allowed with estimate_resistance = true (the coil resistance is a \
                       state only then); add estimate_resistance = true or remove it";
            return Err(s.err(key, msg, "R is not estimated"));
        }
        return Ok(None);
    }
    Ok(Some(ResistanceEstimate {
        rate_std: s.req(keys[0])?,
        initial_std: s.req(keys[1])?,
    }))
}
