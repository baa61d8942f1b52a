//! Floating-frame flexible bodies: the modal basis interface
//! ([`ModalBasis`]) and its inertia invariants ([`Invariants`]).
//!
//! ## Kinematics (paper Eq. 5)
//! A flexible body has a reference frame (origin `r`, rotation `A`) and
//! `n` modal coordinates `w`. Node `k` sits at `s_k` in the frame when
//! undeformed and carries a lumped mass `m_k` and a rotary inertia `J_k`
//! (diagonal, frame axes). Its displacement and small rotation are
//! `Φ_k w` and `Ψ_k w` (the translational and rotational rows of the
//! modal matrix `X`, 3 × n each), so the node's position is
//! `x_k = r + A u_k`, `u_k = s_k + Φ_k w`.
//!
//! ## Inertia invariants
//! The kinetic energy of the lumped-mass body, with velocities
//! `[ṙ (global), ω' (frame), ẇ]`, is exactly
//! `T = ½ Σ m_k |ẋ_k|² + ½ Σ (ω' + Ψ_k ẇ)ᵀ J_k (ω' + Ψ_k ẇ)`, and every
//! node sum in the mass matrix and the quadratic-velocity vector reduces
//! to these constant sums (computed once per basis):
//!
//! | symbol | definition | size |
//! |---|---|---|
//! | `mass` | `Σ m_k` | 1 |
//! | `s0` | `Σ m_k s_k` | 3 |
//! | `e0` | `Σ m_k s_k s_kᵀ` | 3×3 |
//! | `i3` | `Σ m_k Φ_k` | 3×n |
//! | `ls` | `Σ m_k s_k × Φ_kj` | 3×n |
//! | `p_j` | `Σ m_k Φ_kj s_kᵀ` | n × 3×3 |
//! | `q_ij` | `Σ m_k Φ_ki Φ_kjᵀ` | n² × 3×3 |
//! | `v_ij` | `Σ m_k Φ_ki × Φ_kj` | n² × 3 |
//! | `j_rot` | `Σ J_k` | 3×3 |
//! | `c_rot` | `Σ J_k Ψ_k` | 3×n |
//! | `mww` | `Σ m_k Φ_kᵀΦ_k + Ψ_kᵀJ_kΨ_k` | n×n |
//!
//! They are the classical "inertia shape integrals" of the floating frame
//! formulation (Shabana, *Dynamics of Multibody Systems*, 3rd ed., §5.4)
//! written for lumped masses; [`crate::mbs::dynamics`] assembles the
//! mass matrix and quadratic-velocity terms of Eq. 6 from them.
//!
//! ## Design derivatives
//! A basis may carry derivatives of its eigenvalues and mode shapes with
//! respect to named design variables (the ply angles: `dΛ/dθ`, `dX/dθ`
//! from [`crate::modal`]); node masses do not depend on them. The
//! invariants' derivatives follow exactly (they are linear or bilinear in
//! `X`) from the same matrix products
//! ([`Invariants::with_derivatives`]).

use super::geometric::Geometric;
use crate::error::{Error, Result};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use nalgebra::{Matrix3, Vector3};

/// Derivatives of a basis with respect to one design variable.
#[derive(Debug, Clone, PartialEq)]
pub struct BasisDerivative {
    /// Name of the design variable (e.g. `theta1`).
    pub name: String,
    /// `dλ_j/db` (1/s² per unit of b), length n.
    pub eigenvalues: Vec<f64>,
    /// `dX/db` in the layout of [`ModalBasis::shapes`].
    pub shapes: Vec<f64>,
}

/// A mode left out of a basis because it is almost a rigid motion of the
/// frame ([`crate::panels::rigid`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DroppedMode {
    /// 1-based index among the computed modes (ascending frequency).
    pub mode: usize,
    /// Frequency `√λ/(2π)` \[Hz\].
    pub frequency_hz: f64,
    /// Rigid-body content `‖Pφ‖²_M / ‖φ‖²_M` (dimensionless).
    pub content: f64,
}

/// Rigid-body content of a basis's modes, and the modes left out for it
/// (empty for bases that do not compute it, e.g. closed-form beams).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RigidScreen {
    /// Content of each kept mode, in basis order (empty if not computed).
    pub content: Vec<f64>,
    /// Modes dropped because their content exceeded `limit`.
    pub dropped: Vec<DroppedMode>,
    /// The content above which modes were dropped
    /// ([`ModalBasis::screened`]); 1 if the basis was not screened.
    pub limit: f64,
}

