//! A seeded generator of plausible actuators, for tests on devices nobody
//! tuned reldesign to: relays, small and large valves, every gap model
//! (linear, McLyman, fitted McLyman, table with and without r′) and every
//! input-affine core (linear, saturating), or the Jiles–Atherton core on
//! request.
//!
//! Numbers are drawn in the ranges a datasheet would give (supply, coil
//! power, ampere-turns, pole area, stroke, mass), then made consistent the way
//! a designer would: the coil resistance from the supply and the coil power,
//! the turns from the ampere-turns at that current,
//! the preload so that the armature rests open unpowered and the supply can
//! hold it at the open end with a margin, the spring as a share of the
//! preload, damping as a fraction of critical, the saturation flux from a
//! steel's B_sat. Every gap model is derived from one McLyman "truth" of the
//! pole, so the device is the same physical object whatever its model.
//!
//! The output is the physics sections of a description (TOML text), which a
//! test extends with design sections and parses, writes for the CLI, or hands
//! to the Python oracles.

use designer::description::{parse_str, Description};

use crate::Rng;

/// μ0 [H/m].
const MU0: f64 = 4.0e-7 * std::f64::consts::PI;

/// The kind of device, which sets the ranges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    Relay,
    SmallValve,
    LargeValve,
}

/// The gap model of the description.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GapKind {
    Linear,
    McLyman,
    McLymanFit,
    TableWithSlopes,
    Table,
}

/// The core model of the description.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoreKind {
    Linear,
    Saturating,
    JilesAtherton,
}

/// One generated device.
#[derive(Debug, Clone)]
pub struct Device {
    pub name: String,
    pub class: Class,
    pub gap: GapKind,
    pub core: CoreKind,
    /// Supply voltage [V] (u_max).
    pub supply: f64,
    /// Whether the driver can apply −supply (else u_min = 0).
    pub bipolar: bool,
    pub stroke: f64,
    /// The physics sections (TOML).
    pub toml: String,
}

impl Device {
    /// The description with `design` (TOML sections) appended.
    pub fn description_with(&self, design: &str) -> Description {
        let text = format!("{}\n{design}", self.toml);
        parse_str(&text, &format!("{}.toml", self.name)).unwrap_or_else(|e| {
            panic!("generated device {} does not parse: {e}\n{text}", self.name)
        })
    }

    pub fn description(&self) -> Description {
        self.description_with("")
    }
}

/// When the armature of `d`, held at `u` from rest at z_max without flux,
/// leaves z_max (within `horizon` [s]): the shortest pre-movement a device
/// study can give it.
pub fn lift_off(d: &Description, u: f64, horizon: f64) -> Option<f64> {
    use designer::sim::{EventKind, Limit, Options};
    let mut model = designer::model::Model::build(d);
    let run =
        designer::replay::replay(&mut model, &u, &[0.0, horizon], &Options::default()).ok()?;
    run.trajectory
        .events
        .iter()
        .find_map(|e| matches!(e.kind, EventKind::LiftOff { limit: Limit::Max }).then_some(e.t))
}

const GAPS: [GapKind; 5] = [
    GapKind::Linear,
    GapKind::McLyman,
    GapKind::McLymanFit,
    GapKind::TableWithSlopes,
    GapKind::Table,
];
const CLASSES: [Class; 3] = [Class::Relay, Class::SmallValve, Class::LargeValve];

/// Device `index` of the family `seed`: classes and gap models cycle with the
/// index (so devices 15k … 15k + 14 cover every class × gap model), the
/// core alternates linear / saturating (or is Jiles–Atherton when `ja`).
pub fn device(seed: u64, index: u64, ja: bool) -> Device {
    let mut rng = Rng::new(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ index);
    let class = CLASSES[(index % 3) as usize];
    let gap = GAPS[((index / 3) % 5) as usize];
    let core = if ja {
        CoreKind::JilesAtherton
    } else if (index / 15) % 2 == 0 {
        CoreKind::Saturating
    } else {
        CoreKind::Linear
    };
    Draw::new(class, &mut rng).device(format!("device_{seed}_{index}"), gap, core, &mut rng)
}

