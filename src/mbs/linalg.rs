//! Small generic kernels: rotations from Euler parameters, a
//! minimum-degree ordering and a rank-counting, regularised sparse
//! Cholesky factorization.
//!
//! Everything is generic over `T: Scalar` so that the same code runs
//! on `f64` and on `num_dual::Dual64` (exact Jacobian-vector products).
//! Branches (segment choice, rank counting) compare values, which for dual
//! numbers compares the real parts: the derivative follows the same branch
//! as the value. Structural zeros are detected on all components.

use nalgebra::{Matrix3, RealField, Vector3};

/// The scalar types of the kernel: `f64` and `num_dual::Dual64`.
/// `is_exact_zero` is true only when every component is exactly zero: the
/// factorization skips structural zeros of sparse matrices by value without
/// ever dropping a derivative.
///
/// The two symmetric positive definite solves of a right-hand side (the
/// constraint-space matrix and the dense mass of a flexible body) go
/// through this trait so that a dual-number evaluation differentiates them
/// analytically, reusing one real factorization, instead of running the
/// factorization in dual arithmetic (docs/numerics.md): for `A x = b`,
/// `x' = A⁻¹(b' − A' x)` with the factor of the real part of `A`.
pub trait Scalar: RealField + Copy {
    fn is_exact_zero(&self) -> bool;

    /// Factor the constraint-space matrix `a` (lower triangle, row-major
    /// `m × m`) in place as [`ordered_cholesky`] does; for dual numbers
    /// the factor of the real matrix goes to `scratch` and the dual parts
    /// of `a` keep `A' + reg·diag(A')`, for [`Scalar::spd_solve`] with the
    /// same scratch.
    fn spd_factor(
        a: &mut [Self],
        m: usize,
        scale: &mut Vec<Self>,
        tols: (f64, f64),
        scratch: &mut SpdScratch,
    ) -> Factored;

    /// Solve with the factor of [`Scalar::spd_factor`] (`b` overwritten).
    fn spd_solve(
        a: &[Self],
        m: usize,
        scale: &[Self],
        f: Factored,
        b: &mut [Self],
        scratch: &mut SpdScratch,
    );

    /// Factor a dense SPD matrix (row-major `n × n`, both triangles) in
    /// place for [`Scalar::dense_solve`]; `false` at a non-positive pivot.
    fn dense_factor(a: &mut [Self], n: usize) -> bool;

    /// Solve with the factor of [`Scalar::dense_factor`] (`x` overwritten).
    fn dense_solve(a: &[Self], n: usize, x: &mut [Self]);
}

/// Real scratch storage of [`Scalar::spd_factor`] / [`Scalar::spd_solve`].
#[derive(Debug, Clone, Default)]
pub struct SpdScratch {
    col: Vec<f64>,
    nz: Vec<usize>,
    scale: Vec<f64>,
    re: Vec<f64>,
    x: Vec<f64>,
    r: Vec<f64>,
    tmp: Vec<f64>,
}

impl Scalar for f64 {
    #[inline]
    fn is_exact_zero(&self) -> bool {
        *self == 0.0
    }
    fn spd_factor(
        a: &mut [f64],
        m: usize,
        scale: &mut Vec<f64>,
        tols: (f64, f64),
        sc: &mut SpdScratch,
    ) -> Factored {
        ordered_cholesky(a, m, scale, tols, &mut sc.col, &mut sc.nz)
    }
    fn spd_solve(
        a: &[f64],
        m: usize,
        scale: &[f64],
        f: Factored,
        b: &mut [f64],
        sc: &mut SpdScratch,
    ) {
        cholesky_solve(a, m, scale, f.accepted, b, &mut sc.tmp);
    }
    fn dense_factor(a: &mut [f64], n: usize) -> bool {
        dense_cholesky(a, n)
    }
    fn dense_solve(a: &[f64], n: usize, x: &mut [f64]) {
        dense_cholesky_solve(a, n, x);
    }
}