/// The modal data of a flexible body: everything the multibody kernel
/// needs from a finite element model (or from closed-form modes).
#[derive(Debug, Clone, PartialEq)]
pub struct ModalBasis {
    /// Undeformed node positions `s_k` in the body frame, relative to the
    /// frame origin (m).
    pub nodes: Vec<Vector3<f64>>,
    /// Lumped translational mass `m_k` of each node (kg, ≥ 0).
    pub node_mass: Vec<f64>,
    /// Lumped rotary inertia of each node about the frame axes (diagonal,
    /// kg·m², ≥ 0).
    pub node_inertia: Vec<Vector3<f64>>,
    /// Number of modes `n`.
    pub n_modes: usize,
    /// Mode shapes with 6 components per node: entry
    /// `[(k·6 + c)·n + j]` is component `c` (ux, uy, uz in m, then
    /// rx, ry, rz in rad, per unit modal coordinate) of mode `j` at node
    /// `k`.
    pub shapes: Vec<f64>,
    /// Eigenvalues `λ_j = ω_j²` (1/s²), the diagonal of Λ (Eq. 6).
    pub eigenvalues: Vec<f64>,
    /// Derivatives with respect to design variables (may be empty).
    pub derivatives: Vec<BasisDerivative>,
    /// Rigid-body content of the modes and the modes dropped for it.
    pub rigid: RigidScreen,
    /// The modal geometric stiffness of the inertial unit load cases and
    /// of the point-force cases at joint nodes (geometric stiffening,
    /// [`super::geometric`]); `None` when the
    /// basis's source does not provide it.
    pub geometric: Option<Geometric>,
}

impl ModalBasis {
    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Mode shape entry: component `c` (0..6) of mode `j` at node `k`.
    #[inline]
    pub fn shape(&self, k: usize, c: usize, j: usize) -> f64 {
        self.shapes[(k * 6 + c) * self.n_modes + j]
    }

