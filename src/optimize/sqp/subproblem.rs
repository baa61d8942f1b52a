//! The quadratic subproblem of one SQP iteration, solved exactly.
//!
//! In the range-scaled variables `d` (a step of 1 spans a variable's whole
//! range) the subproblem at the current design is
//!
//! ```text
//!   min_d  ½ dᵀB d + ∇fᵀd
//!   s.t.   g_j + ∇g_jᵀ d <= 0          (every constraint j)
//!          lo_i <= d_i <= hi_i          (non-periodic variables)
//! ```
//!
//! with `B = L Lᵀ` the positive definite model of the Lagrangian's Hessian.
//! The change of variables `z = Lᵀ d` turns it into the least-distance
//! problem `min ½|z|² + (L⁻¹∇f)ᵀz` with rows `(L⁻¹ a)ᵀ z <= b`, which
//! [`crate::optimize::qp::solve`] solves exactly through its dual; the
//! multipliers are those of the rows as given, in either variables.
//!
//! When the linearised constraints have no common point inside the bounds
//! (far from the feasible set), the elastic form
//!
//! ```text
//!   min_{d, t}  ½ dᵀB d + ∇fᵀd + ρ t + ½ t²   s.t.  g_j + ∇g_jᵀ d <= t,  t >= 0
//! ```
//!
//! is solved instead (Powell's relaxation in Fletcher's ℓ1 form): it always
//! has a solution, and with `ρ` above the multipliers its step reduces the
//! ℓ1 merit function whenever one can.

use super::super::qp;
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// The data of one subproblem, in scaled variables.
pub struct Subproblem<'a> {
    /// The model Hessian `B` (n × n, symmetric positive definite).
    pub b: &'a DMatrix<f64>,
    /// Scaled gradient of f (length n).
    pub grad_f: &'a [f64],
    /// Constraint values `g_j` (length m).
    pub g: &'a [f64],
    /// Scaled constraint gradients (m rows of length n).
    pub grad_g: &'a [Vec<f64>],
    /// Per variable, the scaled step to its lower and upper bound (`None`
    /// for a periodic variable).
    pub bounds: &'a [Option<(f64, f64)>],
    /// The elastic penalty `ρ` (used only when the linearisation is
    /// inconsistent).
    pub rho: f64,
}

/// The step and multipliers of a subproblem.
#[derive(Debug, Clone)]
pub struct Step {
    /// The scaled step `d` (length n).
    pub d: Vec<f64>,
    /// Multipliers `λ_j >= 0` of the constraints (length m).
    pub lambda: Vec<f64>,
    /// Whether the elastic form was needed.
    pub elastic: bool,
}

/// Relative violation of the linearised constraints above which a
/// subproblem's answer is taken as inconsistent (the dual solver's ridge
/// of 1e-12 leaves residuals far below this on consistent problems).
const CONSISTENT: f64 = 1e-8;