impl Scalar for num_dual::Dual64 {
    #[inline]
    fn is_exact_zero(&self) -> bool {
        self.re == 0.0 && self.eps == 0.0
    }
    fn spd_factor(
        a: &mut [Self],
        m: usize,
        scale: &mut Vec<Self>,
        tols: (f64, f64),
        sc: &mut SpdScratch,
    ) -> Factored {
        sc.re.clear();
        sc.re.extend(a.iter().map(|v| v.re));
        let f = ordered_cholesky(&mut sc.re, m, &mut sc.scale, tols, &mut sc.col, &mut sc.nz);
        for k in 0..m {
            // The regularised system is (A + reg·diag(A)) x = b.
            a[k * m + k].eps *= 1.0 + tols.1;
        }
        // The real factor and scaling stay in the scratch for `spd_solve`;
        // `a` keeps A' in its dual parts.
        scale.clear();
        f
    }
    fn spd_solve(
        a: &[Self],
        m: usize,
        _scale: &[Self],
        f: Factored,
        b: &mut [Self],
        sc: &mut SpdScratch,
    ) {
        // `sc.re` and `sc.scale` hold the real factor of the preceding
        // `spd_factor` of `a`.
        debug_assert_eq!(sc.re.len(), a.len());
        sc.x.clear();
        sc.x.extend(b.iter().map(|v| v.re));
        cholesky_solve(&sc.re, m, &sc.scale, f.accepted, &mut sc.x, &mut sc.tmp);
        // r = b' − A' x (A' symmetric, lower triangle stored).
        sc.r.clear();
        sc.r.extend(b.iter().map(|v| v.eps));
        for i in 0..m {
            for j in 0..=i {
                let e = a[i * m + j].eps;
                if e != 0.0 {
                    sc.r[i] -= e * sc.x[j];
                    if i != j {
                        sc.r[j] -= e * sc.x[i];
                    }
                }
            }
        }
        cholesky_solve(&sc.re, m, &sc.scale, f.accepted, &mut sc.r, &mut sc.tmp);
        for (v, (x, r)) in b.iter_mut().zip(sc.x.iter().zip(&sc.r)) {
            *v = Self::new(*x, *r);
        }
    }
    fn dense_factor(a: &mut [Self], n: usize) -> bool {
        let mut re: Vec<f64> = a.iter().map(|v| v.re).collect();
        let ok = dense_cholesky(&mut re, n);
        for (v, r) in a.iter_mut().zip(&re) {
            v.re = *r;
        }
        ok
    }
    fn dense_solve(a: &[Self], n: usize, x: &mut [Self]) {
        // L Lᵀ x = b on the real parts of `a` (no copies; stack buffers
        // for the flexible bodies' 6 + modes ≤ 64 unknowns).
        let solve = |b: &mut [f64]| {
            for k in 0..n {
                let mut s = b[k];
                for j in 0..k {
                    s -= a[k * n + j].re * b[j];
                }
                b[k] = s / a[k * n + k].re;
            }
            for k in (0..n).rev() {
                let mut s = b[k];
                for r in k + 1..n {
                    s -= a[r * n + k].re * b[r];
                }
                b[k] = s / a[k * n + k].re;
            }
        };
        let (mut xs, mut rs) = ([0.0f64; 64], [0.0f64; 64]);
        let (mut xv, mut rv) = (Vec::new(), Vec::new());
        let (xr, r): (&mut [f64], &mut [f64]) = if n <= 64 {
            (&mut xs[..n], &mut rs[..n])
        } else {
            xv.resize(n, 0.0);
            rv.resize(n, 0.0);
            (&mut xv[..], &mut rv[..])
        };
        for k in 0..n {
            xr[k] = x[k].re;
        }
        solve(xr);
        for i in 0..n {
            let row = &a[i * n..(i + 1) * n];
            r[i] = x[i].eps
                - row
                    .iter()
                    .zip(xr.iter())
                    .map(|(e, v)| e.eps * v)
                    .sum::<f64>();
        }
        solve(r);
        for k in 0..n {
            x[k] = Self::new(xr[k], r[k]);
        }
    }
}

/// `f64` constant converted into the scalar type `T`.
#[inline]
pub fn cst<T: RealField + Copy>(x: f64) -> T {
    nalgebra::convert(x)
}

