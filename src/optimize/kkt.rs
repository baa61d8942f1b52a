//! The Kuhn–Tucker certificate of a design, and the classification of a
//! run's end by it.
//!
//! All quantities live in the range-scaled variables the local solver uses,
//! `y_i = x_i / r_i` with `r_i = upper_i − lower_i` (the period for a
//! periodic variable): a scaled gradient is `∂f/∂y_i = r_i ∂f/∂x_i`, the
//! change of f over the variable's whole range to first order. Constraints
//! are the problem's `g_j(x) <= 0`, which the study normalises (a value
//! of 0.01 is 1 % beyond the limit). The bounds of the non-periodic
//! variables are constraints too: a variable within `1e-9` of its range
//! from a bound contributes the row `−e_i` (lower) or `+e_i` (upper).
//!
//! **Feasible end** (`max_j g_j <= feasibility`): the active set is
//! `A = {j : g_j >= −active}` plus the bounds the design sits on. The
//! multipliers are the non-negative least-squares solution
//!
//! ```text
//!   λ = argmin_{λ >= 0, μ >= 0} | ∇f + Σ_{j∈A} λ_j ∇g_j + Σ_i μ_i n_i |
//! ```
//!
//! (`n_i` the bound rows), solved exactly by [`super::qp`] (the projection
//! of `−∇f` onto the cone of directions that increase no active
//! constraint). The Kuhn–Tucker residual is that least norm relative to the
//! gradient's size,
//!
//! ```text
//!   kt_residual = | ∇f + Σ λ_j ∇g_j + Σ μ_i n_i | / max(1, |∇f|),
//! ```
//!
//! and the end is **converged** when `kt_residual <= stationarity`; else it
//! is **stopped** (the solver stopped before stationarity: iteration
//! limit, objective change, line search failure, budget). A multiplier is
//! reported for every active constraint (`None` for the others).
//!
//! **Infeasible end** (`max g > feasibility`): the same test on the
//! violation `V = ½ Σ_j max(0, g_j)²`, whose gradient divided by the
//! largest violation `v = max g` is `∇V / v = Σ_j (g_j⁺ / v) ∇g_j`, with
//! the bounds as constraints:
//!
//! ```text
//!   violation_residual = | ∇V/v + Σ μ_i n_i |_min / max(1, |∇g_k|)
//! ```
//!
//! (`k` the most violated constraint). At or below `stationarity` the end
//! is a stationary point of the violation: no descent on the violation
//! leads from it towards the feasible set (a local minimum of the
//! violation, as the peak-strain constraint of the SAR problem has many).
//!
//! **At the noise.** An evaluation that integrates a motion with adaptive
//! steps has noise (about 2e-8 of f on the SAR problem at rtol 1e-7,
//! [`super::noise`]), and near an optimum the decrease a step could still
//! make falls below it before the residual falls below `stationarity`.
//! When the solver hands over its curvature model `H` of the Lagrangian
//! (scaled, [`AtNoise`]), the certificate also computes the decrease left
//! along the residual's direction `S` (the least-norm solution above,
//! `S = −(∇f + Σ λ_j ∇g_j + Σ μ_i n_i)`) on that model,
//!
//! ```text
//!   decrease_left = (∇fᵀS)² / (2 SᵀHS),
//! ```
//!
//! and a feasible end whose `decrease_left` is at most the noise
//! allowance of f (3σ of the measured noise, absolute) is **converged at
//! the noise** ([`Certificate::at_noise`]): no step the model can see
//! would show a decrease the evaluation resolves.
//!
//! Tolerances ([`KktTolerances`]) are stated by the study
//! (`[multistart] feasibility_tolerance`, `active_tolerance`,
//! `kt_tolerance`); the defaults are `1e-6`, `1e-4` and `1e-4`.
//!
//! [`nudge_inside`] moves a certified design that stands on the tolerance
//! (`0 < max g <= feasibility`) to `max g <= 0` by Newton steps on the
//! violated constraints with their gradients at the design (so that a
//! design can be compared as strictly feasible).

use super::{qp, Evaluation, Problem, Variable};
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// The tolerances of the certificate (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KktTolerances {
    /// Feasible: `max g <= feasibility`.
    pub feasibility: f64,
    /// Active: `g_j >= −active`.
    pub active: f64,
    /// Stationary: relative residual `<= stationarity`.
    pub stationarity: f64,
}

