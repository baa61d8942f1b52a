//! The per-evaluation linear algebra of [`System`]: the constraint-space
//! solve for the multipliers and accelerations, body by body (the method
//! is in [`crate::mbs::dynamics`]), in real arithmetic, and its tangent for
//! the lanes of a dual-number evaluation.
//!
//! # Tangent
//! The solve gives `v̇ = M⁻¹(Q + Gᵀλ)` with `(A + εD) λ = γ − G M⁻¹ Q`,
//! `A = G M⁻¹ Gᵀ`, `D = diag(A)` and `ε` = [`RANK_REG`] (the regularised
//! system that [`crate::mbs::math::ordered_cholesky`] factors). A dual
//! evaluation carries, per lane, the derivatives `G'`, `M'`, `Q'`, `γ'`
//! of the assembled quantities. Differentiating `M v̇ = Q + Gᵀλ` and the
//! equation for λ gives, with `r₁ = Q' − M' v̇ + G'ᵀλ` and
//! `r₂ = γ' − G' v̇`,
//!
//! ```text
//!   (A + εD) λ' = r₂ − G M⁻¹ r₁ − ε D' λ,     v̇' = M⁻¹ (r₁ + Gᵀ λ'),
//! ```
//!
//! `D'_ii = Σ_b (2 d'_i·w_i − w_iᵀ M'_b w_i)` (`w_i = M_b⁻¹ d_i`). Every
//! solve reuses the real factorizations (the constraint-space Cholesky and
//! each body's inverse mass), and no derivative of `A` is ever formed: a
//! lane costs one product with each `M'_b`, `M_b⁻¹` and the rows, and one
//! constraint-space solve.

use super::prestress::{PRESTRESS_ITERATIONS, PRESTRESS_STALL, PRESTRESS_TOL};
use crate::mbs::math::Factored;
use crate::mbs::math::{
    fdot, gram, min_degree_order, spd_factor, spd_solve, spd_solve_many, sym_times, CholPattern,
    Scalar, MAX_LANES,
};
use crate::mbs::model::Param;
use crate::mbs::system::{
    bump, pval, BodyBlock, SolveScratch, System, Workspace, RANK_REG, RANK_TOL, RIGID,
};

impl System {
    /// `M⁻¹ x` of slot `s` in real arithmetic (into `out`): a flexible
    /// body by its inverse mass, a rigid one by `diag(1/m, J'⁻¹)`.
    fn minv_times(&self, bb: &BodyBlock, s: usize, x: &[f64], out: &mut [f64]) {
        if self.modes[s] > 0 {
            sym_times(&bb.minv, self.dof(s), x, out);
            return;
        }
        let ji = &self.model.bodies[self.moving[s]].inv_inertia;
        for c in 0..3 {
            out[c] = x[c] * bb.inv_mass;
            out[3 + c] = ji[(c, 0)] * x[3] + ji[(c, 1)] * x[4] + ji[(c, 2)] * x[5];
        }
    }

