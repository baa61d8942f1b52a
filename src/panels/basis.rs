//! A panel's finite element modes as the [`ModalBasis`] of a floating-frame
//! flexible body (paper §2.1 Eq. 5–6, §3.1 Eqs. 18–19, §6.2).
//!
//! # What it produces
//! - `nodes`: every mesh node at `(x, y, 0)` in panel coordinates (the
//!   mid-surface is `z = 0`, the origin is the panel centre: the paper's
//!   clamped node). The body frame of the multibody model is this panel
//!   frame; [`ModalBasis::shifted`] moves its origin if a scene needs it.
//! - `node_mass`, `node_inertia`: the HRZ lumped mass of the shell element
//!   ([`crate::fe::Triangle::lumped_mass`]) summed per node over *all*
//!   nodes, constrained ones included (a clamped node still carries its
//!   mass, so the basis mass is `ρ·h·a·b`). `node_inertia` = (θx, θy, θz)
//!   entries of the lumped M: `Σ ρ∫z²dz · A/3` about x and y, and the
//!   element's small drilling inertia about z.
//! - `shapes`: the `n` lowest modes expanded to 6 components per node
//!   (`u, v, w, θx, θy, θz` = ux, uy, uz, rx, ry, rz of [`ModalBasis`];
//!   the element's θx, θy, θz are right-handed rotations about the frame
//!   axes), constrained DOFs = 0. They are the eigen-solver's mass-normalised
//!   modes, so with these node masses `Σ m Φᵀ Φ + Ψᵀ J Ψ = XᵀMX = I` and
//!   [`crate::mbs::Invariants`]' `mww` is the identity.
//! - `eigenvalues`: `λ = ω²` (1/s²), ascending, all > 0.
//! - `derivatives` (when asked): one [`BasisDerivative`] per design variable
//!   of the panel's [`crate::laminate::DesignMap`], named as in
//!   `mode_derivatives.csv` (`theta_1_4` ties plies 1 and 4), per radian of
//!   ply angle. Fixed-mode approach (Eq. 19): `dλ = xᵀK'x`, `dX = 0`.
//!   Updated-mode approach (Eq. 18): also `dX` by Nelson's method
//!   ([`crate::modal::derivatives`]). Node masses do not depend on the ply
//!   angles.
//!
//! # Method
//! The basis is a view of [`PanelAnalysis`] (assembly, shift-invert Lanczos
//! and eigen-derivatives of [`crate::modal`]): no second eigen-solver. A
//! [`BasisBuilder`] keeps the analysis (sparsity pattern, symbolic
//! factorization) across designs, so an optimization loop pays one assembly,
//! one numeric factorization and the Lanczos iteration per design;
//! [`panel_basis`] is the one-shot form. A design's ply thicknesses move
//! `K` and `M` alike: both are assembled anew for every design's laminate
//! and given to the eigen-solver (the symbolic factorization is kept, `M`
//! being diagonal). The lumped masses are recomputed per call from the
//! element geometry (O(elements)) and checked against the diagonal of M
//! the eigen-solver used, entry by entry.
//!
//! Measured (`benches/panel_basis_bench.rs`; SAR panel 3, 32 divisions,
//! 4152 DOF, 14 modes; 2-core x86_64 VM shared with other jobs, fastest of
//! 7): `panel_basis` 52 ms without derivatives, 58 ms fixed-mode, 135 ms
//! updated-mode for 2 variables, of which ≈ 32–38 ms is the one-off set-up
//! (pattern, symbolic factorization); per design with a reused
//! [`BasisBuilder`] 20 / 24 / 97 ms, the same as [`PanelAnalysis::run`]
//! alone (the basis conversion costs < 1 ms).
//!
//! # Supports and the floating frame
//! - `centre_clamp` (the paper's) and `central_patch`: the modes are those
//!   of the panel clamped at the frame origin, the frame is attached to the
//!   clamped node(s) — the classical choice of the paper (§6.2).
//! - `simply_supported`: as computed (edges held); rarely a sensible body.
//! - `free_free`: the six rigid-body modes are removed (only elastic modes
//!   are returned). The floating frame is then the undeformed body's frame
//!   (origin at the panel centre, which is also the lumped centre of mass:
//!   `Σ m_k s_k = 0`). The elastic modes are M-orthogonal to the rigid
//!   motions, so the invariants `i3 = Σ m Φ` vanish and `ls = Σ m s × Φ`
//!   equals `−c_rot = −Σ J Ψ` (the modes carry no momentum and no angular
//!   momentum about the centre). So `ls ≈ 0`: by Cauchy–Schwarz
//!   `|ls_c| ≤ √(Σ_k J_k,c)`, about `h/√(a² + b²)` of the translational
//!   scale `√(Σ m s²)` (measured 2e-6 on a 1 m × 0.6 m, 2 mm plate).
//!   `i3 = 0` and `ls + c_rot = 0` are the linearised Tisserand conditions
//!   of the lumped body (elastic motion carries no linear or angular
//!   momentum relative to the frame), so the frame/elastic inertia coupling
//!   `i3`, `ls + c_rot` vanishes to the solver's rounding (~1e-14 relative)
//!   and the frame is a mean frame of the deforming panel, attached to no
//!   material point: a joint at any node, the centre included, sees that
//!   node's elastic displacement `Φ_k w` (with the centre clamp, joints at
//!   the centre node see none).
//!
//! # Modes that are almost rigid motions
//! Every computed mode's rigid-body content `c = ‖Pφ‖²_M / ‖φ‖²_M`
//! ([`super::rigid`]: `P = R (RᵀMR)⁻¹ RᵀM` projects M-orthogonally onto
//! the six rigid motions `R` of the frame, all node masses included) is
//! recorded in [`ModalBasis::rigid`]. A scene's panel body then drops
//! every mode with `c >` its `rigid_limit` (default
//! [`RIGID_CONTENT_LIMIT`]` = 0.9`; [`ModalBasis::screened`], called in
//! [`crate::scene`]): the body has fewer modes than asked; the dropped
//! ones are listed with frequency and content, and `plyscape simulate`
//! prints them. `rigid_limit = 1` keeps every mode: right when the frame
//! is itself held at the clamped node (a panel welded at its centre to a
//! hub), where these modes are the clamp's real compliance and not a
//! second description of the frame's motion.
//!
//! Why (a free frame, the panel held by joints elsewhere, as in the SAR
//! scene). The strain energy does not see rigid motions (`K R = 0` for the
//! unconstrained panel, and a mode is zero on the clamped DOFs), so the
//! elastic part `(I − P)φ` of a mass-normalised mode has stiffness `λ` and
//! mass `1 − c`: in a floating-frame body, whose frame already carries the
//! rigid part `Pφ`, the mode moves at `ω/√(1 − c)`. The centre clamp's
//! in-plane (drilling) rotation has `c = 1 − 5e-7` at 32 divisions:
//! 8.5 Hz becomes `2π·8.5/√(5.4e-7) = 7.3e4 1/s`, the eigenvalue that
//! made the scene stiff (measured ±7.2e4i 1/s). The two rocking modes
//! (`c = 0.98–0.996`) are the same kind: a single clamped node has no
//! stiffness in the continuum limit, so these three modes tend to rigid
//! motions (`c → 1`, their frequencies depend on the mesh,
//! `docs/numerics.md`) and describe, up to a local dimple at the clamped
//! node, what the frame does; with the joints holding the panel the
//! dimple gives a 445 1/s eigenvalue (free–free basis: 148 1/s). Every
//! other mode has `c ≤ 0.575` (8–48 divisions), so the limit 0.9 sits in
//! a wide gap and the set of dropped modes does not change under small
//! changes of the ply angles.
//!
//! Why dropping and not a projection. Replacing `Φ` by `(I − P)Φ` and a
//! Rayleigh–Ritz step on `(ΦᵀK Φ, Φᵀ(I − P)ᵀM(I − P)Φ) = (Λ, I − BᵀG⁻¹B)`,
//! `B = RᵀMΦ`, `G = RᵀMR`, spans together with `R` the *same* space as
//! `Φ` with `R` and has the same stiffness: to first order it only moves
//! the frame from the clamped node to the mean axes. Its largest Ritz
//! value is at least every Rayleigh quotient `λ_j/(1 − c_j)` of the
//! subspace (the drilling mode's is `(7.3e4)²` again), so the nearly
//! rigid modes must be dropped in any case; dropping them from the
//! clamped basis is the simplest exact form. Exact derivatives: a kept
//! mode's `dλ/dθ`, `dX/dθ` (Eq. 18/19, Nelson) depend on that mode alone,
//! and neither `P` nor the dropped set depends on the ply angles (`M`
//! depends on density and thickness only; the set is fixed while no
//! content crosses the limit, guaranteed by the gap), so the basis's
//! derivatives are the columns of the kept modes
//! (`tests/suite/panels/basis.rs` checks them against central differences).
//! Free–free bases have `c ≈ 1e-23` (elastic modes are M-orthogonal to
//! `R`): nothing is dropped.
//!
//! # Repeated eigenvalues
//! A mode count that ends inside a cluster at this lay-up leaves the
//! cluster out whole ([`crate::modal::keep_whole_clusters`]): the basis
//! has fewer modes and `rigid.split` holds `(asked, computed)`.
//! In the updated-mode approach, the eigenvector derivatives of a cluster
//! of (nearly) repeated eigenvalues refer to adjacent vectors that depend
//! on the design variable ([`crate::modal::Cluster`]); one basis cannot
//! carry them for every variable, so such a basis is refused with
//! [`Error::Numerical`] naming the modes (change `n_modes` or the lay-up,
//! or use the fixed-mode approach). In the fixed-mode approach a cluster's
//! `dλ` are the eigenvalues of `X_CᵀK'X_C` (the one-sided derivatives of
//! the sorted eigenvalues).

