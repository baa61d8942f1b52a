//! Step 5 of the module doc of [`super`]: the line search along
//! `x(α) = x + c₀ + αS` with constraint following, its first trial, the
//! Armijo phase and the fitted step (evaluated with gradients for the
//! next iteration when it ends the search); and step 5b, the slope search
//! of the polish.

use super::geometry::{dot, first_root, least_norm, norm};
use super::{evaluate, variables, Ap, Mmfd, Point};
use crate::error::Result;
use crate::optimize::Evaluation;

/// A line search's result: the accepted point, its α, and its evaluation
/// with gradients when the search made one.
pub(super) type Searched = (Point, f64, Option<Evaluation>);

/// Largest share of the fitted parabola's decrease an accepted trial may
/// leave unrealized without a further call (module doc, step 5).
const ACCEPT_LOSS: f64 = 0.1;

/// What the line search works with in one iteration.
pub(super) struct Search<'s> {
    pub(super) base: &'s Point,
    /// Scaled gradients of f and of all constraints at the base.
    pub(super) gf: &'s [f64],
    pub(super) gg: &'s [Vec<f64>],
    pub(super) s: &'s [f64],
    pub(super) c0: &'s [f64],
    pub(super) binding: &'s [usize],
    /// Curvature `κ = SᵀHS/|S|²` of the Lagrangian's BFGS model along
    /// `S` (scaled), when positive: the first trial `−f'(0)/(κ|S|²)`.
    pub(super) curvature: Option<f64>,
    /// Last trial's α and its pull-back beyond `c₀` (scaled): the curvature
    /// of the followed constraints, reused as `(α/α_last)²` times that
    /// pull-back to predict the next trial's (second-order prediction).
    pub(super) learned: std::cell::RefCell<Option<(f64, Vec<f64>)>>,
}

impl Search<'_> {
    /// The slope of f along the direction at the base, `f'(0) = ∇fᵀS`.
    fn slope0(&self) -> f64 {
        dot(self.gf, self.s)
    }

    /// `max_i |S_i|` (scaled), the direction's size.
    fn s_max(&self) -> f64 {
        self.s.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// f predicted on the binding limits, `φ(0) = f + ∇fᵀc₀`.
    fn phi0(&self) -> f64 {
        self.base.f + dot(self.gf, self.c0)
    }

    /// Reference for a decrease: f at the base, or the predicted f on the
    /// binding limits when reaching them costs (base slightly violated).
    fn f_ref(&self) -> f64 {
        self.base.f.max(self.phi0())
    }

    /// Whether the followed constraints have needed no correction in this
    /// search (none followed, or the last trial met them as it was): then
    /// a fitted step is likely accepted as evaluated, and evaluating it
    /// with gradients saves the next iteration's evaluation. Where the
    /// limits are curved the step will be corrected, and gradients at the
    /// uncorrected point would be wasted.
    fn straight(&self) -> bool {
        self.learned
            .borrow()
            .as_ref()
            .is_none_or(|(_, pull)| pull.iter().all(|p| *p == 0.0))
    }
}

impl Mmfd {
    /// Evaluate the trial `x + c₀ + αS` with constraint following.
    fn trial(&self, problem: &mut Ap<'_>, sr: &Search<'_>, alpha: f64) -> Result<Point> {
        Ok(self.trial_with(problem, sr, alpha, false)?.0)
    }

