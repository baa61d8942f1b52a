//! Small generic kernels: rotations from Euler parameters, a
//! minimum-degree ordering and a rank-counting, regularised sparse
//! Cholesky factorization.
//!
//! Everything is generic over `T: Scalar` so that the same code runs
//! on `f64` and on `num_dual::Dual64` (exact Jacobian-vector products).
//! Branches (segment choice, rank counting) compare values, which for dual
//! numbers compares the real parts: the derivative follows the same branch
//! as the value. Structural zeros are detected on all components.

use super::dual::DualN;
use nalgebra::{Matrix3, RealField, Vector3};

/// The scalar types of the kernel: `f64`, and dual numbers with `NL`
/// derivative lanes (`num_dual::Dual64`, [`DualN<N>`](super::dual::DualN)).
/// `is_exact_zero` is true only when every component is exactly zero.
///
/// The two symmetric positive definite solves of a right-hand side (the
/// constraint-space matrix and the dense mass of a flexible body) are not
/// run in dual arithmetic: the solve is real, and a dual evaluation adds
/// its tangent with the same factorizations ([`super::solve`],
/// docs/numerics.md); the parts accessors below split a number into its
/// real part and lanes for that.
pub trait Scalar: RealField + Copy {
    /// Number of derivative lanes (0 for `f64`).
    const NL: usize;

    fn is_exact_zero(&self) -> bool;

    /// The real part.
    fn re_part(&self) -> f64;

    /// Derivative lane `l < NL`.
    fn lane_part(&self, l: usize) -> f64;

    /// The number with real part `re` and lanes `lanes` (length `NL`).
    fn from_parts(re: f64, lanes: &[f64]) -> Self;

    /// Factor a dense SPD matrix (row-major `n × n`, both triangles) in
    /// place; `false` at a non-positive pivot. The real parts become the
    /// explicit inverse `A⁻¹` ([`spd_inverse`]), so that every later solve
    /// is a matrix–vector product of independent sums instead of a pair
    /// of triangular solves, whose sequential divisions dominate at the
    /// flexible bodies' `n` ≈ 20 (one solve per constraint row touching
    /// the body); the lanes of a dual number keep `A'`.
    fn dense_factor(a: &mut [Self], n: usize) -> bool;
}

/// Most derivative lanes of a [`Scalar`] type (fixed-size lane buffers
/// of the kernel; the multi-lane evaluations use 2 or 4).
pub const MAX_LANES: usize = 8;

/// Real scratch storage of [`spd_factor`] / [`spd_solve`],
/// with the symbolic factorization they follow ([`SpdScratch::set_pattern`];
/// a dense pattern when none of the matrix's size was set).
#[derive(Debug, Clone, Default)]
pub struct SpdScratch {
    pattern: CholPattern,
    tmp: Vec<f64>,
}

impl SpdScratch {
    /// Factor every later matrix with the nonzero structure `pattern`
    /// (computed once per system: the rows touching each body never
    /// change).
    pub fn set_pattern(&mut self, pattern: CholPattern) {
        self.pattern = pattern;
    }

    /// The pattern for an `m × m` matrix: the one set, or a dense one.
    fn pattern(&mut self, m: usize) -> &CholPattern {
        if self.pattern.n != m {
            self.pattern = CholPattern::dense(m);
        }
        &self.pattern
    }
}

/// The symbolic Cholesky factorization of a sparse symmetric matrix in
/// its stored order: which entries of `L` (fill included) can be nonzero.
/// Computed once per system; the numeric factorization and the solves
/// then touch only these entries (the SAR constraint-space factor: 595
/// of the 2145 lower-triangle entries).
#[derive(Debug, Clone, Default)]
pub struct CholPattern {
    n: usize,
    /// Per column `k`: the rows `r > k` of its possible nonzeros, sorted.
    col_rows: Vec<Vec<usize>>,
    /// Per row `i`: the columns `j < i` of its possible nonzeros, sorted.
    row_cols: Vec<Vec<usize>>,
}