use super::analysis::{group_name, in_panel, PanelAnalysis};
use super::rigid::RigidFrame;
use crate::error::{Error, Result};
use crate::fe::{Panel, NODE_DOF};
use crate::laminate::Laminate;
use crate::mbs::{BasisDerivative, ModalBasis, RigidScreen};
use crate::modal::ModeUpdate;
use crate::study::Study;
use nalgebra::Vector3;

/// A panel prepared for repeated basis computations (one per design):
/// mesh, sparsity pattern, symbolic factorization and element geometry are
/// built once in [`BasisBuilder::new`].
pub struct BasisBuilder {
    analysis: PanelAnalysis,
    update: Option<ModeUpdate>,
    geometric: bool,
    /// Panel-frame points whose nearest mesh nodes get the point-force
    /// cases of the joint-load prestress.
    points: Vec<Vector3<f64>>,
}

/// Lumped node masses of a panel: translational (kg) and rotary
/// (θx, θy, θz; kg·m²), one per mesh node.
struct NodeMasses {
    mass: Vec<f64>,
    inertia: Vec<Vector3<f64>>,
}

impl BasisBuilder {
    /// Set up the analysis of `panel`; `derivatives` selects what every
    /// later [`BasisBuilder::basis`] computes (none, fixed-mode `dλ`, or
    /// updated-mode `dλ` and `dX`).
    pub fn new(panel: &Panel, derivatives: Option<ModeUpdate>) -> Result<BasisBuilder> {
        Ok(BasisBuilder {
            analysis: PanelAnalysis::new(panel, derivatives)?,
            update: derivatives,
            geometric: false,
            points: Vec::new(),
        })
    }