/// Rotation matrix `A(p)` of the Euler parameters `p = (e0, e1, e2, e3)`
/// (Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Eq. 6.19),
/// computed from the normalized `p / |p|` so that a drift of `|p|` never
/// changes the physics. Maps body-frame vectors to global ones.
pub fn rotation<T: Scalar>(p: &[T]) -> Matrix3<T> {
    let n2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
    let inv = T::one() / n2;
    let (e0, e1, e2, e3) = (p[0], p[1], p[2], p[3]);
    let two = cst::<T>(2.0);
    Matrix3::new(
        (e0 * e0 + e1 * e1 - e2 * e2 - e3 * e3) * inv,
        two * (e1 * e2 - e0 * e3) * inv,
        two * (e1 * e3 + e0 * e2) * inv,
        two * (e1 * e2 + e0 * e3) * inv,
        (e0 * e0 - e1 * e1 + e2 * e2 - e3 * e3) * inv,
        two * (e2 * e3 - e0 * e1) * inv,
        two * (e1 * e3 - e0 * e2) * inv,
        two * (e2 * e3 + e0 * e1) * inv,
        (e0 * e0 - e1 * e1 - e2 * e2 + e3 * e3) * inv,
    )
}

/// Time derivative of the Euler parameters for a body-frame angular
/// velocity `w`: `ṗ = ½ p ⊗ (0, w)` (4 components). It is orthogonal to `p`,
/// so `|p|` is an invariant of the exact flow, and the normalized `p̂`
/// rotates with exactly `w` whatever `|p|` is.
pub fn euler_rate<T: Scalar>(p: &[T], w: &Vector3<T>) -> [T; 4] {
    let h = cst::<T>(0.5);
    let e = Vector3::new(p[1], p[2], p[3]);
    let v = (w * p[0] + e.cross(w)) * h;
    [-(e.dot(w)) * h, v[0], v[1], v[2]]
}

/// Euler parameters of a proper rotation matrix (Shepperd's method,
/// numerically safe for every angle). `f64` only (set-up code).
pub fn euler_from_rotation(a: &Matrix3<f64>) -> [f64; 4] {
    let q = nalgebra::UnitQuaternion::from_matrix(a);
    [q.w, q.i, q.j, q.k]
}

/// Outcome of [`ordered_cholesky`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Factored {
    /// Numerical rank: pivots whose Schur diagonal exceeds `tol`.
    pub rank: usize,
    /// Rows factored: all of them unless a pivot is not positive (possible
    /// only with `reg = 0` on a singular matrix, or non-finite input); the
    /// solve then uses the leading block.
    pub accepted: usize,
}

/// Greedy minimum-degree ordering of a symmetric sparsity pattern on `n`
/// nodes given by its off-diagonal `edges` (elimination-graph version:
/// eliminating a node joins its neighbours into a clique). Computed once
/// per system; `O(n³)` bit operations, trivial for ≤ a few hundred rows.
pub fn min_degree_order(n: usize, edges: &[(usize, usize)]) -> Vec<usize> {
    let mut adj = vec![vec![false; n]; n];
    for &(i, j) in edges {
        if i != j {
            adj[i][j] = true;
            adj[j][i] = true;
        }
    }
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for _ in 0..n {
        let degree = |v: usize, adj: &Vec<Vec<bool>>, done: &Vec<bool>| {
            (0..n).filter(|&u| !done[u] && adj[v][u]).count()
        };
        let v = (0..n)
            .filter(|&v| !done[v])
            .min_by_key(|&v| (degree(v, &adj, &done), v))
            .unwrap_or(0);
        let nb: Vec<usize> = (0..n).filter(|&u| !done[u] && adj[v][u]).collect();
        for &a in &nb {
            for &b in &nb {
                if a != b {
                    adj[a][b] = true;
                }
            }
        }
        done[v] = true;
        order.push(v);
    }
    order
}