impl CholPattern {
    /// From the off-diagonal nonzeros `(i, j)` of the matrix (either
    /// triangle) by symbolic elimination: eliminating column `k` joins
    /// every pair of rows below it that it touches (`O(n³)` bit
    /// operations, once, for a few hundred rows at most).
    pub fn new(n: usize, entries: &[(usize, usize)]) -> CholPattern {
        let mut nz = vec![vec![false; n]; n];
        for &(i, j) in entries {
            if i != j {
                nz[i.max(j)][i.min(j)] = true;
            }
        }
        let mut col_rows = Vec::with_capacity(n);
        for k in 0..n {
            let rows: Vec<usize> = (k + 1..n).filter(|&r| nz[r][k]).collect();
            for (x, &r) in rows.iter().enumerate() {
                for &c in &rows[..x] {
                    nz[r][c] = true;
                }
            }
            col_rows.push(rows);
        }
        let row_cols = (0..n)
            .map(|i| (0..i).filter(|&j| nz[i][j]).collect())
            .collect();
        CholPattern {
            n,
            col_rows,
            row_cols,
        }
    }

    /// Every entry possibly nonzero.
    pub fn dense(n: usize) -> CholPattern {
        CholPattern {
            n,
            col_rows: (0..n).map(|k| (k + 1..n).collect()).collect(),
            row_cols: (0..n).map(|i| (0..i).collect()).collect(),
        }
    }

    /// Possible nonzeros of `L` below the diagonal.
    pub fn nnz(&self) -> usize {
        self.col_rows.iter().map(Vec::len).sum()
    }
}

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

/// Factor the constraint-space matrix `a` (lower triangle, row-major
/// `m × m`) in place by [`ordered_cholesky`] on the pattern of `sc`.
pub fn spd_factor(
    a: &mut [f64],
    m: usize,
    scale: &mut Vec<f64>,
    tols: (f64, f64),
    sc: &mut SpdScratch,
) -> Factored {
    ordered_cholesky(a, m, scale, tols, sc.pattern(m))
}

/// Solve with the factor of [`spd_factor`] (`b` overwritten).
pub fn spd_solve(
    a: &[f64],
    m: usize,
    scale: &[f64],
    f: Factored,
    b: &mut [f64],
    sc: &mut SpdScratch,
) {
    sc.pattern(m);
    cholesky_solve(a, (scale, &sc.pattern), f.accepted, b, &mut sc.tmp);
}

/// The Gram block `g_ij = b_i · w_j`, `j ≤ i` (row-major `k × k`, lower
/// triangle) of the `k` rows `b_i` of `rows` and `w_i` of `w` (both
/// row-major `k × n`): with `w_i = M⁻¹ b_i`, one body's block of the
/// constraint-space matrix (its constraint rows and applied force).
pub fn gram(rows: &[f64], w: &[f64], n: usize, g: &mut Vec<f64>) {
    let k = rows.len() / n;
    g.clear();
    g.resize(k * k, 0.0);
    for i in 0..k {
        let bi = &rows[i * n..(i + 1) * n];
        for j in 0..=i {
            g[i * k + j] = fdot(bi, &w[j * n..(j + 1) * n]);
        }
    }
}

