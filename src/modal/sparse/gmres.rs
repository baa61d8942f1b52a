//! Krylov iterative refinement: right-preconditioned GMRES with a
//! factorization of the pencil as preconditioner.

// Index loops mirror the formulas in these numeric kernels.
#![allow(clippy::needless_range_loop)]

use faer::Mat;

use super::factor::Factor;

/// Right-preconditioned GMRES on `A x = b` with the factorization `F ≈ A`
/// as preconditioner ("Krylov iterative refinement"). When `F = A` exactly
/// it stops after the residual check; each regularised pivot of `F` (a
/// rank-one difference) costs about one iteration. Modifies `x` (start:
/// `F⁻¹b`, end: the refined solution). Returns the relative residual.
pub(crate) fn gmres_refine(
    factor: &mut Factor<'_>,
    apply_a: &dyn Fn(&[f64], &mut [f64]),
    x: &mut [f64],
    job: Refine<'_>,
) -> f64 {
    let Refine {
        b,
        tol,
        max_iter,
        residual,
        mut first,
    } = job;
    let n = b.len();
    let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
    let bn = norm(b).max(f64::MIN_POSITIVE);
    let r: Vec<f64> = residual.unwrap_or_else(|| {
        let mut ax = vec![0.0; n];
        apply_a(x, &mut ax);
        (0..n).map(|i| b[i] - ax[i]).collect()
    });
    let beta = norm(&r);
    if beta <= tol * bn {
        return beta / bn;
    }
    let mut basis: Vec<Vec<f64>> = vec![r.iter().map(|v| v / beta).collect()];
    let mut zs: Vec<Vec<f64>> = Vec::new();
    // Hessenberg columns after Givens rotations (upper triangular R).
    let mut rmat: Vec<Vec<f64>> = Vec::new();
    let mut cs: Vec<(f64, f64)> = Vec::new();
    let mut g = vec![beta];
    let mut res = beta;
    for j in 0..max_iter {
        let (z, mut w) = match first.take() {
            Some(zw) if j == 0 => zw,
            _ => {
                let mut z = Mat::<f64>::from_fn(n, 1, |i, _| basis[j][i]);
                factor.solve_in_place(z.as_mut());
                let z: Vec<f64> = (0..n).map(|i| z[(i, 0)]).collect();
                let mut w = vec![0.0; n];
                apply_a(&z, &mut w);
                (z, w)
            }
        };
        let mut h = vec![0.0; j + 2];
        for _ in 0..2 {
            for (i, v) in basis.iter().enumerate() {
                let c: f64 = v.iter().zip(&w).map(|(a, b)| a * b).sum();
                h[i] += c;
                w.iter_mut().zip(v).for_each(|(a, b)| *a -= c * b);
            }
        }
        h[j + 1] = norm(&w);
        for (i, &(c, s)) in cs.iter().enumerate() {
            let (a, b) = (h[i], h[i + 1]);
            h[i] = c * a + s * b;
            h[i + 1] = -s * a + c * b;
        }
        let d = (h[j] * h[j] + h[j + 1] * h[j + 1]).sqrt();
        let (c, s) = if d > 0.0 {
            (h[j] / d, h[j + 1] / d)
        } else {
            (1.0, 0.0)
        };
        h[j] = d;
        let gj = g[j];
        g[j] = c * gj;
        g.push(-s * gj);
        cs.push((c, s));
        res = g[j + 1].abs();
        let hn = h[j + 1];
        h.truncate(j + 1);
        rmat.push(h);
        zs.push(z);
        if res <= tol * bn || hn == 0.0 {
            break;
        }
        basis.push(w.iter().map(|v| v / hn).collect());
    }
    // Back substitution R y = g, x += Z y.
    let m = rmat.len();
    let mut y = vec![0.0; m];
    for i in (0..m).rev() {
        let mut t = g[i];
        for k in i + 1..m {
            t -= rmat[k][i] * y[k];
        }
        y[i] = t / rmat[i][i];
    }
    for (k, z) in zs.iter().enumerate() {
        x.iter_mut().zip(z).for_each(|(a, b)| *a += y[k] * b);
    }
    res / bn
}

/// One GMRES refinement job of [`gmres_refine`].
pub(crate) struct Refine<'a> {
    /// Right-hand side `b`.
    pub b: &'a [f64],
    /// Relative residual to reach.
    pub tol: f64,
    /// Largest number of iterations.
    pub max_iter: usize,
    /// `b − A x` when already known (else computed).
    pub residual: Option<Vec<f64>>,
    /// The first iteration's `z = F⁻¹ r/‖r‖` and `A z` when already known
    /// (computed for several columns at once by the caller).
    pub first: Option<(Vec<f64>, Vec<f64>)>,
}
