//! Sequential quadratic programming (SQP) with a damped BFGS model of the
//! Lagrangian and an ℓ1 merit line search, as an argmin [`Solver`].
//!
//! Problem: minimize `f(x)` subject to `g_j(x) <= 0` and the bounds of the
//! non-periodic variables; periodic variables are wrapped into their box.
//! As in [`super::mmfd`], steps live in range-scaled coordinates
//! `y_i = x_i / r_i` (`r_i` the range, or the period).
//!
//! One iteration, at a design with its gradients (one gradient call):
//! 1. **Subproblem** ([`subproblem`]): `min ½ dᵀB d + ∇fᵀd` subject to
//!    `g_j + ∇g_jᵀd <= 0` and the bounds, solved exactly; when the
//!    linearisation is inconsistent, its elastic ℓ1 form. Its multipliers
//!    `λ_j` estimate the Lagrangian's.
//! 2. **Stop test** (Kuhn–Tucker in predicted decrease, as SLSQP states
//!    it): the design is feasible (`max g <= feasibility`) and the step
//!    predicts at most `|∇fᵀd| + Σ λ_j |g_j| <= ftol · max(|f|, 1)`; or
//!    its certificate ([`super::kkt::certify`]) has a residual at most
//!    `stationarity` (the option, tighter than a study's certificate).
//! 3. **Penalties** (Powell): `μ_j = max(λ_j, ½(μ_j + λ_j))`.
//! 4. **Line search** on the ℓ1 merit `φ(x) = f + Σ μ_j max(0, g_j)`
//!    along `x + α d` from α = 1: accepted when
//!    `φ(α) <= φ(0) + η α Dφ` (Armijo, η = `armijo`) with the directional
//!    derivative `Dφ = ∇fᵀd + Σ μ_j (max(0, g_j + ∇g_jᵀd) − max(0, g_j))`;
//!    and `φ(α) < φ(0)` (where `η α Dφ` is below the round-off of `φ(0)`,
//!    Armijo's test alone accepts no decrease at all); else α shrinks to
//!    the minimizer of the quadratic through `φ(0)`, `Dφ` and `φ(α)`,
//!    kept in `[0.1 α, 0.5 α]`. A trial design equal to the current one
//!    (`α d` below the round-off of `x`) ends the search without a step.
//!    Before these two rules, a Tchebycheff subproblem of the deployable
//!    panel's front, at a point where constraint noise of about 1e-9
//!    defeated every step, accepted steps of `α = 1e-9` that left the
//!    design unchanged, each one resetting the count of failed searches,
//!    and spent 100 iterations and 1574 function calls there. The full step is
//!    evaluated with its gradients (`speculative`) once full steps are
//!    being accepted: an accepted step then costs one function and one
//!    gradient call, as the next iteration needs its gradients anyway.
//! 5. **Model update** (Powell's damped BFGS): with `s = α d` and `y` the
//!    change of `∇f + Σ λ_j ∇g_j` over the step, `r = θ y + (1 − θ) B s`
//!    where `θ = 1` if `sᵀy >= 0.2 sᵀBs`, else `0.8 sᵀBs / (sᵀBs − sᵀy)`;
//!    `B ← B − B s sᵀB / sᵀBs + r rᵀ / sᵀr`. The start model `σ I` has
//!    `σ = |∇f| / first_step` (the first unconstrained step moves
//!    `first_step` of the ranges); before the first update it is rescaled
//!    to `yᵀy / sᵀy` (Shanno–Phua). Before each update the model is
//!    self-scaled (Oren–Luenberger): when `0 < sᵀy < sᵀBs`, `B ← τ B`
//!    with `τ = sᵀy / sᵀBs`, so the damping acts only where `sᵀy <= 0`.
//!    Without it a model that learned a steep curvature early (HS 100's
//!    `10 x₅⁶` from a start at `x₅ = −6`) stays steep in every other
//!    direction, each update can flatten it by at most 5× along its step,
//!    and the run creeps with steps growing 1.5–2× an iteration: on HS 100
//!    from 16 Latin-hypercube starts (`studies/hs100_multistart.toml`)
//!    1433 function calls without the scaling, 482 with it (scipy's
//!    SLSQP: 719 from the same starts).
//!
//! A line search that finds no decrease restarts the model; a second one
//! in a row ends the run (`line_search_failed`). Counting follows
//! [`Counted`]: an evaluation with gradients at the design evaluated just
//! before is a gradient call only.
//!
//! References: Powell, *A fast algorithm for nonlinearly constrained
//! optimization calculations* (1978); Oren & Luenberger, *Self-scaling
//! variable metric (SSVM) algorithms* (Management Science 20, 1974);
//! Nocedal & Wright, *Numerical Optimization* (2006), §18.3 (damped BFGS, Procedure 18.2) and §18.5
//! (ℓ1 merit function, eq. 18.29); Kraft, *A software package for
//! sequential quadratic programming* (DFVLR-FB 88-28, 1988), the SLSQP
//! stop test and penalty update.

