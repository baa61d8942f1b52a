//! The modified method of feasible directions (MMFD), as in Vanderplaats'
//! CONMIN/ADS/DOT, which the paper uses (§5, Table 5), as an argmin
//! [`Solver`].
//!
//! Problem: minimize `f(x)` subject to `g_j(x) <= 0` and the bounds of the
//! non-periodic variables (side constraints). Periodic variables are
//! wrapped into their box and never stopped by a bound. Directions and
//! steps live in range-scaled coordinates `y_i = x_i / (upper_i − lower_i)`
//! (the period for periodic variables), so a unit step spans a variable's
//! whole range and variables in degrees and metres are treated alike.
//!
//! One iteration (one gradient evaluation at the current design):
//! 1. Sets: active `g_j >= CT`, violated `g_j > CTMIN`, active side
//!    constraints (a non-periodic variable on its bound). CT starts at the
//!    option `ct` (< 0) and shrinks by `ct_reduction` each iteration towards
//!    `−ctmin`, as CONMIN does, so the active set sharpens near the optimum.
//! 2. Infeasible design → feasibility-restoration move (`restore`): the
//!    shortest step `S` with `g_j + ∇g_jᵀS <= −ctmin/2` for the active and
//!    violated constraints and inside the bounds (push-off past the limit
//!    by half the tolerance), solved exactly by [`super::qp`]. Near the
//!    feasible set it is taken as a Newton step, shortened until the
//!    largest violation decreases. When Newton steps stall (no shortening
//!    lowers the violation, or three in a row lower it by less than 1 %
//!    each), the restoration continues as a descent on the violation `½ Σ max(0, g_j +
//!    ctmin/2)²` along `S` with moves of up to DX2 and Armijo's test; the
//!    run ends `infeasible` only when that descent finds no decrease.
//! 3. Feasible, nothing active → steepest descent, conjugated by
//!    Fletcher–Reeves (`β = |∇f_k|²/|∇f_{k−1}|²`) while consecutive
//!    iterations stay unconstrained, restarted every n iterations.
//! 4. Feasible, something active → the MMFD direction: `min ½|S|² + ∇fᵀS`
//!    s.t. `∇g_jᵀS <= 0` (active) and `S_i >= 0` / `<= 0` (at a lower /
//!    upper bound), i.e. `−∇f` projected onto the cone of non-increasing
//!    directions, solved exactly. Multipliers `λ_j > 0` mark the binding
//!    constraints B; `|S| = 0` with B on its limits is the Kuhn–Tucker
//!    condition.
//! 5. Line search along `x(α) = x + c₀ + αS` by polynomial interpolation:
//!    `c₀ = −N_B(N_BᵀN_B)⁻¹ g_B` first moves onto the binding constraints'
//!    linearised limits; every trial point is pulled back onto them by
//!    Newton corrections with the frozen gradients N_B (constraint
//!    following; one function call each, at most `max_corrections`, stopped
//!    early if they diverge). The pull-back of the last trial, scaled by
//!    `(α/α_last)²`, predicts the next one (the curvature of the limits).
//!    First trial length: on the first iteration the one that changes f by
//!    `dobj1`·|f| on the linear model, but at least a `dx1` move; later
//!    the minimizer of the quadratic model with the curvature of the
//!    Lagrangian along `S`, `α = −f'(0)/(SᵀHS)`: `H` is a damped BFGS
//!    model (`geometry::Bfgs`) started as `κI` with the secant curvature
//!    `κ = sᵀy/sᵀs` of the first pair and updated with every later pair
//!    (`s` the scaled step between two gradient evaluations, `y` the
//!    change of `∇f + Σ λ_j ∇g_j` over it, λ the binding multipliers of
//!    the direction), capped by `dobj2`·|f|; without a model the
//!    Nocedal–Wright estimates `α_prev f'_prev/f'` and
//!    `2|Δf_prev|/|f'|` capped by `dobj2`·|f|, or the previous α when
//!    following constraints; always at most a `dx2` move of any variable
//!    and inside the bounds.
//!    Phase A shortens the trial until it is feasible and decreases f
//!    (Armijo: `f(α) < φ(0) + 10⁻⁴ α f'(0)`): a quadratic through `φ(0)`,
//!    `f'(0)` and the trial (down to 0.01×), or a violated constraint's
//!    zero crossing (quadratic in α from `g(0)`, `∇gᵀS` and the trial).
//!    Phase B fits `q(α) = φ(0) + f'(0) α + c α²` through the accepted
//!    trial (three points after a rejected one) and stops without a
//!    further call when the trial already realizes 90 % of the fit's
//!    decrease, `(α/α* − 1)² <= 0.1` for the fit's minimizer α*. Otherwise
//!    it evaluates α* (capped at 4× the trial, the bounds and constraint
//!    crossings; longer extrapolations continue) *with gradients*, as an
//!    SQP code evaluates its step: accepted (feasible, lower f, the
//!    followed constraints met without a correction), that evaluation is
//!    the next iteration's; otherwise it is an ordinary trial. It is
//!    evaluated without gradients when the fit's f would end the run by a
//!    change exit (no iteration would use the gradients), and when the
//!    followed constraints needed a correction in this search (curved
//!    limits: the step will be corrected, and gradients at the uncorrected
//!    point would be wasted). This, DOT's idea of not evaluating what a
//!    fit predicts well, takes about one function call per gradient call
//!    in the search.
//!
//!    *Step 5b, the slope search* (the polish's option `slope_search`): near an
//!    optimum the decrease a step can make, `½ f'(0)²/κ`, falls below the
//!    noise of an evaluation that integrates a motion with adaptive steps
//!    (about 1e-7 of f on the SAR problem), and phase A finds no decrease
//!    although the exact gradients still point downhill. Then each trial
//!    is evaluated with gradients and judged by its slope `∇f(x(α))ᵀS`:
//!    accepted while it is negative or at most half `|f'(0)|` (the 1-D
//!    minimum not passed, or bracketed closely), moved to the secant root
//!    of the slope when it is steeper positive, and shortened tenfold when
//!    infeasible or when f rises by more than its noise
//!    `max(|f'(0)| α, noise·max(|f|, 1))` (option `noise`, 1e-6 in the
//!    polish: on the SAR problem f jumps by 2.8e-7 of itself between
//!    designs 1e-6° apart, where the adaptive integrator's step sequence
//!    changes). The Kuhn–Tucker test of step 6, with the
//!    exact gradients, then decides where the polish ends; the polish
//!    ends `no_feasible_direction` when three slope steps in a row leave
//!    `|S|` above 0.9 of its smallest value so far (the gradients' own
//!    error floor).
//! 6. Convergence: `|Δf| < DABOBJ` or `|Δf|/|f| < DELOBJ` for ITRMOP
//!    consecutive feasible iterations, or the Kuhn–Tucker test
//!    `|S| <= kt_tolerance · max(|f|, 1)` (or `max(|∇f|, 1)` with the
//!    scaled gradient, option `kt_scale`) with the binding constraints
//!    within CTMIN of their limits, or, with a noise allowance (option
//!    `noise`), the same test at the noise as the certificate's
//!    ([`super::kkt`]): a feasible design, binding constraints within
//!    CTMIN, and the decrease the curvature model predicts along `S` (along
//!    `−∇f` when nothing is active), `(∇fᵀS)²/(2SᵀHS)`, within the
//!    allowance `noise · max(|f|, 1)` (exit `at_noise`). The outcome hands
//!    the model to the certificate ([`LocalOutcome::curvature`]).
//!
//! Counting follows DOT (and the paper's Table 5) and scipy, see
//! [`Counted`]: an evaluation with gradients counts one gradient call,
//! plus one function call unless it is at the design evaluated just before
//! (the accepted point of a line search).