    /// [`Mmfd::trial`], with gradients at the first evaluation when
    /// `gradients`: that evaluation is returned when it is the trial point
    /// itself (no correction was needed), for the next iteration to use.
    fn trial_with(
        &self,
        problem: &mut Ap<'_>,
        sr: &Search<'_>,
        alpha: f64,
        gradients: bool,
    ) -> Result<(Point, Option<Evaluation>)> {
        let lin: Vec<f64> = sr.c0.iter().zip(sr.s).map(|(c, s)| c + alpha * s).collect();
        let mut z = lin.clone();
        if let Some((a_last, pull)) = sr.learned.borrow().as_ref() {
            let k = (alpha / a_last).powi(2);
            for (zi, p) in z.iter_mut().zip(pull) {
                *zi += k * p;
            }
        }
        let mut x = self.moved(problem, &sr.base.x, &z);
        let mut ev = evaluate(problem, &x, gradients)?;
        let mut full = gradients;
        let follow_tol = self.options.follow_tolerance;
        let mut last_r = f64::INFINITY;
        for _ in 0..self.options.max_corrections {
            if sr.binding.is_empty() {
                break;
            }
            let r: Vec<f64> = sr.binding.iter().map(|&j| ev.g[j]).collect();
            let r_max = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            // Converged, or diverging (the step is too long for the frozen
            // gradients: the line search will shorten it).
            if r_max <= follow_tol || r_max >= last_r {
                break;
            }
            last_r = r_max;
            let cols: Vec<&[f64]> = sr.binding.iter().map(|&j| sr.gg[j].as_slice()).collect();
            let Some(dz) = least_norm(&cols, &r) else {
                break;
            };
            for (zi, d) in z.iter_mut().zip(&dz) {
                *zi += d;
            }
            x = self.moved(problem, &sr.base.x, &z);
            ev = evaluate(problem, &x, false)?;
            full = false;
        }
        if !sr.binding.is_empty() && alpha > 0.0 {
            let pull = z.iter().zip(&lin).map(|(a, b)| a - b).collect();
            *sr.learned.borrow_mut() = Some((alpha, pull));
        }
        let p = Point {
            x,
            f: ev.f,
            g: ev.g.clone(),
        };
        Ok((p, full.then_some(ev)))
    }

    /// Largest α keeping `y + c₀ + αS` inside the bounds of the non-periodic
    /// variables.
    fn alpha_max(&self, problem: &Ap<'_>, sr: &Search<'_>) -> f64 {
        let vars = variables(problem);
        let snorm = sr.s_max();
        let mut amax = f64::INFINITY;
        for (i, v) in vars.iter().enumerate() {
            if v.period.is_some() || sr.s[i].abs() <= 1e-9 * snorm {
                continue;
            }
            let y = (sr.base.x[i] - v.lower) / self.range[i] + sr.c0[i];
            let room = if sr.s[i] > 0.0 { 1.0 - y } else { y };
            amax = amax.min(room.max(0.0) / sr.s[i].abs());
        }
        amax
    }

    /// Predicted α where a constraint not followed crosses zero, from
    /// `g(0)`, `∇gᵀS` and the value at the trial `at`.
    fn crossing(&self, sr: &Search<'_>, at: &Point, alpha: f64) -> f64 {
        let mut best = f64::INFINITY;
        for (j, gt) in at.g.iter().enumerate() {
            if sr.binding.contains(&j) {
                continue;
            }
            let g0 = sr.base.g[j] + dot(&sr.gg[j], sr.c0);
            let s = dot(&sr.gg[j], sr.s);
            if s <= 0.0 && *gt <= 0.0 {
                continue;
            }
            let a = (gt - g0 - s * alpha) / (alpha * alpha);
            if let Some(r) = first_root(a, s, g0) {
                best = best.min(r);
            } else if *gt > 0.0 {
                // Linear interpolation between the base and the trial.
                let r = alpha * (0.0 - g0) / (gt - g0);
                if r > 0.0 {
                    best = best.min(r);
                }
            }
        }
        best
    }