    /// Gather every body's block (real parts and lanes): the rows touching
    /// it (`d`: the row's `[∂/∂ṙ, ∂/∂ω', ∂/∂ẇ]` entries of that body) and,
    /// last, its applied force `Q`; then, in real arithmetic, `w = M⁻¹d`,
    /// `M⁻¹Q` and the Gram block `d_i·M⁻¹d_j` of each body.
    fn body_blocks<T: Scalar>(&self, ws: &mut Workspace<T>) {
        let nb = self.nb();
        let nl = T::NL;
        let mut blocks = std::mem::take(&mut ws.blocks);
        blocks.resize_with(nb, BodyBlock::default);
        let mut vecs = std::mem::take(&mut ws.gather);
        vecs.resize_with(nb, Vec::new);
        for (bb, v) in blocks.iter_mut().zip(vecs.iter_mut()) {
            bb.rows.clear();
            v.clear();
        }
        for (r, row) in ws.rows.iter().enumerate() {
            for (side, (slot, blk)) in row.blocks.iter().enumerate() {
                let Some(s) = *slot else { continue };
                let d = self.dof(s);
                let v = &mut vecs[s];
                v.extend_from_slice(blk);
                if d > 6 {
                    let mo = row.modal[side];
                    if mo == RIGID {
                        v.extend(std::iter::repeat_n(T::zero(), d - 6));
                    } else {
                        v.extend_from_slice(&ws.mjac[mo..mo + d - 6]);
                    }
                }
                blocks[s].rows.push(r);
            }
        }
        for (s, (bb, v)) in blocks.iter_mut().zip(vecs.iter_mut()).enumerate() {
            let (o, d) = (self.vel_local(s), self.dof(s));
            v.extend_from_slice(&ws.q[o..o + d]);
            bb.b.clear();
            bb.b.extend(v.iter().map(T::re_part));
            // Lane-major (`lanes[l·len + i]`), filled in one pass over v.
            let len = v.len();
            bb.lanes.clear();
            bb.lanes.resize(nl * len, 0.0);
            for (i, x) in v.iter().enumerate() {
                for l in 0..nl {
                    bb.lanes[l * len + i] = x.lane_part(l);
                }
            }
            if self.modes[s] > 0 {
                bb.minv.clear();
                bb.minv.extend(ws.mfac[s].iter().map(T::re_part));
            } else {
                let b = self.moving[s];
                let mass = pval(&ws.params, Param::Mass(b), self.model.bodies[b].mass);
                bb.inv_mass = 1.0 / mass.re_part();
            }
            let mut w = std::mem::take(&mut bb.w);
            w.clear();
            w.resize(bb.b.len(), 0.0);
            for (x, out) in bb.b.chunks_exact(d).zip(w.chunks_exact_mut(d)) {
                self.minv_times(bb, s, x, out);
            }
            gram(&bb.b, &w, d, &mut bb.g);
            bb.w = w;
        }
        ws.blocks = blocks;
        ws.gather = vecs;
    }

    /// The fill-reducing order of the constraint-space matrix and its
    /// symbolic factorization, once per workspace (the rows touching each
    /// body never change).
    fn order<T: Scalar>(&self, ws: &mut Workspace<T>) {
        let m = ws.rows.len();
        if ws.inv_order.len() == m {
            return;
        }
        let mut edges = Vec::new();
        for bb in &ws.blocks {
            for (x, r) in bb.rows.iter().enumerate() {
                for c in &bb.rows[..x] {
                    edges.push((*r, *c));
                }
            }
        }
        let order = min_degree_order(m, &edges);
        ws.inv_order = vec![0; m];
        for (k, &r) in order.iter().enumerate() {
            ws.inv_order[r] = k;
        }
        let inv = &ws.inv_order;
        let permuted: Vec<(usize, usize)> = edges.iter().map(|&(r, c)| (inv[r], inv[c])).collect();
        ws.spd.set_pattern(CholPattern::new(m, &permuted));
    }

