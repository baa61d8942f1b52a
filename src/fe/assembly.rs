//! Supports, sparse assembly of K, lumped M and the ply-angle derivatives.
//!
//! The sparsity pattern of the reduced (supports applied) stiffness and the
//! position of every element entry in it are computed once, in
//! [`PanelModel::new`]; each assembly then only fills a value array
//! (deterministic: fixed element order, fixed summation order).

use super::element::{
    section_matrix, CompactOps, Mat18, Mat8, Mat8x18, Triangle, DRILLING_PENALTY,
};
use super::mesh::Mesh;
use crate::error::{require_positive, Error, Result};
use crate::laminate::{DesignMap, Laminate};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// DOF per node: u, v, w, θx, θy, θz.
pub const NODE_DOF: usize = 6;
pub(super) const NONE: usize = usize::MAX;
/// Positions in the scatter map are u32 (half the memory traffic of usize).
const MAX_STORED: usize = u32::MAX as usize;

/// The kind of support as written in study files (`[[panels]] support`):
/// `centre_clamp` (also `center_clamp`, the default), `central_patch`
/// (with `patch_size`), `simply_supported` or `free_free`;
/// [`Support::new`] gives the [`Support`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SupportKind {
    /// [`Support::CentreClamp`].
    #[default]
    #[serde(alias = "center_clamp")]
    CentreClamp,
    /// [`Support::CentralPatch`] of `patch_size`.
    CentralPatch,
    /// [`Support::SimplySupported`].
    SimplySupported,
    /// [`Support::FreeFree`].
    FreeFree,
}

/// Reference (boundary) condition of a panel for its modes (paper §6.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Support {
    /// The paper's condition: the centre node clamped (all 6 DOF).
    CentreClamp,
    /// All nodes of the central rectangle |x| ≤ length/2, |y| ≤ width/2
    /// clamped (its corners must be mesh nodes: see
    /// [`Support::forced_points`]). Sizes in m.
    CentralPatch {
        /// Side of the patch along x (m).
        length: f64,
        /// Side of the patch along y (m).
        width: f64,
    },
    /// Hard simple support on all four edges (Reddy's SS-1): w = 0,
    /// tangential displacement = 0 and rotation about the edge normal = 0
    /// (x = ±L/2: v = θx = 0; y = ±W/2: u = θy = 0).
    SimplySupported,
    /// No support: K has the six rigid-body modes as null space;
    /// [`PanelSystem::rigid_modes`] gives them.
    FreeFree,
}

impl Support {
    /// The support of `kind`; `patch` = [length, width] \[m\] is required
    /// for (and only used by) [`SupportKind::CentralPatch`]. Error keys:
    /// `patch_size`.
    pub fn new(kind: SupportKind, patch: Option<[f64; 2]>) -> Result<Support> {
        match kind {
            SupportKind::CentreClamp => Ok(Support::CentreClamp),
            SupportKind::SimplySupported => Ok(Support::SimplySupported),
            SupportKind::FreeFree => Ok(Support::FreeFree),
            SupportKind::CentralPatch => {
                let p = patch.ok_or_else(|| {
                    Error::input("patch_size", "(missing)", "[length, width] in m")
                })?;
                require_positive("patch_size[0]", p[0])?;
                require_positive("patch_size[1]", p[1])?;
                Ok(Support::CentralPatch {
                    length: p[0],
                    width: p[1],
                })
            }
        }
    }

    /// Points the mesh must contain for this support (patch corners).
    pub fn forced_points(&self) -> Vec<[f64; 2]> {
        match *self {
            Support::CentralPatch { length, width } => {
                let (a, b) = (0.5 * length, 0.5 * width);
                vec![[-a, -b], [a, -b], [a, b], [-a, b]]
            }
            _ => Vec::new(),
        }
    }