/// Cholesky factorization of `Â + reg·I` (unit-diagonal scaling
/// `Â = S A S`, `S = diag(1/√a_kk)`) without pivoting, in the order the matrix is
/// stored (use [`min_degree_order`] to keep fill low), skipping exact
/// (structural) zeros in the Schur updates.
///
/// With `reg > 0` the matrix is positive definite, so no pivoting is
/// needed for stability. Each pivot is the squared distance of its row (in
/// the Gram sense) from the span of the rows before it, so the pivots not
/// exceeding `reg + tol` count the dependent rows (`n − rank`) in any
/// order. `scale` receives `S`; `col` and `nz` are scratch.
pub fn ordered_cholesky<T: Scalar>(
    a: &mut [T],
    n: usize,
    scale: &mut Vec<T>,
    tols: (f64, f64),
    col: &mut Vec<T>,
    nz: &mut Vec<usize>,
) -> Factored {
    let (tol, reg) = tols;
    let regt = cst::<T>(reg);
    let tolt = cst::<T>(tol);
    scale.clear();
    for k in 0..n {
        let d = a[k * n + k];
        scale.push(if d > T::zero() {
            T::one() / d.sqrt()
        } else {
            T::zero()
        });
    }
    for i in 0..n {
        let si = scale[i];
        let row = &mut a[i * n..i * n + i + 1];
        for (j, v) in row.iter_mut().enumerate() {
            if !v.is_exact_zero() {
                *v = *v * si * scale[j];
            }
        }
        row[i] += regt;
    }
    col.clear();
    col.resize(n, T::zero());
    let mut rank = 0;
    for k in 0..n {
        let d = a[k * n + k];
        if d.partial_cmp(&T::zero()) != Some(std::cmp::Ordering::Greater) {
            return Factored { rank, accepted: k };
        }
        if d - regt > tolt {
            rank += 1;
        }
        let lkk = d.sqrt();
        a[k * n + k] = lkk;
        let inv = T::one() / lkk;
        nz.clear();
        for r in k + 1..n {
            let v = a[r * n + k];
            if !v.is_exact_zero() {
                let v = v * inv;
                a[r * n + k] = v;
                col[r] = v;
                nz.push(r);
            }
        }
        for (ir, &r) in nz.iter().enumerate() {
            let lr = col[r];
            for &c in &nz[..=ir] {
                a[r * n + c] -= lr * col[c];
            }
        }
    }
    Factored { rank, accepted: n }
}

/// Solve `(Â + reg·I)(S⁻¹x) = S b` with the factor of [`ordered_cholesky`]
/// (`accepted` = [`Factored::accepted`], normally all rows): forward and
/// backward substitution with `L`, scaling by `S` on both sides. `b` is
/// overwritten by `x`; `tmp` is scratch.
pub fn cholesky_solve<T: Scalar>(
    l: &[T],
    n: usize,
    scale: &[T],
    accepted: usize,
    b: &mut [T],
    tmp: &mut Vec<T>,
) {
    tmp.clear();
    tmp.extend((0..accepted).map(|k| b[k] * scale[k]));
    for k in 0..accepted {
        let row = &l[k * n..k * n + k];
        let mut s = tmp[k];
        for (x, y) in row.iter().zip(tmp.iter()) {
            s -= *x * *y;
        }
        tmp[k] = s / l[k * n + k];
    }
    for k in (0..accepted).rev() {
        let mut s = tmp[k];
        for r in k + 1..accepted {
            s -= l[r * n + k] * tmp[r];
        }
        tmp[k] = s / l[k * n + k];
    }
    for v in b.iter_mut() {
        *v = T::zero();
    }
    for k in 0..accepted {
        b[k] = tmp[k] * scale[k];
    }
}

/// In-place dense Cholesky `A = L Lᵀ` of a symmetric positive definite
/// row-major `n × n` matrix (lower triangle read and overwritten).
/// Returns `false` at a non-positive pivot. For the small mass matrices
/// of flexible bodies (`6 + modes`).
pub fn dense_cholesky<T: Scalar>(a: &mut [T], n: usize) -> bool {
    for k in 0..n {
        let mut d = a[k * n + k];
        for j in 0..k {
            d -= a[k * n + j] * a[k * n + j];
        }
        if d.partial_cmp(&T::zero()) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let l = d.sqrt();
        a[k * n + k] = l;
        for r in k + 1..n {
            let mut v = a[r * n + k];
            for j in 0..k {
                v -= a[r * n + j] * a[k * n + j];
            }
            a[r * n + k] = v / l;
        }
    }
    true
}

/// Solve `L Lᵀ x = b` in place with the factor of [`dense_cholesky`].
pub fn dense_cholesky_solve<T: Scalar>(l: &[T], n: usize, b: &mut [T]) {
    for k in 0..n {
        let mut s = b[k];
        for j in 0..k {
            s -= l[k * n + j] * b[j];
        }
        b[k] = s / l[k * n + k];
    }
    for k in (0..n).rev() {
        let mut s = b[k];
        for r in k + 1..n {
            s -= l[r * n + k] * b[r];
        }
        b[k] = s / l[k * n + k];
    }
}