    /// Solve for the multipliers and accelerations with the rows, applied
    /// forces and mass factors in `ws`. Returns `v̇` (velocity layout);
    /// `ws.rhs` = λ. Real arithmetic throughout; a dual evaluation adds
    /// the lanes of the tangent (module doc).
    ///
    /// Structure: `G M⁻¹ Gᵀ = Σ_bodies G_b M_b⁻¹ G_bᵀ`, each body's term a
    /// Gram block of the few rows that touch it ([`System::body_blocks`]);
    /// the matrix is scattered into a fill-reducing order, whose symbolic
    /// factorization ([`CholPattern`]) is computed once per workspace, and
    /// factored on that pattern by the rank-counting Cholesky of
    /// [`crate::mbs::math::sparse`].
    pub(crate) fn solve<T: Scalar>(&self, ws: &mut Workspace<T>) -> Vec<T> {
        let m = ws.rows.len();
        self.body_blocks(ws);
        self.order(ws);
        let mut sol = std::mem::take(&mut ws.sol);
        // λ's right-hand side γ − G M⁻¹ Q: the force is each block's last
        // vector, so d_i·M⁻¹Q is the block's last Gram row.
        sol.rhs.clear();
        sol.rhs
            .extend(ws.rows.iter().map(|row| row.gamma.re_part()));
        for bb in &ws.blocks {
            let k = bb.rows.len() + 1;
            for (i, &r) in bb.rows.iter().enumerate() {
                sol.rhs[r] -= bb.g[(k - 1) * k + i];
            }
        }
        let inv = &ws.inv_order;
        ws.a.clear();
        ws.a.resize(m * m, 0.0);
        for bb in &ws.blocks {
            let k = bb.rows.len() + 1;
            for (x, r) in bb.rows.iter().enumerate() {
                for (c, q) in bb.rows[..=x].iter().enumerate() {
                    let (pr, pc) = (inv[*r], inv[*q]);
                    let (hi, lo) = if pr >= pc { (pr, pc) } else { (pc, pr) };
                    ws.a[hi * m + lo] += bb.g[x * k + c];
                }
            }
        }
        sol.dropped.clear();
        match &ws.drop {
            Some(d) => sol
                .dropped
                .extend((0..m).map(|r| d.get(r).copied().unwrap_or(false))),
            None => sol.dropped.extend((0..m).map(|r| self.dropped(r))),
        }
        let mut ndrop = 0;
        for (r, _) in sol.dropped.iter().enumerate().filter(|(_, d)| **d) {
            ndrop += 1;
            let p = inv[r];
            for c in 0..p {
                ws.a[p * m + c] = 0.0;
            }
            for q in p + 1..m {
                ws.a[q * m + p] = 0.0;
            }
            ws.a[p * m + p] = 1.0;
            sol.rhs[r] = 0.0;
        }
        let f = spd_factor(
            &mut ws.a,
            m,
            &mut ws.scale,
            (RANK_TOL, RANK_REG),
            &mut ws.spd,
        );
        ws.rank = f.rank - ndrop;
        let rhs = std::mem::take(&mut sol.rhs);
        Self::solve_factored(ws, f, &rhs, &mut sol.lam);
        // The joint-load prestress (`super::prestress`): λ by the
        // fixed-point iteration on the same factor, `bz = Bλ`.
        let prestress = self.prestress_columns(ws);
        if prestress {
            let (mut lam, mut z) = (std::mem::take(&mut sol.lam), std::mem::take(&mut sol.bz));
            let (mut r, mut next) = (std::mem::take(&mut sol.prhs), std::mem::take(&mut sol.plam));
            let dropped = std::mem::take(&mut sol.dropped);
            let ok = self.prestress_iterate(
                ws,
                f,
                (&rhs, &dropped),
                &mut lam,
                (&mut z, &mut r, &mut next),
            );
            if !ok {
                // Non-finite accelerations end the run; the time and the
                // bodies go into its error (System::rhs, simulate).
                self.note_prestress_failure(ws, &lam, &next);
                lam.fill(f64::NAN);
            }
            (sol.lam, sol.bz, sol.prhs, sol.plam, sol.dropped) = (lam, z, r, next, dropped);
        }
        sol.rhs = rhs;
        // v̇ = M⁻¹Q + Σ_rows (M⁻¹d) λ.
        sol.acc.clear();
        sol.acc.resize(self.nvel(), 0.0);
        for (s, bb) in ws.blocks.iter().enumerate() {
            let (o, d) = (self.vel_local(s), self.dof(s));
            let k = bb.rows.len();
            let out = &mut sol.acc[o..o + d];
            out.copy_from_slice(&bb.w[k * d..(k + 1) * d]);
            for (i, r) in bb.rows.iter().enumerate() {
                let lam = sol.lam[*r];
                for (a, w) in out.iter_mut().zip(&bb.w[i * d..(i + 1) * d]) {
                    *a += w * lam;
                }
            }
            // − M⁻¹ B λ of the joint-load prestress.
            if prestress && d > 6 {
                sol.tmp.resize(d, 0.0);
                self.minv_times(bb, s, &sol.bz[o..o + d], &mut sol.tmp);
                for (a, t) in sol.acc[o..o + d].iter_mut().zip(&sol.tmp) {
                    *a -= t;
                }
            }
        }
        if T::NL > 0 {
            self.tangent(ws, &mut sol, f);
        }
        let mut buf = [0.0; MAX_LANES];
        let lanes = &mut buf[..T::NL];
        let mut parts = |re: f64, d: &[f64], i: usize, n: usize| {
            for (l, v) in lanes.iter_mut().enumerate() {
                *v = d[l * n + i];
            }
            T::from_parts(re, lanes)
        };
        let nv = self.nvel();
        let acc: Vec<T> = (0..nv)
            .map(|i| parts(sol.acc[i], &sol.dacc, i, nv))
            .collect();
        ws.rhs.clear();
        ws.rhs
            .extend((0..m).map(|r| parts(sol.lam[r], &sol.dlam, r, m)));
        ws.sol = sol;
        acc
    }

