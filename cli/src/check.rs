//! `reldesign check MODEL.toml`: validation and a readable summary.

use std::fmt::Write;
use std::path::Path;

use designer::description::{
    Core, Description, Drive, FloatType, Gains, Gap, Law, SetPoint, Shape, Switching,
};
use designer::model::{Model, ModelPlant, Statics, SwitchingPoint};
use miette::Report;

pub fn run(path: &Path) -> Result<(), Report> {
    let description = crate::load(path)?;
    let mut model = Model::build(&description);
    print!("{}", summary(&mut model, &path.display().to_string()));
    Ok(())
}

/// The text `check` prints.
pub fn summary(model: &mut Model, file: &str) -> String {
    let mut s = String::new();
    let d = model.description.clone();
    let _ = writeln!(s, "{file}: valid actuator description `{}`", d.name);
    let _ = writeln!(s, "\nmodel");
    let _ = writeln!(s, "  states   x = [{}]", model.state_names().join(", "));
    let (input, output) = match d.supply.drive {
        Drive::Voltage => ("coil voltage [V]", "coil current [A]"),
        Drive::Current => ("coil current [A]", "coil voltage [V]"),
    };
    let _ = writeln!(
        s,
        "  input    u = {input}, in [{}, {}]",
        d.supply.u_min, d.supply.u_max
    );
    let _ = writeln!(s, "  output   {output}");
    let _ = writeln!(s, "  gap      {}", gap_text(model, &d));
    let _ = writeln!(s, "  core     {}", core_text(&d));
    let plant = ModelPlant::new(model);
    let _ = writeln!(
        s,
        "  f(x, u)  compiled to {} tape instructions",
        plant.f_tape_len()
    );
    let _ = writeln!(s, "\nparameters");
    for (name, _, value) in model.params.iter() {
        let _ = writeln!(s, "  {name:<12} = {value:e}");
    }
    s.push_str(&statics_text(model));
    s.push_str(&design_text(&d));
    s
}

/// The statics block (pull-in, drop-out, holding), also printed by `limits`.
pub fn statics_text(model: &mut Model) -> String {
    let mut s = String::new();
    let d = model.description.clone();
    let st = Statics::of(model);
    let (unit, what) = match d.supply.drive {
        Drive::Voltage => ("V", "voltage"),
        Drive::Current => ("A", "current"),
    };
    let m = &d.mechanics;
    let _ = writeln!(s, "\nstatics (steady state, φ̇ = 0)");
    let _ = writeln!(
        s,
        "  passive force F(z, 0): {:+.4} N at z_max = {:e} m, {:+.4} N at z_min = {:e} m",
        st.passive_at_max, m.z_max, st.passive_at_min, m.z_min
    );
    let _ = writeln!(
        s,
        "  pull-in  (lift-off from z_max): {}",
        point_text(&st.pull_in, &d, what, unit)
    );
    let _ = writeln!(
        s,
        "  drop-out (release from z_min):  {}",
        point_text(&st.drop_out, &d, what, unit)
    );
    let _ = writeln!(
        s,
        "  holding at z_min with the largest input: φ = {:.4e} Wb, F_mag = {:.4} N against F = {:+.4} N (margin {:.4} N)",
        st.hold_flux,
        st.hold_force,
        st.passive_at_min,
        -st.hold_force - st.passive_at_min
    );
    if matches!(d.core, Core::JilesAtherton(_)) {
        let _ = writeln!(
            s,
            "  (Jiles–Atherton core: statics on the anhysteretic curve)"
        );
    }
    s
}