    /// Check sizes and values; `key` prefixes the error keys.
    pub fn validate(&self, key: &str) -> Result<()> {
        let (nn, n) = (self.nodes.len(), self.n_modes);
        if nn == 0 || self.node_mass.len() != nn || self.node_inertia.len() != nn {
            return Err(Error::input(
                format!("{key}.nodes"),
                format!(
                    "{nn} nodes, {} masses, {} inertias",
                    self.node_mass.len(),
                    self.node_inertia.len()
                ),
                "at least one node, with one mass and one inertia per node",
            ));
        }
        if self.shapes.len() != 6 * nn * n || self.eigenvalues.len() != n {
            return Err(Error::input(
                format!("{key}.shapes"),
                format!(
                    "{} shape entries, {} eigenvalues",
                    self.shapes.len(),
                    self.eigenvalues.len()
                ),
                format!("6·nodes·modes = {} entries and {n} eigenvalues", 6 * nn * n),
            ));
        }
        for (k, &m) in self.node_mass.iter().enumerate() {
            let ji = &self.node_inertia[k];
            if !(m.is_finite() && m >= 0.0) || ji.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(Error::input(
                    format!("{key}.node_mass[{k}]"),
                    format!("{m}, inertia {:?}", ji.as_slice()),
                    "finite lumped masses and rotary inertias ≥ 0",
                ));
            }
        }
        if self.node_mass.iter().sum::<f64>() <= 0.0 {
            return Err(Error::input(
                format!("{key}.node_mass"),
                0.0,
                "a total mass > 0 (kg)",
            ));
        }
        for (j, &l) in self.eigenvalues.iter().enumerate() {
            if !(l.is_finite() && l > 0.0) {
                return Err(Error::input(
                    format!("{key}.eigenvalues[{j}]"),
                    l,
                    "a finite eigenvalue ω² > 0 (constrained or rigid-mode-free modes)",
                ));
            }
        }
        if let Some(i) = self.shapes.iter().position(|v| !v.is_finite()) {
            return Err(Error::input(
                format!("{key}.shapes[{i}]"),
                self.shapes[i],
                "finite mode shape entries",
            ));
        }
        for d in &self.derivatives {
            if d.eigenvalues.len() != n || d.shapes.len() != self.shapes.len() {
                return Err(Error::input(
                    format!("{key}.derivatives.{}", d.name),
                    format!(
                        "{} eigenvalue and {} shape derivatives",
                        d.eigenvalues.len(),
                        d.shapes.len()
                    ),
                    "one derivative per eigenvalue and per shape entry",
                ));
            }
        }
        if let Some(g) = &self.geometric {
            g.validate(key, n, self.derivatives.len())?;
        }
        Ok(())
    }

    /// The nearest node to the body-frame point `p`, with its distance.
    pub fn nearest_node(&self, p: &Vector3<f64>) -> (usize, f64) {
        self.nodes
            .iter()
            .enumerate()
            .map(|(k, s)| (k, (s - p).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, f64::INFINITY))
    }

    /// The first `n` modes (and their derivatives) of this basis.
    pub fn truncated(&self, n: usize) -> ModalBasis {
        let n = n.min(self.n_modes);
        let pick = |v: &[f64]| -> Vec<f64> {
            v.chunks(self.n_modes)
                .flat_map(|row| row[..n].iter().copied())
                .collect()
        };
        ModalBasis {
            nodes: self.nodes.clone(),
            node_mass: self.node_mass.clone(),
            node_inertia: self.node_inertia.clone(),
            n_modes: n,
            shapes: pick(&self.shapes),
            eigenvalues: self.eigenvalues[..n].to_vec(),
            derivatives: self
                .derivatives
                .iter()
                .map(|d| BasisDerivative {
                    name: d.name.clone(),
                    eigenvalues: d.eigenvalues[..n].to_vec(),
                    shapes: pick(&d.shapes),
                })
                .collect(),
            rigid: RigidScreen {
                content: self.rigid.content.iter().take(n).copied().collect(),
                ..self.rigid.clone()
            },
            geometric: self
                .geometric
                .as_ref()
                .map(|g| g.picked(&(0..n).collect::<Vec<_>>())),
        }
    }

    /// The basis without its modes of rigid-body content above `limit`
    /// (`rigid.content` per mode, [`crate::panels::rigid`]): the kept
    /// modes keep their order, eigenvalues and derivative columns, and
    /// `rigid` lists the dropped ones (1-based computed-mode numbers,
    /// frequency \[Hz\], content). A basis without contents (closed-form
    /// beams) is returned as is. Error ([`Error::Numerical`]) if no mode
    /// would be left.
    pub fn screened(&self, limit: f64) -> Result<ModalBasis> {
        if self.rigid.content.len() != self.n_modes {
            return Ok(self.clone());
        }
        let keep: Vec<usize> = (0..self.n_modes)
            .filter(|&j| self.rigid.content[j] <= limit)
            .collect();
        if keep.is_empty() {
            return Err(Error::numerical(
                "mbs::ModalBasis::screened",
                format!(
                    "every mode is almost a rigid motion of the frame (rigid content {:?} > \
                     {limit}); ask for more modes or raise rigid_limit",
                    self.rigid.content
                ),
            ));
        }
        let n = self.n_modes;
        let pick = |v: &[f64]| -> Vec<f64> {
            v.chunks(n)
                .flat_map(|row| keep.iter().map(move |&j| row[j]))
                .collect()
        };
        let mut dropped = self.rigid.dropped.clone();
        dropped.extend(
            (0..n)
                .filter(|&j| self.rigid.content[j] > limit)
                .map(|j| DroppedMode {
                    mode: j + 1,
                    frequency_hz: self.eigenvalues[j].sqrt() / (2.0 * std::f64::consts::PI),
                    content: self.rigid.content[j],
                }),
        );
        Ok(ModalBasis {
            nodes: self.nodes.clone(),
            node_mass: self.node_mass.clone(),
            node_inertia: self.node_inertia.clone(),
            n_modes: keep.len(),
            shapes: pick(&self.shapes),
            eigenvalues: keep.iter().map(|&j| self.eigenvalues[j]).collect(),
            derivatives: self
                .derivatives
                .iter()
                .map(|d| BasisDerivative {
                    name: d.name.clone(),
                    eigenvalues: keep.iter().map(|&j| d.eigenvalues[j]).collect(),
                    shapes: pick(&d.shapes),
                })
                .collect(),
            rigid: RigidScreen {
                content: keep.iter().map(|&j| self.rigid.content[j]).collect(),
                dropped,
                limit,
            },
            geometric: self.geometric.as_ref().map(|g| g.picked(&keep)),
        })
    }

    /// The same body with its frame origin moved to the body-frame point
    /// `o` (node positions become `s_k − o`).
    pub fn shifted(&self, o: &Vector3<f64>) -> ModalBasis {
        let mut b = self.clone();
        for s in b.nodes.iter_mut() {
            *s -= o;
        }
        b.geometric = self.geometric.as_ref().map(|g| g.shifted(o));
        b
    }

    /// Centre of mass of the undeformed body in the frame (m).
    pub fn centre_of_mass(&self) -> Vector3<f64> {
        let m: f64 = self.node_mass.iter().sum();
        self.nodes
            .iter()
            .zip(&self.node_mass)
            .fold(Vector3::zeros(), |a, (s, &mk)| a + s * mk)
            / m
    }
}