    /// Compute (or not) the modal geometric stiffness of the inertial
    /// unit load cases (`panels::geometric`) with every later basis, and
    /// its ply-angle derivatives when the builder computes mode
    /// derivatives: what the scene effect `geometric_stiffening` needs.
    /// Off by default (12 static solves and, per design variable, 12 more).
    pub fn set_geometric(&mut self, on: bool) {
        self.geometric = on;
    }

    /// The joint points (panel frame, m) whose mesh nodes get the three
    /// point-force cases of the joint-load prestress with the geometric
    /// stiffness (`panels::geometric`; 3 more static solves per node and
    /// per design variable). A point farther than 1e-6 of the panel's
    /// size from every node is skipped (the scene refuses such a marker).
    pub fn set_joint_points(&mut self, points: &[Vector3<f64>]) {
        self.points = points.to_vec();
    }

    /// Differentiate every later basis also with respect to the ply
    /// thicknesses named in `names` (`thickness_<1-based plies>`, e.g.
    /// `thickness_1_4`: the common thickness \[m\] of plies 1 and 4), after
    /// the ply angles, when the builder computes derivatives. The node
    /// masses move with a thickness: the basis's derivatives carry them
    /// ([`BasisDerivative::node_mass`]). Errors: a name that is not
    /// `thickness_` with distinct ply numbers of the lay-up (key
    /// `thickness`).
    pub fn set_thickness(&mut self, names: &[String]) -> Result<()> {
        let n = self.analysis.panel.laminate.plies().len();
        let groups = names
            .iter()
            .map(|name| thickness_group(name, n))
            .collect::<Result<Vec<_>>>()?;
        self.analysis.set_thickness_groups(&groups)
    }

