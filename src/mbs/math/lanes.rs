//! [`Scalar`] for `f64` and the dual-number types: their real part and
//! derivative lanes, and the dense factorization that keeps the real
//! parts as an explicit inverse.

use super::dense::spd_inverse;
use super::dual::DualN;
use super::scalar::{Scalar, MAX_LANES};

impl Scalar for f64 {
    const NL: usize = 0;
    #[inline]
    fn is_exact_zero(&self) -> bool {
        *self == 0.0
    }
    #[inline]
    fn re_part(&self) -> f64 {
        *self
    }
    #[inline]
    fn lane_part(&self, _l: usize) -> f64 {
        0.0
    }
    #[inline]
    fn from_parts(re: f64, _lanes: &[f64]) -> f64 {
        re
    }
    fn dense_factor(a: &mut [f64], n: usize) -> bool {
        spd_inverse(a, n)
    }
}

/// Dual numbers read and written by lane, behind [`Scalar`]'s parts
/// accessors (the kernel uses those): a real part and `L` dual parts.
/// `num_dual::Dual64` has one lane; [`DualN<N>`] has `N` (one multi-lane
/// evaluation gives a value and `N` directional derivatives at once).
trait Lanes: Copy {
    /// Number of dual parts.
    const L: usize;
    /// The real part.
    fn re(&self) -> f64;
    /// Dual part `k` (0 when the number carries none).
    fn lane(&self, k: usize) -> f64;
    /// The number with real part `re` and dual parts `lanes` (length `L`).
    fn with(re: f64, lanes: &[f64]) -> Self;
    /// Replace the real part (the dual parts are kept).
    fn set_re(&mut self, re: f64);
    /// Whether every component is exactly zero.
    fn all_zero(&self) -> bool {
        self.re() == 0.0 && (0..Self::L).all(|k| self.lane(k) == 0.0)
    }
}

impl Lanes for num_dual::Dual64 {
    const L: usize = 1;
    #[inline]
    fn re(&self) -> f64 {
        self.re
    }
    #[inline]
    fn lane(&self, _k: usize) -> f64 {
        self.eps
    }
    #[inline]
    fn with(re: f64, lanes: &[f64]) -> Self {
        Self::new(re, lanes[0])
    }
    #[inline]
    fn set_re(&mut self, re: f64) {
        self.re = re;
    }
}

impl<const N: usize> Lanes for DualN<N> {
    const L: usize = {
        assert!(N <= MAX_LANES, "more lanes than the kernel's lane buffers");
        N
    };
    #[inline]
    fn re(&self) -> f64 {
        self.re
    }
    #[inline]
    fn lane(&self, k: usize) -> f64 {
        self.eps[k]
    }
    #[inline]
    fn with(re: f64, lanes: &[f64]) -> Self {
        DualN::new(re, std::array::from_fn(|l| lanes[l]))
    }
    #[inline]
    fn set_re(&mut self, re: f64) {
        self.re = re;
    }
}

/// [`Scalar::dense_factor`] for dual numbers: the real parts become the
/// explicit inverse `A⁻¹` of the real matrix ([`spd_inverse`]), the dual
/// parts keep `A'`, which the tangent of the constraint-space solve reads
/// (`crate::mbs::constraints::tangent`).
fn lanes_dense_factor<D: Lanes>(a: &mut [D], n: usize) -> bool {
    let mut inv: Vec<f64> = a.iter().map(|v| v.re()).collect();
    let ok = spd_inverse(&mut inv, n);
    for (v, m) in a.iter_mut().zip(&inv) {
        v.set_re(*m);
    }
    ok
}

/// [`Scalar`] for a dual-number type through its [`Lanes`].
macro_rules! lanes_scalar {
    () => {
        const NL: usize = <Self as Lanes>::L;
        #[inline]
        fn is_exact_zero(&self) -> bool {
            self.all_zero()
        }
        #[inline]
        fn re_part(&self) -> f64 {
            self.re()
        }
        #[inline]
        fn lane_part(&self, l: usize) -> f64 {
            self.lane(l)
        }
        #[inline]
        fn from_parts(re: f64, lanes: &[f64]) -> Self {
            Self::with(re, lanes)
        }
        fn dense_factor(a: &mut [Self], n: usize) -> bool {
            lanes_dense_factor(a, n)
        }
    };
}

