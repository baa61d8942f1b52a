//! The joint-load prestress of geometric stiffening
//! ([`crate::mbs::model::geometric`], "Joint-load prestress"): the
//! columns of `B` and its products, for the constraint-space solve
//! ([`super::solve`]).
//!
//! # Equations
//! The joints' force on a flexible body at a joint node `P`, in frame
//! axes, is `f_P = Aᵀ Σ_r g_r λ_r` with `g_r` the `∂/∂ṙ` block of row `r`
//! on that side (a row's generalized force on the frame origin is the
//! force it passes). The modal equations get `−Σ_a f_P,a K_{P,a} w`, which
//! is linear in λ: `−B λ`, with the column of row `r`
//! `β_r = Σ_a (Aᵀ g_r)_a K_{P,a} w` (n modal entries, zero elsewhere). So
//!
//! ```text
//!   M v̇ = Q + (Gᵀ − B) λ,   G v̇ = γ.
//! ```
//!
//! `B` is `O(w)`, so the symmetric constraint-space factor of
//! `A = G M⁻¹ Gᵀ` (+ the Tikhonov shift) is kept and λ is found by the
//! fixed-point iteration
//!
//! ```text
//!   A λ_{j+1} = γ − G M⁻¹ Q + G M⁻¹ B λ_j
//! ```
//!
//! (one back-substitution each; `G M⁻¹ z = [w_i·z]` with the rows'
//! `w_i = M⁻¹ g_i` the solve has), from `λ_0` without `B`, until the
//! change is at rounding (`|Δλ|∞ ≤` [`PRESTRESS_TOL`] `|λ|∞`, or a change
//! below [`PRESTRESS_STALL`] `|λ|∞` that stopped shrinking), at most
//! [`PRESTRESS_ITERATIONS`] times; then `v̇ = M⁻¹(Q − Bλ + Gᵀλ)`. It
//! contracts with the factor `‖A⁻¹ G M⁻¹ B‖ = O(w)`; a run that does not
//! converge gets non-finite accelerations, which the integrator reports
//! as a numerical error at that time.
//!
//! # Tangent
//! Differentiating at the converged point (`B' λ` is the lane of
//! `Σ_r β_r λ_r` with the real λ: the dual `β` carries `A'`, `g'`, `w'`
//! and `K'_{P,a}`):
//!
//! ```text
//!   r₁ = Q' − B'λ − M'v̇ + G'ᵀλ,
//!   A λ' = r₂ − G M⁻¹ r₁ − εD'λ + G M⁻¹ B λ',   v̇' = M⁻¹(r₁ − B λ' + Gᵀλ'),
//! ```
//!
//! the same iteration for λ' with the same factor; exact to the
//! iteration's tolerance.

use crate::mbs::math::{fdot, mtv, Scalar};
use crate::mbs::system::{System, Workspace};
use nalgebra::Vector3;

/// Largest number of back-substitutions of the prestress iteration.
pub const PRESTRESS_ITERATIONS: usize = 40;
/// Relative change of λ at which the iteration stops (`|Δλ|∞ ≤ tol ·
/// |λ|∞`): a few rounding errors of the constraint-space solve.
pub const PRESTRESS_TOL: f64 = 1e-14;
/// Relative change below which a change that no longer shrinks counts as
/// rounding (the iterates of one factor stall at a few ulps of the
/// solve's own error).
pub const PRESTRESS_STALL: f64 = 1e-10;