use super::driver::{self, OptState, Recorded};
use super::kkt::{self, KktTolerances};
use super::{Counted, Evaluation, IterRecord, LocalOutcome, Observer, Problem, Termination};
use crate::error::{Error, Result};
use argmin::core::{
    Problem as ArgminProblem, Solver, State, TerminationReason, TerminationStatus, KV,
};
use nalgebra::DMatrix;

pub mod subproblem;

use subproblem::Subproblem;

/// SQP parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct SqpOptions {
    /// Iteration limit: 100 (SLSQP's default).
    pub max_iterations: usize,
    /// Stop when the predicted decrease is at most `ftol · max(|f|, 1)`:
    /// 1e-10, six orders below the 1e-4 at which a study's certificate
    /// judges stationarity, so that f ends within about 1e-10 of its local
    /// minimum on a smooth problem.
    pub ftol: f64,
    /// Feasibility (`max g <= feasibility`), active set and stationarity
    /// of the certificate that may also end the run; stationarity 1e-8.
    pub tolerances: KktTolerances,
    /// Scaled length of the first unconstrained step: 0.02 (a fiftieth of
    /// each variable's range). With a tenth, the SAR problem's first step
    /// from 55°/−55° went 18° along the peak-U3 constraint's tangent and
    /// landed at g = 0.25 in an infeasible valley the run never left (460
    /// f + 136 g, then rescued); with a fiftieth SQP converges there in 12
    /// f + 13 g. The Hock–Schittkowski runs pay 54 f + 51 g for it instead
    /// of 50 f + 48 g (2026-12-02; docs/exploration.md).
    pub first_step: f64,
    /// Armijo's fraction η of the predicted merit decrease: 1e-4.
    pub armijo: f64,
    /// Function calls per line search before it counts as failed: 10.
    pub max_line_evaluations: usize,
    /// Evaluate the full step with its gradients once full steps are being
    /// accepted (saves a second evaluation of the same design where an
    /// evaluation with gradients also gives f, as a simulation does).
    pub speculative: bool,
}

impl Default for SqpOptions {
    fn default() -> Self {
        SqpOptions {
            max_iterations: 100,
            ftol: 1e-10,
            tolerances: KktTolerances {
                feasibility: 1e-6,
                active: 1e-4,
                stationarity: 1e-8,
            },
            first_step: 0.02,
            armijo: 1e-4,
            max_line_evaluations: 10,
            speculative: true,
        }
    }
}

impl SqpOptions {
    /// These options with the feasibility tolerance of a study.
    pub fn with_feasibility(mut self, feasibility: f64) -> Self {
        self.tolerances.feasibility = feasibility;
        self
    }

    /// Check the values (error keys as in `[multistart.sqp]`).
    pub fn validate(&self) -> Result<()> {
        for (k, v) in [
            ("ftol", self.ftol),
            ("first_step", self.first_step),
            ("armijo", self.armijo),
            ("feasibility_tolerance", self.tolerances.feasibility),
        ] {
            crate::error::require_positive(k, v)?;
        }
        if self.armijo >= 0.5 {
            return Err(Error::input(
                "armijo",
                self.armijo,
                "a fraction in (0, 0.5)",
            ));
        }
        for (k, v) in [
            ("max_iterations", self.max_iterations),
            ("max_line_evaluations", self.max_line_evaluations),
        ] {
            if v == 0 {
                return Err(Error::input(k, 0, "a count >= 1"));
            }
        }
        Ok(())
    }
}

