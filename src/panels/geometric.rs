//! Geometric stiffening of a panel body: the membrane prestress of the
//! inertial unit load cases ([`crate::mbs::model::geometric`]) and its
//! geometric stiffness in the panel's modal coordinates, with exact
//! ply-angle derivatives.
//!
//! # Prestress of a unit load case
//! Case `k` loads the panel with the body force per unit mass `b_k(s)` at
//! the undeformed node `s = (x, y, 0)` (panel frame, the body frame of the
//! basis). With the lumped masses `m_p` of the shell element the nodal
//! load is `f_k = m_p b_k(s_p)` on the translations of every free DOF (the
//! rotary inertia is not loaded: its moments are `O(h²)` smaller). The
//! displacement `u_k` solves the panel's own static problem `K u_k = f_k`
//! with the supports of its modes — the beam's choice (the beam is held
//! at its clamped root, where its modes are clamped):
//! - `centre_clamp`, `central_patch`, `simply_supported`: the supports
//!   take the reactions (one `LLᵀ` of the reduced `K`);
//! - `free_free`: no support, so the load is balanced by the body's own
//!   rigid-body acceleration (*inertia relief*, as in MSC Nastran's
//!   `INREL`): `f_k ← (I − M R Rᵀ) f_k` with the M-orthonormal rigid modes
//!   `R`, and `u_k` the solution M-orthogonal to `R`
//!   ([`crate::modal::ModalSolver::solve_static`]). The joint reactions of
//!   the mechanism are not known when the basis is built; they enter at
//!   run time through the joint-load cases below (their own stress
//!   fields, solved the same way).
//!
//! Per element the membrane resultants are `N_k = A ε(u_k) + B κ(u_k)`
//! (N/m per unit coefficient; constant over the CST), and the geometric
//! stiffness is `K_G,k = Σ_e ∫ [w,x w,y]ᵀ N_k [w,x w,y] dA`
//! ([`crate::fe::Triangle::geometric_stiffness`], the von Kármán term;
//! the in-plane terms are left out, as the beam leaves out its axial
//! one). Projected on the mass-normalized modes `X` (w rows):
//! `K_k,ij = Σ_e A_e (∇w_i)ᵀ N_k,e ∇w_j`, units of the table in
//! [`crate::mbs::model::geometric`].
//!
//! # Joint-load cases
//! For each joint node `P` ([`crate::mbs::model::geometric`], "Joint-load
//! prestress") the load is a unit force `e_a` on the translations of `P`
//! (no mass factor), solved and projected exactly as above — on a
//! free–free panel inertia relief balances it by the rigid-body
//! acceleration, which is what the rest of the mechanism's joints and
//! the panel's own inertia share. Units: 1/s² per N.
//!
//! # Ply-angle derivatives (exact)
//! For a design variable `θ` with `K' = dK/dθ` (paper Eq. 20) and
//! `A' , B'` from [`crate::laminate::Laminate::design_derivative`]: the
//! loads do not depend on `θ` (M does not), so `K u' = −K' u` (the same
//! static solve, inertia relief included: `K'` has the rigid modes in
//! its null space); `N' = A' ε + B' κ + A ε(u') + B κ(u')`; and
//! `K'_k,ij = Σ_e A_e [(∇w'_i)ᵀ N ∇w_j + (∇w_i)ᵀ N ∇w'_j + (∇w_i)ᵀ N' ∇w_j]`
//! with the mode derivatives `X'` of the updated-mode approach (zero in
//! the fixed-mode approach, Eq. 19, which then keeps only the prestress
//! derivative).

use super::analysis::PanelAnalysis;
use crate::error::{Error, Result};
use crate::fe::element::Vec18;
use crate::fe::{Support, NODE_DOF};
use crate::laminate::Laminate;
use crate::mbs::model::geometric::{case_load, Geometric, CASES};
use faer::sparse::SparseColMat;
use faer::Mat;
use nalgebra::Vector3;

/// `y = A x` for each column of `x` (both triangles of `A` stored).
fn sparse_mul(a: &SparseColMat<usize, f64>, x: &Mat<f64>) -> Mat<f64> {
    let mut y = Mat::<f64>::zeros(x.nrows(), x.ncols());
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    for c in 0..x.ncols() {
        for j in 0..x.nrows() {
            let xj = x[(j, c)];
            if xj != 0.0 {
                for p in cp[j]..cp[j + 1] {
                    y[(ri[p], c)] += v[p] * xj;
                }
            }
        }
    }
    y
}

/// The static solve of the module doc (supports or inertia relief),
/// in place on the loads `b` (free DOFs × columns).
fn static_solve(an: &PanelAnalysis, b: &mut Mat<f64>) -> Result<()> {
    let free = an.panel.support == Support::FreeFree;
    let rigid: &[Vec<f64>] = if free { &an.sys.rigid_modes } else { &[] };
    an.solver
        .solve_static(b.as_mut(), rigid, super::FREE_FREE_SHIFT)?;
    Ok(())
}

/// Per element: its displacement vector in element DOF order from the
/// free-DOF column `c` of `u`.
fn element_vector(an: &PanelAnalysis, nodes: &[usize; 3], u: &Mat<f64>, c: usize) -> Vec18 {
    Vec18::from_fn(|d, _| {
        an.model
            .free_dof(nodes[d / NODE_DOF], d % NODE_DOF)
            .map_or(0.0, |f| u[(f, c)])
    })
}

/// The slopes `∇w` of every column of `x` (modes) on element `nodes`.
fn mode_slopes(
    an: &PanelAnalysis,
    tri: &crate::fe::Triangle,
    nodes: &[usize; 3],
    x: &Mat<f64>,
) -> Vec<[f64; 2]> {
    let dofs: [Option<usize>; 3] = std::array::from_fn(|i| an.model.free_dof(nodes[i], 2));
    (0..x.ncols())
        .map(|j| tri.slope(std::array::from_fn(|i| dofs[i].map_or(0.0, |f| x[(f, j)]))))
        .collect()
}