impl System {
    /// The columns of `B` (module doc) at the state in `ws` into
    /// `ws.pcols`/`ws.pvals`; whether there is any (the scene has the
    /// effect and a row on a joint node with point cases). Needs the
    /// invariants of the evaluation (after [`System::flex_bodies`]).
    pub(crate) fn prestress_columns<T: Scalar>(&self, ws: &mut Workspace<T>) -> bool {
        ws.pcols.clear();
        ws.pvals.clear();
        if !self.model.geometric_stiffening {
            return false;
        }
        for (r, row) in ws.rows.iter().enumerate() {
            for (side, (slot, blk)) in row.blocks.iter().enumerate() {
                let Some(s) = *slot else { continue };
                let n = self.modes[s];
                let Some((_, node)) = ws.mk[row.markers[side]].node else {
                    continue;
                };
                let body = &self.model.bodies[self.moving[s]];
                let geometric = body.flex.as_ref().and_then(|f| f.basis.geometric.as_ref());
                let Some(b0) = geometric.and_then(|g| g.point_block(node, 0)) else {
                    continue;
                };
                let (Some(inv), k) = (ws.inv[s].as_ref(), &ws.kin[s]) else {
                    continue;
                };
                let av = mtv(&k.a, &Vector3::new(blk[0], blk[1], blk[2]));
                let nn = n * n;
                let off = ws.pvals.len();
                for j in 0..n {
                    let mut b = T::zero();
                    for a in 0..3 {
                        let kr = &inv.kg[(b0 + a) * nn + j * n..(b0 + a) * nn + (j + 1) * n];
                        let kw = kr
                            .iter()
                            .zip(&k.q)
                            .fold(T::zero(), |acc, (x, w)| acc + *x * *w);
                        b += av[a] * kw;
                    }
                    ws.pvals.push(b);
                }
                ws.pcols.push((r, s, off));
            }
        }
        !ws.pcols.is_empty()
    }

    /// Record a prestress iteration that did not converge (time NaN until
    /// [`System::rhs`] sets it): the bodies with joint-load columns and
    /// the last two iterates' largest change.
    pub(crate) fn note_prestress_failure<T: Scalar>(
        &self,
        ws: &Workspace<T>,
        last: &[f64],
        before: &[f64],
    ) {
        let mut bodies: Vec<&str> = Vec::new();
        for &(_, s, _) in &ws.pcols {
            let name = self.model.bodies[self.moving[s]].name.as_str();
            if !bodies.contains(&name) {
                bodies.push(name);
            }
        }
        let change = last
            .iter()
            .zip(before)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let size = last.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        *self.counters.prestress_failure.borrow_mut() = Some((
            f64::NAN,
            format!(
                "the joint-load prestress iteration of body {} did not converge in \
                 {PRESTRESS_ITERATIONS} back-substitutions (last change {change:.3e} of |λ| \
                 {size:.3e})",
                bodies.join(", ")
            ),
        ));
    }

    /// `out = B λ` (velocity layout, modal entries only) with the real
    /// parts of the columns (`lane = None`) or lane `l` of them (`B' λ`).
    pub(crate) fn prestress_force<T: Scalar>(
        &self,
        ws: &Workspace<T>,
        lam: &[f64],
        lane: Option<usize>,
        out: &mut Vec<f64>,
    ) {
        out.clear();
        out.resize(self.nvel(), 0.0);
        for &(r, s, off) in &ws.pcols {
            let o = self.vel_local(s) + 6;
            let n = self.modes[s];
            for (j, b) in ws.pvals[off..off + n].iter().enumerate() {
                let v = match lane {
                    None => b.re_part(),
                    Some(l) => b.lane_part(l),
                };
                out[o + j] += v * lam[r];
            }
        }
    }

    /// `out = base + G M⁻¹ z` for a modal force `z` (velocity layout):
    /// row `i` of body `s` adds `w_i·z_s` (`w_i = M_s⁻¹ g_i`, the solve's
    /// blocks); dropped rows stay 0.
    pub(crate) fn prestress_rhs<T: Scalar>(
        &self,
        ws: &Workspace<T>,
        (base, dropped): (&[f64], &[bool]),
        z: &[f64],
        out: &mut Vec<f64>,
    ) {
        out.clear();
        out.extend_from_slice(base);
        for (s, bb) in ws.blocks.iter().enumerate() {
            let (o, d) = (self.vel_local(s), self.dof(s));
            if d <= 6 {
                continue;
            }
            let zs = &z[o + 6..o + d];
            if zs.iter().all(|v| *v == 0.0) {
                continue;
            }
            for (i, &r) in bb.rows.iter().enumerate() {
                out[r] += fdot(&bb.w[i * d + 6..(i + 1) * d], zs);
            }
        }
        for (o, d) in out.iter_mut().zip(dropped) {
            if *d {
                *o = 0.0;
            }
        }
    }
}
