//! The human-readable design report `reldesign build` prints: gains, the
//! linearization's singularity, per operation the reference, its
//! feasibility, its takeoff and its table, and the observers.

use std::fmt::Write as _;

use crate::description::Estimator;

use super::law::backstepping::design::BacksteppingDesign;
use super::law::decisions::LawDesign;
use super::plan::Design;
use super::trajectory::optimal::OptimalTrajectory;

impl Design {
    /// The report (one block per operation, then the observers).
    pub fn report(&self) -> String {
        let mut s = String::new();
        if let Some(h) = &self.hold {
            let [k1, k2, k3] = h.gains();
            let _ = writeln!(
                s,
                "model-based sliding mode [JA 89]: p = {:e} s⁻¹, K = {:e} s⁻¹ (the tracking law [PT 50] with K = [{k1:e}, {k2:e}, {k3:e}])",
                h.p, h.k
            );
            let _ = writeln!(s, "{}", h.linearization.singularity_text(&self.model.graph));
            let _ = writeln!(
                s,
                "hold at z_ref = {:e} m: flux {:.4e} Wb, steady input {:.4} (supply ≤ {}), guard φ ≤ {:e} Wb",
                h.position, h.holding_flux, h.holding_input, h.u_max, h.phi_guard
            );
        }
        if let Some(b) = &self.backstepping {
            let _ = write!(s, "{}", backstepping_text(b));
        }
        if let Some(c) = &self.controller {
            let _ = writeln!(s, "{}", law_text(&c.law));
            let _ = writeln!(s, "{}", c.linearization.singularity_text(&self.model.graph));
            for o in &c.operations {
                let _ = writeln!(s, "\n{} ({:e} m → {:e} m):", o.operation.name(), o.z0, o.zf);
                if let Some(opt) = &o.optimal {
                    let _ = writeln!(
                        s,
                        "  energy-optimal: J = ∫u² dt = {:.6e} V²·s, max |u| = {:.4} V, mesh {} nodes, residual {:.2e}, {} saturation switch(es)",
                        opt.cost,
                        opt.max_abs_input,
                        opt.t.len(),
                        opt.max_residual,
                        opt.switches.len()
                    );
                    if let Some(rest) = rest_text(opt) {
                        let _ = writeln!(s, "  {rest}");
                    }
                    if let Some(what) = &opt.smoothed_gap {
                        let _ = writeln!(s, "  note: {what}");
                    }
                    if let Some(c) = &opt.contact {
                        let _ = write!(s, "{}", contact_text(c));
                    }
                }
                if let Some(a) = self
                    .description
                    .trajectory
                    .as_ref()
                    .and_then(|t| t.approach())
                {
                    let _ = writeln!(s, "  {}", approach_text(&a, o.zf - o.z0));
                }
                let _ = write!(s, "{}", o.feasibility.report());
                if let Some(takeoff) = &o.takeoff {
                    let _ = writeln!(s, "  {}", takeoff.report_line());
                    if let Some(warning) = takeoff.warning() {
                        let _ = writeln!(s, "  {warning}");
                    }
                }
                let _ = writeln!(s, "  reference table: {} segments", o.table.segments.len());
            }
        }
        if let Some(o) = &self.description.observer {
            let names: Vec<&str> = o
                .estimators
                .iter()
                .map(|e| match e {
                    Estimator::Semera => "semera",
                    Estimator::Integral => "integral",
                    Estimator::Ekf => "ekf",
                    Estimator::Ukf => "ukf",
                })
                .collect();
            let _ = writeln!(
                s,
                "\nobservers: {} at T_s = {:e} s (σ_v = {:e} V, σ_i = {:e} A)",
                names.join(", "),
                o.sample_period,
                o.voltage_noise,
                o.current_noise
            );
        }
        s
    }
}

/// Where the energy-optimal motion is shorter than [t₀, t_f]: when it moves,
/// where it rests, and why.
fn rest_text(opt: &OptimalTrajectory) -> Option<String> {
    let (t0, tf) = (opt.spec.t0, opt.spec.tf);
    let (ta, tb) = opt.arc;
    if ta <= t0 && tb >= tf {
        return None;
    }
    let (place, u) = if tb < tf {
        (
            format!("lands at {:.4} ms and rests", tb * 1e3),
            opt.rest_inputs[1],
        )
    } else {
        (
            format!("rests until {:.4} ms, then moves", ta * 1e3),
            opt.rest_inputs[0],
        )
    };
    Some(format!(
        "the motion {place} (holding input {u:.4}): it lasts {:.4} ms, and any longer interval \
         is spent at rest, which costs less than moving slower ({:.6e} of J)",
        (tb - ta) * 1e3,
        opt.rest_cost,
    ))
}

