//! The simulated position against the measured one, when the record has a
//! position column: the RMS error and the stroke it compares to.

use super::stats::range;

/// The simulated position against the measured one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionError {
    /// RMS of z_sim − z_meas [m].
    pub rms: f64,
    /// Range of the simulated position [m] (the stroke when the armature moves).
    pub stroke: f64,
}

/// The RMS of z_sim − z_meas over the finite samples, and the simulated stroke.
pub(super) fn position_error(z_sim: &[f64], z_meas: &[f64]) -> PositionError {
    let d: Vec<f64> = z_sim
        .iter()
        .zip(z_meas)
        .map(|(a, b)| a - b)
        .filter(|d| d.is_finite())
        .collect();
    let (lo, hi) = range(z_sim);
    PositionError {
        rms: (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt(),
        stroke: hi - lo,
    }
}

#[cfg(test)]
mod tests {
    use super::super::bench::bench;
    use super::super::{localise, Signals};

    #[test]
    fn measured_position_is_compared() {
        let b = bench();
        let n = b.t.len();
        let z_sim: Vec<f64> = (0..n)
            .map(|k| if b.moving[k] { 1e-4 } else { 5e-4 })
            .collect();
        let z_meas: Vec<f64> = z_sim.iter().map(|z| z + 2e-5).collect();
        let ones = vec![1.0; n];
        let l = localise(&Signals {
            t: &b.t,
            v: &b.v,
            i_measured: &b.i,
            i_simulated: &b.i,
            weight: &ones,
            z_simulated: &z_sim,
            moving: &b.moving,
            impacts: &b.impacts,
            flux_simulated: &b.flux,
            z_measured: Some(&z_meas),
        });
        let p = l.position.unwrap();
        assert!((p.rms - 2e-5).abs() < 1e-12 && (p.stroke - 4e-4).abs() < 1e-12);
        assert!(l.to_string().contains("5 % of the stroke"), "{l}");
    }
}
