//! The check of infeasible ends by a pure minimization of the violation.
//!
//! A multistart run that ends infeasible says "descent from this start
//! does not reach the feasible set". [`check`] tests that answer on a
//! sample of such runs (`[multistart] violation_checks`, spread evenly over
//! the infeasible runs by start index): from the same start, projected
//! steepest descent on the violation alone,
//!
//! ```text
//!   V(x) = ½ Σ_j max(0, g_j(x))²,   ∇V = Σ_j max(0, g_j) ∇g_j,
//! ```
//!
//! in range-scaled variables (as MMFD), with Armijo backtracking
//! (`V(x + αd) <= V(x) − 1e-4 α |d|²`, `d = −∇V` scaled, α from the last
//! accepted step times 2, shortened by quadratic interpolation within
//! [0.1, 0.5] down to a move of 1e-10 of the ranges), until
//! `max g <= feasibility_tolerance`, no step lowers V, the rate of the
//! last iterations cannot reach the feasible set within the iteration
//! limit ([`cannot_reach`]), or [`MAX_ITERATIONS`]. The objective plays no
//! part. `violation_checks.csv`
//! lists, per checked start, the run's end and the pure descent's end: when
//! both stay infeasible the start lies in a basin of the violation outside
//! the feasible set, whatever the optimizer.

use crate::error::Result;
use crate::explore::persist::tables::{num, RunRecord};
use crate::optimize::{Counted, Evaluation, Problem};

/// Iteration limit of the pure descent on the violation.
pub const MAX_ITERATIONS: usize = 60;

/// The pure descent's end from one start.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// Start index.
    pub start: usize,
    /// The multistart run's largest violation at its end.
    pub run_max_g: f64,
    /// The pure descent's end design.
    pub x: Vec<f64>,
    /// Its largest constraint value.
    pub max_g: f64,
    /// Iterations of the pure descent.
    pub iterations: usize,
    /// Function and gradient calls of the pure descent.
    pub calls: (usize, usize),
    /// The numerical failure that stopped the descent (then `x` is its
    /// start and `max_g` the run's): one failed check does not end the
    /// others or the study.
    pub error: Option<String>,
}

impl Check {
    /// Did the pure descent reach the feasible set?
    pub fn reached(&self, tolerance: f64) -> bool {
        self.error.is_none() && self.max_g <= tolerance
    }
}

fn violation(g: &[f64]) -> f64 {
    0.5 * g.iter().map(|v| v.max(0.0).powi(2)).sum::<f64>()
}

/// Iterations over which [`cannot_reach`] measures the descent's rate.
pub const STALL_WINDOW: usize = 3;

/// Records `v` (V at iteration `it`) in `recent` and tells whether, at the
/// rate of the last [`STALL_WINDOW`] iterations, the iterations left
/// cannot bring V down to the feasible level `½ tolerance²`:
///
/// ```text
///   (V_{k−w} − V_k) · (MAX_ITERATIONS − k) / w  <  V_k − ½ τ²
/// ```
///
/// Steepest descent decelerates as it nears a stationary point, so the
/// linear extrapolation errs on the side of going on. Measured on the SAR
/// problem (`studies/sar_sweep64.toml`, start 3, rtol 1e-8): V fell from
/// 2.51 to 0.8008 in 4 iterations and then stayed at 0.8007932 (7 digits)
/// for the other 55, zig-zagging along the floor of a valley at max g =
/// 1.115, 90 f + 60 g in all; 21 of that sweep's 27 infeasible runs spent
/// 80–97 f + 52–60 g so in their rescue.
pub fn cannot_reach(recent: &mut Vec<f64>, v: f64, it: usize, tolerance: f64) -> bool {
    recent.push(v);
    let w = STALL_WINDOW;
    if recent.len() <= w {
        return false;
    }
    let drop = recent[recent.len() - 1 - w] - v;
    let left = MAX_ITERATIONS.saturating_sub(it) as f64;
    drop * left / (w as f64) < v - 0.5 * tolerance * tolerance
}

