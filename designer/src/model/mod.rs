//! The actuator model, built symbolically from a [`Description`].
//!
//! State x = [z, v, φ] (+ H_c with the Jiles–Atherton core), input u (coil
//! voltage, or current with `drive = "current"`), time t (only through the
//! resistance drift). Parameters stay named symbols ([`Params`]) so that
//! derivations keep them and code generation can print them as consts.
//!
//! | quantity | equation |
//! | --- | --- |
//! | reluctance | R(z, φ) = R_gap(z) + R_core(φ) (perfect-tracking [PT 5]) |
//! | force | F_mag = −½·R_gap'(z)·φ² ([PT 11]) |
//! | passive force | F(z, v) = k_s·z + c·v + F0 ([PT 10]) |
//! | motion | ż = v, v̇ = (F_mag − F)/m ([PT 15–16]) |
//! | flux, voltage drive | φ̇ = (N·u − R·(R_gap·φ + MMF_core))/(N² + R·k_e) ([PT 17]; [JA 17]) |
//! | flux, current drive | φ̇ = (N·u − (R_gap·φ + MMF_core))/k_e ([JA 16]) |
//! | coil current | i = (N·(R_gap·φ + MMF_core) + k_e·u)/(N² + R·k_e) ([JA 41]) |
//! | coil voltage (current drive) | v = R·u + N·φ̇ ([PT 1]) |

mod core;
mod field_path;
mod gap;
mod params;
mod plant;
mod statics;
mod table;

pub use self::core::LANGEVIN_SERIES_BELOW;
pub use field_path::FieldPath;
pub use gap::{MU0, Z_EPS};
pub use params::Params;
pub use plant::{ModelPlant, PlantError};
pub use statics::{anhysteretic_field, rest_point, Statics, SwitchingPoint};
pub use table::{Spline, SplineKind};

use crate::description::{Core, Description, Drive, Gap};
use crate::sym::{Graph, Id, Tape};

/// The symbolic state-space model of one actuator.
#[derive(Clone)]
pub struct Model {
    pub graph: Graph,
    pub description: Description,
    pub params: Params,
    /// z, v, φ (, H_c)
    pub states: Vec<Id>,
    /// The input u (coil voltage or coil current).
    pub input: Id,
    /// Time t (enters through the resistance drift only).
    pub time: Id,
    /// Free-motion state derivative f(x, u, t).
    pub f: Vec<Id>,
    /// Coil current i.
    pub current: Id,
    /// Coil voltage (equal to u for voltage drive).
    pub voltage: Id,
    pub f_mag: Id,
    pub passive_force: Id,
    pub r_gap: Id,
    pub r_gap_dz: Id,
    /// Model-level names of subexpressions (`r_gap`, `f_mag`, `fringe_den`, …)
    /// for generated code: each one an emitted expression reaches becomes a
    /// `let` of that name.
    pub named: Vec<(&'static str, Id)>,
    /// Stored magnetic energy W(z, φ) (not for the hysteretic core).
    pub stored_energy: Option<Id>,
    /// Coil resistance R(t).
    pub resistance: Id,
}

impl Model {
    pub fn build(description: &Description) -> Model {
        Model::build_with_gap(description, None)
    }

    /// The model with a C¹ tabulated gap replaced by its C² quintic twin
    /// (`table.rs`), for the energy-optimal design, and a sentence saying what
    /// changed; `None` when the gap is already C².
    pub fn c2_twin(description: &Description) -> Option<(Model, String)> {
        let Gap::Table { z, r, r_prime } = &description.gap else {
            return None;
        };
        let spline = Spline::fit(z, r, r_prime.as_deref());
        let twin = spline.c2_twin()?;
        let worst = max_slope_change(&spline, &twin);
        let what = format!(
            "the gap table's {} has a discontinuous R_gap″, which enters the costate equations: \
             the trajectory is solved on the {} (R_gap′ within {:.2} % of the table's between the knots{})",
            spline.kind.describe(),
            twin.kind.describe(),
            100.0 * worst,
            if twin.increasing() { "" } else { "; its slope is not positive everywhere" },
        );
        Some((Model::build_with_gap(description, Some(twin)), what))
    }

