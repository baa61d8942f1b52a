//! The mode-shape rows of a node split into real planes, for the sums over
//! the modes that every right-hand side makes at a node marker: its
//! deformation `Σ_j Φ_j w_j`, rotation `Σ_j Ψ_j w_j` and their rates, and
//! the modal entries `a·Φ_j + b·Ψ_j` of the constraint rows at the node.
//!
//! In a dual evaluation the shapes carry the design seeds (`Φ + Σ_v Φ'_v
//! δ_v`), so each term of these sums is a product of two dual numbers. The
//! planes hold the shapes' real parts and lanes as plain `f64`, built once
//! with the shapes (they change only with the design seeds), and the sums
//! are taken plane by plane with the product rule,
//! `(x·y)'_l = x'_l·y + x·y'_l`: real arithmetic in contiguous arrays
//! instead of `14 × 6` dual products per sum. For `f64` there is one plane
//! and the sums are the plain ones.

use super::scalar::{Scalar, MAX_LANES};
use nalgebra::Vector3;

/// Most planes a number splits into: the real part and its lanes.
const MAX_PLANES: usize = MAX_LANES + 1;

/// The shape rows `(Φ_j, Ψ_j)`, `j < n`, of one node as planes:
/// `v[(j·6 + c)·np + p]` (`np` = 1 + lanes) with plane `p = 0` the real
/// parts and `p = 1 + l` lane `l`, `c < 3` the translation `Φ_j` and
/// `c ≥ 3` the rotation `Ψ_j`. The planes of one entry are contiguous, so
/// the sums below run over all lanes of an entry at once (vector
/// instructions), each lane with the operations, in the order, of the
/// product rule.
#[derive(Debug, Clone, Default)]
pub struct ShapePlanes {
    n: usize,
    np: usize,
    v: Vec<f64>,
}

/// The real part and lanes of `x` into `out` (`1 + NL` long).
fn split<T: Scalar>(x: &T, out: &mut [f64]) {
    out[0] = x.re_part();
    for (l, o) in out[1..].iter_mut().enumerate() {
        *o = x.lane_part(l);
    }
}

impl ShapePlanes {
    /// The planes of the shape rows `phi`, `psi` (equal lengths).
    pub fn new<T: Scalar>(phi: &[Vector3<T>], psi: &[Vector3<T>]) -> ShapePlanes {
        let (n, np) = (phi.len(), 1 + T::NL);
        let mut v = vec![0.0; np * n * 6];
        for (j, (f, s)) in phi.iter().zip(psi).enumerate() {
            for c in 0..6 {
                let e = (j * 6 + c) * np;
                split(if c < 3 { &f[c] } else { &s[c - 3] }, &mut v[e..e + np]);
            }
        }
        ShapePlanes { n, np, v }
    }

    /// Number of modes.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The planes of row `j` (six entries, `np` planes each: `Φ_j`, then
    /// `Ψ_j`).
    fn row(&self, j: usize) -> &[f64] {
        &self.v[j * 6 * self.np..(j + 1) * 6 * self.np]
    }

    /// `(Σ_j Φ_j x_j, Σ_j Ψ_j x_j)` for the `n` numbers `x`.
    pub fn combine<T: Scalar>(&self, x: &[T]) -> (Vector3<T>, Vector3<T>) {
        let np = 1 + T::NL;
        assert!(np <= MAX_PLANES, "at most {} lanes", MAX_PLANES - 1);
        assert!(
            self.n == 0 || np == self.np,
            "planes built for another lane count"
        );
        // acc[c·np + p]: plane p of component c.
        let mut acc = [0.0; MAX_PLANES * 6];
        let mut xp = [0.0; MAX_PLANES];
        for (j, xj) in x.iter().enumerate().take(self.n) {
            split(xj, &mut xp[..np]);
            let row = self.row(j);
            for c in 0..6 {
                let s = &row[c * np..(c + 1) * np];
                let a = &mut acc[c * np..(c + 1) * np];
                a[0] += s[0] * xp[0];
                for p in 1..np {
                    a[p] += s[p] * xp[0] + s[0] * xp[p];
                }
            }
        }
        let entry = |c: usize| T::from_parts(acc[c * np], &acc[c * np + 1..(c + 1) * np]);
        (
            Vector3::new(entry(0), entry(1), entry(2)),
            Vector3::new(entry(3), entry(4), entry(5)),
        )
    }