/// `n` devices of the family `seed` (input-affine cores).
pub fn devices(seed: u64, n: u64) -> Vec<Device> {
    (0..n).map(|i| device(seed, i, false)).collect()
}

/// The drawn physical quantities.
struct Draw {
    class: Class,
    supply: f64,
    bipolar: bool,
    turns: f64,
    resistance: f64,
    area: f64,
    winding_length: f64,
    stroke: f64,
    mass: f64,
    r_core: f64,
    /// The core's magnetic path [m] and relative permeability.
    path: f64,
    mu_r: f64,
    phi_sat: f64,
}

fn log_uniform(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    (rng.uniform(lo.ln(), hi.ln())).exp()
}

fn pick(rng: &mut Rng, values: &[f64]) -> f64 {
    let k = (rng.uniform(0.0, values.len() as f64) as usize).min(values.len() - 1);
    values[k]
}

/// McLyman (perfect-tracking-soft-landing [PT 6]): R(z) and R′(z).
fn mclyman(area: f64, lw: f64, z: f64) -> (f64, f64) {
    let r = |z: f64| {
        if z <= 0.0 {
            return 0.0;
        }
        (z / (MU0 * area)) / (1.0 + z / area.sqrt() * (2.0 * lw / z).ln())
    };
    let h = 1e-9_f64.max(1e-6 * z);
    let dr = if z > h {
        (r(z + h) - r(z - h)) / (2.0 * h)
    } else {
        // R′(0⁺) = 1/(μ0·A)
        1.0 / (MU0 * area)
    };
    (r(z), dr)
}

impl Draw {
    fn new(class: Class, rng: &mut Rng) -> Draw {
        // (supplies, coil power [W], ampere-turns at full power, pole area
        // [m²], l_w [m], stroke [m], mass [kg])
        let (supplies, power, mmf, area, lw, stroke, mass): (&[f64], _, _, _, _, _, _) = match class
        {
            Class::Relay => (
                &[5.0, 12.0, 24.0],
                (0.2, 1.0),
                (100.0, 400.0),
                (10e-6, 40e-6),
                (5e-3, 15e-3),
                (0.3e-3, 1.0e-3),
                (0.5e-3, 3e-3),
            ),
            Class::SmallValve => (
                &[12.0, 24.0],
                (2.0, 8.0),
                (300.0, 1200.0),
                (15e-6, 60e-6),
                (10e-3, 25e-3),
                (0.5e-3, 1.5e-3),
                (1e-3, 8e-3),
            ),
            Class::LargeValve => (
                &[24.0, 48.0],
                (10.0, 40.0),
                (800.0, 3000.0),
                (50e-6, 200e-6),
                (15e-3, 40e-3),
                (1e-3, 3e-3),
                (5e-3, 30e-3),
            ),
        };
        let supply = pick(rng, supplies);
        let power = log_uniform(rng, power.0, power.1);
        let area = log_uniform(rng, area.0, area.1);
        // the winding: R from supply and power, N from the ampere-turns
        let resistance = supply * supply / power;
        let current = supply / resistance;
        let turns = (log_uniform(rng, mmf.0, mmf.1) / current).round().max(10.0);
        // core: l_c / (μ0·μr·A), μr of soft iron, path 2–8 cm
        let mu_r = log_uniform(rng, 300.0, 3000.0);
        let path = rng.uniform(20e-3, 80e-3);
        Draw {
            class,
            supply,
            bipolar: rng.uniform(0.0, 1.0) < 0.75,
            turns,
            resistance,
            area,
            winding_length: rng.uniform(lw.0, lw.1),
            stroke: rng.uniform(stroke.0, stroke.1),
            mass: log_uniform(rng, mass.0, mass.1),
            r_core: path / (MU0 * mu_r * area),
            path,
            mu_r,
            phi_sat: rng.uniform(1.2, 1.8) * area,
        }
    }