use super::driver::{self, OptState, Recorded};
use super::{kkt, Counted, Evaluation, IterRecord, LocalOutcome, Observer, Problem, Termination};
use crate::error::{Error, Result};
use argmin::core::{
    Problem as ArgminProblem, Solver, State, TerminationReason, TerminationStatus, KV,
};
use direction::{Direction, SideConstraints};
use geometry::{dot, least_norm, norm};
pub use options::{KtScale, MmfdOptions};
use restore::Restoration;
use search::Search;

mod direction;
mod geometry;
mod options;
mod restore;
mod search;
#[cfg(test)]
mod tests;

/// A design with its scaled gradients of f and of the constraints.
type Secant = (Vec<f64>, Vec<f64>, Vec<Vec<f64>>);

/// A design with its (function-only or full) evaluation.
#[derive(Debug, Clone)]
struct Point {
    x: Vec<f64>,
    f: f64,
    g: Vec<f64>,
}

impl Point {
    fn max_g(&self) -> f64 {
        self.g.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }
}

/// The MMFD engine as an argmin solver on a [`Counted`] problem; the state's
/// parameter is the current design.
pub struct Mmfd {
    options: MmfdOptions,
    x0: Vec<f64>,
    /// Range (or period) of each variable: the scaling of directions.
    range: Vec<f64>,
    current: Option<Point>,
    ct_now: f64,
    dabobj: f64,
    /// Previous unconstrained scaled gradient and direction (Fletcher–Reeves).
    fr_prev: Option<(Vec<f64>, Vec<f64>)>,
    fr_count: usize,
    /// Previous accepted step length and its slope, for the next first trial.
    prev_step: Option<(f64, f64)>,
    /// The last gradient evaluation's design and scaled gradients of f
    /// and the constraints: the secant curvature of the next iteration.
    secant: Option<Secant>,
    /// Damped BFGS model of the Lagrangian's curvature (scaled).
    curvature: geometry::Bfgs,
    /// |Δf| of the last iteration (quadratic first-trial estimate
    /// `α = 2|Δf|/|f'(0)|`, Nocedal & Wright eq. 3.60).
    last_change: f64,
    abs_count: usize,
    rel_count: usize,
    failed_searches: usize,
    /// Consecutive Newton restorations that lowered the largest violation
    /// by less than 1 % (three switch to descent on the violation).
    slow_restorations: usize,
    /// How the next restoration chooses its length.
    restoration: Restoration,
    /// The smallest `|S|` of the slope search's steps, and its steps since
    /// (see [`Mmfd::slope_stalled`]).
    slope_best: f64,
    slope_stalls: usize,
    iteration: usize,
    termination: Option<Termination>,
    /// The start's evaluation (made by `init`, used by the first
    /// iteration).
    start_evaluation: Option<Evaluation>,
    /// Records not yet passed on.
    records: std::collections::VecDeque<IterRecord>,
}