impl Default for KktTolerances {
    fn default() -> Self {
        KktTolerances {
            feasibility: 1e-6,
            active: 1e-4,
            stationarity: 1e-4,
        }
    }
}

/// How a run ended, by its certificate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum EndClass {
    /// Feasible and Kuhn–Tucker within the tolerances: a certified optimum.
    Converged,
    /// Feasible, but not stationary: the solver stopped short.
    Stopped,
    /// Not feasible within the tolerance.
    Infeasible,
}

impl EndClass {
    /// The name in tables: `converged`, `stopped`, `infeasible`.
    pub fn name(self) -> &'static str {
        match self {
            EndClass::Converged => "converged",
            EndClass::Stopped => "stopped",
            EndClass::Infeasible => "infeasible",
        }
    }

    /// The class of a table name.
    pub fn parse(s: &str) -> Option<EndClass> {
        [EndClass::Converged, EndClass::Stopped, EndClass::Infeasible]
            .into_iter()
            .find(|c| c.name() == s)
    }
}

impl std::fmt::Display for EndClass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The certificate of one design.
#[derive(Debug, Clone, PartialEq)]
pub struct Certificate {
    /// The class of the design.
    pub class: EndClass,
    /// Largest constraint value (`-inf` without constraints).
    pub max_g: f64,
    /// Kuhn–Tucker residual of f (feasible designs only).
    pub kt_residual: Option<f64>,
    /// Multiplier of each constraint: `Some(λ_j >= 0)` when active at a
    /// feasible design, `None` otherwise.
    pub multipliers: Vec<Option<f64>>,
    /// Stationarity residual of the violation (infeasible designs only).
    pub violation_residual: Option<f64>,
    /// Infeasible designs: is the design a stationary point of the
    /// violation? (`None` for feasible designs.)
    pub violation_stationary: Option<bool>,
    /// Feasible designs certified with a curvature model ([`AtNoise`]):
    /// the decrease of f left along the residual's direction on it.
    pub decrease_left: Option<f64>,
    /// Converged by the test at the noise while `kt_residual` is above
    /// `stationarity`: the allowance `decrease_left` met (`None`
    /// otherwise).
    pub at_noise: Option<f64>,
}

/// The test at the noise of the module doc: the solver's curvature model
/// of the Lagrangian and the noise allowance of f.
#[derive(Debug, Clone, Copy)]
pub struct AtNoise<'a> {
    /// `H`, in the range-scaled variables, `n × n`, row-major.
    pub hessian: &'a [f64],
    /// The noise allowance of f, absolute (`> 0`; 3σ of the measured
    /// noise).
    pub allowance: f64,
}

/// The decrease of f the quadratic model `f + αgᵀs + ½α²sᵀHs` predicts
/// along `s` at its minimum, `(gᵀs)²/(2sᵀHs)`, for a descent direction
/// (`gᵀs < 0`) with positive curvature on the row-major `n × n` `hessian`;
/// `None` otherwise.
pub fn decrease_left(hessian: &[f64], g: &[f64], s: &[f64]) -> Option<f64> {
    let n = s.len();
    if hessian.len() != n * n || g.len() != n {
        return None;
    }
    let d0: f64 = g.iter().zip(s).map(|(a, b)| a * b).sum();
    let shs: f64 = (0..n)
        .map(|i| s[i] * (0..n).map(|j| hessian[i * n + j] * s[j]).sum::<f64>())
        .sum();
    let left = d0 * d0 / (2.0 * shs);
    (d0 < 0.0 && shs > 0.0 && left.is_finite()).then_some(left)
}

fn ranges(vars: &[Variable]) -> Vec<f64> {
    vars.iter()
        .map(|v| v.period.unwrap_or(v.upper - v.lower))
        .collect()
}

