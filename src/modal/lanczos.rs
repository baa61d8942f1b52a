//! Block shift-invert Lanczos with full M-reorthogonalisation and thick
//! restart.
//!
//! Operator `Op = (K − σM)⁻¹ M`, self-adjoint in the M-inner product
//! `⟨x, y⟩ = Σ mᵢ xᵢ yᵢ`; its largest eigenvalues `θ = 1/(λ − σ)` belong to
//! the eigenvalues λ of `K x = λ M x` nearest above σ. The basis `V`
//! (`n × m`, `VᵀMV = I`) is built block by block; every new block `Op·Vⱼ`
//! is orthogonalised first against the last two blocks (the three-term
//! recurrence: all the coupling in exact arithmetic) and then against the
//! whole basis (full reorthogonalisation; "twice is enough", classical
//! Gram–Schmidt with GEMM kernels), and the summed coefficients are the
//! columns of the projected matrix `H = VᵀM·Op·V`. Rayleigh–Ritz on `H` gives Ritz pairs `(θ, V y)` whose
//! residual `‖Op V y − θ V y‖_M = ‖B y_last‖` (B: coupling to the next block)
//! is known without extra solves. When the basis is full, the wanted Ritz
//! vectors are kept and the iteration continues from the residual block
//! (thick restart; the Krylov relation is preserved).
//!
//! A block (default 3 vectors) rather than a single vector finds multiple
//! eigenvalues (symmetric panels, square grids) in exact arithmetic. The
//! start block is a fixed SplitMix64 hash of (DOF, column): deterministic to
//! the bit and generic enough not to be orthogonal to symmetric modes, which a
//! constant vector would be.

// Index loops mirror the formulas in these numeric kernels.
#![allow(clippy::needless_range_loop)]

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef, Par};
use nalgebra::{DMatrix, Dyn, SymmetricEigen};

use super::blocks::ShiftInvert;
use super::modes::ModalOptions;
use super::sparse::Pencil;
use crate::error::{Error, Result};

/// Result of the Lanczos iteration (before sign normalisation).
pub(crate) struct LanczosOut {
    /// Ascending eigenvalues, `want` of them.
    pub lambda: Vec<f64>,
    /// `n × want`, M-orthonormal.
    pub vectors: Mat<f64>,
    /// Number of block solves with `K − σM` (columns).
    pub solves: usize,
    /// Number of thick restarts.
    pub restarts: usize,
    /// Largest basis dimension used.
    pub basis: usize,
}

