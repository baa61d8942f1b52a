//! Derivatives of the reduced stiffness and lumped mass with respect to the
//! thickness of groups of plies (ply thickness as a design variable).
//!
//! A group's variable is the common thickness `s` \[m\] of its plies. The
//! element stiffness `K_e = A Gᵀ C_e(s) G + γ_d(s) K_drill` depends on `s`
//! through the section matrix (A, B, D, S; [`crate::laminate::Laminate::thickness_group_derivative`]),
//! the shear stabilisation factor `f(h)` of the total thickness
//! `h` (`∂h/∂s` = plies in the group) and the drilling penalty
//! `γ_d = DRILLING_PENALTY · Ā` (linear in `s`). With the shear block of
//! `C_e` equal to `S f`:
//!
//! - `K' = Σ_e A Gᵀ [C'_ABD; S' f + S f' h'] G + γ_d' K_drill`,
//! - `K'' = Σ_e A Gᵀ [C''_ABD; 2 S' f' h' + S f'' h'²] G` (S and γ_d are
//!   linear in `s`),
//!
//! each assembled by the same element product as K with a per-element
//! section matrix whose shear block is divided by `f` (the product scales
//! it by `f` again). The HRZ lumped mass is linear in the mass and rotary
//! inertia per area ([`super::Triangle::lumped_mass`]), so
//! `M' = lumped(μ', I')` and `M'' = lumped(0, I'')` (μ is linear in `s`).

use super::assembly::{all_finite, PanelModel, NONE};
use super::element::{section_matrix, Mat18, Mat8, DRILLING_PENALTY};
use super::NODE_DOF;
use crate::error::{Error, Result};
use crate::laminate::Laminate;
use faer::sparse::SparseColMat;

/// Thickness derivatives of a panel system, one entry per ply group, on
/// the free DOFs in the order of [`super::PanelSystem`].
#[derive(Debug, Clone)]
pub struct ThicknessSystem {
    /// The ply groups (0-based plies), one variable each.
    pub groups: Vec<Vec<usize>>,
    /// `∂K/∂s` (same pattern as K) \[N/m per m\].
    pub dk: Vec<SparseColMat<usize, f64>>,
    /// `∂²K/∂s²` (same pattern as K); empty unless asked for.
    pub d2k: Vec<SparseColMat<usize, f64>>,
    /// `∂M/∂s`, the lumped diagonal \[kg per m, kg·m² per m\].
    pub dm: Vec<Vec<f64>>,
    /// `∂²M/∂s²` (only the rotary inertias are non-zero); empty unless
    /// asked for.
    pub d2m: Vec<Vec<f64>>,
}

impl PanelModel {
    /// Assemble the thickness derivatives of K and M for `lam` and the ply
    /// `groups` (module doc); the second derivatives when `second`.
    /// Errors: a ply number outside the lay-up ([`Error::Input`] on
    /// `thickness_groups`), a non-finite entry ([`Error::Numerical`]).
    pub fn assemble_thickness(
        &self,
        lam: &Laminate,
        groups: &[Vec<usize>],
        second: bool,
    ) -> Result<ThicknessSystem> {
        let nnz = self.symbolic.row_idx().len();
        let mk = || SparseColMat::new(self.symbolic.clone(), vec![0.0; nnz]);
        let n = self.n_dof();
        let nv = groups.len();
        let n2 = if second { nv } else { 0 };
        let mut sys = ThicknessSystem {
            groups: groups.to_vec(),
            dk: (0..nv).map(|_| mk()).collect(),
            d2k: (0..n2).map(|_| mk()).collect(),
            dm: vec![vec![0.0; n]; nv],
            d2m: vec![vec![0.0; n]; n2],
        };
        self.assemble_thickness_into(lam, &mut sys)?;
        Ok(sys)
    }