/// `a · b` with four partial sums (independent additions the compiler
/// can keep in vector registers).
#[inline]
pub fn fdot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for q in 0..4 {
            acc[q] += x[q] * y[q];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
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
/// (`super::solve`).
fn lanes_dense_factor<D: Lanes>(a: &mut [D], n: usize) -> bool {
    let mut inv: Vec<f64> = a.iter().map(|v| v.re()).collect();
    let ok = spd_inverse(&mut inv, n);
    for (v, m) in a.iter_mut().zip(&inv) {
        v.set_re(*m);
    }
    ok
}

/// In-place explicit inverse of a dense symmetric positive definite
/// matrix (row-major `n × n`, lower triangle read, both triangles
/// written): the Cholesky factor `A = L Lᵀ` ([`dense_cholesky`]), then
/// `X = L⁻¹` and `A⁻¹ = Xᵀ X`, about `n³/2` multiply–adds, each loop an
/// independent vector update. `false` at a non-positive pivot (the
/// contents are then unspecified).
pub fn spd_inverse(a: &mut [f64], n: usize) -> bool {
    if !dense_cholesky(a, n) {
        return false;
    }
    thread_local! {
        static X: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
    }
    X.with_borrow_mut(|x| {
        x.clear();
        x.resize(n * n, 0.0);
        // X = L⁻¹ row by row (row k = (e_k − Σ_{j<k} L_kj X_j) / L_kk,
        // lower triangular), each row update a vector operation.
        for k in 0..n {
            let (done, rest) = x.split_at_mut(k * n);
            let row = &mut rest[..n];
            row[k] = 1.0;
            for j in 0..k {
                let c = a[k * n + j];
                if c != 0.0 {
                    for (r, v) in row[..=j].iter_mut().zip(&done[j * n..j * n + j + 1]) {
                        *r -= c * v;
                    }
                }
            }
            let inv = 1.0 / a[k * n + k];
            for r in row[..=k].iter_mut() {
                *r *= inv;
            }
        }
        // A⁻¹ = Xᵀ X: (A⁻¹)_ij = Σ_{k ≥ max(i, j)} X_ki X_kj.
        a.fill(0.0);
        for k in 0..n {
            let xk = &x[k * n..k * n + k + 1];
            for (i, xi) in xk.iter().enumerate() {
                let out = &mut a[i * n..i * n + k + 1];
                for (o, xj) in out.iter_mut().zip(xk) {
                    *o += xi * xj;
                }
            }
        }
    });
    true
}

/// `out = S x` for a symmetric row-major `n × n` matrix `S`, as a sum of
/// its rows scaled by the entries of `x` (row `j` = column `j`): vector
/// updates, and nothing done for the zero entries of `x` (the rigid
/// part of a constraint row on a flexible body has zero modal entries).
#[inline]
pub fn sym_times(s: &[f64], n: usize, x: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (j, &xj) in x.iter().enumerate() {
        if xj != 0.0 {
            for (o, v) in out.iter_mut().zip(&s[j * n..(j + 1) * n]) {
                *o += xj * v;
            }
        }
    }
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

/// `f64` constant converted into the scalar type `T`.
#[inline]
pub fn cst<T: RealField + Copy>(x: f64) -> T {
    nalgebra::convert(x)
}

/// `A v` for a 3 × 3 matrix, written out. nalgebra's generic product
/// forms `α A v + β y` with `α = 1`, `β = 0` for any scalar type: two
/// more products per entry, which a dual number pays in full (on `f64`
/// the result is the same to the bit: the sums run in the same order).
#[inline(always)]
pub fn mv<T: Scalar>(a: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
    Vector3::from_fn(|i, _| a[(i, 0)] * v[0] + a[(i, 1)] * v[1] + a[(i, 2)] * v[2])
}

/// `Aᵀ v` for a 3 × 3 matrix, written out (see [`mv`]).
#[inline(always)]
pub fn mtv<T: Scalar>(a: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
    Vector3::from_fn(|i, _| a[(0, i)] * v[0] + a[(1, i)] * v[1] + a[(2, i)] * v[2])
}

/// `A B` for 3 × 3 matrices, written out (see [`mv`]).
#[inline(always)]
pub fn mm<T: Scalar>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    Matrix3::from_fn(|i, j| a[(i, 0)] * b[(0, j)] + a[(i, 1)] * b[(1, j)] + a[(i, 2)] * b[(2, j)])
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
/// stored (use [`min_degree_order`] to keep fill low), on the entries of
/// its symbolic factorization.
///
/// With `reg > 0` the matrix is positive definite, so no pivoting is
/// needed for stability. Each pivot is the squared distance of its row (in
/// the Gram sense) from the span of the rows before it, so the pivots not
/// exceeding `reg + tol` count the dependent rows (`n − rank`) in any
/// order. `scale` receives `S`. Only the entries of `pattern` (the
/// symbolic factorization, [`CholPattern`]) are read or written; every
/// other entry of the lower triangle must be zero.
pub fn ordered_cholesky<T: Scalar>(
    a: &mut [T],
    n: usize,
    scale: &mut Vec<T>,
    tols: (f64, f64),
    pattern: &CholPattern,
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
        for &j in &pattern.row_cols[i] {
            let v = &mut a[i * n + j];
            *v = *v * si * scale[j];
        }
        a[i * n + i] = a[i * n + i] * si * si + regt;
    }
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
        let rows = &pattern.col_rows[k];
        for &r in rows {
            a[r * n + k] *= inv;
        }
        for (ir, &r) in rows.iter().enumerate() {
            let lr = a[r * n + k];
            if lr.is_exact_zero() {
                continue;
            }
            for &c in &rows[..=ir] {
                let lc = a[c * n + k];
                a[r * n + c] -= lr * lc;
            }
        }
    }
    Factored { rank, accepted: n }
}