    /// The modal entries `e_j = a·Φ_j + b·Ψ_j` of a constraint row (pushed
    /// onto `out`) and `Σ_j e_j c_j` (the `Ψ` terms skipped when `b` is
    /// exactly zero, as for the point rows of spherical joints).
    pub fn row_entries<T: Scalar>(
        &self,
        (a, b): (&Vector3<T>, &Vector3<T>),
        c: &[T],
        out: &mut Vec<T>,
    ) -> T {
        let np = 1 + T::NL;
        assert!(np <= MAX_PLANES, "at most {} lanes", MAX_PLANES - 1);
        assert!(
            self.n == 0 || np == self.np,
            "planes built for another lane count"
        );
        // ab[k·np + p]: plane p of coefficient k (a, then b).
        let mut ab = [0.0; MAX_PLANES * 6];
        for k in 0..6 {
            split(
                if k < 3 { &a[k] } else { &b[k - 3] },
                &mut ab[k * np..(k + 1) * np],
            );
        }
        let nk = if b.iter().all(|v| v.is_exact_zero()) {
            3
        } else {
            6
        };
        let (mut e, mut cp, mut sum) = ([0.0; MAX_PLANES], [0.0; MAX_PLANES], [0.0; MAX_PLANES]);
        for (j, cj) in c.iter().enumerate().take(self.n) {
            let row = self.row(j);
            // e[p] = Σ_k (ab_k^p s_k^0 + ab_k^0 s_k^p) (p ≥ 1) and
            // e[0] = Σ_k ab_k^0 s_k^0, summed over k in order from −0
            // (as `Iterator::sum` does).
            e[..np].fill(-0.0);
            for k in 0..nk {
                let (s, abk) = (&row[k * np..(k + 1) * np], &ab[k * np..(k + 1) * np]);
                e[0] += abk[0] * s[0];
                for p in 1..np {
                    e[p] += abk[p] * s[0] + abk[0] * s[p];
                }
            }
            out.push(T::from_parts(e[0], &e[1..np]));
            split(cj, &mut cp[..np]);
            sum[0] += e[0] * cp[0];
            for p in 1..np {
                sum[p] += e[p] * cp[0] + e[0] * cp[p];
            }
        }
        T::from_parts(sum[0], &sum[1..np])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::math::DualN;

    type D = DualN<2>;

    fn d(k: usize) -> D {
        let x = k as f64;
        D::from_parts((0.7 * x).sin(), &[(1.3 * x).cos(), (0.4 * x + 1.0).sin()])
    }

    fn close(a: D, b: D) -> bool {
        let tol = |x: f64, y: f64| (x - y).abs() <= 1e-14 * (1.0 + y.abs());
        tol(a.re, b.re) && (0..2).all(|l| tol(a.lane_part(l), b.lane_part(l)))
    }

    /// The shape rows `(Φ_j, Ψ_j)`, `j < n`, with entries `e(6j + c)`.
    type Rows<T> = (Vec<Vector3<T>>, Vec<Vector3<T>>);
    fn shape_rows<T: Scalar>(n: usize, e: impl Fn(usize) -> T) -> Rows<T> {
        let row =
            |j: usize, c: usize| Vector3::new(e(6 * j + c), e(6 * j + c + 1), e(6 * j + c + 2));
        (
            (0..n).map(|j| row(j, 0)).collect(),
            (0..n).map(|j| row(j, 3)).collect(),
        )
    }

    /// `(Σ_j Φ_j x_j, Σ_j Ψ_j x_j)` by the scalar type's own arithmetic.
    fn dual_sums<T: Scalar>((phi, psi): &Rows<T>, x: &[T]) -> (Vector3<T>, Vector3<T>) {
        let (mut u0, mut t0) = (Vector3::<T>::zeros(), Vector3::<T>::zeros());
        for j in 0..x.len() {
            u0 += phi[j] * x[j];
            t0 += psi[j] * x[j];
        }
        (u0, t0)
    }

    #[test]
    fn plane_sums_equal_dual_arithmetic() {
        // The planes' product rule against num-dual's own products, for
        // the deformation sums and the modal entries of a row.
        let n = 5;
        let rows = shape_rows(n, d);
        let (phi, psi) = &rows;
        let x: Vec<D> = (0..n).map(|j| d(100 + j)).collect();
        let planes = ShapePlanes::new(phi, psi);
        assert_eq!(planes.n(), n);
        let (u, t) = planes.combine(&x);
        let (u0, t0) = dual_sums(&rows, &x);
        for c in 0..3 {
            assert!(close(u[c], u0[c]) && close(t[c], t0[c]), "component {c}");
        }
        let (a, b) = (
            Vector3::new(d(50), d(51), d(52)),
            Vector3::new(d(53), d(54), d(55)),
        );
        let mut out = Vec::new();
        let sum = planes.row_entries((&a, &b), &x, &mut out);
        let mut sum0 = D::from(0.0);
        for j in 0..n {
            let e = a.dot(&phi[j]) + b.dot(&psi[j]);
            assert!(close(out[j], e), "entry {j}");
            sum0 += e * x[j];
        }
        assert!(close(sum, sum0));
        // One plane for f64: the plain sums.
        let phr: Vec<Vector3<f64>> = phi.iter().map(|v| v.map(|e| e.re)).collect();
        let psr: Vec<Vector3<f64>> = psi.iter().map(|v| v.map(|e| e.re)).collect();
        let xr: Vec<f64> = x.iter().map(|e| e.re).collect();
        let (ur, _) = ShapePlanes::new(&phr, &psr).combine(&xr);
        assert!((ur[0] - u0[0].re).abs() < 1e-14);
    }

    #[test]
    fn eight_lane_sums_equal_dual_arithmetic_to_the_bit() {
        // With the planes of an entry contiguous, each lane still gets the
        // product rule's operations in the order of dual arithmetic
        // (`acc + (s·x)`: s'x + x's), so the deformation sums equal
        // `DualN<8>`'s own to the last bit.
        type D8 = DualN<8>;
        let e = |k: usize| {
            let x = k as f64;
            D8::new(
                (0.7 * x).sin(),
                std::array::from_fn(|l| (1.3 * x + l as f64).cos()),
            )
        };
        let n = 14;
        let rows = shape_rows(n, e);
        let x: Vec<D8> = (0..n).map(|j| e(200 + j)).collect();
        let (u, t) = ShapePlanes::new(&rows.0, &rows.1).combine(&x);
        let (u0, t0) = dual_sums(&rows, &x);
        for c in 0..3 {
            for (a, b) in [(u[c], u0[c]), (t[c], t0[c])] {
                assert_eq!(a.re.to_bits(), b.re.to_bits(), "component {c}");
                for l in 0..8 {
                    assert_eq!(
                        a.eps[l].to_bits(),
                        b.eps[l].to_bits(),
                        "component {c}, lane {l}"
                    );
                }
            }
        }
    }
}