/// The inertia invariants of a [`ModalBasis`] (see the module doc for
/// their definitions); matrices are row-major, `n` = number of modes.
#[derive(Debug, Clone, PartialEq)]
pub struct Invariants {
    /// Number of modes `n`.
    pub n: usize,
    /// Total mass `Σ m_k` (kg).
    pub mass: f64,
    /// First moment `Σ m_k s_k` of the undeformed body, frame axes (kg·m).
    pub s0: Vector3<f64>,
    /// Second moment `Σ m_k s_k s_kᵀ` of the undeformed body, frame axes
    /// (kg·m²).
    pub e0: Matrix3<f64>,
    /// `[c·n + j]`.
    pub i3: Vec<f64>,
    /// `[c·n + j]`.
    pub ls: Vec<f64>,
    /// `[j·9 + 3r + c]`.
    pub p: Vec<f64>,
    /// `[(i·n + j)·9 + 3r + c]`.
    pub q: Vec<f64>,
    /// `[(i·n + j)·3 + c]`.
    pub v: Vec<f64>,
    /// Sum of the nodal rotary inertias `Σ J_k`, frame axes (kg·m²).
    pub j_rot: Matrix3<f64>,
    /// `[c·n + j]`.
    pub c_rot: Vec<f64>,
    /// `[i·n + j]`.
    pub mww: Vec<f64>,
    /// Λ (1/s²).
    pub lambda: Vec<f64>,
    /// The modal geometric stiffness of the unit load cases
    /// ([`Geometric::cases`], or its derivative); empty when the basis
    /// has none.
    pub kg: Vec<f64>,
}

impl Invariants {
    /// The invariants of `basis`.
    pub fn new(basis: &ModalBasis) -> Invariants {
        let mut inv = Invariants::of_shapes(basis, &ShapeMatrices::new(basis, &basis.shapes));
        inv.kg = basis
            .geometric
            .as_ref()
            .map_or(Vec::new(), |g| g.cases.clone());
        inv
    }

    /// The invariants of `basis` from its arranged shapes `sh`.
    fn of_shapes(basis: &ModalBasis, sh: &ShapeMatrices) -> Invariants {
        let (g, h) = (sh.gram(sh), sh.rot_gram(sh));
        let v = flat_sums(basis, &basis.shapes, (&g, &h), true);
        Invariants::from_flat(basis.n_modes, &v, basis.eigenvalues.clone())
    }

    /// The invariants of `basis` and their derivatives with respect to
    /// each of its design variables, exact: the sums are linear in the
    /// shapes `X` or bilinear (`G = ΦᵀMΦ`, `H = ΨᵀJΨ`), so a derivative
    /// takes the linear sums of `X'` and `G' = S + Sᵀ`, `S = Φ'ᵀMΦ` (and
    /// alike for `H`).
    pub fn with_derivatives(basis: &ModalBasis) -> (Invariants, Vec<Invariants>) {
        let n = basis.n_modes;
        let sh = ShapeMatrices::new(basis, &basis.shapes);
        let mut value = Invariants::of_shapes(basis, &sh);
        let geometric = basis.geometric.as_ref();
        value.kg = geometric.map_or(Vec::new(), |g| g.cases.clone());
        let sym =
            |s: Mat<f64>| Mat::<f64>::from_fn(s.nrows(), s.ncols(), |i, j| s[(i, j)] + s[(j, i)]);
        let derivs = basis
            .derivatives
            .iter()
            .enumerate()
            .map(|(v, d)| {
                let dsh = ShapeMatrices::new(basis, &d.shapes);
                let (dg, dh) = (sym(dsh.gram(&sh)), sym(dsh.rot_gram(&sh)));
                let dv = flat_sums(basis, &d.shapes, (&dg, &dh), false);
                let mut di = Invariants::from_flat(n, &dv, d.eigenvalues.clone());
                di.kg = geometric.map_or(Vec::new(), |g| g.derivatives[v].clone());
                di
            })
            .collect();
        (value, derivs)
    }

