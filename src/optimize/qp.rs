//! The direction-finding subproblem of the feasible-directions method,
//! solved exactly.
//!
//! Primal: `min_S ½|S|² + cᵀS` subject to `a_kᵀ S <= b_k` (k = 1..m), with
//! `S, c, a_k` of length n. Its dual is the bound-constrained quadratic
//! program `min_{λ>=0} ½ λᵀ H λ + qᵀλ` with `H = A Aᵀ` (m × m) and
//! `q = A c + b`; the primal solution is `S = −(c + Aᵀ λ)`. With `b = 0`
//! this is Vanderplaats' MMFD direction: the steepest descent direction
//! projected onto the cone of directions that do not increase the active
//! constraints, and `|S| = 0` with `λ >= 0` is exactly the Kuhn–Tucker
//! condition. m is the number of active constraints (a handful), so the
//! dual is solved by a finite active-set method (Lawson–Hanson style) with
//! dense Cholesky solves. Rows are normalised to unit length and `H` gets a
//! relative ridge of 1e-12 so that dependent or inconsistent rows still give
//! a bounded answer (the least-violating direction).

use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// Solution of the direction-finding subproblem.
#[derive(Debug, Clone)]
pub struct QpSolution {
    /// Primal direction `S` (length n).
    pub s: Vec<f64>,
    /// Multipliers of the rows as given (unnormalised), `>= 0` (length m).
    pub lambda: Vec<f64>,
}

/// Solve `min ½|S|² + cᵀS` s.t. `rows[k]·S <= b[k]`.
pub fn solve(c: &[f64], rows: &[Vec<f64>], b: &[f64]) -> Result<QpSolution> {
    let n = c.len();
    let m = rows.len();
    if m == 0 {
        return Ok(QpSolution {
            s: c.iter().map(|v| -v).collect(),
            lambda: vec![],
        });
    }
    // Normalised rows.
    let mut norms = vec![0.0; m];
    let mut a = DMatrix::<f64>::zeros(m, n);
    let mut bn = DVector::<f64>::zeros(m);
    for k in 0..m {
        let nk = rows[k].iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(nk.is_finite()) {
            return Err(Error::numerical(
                "optimize::qp",
                format!("row {k} of the direction subproblem is not finite"),
            ));
        }
        norms[k] = nk;
        if nk > 0.0 {
            for i in 0..n {
                a[(k, i)] = rows[k][i] / nk;
            }
            bn[k] = b[k] / nk;
        } else {
            bn[k] = b[k];
        }
    }
    let cv = DVector::from_column_slice(c);
    let mut h = &a * a.transpose();
    let ridge = 1e-12 * (1.0 + h.diagonal().max());
    for k in 0..m {
        h[(k, k)] += ridge;
    }
    let q = &a * &cv + &bn;
    let lam = nnqp(&h, &q)?;
    let s = -(cv + a.transpose() * &lam);
    let lambda = (0..m)
        .map(|k| {
            if norms[k] > 0.0 {
                lam[k] / norms[k]
            } else {
                0.0
            }
        })
        .collect();
    Ok(QpSolution {
        s: s.iter().copied().collect(),
        lambda,
    })
}

