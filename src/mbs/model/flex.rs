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
//! ([`Invariants::with_derivatives`]). A ply thickness also moves the
//! node masses `m_k`, `J_k` ([`BasisDerivative::node_mass`]); every sum is
//! linear in them, so its derivative gains the same sum with `m_k'`,
//! `J_k'` in place of `m_k`, `J_k` and the shapes unchanged (and `mass`,
//! `s0`, `e0`, `j_rot` are no longer constant).

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
    /// `dm_k/db` of the lumped node masses (kg per unit of b); empty when
    /// the masses do not depend on b (ply angles). A ply thickness moves
    /// them.
    pub node_mass: Vec<f64>,
    /// `dJ_k/db` of the node rotary inertias; empty alike.
    pub node_inertia: Vec<Vector3<f64>>,
}

impl BasisDerivative {
    /// A derivative of the eigenvalues and shapes only (node masses
    /// independent of the variable).
    pub fn modal(name: String, eigenvalues: Vec<f64>, shapes: Vec<f64>) -> BasisDerivative {
        BasisDerivative {
            name,
            eigenvalues,
            shapes,
            node_mass: Vec::new(),
            node_inertia: Vec::new(),
        }
    }

    /// Does the variable move the node masses?
    pub fn moves_mass(&self) -> bool {
        !self.node_mass.is_empty()
    }
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
    /// `(asked, computed)`: the elastic modes asked for, when that count
    /// split a repeated eigenvalue and the split cluster's members were
    /// left out whole (`computed` of them kept; content and drops above
    /// count among those).
    pub split: Option<(usize, usize)>,
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
            let masses_ok = !d.moves_mass()
                || (d.node_mass.len() == nn
                    && d.node_inertia.len() == nn
                    && d.node_mass.iter().all(|v| v.is_finite())
                    && d.node_inertia
                        .iter()
                        .all(|v| v.iter().all(|x| x.is_finite())));
            if !masses_ok {
                return Err(Error::input(
                    format!("{key}.derivatives.{}.node_mass", d.name),
                    format!(
                        "{} mass and {} inertia derivatives",
                        d.node_mass.len(),
                        d.node_inertia.len()
                    ),
                    format!("none, or {nn} finite ones of each (one per node)"),
                ));
            }
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
                    node_mass: d.node_mass.clone(),
                    node_inertia: d.node_inertia.clone(),
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
    /// beams) or without modes (a body at rest, `scene::ground`) is
    /// returned as is. Error ([`Error::Numerical`]) if no mode would be
    /// left of some.
    pub fn screened(&self, limit: f64) -> Result<ModalBasis> {
        if self.n_modes == 0 || self.rigid.content.len() != self.n_modes {
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
                    node_mass: d.node_mass.clone(),
                    node_inertia: d.node_inertia.clone(),
                })
                .collect(),
            rigid: RigidScreen {
                content: keep.iter().map(|&j| self.rigid.content[j]).collect(),
                dropped,
                limit,
                split: self.rigid.split,
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
        let masses = (&basis.node_mass[..], &basis.node_inertia[..]);
        let v = flat_sums(basis, masses, &basis.shapes, (&g, &h), true);
        Invariants::from_flat(basis.n_modes, &v, basis.eigenvalues.clone())
    }

    /// The invariants of `basis` and their derivatives with respect to
    /// each of its design variables, exact: the sums are linear in the
    /// shapes `X` or bilinear (`G = ΦᵀMΦ`, `H = ΨᵀJΨ`), so a derivative
    /// takes the linear sums of `X'` and `G' = S + Sᵀ`, `S = Φ'ᵀMΦ` (and
    /// alike for `H`); a variable that moves the node masses adds the sums
    /// with the mass derivatives and the shapes unchanged (module doc).
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
                let masses = (&basis.node_mass[..], &basis.node_inertia[..]);
                let mut dv = flat_sums(basis, masses, &d.shapes, (&dg, &dh), false);
                if d.moves_mass() {
                    let dmasses = (&d.node_mass[..], &d.node_inertia[..]);
                    let msh = ShapeMatrices::with_masses(basis, &basis.shapes, dmasses);
                    let (mg, mh) = (msh.gram(&msh), msh.rot_gram(&msh));
                    let mv = flat_sums(basis, dmasses, &basis.shapes, (&mg, &mh), true);
                    dv.iter_mut().zip(&mv).for_each(|(a, b)| *a += b);
                }
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
        ShapeMatrices::with_masses(basis, shapes, (&basis.node_mass, &basis.node_inertia))
    }

    /// The arrangement with the node masses and inertias `(m, j)` in
    /// place of the basis's (their design derivatives).
    fn with_masses(
        basis: &ModalBasis,
        shapes: &[f64],
        (mass, inertia): (&[f64], &[Vector3<f64>]),
    ) -> ShapeMatrices {
        let (nn, n) = (basis.nodes.len(), basis.n_modes);
        let phi = Mat::<f64>::from_fn(nn, 3 * n, |k, col| {
            let (r, j) = (col / n, col % n);
            shapes[(k * 6 + r) * n + j]
        });
        let psi = Mat::<f64>::from_fn(3 * nn, n, |row, j| {
            let (k, c) = (row / 3, row % 3);
            shapes[(k * 6 + 3 + c) * n + j]
        });
        let mphi = Mat::<f64>::from_fn(nn, 3 * n, |k, col| mass[k] * phi[(k, col)]);
        let jpsi = Mat::<f64>::from_fn(3 * nn, n, |row, j| {
            inertia[row / 3][row % 3] * psi[(row, j)]
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
/// the sums without shapes `mass`, `s0`, `e0`, `j_rot` (zero otherwise:
/// for the shape-derivative part of a derivative). `(node_mass,
/// node_inertia)`: the masses of the sums (the basis's, or their
/// derivatives).
fn flat_sums(
    basis: &ModalBasis,
    (node_mass, node_inertia): (&[f64], &[Vector3<f64>]),
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
        let (m, jk) = (node_mass[k], node_inertia[k]);
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
#[path = "flex_tests.rs"]
mod tests;