    /// The line search of step 5. Returns the accepted point, α and the
    /// point's evaluation with gradients if the search made one, or None
    /// when no feasible point with a decrease of f was found.
    pub(super) fn line_search(
        &self,
        problem: &mut Ap<'_>,
        sr: &Search<'_>,
    ) -> Result<Option<Searched>> {
        let o = &self.options;
        let ok = |p: &Point| p.max_g() <= o.ctmin;
        let phi0 = sr.phi0();
        let d0 = sr.slope0();
        let snorm = sr.s_max();
        // Pure pull onto the binding limits (S = 0).
        if snorm == 0.0 || d0 >= 0.0 {
            if norm(sr.c0) == 0.0 {
                return Ok(None);
            }
            let t = self.trial(problem, sr, 0.0)?;
            return Ok((ok(&t) && t.f < sr.f_ref()).then_some((t, 0.0, None)));
        }
        let amax = self.alpha_max(problem, sr);
        let fscale = sr.base.f.abs().max(self.dabobj);
        let mut alpha = match self.prev_step {
            Some(_) if sr.curvature.is_some() => {
                let k = sr.curvature.unwrap_or(f64::NAN);
                (-d0 / (k * dot(sr.s, sr.s))).min(o.dobj2 * fscale / d0.abs())
            }
            None => (o.dobj1 * fscale / d0.abs()).max(o.dx1 / snorm),
            // Following curved limits, f'(0) = −|S|² shrinks quadratically
            // near the optimum while the best α stays about the same.
            Some((a, _)) if !sr.binding.is_empty() => a,
            Some((a, dprev)) => (a * dprev / d0)
                .min(o.dobj2 * fscale / d0.abs())
                .min(2.02 * self.last_change.max(1e-300) / d0.abs()),
        };
        alpha = alpha.min(o.dx2 / snorm).min(amax);

        if !(alpha > 0.0 && alpha.is_finite()) {
            return Ok(None);
        }
        let f_ref = sr.f_ref();
        let mut best: Option<(Point, f64)> = None;
        let mut evals = 0;
        // Phase A: a feasible trial with a decrease.
        while evals < o.max_line_evaluations {
            let t = self.trial(problem, sr, alpha)?;
            evals += 1;
            if !ok(&t) {
                let r = self.crossing(sr, &t, alpha);
                // A followed constraint the corrections could not reach
                // (r infinite): the step was too long for the curvature.
                alpha = if r.is_finite() {
                    r.clamp(0.05 * alpha, 0.9 * alpha)
                } else {
                    0.25 * alpha
                };
                continue;
            }
            if t.f < f_ref + 1e-4 * alpha * d0 {
                best = Some((t, alpha));
                break;
            }
            let c = (t.f - phi0 - d0 * alpha) / (alpha * alpha);
            let a_q = if c > 0.0 {
                -d0 / (2.0 * c)
            } else {
                0.1 * alpha
            };
            alpha = a_q.clamp(0.01 * alpha, 0.5 * alpha);
        }
        let Some((mut bp, mut ba)) = best else {
            return Ok(None);
        };
        // Phase B: a fitted step from the accepted trial.
        let mut lo: Option<(f64, f64)> = None; // a second point for 3-point fits
        let mut stash = None;
        let mut full = true;
        while evals < o.max_line_evaluations {
            // The fit `φ0 + b α + c α²` and its minimizer (capped).
            let (a_star, capped, b, c) = match lo {
                Some((a2, f2)) => {
                    // Quadratic through (0, φ0), (ba, f_b), (a2, f2).
                    let (x1, y1, x2, y2) = (ba, bp.f - phi0, a2, f2 - phi0);
                    let den = x1 * x2 * (x1 - x2);
                    let c = (y1 * x2 - y2 * x1) / den;
                    let b = (y2 * x1 * x1 - y1 * x2 * x2) / den;
                    if c > 0.0 {
                        (-b / (2.0 * c), false, b, c)
                    } else {
                        break;
                    }
                }
                None => {
                    let c = (bp.f - phi0 - d0 * ba) / (ba * ba);
                    if c > 0.0 {
                        let a = -d0 / (2.0 * c);
                        if a > 4.0 * ba {
                            (4.0 * ba, true, d0, c)
                        } else {
                            (a, false, d0, c)
                        }
                    } else {
                        (4.0 * ba, true, d0, c)
                    }
                }
            };
            let limit = amax.min(self.crossing(sr, &bp, ba));
            let a_new = a_star.min(limit);
            if a_new.is_nan() || a_new <= 0.0 || (a_new - ba).abs() <= 0.05 * ba {
                break;
            }
            // The fit predicts the accepted trial well: on the fitted
            // parabola it realizes at least 1 − ACCEPT_LOSS of the decrease
            // of the parabola's minimizer, `(α/α* − 1)² <= ACCEPT_LOSS`.
            if !capped && a_new == a_star && (ba / a_new - 1.0).powi(2) <= ACCEPT_LOSS {
                break;
            }
            // A step that ends the search is evaluated with gradients, which
            // the next iteration reuses when the step is accepted.
            let predicted = phi0 + b * a_new + c * a_new * a_new;
            let last = full
                && (!capped || a_new >= limit)
                && sr.straight()
                && !self.would_stop(sr.base, predicted);
            let (t, ev) = self.trial_with(problem, sr, a_new, last)?;
            evals += 1;
            full &= !last;
            if ok(&t) && t.f < bp.f {
                let prev = (ba, bp.f);
                bp = t;
                ba = a_new;
                if ev.is_some() {
                    stash = ev;
                    break;
                }
                if capped && a_new < limit {
                    lo = None;
                    continue;
                }
                lo = Some(prev);
                if a_new >= limit {
                    break;
                }
            } else {
                if lo.is_some() || !ok(&t) {
                    break;
                }
                lo = Some((a_new, t.f));
            }
        }
        Ok(Some((bp, ba, stash)))
    }