    fn from_flat(n: usize, v: &[f64], lambda: Vec<f64>) -> Invariants {
        let mut at = 0;
        let mut take = |len: usize| {
            let s = v[at..at + len].to_vec();
            at += len;
            s
        };
        let mass = take(1)[0];
        let s0 = Vector3::from_column_slice(&take(3));
        let e0 = Matrix3::from_row_slice(&take(9));
        let i3 = take(3 * n);
        let ls = take(3 * n);
        let p = take(9 * n);
        let q = take(9 * n * n);
        let vv = take(3 * n * n);
        let j_rot = Matrix3::from_row_slice(&take(9));
        let c_rot = take(3 * n);
        let mww = take(n * n);
        Invariants {
            n,
            mass,
            s0,
            e0,
            i3,
            ls,
            p,
            q,
            v: vv,
            j_rot,
            c_rot,
            mww,
            lambda,
            kg: Vec::new(),
        }
    }

    /// The flat layout of every entry that can depend on the design, in
    /// the order of `Invariants::from_flat` (for lifting into dual
    /// numbers), without Λ.
    pub fn len_flat(n: usize) -> usize {
        1 + 3 + 9 + 3 * n + 3 * n + 9 * n + 9 * n * n + 3 * n * n + 9 + 3 * n + n * n
    }
}

/// The mode shapes of a basis (or their derivatives) arranged for the
/// bilinear sums: `Φ` (`N × 3n`, row `k` = node `k`, column `r·n + j` =
/// component `r` of mode `j`) and `Ψ` (`3N × n`, row `3k + c`), with
/// `MΦ` and `JΨ` (rows scaled by the node masses and rotary inertias).
struct ShapeMatrices {
    phi: Mat<f64>,
    mphi: Mat<f64>,
    psi: Mat<f64>,
    jpsi: Mat<f64>,
}

impl ShapeMatrices {
    fn new(basis: &ModalBasis, shapes: &[f64]) -> ShapeMatrices {
        let (nn, n) = (basis.nodes.len(), basis.n_modes);
        let phi = Mat::<f64>::from_fn(nn, 3 * n, |k, col| {
            let (r, j) = (col / n, col % n);
            shapes[(k * 6 + r) * n + j]
        });
        let psi = Mat::<f64>::from_fn(3 * nn, n, |row, j| {
            let (k, c) = (row / 3, row % 3);
            shapes[(k * 6 + 3 + c) * n + j]
        });
        let mphi = Mat::<f64>::from_fn(nn, 3 * n, |k, col| basis.node_mass[k] * phi[(k, col)]);
        let jpsi = Mat::<f64>::from_fn(3 * nn, n, |row, j| {
            basis.node_inertia[row / 3][row % 3] * psi[(row, j)]
        });
        ShapeMatrices {
            phi,
            mphi,
            psi,
            jpsi,
        }
    }

    /// `Φᵀ M Φ_o` (`3n × 3n`), `Φ` of `self` and `Φ_o` of `other`.
    fn gram(&self, other: &ShapeMatrices) -> Mat<f64> {
        let c = self.phi.ncols();
        let mut g = Mat::<f64>::zeros(c, c);
        matmul(
            g.as_mut(),
            Accum::Replace,
            self.phi.transpose(),
            other.mphi.as_ref(),
            1.0,
            Par::Seq,
        );
        g
    }

    /// `Ψᵀ J Ψ_o` (`n × n`).
    fn rot_gram(&self, other: &ShapeMatrices) -> Mat<f64> {
        let c = self.psi.ncols();
        let mut h = Mat::<f64>::zeros(c, c);
        matmul(
            h.as_mut(),
            Accum::Replace,
            self.psi.transpose(),
            other.jpsi.as_ref(),
            1.0,
            Par::Seq,
        );
        h
    }
}