/// The `[trajectory]` and `[controller]` sections, if any.
fn design_text(d: &Description) -> String {
    let mut s = String::new();
    if let Some(t) = &d.trajectory {
        let ops: Vec<&str> = t.operations.iter().map(|&o| o.name()).collect();
        let shape = match t.shape {
            Shape::Polynomial => "5th-degree polynomial",
            Shape::EnergyOptimal => "energy-optimal",
        };
        let _ = writeln!(s, "\ntrajectory");
        let _ = writeln!(
            s,
            "  {}; takeoff t0 = {:e} s, landing tf = {:e} s",
            ops.join(" and "),
            t.takeoff,
            t.landing
        );
        let _ = writeln!(
            s,
            "  shape {shape}, input bound {} (supply [{}, {}])",
            t.u_bound, d.supply.u_min, d.supply.u_max
        );
    }
    if let Some(c) = &d.controller {
        let law = match c.law {
            Law::FeedbackLinearization(Gains::SettlingTime(ts)) => {
                format!("feedback linearization [PT 50], 5 % settling time {ts:e} s (triple pole)")
            }
            Law::FeedbackLinearization(Gains::Poles(p)) => {
                format!("feedback linearization [PT 50], poles {p:?} s⁻¹")
            }
            Law::ModelSlidingMode(m) => format!(
                "model-based sliding mode [JA 89], p = {:e} s⁻¹, K = {:e} s⁻¹, {}",
                m.p,
                m.k,
                match m.position {
                    Some(z) => format!("holding z_ref = {z:e} m"),
                    None => "tracking [trajectory]".into(),
                }
            ),
            Law::Backstepping(b) => format!(
                "backstepping through the force [SB 19], α = {:?} s⁻¹, switching {}, {}",
                b.gains,
                match b.switching {
                    Switching::None => "none",
                    Switching::Intuitive => "intuitive [SB 28]",
                    Switching::Hybrid => "hybrid [SB 31–33]",
                },
                match b.reference {
                    SetPoint::Position(z) => format!("holding y_r = {z:e} m"),
                    SetPoint::Square { low, high, period } => {
                        format!("square reference {low:e} / {high:e} m, period {period:e} s")
                    }
                }
            ),
            Law::SlidingMode(m) => format!(
                "model-free sliding mode [SM 34], λ₁ = {:e} s⁻¹, λ₂ = {:e} s⁻¹, η = {:e} m/s³{}",
                m.lambda1,
                m.lambda2,
                m.eta,
                if m.nonnegative_current {
                    ", the current kept ≥ 0"
                } else {
                    ""
                }
            ),
        };
        let floats: Vec<&str> = c
            .floats
            .iter()
            .map(|f| if *f == FloatType::F32 { "f32" } else { "f64" })
            .collect();
        let _ = writeln!(s, "\ncontroller");
        let _ = writeln!(s, "  {law}");
        let _ = writeln!(
            s,
            "  sample period {:e} s, emitted for {}",
            c.sample_period,
            floats.join(" and ")
        );
        let designs = match c.law {
            Law::Backstepping(_) => "certifies the region (its LMI)",
            Law::ModelSlidingMode(m) if m.position.is_some() => "checks the position",
            _ => "designs the references",
        };
        let _ = writeln!(s, "  `reldesign build` {designs} and emits the code");
    }
    s
}

fn point_text(
    p: &Result<SwitchingPoint, String>,
    d: &Description,
    what: &str,
    unit: &str,
) -> String {
    match p {
        Ok(p) => {
            let value = match d.supply.drive {
                Drive::Voltage => p.voltage,
                Drive::Current => p.current,
            };
            format!(
                "{what} {value:.4} {unit} (flux {:.4e} Wb, current {:.4} A)",
                p.flux, p.current
            )
        }
        Err(why) => format!("none: {why}"),
    }
}

fn gap_text(model: &Model, d: &Description) -> String {
    match &d.gap {
        Gap::Linear { .. } => "linear: R_gap = R_gap0 + k_gap·z".into(),
        Gap::McLyman { .. } => format!(
            "McLyman fringing, ln regularised with z_ε = {:e} m",
            designer::model::Z_EPS
        ),
        Gap::McLymanFit { .. } => format!(
            "fitted McLyman, ln regularised with z_ε = {:e} m",
            designer::model::Z_EPS
        ),
        Gap::Table { z, .. } => {
            let kind = model.gap_spline().map_or("", |s| s.kind.describe());
            format!("table of {} points, {kind}", z.len())
        }
    }
}

fn core_text(d: &Description) -> &'static str {
    match d.core {
        Core::Linear { .. } => "linear: R_core = R_core0",
        Core::Saturating { .. } => {
            "saturating (Fröhlich–Kennelly): R_core = R_core0/(1 − |φ|/φ_sat)"
        }
        Core::JilesAtherton(_) => "inverse Jiles–Atherton hysteresis (adds the state H_c)",
    }
}
