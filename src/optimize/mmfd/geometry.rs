//! Small vector helpers of the direction and line search: dot products,
//! the least-norm multiplier estimate and the first positive root of a
//! quadratic (constraint crossings).

use nalgebra::{DMatrix, DVector};

pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(super) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Least-norm `c` with `Nᵀc = −r` for the columns `cols` (scaled
/// gradients): `c = −N (NᵀN)⁻¹ r`. None if the Gram matrix is singular.
pub(super) fn least_norm(cols: &[&[f64]], r: &[f64]) -> Option<Vec<f64>> {
    let k = cols.len();
    let n = cols.first()?.len();
    let gram = DMatrix::from_fn(k, k, |i, j| dot(cols[i], cols[j]));
    let ridge = 1e-12 * (1.0 + gram.diagonal().max());
    let gram = gram + DMatrix::identity(k, k) * ridge;
    let w = gram.cholesky()?.solve(&DVector::from_column_slice(r));
    let mut c = vec![0.0; n];
    for (col, wi) in cols.iter().zip(w.iter()) {
        for i in 0..n {
            c[i] -= wi * col[i];
        }
    }
    Some(c)
}

/// Smallest positive root of `a α² + b α + c = 0`, if any.
pub(super) fn first_root(a: f64, b: f64, c: f64) -> Option<f64> {
    if a.abs() < 1e-14 * (b.abs() + c.abs()) {
        let r = -c / b;
        return (r > 0.0 && r.is_finite()).then_some(r);
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let q = -0.5 * (b + b.signum() * sq);
    let mut roots = [q / a, c / q];
    roots.sort_by(f64::total_cmp);
    roots.into_iter().find(|r| *r > 0.0 && r.is_finite())
}