    /// The fixed-point iteration of the joint-load prestress
    /// (`super::prestress`): `λ ← (A + εD)⁻¹(base + G M⁻¹ B λ)` from the
    /// `λ` given until its change is at rounding; `z` holds `B λ` of the
    /// returned λ. False if it does not converge in
    /// [`PRESTRESS_ITERATIONS`] back-substitutions.
    fn prestress_iterate<T: Scalar>(
        &self,
        ws: &mut Workspace<T>,
        f: Factored,
        (base, dropped): (&[f64], &[bool]),
        lam: &mut Vec<f64>,
        (z, rhs, next): (&mut Vec<f64>, &mut Vec<f64>, &mut Vec<f64>),
    ) -> bool {
        let mut last = f64::INFINITY;
        for _ in 0..PRESTRESS_ITERATIONS {
            self.prestress_force(ws, lam, None, z);
            self.prestress_rhs(ws, (base, dropped), z, rhs);
            Self::solve_factored(ws, f, rhs, next);
            bump(&self.counters.prestress_iterations);
            let (mut change, mut size) = (0.0f64, 0.0f64);
            for (a, b) in next.iter().zip(lam.iter()) {
                change = change.max((a - b).abs());
                size = size.max(a.abs());
            }
            std::mem::swap(lam, next);
            if !change.is_finite() {
                return false;
            }
            // Converged, or stalled at rounding: the change stopped
            // shrinking once it was below PRESTRESS_STALL · |λ|.
            if change <= PRESTRESS_TOL * size
                || (change <= PRESTRESS_STALL * size && change >= last)
            {
                self.prestress_force(ws, lam, None, z);
                return true;
            }
            last = change;
        }
        false
    }

    /// `out = (A + εD)⁻¹ b` with the factor `f` in `ws.a` (rows in the
    /// system's order; the fill-reducing permutation applied and undone).
    fn solve_factored<T: Scalar>(
        ws: &mut Workspace<T>,
        f: Factored,
        b: &[f64],
        out: &mut Vec<f64>,
    ) {
        let m = b.len();
        out.clear();
        out.resize(m, 0.0);
        for (r, v) in b.iter().enumerate() {
            out[ws.inv_order[r]] = *v;
        }
        spd_solve(&ws.a, m, &ws.scale, f, out, &mut ws.spd);
        let mut permuted = std::mem::take(&mut ws.perm);
        permuted.clone_from(out);
        for (r, o) in out.iter_mut().enumerate() {
            *o = permuted[ws.inv_order[r]];
        }
        ws.perm = permuted;
    }

