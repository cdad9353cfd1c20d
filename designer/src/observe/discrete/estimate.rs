//! What the designer's filters report at each sample.

use crate::sim::Mode;

/// What the filters output at each sample: the posterior estimate, which is
/// what the controllers consume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// z [m]
    pub z: f64,
    /// v [m/s] of [JA 85]
    pub v: f64,
    /// a [m/s²] of [JA 87]
    pub a: f64,
    /// φ [Wb]
    pub phi: f64,
    /// H_c [A/m] (Jiles–Atherton core only)
    pub hc: Option<f64>,
    /// R [Ω] (when estimated)
    pub r: Option<f64>,
    /// [JA 86], with the band of [`super::DiscreteModel::mode_band`]
    pub mode: Mode,
}

impl From<reldesign_runtime::observe::Estimate<f64>> for Estimate {
    /// The runtime's estimate with its mode q of [JA 86] as a [`Mode`].
    fn from(e: reldesign_runtime::observe::Estimate<f64>) -> Estimate {
        Estimate {
            z: e.z,
            v: e.v,
            a: e.a,
            phi: e.phi,
            hc: e.hc,
            r: e.r,
            mode: match e.mode {
                1 => Mode::StuckMin,
                3 => Mode::StuckMax,
                _ => Mode::Free,
            },
        }
    }
}