/// Add `A Σ (∇a_i)ᵀ N ∇b_j` to the n × n block `k` (row-major).
fn add_block(k: &mut [f64], area: f64, n: [f64; 3], ga: &[[f64; 2]], gb: &[[f64; 2]]) {
    let m = ga.len();
    for (i, a) in ga.iter().enumerate() {
        let (nx, ny) = (n[0] * a[0] + n[2] * a[1], n[2] * a[0] + n[1] * a[1]);
        for (j, b) in gb.iter().enumerate() {
            k[i * m + j] += area * (nx * b[0] + ny * b[1]);
        }
    }
}

/// The modal geometric stiffness of the unit load cases (module doc) for
/// the modes `x` (free DOFs × n, mass-normalized) of the analysis's last
/// run with lay-up `laminate`, and its derivative for each design
/// variable `v` with `dmodes[v]` = `dX/dθ_v` (None: fixed-mode, `dX = 0`);
/// after the inertial cases, the three point-force cases of each mesh
/// node in `points` (joint-load prestress: a unit force along x, y, z on
/// the node's translations, held like the inertial cases; a force on a
/// supported DOF goes into the support and stresses nothing).
/// The derivatives need the analysis's `dK/dθ_v` (built with mode
/// derivatives).
pub(super) fn modal_geometric(
    an: &PanelAnalysis,
    laminate: &Laminate,
    x: &Mat<f64>,
    dmodes: &[Option<&Mat<f64>>],
    points: &[usize],
) -> Result<Geometric> {
    let (sys, mesh) = (&an.sys, &an.panel.mesh);
    let (nd, n) = (sys.m_diag.len(), x.ncols());
    if dmodes.len() > sys.dk.len() {
        return Err(Error::numerical(
            "panels::geometric",
            format!(
                "{} mode derivatives but {} stiffness derivatives assembled",
                dmodes.len(),
                sys.dk.len()
            ),
        ));
    }
    let cols = CASES + 3 * points.len();
    let mut u = Mat::<f64>::from_fn(nd, cols, |f, k| {
        let (node, comp) = sys.dof_map[f];
        if comp >= 3 {
            return 0.0;
        }
        if k >= CASES {
            let (p, a) = ((k - CASES) / 3, (k - CASES) % 3);
            return if points[p] == node && a == comp {
                1.0
            } else {
                0.0
            };
        }
        let p = mesh.nodes[node];
        sys.m_diag[f] * case_load(k, &Vector3::new(p[0], p[1], 0.0))[comp]
    });
    static_solve(an, &mut u)?;
    let st = laminate.stiffness();
    // du/dθ_v and dA, dB per variable.
    let mut du = Vec::with_capacity(dmodes.len());
    let mut dst = Vec::with_capacity(dmodes.len());
    for v in 0..dmodes.len() {
        let mut r = sparse_mul(&sys.dk[v], &u);
        for e in r.col_iter_mut() {
            for y in e.iter_mut() {
                *y = -*y;
            }
        }
        static_solve(an, &mut r)?;
        du.push(r);
        dst.push(laminate.design_derivative(&an.panel.design, v));
    }
    let nn = n * n;
    let mut cases = vec![0.0; cols * nn];
    let mut derivatives = vec![vec![0.0; cols * nn]; dmodes.len()];
    for (e, nodes) in mesh.triangles.iter().enumerate() {
        let (tri, _) = an.model.element(e);
        let ops = an.model.element_ops(e);
        let g = mode_slopes(an, tri, nodes, x);
        let dg: Vec<Option<Vec<[f64; 2]>>> = dmodes
            .iter()
            .map(|d| d.map(|d| mode_slopes(an, tri, nodes, d)))
            .collect();
        for k in 0..cols {
            let q = element_vector(an, nodes, &u, k);
            let nk = tri.membrane_resultants(ops, &st.a, &st.b, &q);
            let block = &mut cases[k * nn..(k + 1) * nn];
            add_block(block, tri.area, nk, &g, &g);
            for v in 0..dmodes.len() {
                let dq = element_vector(an, nodes, &du[v], k);
                let n1 = tri.membrane_resultants(ops, &dst[v].a, &dst[v].b, &q);
                let n2 = tri.membrane_resultants(ops, &st.a, &st.b, &dq);
                let dn = [n1[0] + n2[0], n1[1] + n2[1], n1[2] + n2[2]];
                let block = &mut derivatives[v][k * nn..(k + 1) * nn];
                add_block(block, tri.area, dn, &g, &g);
                if let Some(dg) = &dg[v] {
                    add_block(block, tri.area, nk, dg, &g);
                    add_block(block, tri.area, nk, &g, dg);
                }
            }
        }
    }
    // Exact symmetry (the sums above are symmetric up to rounding).
    for m in std::iter::once(&mut cases).chain(derivatives.iter_mut()) {
        for k in 0..cols {
            for i in 0..n {
                for j in 0..i {
                    let (a, b) = (k * nn + i * n + j, k * nn + j * n + i);
                    let s = 0.5 * (m[a] + m[b]);
                    m[a] = s;
                    m[b] = s;
                }
            }
        }
    }
    if let Some(i) = cases.iter().position(|v| !v.is_finite()) {
        return Err(Error::numerical(
            "panels::geometric",
            format!("geometric stiffness entry {i} is {}", cases[i]),
        ));
    }
    Ok(Geometric {
        n,
        cases,
        derivatives,
        point_nodes: points.to_vec(),
    })
}
