//! Steps 1, 3 and 4 of the module doc of [`super`]: the active side
//! constraints, the search direction (steepest descent conjugated by
//! Fletcher–Reeves when nothing is active, else the MMFD direction, `−∇f`
//! projected onto the cone of non-increasing directions by [`qp`]) and the
//! secant update of the Lagrangian's curvature model along the step to
//! the current design.

use super::geometry::{dot, norm};
use super::Mmfd;
use crate::error::Result;
use crate::optimize::{qp, Variable};

/// The side constraints active at a design: a non-periodic variable
/// within `1e-9` of its range from a bound.
pub(super) struct SideConstraints {
    /// Their rows in the direction problem: `−e_i` (lower) or `+e_i` (upper).
    pub(super) rows: Vec<Vec<f64>>,
    /// Their variables with the sign a direction may take there (`1` at the
    /// lower bound, `−1` at the upper).
    vars: Vec<(usize, f64)>,
}

impl SideConstraints {
    /// The side constraints active at `x` (`range`: each variable's range).
    pub(super) fn at(vars: &[Variable], x: &[f64], range: &[f64]) -> SideConstraints {
        let n = vars.len();
        let eps = 1e-9;
        let mut side_rows = Vec::new();
        let mut side_vars = Vec::new();
        for (i, v) in vars.iter().enumerate() {
            if v.period.is_some() {
                continue;
            }
            let y = (x[i] - v.lower) / range[i];
            let mut e = vec![0.0; n];
            if y <= eps {
                e[i] = -1.0;
                side_rows.push(e);
                side_vars.push((i, 1.0));
            } else if y >= 1.0 - eps {
                e[i] = 1.0;
                side_rows.push(e);
                side_vars.push((i, -1.0));
            }
        }
        SideConstraints {
            rows: side_rows,
            vars: side_vars,
        }
    }
}

/// A search direction `S` (scaled) and the constraints it binds.
pub(super) struct Direction {
    pub(super) s: Vec<f64>,
    /// The active constraints with a positive multiplier that `S` is
    /// tangent to.
    pub(super) binding: Vec<usize>,
    /// Their multipliers.
    mult: Vec<f64>,
}

impl Direction {
    /// Step 4, the MMFD direction for the `active` constraints and the
    /// active side constraints: `min ½|S|² + ∇fᵀS` s.t. `∇g_jᵀS <= 0` and
    /// the side rows, solved exactly; `gf`, `gg` the scaled gradients.
    pub(super) fn projected(
        gf: &[f64],
        gg: &[Vec<f64>],
        active: &[usize],
        sides: &SideConstraints,
    ) -> Result<Direction> {
        let mut rows: Vec<Vec<f64>> = active.iter().map(|&j| gg[j].clone()).collect();
        rows.extend(sides.rows.iter().cloned());
        let b = vec![0.0; rows.len()];
        let sol = qp::solve(gf, &rows, &b)?;
        let lmax = sol.lambda.iter().copied().fold(0.0, f64::max);
        // Binding: positive multiplier and S tangent to the constraint
        // (complementarity); constraints S moves away from are free.
        let sn = norm(&sol.s);
        let binding: Vec<usize> = active
            .iter()
            .enumerate()
            .filter(|(k, &j)| {
                sol.lambda[*k] > 1e-8 * lmax.max(1e-300)
                    && dot(&gg[j], &sol.s) >= -1e-6 * norm(&gg[j]) * sn
            })
            .map(|(_, &j)| j)
            .collect();
        let mult: Vec<f64> = active
            .iter()
            .enumerate()
            .filter(|(_, j)| binding.contains(j))
            .map(|(k, _)| sol.lambda[k])
            .collect();
        let mut s = sol.s;
        // Remove round-off components pointing out of an active bound.
        for &(i, sign) in &sides.vars {
            if s[i] * sign < 0.0 {
                s[i] = 0.0;
            }
        }
        Ok(Direction { s, binding, mult })
    }
}

impl Mmfd {
    /// Step 3, nothing active: `−∇f` (scaled `gf`), conjugated by
    /// Fletcher–Reeves with the previous unconstrained direction while it
    /// stays a descent direction, restarted every n iterations.
    pub(super) fn conjugate_direction(&mut self, gf: &[f64]) -> Direction {
        let n = gf.len();
        let mut s: Vec<f64> = gf.iter().map(|v| -v).collect();
        if let Some((gprev, sprev)) = &self.fr_prev {
            if self.fr_count < n {
                let beta = dot(gf, gf) / dot(gprev, gprev).max(1e-300);
                let cand: Vec<f64> = s.iter().zip(sprev).map(|(a, b)| a + beta * b).collect();
                if dot(&cand, gf) < -1e-3 * norm(&cand) * norm(gf) {
                    s = cand;
                    self.fr_count += 1;
                } else {
                    self.fr_count = 0;
                }
            } else {
                self.fr_count = 0;
            }
        }
        self.fr_prev = Some((gf.to_vec(), s.clone()));
        Direction {
            s,
            binding: vec![],
            mult: vec![],
        }
    }

    /// Secant curvature of the Lagrangian (with the binding multipliers of
    /// `dir`) along the step from the last gradient evaluation to `x`,
    /// whose scaled gradients are `gf`, `gg`: one update of the BFGS model.
    pub(super) fn update_curvature(
        &mut self,
        vars: &[Variable],
        x: &[f64],
        (gf, gg): (&[f64], &[Vec<f64>]),
        dir: &Direction,
    ) {
        if let Some((xp, gfp, ggp)) = self.secant.take() {
            let st: Vec<f64> = vars
                .iter()
                .enumerate()
                .map(|(i, v)| v.difference(x[i], xp[i]) / self.range[i])
                .collect();
            let mut y: Vec<f64> = gf.iter().zip(&gfp).map(|(a, b)| a - b).collect();
            for (&j, l) in dir.binding.iter().zip(&dir.mult) {
                for (yi, (a, b)) in y.iter_mut().zip(gg[j].iter().zip(&ggp[j])) {
                    *yi += l * (a - b);
                }
            }
            self.curvature.update(&st, &y);
        }
    }
}
