//! The per-evaluation linear algebra of [`System`]: the constraint-space
//! solve for the multipliers and accelerations, body by body (the method
//! is in [`crate::mbs::dynamics`]), in real arithmetic. Its tangent for
//! the lanes of a dual-number evaluation is [`super::tangent`].

use super::prestress::{PRESTRESS_ITERATIONS, PRESTRESS_STALL, PRESTRESS_TOL};
use crate::mbs::math::Factored;
use crate::mbs::math::{
    gram, min_degree_order, spd_factor, spd_solve, sym_times, CholPattern, Scalar,
};
use crate::mbs::model::Param;
use crate::mbs::system::{bump, pval, BodyBlock, System, Workspace, RANK_REG, RANK_TOL, RIGID};

impl System {
    /// `M⁻¹ x` of slot `s` in real arithmetic (into `out`): a flexible
    /// body by its inverse mass, a rigid one by `diag(1/m, J'⁻¹)`.
    pub(super) fn minv_times(&self, bb: &BodyBlock, s: usize, x: &[f64], out: &mut [f64]) {
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
    /// `M⁻¹Q` and the Gram block `d_i·M⁻¹d_j` of each body. Each entry is
    /// split as it is gathered: its real part into `b`, its lanes into
    /// `lanes` (lane-interleaved, `lanes[i · nl + l]`).
    fn body_blocks<T: Scalar>(&self, ws: &mut Workspace<T>) {
        let nb = self.nb();
        let mut blocks = std::mem::take(&mut ws.blocks);
        blocks.resize_with(nb, BodyBlock::default);
        for bb in blocks.iter_mut() {
            bb.rows.clear();
            bb.b.clear();
            bb.lanes.clear();
        }
        for (r, row) in ws.rows.iter().enumerate() {
            for (side, (slot, blk)) in row.blocks.iter().enumerate() {
                let Some(s) = *slot else { continue };
                let d = self.dof(s);
                let bb = &mut blocks[s];
                split_into(blk, &mut bb.b, &mut bb.lanes);
                if d > 6 {
                    let mo = row.modal[side];
                    if mo == RIGID {
                        bb.b.extend(std::iter::repeat_n(0.0, d - 6));
                        bb.lanes.extend(std::iter::repeat_n(0.0, (d - 6) * T::NL));
                    } else {
                        split_into(&ws.mjac[mo..mo + d - 6], &mut bb.b, &mut bb.lanes);
                    }
                }
                bb.rows.push(r);
            }
        }
        for (s, bb) in blocks.iter_mut().enumerate() {
            let (o, d) = (self.vel_local(s), self.dof(s));
            split_into(&ws.q[o..o + d], &mut bb.b, &mut bb.lanes);
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
        // Where each Gram entry `(x, c ≤ x)` of each body lands in the
        // permuted lower triangle, in the order `solve` adds them.
        ws.scatter.clear();
        for bb in &ws.blocks {
            for (x, r) in bb.rows.iter().enumerate() {
                for q in &bb.rows[..=x] {
                    let (pr, pc) = (inv[*r], inv[*q]);
                    ws.scatter.push(pr.max(pc) * m + pr.min(pc));
                }
            }
        }
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
        ws.spd.zero_matrix(&mut ws.a, m);
        let mut at = ws.scatter.iter();
        for bb in &ws.blocks {
            let k = bb.rows.len() + 1;
            for x in 0..bb.rows.len() {
                for (g, &e) in bb.g[x * k..x * k + x + 1].iter().zip(at.by_ref()) {
                    ws.a[e] += g;
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
            ws.spd.unit_row(&mut ws.a, m, ws.inv_order[r]);
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
        // Real parts and lanes (lane-interleaved) into the scalar type.
        let nl = T::NL;
        let nv = self.nvel();
        let acc: Vec<T> = (0..nv)
            .map(|i| T::from_parts(sol.acc[i], &sol.dacc[i * nl..(i + 1) * nl]))
            .collect();
        ws.rhs.clear();
        ws.rhs
            .extend((0..m).map(|r| T::from_parts(sol.lam[r], &sol.dlam[r * nl..(r + 1) * nl])));
        ws.sol = sol;
        acc
    }

    /// The fixed-point iteration of the joint-load prestress
    /// (`super::prestress`): `λ ← (A + εD)⁻¹(base + G M⁻¹ B λ)` from the
    /// `λ` given until its change is at rounding; `z` holds `B λ` of the
    /// returned λ. False if it does not converge in
    /// [`PRESTRESS_ITERATIONS`] back-substitutions.
    pub(super) fn prestress_iterate<T: Scalar>(
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
}

/// Append the real parts of `v` to `re` and their lanes to `lanes`
/// (lane-interleaved: the `NL` lanes of each entry together).
fn split_into<T: Scalar>(v: &[T], re: &mut Vec<f64>, lanes: &mut Vec<f64>) {
    re.extend(v.iter().map(T::re_part));
    for x in v {
        lanes.extend((0..T::NL).map(|l| x.lane_part(l)));
    }
}