/// Every invariant sum in the order of [`Invariants::from_flat`]: the
/// sums linear in `shapes` (`i3`, `ls`, `p`, `c_rot`) node by node, the
/// bilinear ones read from `G` (`q_ij[r][c] = G[r·n+i, c·n+j]`, `v_ij`
/// its antisymmetric part, `mww = Σ_r G_rr + H`) and, when `constant`,
/// the design-independent `mass`, `s0`, `e0`, `j_rot` (zero otherwise:
/// node masses and positions do not depend on the design).
fn flat_sums(
    basis: &ModalBasis,
    shapes: &[f64],
    (g, h): (&Mat<f64>, &Mat<f64>),
    constant: bool,
) -> Vec<f64> {
    let n = basis.n_modes;
    let mut mass = 0.0;
    let mut s0 = Vector3::<f64>::zeros();
    let mut e0 = Matrix3::<f64>::zeros();
    let mut j_rot = Matrix3::<f64>::zeros();
    let mut i3 = vec![0.0; 3 * n];
    let mut ls = vec![0.0; 3 * n];
    let mut p = vec![0.0; 9 * n];
    let mut c_rot = vec![0.0; 3 * n];
    for (k, s) in basis.nodes.iter().enumerate() {
        let (m, jk) = (basis.node_mass[k], basis.node_inertia[k]);
        if constant {
            mass += m;
            s0 += s * m;
            e0 += s * s.transpose() * m;
            for c in 0..3 {
                j_rot[(c, c)] += jk[c];
            }
        }
        for j in 0..n {
            let phi = Vector3::from_fn(|c, _| shapes[(k * 6 + c) * n + j]);
            let mp = phi * m;
            let sxp = s.cross(&phi) * m;
            for c in 0..3 {
                i3[c * n + j] += mp[c];
                ls[c * n + j] += sxp[c];
                c_rot[c * n + j] += jk[c] * shapes[(k * 6 + 3 + c) * n + j];
                for r in 0..3 {
                    p[j * 9 + 3 * r + c] += mp[r] * s[c];
                }
            }
        }
    }
    let mut q = vec![0.0; 9 * n * n];
    let mut vv = vec![0.0; 3 * n * n];
    let mut mww = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let gg = |r: usize, c: usize| g[(r * n + i, c * n + j)];
            let o = (i * n + j) * 9;
            for r in 0..3 {
                for c in 0..3 {
                    q[o + 3 * r + c] = gg(r, c);
                }
            }
            let o = (i * n + j) * 3;
            vv[o] = gg(1, 2) - gg(2, 1);
            vv[o + 1] = gg(2, 0) - gg(0, 2);
            vv[o + 2] = gg(0, 1) - gg(1, 0);
            mww[i * n + j] = gg(0, 0) + gg(1, 1) + gg(2, 2) + h[(i, j)];
        }
    }
    let mut out = Vec::with_capacity(Invariants::len_flat(n));
    out.push(mass);
    out.extend(s0.iter().copied());
    out.extend(e0.transpose().iter().copied()); // row-major
    out.extend(i3);
    out.extend(ls);
    out.extend(p);
    out.extend(q);
    out.extend(vv);
    out.extend(j_rot.transpose().iter().copied());
    out.extend(c_rot);
    out.extend(mww);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::math::Scalar;
    use num_dual::Dual64;

    /// The definitions node by node (the table of the module doc), in any
    /// scalar, flattened in the order of [`Invariants::from_flat`]: the
    /// reference for the matrix-product sums.
    fn sums<T: Scalar>(basis: &ModalBasis, x: &dyn Fn(usize) -> T) -> Vec<T> {
        let n = basis.n_modes;
        let mut mass = T::zero();
        let mut s0 = Vector3::<T>::zeros();
        let mut e0 = Matrix3::<T>::zeros();
        let mut i3 = vec![T::zero(); 3 * n];
        let mut ls = vec![T::zero(); 3 * n];
        let mut p = vec![T::zero(); 9 * n];
        let mut q = vec![T::zero(); 9 * n * n];
        let mut vv = vec![T::zero(); 3 * n * n];
        let mut j_rot = Matrix3::<T>::zeros();
        let mut c_rot = vec![T::zero(); 3 * n];
        let mut mww = vec![T::zero(); n * n];
        let mut phi = vec![Vector3::<T>::zeros(); n];
        let mut psi = vec![Vector3::<T>::zeros(); n];
        for (k, s) in basis.nodes.iter().enumerate() {
            let m = T::from_subset(&basis.node_mass[k]);
            let jk = basis.node_inertia[k].map(|v| T::from_subset(&v));
            let s = s.map(|v| T::from_subset(&v));
            for j in 0..n {
                for c in 0..3 {
                    phi[j][c] = x((k * 6 + c) * n + j);
                    psi[j][c] = x((k * 6 + 3 + c) * n + j);
                }
            }
            mass += m;
            s0 += s * m;
            e0 += s * s.transpose() * m;
            for c in 0..3 {
                j_rot[(c, c)] += jk[c];
            }
            for j in 0..n {
                let mp = phi[j] * m;
                let sxp = s.cross(&phi[j]) * m;
                for c in 0..3 {
                    i3[c * n + j] += mp[c];
                    ls[c * n + j] += sxp[c];
                    c_rot[c * n + j] += jk[c] * psi[j][c];
                    for r in 0..3 {
                        p[j * 9 + 3 * r + c] += mp[r] * s[c];
                    }
                }
                for i in 0..n {
                    let pi = phi[i] * m;
                    let o = (i * n + j) * 9;
                    for r in 0..3 {
                        for c in 0..3 {
                            q[o + 3 * r + c] += pi[r] * phi[j][c];
                        }
                    }
                    let cr = pi.cross(&phi[j]);
                    for c in 0..3 {
                        vv[(i * n + j) * 3 + c] += cr[c];
                    }
                    mww[i * n + j] += pi.dot(&phi[j]) + psi[i].component_mul(&jk).dot(&psi[j]);
                }
            }
        }
        let mut out = Vec::with_capacity(Invariants::len_flat(n));
        out.push(mass);
        out.extend(s0.iter().copied());
        out.extend(e0.transpose().iter().copied()); // row-major
        out.extend(i3);
        out.extend(ls);
        out.extend(p);
        out.extend(q);
        out.extend(vv);
        out.extend(j_rot.transpose().iter().copied());
        out.extend(c_rot);
        out.extend(mww);
        out
    }

    /// Two point masses on a massless spring along x, one mode (the
    /// stretching mode), with a third rotary-inertia node.
    fn dumbbell() -> ModalBasis {
        let a = 0.5f64.sqrt();
        // Mode: masses 1 kg at ±1 m move ∓a along x (mass-normalized:
        // 2·a² = 1), plus a node with rotary inertia rotating 0.3 rad.
        let mut shapes = vec![0.0; 18];
        shapes[0] = -a;
        shapes[6] = a;
        shapes[12 + 5] = 0.3;
        ModalBasis {
            nodes: vec![
                Vector3::new(-1.0, 0.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::zeros(),
            ],
            node_mass: vec![1.0, 1.0, 0.0],
            node_inertia: vec![
                Vector3::zeros(),
                Vector3::zeros(),
                Vector3::new(0.0, 0.0, 0.2),
            ],
            n_modes: 1,
            shapes,
            eigenvalues: vec![4.0],
            derivatives: vec![BasisDerivative {
                name: "b".into(),
                eigenvalues: vec![1.0],
                shapes: {
                    let mut d = vec![0.0; 18];
                    d[6] = 2.0;
                    d
                },
            }],
            rigid: RigidScreen::default(),
            geometric: None,
        }
    }

    #[test]
    fn dumbbell_invariants_by_hand() {
        // Closed forms derived in this test from the definitions.
        let b = dumbbell();
        b.validate("b").unwrap();
        let inv = Invariants::new(&b);
        let a = 0.5f64.sqrt();
        assert_eq!(inv.mass, 2.0);
        assert!(inv.s0.norm() < 1e-15);
        assert!((inv.e0[(0, 0)] - 2.0).abs() < 1e-15);
        // i3 = Σ m Φ = −a + a = 0; ls = Σ m s × Φ = 0 (s ∥ Φ).
        assert!(inv.i3.iter().all(|v| v.abs() < 1e-15));
        assert!(inv.ls.iter().all(|v| v.abs() < 1e-15));
        // p = Σ m Φ sᵀ: (−a)(−1) + a·1 = 2a in entry (x, x).
        assert!((inv.p[0] - 2.0 * a).abs() < 1e-15);
        // q = Σ m Φ Φᵀ: 2a² = 1 in (x, x); v = 0.
        assert!((inv.q[0] - 1.0).abs() < 1e-15);
        // Rotary: c_rot z = 0.2·0.3, mww = 1 + 0.3²·0.2.
        assert!((inv.c_rot[2] - 0.06).abs() < 1e-15);
        assert!((inv.mww[0] - (1.0 + 0.018)).abs() < 1e-15);
        assert!((inv.j_rot[(2, 2)] - 0.2).abs() < 1e-15);
    }

    /// A basis of 7 nodes and 3 modes with deterministic pseudo-random
    /// positions, masses, inertias, shapes and shape derivatives.
    fn scrambled() -> ModalBasis {
        let r = |k: usize| ((k as f64 * 0.618_034 + 0.1).fract() - 0.5) * 2.0;
        let (nn, n) = (7, 3);
        ModalBasis {
            nodes: (0..nn)
                .map(|k| Vector3::new(r(3 * k), r(3 * k + 1), r(3 * k + 2)))
                .collect(),
            node_mass: (0..nn).map(|k| 1.0 + r(50 + k).abs()).collect(),
            node_inertia: (0..nn)
                .map(|k| Vector3::new(r(60 + k).abs(), r(70 + k).abs(), r(80 + k).abs()))
                .collect(),
            n_modes: n,
            shapes: (0..6 * nn * n).map(|i| r(100 + i)).collect(),
            eigenvalues: vec![1.0, 2.0, 3.0],
            derivatives: vec![BasisDerivative {
                name: "b".into(),
                eigenvalues: vec![0.1, 0.2, 0.3],
                shapes: (0..6 * nn * n).map(|i| r(400 + i)).collect(),
            }],
            rigid: RigidScreen::default(),
            geometric: None,
        }
    }

    #[test]
    fn matrix_product_sums_equal_the_node_by_node_definitions() {
        // Values from f64 sums, derivatives from dual-number sums of the
        // definitions, both node by node; the products agree to round-off.
        let b = scrambled();
        let (inv, d) = Invariants::with_derivatives(&b);
        let n = b.n_modes;
        let want =
            Invariants::from_flat(n, &sums::<f64>(&b, &|i| b.shapes[i]), b.eigenvalues.clone());
        let dual = sums::<Dual64>(&b, &|i| {
            Dual64::new(b.shapes[i], b.derivatives[0].shapes[i])
        });
        let eps: Vec<f64> = dual.iter().map(|x| x.eps).collect();
        let dwant = Invariants::from_flat(n, &eps, vec![0.1, 0.2, 0.3]);
        let close = |a: &Invariants, b: &Invariants, what: &str| {
            for (name, x, y) in [
                ("i3", &a.i3, &b.i3),
                ("ls", &a.ls, &b.ls),
                ("p", &a.p, &b.p),
                ("q", &a.q, &b.q),
                ("v", &a.v, &b.v),
                ("c_rot", &a.c_rot, &b.c_rot),
                ("mww", &a.mww, &b.mww),
            ] {
                for (u, v) in x.iter().zip(y) {
                    assert!((u - v).abs() < 1e-13, "{what} {name}: {u} vs {v}");
                }
            }
            assert!((a.e0 - b.e0).norm() < 1e-13 && (a.s0 - b.s0).norm() < 1e-13);
            assert!((a.j_rot - b.j_rot).norm() < 1e-13 && (a.mass - b.mass).abs() < 1e-13);
        };
        close(&inv, &want, "value");
        close(&d[0], &dwant, "derivative");
        assert_eq!(d[0].mass, 0.0);
    }

    #[test]
    fn invariant_derivatives_match_finite_differences() {
        // Central finite differences of the invariants along dX.
        let b = dumbbell();
        let (_, d) = Invariants::with_derivatives(&b);
        let h = 1e-6;
        let at = |t: f64| {
            let mut x = b.clone();
            for (s, ds) in x.shapes.iter_mut().zip(&b.derivatives[0].shapes) {
                *s += t * ds;
            }
            Invariants::new(&x)
        };
        let (ip, im) = (at(h), at(-h));
        let fd = |a: &[f64], b: &[f64]| -> Vec<f64> {
            a.iter().zip(b).map(|(x, y)| (x - y) / (2.0 * h)).collect()
        };
        for (an, num) in [
            (&d[0].p, fd(&ip.p, &im.p)),
            (&d[0].q, fd(&ip.q, &im.q)),
            (&d[0].mww, fd(&ip.mww, &im.mww)),
            (&d[0].i3, fd(&ip.i3, &im.i3)),
        ] {
            for (x, y) in an.iter().zip(&num) {
                assert!((x - y).abs() < 1e-8, "{x} vs {y}");
            }
        }
        assert_eq!(d[0].lambda, vec![1.0]);
        assert_eq!(d[0].mass, 0.0);
    }

    #[test]
    fn truncation_and_bad_input() {
        let mut b = dumbbell();
        b.n_modes = 1;
        assert_eq!(b.truncated(5).n_modes, 1);
        b.eigenvalues[0] = -1.0;
        let e = b.validate("scene.bodies[0].modal").unwrap_err().to_string();
        assert!(e.contains("eigenvalues[0]"), "{e}");
    }
}