/// Deterministic start value in [−0.5, 0.5): SplitMix64 of (dof, column).
fn start_value(i: usize, c: usize) -> f64 {
    let mut z = (i as u64)
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add((c as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

/// `W ← Op W = (K − σM)⁻¹ M W`.
fn apply_op(factor: &mut ShiftInvert<'_>, mass: &[f64], mut w: MatMut<'_, f64>) {
    for c in 0..w.ncols() {
        let col = w
            .rb_mut()
            .col_mut(c)
            .try_as_col_major_mut()
            .expect("column-major")
            .as_slice_mut();
        col.iter_mut().zip(mass).for_each(|(x, &m)| *x *= m);
    }
    factor.solve_in_place(w);
}

/// Orthogonalise the columns of `w` against `v` (M-inner product):
/// a first pass against the columns `local..` (where, in exact arithmetic,
/// all the coupling of a Lanczos step lives: the last two blocks), then a
/// second, full pass ("twice is enough"). `local = 0` gives classical
/// Gram–Schmidt twice. Returns the summed coefficients `VᵀMW`
/// (`v.ncols() × w.ncols()`).
fn cgs2(v: MatRef<'_, f64>, mass: &[f64], mut w: MatMut<'_, f64>, local: usize) -> Mat<f64> {
    let (n, p) = (w.nrows(), w.ncols());
    let m = v.ncols();
    let mut total = Mat::<f64>::zeros(m, p);
    if m == 0 {
        return total;
    }
    let mut mw = Mat::<f64>::zeros(n, p);
    for from in [local.min(m), 0] {
        let vs = v.subcols(from, m - from);
        let mut c = Mat::<f64>::zeros(m - from, p);
        for j in 0..p {
            let src = col_slice(w.rb(), j);
            let dst = mw
                .col_mut(j)
                .try_as_col_major_mut()
                .expect("column-major")
                .as_slice_mut();
            for i in 0..n {
                dst[i] = mass[i] * src[i];
            }
        }
        matmul(
            c.as_mut(),
            Accum::Replace,
            vs.transpose(),
            mw.as_ref(),
            1.0,
            Par::Seq,
        );
        matmul(w.rb_mut(), Accum::Add, vs, c.as_ref(), -1.0, Par::Seq);
        for j in 0..p {
            for i in 0..m - from {
                total[(from + i, j)] += c[(i, j)];
            }
        }
    }
    total
}
/// Column `j` of a column-major matrix as a slice.
fn col_slice(m: MatRef<'_, f64>, j: usize) -> &[f64] {
    m.col(j)
        .try_as_col_major()
        .expect("faer matrices are column-major")
        .as_slice()
}

fn m_dot(mass: &[f64], a: &[f64], b: &[f64]) -> f64 {
    let mut s = 0.0;
    for i in 0..mass.len() {
        s += mass[i] * a[i] * b[i];
    }
    s
}

/// M-orthonormalise the columns of `w` among themselves (modified
/// Gram–Schmidt, twice) with deflation. Returns the accepted columns `Q` and
/// `B` (`q × p`) with `W = Q B`. A column whose norm drops below
/// `defl · ref_norm[c]` is deflated (it lies in the span already built).
fn block_qr(w: MatRef<'_, f64>, mass: &[f64], ref_norm: &[f64]) -> (Mat<f64>, Mat<f64>) {
    let (n, p) = (w.nrows(), w.ncols());
    let defl = 1e-10;
    let mut q: Vec<Vec<f64>> = Vec::new();
    let mut b = Mat::<f64>::zeros(p, p);
    for c in 0..p {
        let mut x: Vec<f64> = col_slice(w, c).to_vec();
        for _ in 0..2 {
            for (r, qr) in q.iter().enumerate() {
                let h = m_dot(mass, qr, &x);
                b[(r, c)] += h;
                x.iter_mut().zip(qr).for_each(|(a, &b)| *a -= h * b);
            }
        }
        let nrm = m_dot(mass, &x, &x).sqrt();
        if nrm > defl * ref_norm[c] && nrm > 0.0 {
            let r = q.len();
            b[(r, c)] = nrm;
            x.iter_mut().for_each(|v| *v /= nrm);
            q.push(x);
        }
    }
    let qn = q.len();
    let mut qm = Mat::<f64>::zeros(n, qn);
    for (j, qj) in q.iter().enumerate() {
        qm.col_mut(j)
            .try_as_col_major_mut()
            .expect("contiguous")
            .as_slice_mut()
            .copy_from_slice(qj);
    }
    let bm = Mat::<f64>::from_fn(qn, p, |i, j| b[(i, j)]);
    (qm, bm)
}

/// Fresh deterministic vectors M-orthogonal to `v`, for a start block or
/// after an invariant subspace was found. `salt` varies the sequence.
fn fresh_block(
    v: MatRef<'_, f64>,
    mass: &[f64],
    p: usize,
    salt: usize,
    factor: &mut ShiftInvert<'_>,
    solves: &mut usize,
) -> Mat<f64> {
    let n = mass.len();
    let mut x = Mat::<f64>::from_fn(n, p, |i, c| start_value(i, c + salt));
    // One application of Op damps the components of high modes.
    apply_op(factor, mass, x.as_mut());
    *solves += p;
    cgs2(v, mass, x.as_mut(), 0);
    let norms: Vec<f64> = (0..p)
        .map(|c| {
            let col = col_slice(x.as_ref(), c);
            m_dot(mass, col, col).sqrt()
        })
        .collect();
    // After orthogonalisation the reference is the column's own norm before
    // it; use the largest as a floor so that numerically dependent columns
    // are deflated.
    let r = norms
        .iter()
        .cloned()
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    block_qr(x.as_ref(), mass, &vec![r; p]).0
}

/// Lowest `want` eigenpairs of `K x = λ M x` above the shift.
pub(crate) fn block_lanczos(
    pencil: &Pencil,
    factor: &mut ShiftInvert<'_>,
    opts: &ModalOptions,
    want: usize,
) -> Result<LanczosOut> {
    let mut run = Lanczos::new(pencil, factor, opts, want);
    let mut q = run.fresh_block();
    loop {
        let (step, mut q_next) = run.extend(&q)?;
        // Rayleigh–Ritz (a dense eigen-decomposition of H, the dominant
        // cost per step after the solves) only from twice the wanted count:
        // at tol 1e-10 the wanted pairs converge well after that (the SAR
        // panel at dimension ~3k), so earlier checks would only cost time.
        let exhausted = run.dim == run.n;
        let check_from = 2 * want;
        let next = q_next.ncols();
        if run.dim < check_from && !exhausted && next > 0 && run.dim + next <= run.m_max {
            q = q_next;
            run.local = step.start;
            continue;
        }
        let ritz = run.rayleigh_ritz();
        let need = want.min(run.dim);
        let converged = run.dim >= want
            && ritz.order[..need].iter().all(|&c| {
                let th = ritz.eig.eigenvalues[c];
                th > 0.0 && ritz.residual(&step, c) <= opts.tol * th
            });
        if converged || exhausted {
            return run.finish(&ritz);
        }
        if q_next.ncols() == 0 {
            // Invariant subspace: continue with fresh directions.
            run.salt += run.p;
            q_next = run.fresh_block();
        }
        if run.dim + q_next.ncols() > run.m_max {
            run.restart(&ritz, &step, q_next.ncols())?;
        }
        q = q_next;
    }
}

/// One Lanczos run: the basis `V` (`n × dim` in use), the projected matrix
/// `H` and the counts reported in [`LanczosOut`].
struct Lanczos<'a, 'f, 'p> {
    mass: &'a [f64],
    factor: &'f mut ShiftInvert<'p>,
    opts: &'a ModalOptions,
    want: usize,
    n: usize,
    /// Block size.
    p: usize,
    /// Largest basis dimension; beyond it the basis restarts.
    m_max: usize,
    v: Mat<f64>,
    h: Mat<f64>,
    dim: usize,
    solves: usize,
    restarts: usize,
    basis: usize,
    /// Offset of the start-value sequence of the next fresh block.
    salt: usize,
    /// First basis column of the previous block: the first CGS pass runs
    /// against `local..dim` only (full after a restart or fresh block).
    local: usize,
}

/// The block a step added to the basis and its coupling to the next.
struct Step {
    /// Its first column in the basis.
    start: usize,
    /// Its width.
    pb: usize,
    /// The coupling `B` to the next block (`next × pb`).
    b: Mat<f64>,
}

/// Rayleigh–Ritz on `H`: its eigen-decomposition and the order of its
/// eigenvalues, largest θ first (ties by index keep the result
/// deterministic).
struct Ritz {
    eig: SymmetricEigen<f64, Dyn>,
    order: Vec<usize>,
}

impl Ritz {
    /// The residual `‖B y_last‖` of the Ritz pair of column `col`, with
    /// `y_last` its entries on the last block.
    fn residual(&self, step: &Step, col: usize) -> f64 {
        let b = &step.b;
        let mut s = 0.0;
        for r in 0..b.nrows() {
            let mut t = 0.0;
            for c in 0..step.pb {
                t += b[(r, c)] * self.eig.eigenvectors[(step.start + c, col)];
            }
            s += t * t;
        }
        s.sqrt()
    }

    /// The Ritz vectors `V y` of the `count` largest θ.
    fn vectors(&self, v: MatRef<'_, f64>, count: usize) -> Mat<f64> {
        let dim = v.ncols();
        let y = Mat::<f64>::from_fn(dim, count, |i, j| self.eig.eigenvectors[(i, self.order[j])]);
        let mut out = Mat::<f64>::zeros(v.nrows(), count);
        matmul(out.as_mut(), Accum::Replace, v, y.as_ref(), 1.0, Par::Seq);
        out
    }
}

impl<'a, 'f, 'p> Lanczos<'a, 'f, 'p> {
    fn new(
        pencil: &'a Pencil,
        factor: &'f mut ShiftInvert<'p>,
        opts: &'a ModalOptions,
        want: usize,
    ) -> Self {
        let n = pencil.n();
        let p = opts.block_size.clamp(1, n);
        let m_max = opts
            .max_basis
            .unwrap_or(3 * want + 4 * p + 8)
            .max(want + 2 * p)
            .min(n);
        let cap = m_max + p;
        Lanczos {
            mass: pencil.mass(),
            factor,
            opts,
            want,
            n,
            p,
            m_max,
            v: Mat::<f64>::zeros(n, cap),
            h: Mat::<f64>::zeros(cap, cap),
            dim: 0,
            solves: 0,
            restarts: 0,
            basis: 0,
            salt: 0,
            local: 0,
        }
    }

    /// A fresh block M-orthogonal to the basis ([`fresh_block`]).
    fn fresh_block(&mut self) -> Mat<f64> {
        fresh_block(
            self.v.as_ref().subcols(0, self.dim),
            self.mass,
            self.p,
            self.salt,
            self.factor,
            &mut self.solves,
        )
    }

    /// Place the block `q` in the basis, apply the operator to it and
    /// orthogonalise the result (its coefficients are the block's columns
    /// of `H`); returns the step and the next block.
    fn extend(&mut self, q: &Mat<f64>) -> Result<(Step, Mat<f64>)> {
        let (n, mass) = (self.n, self.mass);
        let pb = q.ncols();
        if pb == 0 {
            return Err(Error::numerical(
                "modal::lanczos",
                format!(
                    "no new direction found at basis dimension {} of {n}",
                    self.dim
                ),
            ));
        }
        let start = self.dim;
        self.v.as_mut().subcols_mut(start, pb).copy_from(q.as_ref());
        self.dim += pb;
        self.basis = self.basis.max(self.dim);
        let mut w = q.clone();
        apply_op(self.factor, mass, w.as_mut());
        self.solves += pb;
        let ref_norm: Vec<f64> = (0..pb)
            .map(|c| {
                let col = col_slice(w.as_ref(), c);
                m_dot(mass, col, col).sqrt()
            })
            .collect();
        let coef = cgs2(
            self.v.as_ref().subcols(0, self.dim),
            mass,
            w.as_mut(),
            self.local,
        );
        for j in 0..pb {
            for i in 0..self.dim {
                self.h[(i, start + j)] = coef[(i, j)];
            }
        }
        let (q_next, b) = block_qr(w.as_ref(), mass, &ref_norm);
        Ok((Step { start, pb, b }, q_next))
    }

    /// Rayleigh–Ritz on the symmetric part of `H` (its upper triangle is
    /// computed).
    fn rayleigh_ritz(&self) -> Ritz {
        let (dim, h) = (self.dim, &self.h);
        let hs =
            DMatrix::<f64>::from_fn(dim, dim, |i, j| if i <= j { h[(i, j)] } else { h[(j, i)] });
        let eig = SymmetricEigen::new(hs);
        let mut order: Vec<usize> = (0..dim).collect();
        order.sort_by(|&a, &c| {
            eig.eigenvalues[c]
                .total_cmp(&eig.eigenvalues[a])
                .then(a.cmp(&c))
        });
        Ritz { eig, order }
    }

    /// The wanted eigenpairs `λ = σ + 1/θ` from the converged (or
    /// exhausted) basis.
    fn finish(&self, ritz: &Ritz) -> Result<LanczosOut> {
        let (dim, want, opts) = (self.dim, self.want, self.opts);
        if dim < want {
            return Err(Error::numerical(
                "modal::lanczos",
                format!("basis exhausted at dimension {dim} < {want} wanted modes"),
            ));
        }
        let vectors = ritz.vectors(self.v.as_ref().subcols(0, dim), want);
        let mut lambda = Vec::with_capacity(want);
        for &c in &ritz.order[..want] {
            let th = ritz.eig.eigenvalues[c];
            if th <= 0.0 || !th.is_finite() {
                return Err(Error::numerical(
                    "modal::lanczos",
                    format!(
                        "Ritz value theta = {th:e} of (K - sigma M)^-1 M is not positive \
                         (shift sigma = {:e})",
                        opts.shift
                    ),
                ));
            }
            lambda.push(opts.shift + 1.0 / th);
        }
        Ok(LanczosOut {
            lambda,
            vectors,
            solves: self.solves,
            restarts: self.restarts,
            basis: self.basis,
        })
    }

    /// Thick restart before a block of `incoming` columns: keep the wanted
    /// Ritz vectors plus a block of the next ones, with `H` their diagonal
    /// of θ. An error after `max_restarts`.
    fn restart(&mut self, ritz: &Ritz, step: &Step, incoming: usize) -> Result<()> {
        let (dim, want, p, m_max) = (self.dim, self.want, self.p, self.m_max);
        self.restarts += 1;
        if self.restarts > self.opts.max_restarts {
            let need = want.min(dim);
            let worst = ritz.order[..need]
                .iter()
                .map(|&c| ritz.residual(step, c) / ritz.eig.eigenvalues[c].abs())
                .fold(0.0, f64::max);
            return Err(Error::numerical(
                "modal::lanczos",
                format!(
                    "no convergence after {} restarts (basis {m_max}, block {p}): worst \
                     relative Ritz residual {worst:e} > tol {:e}",
                    self.opts.max_restarts, self.opts.tol
                ),
            ));
        }
        let keep = (want + p).min(dim).min(m_max - incoming);
        let kept = ritz.vectors(self.v.as_ref().subcols(0, dim), keep);
        self.v
            .as_mut()
            .subcols_mut(0, keep)
            .copy_from(kept.as_ref());
        self.h.fill(0.0);
        for (j, &c) in ritz.order[..keep].iter().enumerate() {
            self.h[(j, j)] = ritz.eig.eigenvalues[c];
        }
        self.dim = keep;
        self.local = 0;
        Ok(())
    }
}