impl Scalar for num_dual::Dual64 {
    lanes_scalar!();
}

impl<const N: usize> Scalar for DualN<N> {
    lanes_scalar!();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::math::{dense_cholesky, dense_cholesky_solve, gram, sym_times};

    /// An SPD matrix `A(ε) = B Bᵀ + I + ε₁ C₁ + ε₂ C₂` (`C_q` symmetric)
    /// and a right-hand side `b(ε)`, for the dual solves.
    fn perturbed_system(n: usize, e: [f64; 2]) -> (Vec<f64>, Vec<f64>) {
        let b: Vec<f64> = (0..n * n)
            .map(|k| ((k * 7 % 11) as f64 - 5.0) / 3.0)
            .collect();
        let c = |q: usize, i: usize, j: usize| (((i + j + q) * 5 % 7) as f64 - 3.0) / 10.0;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|k| b[i * n + k] * b[j * n + k]).sum::<f64>()
                    + if i == j { 1.0 } else { 0.0 }
                    + e[0] * c(0, i, j)
                    + e[1] * c(1, i, j);
            }
        }
        let rhs = (0..n)
            .map(|k| k as f64 - 1.5 + e[0] * (k as f64).sin() + e[1] * (k as f64).cos())
            .collect();
        (a, rhs)
    }

    #[test]
    fn inverse_mass_and_gram_blocks() {
        // The explicit inverse of dense_factor against A·A⁻¹ = I, the Gram
        // block of gram against triangular solves (dense_cholesky)
        // and plain dot products, and the dual form: real parts the
        // inverse of the real matrix, lanes the matrix's derivative A'
        // (what the tangent of the constraint-space solve reads).
        use crate::mbs::math::DualN;
        let n = 6;
        let (a0, b0) = perturbed_system(n, [0.0; 2]);
        let (a1, _) = perturbed_system(n, [1.0, 0.0]);
        let (a2, _) = perturbed_system(n, [0.0, 1.0]);
        let mut inv = a0.clone();
        assert!(<f64 as Scalar>::dense_factor(&mut inv, n));
        for i in 0..n {
            for j in 0..n {
                let p: f64 = (0..n).map(|k| a0[i * n + k] * inv[k * n + j]).sum();
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((p - e).abs() < 1e-12, "(A A⁻¹)[{i}][{j}] = {p}");
            }
        }
        // Two vectors b and 2b: w = (x, 2x), g = (b·x; 2b·x, 4b·x).
        let mut l = a0.clone();
        assert!(dense_cholesky(&mut l, n));
        let mut x = b0.clone();
        dense_cholesky_solve(&l, n, &mut x);
        let rows: Vec<f64> = b0
            .iter()
            .chain(b0.iter())
            .enumerate()
            .map(|(k, v)| if k < n { *v } else { 2.0 * v })
            .collect();
        let (mut w, mut g) = (vec![0.0; 2 * n], Vec::new());
        for (b, wi) in rows.chunks_exact(n).zip(w.chunks_exact_mut(n)) {
            sym_times(&inv, n, b, wi);
        }
        gram(&rows, &w, n, &mut g);
        let bx: f64 = (0..n).map(|k| b0[k] * x[k]).sum();
        for k in 0..n {
            assert!((w[k] - x[k]).abs() < 1e-12 * (1.0 + x[k].abs()));
            assert!((w[n + k] - 2.0 * x[k]).abs() < 1e-12 * (1.0 + x[k].abs()));
        }
        for (got, want) in [(g[0], bx), (g[2], 2.0 * bx), (g[3], 4.0 * bx)] {
            assert!((got - want).abs() < 1e-12 * (1.0 + want.abs()));
        }
        let mut ad: Vec<DualN<2>> = (0..n * n)
            .map(|k| DualN::<2>::with(a0[k], &[a1[k] - a0[k], a2[k] - a0[k]]))
            .collect();
        assert!(<DualN<2> as Scalar>::dense_factor(&mut ad, n));
        for k in 0..n * n {
            assert!((ad[k].re - inv[k]).abs() < 1e-14 * (1.0 + inv[k].abs()));
            assert_eq!(ad[k].lane(0), a1[k] - a0[k]);
            assert_eq!(ad[k].lane(1), a2[k] - a0[k]);
        }
    }
}