/// A design with its evaluation and scaled gradients.
#[derive(Debug, Clone)]
struct Point {
    x: Vec<f64>,
    f: f64,
    g: Vec<f64>,
    /// Scaled gradient of f and of each constraint.
    grad_f: Vec<f64>,
    grad_g: Vec<Vec<f64>>,
    /// The unscaled evaluation (for the certificate).
    evaluation: Evaluation,
}

impl Point {
    fn max_g(&self) -> f64 {
        self.g.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }
}

use driver::{counts, variables, Ap};

fn evaluate(problem: &mut Ap<'_>, x: &[f64], gradients: bool) -> Result<Evaluation> {
    driver::evaluate(problem, x, gradients, "optimize::sqp")
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The ℓ1 penalty `Σ μ_j max(0, g_j)`.
fn penalty(mu: &[f64], g: &[f64]) -> f64 {
    mu.iter().zip(g).map(|(m, gj)| m * gj.max(0.0)).sum()
}

/// The SQP engine as an argmin solver on a [`Counted`] problem.
pub struct Sqp {
    options: SqpOptions,
    x0: Vec<f64>,
    range: Vec<f64>,
    current: Option<Point>,
    /// Model Hessian of the Lagrangian (scaled variables).
    b: DMatrix<f64>,
    /// Whether `b` is still the start model (rescaled at the first update).
    b_fresh: bool,
    /// ℓ1 penalties μ_j.
    mu: Vec<f64>,
    /// The last line search accepted the full step.
    full_steps: bool,
    /// Line searches in a row that found no decrease.
    failures: usize,
    iteration: usize,
    termination: Option<Termination>,
    records: std::collections::VecDeque<IterRecord>,
}

impl Sqp {
    /// A solver starting from `x0` (wrapped/clamped into the box).
    pub fn new(problem: &dyn Problem, x0: &[f64], options: SqpOptions) -> Result<Self> {
        options.validate()?;
        let vars = problem.variables();
        if x0.len() != vars.len() {
            return Err(Error::input(
                "sqp.x0",
                x0.len(),
                format!("{} values", vars.len()),
            ));
        }
        let mut x = Vec::with_capacity(x0.len());
        for (i, (v, &xi)) in vars.iter().zip(x0).enumerate() {
            if !xi.is_finite() {
                return Err(Error::input(format!("sqp.x0[{i}]"), xi, "a finite value"));
            }
            x.push(v.wrap(xi));
        }
        let n = vars.len();
        Ok(Sqp {
            range: vars
                .iter()
                .map(|v| v.period.unwrap_or(v.upper - v.lower))
                .collect(),
            options,
            x0: x,
            current: None,
            b: DMatrix::identity(n, n),
            b_fresh: true,
            mu: vec![0.0; problem.n_constraints()],
            full_steps: false,
            failures: 0,
            iteration: 0,
            termination: None,
            records: Default::default(),
        })
    }

    /// Why the solver stopped (None while running).
    pub fn termination(&self) -> Option<&Termination> {
        self.termination.as_ref()
    }

    /// The point of an evaluation with gradients at `x`.
    fn point(&self, x: Vec<f64>, ev: Evaluation) -> Point {
        let scale =
            |g: &[f64]| -> Vec<f64> { g.iter().zip(&self.range).map(|(a, r)| a * r).collect() };
        let grad_f = ev.grad_f.as_deref().map(scale).unwrap_or_default();
        let grad_g = ev
            .grad_g
            .as_ref()
            .map(|rows| rows.iter().map(|r| scale(r)).collect())
            .unwrap_or_default();
        Point {
            x,
            f: ev.f,
            g: ev.g.clone(),
            grad_f,
            grad_g,
            evaluation: ev,
        }
    }

    /// The design at scaled offset `z` from `x`.
    fn moved(&self, problem: &Ap<'_>, x: &[f64], z: &[f64]) -> Vec<f64> {
        variables(problem)
            .iter()
            .enumerate()
            .map(|(i, v)| v.wrap(x[i] + z[i] * self.range[i]))
            .collect()
    }

    /// The start model `σ I` with `σ = |∇f| / first_step` (1 for a zero
    /// gradient).
    fn start_model(&mut self, grad_f: &[f64]) {
        let n = grad_f.len();
        let gn = dot(grad_f, grad_f).sqrt();
        let sigma = if gn > 0.0 {
            gn / self.options.first_step
        } else {
            1.0
        };
        self.b = DMatrix::identity(n, n) * sigma;
        self.b_fresh = true;
    }

    /// Evaluate the start with gradients and record it.
    fn start(&mut self, problem: &mut Ap<'_>) -> Result<()> {
        let ev = evaluate(problem, &self.x0, true)?;
        let p = self.point(self.x0.clone(), ev);
        self.start_model(&p.grad_f);
        self.push_record(problem, &p, 0.0);
        self.current = Some(p);
        Ok(())
    }

    /// Per variable, the scaled distances to its bounds from `x`.
    fn step_bounds(&self, problem: &Ap<'_>, x: &[f64]) -> Vec<Option<(f64, f64)>> {
        variables(problem)
            .iter()
            .enumerate()
            .map(|(i, v)| match v.period {
                Some(_) => None,
                None => Some((
                    (v.lower - x[i]) / self.range[i],
                    (v.upper - x[i]) / self.range[i],
                )),
            })
            .collect()
    }

    /// Step 2 of the module doc: does the run end at `p` with the
    /// subproblem's step `d` and multipliers `lambda`?
    fn converged(&self, problem: &Ap<'_>, p: &Point, d: &[f64], lambda: &[f64]) -> Result<bool> {
        let t = &self.options.tolerances;
        if p.max_g() > t.feasibility {
            return Ok(false);
        }
        let predicted = dot(&p.grad_f, d).abs()
            + lambda
                .iter()
                .zip(&p.g)
                .map(|(l, g)| (l * g).abs())
                .sum::<f64>();
        if predicted <= self.options.ftol * p.f.abs().max(1.0) {
            return Ok(true);
        }
        let cert = kkt::certify(variables(problem), &p.x, &p.evaluation, t)?;
        Ok(cert.class == kkt::EndClass::Converged)
    }

    /// One iteration (steps 1–5 of the module doc).
    fn iterate(&mut self, problem: &mut Ap<'_>) -> Result<()> {
        let cur = self
            .current
            .clone()
            .ok_or_else(|| Error::numerical("optimize::sqp", "no current design"))?;
        let bounds = self.step_bounds(problem, &cur.x);
        let rho = 10.0
            * (1.0
                + self.mu.iter().copied().fold(0.0, f64::max)
                + dot(&cur.grad_f, &cur.grad_f).sqrt());
        let step = Subproblem {
            b: &self.b,
            grad_f: &cur.grad_f,
            g: &cur.g,
            grad_g: &cur.grad_g,
            bounds: &bounds,
            rho,
        }
        .solve()?;
        if self.converged(problem, &cur, &step.d, &step.lambda)? {
            self.termination = Some(Termination::KuhnTucker);
            return Ok(());
        }
        for (m, l) in self.mu.iter_mut().zip(&step.lambda) {
            *m = l.abs().max(0.5 * (*m + l.abs()));
        }
        match self.line_search(problem, &cur, &step.d)? {
            Some((alpha, next)) => {
                self.failures = 0;
                self.update_model(&cur, &next, &step.d, alpha, &step.lambda);
                self.finish_iteration(problem, &cur, next, alpha);
            }
            None => {
                self.failures += 1;
                self.full_steps = false;
                if self.failures >= 2 || self.b_fresh {
                    self.termination = Some(Termination::LineSearchFailed);
                } else {
                    self.start_model(&cur.grad_f);
                }
            }
        }
        Ok(())
    }

    /// Step 4: the accepted step length and design (with gradients), or
    /// `None` when no trial lowered the merit function enough.
    fn line_search(
        &mut self,
        problem: &mut Ap<'_>,
        cur: &Point,
        d: &[f64],
    ) -> Result<Option<(f64, Point)>> {
        let phi0 = cur.f + penalty(&self.mu, &cur.g);
        let lin: Vec<f64> = cur
            .g
            .iter()
            .zip(&cur.grad_g)
            .map(|(g, a)| g + dot(a, d))
            .collect();
        let dphi = dot(&cur.grad_f, d) + penalty(&self.mu, &lin) - penalty(&self.mu, &cur.g);
        if dphi.is_nan() || dphi >= 0.0 {
            return Ok(None);
        }
        let mut alpha = 1.0;
        for _ in 0..self.options.max_line_evaluations {
            let z: Vec<f64> = d.iter().map(|v| alpha * v).collect();
            let x = self.moved(problem, &cur.x, &z);
            if x == cur.x {
                // The step no longer moves the design (below round-off):
                // nothing is left to search along d.
                return Ok(None);
            }
            let with_gradients = self.options.speculative && alpha == 1.0 && self.full_steps;
            let ev = evaluate(problem, &x, with_gradients)?;
            let phi = ev.f + penalty(&self.mu, &ev.g);
            if phi < phi0 && phi <= phi0 + self.options.armijo * alpha * dphi {
                self.full_steps = alpha == 1.0;
                let ev = if with_gradients {
                    ev
                } else {
                    evaluate(problem, &x, true)?
                };
                return Ok(Some((alpha, self.point(x, ev))));
            }
            // Minimizer of φ(0) + Dφ a + c a² through φ(alpha).
            let c = (phi - phi0 - dphi * alpha) / (alpha * alpha);
            let fit = if c > 0.0 {
                -dphi / (2.0 * c)
            } else {
                0.1 * alpha
            };
            alpha = fit.clamp(0.1 * alpha, 0.5 * alpha);
            self.full_steps = false;
        }
        Ok(None)
    }

    /// Step 5: the damped BFGS update over the accepted step.
    fn update_model(&mut self, old: &Point, new: &Point, d: &[f64], alpha: f64, lambda: &[f64]) {
        let n = d.len();
        let s: Vec<f64> = d.iter().map(|v| alpha * v).collect();
        let lagrangian = |p: &Point| -> Vec<f64> {
            let mut v = p.grad_f.clone();
            for (l, row) in lambda.iter().zip(&p.grad_g) {
                for (vi, ri) in v.iter_mut().zip(row) {
                    *vi += l * ri;
                }
            }
            v
        };
        let (ln, lo) = (lagrangian(new), lagrangian(old));
        let y: Vec<f64> = ln.iter().zip(&lo).map(|(a, b)| a - b).collect();
        let sy = dot(&s, &y);
        if self.b_fresh && sy > 0.0 {
            self.b = DMatrix::identity(n, n) * (dot(&y, &y) / sy);
        }
        self.b_fresh = false;
        let sv = nalgebra::DVector::from_column_slice(&s);
        let mut bs = &self.b * &sv;
        let mut sbs = sv.dot(&bs);
        if sbs.is_nan() || sbs <= 0.0 || !sy.is_finite() {
            return;
        }
        // Self-scaling (Oren–Luenberger): a model steeper along s than the
        // measured curvature is shrunk as a whole first.
        if sy > 0.0 && sy < sbs {
            let tau = sy / sbs;
            self.b *= tau;
            bs *= tau;
            sbs = sy;
        }
        let theta = if sy >= 0.2 * sbs {
            1.0
        } else {
            0.8 * sbs / (sbs - sy)
        };
        let r = nalgebra::DVector::from_iterator(
            n,
            y.iter()
                .zip(bs.iter())
                .map(|(a, b)| theta * a + (1.0 - theta) * b),
        );
        let sr = sv.dot(&r);
        if sr.is_nan() || sr <= 0.0 {
            return;
        }
        self.b += &r * r.transpose() / sr - &bs * bs.transpose() / sbs;
        // Keep it symmetric against round-off.
        self.b = (&self.b + self.b.transpose()) * 0.5;
        if self.b.clone().cholesky().is_none() {
            self.start_model(&new.grad_f);
        }
    }

    /// Record the iteration and apply the change exit.
    fn finish_iteration(&mut self, problem: &Ap<'_>, old: &Point, new: Point, alpha: f64) {
        self.iteration += 1;
        let feasible = new.max_g() <= self.options.tolerances.feasibility
            && old.max_g() <= self.options.tolerances.feasibility;
        let change = (new.f - old.f).abs();
        let moved = self.scaled_distance(problem, &old.x, &new.x);
        self.push_record(problem, &new, moved);
        let small = change <= self.options.ftol * old.f.abs().max(1.0);
        self.current = Some(new);
        if feasible && small && alpha == 1.0 {
            self.termination = Some(Termination::RelativeChange);
        } else if self.iteration >= self.options.max_iterations {
            self.termination = Some(Termination::MaxIterations);
        }
    }

    fn scaled_distance(&self, problem: &Ap<'_>, a: &[f64], b: &[f64]) -> f64 {
        variables(problem)
            .iter()
            .enumerate()
            .map(|(i, v)| (v.difference(a[i], b[i]) / self.range[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    fn push_record(&mut self, problem: &Ap<'_>, p: &Point, step: f64) {
        let (fc, gc) = counts(problem);
        self.records.push_back(IterRecord {
            iteration: self.iteration,
            x: p.x.clone(),
            f: p.f,
            g: p.g.clone(),
            max_g: p.max_g(),
            ct: Some(-self.options.tolerances.active),
            step,
            function_calls: fc,
            gradient_calls: gc,
        });
    }
}

impl Recorded for Sqp {
    fn take_record(&mut self) -> Option<IterRecord> {
        self.records.pop_front()
    }
}

impl<'a> Solver<Counted<'a>, OptState> for Sqp {
    fn name(&self) -> &str {
        "SQP"
    }

    fn init(
        &mut self,
        problem: &mut ArgminProblem<Counted<'a>>,
        state: OptState,
    ) -> std::result::Result<(OptState, Option<KV>), argmin::core::Error> {
        self.start(problem).map_err(argmin::core::Error::from)?;
        let f = self.current.as_ref().map_or(f64::NAN, |p| p.f);
        Ok((state.param(self.x0.clone()).cost(f), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut ArgminProblem<Counted<'a>>,
        state: OptState,
    ) -> std::result::Result<(OptState, Option<KV>), argmin::core::Error> {
        self.iterate(problem).map_err(argmin::core::Error::from)?;
        let (x, f) = match &self.current {
            Some(p) => (p.x.clone(), p.f),
            None => (self.x0.clone(), f64::NAN),
        };
        Ok((state.param(x).cost(f), None))
    }

    fn terminate(&mut self, _state: &OptState) -> TerminationStatus {
        match &self.termination {
            Some(t) => TerminationStatus::Terminated(TerminationReason::SolverExit(t.to_string())),
            None => TerminationStatus::NotTerminated,
        }
    }
}

/// Minimize `problem` from `x0` with SQP; records go to `observer`, one
/// per iteration (the start first).
pub fn minimize(
    problem: &dyn Problem,
    x0: &[f64],
    options: &SqpOptions,
    observer: &mut dyn Observer,
) -> Result<LocalOutcome> {
    let mut solver = Sqp::new(problem, x0, options.clone())?;
    let mut ap = ArgminProblem::new(Counted::new(problem));
    driver::run(&mut solver, &mut ap, OptState::new(), observer)?;
    let p = solver
        .current
        .clone()
        .ok_or_else(|| Error::numerical("optimize::sqp", "no iteration was run"))?;
    Ok(driver::local_outcome(
        &ap,
        (p.x, p.f, p.g),
        -options.tolerances.active,
        solver.iteration,
        solver.termination,
    ))
}

#[cfg(test)]
mod tests;