    /// The distinct mesh nodes at the joint points ([`mesh_joint_nodes`]).
    fn joint_nodes(&self) -> Vec<usize> {
        mesh_joint_nodes(&self.analysis.panel.mesh, &self.points)
    }

    /// The basis of the panel with lay-up `laminate` (same ply count as the
    /// panel's, angles in rad) and its `n_modes` lowest elastic modes.
    /// Errors: `n_modes` = 0 or more than the free DOFs → [`Error::Input`];
    /// solver failures, a non-positive eigenvalue or a cluster of repeated
    /// eigenvalues in the updated-mode approach → [`Error::Numerical`].
    pub fn basis(&mut self, laminate: &Laminate, n_modes: usize) -> Result<ModalBasis> {
        if n_modes == 0 {
            return Err(Error::input("n_modes", 0, "at least 1 mode"));
        }
        let run = self.analysis.run(laminate, n_modes)?;
        let lumped = self.node_masses(&run.frame)?;
        let nn = self.analysis.panel.mesh.nodes.len();
        let x = &run.modes.modes;
        for (j, &l) in run.modes.lambda.iter().enumerate() {
            if !(l.is_finite() && l > 0.0) {
                return Err(Error::numerical(
                    "panels::basis",
                    format!("eigenvalue {j} = {l:e} 1/s² is not positive"),
                ));
            }
        }
        // Every computed mode, with its rigid-body content; the scene
        // drops the nearly rigid ones (ModalBasis::screened).
        let keep: Vec<usize> = (0..run.modes.lambda.len()).collect();
        let rigid = RigidScreen {
            content: run.rigid_content.clone(),
            dropped: Vec::new(),
            limit: 1.0,
            split: run.asked.map(|a| (a, run.modes.lambda.len())),
        };
        let n = keep.len();
        // Scatter the kept columns of a free-DOF matrix (n_dof × computed)
        // into the 6-per-node layout.
        let expand = |m: &faer::Mat<f64>| -> Vec<f64> {
            let mut out = vec![0.0; NODE_DOF * nn * n];
            for (f, &(node, comp)) in run.dof_map.iter().enumerate() {
                let row = &mut out[(node * NODE_DOF + comp) * n..][..n];
                for (r, &j) in row.iter_mut().zip(&keep) {
                    *r = m[(f, j)];
                }
            }
            out
        };
        let shapes = expand(x);
        if self.geometric && self.update.is_some() && !self.analysis.thickness_groups().is_empty() {
            return Err(Error::input(
                "thickness_groups",
                format!("{:?}", self.analysis.thickness_groups()),
                "no ply-thickness variables with geometric stiffening (the geometric \
                 stiffness's thickness derivatives are not implemented)",
            ));
        }
        let geometric = if self.geometric {
            let dmodes: Vec<Option<&faer::Mat<f64>>> = run
                .derivatives
                .iter()
                .map(|d| match self.update {
                    Some(ModeUpdate::Updated) => d.dmodes.as_ref(),
                    _ => None,
                })
                .collect();
            Some(super::geometric::modal_geometric(
                &self.analysis,
                laminate,
                x,
                &dmodes,
                &self.joint_nodes(),
            )?)
        } else {
            None
        };
        let mut derivatives = Vec::with_capacity(run.derivatives.len());
        let n_angles = self.analysis.panel.design.len();
        let mut thickness = self.analysis.thickness_groups().iter().peekable();
        for (v, (d, name)) in run.derivatives.iter().zip(&run.variables).enumerate() {
            let dshapes = match (self.update, &d.dmodes) {
                (Some(ModeUpdate::Updated), Some(dx)) => {
                    if let Some(c) = d.clusters.first() {
                        return Err(Error::numerical(
                            "panels::basis",
                            format!(
                                "modes {}..={} (λ = {:?} 1/s²) form a cluster of repeated \
                                 eigenvalues: their eigenvector derivatives with respect to \
                                 {name} refer to variable-specific adjacent vectors; use the \
                                 fixed-mode approach, another n_modes or another lay-up",
                                c.first,
                                c.first + c.len - 1,
                                &run.modes.lambda[c.first..c.first + c.len]
                            ),
                        ));
                    }
                    expand(dx)
                }
                _ => vec![0.0; shapes.len()],
            };
            let mut bd = BasisDerivative::modal(
                name.clone(),
                keep.iter().map(|&j| d.dlambda[j]).collect(),
                dshapes,
            );
            if let Some(g) = thickness.next_if(|_| v >= n_angles) {
                (bd.node_mass, bd.node_inertia) = node_mass_derivatives(laminate, g, &lumped);
            }
            derivatives.push(bd);
        }
        Ok(ModalBasis {
            nodes: panel_nodes(&self.analysis.panel),
            node_mass: lumped.mass,
            node_inertia: lumped.inertia,
            n_modes: n,
            shapes,
            eigenvalues: keep.iter().map(|&j| run.modes.lambda[j]).collect(),
            derivatives,
            rigid,
            geometric,
        })
    }