/// `min_{λ>=0} ½ λᵀHλ + qᵀλ` for symmetric positive definite `H`, by the
/// primal active-set method: free set P grows by the most negative
/// gradient component; an infeasible subproblem solution is cut back to the
/// boundary and the variables that hit zero leave P. Finite for definite H.
fn nnqp(h: &DMatrix<f64>, q: &DVector<f64>) -> Result<DVector<f64>> {
    let m = q.len();
    let mut lam = DVector::<f64>::zeros(m);
    let mut free = vec![false; m];
    let scale = q.amax().max(h.amax()).max(1e-300);
    let tol = 1e-13 * scale;
    for _outer in 0..(4 * m + 10) {
        let grad = h * &lam + q;
        // Most negative gradient among the bound variables.
        let mut pick = None;
        let mut best = -tol;
        for k in 0..m {
            if !free[k] && grad[k] < best {
                best = grad[k];
                pick = Some(k);
            }
        }
        let Some(t) = pick else {
            return Ok(lam);
        };
        free[t] = true;
        for _inner in 0..(2 * m + 2) {
            let idx: Vec<usize> = (0..m).filter(|&k| free[k]).collect();
            let p = idx.len();
            let hp = DMatrix::from_fn(p, p, |i, j| h[(idx[i], idx[j])]);
            let qp = DVector::from_fn(p, |i, _| -q[idx[i]]);
            let z = hp.cholesky().map(|ch| ch.solve(&qp)).ok_or_else(|| {
                Error::numerical(
                    "optimize::qp",
                    "dual Hessian of the direction subproblem is not definite",
                )
            })?;
            if z.iter().all(|&v| v > 0.0) {
                for (i, &k) in idx.iter().enumerate() {
                    lam[k] = z[i];
                }
                break;
            }
            // Step from lam towards z until the first variable hits zero.
            let mut alpha = 1.0f64;
            for (i, &k) in idx.iter().enumerate() {
                if z[i] <= 0.0 {
                    let d = lam[k] - z[i];
                    if d > 0.0 {
                        alpha = alpha.min(lam[k] / d);
                    } else {
                        alpha = 0.0;
                    }
                }
            }
            let big = lam.amax().max(z.amax());
            for (i, &k) in idx.iter().enumerate() {
                lam[k] += alpha * (z[i] - lam[k]);
                if z[i] <= 0.0 && lam[k] <= 1e-14 * (1.0 + big) {
                    lam[k] = 0.0;
                    free[k] = false;
                }
            }
            if !free.iter().any(|&f| f) {
                break;
            }
        }
    }
    Err(Error::numerical(
        "optimize::qp",
        format!("active-set method did not converge on {m} constraints"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Projection of −c onto the half-space `S_1 <= 0`, closed form derived
    /// here from KKT `S + c + λ e1 = 0`: for c1 < 0, λ = −c1 and S1 = 0;
    /// for c1 > 0 the row is slack, λ = 0 and S = −c. (Tolerances allow for
    /// the 1e-12 ridge.)
    #[test]
    fn half_space_projection() {
        let sol = solve(&[-2.0, 1.0], &[vec![1.0, 0.0]], &[0.0]).unwrap();
        assert!(sol.s[0].abs() < 1e-10 && (sol.s[1] + 1.0).abs() < 1e-12);
        assert!((sol.lambda[0] - 2.0).abs() < 1e-9);
        let sol = solve(&[2.0, 1.0], &[vec![1.0, 0.0]], &[0.0]).unwrap();
        assert!((sol.s[0] + 2.0).abs() < 1e-12 && sol.lambda[0] == 0.0);
    }

    /// Cone of two constraints with c in its polar cone: S = 0 (a
    /// Kuhn–Tucker point), multipliers from `c = −Aᵀλ` solved by hand:
    /// c = (−1, −3), rows (1, 1), (0, 1) give λ = (1, 2).
    #[test]
    fn kuhn_tucker_point_gives_zero_direction() {
        let rows = vec![vec![1.0, 1.0], vec![0.0, 1.0]];
        let sol = solve(&[-1.0, -3.0], &rows, &[0.0, 0.0]).unwrap();
        assert!(sol.s.iter().all(|v| v.abs() < 1e-9), "{:?}", sol.s);
        assert!((sol.lambda[0] - 1.0).abs() < 1e-6 && (sol.lambda[1] - 2.0).abs() < 1e-6);
    }

    /// Nearest point of the half-plane `x + y >= 2` to the origin:
    /// `(1, 1)` (closed form), as a restoration move `−(x+y) <= −2`.
    #[test]
    fn restoration_move_is_nearest_point() {
        let sol = solve(&[0.0, 0.0], &[vec![-1.0, -1.0]], &[-2.0]).unwrap();
        assert!((sol.s[0] - 1.0).abs() < 1e-9 && (sol.s[1] - 1.0).abs() < 1e-9);
    }
}
