//! Edge timing: whether the residual after the voltage steps is what a step
//! placed off its instant explains, rather than a cause of the model.
//!
//! A voltage step falls anywhere inside its sample interval; where the replay
//! places it off by δ, the current right after it is off by about the
//! current's slope change × δ, at most half a sample's worth:
//! ½·|(i_{k+1} − i_k) − (i_{k−1} − i_{k−2})| for the step's first sample k.
//! A step is *within timing* when the residual over its first
//! [`TIMING_SAMPLES`] samples stays below that bound plus 3 σ of the current
//! noise ([`noise_std`]: the median absolute second
//! difference). When the residual concentrates after the steps and at least
//! 80 % of them are within timing, the report says the error is edge timing,
//! not a cause.

use crate::diagnose::rank::noise_std;

/// Samples after a step whose residual edge timing may explain.
const TIMING_SAMPLES: usize = 3;
/// Fraction of the steps within timing for the report to blame the timing.
const TIMING_SHARE: f64 = 0.8;

/// How many voltage steps have a residual within what their timing explains.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgeTiming {
    /// Steps with samples on both sides to judge.
    pub steps: usize,
    /// Steps whose residual stays within the edge-timing bound.
    pub within: usize,
}

impl EdgeTiming {
    /// Whether at least 80 % of the steps are within timing.
    pub fn explains(&self) -> bool {
        self.steps > 0 && self.within as f64 >= TIMING_SHARE * self.steps as f64
    }
}

/// The steps (first samples after each) whose residual stays within the
/// edge-timing bound (see the module documentation).
pub(super) fn edge_timing(i: &[f64], r: &[f64], steps: &[usize]) -> EdgeTiming {
    let sigma = noise_std(i);
    let judged: Vec<bool> = steps
        .iter()
        .filter(|&&k| k >= 2 && k + TIMING_SAMPLES < i.len())
        .map(|&k| {
            let bound = 0.5 * ((i[k + 1] - i[k]) - (i[k - 1] - i[k - 2])).abs() + 3.0 * sigma;
            r[k..k + TIMING_SAMPLES]
                .iter()
                .all(|x| x.is_finite() && x.abs() <= bound)
        })
        .collect();
    EdgeTiming {
        steps: judged.len(),
        within: judged.iter().filter(|&&b| b).count(),
    }
}

#[cfg(test)]
mod tests {
    use super::super::bench::{bench, run_with_noise, top, DT, TAU};
    use crate::diagnose::localise::Region;

    /// A replay whose steps are 0.4 sample late: the current lags by the
    /// slope change × 0.4·Δ after each step, decaying with τ.
    #[test]
    fn residual_of_steps_placed_off_their_instant_is_edge_timing() {
        let b = bench();
        // Slope change at a step: ±(24 V / 12 Ω)/τ.
        let lag = 0.4 * DT * 2.0 / TAU;
        let l = run_with_noise(
            &b,
            |k| {
                let sign = if b.v[k] > 12.0 { -1.0 } else { 1.0 };
                sign * lag * (-b.since_step[k] / TAU).exp()
            },
            0.002,
        );
        assert_eq!(top(&l), Region::AfterVoltageSteps, "{l}");
        assert!(l.is_edge_timing(), "{:?}\n{l}", l.edge_timing);
        assert!(l.to_string().contains("edge timing"), "{l}");
    }
}