    /// The lanes of λ' and v̇' (module doc) into `sol.dlam` and
    /// `sol.dacc`, from the real solution in `sol` and the lanes of the
    /// rows, forces and masses in `ws`, with the real constraint-space
    /// factor `f`.
    ///
    /// All lanes in one pass: each flexible body's dual mass matrix is
    /// read once for every lane's `M'v̇` and `w_iᵀM'w_i`
    /// ([`mass_lane_terms`]), and the lanes' right-hand sides for λ' are
    /// the columns of one multi-column solve with the shared factor
    /// ([`spd_solve_many`]). Each lane gets the operations, in the order,
    /// of a lane-by-lane tangent, so the results do not depend on how many
    /// lanes ride together. Lane-interleaved buffers (`x[i * nl + l]`):
    /// the right-hand sides, `D'` and λ'; lane-major (`x[l * d + i]`): a
    /// body's `r₁` and `u`, and `sol.dlam`, `sol.dacc`.
    fn tangent<T: Scalar>(&self, ws: &mut Workspace<T>, sol: &mut SolveScratch, f: Factored) {
        let (m, nv, nl) = (ws.rows.len(), self.nvel(), T::NL);
        sol.dacc.clear();
        sol.dacc.resize(nl * nv, 0.0);
        let take = std::mem::take::<Vec<f64>>;
        let (mut rhs, mut dd) = (take(&mut sol.lane_rhs), take(&mut sol.dd));
        let (mut dlam, mut mp) = (take(&mut sol.lane_lam), take(&mut sol.mp));
        rhs.clear();
        dd.clear();
        dd.resize(m * nl, 0.0);
        // r₂ = γ' − G'v̇ starts as γ'.
        for row in &ws.rows {
            rhs.extend((0..nl).map(|l| row.gamma.lane_part(l)));
        }
        // B'λ of the joint-load prestress, lane-major (`nl × nvel`).
        let prestress = !ws.pcols.is_empty();
        let mut bl = take(&mut sol.bz);
        bl.clear();
        if prestress {
            let mut one = Vec::new();
            for l in 0..nl {
                self.prestress_force(ws, &sol.lam, Some(l), &mut one);
                bl.extend_from_slice(&one);
            }
        }
        let mut dm = [0.0; MAX_LANES];
        for (s, bb) in ws.blocks.iter().enumerate() {
            let (o, d) = (self.vel_local(s), self.dof(s));
            let k = bb.rows.len();
            let a = &sol.acc[o..o + d];
            let stride = (k + 1) * d;
            // r₁ starts as Q' − M'v̇ (a rigid body's M' is diag(m'I, 0)).
            sol.r1.clear();
            for l in 0..nl {
                let q = &bb.lanes[l * stride + k * d..(l + 1) * stride];
                sol.r1.extend_from_slice(q);
            }
            if d > 6 {
                mass_lane_terms(&ws.mfac[s], a, &bb.w[..k * d], d, (&mut mp, &mut sol.quad));
                for l in 0..nl {
                    let r1 = &mut sol.r1[l * d..(l + 1) * d];
                    for (i, x) in r1.iter_mut().enumerate() {
                        *x -= mp[i * nl + l];
                    }
                    if prestress {
                        let b = &bl[l * nv + o + 6..l * nv + o + d];
                        for (x, b) in r1[6..].iter_mut().zip(b) {
                            *x -= b;
                        }
                    }
                }
            } else {
                let b = self.moving[s];
                let mass = pval(&ws.params, Param::Mass(b), self.model.bodies[b].mass);
                for (l, v) in dm[..nl].iter_mut().enumerate() {
                    *v = mass.lane_part(l);
                }
                for (r1, dm) in sol.r1.chunks_exact_mut(d).zip(&dm[..nl]) {
                    for (x, v) in r1[..3].iter_mut().zip(&a[..3]) {
                        *x -= dm * v;
                    }
                }
            }
            for (i, &r) in bb.rows.iter().enumerate() {
                let wi = &bb.w[i * d..(i + 1) * d];
                for l in 0..nl {
                    let di = &bb.lanes[l * stride + i * d..l * stride + (i + 1) * d];
                    rhs[r * nl + l] -= fdot(di, a);
                    let lam = sol.lam[r];
                    for (x, y) in sol.r1[l * d..(l + 1) * d].iter_mut().zip(di) {
                        *x += y * lam;
                    }
                    // D'_rr: 2 d'·w − wᵀM'w of this side.
                    let quad = if d > 6 {
                        sol.quad[i * nl + l]
                    } else {
                        dm[l] * (wi[0] * wi[0] + wi[1] * wi[1] + wi[2] * wi[2])
                    };
                    dd[r * nl + l] += 2.0 * fdot(di, wi) - quad;
                }
            }
            // u = M⁻¹r₁ (straight into v̇'), and the right-hand side − G u.
            for l in 0..nl {
                let r1 = &sol.r1[l * d..(l + 1) * d];
                let u = &mut sol.dacc[l * nv + o..l * nv + o + d];
                self.minv_times(bb, s, r1, u);
                for (i, &r) in bb.rows.iter().enumerate() {
                    rhs[r * nl + l] -= fdot(&bb.w[i * d..(i + 1) * d], r1);
                }
            }
        }
        for r in 0..m {
            for l in 0..nl {
                let x = r * nl + l;
                if sol.dropped[r] {
                    rhs[x] = 0.0;
                } else {
                    rhs[x] -= RANK_REG * dd[x] * sol.lam[r];
                }
            }
        }
        // λ' of every lane from one multi-column solve (the fill-reducing
        // permutation applied and undone, as in solve_factored).
        dlam.clear();
        dlam.resize(m * nl, 0.0);
        for (r, &p) in ws.inv_order.iter().enumerate() {
            dlam[p * nl..(p + 1) * nl].copy_from_slice(&rhs[r * nl..(r + 1) * nl]);
        }
        spd_solve_many(&ws.a, m, &ws.scale, f, nl, &mut dlam, &mut ws.spd);
        sol.dlam.clear();
        sol.dlam.resize(nl * m, 0.0);
        for (r, &p) in ws.inv_order.iter().enumerate() {
            for l in 0..nl {
                sol.dlam[l * m + r] = dlam[p * nl + l];
            }
        }
        if prestress {
            // λ' by the same iteration, lane by lane; then v̇' −= M⁻¹ B λ'.
            let (mut z, mut r) = (take(&mut sol.prhs), take(&mut sol.plam));
            let mut next = take(&mut sol.tmp);
            let (mut lane_rhs, mut lane_lam) = (Vec::with_capacity(m), Vec::with_capacity(m));
            for l in 0..nl {
                lane_rhs.clear();
                lane_rhs.extend((0..m).map(|x| rhs[x * nl + l]));
                lane_lam.clear();
                lane_lam.extend_from_slice(&sol.dlam[l * m..(l + 1) * m]);
                let ok = self.prestress_iterate(
                    ws,
                    f,
                    (&lane_rhs, &sol.dropped),
                    &mut lane_lam,
                    (&mut z, &mut r, &mut next),
                );
                if !ok {
                    lane_lam.fill(f64::NAN);
                }
                for (s, bb) in ws.blocks.iter().enumerate() {
                    let (o, d) = (self.vel_local(s), self.dof(s));
                    if d > 6 {
                        next.resize(d, 0.0);
                        self.minv_times(bb, s, &z[o..o + d], &mut next);
                        for (x, t) in sol.dacc[l * nv + o..l * nv + o + d].iter_mut().zip(&next) {
                            *x -= t;
                        }
                    }
                }
                sol.dlam[l * m..(l + 1) * m].copy_from_slice(&lane_lam);
            }
            (sol.prhs, sol.plam, sol.tmp) = (z, r, next);
        }
        // v̇' = u + Σ_rows w λ'.
        for l in 0..nl {
            let lam = &sol.dlam[l * m..(l + 1) * m];
            for (s, bb) in ws.blocks.iter().enumerate() {
                let (o, d) = (self.vel_local(s), self.dof(s));
                let out = &mut sol.dacc[l * nv + o..l * nv + o + d];
                for (i, r) in bb.rows.iter().enumerate() {
                    let lr = lam[*r];
                    for (x, w) in out.iter_mut().zip(&bb.w[i * d..(i + 1) * d]) {
                        *x += w * lr;
                    }
                }
            }
        }
        (sol.lane_rhs, sol.dd, sol.lane_lam, sol.mp) = (rhs, dd, dlam, mp);
        sol.bz = bl;
    }
}