use driver::{counts, variables, Ap};

fn evaluate(problem: &mut Ap<'_>, x: &[f64], gradients: bool) -> Result<Evaluation> {
    driver::evaluate(problem, x, gradients, "optimize::mmfd")
}

impl Mmfd {
    /// A solver starting from `x0` (wrapped/clamped into the box).
    pub fn new(problem: &dyn Problem, x0: &[f64], options: MmfdOptions) -> Result<Self> {
        options.validate()?;
        let vars = problem.variables();
        if x0.len() != vars.len() {
            return Err(Error::input(
                "mmfd.x0",
                x0.len(),
                format!("{} values", vars.len()),
            ));
        }
        let mut x = Vec::with_capacity(x0.len());
        for (i, (v, &xi)) in vars.iter().zip(x0).enumerate() {
            if !xi.is_finite() {
                return Err(Error::input(format!("mmfd.x0[{i}]"), xi, "a finite value"));
            }
            x.push(v.wrap(xi));
        }
        let range = vars
            .iter()
            .map(|v| v.period.unwrap_or(v.upper - v.lower))
            .collect();
        Ok(Mmfd {
            ct_now: options.ct,
            options,
            x0: x,
            range,
            current: None,
            dabobj: 0.0,
            fr_prev: None,
            fr_count: 0,
            prev_step: None,
            secant: None,
            curvature: geometry::Bfgs::default(),
            last_change: f64::INFINITY,
            abs_count: 0,
            rel_count: 0,
            failed_searches: 0,
            slow_restorations: 0,
            restoration: Restoration::Newton,
            slope_best: f64::INFINITY,
            slope_stalls: 0,
            iteration: 0,
            termination: None,
            start_evaluation: None,
            records: Default::default(),
        })
    }