/// Pure descent on the violation from `x0` (see the module doc): the end
/// design, its evaluation (with gradients unless the iteration limit
/// ended the descent) and the iterations taken.
pub fn descend(
    problem: &dyn Problem,
    x0: &[f64],
    tolerance: f64,
) -> Result<(Vec<f64>, Evaluation, usize)> {
    let vars = problem.variables();
    let r: Vec<f64> = vars
        .iter()
        .map(|v| v.period.unwrap_or(v.upper - v.lower))
        .collect();
    let step_to = |x: &[f64], d: &[f64], a: f64| -> Vec<f64> {
        vars.iter()
            .enumerate()
            .map(|(i, v)| v.wrap(x[i] + a * d[i] * r[i]))
            .collect()
    };
    let mut x: Vec<f64> = x0.iter().zip(vars).map(|(&v, var)| var.wrap(v)).collect();
    let mut alpha: f64 = 0.1;
    let mut recent = Vec::with_capacity(MAX_ITERATIONS);
    for it in 0..MAX_ITERATIONS {
        let e = problem.evaluate(&x, true)?;
        if e.max_g() <= tolerance {
            return Ok((x, e, it));
        }
        let v0 = violation(&e.g);
        if cannot_reach(&mut recent, v0, it, tolerance) {
            return Ok((x, e, it));
        }
        let gg = e.grad_g.clone().unwrap_or_default();
        let mut d = vec![0.0; x.len()];
        for (gj, row) in e.g.iter().zip(&gg) {
            for (di, (dg, ri)) in d.iter_mut().zip(row.iter().zip(&r)) {
                *di -= gj.max(0.0) * dg * ri;
            }
        }
        let dd: f64 = d.iter().map(|v| v * v).sum();
        let length = dd.sqrt();
        if length == 0.0 {
            return Ok((x, e, it));
        }
        alpha = (2.0 * alpha).min(0.2 / length);
        let mut accepted = None;
        while alpha * length > 1e-10 {
            let xt = step_to(&x, &d, alpha);
            let vt = violation(&problem.evaluate(&xt, false)?.g);
            if vt <= v0 - 1e-4 * alpha * dd {
                accepted = Some(xt);
                break;
            }
            let curvature = vt - v0 + alpha * dd;
            let fit = if curvature > 0.0 {
                dd * alpha * alpha / (2.0 * curvature)
            } else {
                0.5 * alpha
            };
            alpha = fit.clamp(0.1 * alpha, 0.5 * alpha);
        }
        match accepted {
            Some(xt) => x = xt,
            None => return Ok((x, e, it)),
        }
    }
    let e = problem.evaluate(&x, false)?;
    Ok((x, e, MAX_ITERATIONS))
}

/// The infeasible runs to check: `count` of them spread evenly by start
/// index (all when there are fewer).
pub fn sample(runs: &[RunRecord], count: usize) -> Vec<&RunRecord> {
    let infeasible: Vec<&RunRecord> = runs
        .iter()
        .filter(|r| crate::explore::persist::tables::class_name(r) == "infeasible")
        .collect();
    if count == 0 || infeasible.is_empty() {
        return vec![];
    }
    let k = count.min(infeasible.len());
    (0..k)
        .map(|i| infeasible[i * infeasible.len() / k])
        .collect()
}

/// Check the sampled infeasible runs from their starts. A descent that
/// fails (an evaluation's numerical error) is recorded with its error.
pub fn check(problem: &dyn Problem, runs: &[&RunRecord], tolerance: f64) -> Vec<Check> {
    runs.iter()
        .map(|r| {
            let counted = Counted::new(problem);
            let run_max_g = r.result.as_ref().map_or(f64::INFINITY, |res| res.max_g());
            let (x, max_g, iterations, error) = match descend(&counted, &r.x0, tolerance) {
                Ok((x, e, it)) => (x, e.max_g(), it, None),
                Err(e) => (r.x0.clone(), run_max_g, 0, Some(e.to_string())),
            };
            Check {
                start: r.start,
                run_max_g,
                x,
                max_g,
                iterations,
                calls: (counted.function_calls(), counted.gradient_calls()),
                error,
            }
        })
        .collect()
}