    fn build_with_gap(description: &Description, gap_spline: Option<Spline>) -> Model {
        let mut g = Graph::new();
        let mut params = Params::default();
        let z = g.symbol("z");
        let v = g.symbol("v");
        let phi = g.symbol("phi");
        let hc = matches!(description.core, Core::JilesAtherton(_)).then(|| g.symbol("H_c"));
        let u = g.symbol("u");
        let t = g.symbol("t");

        let mut named = Vec::new();
        let r_gap = match gap_spline {
            Some(spline) => spline.expression(&mut g, z),
            None => gap::reluctance(&mut g, &mut params, &description.gap, z, &mut named),
        };
        let r_gap_dz = g.diff(r_gap, z);
        let mmf_core = self::core::mmf(&mut g, &mut params, &description.core, phi, hc);
        let gap_mmf = g.mul(r_gap, phi);
        let mmf = g.add(gap_mmf, mmf_core);

        let coil = &description.coil;
        let n = params.key(&mut g, "coil.turns", coil.turns);
        let r_nominal = params.key(&mut g, "coil.resistance", coil.resistance);
        let k_e = params.key(&mut g, "coil.eddy", coil.eddy);
        let resistance = if coil.resistance_drift != 0.0 {
            let drift = params.key(&mut g, "coil.resistance_drift", coil.resistance_drift);
            let dr = g.mul(drift, t);
            g.add(r_nominal, dr)
        } else {
            r_nominal
        };

        let (phi_dot, current, voltage) = electrical(
            &mut g,
            description.supply.drive,
            [n, resistance, k_e, u, mmf],
            &mut named,
        );

        let m = &description.mechanics;
        let mass = params.key(&mut g, "mechanics.mass", m.mass);
        let k_s = params.key(&mut g, "mechanics.stiffness", m.stiffness);
        let damping = params.key(&mut g, "mechanics.damping", m.damping);
        let f0 = params.key(&mut g, "mechanics.preload", m.preload);
        // [PT 10] F(z, v) = k_s·z + c·v + F0
        let ksz = g.mul(k_s, z);
        let cv = g.mul(damping, v);
        let passive_force = g.sum(&[ksz, cv, f0]);
        // [PT 11] F_mag = −½·R_gap'·φ²
        let phi2 = g.powi(phi, 2);
        let rp_phi2 = g.mul(r_gap_dz, phi2);
        let f_mag = g.scale(-0.5, rp_phi2);
        // [PT 16] v̇ = (F_mag − F)/m
        let net = g.sub(f_mag, passive_force);
        let accel = g.div(net, mass);
        named.extend([
            ("r_gap", r_gap),
            ("mmf", mmf),
            ("f_mag", f_mag),
            ("f_passive", passive_force),
            ("f_net", net),
        ]);

        let mut states = vec![z, v, phi];
        let mut f = vec![v, accel, phi_dot];
        if let (Some(hc), Core::JilesAtherton(ja)) = (hc, &description.core) {
            states.push(hc);
            f.push(self::core::ja_field_rate(
                &mut g,
                &mut params,
                ja,
                phi,
                hc,
                phi_dot,
            ));
        }

        let stored_energy =
            self::core::stored_energy(&mut g, &params, &description.core, phi).map(|w_core| {
                // W = ½·R_gap(z)·φ² + W_core(φ)
                let gap_energy = g.mul(r_gap, phi2);
                let half = g.scale(0.5, gap_energy);
                g.add(half, w_core)
            });

        Model {
            graph: g,
            description: description.clone(),
            params,
            states,
            input: u,
            time: t,
            f,
            current,
            voltage,
            f_mag,
            passive_force,
            r_gap,
            r_gap_dz,
            named,
            stored_energy,
            resistance,
        }
    }

