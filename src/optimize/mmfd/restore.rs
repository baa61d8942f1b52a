//! Step 2 of the method: restoring feasibility from an infeasible design.
//!
//! The restoration direction `S` is the shortest step to the linearised
//! limits of the active and violated constraints, pushed past them by half
//! the tolerance, inside the bounds:
//!
//! ```text
//!   min ½|S|²   s.t.   g_j + ∇g_jᵀS <= −ctmin/2  (g_j >= CT),   bounds,
//! ```
//!
//! solved exactly by [`crate::optimize::qp`] (for one violated constraint
//! `S = −(g + ctmin/2) ∇g/|∇g|²`, the steepest descent on the violation;
//! for several a Gauss–Newton step). Its length is taken in one of two
//! ways:
//!
//! - **Newton** (near the feasible set, the usual case inside an
//!   optimization): the full step first, shortened until the largest
//!   violation decreases (quadratic backtracking with the known slope,
//!   factors 0.1–0.5, down to a move of 1e-10 of the ranges). Where the
//!   linearisation describes the constraints this lands on their limits
//!   in one or two iterations.
//! - **Descent on the violation** (when the Newton steps stall: no
//!   shortening lowers the largest violation, or three restorations in a
//!   row lower it by less than 1 % each, as in a curved valley of the
//!   violation or at a local minimum of it along `S`): there the
//!   linearisation says nothing about the length (a peak constraint with
//!   many local minima, as the SAR problem's, sends the Newton step across
//!   several of them), so the step is chosen by the
//!   merit of the violation
//!
//!   ```text
//!     V(x) = ½ Σ_j max(0, g_j(x) + ctmin/2)²,
//!   ```
//!
//!   whose slope along `S` is `∇Vᵀ S <= −2V` by the subproblem's
//!   constraints (`−∇V`, projected on the bounds, when the subproblem
//!   gives no descent). The first trial moves the largest-moving variable
//!   by DX2 of its range, later ones by twice the last accepted move (at
//!   most DX2), and a trial is accepted on sufficient decrease
//!   `V(α) <= V(0) + 10⁻⁴ α ∇VᵀS` (Armijo), else shortened as above. This
//!   is the descent that [`crate::explore`]'s violation check runs
//!   independently from the same start; it continues until the design is
//!   feasible (then the method's ordinary steps resume) or no trial down
//!   to a move of 1e-10 lowers V: the run ends `infeasible` there, at a
//!   stationary point of the violation or at a kink or noise floor of it.
//!   (Before, the stall itself ended the run: on the SAR sweep 51 runs
//!   ended `infeasible` and none of them at a stationary point.)
//!
//! **Kinks.** A peak constraint is the larger of two smooth functions
//! where two local maxima in time have the same height; there the
//! violation has a kink, its gradient jumps between the two branches, and
//! a descent zigzags onto the kink with shrinking steps. On the SAR
//! problem from sweep start 16 the descent ends so at 37.2°/−32.8°, g =
//! 0.034, where U3's interior maximum at 2.33 s and its value at the end
//! time, 3 s, agree to 1e-8; a bundle of the two branches' linearisations
//! (the previous iterate's kept in the subproblem) found no descent there
//! either, so the kink is a local minimum of the violation, which the
//! single-branch gradient of the peak cannot certify (the end is reported
//! `infeasible`, not stationary).
//!
//! Why Newton first: on the ripple test problem
//! ([`crate::optimize::testproblems::ripple`]) descent on the violation
//! from every infeasible start reaches the feasible set from 32 of 144
//! starts of a grid; Newton steps, continued by the descent where they
//! stall, from 44 (`tests/suite/optimize/mmfd.rs`).

use super::geometry::{dot, norm};
use super::{evaluate, variables, Ap, Mmfd, Point};
use crate::error::Result;
use crate::optimize::qp;

/// Armijo's sufficient-decrease factor of the descent on the violation.
const ARMIJO: f64 = 1e-4;

/// How the next restoration chooses its length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Restoration {
    /// The Newton step, shortened until the largest violation decreases.
    Newton,
    /// Descent on the violation; the field is the last accepted move
    /// (largest scaled component), or DX2/2 before the first.
    Descent(f64),
}

/// The violation merit `V = ½ Σ max(0, g_j + shift)²`.
fn merit(g: &[f64], shift: f64) -> f64 {
    0.5 * g.iter().map(|v| (v + shift).max(0.0).powi(2)).sum::<f64>()
}

impl Mmfd {
    /// The restoration direction (scaled): the subproblem of the module
    /// doc; `None` when it is zero (the bounds leave no move).
    pub(super) fn restoration_direction(
        &self,
        problem: &Ap<'_>,
        base: &Point,
        gg: &[Vec<f64>],
    ) -> Result<Option<Vec<f64>>> {
        let ctmin = self.options.ctmin;
        let vars = variables(problem);
        let n = vars.len();
        let mut rows = Vec::new();
        let mut b = Vec::new();
        for (j, gj) in base.g.iter().enumerate() {
            if *gj >= self.ct_now {
                rows.push(gg[j].clone());
                b.push(-gj - 0.5 * ctmin);
            }
        }
        for (i, v) in vars.iter().enumerate() {
            if v.period.is_some() {
                continue;
            }
            let y = (base.x[i] - v.lower) / self.range[i];
            let mut e = vec![0.0; n];
            e[i] = 1.0;
            rows.push(e.clone());
            b.push(1.0 - y);
            e[i] = -1.0;
            rows.push(e);
            b.push(y);
        }
        let sol = qp::solve(&vec![0.0; n], &rows, &b)?;
        if sol.s.iter().all(|&v| v == 0.0) {
            return Ok(None);
        }
        Ok(Some(sol.s))
    }