    /// Why the solver stopped (None while running).
    pub fn termination(&self) -> Option<&Termination> {
        self.termination.as_ref()
    }

    /// The current design with its f and g.
    pub fn current(&self) -> Option<(&[f64], f64, &[f64])> {
        self.current
            .as_ref()
            .map(|p| (p.x.as_slice(), p.f, p.g.as_slice()))
    }

    /// Design at scaled offset `z` from `x`: wrapped (periodic) or clamped.
    fn moved(&self, problem: &Ap<'_>, x: &[f64], z: &[f64]) -> Vec<f64> {
        let vars = variables(problem);
        vars.iter()
            .enumerate()
            .map(|(i, v)| v.wrap(x[i] + z[i] * self.range[i]))
            .collect()
    }

    /// Whether an iteration from `old` to a feasible design with f =
    /// `f_new` would end the run by a change exit (then its point is not
    /// evaluated with gradients: no iteration would use them).
    fn would_stop(&self, old: &Point, f_new: f64) -> bool {
        let o = &self.options;
        let df = (f_new - old.f).abs();
        (self.abs_count + 1 >= o.itrmop && df < self.dabobj)
            || (self.rel_count + 1 >= o.itrmop && df < o.delobj * old.f.abs().max(1e-300))
    }

    /// Record the iteration and update the convergence counters.
    fn finish_iteration(&mut self, problem: &Ap<'_>, old: &Point, new: Point, step: f64) {
        let o = self.options.clone();
        let feasible = old.max_g() <= o.ctmin && new.max_g() <= o.ctmin;
        let df = (new.f - old.f).abs();
        if df > 0.0 {
            self.last_change = df;
        }
        if feasible && df < self.dabobj {
            self.abs_count += 1;
        } else {
            self.abs_count = 0;
        }
        if feasible && df < o.delobj * old.f.abs().max(1e-300) {
            self.rel_count += 1;
        } else {
            self.rel_count = 0;
        }
        self.iteration += 1;
        self.ct_now = (self.ct_now * o.ct_reduction).min(-o.ctmin);
        self.push_record(problem, &new, step);
        self.current = Some(new);
        if self.abs_count >= o.itrmop {
            self.termination = Some(Termination::AbsoluteChange);
        } else if self.rel_count >= o.itrmop {
            self.termination = Some(Termination::RelativeChange);
        } else if self.iteration >= o.max_iterations {
            self.termination = Some(Termination::MaxIterations);
        }
    }

