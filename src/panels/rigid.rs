//! Rigid-body content of a panel mode: how much of a mode is a rigid
//! motion of the panel's frame.
//!
//! # Definition
//! The six rigid motions of the frame about its origin (the panel centre,
//! which is the clamped node of `centre_clamp`) are the columns of `R`:
//! node `k` at `s_k = (x_k, y_k, 0)` \[m\] moves by `u_k = a + ω × s_k` and
//! turns by `ω`, for `(a, ω) = e_1 … e_6` (translations x, y, z \[m\],
//! rotations about x, y, z \[rad\]). With the lumped mass `M` (node masses
//! `m_k` \[kg\], rotary inertias `J_k` \[kg·m²\], *all* nodes, the clamped one
//! included: it is part of the rigid body the frame carries) the
//! M-orthogonal projector onto span(R) is `P = R G⁻¹ Rᵀ M`, `G = RᵀMR`, and
//! the rigid content of a mode φ is
//!
//! ```text
//! c(φ) = ‖Pφ‖²_M / ‖φ‖²_M = bᵀ G⁻¹ b / φᵀMφ,   b = RᵀMφ,
//! b = [ Σ m_k u_k ;  Σ m_k s_k × u_k + Σ J_k ∘ ψ_k ]   (u_k, ψ_k: φ at k),
//! G = [ m I        −Σ m_k s̃_k           ]
//!     [ Σ m_k s̃_k  Σ m_k s̃_kᵀ s̃_k + diag ΣJ_k ],
//! ```
//!
//! dimensionless, in \[0, 1\]. `b` is the pair of inertia invariants
//! (`i3`, `ls + c_rot`) of the mode, so `c = 0` means the mode carries no
//! momentum and no angular momentum relative to the frame (a mean-axis
//! mode: every free–free elastic mode), `c ≈ 1` that the mode is almost a
//! rigid motion. The single clamped node of `centre_clamp` leaves the
//! in-plane rotation about it resisted only by the drilling stiffness:
//! that mode has `c ≈ 1 − 5e-7` (SAR panel 3, 32 divisions), and in a
//! floating-frame body it duplicates the frame's own rotation about the
//! panel normal (see [`crate::panels::basis`] for the treatment).
//!
//! `R`, `M` and hence `P` do not depend on the ply angles (the lumped mass
//! depends on density and ply thickness only), so `P` commutes with
//! `d/dθ`.

use crate::error::{Error, Result};
use crate::fe::{Panel, Triangle, NODE_DOF};
use crate::laminate::Laminate;
use nalgebra::{Cholesky, Matrix3, Matrix6, Vector3, Vector6, U6};

/// The rigid body of a panel's frame: node positions and lumped masses of
/// every node, and the Cholesky factor of `G = RᵀMR` (module doc).
#[derive(Debug, Clone)]
pub struct RigidFrame {
    nodes: Vec<[f64; 2]>,
    mass: Vec<f64>,
    inertia: Vec<Vector3<f64>>,
    g: Cholesky<f64, U6>,
}

/// `s̃` such that `s̃ v = s × v`.
fn skew(s: Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -s.z, s.y, s.z, 0.0, -s.x, -s.y, s.x, 0.0)
}