/// Every lane's `M'_l v` and `w_iᵀ M'_l w_i` from one pass over a
/// flexible body's dual mass matrix `s` (row-major `d × d`, symmetric;
/// the lanes of each entry are `M'`, [`Scalar::dense_factor`]) for the
/// `k` rows `w_i` of `w` (row-major `k × d`). Outputs lane-interleaved:
/// `mv[i * nl + l]`, `q[i * nl + l]`.
///
/// The operations per lane are those of [`sym_times`] (`M'v`, zero
/// entries of `v` skipped) and of [`quad_forms`] (`Y = M' Wᵀ` by fused
/// multiply-adds in the order of the inner index, then one [`fdot`] per
/// row), so every lane's numbers are those of the lane-by-lane products.
fn mass_lane_terms<T: Scalar>(
    s: &[T],
    v: &[f64],
    w: &[f64],
    d: usize,
    (mv, q): (&mut Vec<f64>, &mut Vec<f64>),
) {
    let nl = T::NL;
    let k = w.len() / d;
    mv.clear();
    mv.resize(d * nl, 0.0);
    for (j, &vj) in v.iter().enumerate() {
        if vj != 0.0 {
            for (i, e) in s[j * d..(j + 1) * d].iter().enumerate() {
                for (l, o) in mv[i * nl..(i + 1) * nl].iter_mut().enumerate() {
                    *o += vj * e.lane_part(l);
                }
            }
        }
    }
    q.clear();
    q.resize(k * nl, 0.0);
    if k == 1 {
        // One row: faer's product takes its matrix-vector path, whose sums
        // are ordered otherwise; take that path lane by lane.
        let (mut mp, mut one) = (Vec::with_capacity(d * d), Vec::new());
        for (l, ql) in q.iter_mut().enumerate() {
            mp.clear();
            mp.extend(s.iter().map(|e| e.lane_part(l)));
            quad_forms(&mp, w, d, &mut one);
            *ql = one[0];
        }
        return;
    }
    // Y, lane-major: column c of lane l at y[(l * k + c) * d..].
    let mut y = vec![0.0; nl * k * d];
    let mut acc = [0.0; MAX_LANES];
    for x in 0..d {
        let row = &s[x * d..(x + 1) * d];
        for c in 0..k {
            let acc = &mut acc[..nl];
            acc.fill(0.0);
            for (e, &wj) in row.iter().zip(&w[c * d..(c + 1) * d]) {
                for (l, a) in acc.iter_mut().enumerate() {
                    *a = e.lane_part(l).mul_add(wj, *a);
                }
            }
            for (l, a) in acc.iter().enumerate() {
                y[(l * k + c) * d + x] = *a;
            }
        }
    }
    for c in 0..k {
        for l in 0..nl {
            q[c * nl + l] = fdot(
                &y[(l * k + c) * d..(l * k + c + 1) * d],
                &w[c * d..(c + 1) * d],
            );
        }
    }
}