    /// Scaled step length `|Δy|` between two designs.
    fn scaled_distance(&self, problem: &Ap<'_>, a: &[f64], b: &[f64]) -> f64 {
        let vars = variables(problem);
        vars.iter()
            .enumerate()
            .map(|(i, v)| (v.difference(a[i], b[i]) / self.range[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// Step 2: the restoration move from the infeasible `base` (Newton,
    /// or descent on the violation; see [`restore`]); `None` when neither
    /// lowers the violation.
    fn restoration_move(
        &mut self,
        problem: &mut Ap<'_>,
        base: &Point,
        gg: &[Vec<f64>],
    ) -> Result<Option<Point>> {
        let s = self.restoration_direction(problem, base, gg)?;
        if let (Restoration::Newton, Some(s)) = (self.restoration, &s) {
            if let Some(p) = self.newton_restoration(problem, base, gg, s)? {
                let slow = base.max_g() - p.max_g() < 0.01 * base.max_g();
                self.slow_restorations = if slow { self.slow_restorations + 1 } else { 0 };
                if self.slow_restorations >= 3 {
                    self.restoration = Restoration::Descent(0.5 * self.options.dx2);
                }
                return Ok(Some(p));
            }
        }
        let last = match self.restoration {
            Restoration::Descent(last) => last,
            Restoration::Newton => 0.5 * self.options.dx2,
        };
        let moved = self.violation_descent(problem, base, gg, s.as_deref(), last)?;
        Ok(moved.map(|(p, step)| {
            self.restoration = Restoration::Descent(step);
            p
        }))
    }

    /// One MMFD iteration (steps 1–6 of the module doc).
    fn iterate(&mut self, problem: &mut Ap<'_>) -> Result<()> {
        let vars = variables(problem).to_vec();
        let (base, gf, gg) = self.base_point(problem)?;
        // Step 2: restoration.
        if base.max_g() > self.options.ctmin {
            return self.restore_from(problem, &base, &gg);
        }
        self.restoration = Restoration::Newton;
        self.slow_restorations = 0;
        // Step 1: active sets.
        let active: Vec<usize> = (0..base.g.len())
            .filter(|&j| base.g[j] >= self.ct_now)
            .collect();
        let sides = SideConstraints::at(&vars, &base.x, &self.range);
        // Steps 3–4: direction.
        let unconstrained = active.is_empty() && sides.rows.is_empty();
        let dir = if unconstrained {
            self.conjugate_direction(&gf)
        } else {
            self.fr_prev = None;
            self.fr_count = 0;
            Direction::projected(&gf, &gg, &active, &sides)?
        };
        self.update_curvature(&vars, &base.x, (&gf, &gg), &dir);
        let curvature = self.curvature.along(&dir.s);
        self.secant = Some((base.x.clone(), gf.clone(), gg.clone()));
        // Kuhn–Tucker test.
        if self.kuhn_tucker(&base, &gf, &dir) {
            self.stop(problem, &base, Termination::KuhnTucker);
            return Ok(());
        }
        if self.at_noise(&base, &gf, &dir, unconstrained) {
            self.stop(problem, &base, Termination::AtNoise);
            return Ok(());
        }
        self.search_and_move(problem, &base, (&gf, &gg), &dir, curvature)
    }

    /// The current design evaluated with gradients (the evaluation the
    /// last step made, if any; the start's on the first iteration), with
    /// the gradients of f and of the constraints scaled by the ranges.
    fn base_point(&mut self, problem: &mut Ap<'_>) -> Result<(Point, Vec<f64>, Vec<Vec<f64>>)> {
        if self.current.is_none() {
            self.start(problem)?;
        }
        let x = self
            .current
            .as_ref()
            .map(|p| p.x.clone())
            .unwrap_or_default();
        let ev = match self.start_evaluation.take() {
            Some(ev) => ev,
            None => evaluate(problem, &x, true)?,
        };
        let base = Point {
            x,
            f: ev.f,
            g: ev.g.clone(),
        };
        let missing = || Error::numerical("optimize::mmfd", "problem returned no gradients");
        let gf: Vec<f64> = ev
            .grad_f
            .as_ref()
            .ok_or_else(missing)?
            .iter()
            .zip(&self.range)
            .map(|(g, r)| g * r)
            .collect();
        let gg: Vec<Vec<f64>> = match &ev.grad_g {
            Some(rows) => rows
                .iter()
                .map(|row| row.iter().zip(&self.range).map(|(g, r)| g * r).collect())
                .collect(),
            None if base.g.is_empty() => vec![],
            None => return Err(missing()),
        };
        if gf.iter().chain(gg.iter().flatten()).any(|v| !v.is_finite()) {
            return Err(Error::numerical(
                "optimize::mmfd",
                format!("non-finite gradient at x = {:?}", base.x),
            ));
        }
        Ok((base, gf, gg))
    }

    /// Step 2 from the infeasible `base`: the restoration move, or the end
    /// of the run (`infeasible`) when no move lowers the violation.
    fn restore_from(&mut self, problem: &mut Ap<'_>, base: &Point, gg: &[Vec<f64>]) -> Result<()> {
        self.fr_prev = None;
        self.prev_step = None;
        match self.restoration_move(problem, base, gg)? {
            Some(p) => {
                let step = self.scaled_distance(problem, &p.x, &base.x);
                self.finish_iteration(problem, base, p, step);
            }
            None => self.stop(problem, base, Termination::Infeasible),
        }
        Ok(())
    }

    /// The Kuhn–Tucker test of step 6: `|S|` within `kt_tolerance` of the
    /// option's scale with the binding constraints on their limits.
    fn kuhn_tucker(&self, base: &Point, gf: &[f64], dir: &Direction) -> bool {
        let o = &self.options;
        let on_limits = dir.binding.iter().all(|&j| base.g[j].abs() <= o.ctmin);
        let kt_scale = match o.kt_scale {
            KtScale::Objective => base.f.abs().max(1.0),
            KtScale::Gradient => norm(gf).max(1.0),
        };
        norm(&dir.s) <= o.kt_tolerance * kt_scale && on_limits
    }

    /// The exit at the noise of step 6: with a noise allowance (option
    /// `noise`), a feasible design whose binding constraints are on their
    /// limits and from which the curvature model predicts a decrease
    /// ([`kkt::decrease_left`]) within the allowance `noise · max(|f|, 1)`
    /// along the direction the certificate tests: `S`, or `−∇f` when
    /// nothing is active (`S` is then conjugated).
    fn at_noise(&self, base: &Point, gf: &[f64], dir: &Direction, unconstrained: bool) -> bool {
        let o = &self.options;
        let Some(h) = self.curvature.matrix() else {
            return false;
        };
        if o.noise <= 0.0 || base.max_g() > o.ctmin {
            return false;
        }
        let on_limits = dir.binding.iter().all(|&j| base.g[j].abs() <= o.ctmin);
        let steepest: Vec<f64>;
        let s = if unconstrained {
            steepest = gf.iter().map(|v| -v).collect();
            &steepest
        } else {
            &dir.s
        };
        let allowance = o.noise * base.f.abs().max(1.0);
        on_limits && kkt::decrease_left(h, gf, s).is_some_and(|d| d <= allowance)
    }

    /// Steps 5–5b: the line search along `dir` (then, if enabled and it
    /// fails, the slope search) and the move to the point found. The run
    /// ends when the slope search stalls or two searches in a row fail.
    fn search_and_move(
        &mut self,
        problem: &mut Ap<'_>,
        base: &Point,
        (gf, gg): (&[f64], &[Vec<f64>]),
        dir: &Direction,
        curvature: Option<f64>,
    ) -> Result<()> {
        let n = base.x.len();
        let (s, binding) = (&dir.s, &dir.binding);
        let c0 = if binding.is_empty() {
            vec![0.0; n]
        } else {
            let cols: Vec<&[f64]> = binding.iter().map(|&j| gg[j].as_slice()).collect();
            let r: Vec<f64> = binding.iter().map(|&j| base.g[j]).collect();
            least_norm(&cols, &r).unwrap_or_else(|| vec![0.0; n])
        };
        let d0 = dot(gf, s);
        let sr = Search {
            base,
            gf,
            gg,
            s,
            c0: &c0,
            binding,
            curvature,
            learned: std::cell::RefCell::new(None),
        };
        let searched = match self.line_search(problem, &sr)? {
            None if self.options.slope_search => {
                let found = self.slope_search(problem, &sr)?;
                if found.is_some() && self.slope_stalled(norm(s)) {
                    self.stop(problem, base, Termination::NoFeasibleDirection);
                    return Ok(());
                }
                found
            }
            found => found,
        };
        match searched {
            Some((p, alpha, ev)) => {
                self.failed_searches = 0;
                self.start_evaluation = ev;
                if alpha > 0.0 {
                    self.prev_step = Some((alpha, d0));
                }
                let step = self.scaled_distance(problem, &p.x, &base.x);
                self.finish_iteration(problem, base, p, step);
            }
            None => {
                self.failed_searches += 1;
                self.fr_prev = None;
                self.prev_step = None;
                if self.failed_searches >= 2 {
                    self.stop(problem, base, Termination::NoFeasibleDirection);
                } else {
                    self.finish_iteration(problem, base, base.clone(), 0.0);
                }
            }
        }
        Ok(())
    }

    /// End the run at `base`, not moved, for `why`.
    fn stop(&mut self, problem: &Ap<'_>, base: &Point, why: Termination) {
        self.current = Some(base.clone());
        self.termination = Some(why);
        self.record_stay(problem, base);
    }

    /// Whether the slope search has stalled: a step it found from a
    /// direction of size `size` (the Kuhn–Tucker measure `|S|`) that is not
    /// 10 % below the smallest of its earlier steps, for the third time.
    /// The gradients' own error then keeps `|S|` from falling further.
    fn slope_stalled(&mut self, size: f64) -> bool {
        if size < 0.9 * self.slope_best {
            self.slope_best = size;
            self.slope_stalls = 0;
        } else {
            self.slope_stalls += 1;
        }
        self.slope_stalls >= 3
    }

    /// Evaluate the start design with gradients (kept for the first
    /// iteration), set DABOBJ from its f and record it.
    fn start(&mut self, problem: &mut Ap<'_>) -> Result<()> {
        let ev = evaluate(problem, &self.x0, true)?;
        let base = Point {
            x: self.x0.clone(),
            f: ev.f,
            g: ev.g.clone(),
        };
        self.dabobj = self
            .options
            .dabobj
            .unwrap_or((1e-4 * base.f.abs()).max(1e-10));
        self.push_record(problem, &base, 0.0);
        self.current = Some(base);
        self.start_evaluation = Some(ev);
        Ok(())
    }

    /// Record a final iteration that did not move.
    fn record_stay(&mut self, problem: &Ap<'_>, p: &Point) {
        self.push_record(problem, p, 0.0);
    }

    /// Queue the record of design `p` reached by a scaled step `step`, with
    /// the iterations completed, the calls so far and the current CT.
    fn push_record(&mut self, problem: &Ap<'_>, p: &Point, step: f64) {
        let (fc, gc) = counts(problem);
        self.records.push_back(IterRecord {
            iteration: self.iteration,
            x: p.x.clone(),
            f: p.f,
            g: p.g.clone(),
            max_g: p.max_g(),
            ct: Some(self.ct_now),
            step,
            function_calls: fc,
            gradient_calls: gc,
        });
    }
}

impl Recorded for Mmfd {
    fn take_record(&mut self) -> Option<IterRecord> {
        self.records.pop_front()
    }
}

impl<'a> Solver<Counted<'a>, OptState> for Mmfd {
    fn name(&self) -> &str {
        "MMFD"
    }

    /// Evaluate and record the start (so that its record leaves before the
    /// first iteration's work).
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

/// Minimize `problem` from `x0` with MMFD; records go to `observer`, one
/// per iteration. The outcome carries Table 5's counts: iterations,
/// function and gradient calls, active constraints (`g >= CT` with the
/// final CT) and active side constraints, plus why it stopped.
pub fn minimize(
    problem: &dyn Problem,
    x0: &[f64],
    options: &MmfdOptions,
    observer: &mut dyn Observer,
) -> Result<LocalOutcome> {
    let mut solver = Mmfd::new(problem, x0, options.clone())?;
    let mut ap = ArgminProblem::new(Counted::new(problem));
    driver::run(&mut solver, &mut ap, OptState::new(), observer)?;
    let p = solver
        .current
        .clone()
        .ok_or_else(|| Error::numerical("optimize::mmfd", "no iteration was run"))?;
    Ok(LocalOutcome {
        curvature: solver.curvature.matrix().map(<[f64]>::to_vec),
        ..driver::local_outcome(
            &ap,
            (p.x, p.f, p.g),
            solver.ct_now,
            solver.iteration,
            solver.termination,
        )
    })
}