    /// Step 5b of the module doc: the slope search, tried (with
    /// `slope_search` on) when the line search found no decrease of f.
    /// Every trial is evaluated with gradients and judged by the slope
    /// `d(α) = ∇f(x(α))ᵀS` instead of by f: a feasible trial whose slope is
    /// still negative, or at most half the start's `|d(0)|`, is accepted;
    /// a steeper positive slope (the 1-D minimum passed) moves the trial to
    /// the secant root between the last negative slope and it. f may rise
    /// by at most its noise, `max(|d(0)| α, noise·max(|f|, 1))`: an
    /// infeasible trial or a larger rise is shortened tenfold. `None` when
    /// no trial is accepted within twice `max_line_evaluations`.
    pub(super) fn slope_search(
        &self,
        problem: &mut Ap<'_>,
        sr: &Search<'_>,
    ) -> Result<Option<Searched>> {
        let o = &self.options;
        let d0 = sr.slope0();
        let snorm = sr.s_max();
        if snorm == 0.0 || d0.is_nan() || d0 >= 0.0 {
            return Ok(None);
        }
        // The line search's pull-back extrapolation is for its own trials.
        *sr.learned.borrow_mut() = None;
        let f_ref = sr.f_ref();
        let noise = o.noise * sr.base.f.abs().max(1.0);
        let model = match sr.curvature {
            Some(k) => -d0 / (k * dot(sr.s, sr.s)),
            None => o.dx1 / snorm,
        };
        let mut alpha = model.min(o.dx2 / snorm).min(self.alpha_max(problem, sr));
        let (mut lo, mut d_lo) = (0.0, d0);
        for _ in 0..2 * o.max_line_evaluations {
            if !(alpha > lo && alpha.is_finite()) {
                break;
            }
            let (t, ev) = self.trial_with(problem, sr, alpha, true)?;
            let ev = match ev {
                Some(ev) => ev,
                None => evaluate(problem, &t.x, true)?,
            };
            let slope = ev.grad_f.as_ref().map(|g| {
                g.iter()
                    .zip(&self.range)
                    .zip(sr.s)
                    .map(|((g, r), s)| g * r * s)
                    .sum::<f64>()
            });
            let Some(d1) = slope.filter(|d| d.is_finite()) else {
                break;
            };
            if t.max_g() > o.ctmin || t.f > f_ref + noise.max(d0.abs() * alpha) {
                alpha = lo + 0.1 * (alpha - lo);
                continue;
            }
            if d1 <= 0.5 * d0.abs() {
                return Ok(Some((t, alpha, Some(ev))));
            }
            if d1 < 0.0 {
                (lo, d_lo) = (alpha, d1);
            }
            alpha = lo + (alpha - lo) * d_lo / (d_lo - d1);
        }
        Ok(None)
    }
}