fn norm(a: &[f64]) -> f64 {
    a.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// Rows `−e_i` / `+e_i` of the bounds the design `x` sits on.
fn bound_rows(vars: &[Variable], x: &[f64]) -> Vec<Vec<f64>> {
    let n = vars.len();
    let mut rows = Vec::new();
    for (i, v) in vars.iter().enumerate() {
        if v.period.is_some() {
            continue;
        }
        let y = (x[i] - v.lower) / (v.upper - v.lower);
        let mut e = vec![0.0; n];
        if y <= 1e-9 {
            e[i] = -1.0;
            rows.push(e);
        } else if y >= 1.0 - 1e-9 {
            e[i] = 1.0;
            rows.push(e);
        }
    }
    rows
}

/// The certificate of design `x` from its evaluation with gradients
/// (see the module doc for the formulas).
pub fn certify(
    vars: &[Variable],
    x: &[f64],
    ev: &Evaluation,
    tol: &KktTolerances,
) -> Result<Certificate> {
    certify_with(vars, x, ev, tol, None)
}

/// [`certify`] with the test at the noise when `at_noise` is given.
pub fn certify_with(
    vars: &[Variable],
    x: &[f64],
    ev: &Evaluation,
    tol: &KktTolerances,
    at_noise: Option<AtNoise<'_>>,
) -> Result<Certificate> {
    let missing = || Error::numerical("optimize::kkt", "the evaluation has no gradients");
    let r = ranges(vars);
    let scale = |g: &[f64]| -> Vec<f64> { g.iter().zip(&r).map(|(a, b)| a * b).collect() };
    let gf = scale(ev.grad_f.as_ref().ok_or_else(missing)?);
    let m = ev.g.len();
    let gg: Vec<Vec<f64>> = match &ev.grad_g {
        Some(rows) => rows.iter().map(|row| scale(row)).collect(),
        None if m == 0 => vec![],
        None => return Err(missing()),
    };
    if gf.iter().chain(gg.iter().flatten()).any(|v| !v.is_finite()) {
        return Err(Error::numerical(
            "optimize::kkt",
            format!("non-finite gradient at x = {x:?}"),
        ));
    }
    let max_g = ev.max_g();
    let bounds = bound_rows(vars, x);
    if max_g <= tol.feasibility {
        let active: Vec<usize> = (0..m).filter(|&j| ev.g[j] >= -tol.active).collect();
        let mut rows: Vec<Vec<f64>> = active.iter().map(|&j| gg[j].clone()).collect();
        rows.extend(bounds.iter().cloned());
        let sol = qp::solve(&gf, &rows, &vec![0.0; rows.len()])?;
        let residual = norm(&sol.s) / norm(&gf).max(1.0);
        let mut multipliers = vec![None; m];
        for (k, &j) in active.iter().enumerate() {
            multipliers[j] = Some(sol.lambda[k]);
        }
        let left = at_noise.and_then(|a| decrease_left(a.hessian, &gf, &sol.s));
        let stationary = residual <= tol.stationarity;
        let at_noise = at_noise
            .map(|a| a.allowance)
            .filter(|&a| !stationary && a > 0.0 && left.is_some_and(|d| d <= a));
        return Ok(Certificate {
            class: if stationary || at_noise.is_some() {
                EndClass::Converged
            } else {
                EndClass::Stopped
            },
            max_g,
            kt_residual: Some(residual),
            multipliers,
            violation_residual: None,
            violation_stationary: None,
            decrease_left: left,
            at_noise,
        });
    }
    // Infeasible: the gradient of the violation, per unit of violation.
    let n = vars.len();
    let mut dv = vec![0.0; n];
    let mut worst = 0;
    for (j, (gj, row)) in ev.g.iter().zip(&gg).enumerate() {
        if *gj > 0.0 {
            let w = gj / max_g;
            for (d, r) in dv.iter_mut().zip(row) {
                *d += w * r;
            }
        }
        if *gj > ev.g[worst] {
            worst = j;
        }
    }
    let sol = qp::solve(&dv, &bounds, &vec![0.0; bounds.len()])?;
    let residual = norm(&sol.s) / norm(&gg[worst]).max(1.0);
    Ok(Certificate {
        class: EndClass::Infeasible,
        max_g,
        kt_residual: None,
        multipliers: vec![None; m],
        violation_residual: Some(residual),
        violation_stationary: Some(residual <= tol.stationarity),
        decrease_left: None,
        at_noise: None,
    })
}

/// Evaluate `x` with gradients and certify it; when `x` is the design of
/// the problem's last evaluation with gradients
/// ([`Problem::last_gradient`], kept by a counting wrapper), that
/// evaluation is used and no new one is made.
pub fn certify_at(
    problem: &dyn Problem,
    x: &[f64],
    tol: &KktTolerances,
) -> Result<(Evaluation, Certificate)> {
    certify_at_with(problem, x, tol, None)
}

/// [`certify_at`] with the test at the noise when `at_noise` is given.
pub fn certify_at_with(
    problem: &dyn Problem,
    x: &[f64],
    tol: &KktTolerances,
    at_noise: Option<AtNoise<'_>>,
) -> Result<(Evaluation, Certificate)> {
    let ev = match problem.last_gradient() {
        Some((at, ev)) if at == x => ev,
        _ => problem.evaluate(x, true)?,
    };
    let c = certify_with(problem.variables(), x, &ev, tol, at_noise)?;
    Ok((ev, c))
}

/// From a design with `0 < max g` and the gradients of its evaluation
/// `ev`, up to three Newton steps on the constraints with `g_j > −margin`
/// towards `g_j = −margin` (`margin` >= 1e-12: the constraints' noise,
/// so that the design reached is inside by more than a jump of it;
/// least-norm steps in scaled variables with the
/// frozen gradients, kept inside the box): the first design reached with
/// `max g <= 0`, with its function-only evaluation, or `None`. Each step
/// costs one function call of `problem`.
pub fn nudge_inside(
    problem: &dyn Problem,
    x: &[f64],
    ev: &Evaluation,
    margin: f64,
) -> Result<Option<(Vec<f64>, Evaluation)>> {
    let vars = problem.variables();
    let Some(grad_g) = &ev.grad_g else {
        return Ok(None);
    };
    let r = ranges(vars);
    let target = -margin.max(1e-12);
    let set: Vec<usize> = (0..ev.g.len()).filter(|&j| ev.g[j] > target).collect();
    if set.is_empty() {
        return Ok(None);
    }
    let cols: Vec<Vec<f64>> = set
        .iter()
        .map(|&j| grad_g[j].iter().zip(&r).map(|(a, b)| a * b).collect())
        .collect();
    let k = cols.len();
    let gram = DMatrix::<f64>::from_fn(k, k, |a, b| {
        cols[a].iter().zip(&cols[b]).map(|(p, q)| p * q).sum()
    });
    let ridge = 1e-12 * (1.0 + gram.diagonal().max());
    let Some(chol) = (gram + DMatrix::identity(k, k) * ridge).cholesky() else {
        return Ok(None);
    };
    let mut z = vec![0.0; vars.len()];
    let mut g: Vec<f64> = set.iter().map(|&j| ev.g[j]).collect();
    for _ in 0..3 {
        // Least-norm dz with colsᵀ dz = target − g (linearised).
        let rhs = DVector::from_iterator(k, g.iter().map(|v| target - v));
        let w = chol.solve(&rhs);
        for (col, wi) in cols.iter().zip(w.iter()) {
            for (zi, c) in z.iter_mut().zip(col) {
                *zi += wi * c;
            }
        }
        let xn: Vec<f64> = vars
            .iter()
            .enumerate()
            .map(|(i, v)| v.wrap(x[i] + z[i] * r[i]))
            .collect();
        let en = problem.evaluate(&xn, false)?;
        if !en.f.is_finite() || en.g.iter().any(|v| !v.is_finite()) {
            return Ok(None);
        }
        if en.max_g() <= 0.0 {
            return Ok(Some((xn, en)));
        }
        g = set.iter().map(|&j| en.g[j]).collect();
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimize::testproblems;

    fn tol() -> KktTolerances {
        KktTolerances::default()
    }

    /// HS 100 at the published optimum (Hock & Schittkowski 1981, problem
    /// 100, x* to 7 digits): constraints 1 and 4 active, positive
    /// multipliers, residual at the level of the 7-digit rounding of x*;
    /// at the standard start the residual is large (not stationary).
    #[test]
    fn hs100_optimum_is_certified_and_its_start_is_not() {
        let p = testproblems::hs100();
        let mut t = tol();
        t.feasibility = 1e-5; // x* rounded to 7 digits violates g1 by ~1e-7
        let (_, c) = certify_at(&p, &p.optima[0], &t).unwrap();
        assert_eq!(c.class, EndClass::Converged, "{c:?}");
        assert!(c.kt_residual.unwrap() < 1e-5, "{c:?}");
        let l = &c.multipliers;
        assert!(l[0].unwrap() > 0.0 && l[3].unwrap() > 0.0, "{l:?}");
        assert!(l[1].is_none() && l[2].is_none(), "{l:?}");
        let (_, c) = certify_at(&p, &p.x0, &t).unwrap();
        assert_eq!(c.class, EndClass::Stopped);
        assert!(c.kt_residual.unwrap() > 0.1);
    }

    /// HS 22 at (1, 1): ∇f = (−2, 0), ∇g1 = (1, 1), ∇g2 = (2, −1); the
    /// multipliers solve −2 + λ1 + 2λ2 = 0, λ1 − λ2 = 0: λ = (2/3, 2/3)
    /// (derived here; Hock & Schittkowski 1981, problem 22, box [−5, 5]²).
    #[test]
    fn hs22_multipliers_match_the_closed_form() {
        let vars = [
            Variable::bounded("x1", -5.0, 5.0).unwrap(),
            Variable::bounded("x2", -5.0, 5.0).unwrap(),
        ];
        let ev = Evaluation {
            f: 1.0,
            g: vec![0.0, 0.0],
            grad_f: Some(vec![-2.0, 0.0]),
            grad_g: Some(vec![vec![1.0, 1.0], vec![2.0, -1.0]]),
        };
        let c = certify(&vars, &[1.0, 1.0], &ev, &tol()).unwrap();
        assert_eq!(c.class, EndClass::Converged);
        for l in &c.multipliers {
            assert!((l.unwrap() - 2.0 / 3.0).abs() < 1e-9, "{c:?}");
        }
    }

    /// A certificate at the design of the last evaluation with gradients
    /// reuses it: through a counter (and a counter started from it, as the
    /// drivers nest them) no call is counted; elsewhere one gradient call.
    #[test]
    fn a_certificate_where_the_gradients_are_known_evaluates_nothing() {
        let p = testproblems::disc();
        let s = -std::f64::consts::FRAC_1_SQRT_2;
        let outer = crate::optimize::Counted::new(&p);
        outer.evaluate(&[s, s], true).unwrap();
        let inner = crate::optimize::Counted::new(&outer);
        let (ev, c) = certify_at(&inner, &[s, s], &tol()).unwrap();
        assert_eq!(c.class, EndClass::Converged);
        assert_eq!(ev, p.evaluate(&[s, s], true).unwrap());
        assert_eq!((inner.function_calls(), inner.gradient_calls()), (0, 0));
        assert_eq!((outer.function_calls(), outer.gradient_calls()), (1, 1));
        certify_at(&inner, &[0.5, 0.5], &tol()).unwrap();
        assert_eq!((inner.function_calls(), inner.gradient_calls()), (1, 1));
    }

    /// The disc problem (f = x + y on x² + y² <= 1): at x* = −(1, 1)/√2 the
    /// multiplier is 1/√2 (∇f = (1, 1) = −λ (−√2, −√2), closed form).
    /// Beyond the tolerance the end is infeasible and not a stationary
    /// point of the violation; on the tolerance a nudge reaches max g <= 0.
    #[test]
    fn disc_multiplier_violation_and_nudge() {
        let p = testproblems::disc();
        let s = -std::f64::consts::FRAC_1_SQRT_2;
        let (_, c) = certify_at(&p, &[s, s], &tol()).unwrap();
        assert_eq!(c.class, EndClass::Converged);
        assert!((c.multipliers[0].unwrap() + s).abs() < 1e-9, "{c:?}");
        let (_, c) = certify_at(&p, &[1.0, 0.5], &tol()).unwrap();
        assert_eq!(c.class, EndClass::Infeasible);
        assert_eq!(c.violation_stationary, Some(false));
        let x = [s * (1.0 + 2e-7), s];
        let ev = p.evaluate(&x, true).unwrap();
        assert!(ev.max_g() > 0.0);
        let (xn, en) = nudge_inside(&p, &x, &ev, 1e-12).unwrap().unwrap();
        assert!(en.max_g() <= 0.0 && (xn[0] - s).abs() < 1e-6, "{xn:?}");
        // With a margin (a noise of g of 1e-6): inside by about the margin.
        let (_, en) = nudge_inside(&p, &x, &ev, 1e-6).unwrap().unwrap();
        assert!((-1.1e-6..=-0.9e-6).contains(&en.max_g()), "{}", en.max_g());
    }

    /// The test at the noise on the disc problem, on the circle at the
    /// angle δ = 1e-3 from x*: the residual is about sin δ = 1e-3 (not
    /// stationary at 1e-4), and the decrease left along the circle is
    /// √2(1 − cos δ) = 7.07e-7 (closed form). With the Lagrangian's exact
    /// Hessian λ∇²g = √2·I (λ = 1/√2), in the scaled variables `r² √2·I`
    /// (r = 4, the range), the model's decrease left matches it to 1e-3;
    /// an allowance of 1e-6 certifies the design at the noise, one of
    /// 5e-7 does not, nor does a missing model.
    #[test]
    fn the_test_at_the_noise_uses_the_decrease_left() {
        let p = testproblems::disc();
        let (delta, r) = (1e-3_f64, 4.0);
        let a = 1.25 * std::f64::consts::PI + delta;
        let x = [a.cos(), a.sin()];
        let k = r * r * std::f64::consts::SQRT_2;
        let h = [k, 0.0, 0.0, k];
        let exact = std::f64::consts::SQRT_2 * (1.0 - delta.cos());
        let with = |allowance: f64| {
            let noisy = Some(AtNoise {
                hessian: &h,
                allowance,
            });
            certify_at_with(&p, &x, &tol(), noisy).unwrap().1
        };
        let c = with(1e-6);
        assert_eq!(c.class, EndClass::Converged, "{c:?}");
        assert_eq!(c.at_noise, Some(1e-6));
        assert!((c.kt_residual.unwrap() - delta).abs() < 1e-6, "{c:?}");
        let left = c.decrease_left.unwrap();
        assert!((left / exact - 1.0).abs() < 1e-3, "{left} vs {exact}");
        let c = with(5e-7);
        assert_eq!((c.class, c.at_noise), (EndClass::Stopped, None), "{c:?}");
        let (_, c) = certify_at(&p, &x, &tol()).unwrap();
        assert_eq!((c.class, c.decrease_left), (EndClass::Stopped, None));
        // No descent along the direction, or no positive curvature: none.
        assert_eq!(decrease_left(&h, &[1.0, 0.0], &[1.0, 0.0]), None);
        assert_eq!(decrease_left(&[0.0; 4], &[1.0, 0.0], &[-1.0, 0.0]), None);
    }

    /// A lower bound as a constraint: f = x on [0, 1] at x = 0 is a
    /// Kuhn–Tucker point with the bound active; unconstrained Himmelblau
    /// at (3, 2) (Himmelblau 1972) has a zero residual; at (0, 0) it has
    /// not.
    #[test]
    fn bounds_count_as_constraints() {
        let h = testproblems::himmelblau();
        let (_, c) = certify_at(&h, &[3.0, 2.0], &tol()).unwrap();
        assert_eq!(c.class, EndClass::Converged);
        assert!(c.multipliers.is_empty());
        let (_, c) = certify_at(&h, &[0.0, 0.0], &tol()).unwrap();
        assert_eq!(c.class, EndClass::Stopped);
        let vars = [Variable::bounded("x", 0.0, 1.0).unwrap()];
        let ev = Evaluation {
            f: 0.0,
            g: vec![],
            grad_f: Some(vec![1.0]),
            grad_g: Some(vec![]),
        };
        let c = certify(&vars, &[0.0], &ev, &tol()).unwrap();
        assert_eq!(c.class, EndClass::Converged);
        let c = certify(&vars, &[0.5], &ev, &tol()).unwrap();
        assert_eq!(c.class, EndClass::Stopped);
    }

    /// A stationary point of the violation: g = 1 + (x − 0.5)² > 0 on
    /// [0, 1] has its least violation at x = 0.5 (closed form).
    #[test]
    fn a_local_minimum_of_the_violation_is_stationary() {
        let vars = [Variable::bounded("x", 0.0, 1.0).unwrap()];
        let at = |x: f64| Evaluation {
            f: x,
            g: vec![1.0 + (x - 0.5).powi(2)],
            grad_f: Some(vec![1.0]),
            grad_g: Some(vec![vec![2.0 * (x - 0.5)]]),
        };
        let c = certify(&vars, &[0.5], &at(0.5), &tol()).unwrap();
        assert_eq!(c.violation_stationary, Some(true));
        let c = certify(&vars, &[0.2], &at(0.2), &tol()).unwrap();
        assert_eq!(c.violation_stationary, Some(false));
        // At the lower bound the violation decreases inwards: descent
        // leaves the bound, not stationary.
        let c = certify(&vars, &[0.0], &at(0.0), &tol()).unwrap();
        assert_eq!(c.violation_stationary, Some(false));
        // Its minimum outside the box, beyond the lower bound: the bound
        // stops descent, stationary in the box.
        let beyond = |x: f64| Evaluation {
            f: x,
            g: vec![1.0 + (x + 0.5).powi(2)],
            grad_f: Some(vec![1.0]),
            grad_g: Some(vec![vec![2.0 * (x + 0.5)]]),
        };
        let c = certify(&vars, &[0.0], &beyond(0.0), &tol()).unwrap();
        assert_eq!(c.violation_stationary, Some(true));
    }
}
