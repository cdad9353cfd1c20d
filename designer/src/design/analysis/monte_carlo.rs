//! The sliding-mode robustness of a whole design, nominal and over parameter
//! bounds by Monte Carlo (model-free-sliding-mode-soft-landing [SM §4.1], last
//! paragraph: the worst case over every parameter within its bounds).
//!
//! The references are the design's (`[trajectory]`), as the emitted code
//! tracks them; each draw changes the device, not the design. A draw varies every key of
//! `--vary KEY=±P%` uniformly within ±P % of its nominal value; draw k is
//! generated from (seed, k) alone, so the answer does not depend on the
//! number of threads. The draws run in parallel with the `parallel` feature
//! (`designer/src/parallel.rs`).

use crate::description::{params, Description, Law, Operation, SlidingSurface};
use crate::model::Model;
use crate::parallel;
use crate::random::SplitMix64;

use super::robustness::{operation_end, ErrorBounds, Evaluator, Robustness};
use crate::design::derive::linearization::Linearization;
use crate::design::plan::{design_reference, SharedReference};

/// Why an analysis could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RobustnessError {
    #[error(
        "the robustness bound (model-free-sliding-mode (49)) is the sliding-mode law's: the \
         description needs [trajectory] and [controller] with law = \"sliding-mode\" \
         (lambda1, lambda2, eta){found}"
    )]
    NotSlidingMode { found: String },
    #[error("--vary {text}: {problem}")]
    Variation { text: String, problem: String },
    #[error("--vary {path}: draw {draw} gives {value:e}, outside the key's domain ({expected}); use a smaller ±P %")]
    OutOfDomain {
        path: String,
        draw: usize,
        value: f64,
        expected: String,
    },
    #[error("{0}")]
    Design(String),
    #[error("--draws must be at least 1")]
    NoDraws,
    #[error("internal error: the model of draw {draw} lacks the parameter `{name}`")]
    Parameter { draw: usize, name: String },
}

/// Keys that act at the impacts only, not along the reference.
const IMPACT_ONLY: [&str; 2] = ["mechanics.restitution", "mechanics.bounce_threshold"];

/// `KEY=±P%`: the key's value varies uniformly within ±P % of its nominal.
#[derive(Debug, Clone, PartialEq)]
pub struct Variation {
    pub path: String,
    /// P/100.
    pub fraction: f64,
}

impl Variation {
    /// Reads `KEY=±P%` (also `KEY=P%`) for the description `d`: the key must
    /// be one of its numeric model parameters.
    pub fn parse(text: &str, d: &Description) -> Result<Variation, RobustnessError> {
        let bad = |problem: String| RobustnessError::Variation {
            text: text.to_owned(),
            problem,
        };
        let (path, amount) = text
            .split_once('=')
            .ok_or_else(|| bad("expected KEY=±P% (e.g. coil.resistance=±10%)".into()))?;
        let path = path.trim();
        params::domain(d, path).map_err(|e| bad(e.to_string()))?;
        if IMPACT_ONLY.contains(&path) {
            return Err(bad(format!(
                "`{path}` acts at impacts only and does not enter the bound (49); vary a key of \
                 the coil, gap, core or the motion"
            )));
        }
        let number = amount
            .trim()
            .trim_start_matches('±')
            .trim_start_matches("+-")
            .strip_suffix('%')
            .ok_or_else(|| bad(format!("expected ±P% after `=`, found `{amount}`")))?;
        let percent: f64 = number
            .trim()
            .parse()
            .map_err(|_| bad(format!("`{number}` is not a number of percent")))?;
        if !(percent.is_finite() && (0.0..100.0).contains(&percent)) {
            return Err(bad(format!("expected 0 ≤ P < 100, found {percent}")));
        }
        Ok(Variation {
            path: path.to_owned(),
            fraction: percent / 100.0,
        })
    }
}

/// The nominal analysis: one entry per designed operation.
#[derive(Debug, Clone)]
pub struct Nominal {
    pub operations: Vec<(Operation, Robustness)>,
    /// The supply [u_min, u_max].
    pub u_min: f64,
    pub u_max: f64,
}

/// One Monte-Carlo draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Draw {
    pub index: usize,
    /// The varied keys and their values.
    pub values: Vec<(String, f64)>,
    /// The largest required u_max over the operations (∞ where a reference
    /// is infeasible for this device).
    pub required_u_max: f64,
    /// The supply meets [SM 49] on both sides for every operation.
    pub met: bool,
}

/// The running summary of draws: the worst so far (the lowest index among
/// equals) and how many the supply meets.
struct Tally {
    worst: Option<Draw>,
    met: usize,
}

impl Tally {
    fn empty() -> Tally {
        Tally {
            worst: None,
            met: 0,
        }
    }

    fn of(d: Draw) -> Tally {
        Tally {
            met: usize::from(d.met),
            worst: Some(d),
        }
    }

    fn merge(self, other: Tally) -> Tally {
        let worst = match (self.worst, other.worst) {
            (Some(a), Some(b)) => Some(worse(a, b)),
            (a, b) => a.or(b),
        };
        Tally {
            worst,
            met: self.met + other.met,
        }
    }
}

/// The draw needing the larger u_max; on a tie the lower index.
fn worse(a: Draw, b: Draw) -> Draw {
    match a.required_u_max.total_cmp(&b.required_u_max) {
        std::cmp::Ordering::Greater => a,
        std::cmp::Ordering::Less => b,
        std::cmp::Ordering::Equal if a.index <= b.index => a,
        std::cmp::Ordering::Equal => b,
    }
}

