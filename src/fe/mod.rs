//! Panel finite elements: mesh, laminated shell triangle, sparse assembly,
//! supports (paper §2.2, §3.2 Eq. 20, §6.2).
//!
//! # API (what the modal analysis takes from here)
//!
//! ```text
//! let panels = fe::panels_from_study(&study)?;         // [[panels]] of a study file, or by hand:
//! let mesh   = Mesh::structured(&MeshParams { length, width, divisions, points })?;
//! let model  = PanelModel::new(mesh, Support::CentreClamp)?;   // pattern + scatter map, once
//! let sys    = model.assemble(&laminate, &design_map, Derivatives::Second)?;
//! // or in one shot: fe::assemble(&mesh, &laminate, support, &design_map, Derivatives::First)?
//! model.assemble_into(&new_laminate, &design_map, &mut sys)?;   // reuse buffers in a loop
//!
//! sys.k        : SparseColMat<usize, f64>       reduced K_ff (supports applied), n × n,
//!                                               both triangles stored, symmetric
//! sys.m_diag   : Vec<f64>                       lumped diagonal M (HRZ), same DOF order;
//!                                               independent of the ply angles
//! sys.dk[v]    : SparseColMat (same pattern)    dK/dθ_v, v = design variable   (First, Second)
//! sys.d2k[v]   : SparseColMat (same pattern)    d²K/dθ_v²                      (Second)
//! sys.d2k_mixed(v, w)                           Some(&d2k[v]) if v == w, None (= exactly 0) otherwise
//! sys.dof_map  : Vec<(node, component)>         free DOF → node, 0..6 = u, v, w, θx, θy, θz
//! sys.nodes    : Vec<[x, y]>                    panel coordinates, origin at the centre [m]
//! sys.rigid_modes : Vec<Vec<f64>>               FreeFree only: 6 M-orthonormal rigid-body modes
//! ```
//!
//! Angles in radians; a design variable ties one or more plies
//! ([`crate::laminate::DesignMap`]; the paper's [θ1/θ2/θ2/θ1] is
//! `DesignMap::symmetric(4)`). Derivatives are assembled only when asked
//! for. K depends on the ply angles only through A, B, D, S, so
//! `dK/dθ_v = Σ_e A_e Gᵀ (∂C/∂θ_v) G` with the element operators unchanged
//! (Eq. 20); M does not depend on them.
//!
//! # Method
//! - [`mesh`]: structured triangle grid with lines through every attachment
//!   point, patch corner and the centre.
//! - [`element`]: stabilised DSG3 Mindlin–Reissner triangle with CST
//!   membrane + Hughes–Brezzi drilling, full A–B–D coupling, HRZ mass; the
//!   module doc says why this element.
//! - [`assembly`]: supports by elimination; the sparsity pattern and the
//!   position of every element entry are computed once per model, each
//!   assembly fills values in a fixed order (bit-for-bit deterministic).
//! - [`spec`]: the `[[panels]]` study-file section.
//!
//! # Measured (tests/suite/fe/*.rs; 2-core x86_64 VM)
//! - SS square plate, uniform load, 32×32 cells: centre deflection within
//!   0.24 % of the Kirchhoff series at a/h = 1000 and 0.19 % of the FSDT
//!   Navier series at a/h = 10 (no shear locking; second-order convergence).
//! - SS square plate, 24×24 cells: lowest four frequencies within 0.34 % of
//!   the closed form.
//! - Assembly of K for SAR panel 3 (`assemble_into`, buffers reused; wall
//!   time, min of 21, on the VM loaded by other jobs): 0.5 ms at 20
//!   divisions (1 884 DOF), 1.9 ms at 40 (6 636 DOF), 4.8 ms at 64
//!   (15 984 DOF, the ≈0.5 % mesh), 9.9 ms at 80. Each derivative matrix
//!   costs about as much as K. The cost is dominated by the scatter into
//!   the value array (memory bound); the per-element entry lists are sorted
//!   by position for locality.
//!
//! # Limitations
//! - Flat panels only (the element is a flat facet; no curvature).
//! - CST membrane: stiff in in-plane bending; irrelevant for the flexural
//!   modes of symmetric lay-ups, coarse for in-plane dominated ones.
//! - Lumped mass ignores the first-moment coupling inertia of unsymmetric
//!   lay-ups.

pub mod assembly;
pub mod element;
pub mod mesh;
pub mod spec;
pub mod thickness;

pub use assembly::{
    assemble, Derivatives, PanelModel, PanelSystem, Support, SupportKind, NODE_DOF,
};
pub use element::{section_matrix, Triangle};
pub use mesh::{Mesh, MeshParams};
pub use spec::{panels_from_study, Panel, PanelSpec};
pub use thickness::ThicknessSystem;