/// `q_i = w_iᵀ S w_i` for the `k` rows `w_i` of `w` (row-major `k × d`)
/// and a symmetric row-major `d × d` matrix `S`: one product `Y = S Wᵀ`
/// (faer's small-matrix kernels), then a dot per row.
fn quad_forms(s: &[f64], w: &[f64], d: usize, q: &mut Vec<f64>) {
    let k = w.len() / d;
    let sm = faer::MatRef::from_row_major_slice(s, d, d);
    let wt = faer::MatRef::from_row_major_slice(w, k, d).transpose();
    let mut y = faer::Mat::<f64>::zeros(d, k);
    faer::linalg::matmul::matmul(
        y.as_mut(),
        faer::Accum::Replace,
        sm,
        wt,
        1.0,
        faer::Par::Seq,
    );
    q.clear();
    q.extend((0..k).map(|i| {
        let col = y
            .col(i)
            .try_as_col_major()
            .expect("column-major")
            .as_slice();
        fdot(col, &w[i * d..(i + 1) * d])
    }));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::math::DualN;

    #[test]
    fn all_lane_mass_terms_are_the_lane_by_lane_products_to_the_bit() {
        // A symmetric dual matrix whose 8 lanes are 8 symmetric matrices
        // M'_l, a vector v with zero entries and k rows w_i: the one-pass
        // kernel must give, per lane, the numbers of sym_times (M'_l v)
        // and quad_forms (w_iᵀ M'_l w_i), which the lane-by-lane tangent
        // used. Sizes of the SAR panels (6 + 14) and others.
        let f = |k: usize| ((k as f64 * 0.618_033_988_7 + 0.1).fract() - 0.5) * 7.0;
        let mut bad = Vec::new();
        for (d, k) in [6, 8, 9, 12, 16, 20, 26, 34]
            .into_iter()
            .flat_map(|d| (1..=24).map(move |k| (d, k)))
        {
            let mut s = vec![DualN::<8>::cst(0.0); d * d];
            for i in 0..d {
                for j in 0..=i {
                    let lanes = std::array::from_fn(|l| f(1000 * (l + 1) + i * d + j));
                    let e = DualN::<8>::new(f(i * d + j), lanes);
                    s[i * d + j] = e;
                    s[j * d + i] = e;
                }
            }
            let v: Vec<f64> = (0..d)
                .map(|j| if j % 5 == 3 { 0.0 } else { f(50_000 + j) })
                .collect();
            let w: Vec<f64> = (0..k * d).map(|x| f(70_000 + x)).collect();
            let (mut mv, mut q) = (Vec::new(), Vec::new());
            mass_lane_terms(&s, &v, &w, d, (&mut mv, &mut q));
            for l in 0..8 {
                let mp: Vec<f64> = s.iter().map(|e| e.eps[l]).collect();
                let mut want = vec![0.0; d];
                sym_times(&mp, d, &v, &mut want);
                let mut wq = Vec::new();
                quad_forms(&mp, &w, d, &mut wq);
                let same_mv = (0..d).all(|i| mv[i * 8 + l].to_bits() == want[i].to_bits());
                let same_q = (0..k).all(|i| q[i * 8 + l].to_bits() == wq[i].to_bits());
                if !(same_mv && same_q) {
                    bad.push((d, k, l, same_mv, same_q));
                }
            }
        }
        assert!(
            bad.is_empty(),
            "(d, k, lane, M'v equal, quad equal): {bad:?}"
        );
    }

    #[test]
    fn quadratic_forms_of_rows_match_the_definition() {
        // S symmetric 5 × 5, three rows w_i: q_i = Σ_jk S_jk w_ij w_ik.
        let d = 5;
        let f = |k: usize| ((k as f64 * 0.7548777 + 0.3).fract() - 0.5) * 3.0;
        let mut s = vec![0.0; d * d];
        for j in 0..d {
            for k in 0..=j {
                let v = f(j * d + k);
                s[j * d + k] = v;
                s[k * d + j] = v;
            }
        }
        let w: Vec<f64> = (0..3 * d).map(|k| f(100 + k)).collect();
        let mut q = Vec::new();
        quad_forms(&s, &w, d, &mut q);
        assert_eq!(q.len(), 3);
        for (i, qi) in q.iter().enumerate() {
            let wi = &w[i * d..(i + 1) * d];
            let want: f64 = (0..d)
                .flat_map(|j| (0..d).map(move |k| (j, k)))
                .map(|(j, k)| s[j * d + k] * wi[j] * wi[k])
                .sum();
            assert!(
                (qi - want).abs() < 1e-13 * (1.0 + want.abs()),
                "{qi} vs {want}"
            );
        }
    }
}