    /// Constrained flags per global DOF (`6·node + component`).
    fn constrained(&self, mesh: &Mesh) -> Result<Vec<bool>> {
        let n = mesh.nodes.len();
        let mut fixed = vec![false; NODE_DOF * n];
        let tol = 1e-9 * mesh.length.max(mesh.width);
        let (hx, hy) = (0.5 * mesh.length, 0.5 * mesh.width);
        match *self {
            Support::CentreClamp => fixed[NODE_DOF * mesh.centre..][..NODE_DOF].fill(true),
            Support::CentralPatch { length, width } => {
                let (a, b) = (0.5 * length, 0.5 * width);
                if a > hx + tol || b > hy + tol {
                    return Err(Error::input(
                        "patch_size",
                        format!("[{length}, {width}]"),
                        format!(
                            "a patch within the panel ({} x {})",
                            mesh.length, mesh.width
                        ),
                    ));
                }
                for c in self.forced_points() {
                    if mesh.node_at(c[0], c[1]).is_none() {
                        return Err(Error::input(
                            "patch_size",
                            format!("[{length}, {width}]"),
                            "patch corners that are mesh nodes (add Support::forced_points to the mesh points)",
                        ));
                    }
                }
                for (i, p) in mesh.nodes.iter().enumerate() {
                    if p[0].abs() <= a + tol && p[1].abs() <= b + tol {
                        fixed[NODE_DOF * i..][..NODE_DOF].fill(true);
                    }
                }
            }
            Support::SimplySupported => {
                for (i, p) in mesh.nodes.iter().enumerate() {
                    let d = NODE_DOF * i;
                    if (p[0].abs() - hx).abs() <= tol {
                        fixed[d + 1] = true;
                        fixed[d + 2] = true;
                        fixed[d + 3] = true;
                    }
                    if (p[1].abs() - hy).abs() <= tol {
                        fixed[d] = true;
                        fixed[d + 2] = true;
                        fixed[d + 4] = true;
                    }
                }
            }
            Support::FreeFree => {}
        }
        Ok(fixed)
    }
}

/// Element entries that are zero for every laminate: the drilling rotation
/// θz couples only with u, v and θz (the section terms never involve θz), so
/// θz–{w, θx, θy} pairs are left out of the pattern (about 1/6 of the
/// entries). Arguments are element DOF indices.
fn structural_zero(a: usize, b: usize) -> bool {
    let (ca, cb) = (a % NODE_DOF, b % NODE_DOF);
    (ca == 5 && (2..5).contains(&cb)) || (cb == 5 && (2..5).contains(&ca))
}

/// Which ply-angle derivatives of K to assemble.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Derivatives {
    /// K and M only.
    None,
    /// Also dK/dθ_v for every design variable.
    First,
    /// Also d²K/dθ_v² (mixed second derivatives vanish, see
    /// [`PanelSystem::d2k_mixed`]).
    Second,
}

/// The assembled, reduced panel system (free DOF only).
#[derive(Debug, Clone)]
pub struct PanelSystem {
    /// Stiffness K_ff, both triangles stored, symmetric \[N/m, N, N·m\].
    pub k: SparseColMat<usize, f64>,
    /// Lumped diagonal mass, free DOF order \[kg, kg·m²\].
    pub m_diag: Vec<f64>,
    /// dK/dθ_v per design variable v (same pattern as `k`); empty unless
    /// asked for \[per rad\].
    pub dk: Vec<SparseColMat<usize, f64>>,
    /// d²K/dθ_v² per design variable (same pattern); empty unless asked for.
    pub d2k: Vec<SparseColMat<usize, f64>>,
    /// Free DOF → (node, component 0..6 = u, v, w, θx, θy, θz).
    pub dof_map: Vec<(usize, usize)>,
    /// Node coordinates (panel frame, origin at the centre) \[m\].
    pub nodes: Vec<[f64; 2]>,
    /// For [`Support::FreeFree`]: the six rigid-body modes (translations
    /// x, y, z, rotations about x, y, z through the panel centre), in free
    /// DOF order, M-orthonormalised (Gram–Schmidt in that order). Empty for
    /// the other supports.
    pub rigid_modes: Vec<Vec<f64>>,
}

impl PanelSystem {
    /// d²K/dθ_v dθ_w: `Some` only for v == w (when assembled). Mixed
    /// derivatives are exactly zero: design variables tie disjoint plies and
    /// each ply's stiffness depends on its own angle only.
    pub fn d2k_mixed(&self, v: usize, w: usize) -> Option<&SparseColMat<usize, f64>> {
        if v == w {
            self.d2k.get(v)
        } else {
            None
        }
    }

    /// Number of free DOF.
    pub fn n_dof(&self) -> usize {
        self.m_diag.len()
    }
}

/// Mesh + support with the sparsity pattern and scatter map built once;
/// assemble as many laminates as needed.
#[derive(Debug, Clone)]
pub struct PanelModel {
    pub(super) mesh: Mesh,
    support: Support,
    pub(super) tris: Vec<Triangle>,
    pub(super) ops: Vec<CompactOps>,
    pub(super) free: Vec<usize>,
    dof_map: Vec<(usize, usize)>,
    pub(super) symbolic: SymbolicSparseColMat<usize>,
    /// For each element, the stored entries it contributes to: position in
    /// the value array (sorted, for locality) ...
    pub(super) scatter: Vec<u32>,
    /// ... and the index of the contribution in the column-major 18×18
    /// element matrix (always a lower-triangle entry, so K is exactly
    /// symmetric although GᵀCG is symmetric only up to rounding).
    pub(super) local: Vec<u16>,
    /// Element e's entries are `offsets[e]..offsets[e + 1]`.
    pub(super) offsets: Vec<usize>,
}