    /// Number of continuous states (3, or 4 with H_c).
    pub fn dim(&self) -> usize {
        self.states.len()
    }

    /// Names of the states, in order.
    pub fn state_names(&self) -> Vec<&str> {
        self.states
            .iter()
            .map(|&s| self.graph.name_of(s).unwrap_or("?"))
            .collect()
    }

    pub fn has_field_state(&self) -> bool {
        self.states.len() == 4
    }

    /// Tape inputs: the states, then u, then t.
    pub fn tape_inputs(&self) -> Vec<Id> {
        let mut inputs = self.states.clone();
        inputs.push(self.input);
        inputs.push(self.time);
        inputs
    }

    /// Replaces every parameter by its value (constant folding follows).
    pub fn bind_params(&mut self, exprs: &[Id]) -> Vec<Id> {
        let map = self.params.bindings(&mut self.graph);
        self.graph.substitute_all(exprs, &map)
    }

    /// Compiles `exprs` (parameters bound to their values) to a tape of
    /// (states…, u, t).
    pub fn compile(&mut self, exprs: &[Id]) -> Tape {
        let bound = self.bind_params(exprs);
        let inputs = self.tape_inputs();
        Tape::compile(&self.graph, &inputs, &bound)
            .expect("model expressions only use states, u, t and parameters")
    }

    /// ∂f/∂x, symbolically.
    pub fn jacobian(&mut self) -> Vec<Vec<Id>> {
        let (f, x) = (self.f.clone(), self.states.clone());
        self.graph.jacobian(&f, &x)
    }

    /// The gap interpolant of a table model (for reports).
    pub fn gap_spline(&self) -> Option<Spline> {
        match &self.description.gap {
            Gap::Table { z, r, r_prime } => Some(Spline::fit(z, r, r_prime.as_deref())),
            _ => None,
        }
    }
}

/// max |R′_b − R′_a| / max |R′_a| over 32 points per segment.
fn max_slope_change(a: &Spline, b: &Spline) -> f64 {
    let mut worst: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for w in a.knots.windows(2) {
        for j in 0..=32 {
            let z = w[0] + (w[1] - w[0]) * j as f64 / 32.0;
            let (da, db) = (a.eval(z).1, b.eval(z).1);
            worst = worst.max((db - da).abs());
            scale = scale.max(da.abs());
        }
    }
    worst / scale
}

/// (φ̇, coil current, coil voltage) for the drive mode; the name of the
/// flux equation's denominator goes to `names`.
fn electrical(
    g: &mut Graph,
    drive: Drive,
    [n, r, k_e, u, mmf]: [Id; 5],
    names: &mut gap::Names,
) -> (Id, Id, Id) {
    match drive {
        Drive::Voltage => {
            // k = N² + R·k_e
            let n2 = g.powi(n, 2);
            let rk = g.mul(r, k_e);
            let k = g.add(n2, rk);
            names.push(("flux_den", k));
            // φ̇ = (N·u − R·MMF)/k
            let nu = g.mul(n, u);
            let r_mmf = g.mul(r, mmf);
            let num = g.sub(nu, r_mmf);
            let phi_dot = g.div(num, k);
            // i = (N·MMF + k_e·u)/k
            let n_mmf = g.mul(n, mmf);
            let ku = g.mul(k_e, u);
            let num_i = g.add(n_mmf, ku);
            let current = g.div(num_i, k);
            (phi_dot, current, u)
        }
        Drive::Current => {
            // φ̇ = (N·i − MMF)/k_e, v = R·i + N·φ̇
            let nu = g.mul(n, u);
            let num = g.sub(nu, mmf);
            let phi_dot = g.div(num, k_e);
            let ri = g.mul(r, u);
            let n_phidot = g.mul(n, phi_dot);
            let voltage = g.add(ri, n_phidot);
            (phi_dot, u, voltage)
        }
    }
}