/// The backstepping law's lines: gains, the region per target, the guard.
fn backstepping_text(b: &BacksteppingDesign) -> String {
    let mut s = String::new();
    let [a1, a2, a3] = b.gains;
    let r = &b.region;
    let _ = writeln!(
        s,
        "backstepping through the force [SB 19]: α₁ = {a1:e} s⁻¹, α₂ = {a2:e} s⁻¹, α₃ = {a3:e} s⁻¹, switching {}",
        b.switching.name()
    );
    let [p11, p12, p22] = r.p;
    let _ = writeln!(
        s,
        "region [SB Theorem 3]: P = [[{p11:.6e}, {p12:.6e}], [{p12:.6e}, {p22:.6e}]] (tr P = {:.6e}), decay α = {:e} s⁻¹{}",
        p11 + p22,
        r.decay,
        if r.extended {
            " (with the spring's rest inside D: the paper's min tr P alone leaves it out)"
        } else {
            ""
        }
    );
    for ((t, l), i) in r.targets.iter().zip(&r.levels).zip(&r.identity) {
        let yes = |b: bool| if b { "inside" } else { "outside" };
        let _ = writeln!(
            s,
            "  y_r = {:e} m: holding force {:.4} N, C = {:.4e} (rest z = {:e} m {} D); with P = ½I [SB 11]: C = {:.4e}, rest {}",
            t.position,
            t.holding_force,
            l.c,
            b.rest,
            yes(l.contains_rest),
            i.c,
            yes(i.contains_rest)
        );
    }
    let _ = writeln!(s, "guard φ ≤ {:e} Wb (g_F ∝ φ)", b.phi_guard);
    s
}

/// The law's line of the report.
fn law_text(law: &LawDesign) -> String {
    match *law {
        LawDesign::FeedbackLinearization {
            gains: [k1, k2, k3],
        } => {
            format!("feedback linearization: gains K = [{k1:e}, {k2:e}, {k3:e}] [PT 48]")
        }
        LawDesign::SlidingMode {
            lambda1,
            lambda2,
            nonnegative_current,
        } => format!(
            "sliding mode (model-free): λ₁ = {lambda1:e} s⁻¹, λ₂ = {lambda2:e} s⁻¹ [SM 17]{}",
            if nonnegative_current {
                ", the current kept ≥ 0 [SM §5]"
            } else {
                ""
            }
        ),
        LawDesign::ModelSlidingMode { p, k } => {
            let [k1, k2, k3] = super::law::decisions::model_sliding_gains(p, k);
            format!(
                "model-based sliding mode [JA 89]: p = {p:e} s⁻¹, K = {k:e} s⁻¹ (the tracking law [PT 50] with K = [{k1:e}, {k2:e}, {k3:e}]), inputs in [0, u_max] [JA 94]"
            )
        }
    }
}

/// The probability-based design beside the deterministic one: the cost and
/// the contact speeds over the stop's distribution.
fn contact_text(c: &crate::design::trajectory::optimal::robust::ContactDesign) -> String {
    let mut s = String::new();
    let mm = |v: f64| v * 1e3;
    let _ = writeln!(
        s,
        "  contact uncertainty σ = {:.3e} m (half-normal into the stroke): J = ∫u² dt + W·E[v_c²], W = {:.4e}, {} continuation step(s)",
        c.sigma, c.weight, c.steps
    );
    let _ = writeln!(
        s,
        "    {:<14} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12}",
        "reference", "J", "E|v_c| mm/s", "worst mm/s", "at σ mm/s", "at 2σ mm/s", "at 3σ mm/s"
    );
    for (name, j, f) in [
        ("robust", c.cost, &c.robust),
        ("deterministic", c.deterministic_cost, &c.deterministic),
    ] {
        let _ = writeln!(
            s,
            "    {:<14} {:>12.6e} {:>12.3} {:>12.3} {:>12.3} {:>12.3} {:>12.3}",
            name,
            j,
            mm(f.expected_speed),
            mm(f.worst_speed),
            mm(f.speed_at[0]),
            mm(f.speed_at[1]),
            mm(f.speed_at[2])
        );
    }
    let _ = writeln!(
        s,
        "    (worst: over the stops within 3σ; the deterministic reference's ∫u² dt = {:.6e})",
        c.deterministic_energy
    );
    s
}

/// The approach of `[trajectory] standoff` in one line.
fn approach_text(a: &crate::description::Approach, stroke: f64) -> String {
    format!(
        "approach: the move ends at rest {:e} m short of the stop ({:.1} % of the stroke), \
         then {:e} m/s into it over the last {:.4} ms: any stop or lead within the standoff \
         is met at no more than that speed",
        a.standoff,
        100.0 * a.standoff / stroke.abs(),
        a.speed,
        1e3 * a.duration()
    )
}