/// The Monte-Carlo summary.
#[derive(Debug, Clone, PartialEq)]
pub struct MonteCarlo {
    pub draws: usize,
    /// The draw with the largest required u_max (the first, on ties).
    pub worst: Draw,
    /// The share of draws whose required u_max the supply meets.
    pub share_met: f64,
}

/// The design's references and the model functions, ready for any device.
pub struct Analysis<'a> {
    description: &'a Description,
    model: Model,
    evaluator: Evaluator,
    surface: SlidingSurface,
    bounds: ErrorBounds,
    samples: usize,
    t_end: f64,
    references: Vec<(Operation, SharedReference)>,
}

impl<'a> Analysis<'a> {
    /// The analysis of the references `[trajectory]` designs (not refused
    /// where infeasible: the analysis says where), with `samples` + 1
    /// instants per operation and the error bounds [SM 52].
    pub fn new(
        description: &'a Description,
        bounds: ErrorBounds,
        samples: usize,
    ) -> Result<Analysis<'a>, RobustnessError> {
        let d = description;
        let surface = match (&d.controller, &d.trajectory) {
            (Some(c), Some(_)) => match c.law {
                Law::SlidingMode(s) => Ok(s),
                other => Err(format!(", found law = \"{}\"", other.name())),
            },
            (None, _) => Err(", found no [controller]".into()),
            (Some(_), None) => Err(", found no [trajectory]".into()),
        }
        .map_err(|found| RobustnessError::NotSlidingMode { found })?;
        let Some(t) = &d.trajectory else {
            return Err(RobustnessError::NotSlidingMode {
                found: String::new(),
            });
        };
        let design = |e: &dyn std::fmt::Display| RobustnessError::Design(e.to_string());
        let mut model = Model::build(d);
        let lin = Linearization::derive(&mut model).map_err(|e| design(&e))?;
        let references = t
            .operations
            .iter()
            .map(|&op| {
                design_reference(d, &mut model, &lin, op)
                    .map(|(r, _)| (op, r))
                    .map_err(|e| design(&e))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Analysis {
            description,
            evaluator: Evaluator::new(&model, &lin),
            model,
            surface,
            bounds,
            samples,
            t_end: operation_end(t.takeoff, t.landing),
            references,
        })
    }

    /// Every operation at the parameter values `p`.
    fn operations(&self, p: &[f64]) -> Vec<(Operation, Robustness)> {
        self.references
            .iter()
            .map(|(op, r)| {
                let analysis = self.evaluator.analyse(
                    r.as_ref(),
                    self.t_end,
                    self.samples,
                    &self.surface,
                    &self.bounds,
                    p,
                );
                (*op, analysis)
            })
            .collect()
    }

    /// The description's own device.
    pub fn nominal(&self) -> Nominal {
        let p = self.evaluator.values(&self.model).unwrap_or_default();
        Nominal {
            operations: self.operations(&p),
            u_min: self.description.supply.u_min,
            u_max: self.description.supply.u_max,
        }
    }

    /// `draws` devices within `variations`, from `seed`; `progress` is
    /// called once per finished draw (from any thread).
    pub fn monte_carlo(
        &self,
        variations: &[Variation],
        draws: usize,
        seed: u64,
        progress: &(dyn Fn() + Sync),
    ) -> Result<MonteCarlo, RobustnessError> {
        if draws == 0 {
            return Err(RobustnessError::NoDraws);
        }
        // reduced as they come (no list of every draw), associatively, so the
        // answer is the same whatever the split between threads
        let tally = parallel::try_map_reduce(
            draws,
            |k| {
                let draw = self.draw(variations, seed, k);
                progress();
                draw.map(Tally::of)
            },
            Tally::empty,
            Tally::merge,
        )?;
        let worst = tally.worst.ok_or(RobustnessError::NoDraws)?;
        Ok(MonteCarlo {
            draws,
            worst,
            share_met: tally.met as f64 / draws as f64,
        })
    }

    /// Draw `k`: the varied description, its model's parameter values, the
    /// required u_max.
    fn draw(&self, variations: &[Variation], seed: u64, k: usize) -> Result<Draw, RobustnessError> {
        let mut rng = SplitMix64::for_stream(seed, k as u64);
        let mut d = self.description.clone();
        let mut values = Vec::with_capacity(variations.len());
        for v in variations {
            let nominal = params::get(&d, &v.path).map_err(|e| RobustnessError::Variation {
                text: v.path.clone(),
                problem: e.to_string(),
            })?;
            let value = nominal * (1.0 + v.fraction * (2.0 * rng.uniform() - 1.0));
            params::set(&mut d, &v.path, value).map_err(|_| RobustnessError::OutOfDomain {
                path: v.path.clone(),
                draw: k,
                value,
                expected: params::domain(&d, &v.path)
                    .map_or_else(|_| String::new(), |dom| dom.text()),
            })?;
            values.push((v.path.clone(), value));
        }
        let model = Model::build(&d);
        let p = self
            .evaluator
            .values(&model)
            .map_err(|name| RobustnessError::Parameter { draw: k, name })?;
        let operations = self.operations(&p);
        let required_u_max = operations
            .iter()
            .map(|(_, r)| {
                if r.feasible {
                    r.required_u_max
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::NEG_INFINITY, f64::max);
        let supply = &self.description.supply;
        Ok(Draw {
            index: k,
            values,
            required_u_max,
            met: operations
                .iter()
                .all(|(_, r)| r.met(supply.u_min, supply.u_max)),
        })
    }
}