    /// A Newton restoration along `s` (see the module doc); `None` when no
    /// shortening lowers the largest violation.
    pub(super) fn newton_restoration(
        &self,
        problem: &mut Ap<'_>,
        base: &Point,
        gg: &[Vec<f64>],
        s: &[f64],
    ) -> Result<Option<Point>> {
        let v0 = base.max_g();
        let worst = (0..base.g.len())
            .max_by(|&a, &b| base.g[a].total_cmp(&base.g[b]))
            .unwrap_or(0);
        let slope = dot(&gg[worst], s).min(0.0);
        let length = norm(s);
        let mut alpha = 1.0;
        while alpha * length > 1e-10 {
            let Some(p) = self.restoration_trial(problem, base, s, alpha)? else {
                break; // the bounds leave no move
            };
            let v = p.max_g();
            if v < v0 {
                return Ok(Some(p));
            }
            alpha = shorten(alpha, v - v0, slope);
        }
        Ok(None)
    }

    /// A step of descent on the violation from `base` along the
    /// subproblem's direction `s` (or `−∇V`), after a last accepted move
    /// `last`; the accepted design and its move, `None` when no trial
    /// lowers V enough.
    pub(super) fn violation_descent(
        &self,
        problem: &mut Ap<'_>,
        base: &Point,
        gg: &[Vec<f64>],
        s: Option<&[f64]>,
        last: f64,
    ) -> Result<Option<(Point, f64)>> {
        let shift = 0.5 * self.options.ctmin;
        let v0 = merit(&base.g, shift);
        let mut grad = vec![0.0; self.range.len()];
        for (gj, row) in base.g.iter().zip(gg) {
            let w = (gj + shift).max(0.0);
            for (d, r) in grad.iter_mut().zip(row) {
                *d += w * r;
            }
        }
        let d = match s {
            Some(s) if dot(&grad, s) < 0.0 => s.to_vec(),
            _ => self.projected_descent(problem, base, &grad),
        };
        let largest = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let slope = dot(&grad, &d);
        if largest == 0.0 || slope >= 0.0 {
            return Ok(None);
        }
        let dx2 = self.options.dx2;
        let mut alpha = (2.0 * last).min(dx2) / largest;
        let length = norm(&d);
        while alpha * length > 1e-10 {
            let Some(p) = self.restoration_trial(problem, base, &d, alpha)? else {
                return Ok(None);
            };
            let v = merit(&p.g, shift);
            if v <= v0 + ARMIJO * alpha * slope {
                return Ok(Some((p, alpha * largest)));
            }
            alpha = shorten(alpha, v - v0, slope);
        }
        Ok(None)
    }

    /// `−∇V` with the components that would leave the box at a bound
    /// removed.
    fn projected_descent(&self, problem: &Ap<'_>, base: &Point, grad: &[f64]) -> Vec<f64> {
        let vars = variables(problem);
        vars.iter()
            .enumerate()
            .map(|(i, v)| {
                let d = -grad[i];
                let at_lower = v.period.is_none() && base.x[i] <= v.lower;
                let at_upper = v.period.is_none() && base.x[i] >= v.upper;
                if (at_lower && d < 0.0) || (at_upper && d > 0.0) {
                    0.0
                } else {
                    d
                }
            })
            .collect()
    }

    /// The design `α s` (scaled) from `base`, evaluated without
    /// gradients; `None` when the bounds leave no move.
    fn restoration_trial(
        &self,
        problem: &mut Ap<'_>,
        base: &Point,
        s: &[f64],
        alpha: f64,
    ) -> Result<Option<Point>> {
        let z: Vec<f64> = s.iter().map(|v| alpha * v).collect();
        let x = self.moved(problem, &base.x, &z);
        if x == base.x {
            return Ok(None);
        }
        let ev = evaluate(problem, &x, false)?;
        Ok(Some(Point {
            x,
            f: ev.f,
            g: ev.g,
        }))
    }
}

/// The next, shorter trial after a rejected one at `alpha` that changed
/// the merit by `rise` where its slope is `slope`: the minimizer of the
/// quadratic through both, kept within [0.1, 0.5] of `alpha`.
fn shorten(alpha: f64, rise: f64, slope: f64) -> f64 {
    let curvature = rise - slope * alpha;
    let fit = if curvature > 0.0 && slope < 0.0 {
        -slope * alpha * alpha / (2.0 * curvature)
    } else {
        0.5 * alpha
    };
    fit.clamp(0.1 * alpha, 0.5 * alpha)
}