    /// HRZ lumped masses of every node (from the analysis's
    /// [`RigidFrame`], i.e. from the laminate of this design); each free
    /// DOF's value is checked against the diagonal of M the eigen-solver
    /// used (the basis must be M-orthonormal with exactly these masses).
    fn node_masses(&self, frame: &RigidFrame) -> Result<NodeMasses> {
        let (mass, inertia) = (frame.mass().to_vec(), frame.inertia().to_vec());
        let solver_mass = self.analysis.solver.mass();
        for (f, &(node, comp)) in self.analysis.sys.dof_map.iter().enumerate() {
            let ours = if comp < 3 {
                mass[node]
            } else {
                inertia[node][comp - 3]
            };
            let m = solver_mass[f];
            if (ours - m).abs() > 1e-12 * m.abs() {
                return Err(Error::numerical(
                    "panels::basis::node_masses",
                    format!(
                        "lumped mass of node {node}, component {comp}: {ours:e} differs from \
                         the eigen-solver's M entry {m:e}"
                    ),
                ));
            }
        }
        Ok(NodeMasses { mass, inertia })
    }
}

/// The basis of a body at rest built from `panel` (the scene's `ground`
/// module): the panel's nodes and HRZ lumped masses for `laminate`, no
/// modes, and, when `derivatives` is given, one empty derivative per
/// design variable, the ply-angle groups' and then the thickness
/// variables `thickness` (names as [`BasisBuilder::set_thickness`]): their
/// names resolve the study's sensitivity lanes, whose values are then
/// zero. Neither `K` nor `M` is assembled and no eigen-analysis is done.
/// Errors: a bad thickness name (key `thickness`), the rigid frame's.
pub fn rest_basis(
    panel: &Panel,
    laminate: &Laminate,
    (derivatives, thickness): (Option<ModeUpdate>, &[String]),
) -> Result<ModalBasis> {
    let frame = RigidFrame::of_panel(panel, laminate)?;
    let n = panel.laminate.plies().len();
    let thickness = thickness
        .iter()
        .map(|name| Ok(group_name("thickness", &thickness_group(name, n)?)))
        .collect::<Result<Vec<_>>>()?;
    let names = (panel.design.groups().iter())
        .map(|g| group_name("theta", g))
        .chain(thickness);
    let derivatives = match derivatives {
        Some(_) => names
            .map(|name| BasisDerivative::modal(name, Vec::new(), Vec::new()))
            .collect(),
        None => Vec::new(),
    };
    Ok(ModalBasis {
        nodes: panel_nodes(panel),
        node_mass: frame.mass().to_vec(),
        node_inertia: frame.inertia().to_vec(),
        n_modes: 0,
        shapes: Vec::new(),
        eigenvalues: Vec::new(),
        derivatives,
        rigid: RigidScreen {
            content: Vec::new(),
            dropped: Vec::new(),
            limit: 1.0,
            split: None,
        },
        geometric: None,
    })
}

/// The mesh nodes of `panel` in its frame (m, `z = 0`).
fn panel_nodes(panel: &Panel) -> Vec<Vector3<f64>> {
    (panel.mesh.nodes.iter())
        .map(|p| Vector3::new(p[0], p[1], 0.0))
        .collect()
}