    fn device(&self, name: String, gap: GapKind, core: CoreKind, rng: &mut Rng) -> Device {
        let z_max = self.stroke;
        // the force the supply can hold at the open end (linear magnetics,
        // flux capped below saturation)
        let (r_open, dr_open) = mclyman(self.area, self.winding_length, z_max);
        let mmf = self.turns * self.supply / self.resistance;
        let phi = (mmf / (r_open + self.r_core)).min(0.7 * self.phi_sat);
        let f_capacity = 0.5 * dr_open * phi * phi;
        // holding at z_max needs a share of it; the spring adds σ of that at z_min
        let f_hold = rng.uniform(0.12, 0.35) * f_capacity;
        let sigma = rng.uniform(0.2, 1.0);
        let stiffness = sigma * f_hold / z_max;
        let preload = -f_hold * (1.0 + sigma);
        // at z_min the flux of the rest state must stay below saturation
        let dr_closed = 1.0 / (MU0 * self.area);
        let phi_closed = (2.0 * preload.abs() / dr_closed).sqrt();
        let phi_sat = self.phi_sat.max(1.5 * phi_closed);
        let zeta = rng.uniform(0.05, 0.5);
        let damping = zeta * 2.0 * (stiffness * self.mass).sqrt();
        let eddy = rng.uniform(0.0, 0.3) * self.turns * self.turns / self.resistance;
        let u_min = if self.bipolar { -self.supply } else { 0.0 };
        let toml = format!(
            "name = \"{name}\"\n\n[coil]\nturns = {turns}\nresistance = {r:e}\neddy = {eddy:e}\n\n\
             {gap}\n{core}\n\
             [mechanics]\nmass = {mass:e}\nstiffness = {stiffness:e}\ndamping = {damping:e}\n\
             preload = {preload:e}\nz_min = 0.0\nz_max = {z_max:e}\nrestitution = {gamma:e}\n\
             bounce_threshold = 1e-3\n\n\
             [supply]\ndrive = \"voltage\"\nu_min = {u_min:e}\nu_max = {u_max:e}\n",
            turns = self.turns,
            r = self.resistance,
            gap = self.gap_toml(gap, rng),
            core = self.core_toml(core, phi_sat, rng),
            mass = self.mass,
            gamma = rng.uniform(0.2, 0.7),
            u_max = self.supply,
        );
        Device {
            name,
            class: self.class,
            gap,
            core,
            supply: self.supply,
            bipolar: self.bipolar,
            stroke: z_max,
            toml,
        }
    }

    fn gap_toml(&self, kind: GapKind, rng: &mut Rng) -> String {
        let (a, lw, z_max) = (self.area, self.winding_length, self.stroke);
        match kind {
            GapKind::Linear => {
                // the secant of the McLyman truth over the stroke
                let (r_max, _) = mclyman(a, lw, z_max);
                format!("[gap]\nmodel = \"linear\"\nslope = {:e}\n", r_max / z_max)
            }
            GapKind::McLyman => {
                format!("[gap]\nmodel = \"mclyman\"\narea = {a:e}\nwinding_length = {lw:e}\n")
            }
            GapKind::McLymanFit => {
                // the same law with a small residual reluctance of the joint
                let r0 = rng.uniform(0.0, 0.05) * mclyman(a, lw, z_max).0;
                format!(
                    "[gap]\nmodel = \"mclyman-fit\"\nr0 = {r0:e}\nr0_prime = {:e}\nk1 = {:e}\nk2 = {:e}\n",
                    1.0 / (MU0 * a),
                    1.0 / a.sqrt(),
                    2.0 * lw
                )
            }
            GapKind::TableWithSlopes | GapKind::Table => {
                // denser near the closed end, as an FEA sweep would be
                let n = rng.uniform(8.0, 16.0) as usize;
                let z: Vec<f64> = (0..n)
                    .map(|k| {
                        let s = k as f64 / (n - 1) as f64;
                        1.05 * z_max * s * (0.4 + 0.6 * s)
                    })
                    .collect();
                let values: Vec<(f64, f64)> = z.iter().map(|&z| mclyman(a, lw, z)).collect();
                let list = |v: &mut dyn Iterator<Item = f64>| {
                    v.map(|x| format!("{x:e}")).collect::<Vec<_>>().join(", ")
                };
                let mut s = format!(
                    "[gap]\nmodel = \"table\"\nz = [{}]\nr = [{}]\n",
                    list(&mut z.iter().copied()),
                    list(&mut values.iter().map(|v| v.0))
                );
                if kind == GapKind::TableWithSlopes {
                    s += &format!("r_prime = [{}]\n", list(&mut values.iter().map(|v| v.1)));
                }
                s
            }
        }
    }

