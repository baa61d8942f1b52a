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

/// A damped BFGS model `H` of the Lagrangian's Hessian in scaled
/// coordinates, for the curvature `SᵀHS/|S|²` along a search direction
/// (the first trial of step 5, `α = −f'(0)/(SᵀHS)`).
///
/// Started as `κI` at the first pair with `sᵀy > 0`, `κ = sᵀy/sᵀs` (the
/// secant curvature along that step: one pair tells nothing about the
/// other directions), then updated with every later pair by
/// `H ← H − (Hs)(Hs)ᵀ/(sᵀHs) + ỹỹᵀ/(sᵀỹ)` with Powell's damping
/// `ỹ = θy + (1 − θ)Hs`, `θ = 1` if `sᵀy >= 0.2 sᵀHs`, else
/// `θ = 0.8 sᵀHs/(sᵀHs − sᵀy)` (Nocedal & Wright, *Numerical
/// Optimization*, 2nd ed., procedure 18.2), which keeps `H` positive
/// definite where the Lagrangian's curvature along `s` is not.
#[derive(Debug, Clone, Default)]
pub(super) struct Bfgs {
    /// `n × n`, row-major; empty until the first usable pair.
    h: Vec<f64>,
}

impl Bfgs {
    fn times(&self, s: &[f64]) -> Vec<f64> {
        let n = s.len();
        (0..n)
            .map(|i| dot(&self.h[i * n..(i + 1) * n], s))
            .collect()
    }

    /// Update with the step `s` and the change `y` of the Lagrangian's
    /// gradient over it (both scaled); pairs with `s = 0` or non-finite
    /// entries are skipped.
    pub(super) fn update(&mut self, s: &[f64], y: &[f64]) {
        let n = s.len();
        let ss = dot(s, s);
        if ss == 0.0 || s.iter().chain(y).any(|v| !v.is_finite()) {
            return;
        }
        if self.h.len() != n * n {
            let sy = dot(s, y);
            if sy <= 0.0 {
                return;
            }
            let scale = sy / ss;
            self.h = (0..n * n)
                .map(|k| if k % (n + 1) == 0 { scale } else { 0.0 })
                .collect();
            return;
        }
        let hs = self.times(s);
        let shs = dot(s, &hs);
        let sy = dot(s, y);
        let theta = if sy >= 0.2 * shs {
            1.0
        } else {
            0.8 * shs / (shs - sy)
        };
        let yt: Vec<f64> = y
            .iter()
            .zip(&hs)
            .map(|(a, b)| theta * a + (1.0 - theta) * b)
            .collect();
        let syt = dot(s, &yt);
        if !(shs > 0.0 && syt > 0.0) {
            return;
        }
        for i in 0..n {
            for j in 0..n {
                self.h[i * n + j] += yt[i] * yt[j] / syt - hs[i] * hs[j] / shs;
            }
        }
    }

    /// The model `H` (`n × n`, row-major), once it exists.
    pub(super) fn matrix(&self) -> Option<&[f64]> {
        (!self.h.is_empty()).then_some(self.h.as_slice())
    }

    /// The curvature `SᵀHS/|S|²` along `s`, when the model exists and it
    /// is positive.
    pub(super) fn along(&self, s: &[f64]) -> Option<f64> {
        let n = s.len();
        let ss = dot(s, s);
        if self.h.len() != n * n || ss == 0.0 {
            return None;
        }
        let k = dot(s, &self.times(s)) / ss;
        (k > 0.0 && k.is_finite()).then_some(k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a quadratic `½xᵀAx` the pairs are exact (`y = As`): the model
    /// starts with the secant curvature of the first step, meets the
    /// secant condition along each update's step, and after `n` mutually
    /// A-conjugate steps has the Hessian's curvature along any direction
    /// (BFGS's hereditary property, Nocedal & Wright §6.1, theorem 6.4's
    /// setting).
    #[test]
    fn bfgs_learns_a_quadratic_and_stays_positive() {
        let a = [[4.0, 1.0, 0.0], [1.0, 3.0, 0.5], [0.0, 0.5, 1.0]];
        let times = |s: &[f64]| -> Vec<f64> { a.iter().map(|r| dot(r, s)).collect() };
        let mut h = Bfgs::default();
        assert_eq!(h.along(&[1.0, 0.0, 0.0]), None);
        let s0 = [1.0, 0.0, 0.0];
        h.update(&s0, &times(&s0));
        assert!((h.along(&[0.0, 1.0, 0.0]).unwrap() - 4.0).abs() < 1e-12);
        // A-conjugate steps by Gram–Schmidt in the A inner product.
        let mut steps: Vec<Vec<f64>> = Vec::new();
        for e in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] {
            let mut s = e.to_vec();
            for p in &steps {
                let c = dot(&e, &times(p)) / dot(p, &times(p));
                s.iter_mut().zip(p).for_each(|(a, b)| *a -= c * b);
            }
            h.update(&s, &times(&s));
            let secant = dot(&s, &times(&s)) / dot(&s, &s);
            assert!((h.along(&s).unwrap() - secant).abs() < 1e-12 * secant);
            steps.push(s);
        }
        for d in [[1.0, -2.0, 0.5], [0.0, 1.0, 0.0], [0.3, 0.2, -1.0]] {
            let exact = dot(&d, &times(&d)) / dot(&d, &d);
            assert!((h.along(&d).unwrap() - exact).abs() < 1e-9 * exact, "{d:?}");
        }
        // Negative curvature along a step is damped, not taken.
        h.update(&[1.0, 0.0, 0.0], &[-1.0, 0.0, 0.0]);
        for d in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, -1.0]] {
            assert!(h.along(&d).unwrap() > 0.0);
        }
    }
}
