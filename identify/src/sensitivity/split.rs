//! The sensitivities of a long record in two halves, side by side.
//!
//! S′ = f_x·S + f_θ is linear in S, and so is every update of one pass
//! (an RK4 or Radau step, an impact's saltation, a stick): over the second
//! half, S(t) = S₂(t) + Φ(t)·S(t_mid), with S₂ the pass from S = 0 and Φ the
//! fundamental matrix, Φ(t_mid) = I. Φ is d more columns of the same pass,
//! homogeneous like a step's column (no f_θ, no jump); a step's jump and the
//! restitution's are affine, in S₂ alone. The two halves are the same
//! arithmetic as one pass but for the sum's rounding, and each evaluates the
//! tape on its own samples: on two cores the pass takes about half as long.
//!
//! Only where the columns outnumber the states three times ([`worth_it`]):
//! the d columns of Φ then cost less against them (the polish's 23 columns
//! on 4 states: 40 % more work, done in 0.73 of the time on two cores).
//! Those are the polish's last fit (the values and the edges' instants on
//! the whole record), which runs once the other core is free, and the joint
//! fit's. Not the ranking's (2–6 columns), the recalibration's (6–7 on 3
//! states) nor the polish's first stage (11 on 4), which run beside other
//! fits: split on a busy core they only cost more (twice the columns
//! instead of three times: 0.09 s more on the hysteresis benchmark record,
//! 2.20 s against 2.10 s over six runs each).

use nalgebra::DMatrix;

use super::{along_from, Field, InputStep, OutputSensitivities, Theta, Unsupported};
use crate::model::Model;
use crate::sim::{Input, Trajectory};

/// Records of at least this many samples are split, …
pub const MIN_SAMPLES: usize = 2000;

/// … where there are at least three times as many columns as states.
pub(super) fn worth_it(samples: usize, states: usize, columns: usize) -> bool {
    samples >= MIN_SAMPLES && columns >= 3 * states
}

/// `super::along` of `theta`'s columns (the steps' from `first_step` on)
/// in two halves run side by side.
pub(super) fn along_in_halves<I: Input + Sync + ?Sized>(
    model: &Model,
    theta: &[Theta],
    first_step: usize,
    steps: &[InputStep],
    trajectory: &Trajectory,
    input: &I,
) -> Result<OutputSensitivities, Unsupported> {
    let (n, d, p) = (trajectory.len(), model.dim(), theta.len());
    // Half 2 takes the steps before its first sample as applied; a step
    // right at it is applied by half 1 only where an event falls there too
    // (the pass applies a step at an interval's end in the next interval,
    // unless an event there makes it go round once more): not there.
    let t = &trajectory.t;
    let mut mid = n / 2;
    while mid + 1 < n && steps.iter().any(|e| e.t == t[mid]) {
        mid += 1;
    }
    // the second half's columns: the parameters', Φ's, the steps'
    let mut theta2 = theta[..first_step].to_vec();
    theta2.extend(std::iter::repeat(Theta::StepInstant).take(d));
    theta2.extend_from_slice(&theta[first_step..]);
    let p2 = theta2.len();
    let mut s0 = vec![0.0; d * p2];
    for i in 0..d {
        s0[i * p2 + first_step + i] = 1.0;
    }
    let (first, second) = rayon::join(
        || {
            let mut model = model.clone();
            let field = Field::new(&mut model, theta, None);
            along_from(
                &field,
                first_step,
                steps,
                &slice(trajectory, 0, mid + 1),
                input,
                None,
            )
        },
        || {
            let mut model = model.clone();
            let field = Field::new(&mut model, &theta2, None);
            let tail = slice(trajectory, mid, n);
            along_from(&field, first_step + d, steps, &tail, input, Some(s0))
        },
    );
    let (head, s_mid) = first?;
    let (tail, _) = second?;
    // the second half's column of the first half's column j
    let column = |j: usize| if j < first_step { j } else { j + d };
    let joined = |a: &DMatrix<f64>, b: &DMatrix<f64>| {
        DMatrix::from_fn(n, p, |k, j| match k <= mid {
            true => a[(k, j)],
            false => {
                let r = k - mid;
                let through_mid: f64 = (0..d)
                    .map(|m| b[(r, first_step + m)] * s_mid[m * p + j])
                    .sum();
                b[(r, column(j))] + through_mid
            }
        })
    };
    Ok(OutputSensitivities {
        current: joined(&head.current, &tail.current),
        z: joined(&head.z, &tail.z),
        phi: joined(&head.phi, &tail.phi),
        radau_intervals: head.radau_intervals + tail.radau_intervals,
        rk4_intervals: head.rk4_intervals + tail.rk4_intervals,
    })
}

