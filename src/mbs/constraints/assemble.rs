//! Assembly of the constraint rows of every joint at the current marker
//! kinematics, in the order of the model's joints: the rows of
//! [`super::rows`], their modal Jacobian entries on flexible sides, the
//! body-frame angular blocks, `Φ̇`, and the Baumgarte-stabilised
//! right-hand side `γ − 2αΦ̇ − α²Φ` of `G v̇`.

use super::rows::joint_rows;
use crate::mbs::math::{cst, mtv, Scalar};
use crate::mbs::system::{Row, System, Workspace};
use nalgebra::Vector3;

impl System {
    /// Assemble all constraint rows at time `t` into `ws.rows` (marker
    /// kinematics from `ws.mk`).
    pub fn constraints<T: Scalar>(&self, t: f64, ws: &mut Workspace<T>) {
        ws.rows.clear();
        ws.mjac.clear();
        let alpha = self.model.baumgarte;
        for joint in &self.model.joints {
            let first = ws.rows.len();
            let markers = (&ws.mk[joint.i], &ws.mk[joint.j]);
            joint_rows(&joint.kind, markers, t, &mut ws.rows);
            for row in &mut ws.rows[first..] {
                row.markers = [joint.i, joint.j];
            }
        }
        // Modal entries of flexible sides, ω-global blocks to ω' body-frame
        // blocks, and Φ̇.
        let mut rows = std::mem::take(&mut ws.rows);
        for row in rows.iter_mut() {
            let mut phidot = -row.phidot; // holds −ν on entry
            for side in 0..2 {
                let (slot, blk) = &mut row.blocks[side];
                let Some(s) = *slot else { continue };
                let k = &ws.kin[s];
                let dv = Vector3::new(blk[0], blk[1], blk[2]);
                let wg = Vector3::new(blk[3], blk[4], blk[5]);
                let mk = &ws.mk[row.markers[side]];
                if mk.node.is_some() {
                    // ∂/∂ẇ_j = (Aᵀdv)·Φ_kj + (Tᵀ Aᵀ(dw_g − s×dv))·Ψ_kj.
                    let av = mtv(&k.a, &dv);
                    // Without the node's rotation (spherical joints only)
                    // ω-block − s × v-block is exactly zero.
                    let aw = if ws.rotations[row.markers[side]] {
                        mtv(&mk.tangent, &mtv(&k.a, &(wg - mk.s.cross(&dv))))
                    } else {
                        Vector3::zeros()
                    };
                    row.modal[side] = ws.mjac.len();
                    let planes = &ws.planes[row.markers[side]];
                    phidot += planes.row_entries((&av, &aw), &k.qd, &mut ws.mjac);
                }
                let wb = mtv(&k.a, &wg);
                blk[3] = wb[0];
                blk[4] = wb[1];
                blk[5] = wb[2];
                phidot += dv.dot(&k.v) + wg.dot(&k.w);
            }
            row.phidot = phidot;
            // Stabilised acceleration right-hand side.
            let a = cst::<T>(alpha);
            row.gamma -= cst::<T>(2.0) * a * phidot + a * a * row.phi;
        }
        ws.rows = rows;
    }

    /// The values `Φ` of the constraint rows `rows` (ascending indices)
    /// at time `t` into `out` (`out[k]` of `rows[k]`), from the marker
    /// kinematics in `ws.mk` (after [`System::kinematics`]): only the
    /// joints holding those rows are evaluated, without the assembly.
    pub fn row_values<T: Scalar>(
        &self,
        t: f64,
        ws: &Workspace<T>,
        rows: &[usize],
        out: &mut Vec<T>,
    ) {
        out.clear();
        let mut scratch: Vec<Row<T>> = Vec::new();
        let mut first = 0;
        let mut next = rows.iter().peekable();
        for joint in &self.model.joints {
            let n = joint.kind.equations();
            if next.peek().is_some_and(|&&r| r < first + n) {
                scratch.clear();
                let markers = (&ws.mk[joint.i], &ws.mk[joint.j]);
                joint_rows(&joint.kind, markers, t, &mut scratch);
                while let Some(&&r) = next.peek().filter(|&&&r| r < first + n) {
                    out.push(scratch[r - first].phi);
                    next.next();
                }
            }
            first += n;
        }
    }
}
