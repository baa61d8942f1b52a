//! A study's multibody scene as a multi-objective problem: the objectives
//! of `[front]` with `[problem] name = "scene"`.
//!
//! Each `[[front.objectives]]` names a `[[scene.responses]]` entry
//! (`{ name = "psi0" }`, `{ name = "u3_peak", goal = "maximize" }`). The
//! variables, the start design, the constraints (`g_j = R_j/c_j − 1 <= 0`)
//! and the exact gradients (per degree) are the scene problem's
//! ([`crate::explore::problem::scene_problem`]); `[scene_problem.objective]` is not an
//! objective of the front, its `normalize_at` only chooses the design
//! where the objectives are normalised.
//!
//! **Normalisation.** Objective `i` is `f_i = R_i(x) / |R_i(x_n)|` with
//! `x_n` the `[scene_problem.objective] normalize_at` design when given,
//! else the `[scene_problem] start` design: every objective is about 1 at
//! that design, whatever its unit, so that the subproblems' tolerances
//! and the Tchebycheff scaling see numbers of order one. The response in
//! its own unit is `R_i = f_i · |R_i(x_n)|`
//! ([`MultiProblem::objective_scale`]); `front.csv`, `grid.csv` and the
//! plots are written in those units.
//!
//! **One simulation per design.** A simulation gives every response and
//! its gradient at once, so an evaluation simulates once for all
//! objectives and constraints, and designs already simulated are not
//! simulated again: evaluations are cached by the design's bits (an
//! evaluation with gradients also answers a later one without, with its
//! values: a simulation with sensitivity lanes is not bit-identical to
//! one without, they agree to about the integrator's tolerance). The
//! methods' function calls are counted as the optimizers ask for them;
//! [`MultiProblem::simulations`] counts the simulations actually run.
//!
//! **Peaks as pieces.** A minimized `peak` response (a maximum over time)
//! whose `[[front.objectives]]` entry names `critical_points = K` is the
//! largest of `K` smooth pieces, the response at its `K` largest local
//! maxima in time (the peak where it has fewer): the evaluation carries
//! pieces 2 to `K` ([`MultiEvaluation::pieces`], normalised as the
//! objective), and the gradient side's scalarizations take the objective
//! piece by piece (`optimize::multiobjective`'s module doc), as the
//! constraints of `[[scene_problem.constraints]]` take a peak's critical
//! points (`scene_bounds`).

use super::scene_bounds::MAX_CRITICAL_POINTS;
use super::scene_problem::{peak_sense, SceneProblem, SceneProblemSpec};
use crate::error::{Error, Result};
use crate::mbs::responses::Sense;
use crate::optimize::multiobjective::{MultiEvaluation, MultiProblem};
use crate::optimize::Variable;
use crate::study::Study;
use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The scene's responses as objectives (see the module doc).
pub struct SceneFrontProblem {
    inner: SceneProblem,
    /// The objectives' response names, in `[front]` order.
    names: Vec<String>,
    /// Their units (`J*s`, `J`, ...).
    units: Vec<String>,
    /// `|R_i(x_n)|`.
    scales: Vec<f64>,
    /// Evaluations by the bits of their design.
    cache: Mutex<HashMap<Vec<u64>, MultiEvaluation>>,
    /// Simulations run (cache misses).
    simulations: AtomicUsize,
    /// Each objective's pieces `K_i` (1: the response alone).
    points: Vec<usize>,
}

/// `[scene_problem]` as parsed (for `normalize_at`).
fn spec(study: &Study) -> Result<SceneProblemSpec> {
    study.require_section(
        "scene_problem",
        "the scene problem (variables, start, objective)",
    )
}

impl SceneFrontProblem {
    /// Check that every name is a `[[scene.responses]]` entry (key
    /// `front.objectives[k].name`) and `[scene_problem]` is valid, without
    /// simulating.
    pub fn check(study: &Study, names: &[String]) -> Result<()> {
        SceneProblem::check(study)?;
        let plan = crate::scene::ScenePlan::new(study)?;
        let known: Vec<&str> = (plan.spec().responses.iter())
            .map(|r| r.name.as_str())
            .collect();
        for (k, n) in names.iter().enumerate() {
            if !known.contains(&n.as_str()) {
                return Err(study.error(
                    format!("front.objectives[{k}].name"),
                    format!("\"{n}\""),
                    format!("a [[scene.responses]] name ({})", known.join(", ")),
                ));
            }
        }
        Ok(())
    }

    /// Build from a study with `[scene]`, `[[panels]]` and
    /// `[scene_problem]`, with the responses `names` as objectives; the
    /// scene problem evaluates its start design once (the constraints'
    /// references) and this its normalisation design once more.
    pub fn from_study(study: &Study, names: &[String]) -> Result<SceneFrontProblem> {
        Self::check(study, names)?;
        let inner = SceneProblem::from_study(study)?;
        let spec = spec(study)?;
        let at = (spec.objective.normalize_at.clone()).unwrap_or_else(|| spec.start.clone());
        let (_, extra, _) = inner.evaluate_with(&at, false, names)?;
        for (k, (n, v)) in names.iter().zip(&extra.values).enumerate() {
            if !(v.is_finite() && *v != 0.0) {
                return Err(study.error(
                    format!("front.objectives[{k}].name"),
                    format!("\"{n}\""),
                    format!(
                        "a response that is not zero at the normalisation design {at:?} (it is {v:e})"
                    ),
                ));
            }
        }
        let units = extra.units.clone();
        Ok(SceneFrontProblem {
            inner,
            names: names.to_vec(),
            units,
            scales: extra.values.iter().map(|v| v.abs()).collect(),
            cache: Mutex::new(HashMap::new()),
            simulations: AtomicUsize::new(0),
            points: vec![1; names.len()],
        })
    }