/// Rotation matrix of the rotation vector `θ` (Rodrigues:
/// `I + (sin φ/φ) θ̃ + ((1 − cos φ)/φ²) θ̃²`, `φ = |θ|`), with the
/// coefficients from their Taylor series for `φ² < 1e-4` (error below
/// 1e-22) so that dual numbers stay finite at `θ = 0`.
pub fn rotation_vector<T: Scalar>(th: &Vector3<T>) -> Matrix3<T> {
    let p2 = th.norm_squared();
    let (a, b) = if p2 < cst::<T>(1e-4) {
        let c = |k: f64| cst::<T>(k);
        (
            T::one() - p2 / c(6.0) + p2 * p2 / c(120.0) - p2 * p2 * p2 / c(5040.0),
            c(0.5) - p2 / c(24.0) + p2 * p2 / c(720.0) - p2 * p2 * p2 / c(40320.0),
        )
    } else {
        let phi = p2.sqrt();
        (phi.sin() / phi, (T::one() - phi.cos()) / p2)
    };
    let k = th.cross_matrix();
    Matrix3::identity() + k * a + k * k * b
}

/// Tangent operator of the rotation vector and its rate term: for
/// `R(θ) = exp(θ̃)`, `Ṙ Rᵀ = (T(θ) θ̇)~` with
/// `T = I + b θ̃ + c θ̃²`, `b = (1 − cos φ)/φ²`, `c = (φ − sin φ)/φ³`,
/// and `Ṫ θ̇ = ḃ (θ×θ̇) + ċ θ×(θ×θ̇) + c θ̇×(θ×θ̇)` with
/// `ḃ = 2 b'(φ²)(θ·θ̇)`, `ċ = 2 c'(φ²)(θ·θ̇)` (derivatives with respect to
/// `u = φ²`). Returns `(T, Ṫ θ̇)`. Series in `u` for `φ < 0.1`
/// (truncation below 1e-16), closed forms above.
pub fn rotation_tangent<T: Scalar>(th: &Vector3<T>, thd: &Vector3<T>) -> (Matrix3<T>, Vector3<T>) {
    let u = th.norm_squared();
    let c = |k: f64| cst::<T>(k);
    let (b, cc, db, dc) = if u < c(1e-2) {
        let u2 = u * u;
        let u3 = u2 * u;
        let u4 = u3 * u;
        (
            c(0.5) - u / c(24.0) + u2 / c(720.0) - u3 / c(40320.0) + u4 / c(3628800.0),
            c(1.0 / 6.0) - u / c(120.0) + u2 / c(5040.0) - u3 / c(362880.0) + u4 / c(39916800.0),
            c(-1.0 / 24.0) + u * c(2.0 / 720.0) - u2 * c(3.0 / 40320.0) + u3 * c(4.0 / 3628800.0),
            c(-1.0 / 120.0) + u * c(2.0 / 5040.0) - u2 * c(3.0 / 362880.0)
                + u3 * c(4.0 / 39916800.0),
        )
    } else {
        let phi = u.sqrt();
        let (s, co) = (phi.sin(), phi.cos());
        let phi5 = u * u * phi;
        (
            (T::one() - co) / u,
            (phi - s) / (u * phi),
            (phi * s * c(0.5) - (T::one() - co)) / (u * u),
            ((T::one() - co) * phi * c(0.5) - (phi - s) * c(1.5)) / phi5,
        )
    };
    let k = th.cross_matrix();
    let tmat = Matrix3::identity() + k * b + k * k * cc;
    let two_dot = c(2.0) * th.dot(thd);
    let txd = th.cross(thd);
    let rate = txd * (db * two_dot) + th.cross(&txd) * (dc * two_dot) + thd.cross(&txd) * cc;
    (tmat, rate)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordered_cholesky_counts_rank_and_solves_regularised_system() {
        // A = G Gᵀ with G 4×3 whose 4th row = row0 + row1 (rank 3):
        // identity construction, closed form derived in this test. The
        // right-hand side is in the range of A (consistent).
        let g = [
            [1.0, 2.0, 0.5],
            [0.0, 1.0, -1.0],
            [3.0, 0.0, 1.0],
            [1.0, 3.0, -0.5],
        ];
        let n = 4;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..3).map(|k| g[i][k] * g[j][k]).sum();
            }
        }
        let a0 = a.clone();
        let b0: Vec<f64> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| a0[i * n + j] * [0.3, -1.2, 0.7, 0.0][j])
                    .sum()
            })
            .collect();
        let mut b = b0.clone();
        let (mut scale, mut col, mut nz, mut tmp) = (vec![], vec![], vec![], vec![]);
        let f = ordered_cholesky(&mut a, n, &mut scale, (1e-8, 1e-12), &mut col, &mut nz);
        assert_eq!((f.rank, f.accepted), (3, 4));
        cholesky_solve(&a, n, &scale, n, &mut b, &mut tmp);
        for i in 0..n {
            let r: f64 = (0..n).map(|j| a0[i * n + j] * b[j]).sum::<f64>() - b0[i];
            assert!(r.abs() < 1e-9, "row {i} residual {r}");
        }
        // Minimum degree on a path 0-1-2-3 eliminates an end first.
        let order = min_degree_order(4, &[(0, 1), (1, 2), (2, 3)]);
        assert!(order[0] == 0 || order[0] == 3);
    }

    #[test]
    fn rotation_is_orthonormal_and_matches_quaternion() {
        // Reference: nalgebra's UnitQuaternion::to_rotation_matrix.
        let p = [0.3, -0.5, 0.7, 0.2];
        let a = rotation(&p);
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            p[0], p[1], p[2], p[3],
        ));
        let r = q.to_rotation_matrix().into_inner();
        assert!((a - r).norm() < 1e-14);
        assert!((a.transpose() * a - Matrix3::identity()).norm() < 1e-14);
    }

    #[test]
    fn rotation_vector_matches_axis_angle_on_both_branches() {
        // Reference: nalgebra's Rotation3::from_scaled_axis.
        for th in [
            Vector3::new(0.001, -0.002, 0.003),
            Vector3::new(0.3, -0.5, 0.7),
        ] {
            let r = nalgebra::Rotation3::from_scaled_axis(th).into_inner();
            assert!((rotation_vector(&th) - r).norm() < 1e-15);
        }
    }

    #[test]
    fn rotation_tangent_matches_finite_differences_on_both_branches() {
        // Ṙ Rᵀ = (T θ̇)~ and d/dt(T θ̇) at fixed θ̇ = Ṫ θ̇, by central
        // differences along θ(t) = θ0 + t θ̇.
        for (th, thd) in [
            (
                Vector3::new(0.01, -0.02, 0.03),
                Vector3::new(0.5, 0.2, -0.7),
            ),
            (Vector3::new(0.4, -0.5, 0.7), Vector3::new(0.5, 0.2, -0.7)),
        ] {
            let h = 1e-6;
            let rp = rotation_vector(&(th + thd * h));
            let rm = rotation_vector(&(th - thd * h));
            let w = (rp - rm) / (2.0 * h) * rotation_vector(&th).transpose();
            let axial = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
            let (t, rate) = rotation_tangent(&th, &thd);
            assert!((axial - t * thd).norm() < 1e-8, "{:?}", axial - t * thd);
            let (tp, _) = rotation_tangent(&(th + thd * h), &thd);
            let (tm, _) = rotation_tangent(&(th - thd * h), &thd);
            let fd = (tp - tm) / (2.0 * h) * thd;
            assert!((fd - rate).norm() < 1e-8, "{:?}", fd - rate);
        }
    }

    #[test]
    fn dense_cholesky_solves_spd_system() {
        // A = B Bᵀ + I (SPD by construction); residual check.
        let n = 5;
        let b: Vec<f64> = (0..n * n)
            .map(|k| ((k * 7 % 11) as f64 - 5.0) / 3.0)
            .collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|k| b[i * n + k] * b[j * n + k]).sum::<f64>()
                    + if i == j { 1.0 } else { 0.0 };
            }
        }
        let a0 = a.clone();
        let rhs: Vec<f64> = (0..n).map(|k| k as f64 - 1.5).collect();
        let mut x = rhs.clone();
        assert!(dense_cholesky(&mut a, n));
        dense_cholesky_solve(&a, n, &mut x);
        for i in 0..n {
            let r: f64 = (0..n).map(|j| a0[i * n + j] * x[j]).sum::<f64>() - rhs[i];
            assert!(r.abs() < 1e-12);
        }
    }
}