/// `violation_checks.csv`: header and one row per check.
pub fn table(problem: &dyn Problem, checks: &[Check], tolerance: f64) -> Vec<Vec<String>> {
    let mut h = vec!["start".to_string(), "run_max_g".into()];
    h.extend(problem.variables().iter().map(|v| format!("x_{}", v.name)));
    h.extend(
        [
            "max_g",
            "reached_feasible",
            "iterations",
            "function_calls",
            "gradient_calls",
        ]
        .map(String::from),
    );
    let mut rows = vec![h];
    for c in checks {
        let mut row = vec![c.start.to_string(), num(c.run_max_g)];
        row.extend(c.x.iter().map(|&v| num(v)));
        row.push(num(c.max_g));
        row.push(match &c.error {
            Some(e) => format!("error: {e}"),
            None => c.reached(tolerance).to_string(),
        });
        row.push(c.iterations.to_string());
        row.push(c.calls.0.to_string());
        row.push(c.calls.1.to_string());
        rows.push(row);
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimize::testproblems::islands;

    /// The stall test: a descent whose V has stopped falling ends; one
    /// whose recent rate would reach the feasible level goes on.
    #[test]
    fn a_descent_that_stopped_falling_cannot_reach_the_feasible_set() {
        let mut recent = Vec::new();
        let stalled = [2.5, 0.85, 0.8016, 0.8009, 0.800_793_2, 0.800_793_2];
        let ends: Vec<bool> = stalled
            .iter()
            .enumerate()
            .map(|(it, &v)| cannot_reach(&mut recent, v, it, 1e-6))
            .collect();
        assert_eq!(ends, [false, false, false, false, false, true]);
        // Halving every iteration reaches ½τ² long before the limit.
        let mut recent = Vec::new();
        for it in 0..20 {
            let v = 0.5_f64.powi(it as i32);
            assert!(!cannot_reach(&mut recent, v, it, 1e-6), "{it}");
        }
        // A slow but steady fall that the limit cannot finish ends.
        let mut recent = Vec::new();
        let slow: Vec<bool> = (0..6)
            .map(|it| cannot_reach(&mut recent, 1.0 - 0.001 * it as f64, it, 1e-6))
            .collect();
        assert_eq!(slow, [false, false, false, true, true, true]);
    }

    #[test]
    fn pure_descent_on_the_violation_finds_its_basin() {
        let p = islands();
        // From 0.3 the violation's descent goes to its minimum at 0.
        let (x, e, _) = descend(&p, &[0.3], 1e-6).unwrap();
        let max_g = e.max_g();
        assert!(
            x[0].abs() < 1e-3 && (max_g - 0.5).abs() < 1e-6,
            "{x:?} {max_g}"
        );
        // From 1.5 it climbs out to the feasible set at |x| >= 2.10938.
        let (x, e, _) = descend(&p, &[1.5], 1e-6).unwrap();
        let max_g = e.max_g();
        assert!(max_g <= 1e-6 && x[0] >= 2.1093, "{x:?} {max_g}");
    }

    /// Islands whose evaluation fails right of x = 1 (as a basis fails at
    /// a design with repeated eigenvalues).
    struct Failing(crate::optimize::testproblems::Analytic);

    impl Problem for Failing {
        fn variables(&self) -> &[crate::optimize::Variable] {
            self.0.variables()
        }
        fn n_constraints(&self) -> usize {
            1
        }
        fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
            if x[0] > 1.0 {
                return Err(crate::error::Error::numerical("test", "no basis here"));
            }
            self.0.evaluate(x, gradients)
        }
    }

    #[test]
    fn a_failed_descent_is_a_row_with_its_error_not_the_end_of_the_checks() {
        let p = Failing(islands());
        let rec = |start: usize, x0: f64| RunRecord {
            certificate: None,
            polish: String::new(),
            start,
            x0: vec![x0],
            result: Some(crate::explore::persist::tables::RunResult {
                x: vec![0.0],
                f: 0.0,
                g: vec![0.5],
            }),
            exit: "infeasible".into(),
            iterations: 1,
            function_calls: 1,
            gradient_calls: 1,
            wall_seconds: 0.0,
            optimum: None,
        };
        // From 1.5 the evaluation fails; from 0.3 the descent ends at 0.
        let runs = [rec(0, 1.5), rec(1, 0.3)];
        let checks = check(&p, &runs.iter().collect::<Vec<_>>(), 1e-6);
        assert!(checks[0]
            .error
            .as_deref()
            .is_some_and(|e| e.contains("no basis")));
        assert!(!checks[0].reached(1e-6) && checks[0].max_g == 0.5);
        assert!(checks[1].error.is_none() && (checks[1].max_g - 0.5).abs() < 1e-6);
        let t = table(&p, &checks, 1e-6);
        assert!(
            t[1][4].starts_with("error: ") && t[2][4] == "false",
            "{t:?}"
        );
    }
}