    /// Re-assemble `sys` (from [`PanelModel::assemble_thickness`] on this
    /// model) for `lam`, reusing its buffers.
    pub fn assemble_thickness_into(&self, lam: &Laminate, sys: &mut ThicknessSystem) -> Result<()> {
        let n_plies = lam.plies().len();
        if let Some(k) = sys.groups.iter().flatten().find(|&&k| k >= n_plies) {
            return Err(Error::input(
                "thickness_groups",
                k + 1,
                format!("ply numbers within the lay-up (1..={n_plies})"),
            ));
        }
        let h = lam.thickness();
        let c0 = section_matrix(&lam.stiffness());
        let second = !sys.d2k.is_empty();
        for v in 0..sys.groups.len() {
            let td = lam.thickness_group_derivative(&sys.groups[v]);
            let c1 = section_matrix(&td.first);
            let c2 = section_matrix(&td.second);
            let gamma1 = DRILLING_PENALTY * td.membrane_mean;
            let mut vals: Vec<&mut [f64]> = vec![sys.dk[v].val_mut()];
            if second {
                vals.push(sys.d2k[v].val_mut());
            }
            self.fill_thickness(&mut vals, (&c0, &c1, &c2), (h, td.thickness), gamma1)?;
            self.fill_mass(&mut sys.dm[v], td.mass, td.rotary[0]);
            if second {
                self.fill_mass(&mut sys.d2m[v], 0.0, td.rotary[1]);
            }
            check_finite(&sys.dm[v], "dM", v)?;
            if second {
                check_finite(&sys.d2m[v], "d2M", v)?;
            }
        }
        Ok(())
    }

    /// `vals[0]` ← K', `vals[1]` (if present) ← K'' (module doc): `cs` =
    /// (C, C', C'') of the laminate, `(h, dh)` its thickness and `∂h/∂s`,
    /// `gamma1` = `∂γ_d/∂s`.
    fn fill_thickness(
        &self,
        vals: &mut [&mut [f64]],
        (c0, c1, c2): (&Mat8, &Mat8, &Mat8),
        (h, dh): (f64, f64),
        gamma1: f64,
    ) -> Result<()> {
        for v in vals.iter_mut() {
            v.fill(0.0);
        }
        let mut ke = Mat18::zeros();
        for (e, (t, g)) in self.tris.iter().zip(&self.ops).enumerate() {
            let range = self.offsets[e]..self.offsets[e + 1];
            let (pos, loc) = (&self.scatter[range.clone()], &self.local[range]);
            let [f, f1, f2] = t.shear_factor_derivatives(h);
            for (m, val) in vals.iter_mut().enumerate() {
                // The element product scales the shear block by f: divide
                // the wanted shear block by f first.
                let mut c = if m == 0 { *c1 } else { *c2 };
                for i in 6..8 {
                    for j in 6..8 {
                        let s = if m == 0 {
                            c1[(i, j)] * f + c0[(i, j)] * f1 * dh
                        } else {
                            2.0 * c1[(i, j)] * f1 * dh + c0[(i, j)] * f2 * dh * dh
                        };
                        c[(i, j)] = s / f;
                    }
                }
                t.section_stiffness_into(g, &c, h, &mut ke);
                if m == 0 {
                    t.add_drilling(gamma1, &mut ke);
                }
                let ks = ke.as_slice();
                for (&p, &l) in pos.iter().zip(loc) {
                    val[p as usize] += ks[l as usize];
                }
            }
        }
        for (m, val) in vals.iter().enumerate() {
            all_finite(val, PLACE, || {
                format!("the thickness derivative {} of K", m + 1)
            })?;
        }
        Ok(())
    }

    /// The lumped diagonal for mass and rotary inertia per area `(mu, ir)`
    /// on the free DOFs, written into `m` (overwritten).
    fn fill_mass(&self, m: &mut [f64], mu: f64, ir: f64) {
        m.fill(0.0);
        for (t, tri) in self.mesh.triangles.iter().zip(&self.tris) {
            let me = tri.lumped_mass(mu, ir);
            for (a, &v) in me.iter().enumerate() {
                let f = self.free[NODE_DOF * t[a / NODE_DOF] + a % NODE_DOF];
                if f != NONE {
                    m[f] += v;
                }
            }
        }
    }
}

fn check_finite(m: &[f64], what: &str, v: usize) -> Result<()> {
    all_finite(m, PLACE, || format!("{what} for thickness group {v}"))
}

/// Where the thickness assembly's numerical errors happen.
const PLACE: &str = "fe::PanelModel::assemble_thickness";