impl PanelModel {
    /// Element geometry, supports, sparsity pattern and scatter map.
    pub fn new(mesh: Mesh, support: Support) -> Result<PanelModel> {
        let tris = mesh
            .triangles
            .iter()
            .map(|t| Triangle::new(t.map(|i| mesh.nodes[i])))
            .collect::<Result<Vec<_>>>()?;
        let ops = tris.iter().map(Triangle::compact_operator).collect();
        let fixed = support.constrained(&mesh)?;
        let mut free = vec![NONE; fixed.len()];
        let mut dof_map = Vec::new();
        for (g, &f) in fixed.iter().enumerate() {
            if !f {
                free[g] = dof_map.len();
                dof_map.push((g / NODE_DOF, g % NODE_DOF));
            }
        }
        let n = dof_map.len();
        if n == 0 {
            return Err(Error::input(
                "support",
                "(all DOF fixed)",
                "a support leaving free DOF",
            ));
        }
        let edofs = |t: &[usize; 3]| -> [usize; 18] {
            std::array::from_fn(|a| free[NODE_DOF * t[a / NODE_DOF] + a % NODE_DOF])
        };
        let mut pairs: Vec<(usize, usize)> = Vec::with_capacity(mesh.triangles.len() * 324);
        for t in &mesh.triangles {
            let d = edofs(t);
            for (a, &c) in d.iter().enumerate() {
                for (b, &r) in d.iter().enumerate() {
                    if c != NONE && r != NONE && !structural_zero(a, b) {
                        pairs.push((c, r));
                    }
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut col_ptr = vec![0usize; n + 1];
        for &(c, _) in &pairs {
            col_ptr[c + 1] += 1;
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        let row_idx: Vec<usize> = pairs.iter().map(|&(_, r)| r).collect();
        if row_idx.len() >= MAX_STORED {
            return Err(Error::numerical(
                "fe::PanelModel::new",
                format!(
                    "{} stored entries exceed the u32 scatter map",
                    row_idx.len()
                ),
            ));
        }
        let mut scatter = Vec::with_capacity(mesh.triangles.len() * 270);
        let mut local = Vec::with_capacity(mesh.triangles.len() * 270);
        let mut offsets = Vec::with_capacity(mesh.triangles.len() + 1);
        offsets.push(0);
        let mut entries: Vec<(u32, u16)> = Vec::with_capacity(324);
        for t in &mesh.triangles {
            let d = edofs(t);
            entries.clear();
            for (a, &c) in d.iter().enumerate() {
                for (b, &r) in d.iter().enumerate() {
                    if c == NONE || r == NONE || structural_zero(a, b) {
                        continue;
                    }
                    let col = &row_idx[col_ptr[c]..col_ptr[c + 1]];
                    let k = col
                        .binary_search(&r)
                        .expect("pattern contains every element pair");
                    // lower-triangle entry (max(a,b), min(a,b)), column-major
                    let l = 18 * a.min(b) + a.max(b);
                    entries.push(((col_ptr[c] + k) as u32, l as u16));
                }
            }
            entries.sort_unstable();
            scatter.extend(entries.iter().map(|e| e.0));
            local.extend(entries.iter().map(|e| e.1));
            offsets.push(scatter.len());
        }
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Ok(PanelModel {
            mesh,
            support,
            tris,
            ops,
            free,
            dof_map,
            symbolic,
            scatter,
            local,
            offsets,
        })
    }

    /// The mesh.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The support.
    pub fn support(&self) -> Support {
        self.support
    }

    /// Number of free DOF.
    pub fn n_dof(&self) -> usize {
        self.dof_map.len()
    }

    /// Free index of (node, component), `None` if constrained.
    pub fn free_dof(&self, node: usize, comp: usize) -> Option<usize> {
        self.free
            .get(NODE_DOF * node + comp)
            .copied()
            .filter(|&f| f != NONE)
    }

    /// Element `e`'s geometry and strain operator G (8×18).
    pub fn element(&self, e: usize) -> (&Triangle, Mat8x18) {
        (&self.tris[e], self.tris[e].strain_operator())
    }

    /// Element `e`'s compact operator blocks (as used in assembly).
    pub fn element_ops(&self, e: usize) -> &CompactOps {
        &self.ops[e]
    }

    /// Element stiffness (18×18, element DOF order) for a laminate:
    /// `A·GᵀC_eG + K_drill`.
    pub fn element_stiffness(&self, e: usize, lam: &Laminate) -> Mat18 {
        let c = section_matrix(&lam.stiffness());
        let (t, g) = (&self.tris[e], &self.ops[e]);
        let mut k = t.section_stiffness(g, &c, lam.thickness());
        t.add_drilling(DRILLING_PENALTY * lam.membrane_mean(), &mut k);
        k
    }

    /// One pass over the elements filling every requested matrix:
    /// `vals[0]` gets K (section matrix `cs[0]` plus drilling with penalty
    /// `gamma`), `vals[m]` for m ≥ 1 gets the section term with `cs[m]`
    /// (the derivatives; no drilling). Each element's entry list is read
    /// once for all matrices. Values are zeroed first.
    fn fill_all(&self, vals: &mut [&mut [f64]], cs: &[Mat8], h: f64, gamma: f64) -> Result<()> {
        for v in vals.iter_mut() {
            v.fill(0.0);
        }
        let mut ke = Mat18::zeros();
        for (e, (t, g)) in self.tris.iter().zip(&self.ops).enumerate() {
            let range = self.offsets[e]..self.offsets[e + 1];
            let (pos, loc) = (&self.scatter[range.clone()], &self.local[range]);
            for (m, (val, c)) in vals.iter_mut().zip(cs).enumerate() {
                t.section_stiffness_into(g, c, h, &mut ke);
                if m == 0 {
                    t.add_drilling(gamma, &mut ke);
                }
                let ks = ke.as_slice();
                for (&p, &l) in pos.iter().zip(loc) {
                    val[p as usize] += ks[l as usize];
                }
            }
        }
        for (m, val) in vals.iter().enumerate() {
            all_finite(val, "fe::PanelModel::assemble", || {
                format!("matrix {m} (0 = K, then dK, d2K)")
            })?;
        }
        Ok(())
    }

    /// Assemble K, M and (as asked) dK/dθ_v, d²K/dθ_v² for `lam` with
    /// design variables `design` (paper Eq. 20: `dK/dθ = Σ_e A_e GᵀC'G`).
    pub fn assemble(
        &self,
        lam: &Laminate,
        design: &DesignMap,
        want: Derivatives,
    ) -> Result<PanelSystem> {
        let nnz = self.symbolic.row_idx().len();
        let mk = || SparseColMat::new(self.symbolic.clone(), vec![0.0; nnz]);
        let n1 = if want >= Derivatives::First {
            design.len()
        } else {
            0
        };
        let n2 = if want >= Derivatives::Second {
            design.len()
        } else {
            0
        };
        let mut sys = PanelSystem {
            k: mk(),
            m_diag: vec![0.0; self.n_dof()],
            dk: (0..n1).map(|_| mk()).collect(),
            d2k: (0..n2).map(|_| mk()).collect(),
            dof_map: self.dof_map.clone(),
            nodes: self.mesh.nodes.clone(),
            rigid_modes: Vec::new(),
        };
        self.assemble_into(lam, design, &mut sys)?;
        Ok(sys)
    }

    /// Re-assemble into a system previously returned by
    /// [`PanelModel::assemble`] on this model (same design-variable count and
    /// derivative level: those of `sys`), reusing its buffers: the cheap path
    /// inside an optimization loop.
    pub fn assemble_into(
        &self,
        lam: &Laminate,
        design: &DesignMap,
        sys: &mut PanelSystem,
    ) -> Result<()> {
        let n_plies = lam.plies().len();
        if let Some(k) = design.groups().iter().flatten().find(|&&k| k >= n_plies) {
            return Err(Error::input(
                "design",
                k + 1,
                format!("ply numbers within the lay-up (1..={n_plies})"),
            ));
        }
        let nnz = self.symbolic.row_idx().len();
        let same = |m: &SparseColMat<usize, f64>| m.val().len() == nnz && m.nrows() == self.n_dof();
        let levels_ok = [sys.dk.len(), sys.d2k.len()]
            .iter()
            .all(|&l| l == 0 || l == design.len());
        if !same(&sys.k)
            || !sys.dk.iter().all(same)
            || !sys.d2k.iter().all(same)
            || !levels_ok
            || sys.m_diag.len() != self.n_dof()
        {
            return Err(Error::input(
                "system",
                "(buffers of another model)",
                "a PanelSystem assembled by this PanelModel with this design map",
            ));
        }
        let h = lam.thickness();
        let gamma = DRILLING_PENALTY * lam.membrane_mean();
        let mut cs = vec![section_matrix(&lam.stiffness())];
        cs.extend((0..sys.dk.len()).map(|v| section_matrix(&lam.design_derivative(design, v))));
        cs.extend(
            (0..sys.d2k.len()).map(|v| section_matrix(&lam.design_second_derivative(design, v, v))),
        );
        let mut vals: Vec<&mut [f64]> = std::iter::once(sys.k.val_mut())
            .chain(sys.dk.iter_mut().map(|m| m.val_mut()))
            .chain(sys.d2k.iter_mut().map(|m| m.val_mut()))
            .collect();
        self.fill_all(&mut vals, &cs, h, gamma)?;
        let (mu, ir) = (lam.mass_per_area(), lam.rotary_inertia_per_area());
        sys.m_diag.fill(0.0);
        for (t, tri) in self.mesh.triangles.iter().zip(&self.tris) {
            let me = tri.lumped_mass(mu, ir);
            for (a, &m) in me.iter().enumerate() {
                let f = self.free[NODE_DOF * t[a / NODE_DOF] + a % NODE_DOF];
                if f != NONE {
                    sys.m_diag[f] += m;
                }
            }
        }
        sys.rigid_modes = if self.support == Support::FreeFree {
            self.rigid_modes(&sys.m_diag)?
        } else {
            Vec::new()
        };
        Ok(())
    }

    /// The six rigid-body displacement fields about the panel centre (free
    /// DOF order, not normalised): translations x, y, z; rotations about x
    /// (w = y, θx = 1), y (w = −x, θy = 1), z (u = −y, v = x, θz = 1).
    pub fn rigid_fields(&self) -> Vec<Vec<f64>> {
        let mut r = vec![vec![0.0; self.n_dof()]; 6];
        for (f, &(node, comp)) in self.dof_map.iter().enumerate() {
            let [x, y] = self.mesh.nodes[node];
            let vals = match comp {
                0 => [1.0, 0.0, 0.0, 0.0, 0.0, -y],
                1 => [0.0, 1.0, 0.0, 0.0, 0.0, x],
                2 => [0.0, 0.0, 1.0, y, -x, 0.0],
                3 => [0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
                4 => [0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
                _ => [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
            };
            for (m, v) in vals.into_iter().enumerate() {
                r[m][f] = v;
            }
        }
        r
    }

    fn rigid_modes(&self, m: &[f64]) -> Result<Vec<Vec<f64>>> {
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(6);
        let dot = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .zip(m)
                .map(|((x, y), w)| x * y * w)
                .sum::<f64>()
        };
        for mut r in self.rigid_fields() {
            for q in &out {
                let c = dot(&r, q);
                r.iter_mut().zip(q).for_each(|(x, y)| *x -= c * y);
            }
            let nrm = dot(&r, &r);
            if nrm.is_nan() || nrm <= 0.0 || nrm.is_infinite() {
                return Err(Error::numerical(
                    "fe::PanelModel::rigid_modes",
                    format!("rigid field {} has M-norm² {nrm:e}", out.len()),
                ));
            }
            let s = 1.0 / nrm.sqrt();
            r.iter_mut().for_each(|x| *x *= s);
            out.push(r);
        }
        Ok(out)
    }

    /// Consistent load vector of a uniform pressure q \[Pa\] along +z
    /// (q·A/3 on w of each vertex), free DOF order \[N\].
    pub fn uniform_pressure_load(&self, q: f64) -> Vec<f64> {
        let mut f = vec![0.0; self.n_dof()];
        for (t, tri) in self.mesh.triangles.iter().zip(&self.tris) {
            for &i in t {
                if let Some(d) = self.free_dof(i, 2) {
                    f[d] += q * tri.area / 3.0;
                }
            }
        }
        f
    }
}

/// One-shot assembly: [`PanelModel::new`] then [`PanelModel::assemble`].
pub fn assemble(
    mesh: &Mesh,
    lam: &Laminate,
    support: Support,
    design: &DesignMap,
    want: Derivatives,
) -> Result<PanelSystem> {
    PanelModel::new(mesh.clone(), support)?.assemble(lam, design, want)
}

/// `Ok` when every entry of `val` is finite; else a numerical error at
/// `place` naming the first non-finite entry of `what()` and its value.
pub(super) fn all_finite(val: &[f64], place: &str, what: impl FnOnce() -> String) -> Result<()> {
    match val.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(Error::numerical(
            place,
            format!("non-finite entry {i} of {}: {}", what(), val[i]),
        )),
        None => Ok(()),
    }
}