    /// Objective `i` as the largest of `points[i]` pieces (module doc;
    /// checked by [`SceneFrontProblem::check_points`]).
    pub fn with_points(mut self, points: Vec<usize>) -> SceneFrontProblem {
        self.points = points;
        self
    }

    /// Each objective's `critical_points` (`points[k]`: the count given,
    /// and whether the objective is maximized) is 1 to
    /// [`MAX_CRITICAL_POINTS`] on a minimized `peak` response of sense
    /// `max` (key `front.objectives[k].critical_points`).
    pub fn check_points(
        study: &Study,
        names: &[String],
        points: &[(Option<usize>, bool)],
    ) -> Result<()> {
        let plan = crate::scene::ScenePlan::new(study)?;
        for (k, (name, &(count, maximize))) in names.iter().zip(points).enumerate() {
            let Some(count) = count else { continue };
            let expected = if !(1..=MAX_CRITICAL_POINTS).contains(&count) {
                format!("a count from 1 to {MAX_CRITICAL_POINTS}")
            } else if peak_sense(plan.spec(), name) != Some(Sense::Max) {
                format!("a `peak` response of sense `max` (\"{name}\" is not)")
            } else if maximize {
                "a minimized objective (a maximized peak is no maximum of pieces)".into()
            } else {
                continue;
            };
            return Err(study.error(
                format!("front.objectives[{k}].critical_points"),
                count,
                expected,
            ));
        }
        Ok(())
    }

    /// `|R_i(x_n)|`, the divisors of the objectives (response units).
    pub fn scales(&self) -> &[f64] {
        &self.scales
    }

    fn simulate(&self, x: &[f64], gradients: bool) -> Result<MultiEvaluation> {
        self.simulations.fetch_add(1, Ordering::Relaxed);
        // The objectives, then each one's further pieces, with its scale.
        let mut at: Vec<(String, usize)> = self.names.iter().map(|n| (n.clone(), 0)).collect();
        let mut scales = self.scales.clone();
        for (i, &k) in self.points.iter().enumerate() {
            at.extend((1..k).map(|p| (self.names[i].clone(), p)));
            scales.extend((1..k).map(|_| self.scales[i]));
        }
        let (e, extra, _) = self.inner.evaluate_at_points(x, gradients, &at)?;
        let mut f: Vec<f64> = (extra.values.iter().zip(&scales))
            .map(|(v, s)| v / s)
            .collect();
        let mut grad_f: Option<Vec<Vec<f64>>> = extra.gradients.map(|rows| {
            (rows.iter().zip(&scales))
                .map(|(row, s)| row.iter().map(|v| v / s).collect())
                .collect()
        });
        let m = self.names.len();
        Ok(MultiEvaluation {
            pieces: f.split_off(m),
            grad_pieces: grad_f.as_mut().map(|rows| rows.split_off(m)),
            f,
            g: e.g,
            grad_f,
            grad_g: e.grad_g,
        })
    }
}

impl MultiProblem for SceneFrontProblem {
    fn variables(&self) -> &[Variable] {
        crate::optimize::Problem::variables(&self.inner)
    }
    fn objective_names(&self) -> Vec<String> {
        self.names.clone()
    }
    fn n_constraints(&self) -> usize {
        crate::optimize::Problem::n_constraints(&self.inner)
    }
    /// One simulation for every objective and constraint, or none when the
    /// design was simulated before (with gradients, when they are asked).
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<MultiEvaluation> {
        let key: Vec<u64> = x.iter().map(|v| v.to_bits()).collect();
        let cache = || {
            self.cache.lock().map_err(|_| {
                Error::numerical("explore::scene_front", "an evaluation thread panicked")
            })
        };
        if let Some(e) = cache()?.get(&key) {
            if !gradients || e.grad_f.is_some() {
                let mut e = e.clone();
                if !gradients {
                    (e.grad_f, e.grad_g) = (None, None);
                }
                return Ok(e);
            }
        }
        let e = self.simulate(x, gradients)?;
        cache()?.insert(key, e.clone());
        Ok(e)
    }
    fn objective_pieces(&self, i: usize) -> usize {
        self.points[i]
    }
    fn name(&self) -> &str {
        crate::optimize::Problem::name(&self.inner)
    }
    /// The response's name and unit: `psi0 [J*s]`.
    fn objective_label(&self, i: usize) -> String {
        format!("{} [{}]", self.names[i], self.units[i])
    }
    fn objective_unit(&self, i: usize) -> Option<String> {
        Some(self.units[i].clone())
    }
    fn objective_scale(&self, i: usize) -> f64 {
        self.scales[i]
    }
    fn start(&self) -> Vec<f64> {
        self.inner.start().to_vec()
    }
    fn simulations(&self) -> Option<usize> {
        Some(self.simulations.load(Ordering::Relaxed))
    }
    fn variable_label(&self, i: usize) -> String {
        crate::optimize::Problem::variable_label(&self.inner, i)
    }
}