/// Solve `(Â + reg·I)(S⁻¹x) = S b` with the factor of [`ordered_cholesky`]
/// (`accepted` = [`Factored::accepted`], normally all rows): forward and
/// backward substitution with `L` over the entries of `pattern`, scaling
/// by `S` on both sides. `b` is overwritten by `x`; `tmp` is scratch.
pub fn cholesky_solve<T: Scalar>(
    l: &[T],
    (scale, pattern): (&[T], &CholPattern),
    accepted: usize,
    b: &mut [T],
    tmp: &mut Vec<T>,
) {
    let n = pattern.n;
    tmp.clear();
    tmp.extend((0..accepted).map(|k| b[k] * scale[k]));
    for k in 0..accepted {
        let mut s = tmp[k];
        for &j in &pattern.row_cols[k] {
            s -= l[k * n + j] * tmp[j];
        }
        tmp[k] = s / l[k * n + k];
    }
    for k in (0..accepted).rev() {
        let mut s = tmp[k];
        for &r in pattern.col_rows[k].iter().take_while(|&&r| r < accepted) {
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
    Matrix3::identity() + k * a + mm(&k, &k) * b
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
    let tmat = Matrix3::identity() + k * b + mm(&k, &k) * cc;
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
        let (mut scale, mut tmp) = (vec![], vec![]);
        let dense = CholPattern::dense(n);
        let f = ordered_cholesky(&mut a, n, &mut scale, (1e-8, 1e-12), &dense);
        assert_eq!((f.rank, f.accepted), (3, 4));
        cholesky_solve(&a, (&scale, &dense), n, &mut b, &mut tmp);
        for i in 0..n {
            let r: f64 = (0..n).map(|j| a0[i * n + j] * b[j]).sum::<f64>() - b0[i];
            assert!(r.abs() < 1e-9, "row {i} residual {r}");
        }
        // The same matrix on its symbolic factorization (all entries
        // are coupled here: the pattern is dense) gives the same factor.
        let edges: Vec<(usize, usize)> = (0..n).flat_map(|i| (0..i).map(move |j| (i, j))).collect();
        let sym = CholPattern::new(n, &edges);
        assert_eq!(sym.nnz(), dense.nnz());
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

    #[test]
    fn symbolic_pattern_has_the_fill_and_factors_like_the_dense_one() {
        // An arrow: row 0 coupled to every other row. Eliminated first it
        // fills the whole lower triangle (the classic worst order); last,
        // it fills nothing. Exact counts from the elimination graph.
        let n = 6;
        let arrow_first: Vec<(usize, usize)> = (1..n).map(|i| (i, 0)).collect();
        assert_eq!(CholPattern::new(n, &arrow_first).nnz(), n * (n - 1) / 2);
        let arrow_last: Vec<(usize, usize)> = (0..n - 1).map(|i| (n - 1, i)).collect();
        assert_eq!(CholPattern::new(n, &arrow_last).nnz(), n - 1);
        // A sparse SPD matrix (arrow last plus a band) factored and solved
        // on its pattern equals the dense-pattern factorization to the bit
        // (the skipped entries are exact zeros).
        let mut edges = arrow_last.clone();
        edges.extend((1..n - 1).map(|i| (i, i - 1)));
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            a[i * n + i] = 4.0 + i as f64;
        }
        for &(i, j) in &edges {
            a[i * n + j] = -0.5 - 0.1 * j as f64;
            a[j * n + i] = a[i * n + j];
        }
        let sparse = CholPattern::new(n, &edges);
        let dense = CholPattern::dense(n);
        let (mut a1, mut a2) = (a.clone(), a.clone());
        let (mut s1, mut s2, mut tmp) = (vec![], vec![], vec![]);
        let f1 = ordered_cholesky(&mut a1, n, &mut s1, (1e-8, 1e-12), &sparse);
        let f2 = ordered_cholesky(&mut a2, n, &mut s2, (1e-8, 1e-12), &dense);
        assert_eq!(f1, f2);
        for i in 0..n {
            for j in 0..=i {
                assert_eq!(a1[i * n + j], a2[i * n + j], "L[{i}][{j}]");
            }
        }
        let b: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let (mut x1, mut x2) = (b.clone(), b.clone());
        cholesky_solve(&a1, (&s1, &sparse), n, &mut x1, &mut tmp);
        cholesky_solve(&a2, (&s2, &dense), n, &mut x2, &mut tmp);
        assert_eq!(x1, x2);
        // And it solves the (regularised) system.
        for i in 0..n {
            let r: f64 = (0..n).map(|j| a[i * n + j] * x1[j]).sum::<f64>() - b[i];
            assert!(r.abs() < 1e-10, "row {i} residual {r}");
        }
    }

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
        use crate::mbs::dual::DualN;
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