/// The distinct nodes of `mesh` at the panel-frame points `points`, in
/// the order first met: each point's nearest node, if it lies within
/// `1e-6` of the panel's size (the largest node distance from the
/// centre, at least 1 mm); farther points are skipped.
pub(crate) fn mesh_joint_nodes(mesh: &crate::fe::Mesh, points: &[Vector3<f64>]) -> Vec<usize> {
    let nodes = &mesh.nodes;
    let at = |k: usize| Vector3::new(nodes[k][0], nodes[k][1], 0.0);
    let size = (0..nodes.len()).fold(1e-3f64, |m, k| m.max(at(k).norm()));
    let mut out = Vec::new();
    for p in points {
        let near = (0..nodes.len())
            .map(|k| (k, (at(k) - p).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((k, d)) = near {
            if d <= 1e-6 * size && !out.contains(&k) {
                out.push(k);
            }
        }
    }
    out
}

/// The 0-based plies of a thickness variable's name `thickness_<plies>`
/// (1-based, distinct, within `1..=n`).
pub fn thickness_group(name: &str, n: usize) -> Result<Vec<usize>> {
    let bad = || {
        Error::input(
            "thickness",
            format!("\"{name}\""),
            format!("thickness_<ply>[_<ply>...] with distinct ply numbers in 1..={n}"),
        )
    };
    let rest = name.strip_prefix("thickness_").ok_or_else(bad)?;
    let mut g = Vec::new();
    for p in rest.split('_') {
        let k: usize = p.parse().map_err(|_| bad())?;
        if k == 0 || k > n || g.contains(&(k - 1)) {
            return Err(bad());
        }
        g.push(k - 1);
    }
    Ok(g)
}

/// `dm_k/ds`, `dJ_k/ds` of the HRZ node masses for the common thickness
/// `s` of the plies of `group`: the lumped masses are linear in the mass
/// and rotary inertia per area (`fe::element`: `m/3` and `J_z ∝ m` per
/// node, `J_x = J_y ∝ I`), so each scales with its per-area quantity:
/// `m_k' = m_k μ'/μ`, `J_kx' = J_kx I'/I`, `J_kz' = J_kz μ'/μ`.
fn node_mass_derivatives(
    laminate: &Laminate,
    group: &[usize],
    lumped: &NodeMasses,
) -> (Vec<f64>, Vec<Vector3<f64>>) {
    let td = laminate.thickness_group_derivative(group);
    let rm = td.mass / laminate.mass_per_area();
    let ri = td.rotary[0] / laminate.rotary_inertia_per_area();
    let mass = lumped.mass.iter().map(|m| m * rm).collect();
    let inertia = lumped
        .inertia
        .iter()
        .map(|j| Vector3::new(j.x * ri, j.y * ri, j.z * rm))
        .collect();
    (mass, inertia)
}

/// Largest rigid-body content `c` a mode of a basis may have (module doc,
/// "Modes that are almost rigid motions"). 0.9: a kept mode is at most
/// 90 % frame motion, so the frame raises its frequency by at most
/// `1/√(1 − c) = 3.2`. It lies in a wide gap of the centre clamp's
/// spectrum: rocking and drilling modes have `c ≥ 0.979`, every other
/// mode `c ≤ 0.575` (SAR panel, 8 to 48 divisions).
pub const RIGID_CONTENT_LIMIT: f64 = 0.9;

/// The modal basis of a panel for a floating-frame flexible body (module
/// doc): mesh nodes (panel coordinates, `z = 0` mid-surface, origin at the
/// panel centre = the paper's clamped node), HRZ lumped node masses
/// (translational) and rotary inertias (rotational diagonal of M), the
/// `n_modes` lowest modes expanded to 6 components per node (constrained
/// DOFs = 0), eigenvalues (1/s²), and — when asked — derivatives with
/// respect to the panel's design variables (`dΛ/dθ`, `dX/dθ` per rad) by
/// the fixed-mode (Eq. 19: `dX = 0`, `dλ = xᵀK'x`) or updated-mode
/// (Eq. 18: Nelson `dX`) approach. Free–free panels: elastic modes only.
/// For many designs of one panel use [`BasisBuilder`].
pub fn panel_basis(
    panel: &Panel,
    n_modes: usize,
    derivatives: Option<ModeUpdate>,
) -> Result<ModalBasis> {
    panel_basis_geometric(panel, n_modes, derivatives, None)
}

/// [`panel_basis`] with the modal geometric stiffness of the inertial
/// unit load cases ([`BasisBuilder::set_geometric`]) when `geometric` is
/// given, and the point-force cases at the nodes of the panel-frame
/// joint points it lists ([`BasisBuilder::set_joint_points`]).
pub fn panel_basis_geometric(
    panel: &Panel,
    n_modes: usize,
    derivatives: Option<ModeUpdate>,
    geometric: Option<&[Vector3<f64>]>,
) -> Result<ModalBasis> {
    if n_modes == 0 {
        return Err(Error::input("n_modes", 0, "at least 1 mode"));
    }
    let mut builder = BasisBuilder::new(panel, derivatives)?;
    builder.set_geometric(geometric.is_some());
    builder.set_joint_points(geometric.unwrap_or(&[]));
    builder
        .basis(&panel.laminate, n_modes)
        .map_err(|e| in_panel(e, &panel.name))
}

/// [`panel_basis`] for the panel named `name` in the study's `[[panels]]`
/// section (with the geometric stiffness and joint points of `geometric`,
/// as [`panel_basis_geometric`]). Errors name
/// the study file: an unknown name is an input error on key `panels.name`
/// listing the names available; errors of the panel entry carry
/// `panels[i]`.
pub fn basis_for_study(
    study: &Study,
    name: &str,
    n_modes: usize,
    derivatives: Option<ModeUpdate>,
    geometric: Option<&[Vector3<f64>]>,
) -> Result<ModalBasis> {
    basis_for_study_thickness(study, name, n_modes, (derivatives, &[]), geometric)
}

/// [`basis_for_study`] whose derivatives (when `derivatives` is `Some`)
/// include the ply thicknesses `thickness` (names as
/// [`BasisBuilder::set_thickness`]) after the ply angles.
pub fn basis_for_study_thickness(
    study: &Study,
    name: &str,
    n_modes: usize,
    (derivatives, thickness): (Option<ModeUpdate>, &[String]),
    geometric: Option<&[Vector3<f64>]>,
) -> Result<ModalBasis> {
    if n_modes == 0 {
        return Err(Error::input("n_modes", 0, "at least 1 mode"));
    }
    with_study_panel(study, name, |panel| {
        let mut builder = BasisBuilder::new(panel, derivatives)?;
        builder.set_thickness(thickness)?;
        builder.set_geometric(geometric.is_some());
        builder.set_joint_points(geometric.unwrap_or(&[]));
        builder.basis(&panel.laminate, n_modes)
    })
}

/// The basis of a body at rest built from the study's panel `name`
/// ([`rest_basis`]: nodes and masses, no modes; errors as
/// [`basis_for_study`]).
pub fn rest_basis_for_study(
    study: &Study,
    name: &str,
    variables: (Option<ModeUpdate>, &[String]),
) -> Result<ModalBasis> {
    with_study_panel(study, name, |panel| {
        rest_basis(panel, &panel.laminate, variables)
    })
}

/// `make` for the study's panel `name`, its errors located in the
/// panel's entry; an unknown name is [`unknown_panel`].
fn with_study_panel(
    study: &Study,
    name: &str,
    make: impl FnOnce(&Panel) -> Result<ModalBasis>,
) -> Result<ModalBasis> {
    let panels = crate::fe::panels_from_study(study)?;
    let Some(i) = panels.iter().position(|p| p.name == name) else {
        return Err(unknown_panel(study, name, &panels));
    };
    let panel = &panels[i];
    make(panel)
        .map_err(|e| in_panel(e, &panel.name))
        .map_err(|e| e.in_file(&study.path, &format!("panels[{i}]")))
}

/// The error for a panel name that no `[[panels]]` entry of `study` has:
/// key `panels.name`, with the names available.
pub fn unknown_panel(study: &Study, name: &str, panels: &[Panel]) -> Error {
    let names: Vec<String> = panels.iter().map(|p| format!("\"{}\"", p.name)).collect();
    let expected = if names.is_empty() {
        "the name of a [[panels]] entry (the study has none)".to_string()
    } else {
        format!("the name of a [[panels]] entry: {}", names.join(", "))
    };
    study.error("panels.name", format!("\"{name}\""), expected)
}