/// Samples `from..to` of `trajectory` (every event kept: a pass skips those
/// at or before its first sample).
fn slice(trajectory: &Trajectory, from: usize, to: usize) -> Trajectory {
    Trajectory {
        t: trajectory.t[from..to].to_vec(),
        x: trajectory.x[from..to].to_vec(),
        u: trajectory.u[from..to].to_vec(),
        mode: trajectory.mode[from..to].to_vec(),
        events: trajectory.events.clone(),
        ..Trajectory::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::{parse_file, Description};
    use crate::sensitivity::{along, symbols};
    use crate::sim::{EventKind, Options, PiecewiseLinear};
    use crate::Measured;

    fn example(name: &str) -> Description {
        let path = format!("{}/../examples/{name}", env!("CARGO_MANIFEST_DIR"));
        parse_file(std::path::Path::new(&path)).expect("the example parses")
    }

    /// 3 000 samples every 20 µs: `high` volts in [0, 700) and [1400,
    /// 2100), else 0 (the halves meet inside the second pulse).
    fn pulses(high: f64) -> Measured {
        let n = 3000;
        let on = |k: usize| (k < 700) || (1400..2100).contains(&k);
        Measured {
            t: (0..n).map(|k| k as f64 * 20e-6).collect(),
            v: (0..n).map(|k| if on(k) { high } else { 0.0 }).collect(),
            i: vec![0.0; n],
            z: None,
            phi: None,
            lambda: None,
            dt: 20e-6,
            file_name: "synthetic.csv".into(),
            edges: None,
        }
    }

    /// One pass and two halves of `paths` and a step at each of the
    /// record's three voltage edges, each column's largest difference
    /// relative to its largest value, and the replay's events after the
    /// halves' meeting.
    fn difference(d: &Description, paths: &[&str]) -> (f64, Vec<EventKind>) {
        let data = pulses(24.0);
        let input: PiecewiseLinear = crate::edges::replay_input(&data).unwrap();
        let mut model = Model::build(d);
        let options = Options {
            rtol: 1e-10,
            max_steps: 10_000_000,
            ..Options::default()
        };
        let replay = crate::replay::replay(&mut model, &input, &data.t, &options).unwrap();
        let steps: Vec<InputStep> = [699, 1399, 2099]
            .iter()
            .map(|&k| InputStep {
                t: data.t[k],
                before: data.v[k],
                after: data.v[k + 1],
            })
            .collect();
        let mut theta = symbols(&model, paths).unwrap();
        theta.extend(steps.iter().map(|_| Theta::StepInstant));
        let tr = &replay.trajectory;
        let halves = along_in_halves(&model, &theta, paths.len(), &steps, tr, &input).unwrap();
        let mut one_model = model.clone();
        let field = Field::new(&mut one_model, &theta, None);
        let one = along(&field, paths.len(), &steps, tr, &input).unwrap();
        let worst = [
            (&one.current, &halves.current),
            (&one.z, &halves.z),
            (&one.phi, &halves.phi),
        ]
        .iter()
        .flat_map(|(a, b)| {
            (0..a.ncols()).map(move |j| {
                let scale = a.column(j).amax();
                let diff = (a.column(j) - b.column(j)).amax();
                if scale > 0.0 {
                    diff / scale
                } else {
                    diff
                }
            })
        })
        .fold(0.0, f64::max);
        assert_eq!(
            (one.radau_intervals, one.rk4_intervals),
            (halves.radau_intervals, halves.rk4_intervals)
        );
        eprintln!("largest relative difference {worst:e}");
        let t_mid = tr.t[tr.len() / 2];
        let later = tr.events.iter().filter(|e| e.t > t_mid);
        (worst, later.map(|e| e.kind).collect())
    }

    #[test]
    fn only_long_records_with_many_columns_are_split() {
        // the polish's last fit on a Jiles–Atherton core: 6 values, 17 edges
        assert!(worth_it(12_000, 4, 23));
        // its first stage, the recalibration, the ranking's fits
        assert!(!worth_it(3_693, 4, 11) && !worth_it(12_000, 3, 7));
        assert!(!worth_it(12_000, 4, 6) && !worth_it(MIN_SAMPLES - 1, 3, 30));
    }

    #[test]
    fn two_halves_give_one_pass_through_impacts_and_bounces() {
        let mut d = example("semera-valve.toml");
        crate::params::set(&mut d, "coil.eddy", 2e3).unwrap();
        let paths = [
            "coil.resistance",
            "coil.eddy",
            "core.phi_sat",
            "gap.slope",
            "mechanics.stiffness",
            "mechanics.restitution",
        ];
        let (worst, later) = difference(&d, &paths);
        // bounces in the second half: its Φ passes through their saltations
        let bounces = (later.iter())
            .filter(|e| matches!(e, EventKind::Impact { v_after, .. } if *v_after != 0.0))
            .count();
        assert!(bounces >= 2, "{later:?}");
        assert!(worst < 1e-12, "largest relative difference {worst:e}");
    }

    #[test]
    fn two_halves_give_one_pass_on_a_jiles_atherton_core() {
        let d = example("jiles-atherton-valve.toml");
        let paths = [
            "coil.resistance",
            "core.m_sat",
            "core.b",
            "core.c",
            "core.kappa",
            "core.length",
        ];
        let (worst, _) = difference(&d, &paths);
        assert!(worst < 1e-12, "largest relative difference {worst:e}");
    }
}