    fn core_toml(&self, kind: CoreKind, phi_sat: f64, rng: &mut Rng) -> String {
        match kind {
            CoreKind::Linear => format!("[core]\nmodel = \"linear\"\nr0 = {:e}\n", self.r_core),
            CoreKind::Saturating => format!(
                "[core]\nmodel = \"saturating\"\nr0 = {:e}\nphi_sat = {phi_sat:e}\n",
                self.r_core
            ),
            CoreKind::JilesAtherton => {
                // a soft steel around the jiles-atherton-actuator-model's
                // ([JA Table 2]: b = 2.45 mT, α = 3.66e-3, c = 0.736, κ = 943
                // A/m) on the drawn path, B_sat → M_sat, and b such that the
                // anhysteretic curve's initial relative permeability is the
                // drawn μr (so the core's reluctance at small flux is the
                // linear cores' r0). On M = M_sat·L(μ0(H + αM)/b), L(x) ≈ x/3,
                // dM/dH at 0 is χ = k/(1 − α·k) with k = μ0·M_sat/(3b).
                let m_sat = phi_sat / self.area / MU0;
                let alpha = log_uniform(rng, 1e-3, 8e-3);
                let chi = self.mu_r - 1.0;
                let k = chi / (1.0 + alpha * chi);
                let b = MU0 * m_sat / (3.0 * k);
                format!(
                    "[core]\nmodel = \"jiles-atherton\"\nlength = {:e}\narea = {:e}\n\
                     m_sat = {m_sat:e}\nb = {b:e}\nc = {:e}\nkappa = {:e}\nalpha = {alpha:e}\n",
                    self.path,
                    self.area,
                    rng.uniform(0.3, 0.8),
                    log_uniform(rng, 50.0, 1000.0),
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_device_parses_and_rests_open_unpowered() {
        for d in devices(7, 30) {
            let desc = d.description();
            let m = &desc.mechanics;
            // unpowered: the passive force pushes towards z_max everywhere
            assert!(m.stiffness * m.z_max + m.preload < 0.0, "{}", d.name);
            assert!(desc.supply.u_max == d.supply);
        }
    }

    #[test]
    fn fifteen_consecutive_devices_cover_every_class_and_gap_model() {
        let ds = devices(3, 15);
        for class in CLASSES {
            for gap in GAPS {
                assert!(ds.iter().any(|d| d.class == class && d.gap == gap));
            }
        }
    }

    /// The core is a soft steel: on its anhysteretic curve the relative
    /// permeability at low flux is the drawn μr, so its reluctance there is
    /// the linear cores' r0 (the generator's first Jiles–Atherton cores had
    /// b of 0.1–0.4 T, μr ≈ 2–7: no supply could close them). (From a
    /// demagnetised core the initial curve is lower, χ₀ ≈ c·χ.)
    #[test]
    fn jiles_atherton_devices_parse_and_are_soft_steel() {
        use designer::description::Core;
        for i in 0..6 {
            let d = device(5, i, true);
            assert_eq!(d.core, CoreKind::JilesAtherton);
            let Core::JilesAtherton(ja) = d.description().core else {
                panic!("{}: not a Jiles–Atherton core", d.name);
            };
            // the same draw with the input-affine core (saturating below 15)
            let Core::Saturating { r0, .. } = device(5, i, false).description().core else {
                panic!("device {i} of family 5 is not saturating");
            };
            let b = 1e-3;
            let h = designer::model::anhysteretic_field(&ja, b);
            let reluctance = h * ja.length / (b * ja.area);
            assert!(
                (reluctance / r0 - 1.0).abs() < 1e-4,
                "{}: {reluctance} H⁻¹ against r0 = {r0}",
                d.name
            );
            let b_sat = MU0 * ja.m_sat;
            assert!((1.2..=2.7).contains(&b_sat), "{}: B_sat = {b_sat}", d.name);
        }
    }

    #[test]
    fn the_same_seed_gives_the_same_devices() {
        let (a, b) = (devices(11, 6), devices(11, 6));
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.toml, y.toml);
        }
        assert_ne!(devices(12, 1)[0].toml, a[0].toml);
    }
}
