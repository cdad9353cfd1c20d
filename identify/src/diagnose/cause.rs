//! The vocabulary of causes (`shared/spec/measured-data.md`): each names one
//! extension of the actuator description, `none` names the model as it is.

use std::fmt;
use std::str::FromStr;

/// One cause of a model–data discrepancy, as the spec names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Cause {
    /// `coil.eddy` > 0.
    EddyCurrents,
    /// `core.model = "saturating"` instead of `linear`.
    Saturation,
    /// `core.model = "jiles-atherton"` instead of `linear` / `saturating`.
    Hysteresis,
    /// `gap.model = "mclyman"` instead of `linear`.
    Fringing,
    /// `coil.resistance_drift` ≠ 0.
    ResistanceDrift,
    /// `mechanics.restitution` > 0.
    Bouncing,
    /// The model already explains the data within its noise.
    None,
    /// The residual stays well above the noise after the best extension(s):
    /// something outside this vocabulary. An answer, never a candidate.
    Unexplained,
}

impl Cause {
    /// Every extension of the vocabulary (all causes but `none`), in spec order.
    pub const EXTENSIONS: [Cause; 6] = [
        Cause::EddyCurrents,
        Cause::Saturation,
        Cause::Hysteresis,
        Cause::Fringing,
        Cause::ResistanceDrift,
        Cause::Bouncing,
    ];

    /// The spec's name (`eddy-currents`, …, `none`).
    pub fn name(self) -> &'static str {
        match self {
            Cause::EddyCurrents => "eddy-currents",
            Cause::Saturation => "saturation",
            Cause::Hysteresis => "hysteresis",
            Cause::Fringing => "fringing",
            Cause::ResistanceDrift => "resistance-drift",
            Cause::Bouncing => "bouncing",
            Cause::None => "none",
            Cause::Unexplained => "unexplained",
        }
    }
}

impl fmt::Display for Cause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Cause {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Cause::EXTENSIONS
            .into_iter()
            .chain([Cause::None])
            .find(|c| c.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown cause `{s}` (expected one of: eddy-currents, saturation, \
                     hysteresis, fringing, resistance-drift, bouncing, none)"
                )
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for c in Cause::EXTENSIONS.into_iter().chain([Cause::None]) {
            assert_eq!(c.name().parse::<Cause>(), Ok(c));
        }
        assert!("eddy".parse::<Cause>().is_err());
    }
}