impl RigidFrame {
    /// From node coordinates \[m\] (panel frame, `z = 0`), translational
    /// node masses \[kg\] and rotary inertias (θx, θy, θz) \[kg·m²\] of all
    /// nodes. Errors: lengths differ, or `G` is not positive definite
    /// (no mass, or all of it on a line) → [`Error::Numerical`].
    pub fn new(
        nodes: Vec<[f64; 2]>,
        mass: Vec<f64>,
        inertia: Vec<Vector3<f64>>,
    ) -> Result<RigidFrame> {
        if mass.len() != nodes.len() || inertia.len() != nodes.len() {
            return Err(Error::numerical(
                "panels::rigid::RigidFrame::new",
                format!(
                    "{} nodes, {} masses, {} inertias",
                    nodes.len(),
                    mass.len(),
                    inertia.len()
                ),
            ));
        }
        let mut g = Matrix6::<f64>::zeros();
        for ((p, &m), j) in nodes.iter().zip(&mass).zip(&inertia) {
            let st = skew(Vector3::new(p[0], p[1], 0.0));
            let tt = Matrix3::identity() * m;
            let rt = st * m;
            let rr = st.transpose() * st * m + Matrix3::from_diagonal(j);
            let mut block = Matrix6::zeros();
            block.fixed_view_mut::<3, 3>(0, 0).copy_from(&tt);
            block.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-rt));
            block.fixed_view_mut::<3, 3>(3, 0).copy_from(&rt);
            block.fixed_view_mut::<3, 3>(3, 3).copy_from(&rr);
            g += block;
        }
        let g = Cholesky::new(g).ok_or_else(|| {
            Error::numerical(
                "panels::rigid::RigidFrame::new",
                "the rigid-body mass matrix RᵀMR is not positive definite",
            )
        })?;
        Ok(RigidFrame {
            nodes,
            mass,
            inertia,
            g,
        })
    }

    /// The frame of `panel` with the lumped (HRZ) masses of `laminate`,
    /// every node included (the same masses as the assembled diagonal of
    /// M on the free DOFs).
    pub fn of_panel(panel: &Panel, laminate: &Laminate) -> Result<RigidFrame> {
        let mesh = &panel.mesh;
        let nn = mesh.nodes.len();
        let (mu, ir) = (laminate.mass_per_area(), laminate.rotary_inertia_per_area());
        let mut mass = vec![0.0; nn];
        let mut inertia = vec![Vector3::zeros(); nn];
        for t in &mesh.triangles {
            let me = Triangle::new(t.map(|i| mesh.nodes[i]))?.lumped_mass(mu, ir);
            for (a, &node) in t.iter().enumerate() {
                mass[node] += me[NODE_DOF * a];
                for c in 0..3 {
                    inertia[node][c] += me[NODE_DOF * a + 3 + c];
                }
            }
        }
        RigidFrame::new(mesh.nodes.clone(), mass, inertia)
    }

    /// Node masses \[kg\] (all nodes).
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }

    /// Node rotary inertias (θx, θy, θz) \[kg·m²\] (all nodes).
    pub fn inertia(&self) -> &[Vector3<f64>] {
        &self.inertia
    }

    /// `b = RᵀMφ` and `φᵀMφ` of a field given as `(node, component, value)`
    /// triples (components 0..6 = u, v, w, θx, θy, θz; missing entries are
    /// zero, e.g. constrained DOFs).
    pub fn moments<I>(&self, field: I) -> (Vector6<f64>, f64)
    where
        I: IntoIterator<Item = (usize, usize, f64)>,
    {
        let mut b = Vector6::zeros();
        let mut norm = 0.0;
        for (node, comp, x) in field {
            if comp < 3 {
                let m = self.mass[node];
                let p = self.nodes[node];
                let mut u = Vector3::zeros();
                u[comp] = x;
                b[comp] += m * x;
                let r = Vector3::new(p[0], p[1], 0.0).cross(&u) * m;
                for c in 0..3 {
                    b[3 + c] += r[c];
                }
                norm += m * x * x;
            } else {
                let j = self.inertia[node][comp - 3];
                b[comp] += j * x;
                norm += j * x * x;
            }
        }
        (b, norm)
    }

    /// Coefficients `c = G⁻¹ b` of the rigid part `Pφ = R c` (translation
    /// \[m\] and rotation \[rad\] of the frame per unit modal coordinate).
    pub fn coefficients(&self, b: &Vector6<f64>) -> Vector6<f64> {
        self.g.solve(b)
    }

    /// Rigid content `bᵀG⁻¹b / φᵀMφ` (module doc) of a field given as
    /// `(node, component, value)` triples; 0 for a zero field.
    pub fn content<I>(&self, field: I) -> f64
    where
        I: IntoIterator<Item = (usize, usize, f64)>,
    {
        let (b, norm) = self.moments(field);
        if norm > 0.0 {
            (b.dot(&self.g.solve(&b)) / norm).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// `(R c)` at node `node`: translation `a + ω × s` \[m\] and rotation
    /// `ω` \[rad\] for `c = (a, ω)`.
    pub fn motion(&self, c: &Vector6<f64>, node: usize) -> [f64; 6] {
        let p = self.nodes[node];
        let a = c.fixed_rows::<3>(0);
        let w = Vector3::new(c[3], c[4], c[5]);
        let u = Vector3::new(a[0], a[1], a[2]) + w.cross(&Vector3::new(p[0], p[1], 0.0));
        [u.x, u.y, u.z, w.x, w.y, w.z]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> RigidFrame {
        let nodes = vec![
            [-1.0, -0.5],
            [1.0, -0.5],
            [1.0, 0.5],
            [-1.0, 0.5],
            [0.0, 0.0],
        ];
        let mass = vec![1.0, 2.0, 1.5, 0.5, 3.0];
        let inertia = vec![Vector3::new(1e-3, 2e-3, 1e-4); 5];
        RigidFrame::new(nodes, mass, inertia).unwrap()
    }

    #[test]
    fn rigid_motions_have_content_one() {
        let f = square();
        for k in 0..6 {
            let mut c = Vector6::zeros();
            c[k] = 1.0;
            c[(k + 2) % 6] = 0.3;
            let field: Vec<_> = (0..5)
                .flat_map(|n| {
                    let m = f.motion(&c, n);
                    (0..6).map(move |comp| (n, comp, m[comp]))
                })
                .collect();
            let content = f.content(field.iter().copied());
            assert!((content - 1.0).abs() < 1e-12, "{k}: {content}");
            let (b, _) = f.moments(field);
            assert!((f.coefficients(&b) - c).norm() < 1e-12);
        }
    }

    #[test]
    fn orthogonal_field_has_content_zero() {
        // An arbitrary field has some rigid content; its elastic part
        // φ − Pφ has none.
        let f = square();
        let field: Vec<(usize, usize, f64)> = (0..5)
            .flat_map(|n| (0..6).map(move |c| (n, c, ((n * 7 + c * 3) % 5) as f64 - 2.0)))
            .collect();
        let (b, _) = f.moments(field.iter().copied());
        let c = f.coefficients(&b);
        let projected: Vec<_> = field
            .iter()
            .map(|&(n, comp, x)| (n, comp, x - f.motion(&c, n)[comp]))
            .collect();
        assert!(f.content(projected) < 1e-24);
        let c0 = f.content(field);
        assert!(c0 > 0.0 && c0 < 1.0);
    }
}