impl Subproblem<'_> {
    /// Solve the subproblem (elastic when needed).
    pub fn solve(&self) -> Result<Step> {
        let n = self.grad_f.len();
        let l = self.b.clone().cholesky().ok_or_else(|| {
            Error::numerical(
                "optimize::sqp",
                "the model Hessian is not positive definite",
            )
        })?;
        let l = l.l();
        let lsolve = |v: &[f64]| -> Vec<f64> {
            let x = l
                .solve_lower_triangular(&DVector::from_column_slice(v))
                .unwrap_or_else(|| DVector::zeros(n));
            x.iter().copied().collect()
        };
        let c = lsolve(self.grad_f);
        let rows_g: Vec<Vec<f64>> = self.grad_g.iter().map(|a| lsolve(a)).collect();
        let mut rows_b = Vec::new();
        let mut rhs_b = Vec::new();
        for (i, bound) in self.bounds.iter().enumerate() {
            if let Some((lo, hi)) = bound {
                let mut e = vec![0.0; n];
                e[i] = 1.0;
                let r = lsolve(&e);
                rows_b.push(r.iter().map(|v| -v).collect::<Vec<f64>>());
                rhs_b.push(-lo);
                rows_b.push(r);
                rhs_b.push(*hi);
            }
        }
        let back = |z: &[f64]| -> Vec<f64> {
            let x = l
                .transpose()
                .solve_upper_triangular(&DVector::from_column_slice(&z[..n]))
                .unwrap_or_else(|| DVector::zeros(n));
            x.iter().copied().collect()
        };
        let m = self.g.len();
        let mut rows = rows_g.clone();
        rows.extend(rows_b.iter().cloned());
        let mut rhs: Vec<f64> = self.g.iter().map(|v| -v).collect();
        rhs.extend(&rhs_b);
        let plain = qp::solve(&c, &rows, &rhs)?;
        let d = back(&plain.s);
        if self.consistent(&d) {
            return Ok(Step {
                d,
                lambda: plain.lambda[..m].to_vec(),
                elastic: false,
            });
        }
        // Elastic form: one more coordinate t with unit curvature.
        let mut ce = c.clone();
        ce.push(self.rho);
        let mut rows_e: Vec<Vec<f64>> = rows_g
            .iter()
            .map(|r| {
                let mut r = r.clone();
                r.push(-1.0);
                r
            })
            .collect();
        let mut t_row = vec![0.0; n];
        t_row.push(-1.0);
        rows_e.push(t_row);
        rows_e.extend(rows_b.iter().map(|r| {
            let mut r = r.clone();
            r.push(0.0);
            r
        }));
        let mut rhs_e: Vec<f64> = self.g.iter().map(|v| -v).collect();
        rhs_e.push(0.0);
        rhs_e.extend(&rhs_b);
        let elastic = qp::solve(&ce, &rows_e, &rhs_e)?;
        Ok(Step {
            d: back(&elastic.s),
            lambda: elastic.lambda[..m].to_vec(),
            elastic: true,
        })
    }

    /// Whether `d` meets the linearised constraints and the bounds (to
    /// [`CONSISTENT`] of the constraints' size).
    fn consistent(&self, d: &[f64]) -> bool {
        let scale = 1.0 + self.g.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let lin_ok = self.g.iter().zip(self.grad_g).all(|(gj, a)| {
            let lin = gj + a.iter().zip(d).map(|(x, y)| x * y).sum::<f64>();
            lin <= CONSISTENT * scale
        });
        let box_ok = self.bounds.iter().zip(d).all(|(b, di)| match b {
            Some((lo, hi)) => *di >= lo - CONSISTENT && *di <= hi + CONSISTENT,
            None => true,
        });
        lin_ok && box_ok && d.iter().all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `min ½(d1² + d2²) − d1 − d2` s.t. `d1 + d2 <= 1`: the projection of
    /// (1, 1) on the half-plane is (½, ½) with multiplier ½ (closed form of
    /// the Kuhn–Tucker system `d + λ(1, 1) = (1, 1)`, `d1 + d2 = 1`).
    #[test]
    fn one_linear_constraint_has_the_closed_form_step() {
        let b = DMatrix::identity(2, 2);
        let sp = Subproblem {
            b: &b,
            grad_f: &[-1.0, -1.0],
            g: &[-1.0],
            grad_g: &[vec![1.0, 1.0]],
            bounds: &[None, None],
            rho: 100.0,
        };
        let s = sp.solve().unwrap();
        assert!((s.d[0] - 0.5).abs() < 1e-10 && (s.d[1] - 0.5).abs() < 1e-10);
        assert!((s.lambda[0] - 0.5).abs() < 1e-10);
        assert!(!s.elastic);
    }

    /// A non-identity B: `min ½ dᵀ diag(4, 1) d − d1` with `d1 <= 0.1`
    /// (bound): unconstrained d1 = ¼ is cut to the bound 0.1.
    #[test]
    fn bounds_cut_the_newton_step() {
        let b = DMatrix::from_row_slice(2, 2, &[4.0, 0.0, 0.0, 1.0]);
        let sp = Subproblem {
            b: &b,
            grad_f: &[-1.0, 0.0],
            g: &[],
            grad_g: &[],
            bounds: &[Some((-1.0, 0.1)), Some((-1.0, 1.0))],
            rho: 100.0,
        };
        let s = sp.solve().unwrap();
        assert!((s.d[0] - 0.1).abs() < 1e-10 && s.d[1].abs() < 1e-12);
    }

    /// Inconsistent linearisation: `d1 >= 2` (as `2 − d1 <= 0`) inside the
    /// box `|d1| <= 1` cannot hold; the elastic step goes to the bound that
    /// comes closest, d1 = 1.
    #[test]
    fn inconsistent_constraints_take_the_elastic_step() {
        let b = DMatrix::identity(1, 1);
        let sp = Subproblem {
            b: &b,
            grad_f: &[0.0],
            g: &[2.0],
            grad_g: &[vec![-1.0]],
            bounds: &[Some((-1.0, 1.0))],
            rho: 100.0,
        };
        let s = sp.solve().unwrap();
        assert!(s.elastic);
        assert!((s.d[0] - 1.0).abs() < 1e-8, "{:?}", s.d);
    }
}
