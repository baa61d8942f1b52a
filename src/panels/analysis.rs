//! One panel's modal analysis reused across lay-ups ([`PanelAnalysis`]):
//! laminate → shell FE → reduced `K`, lumped `M` → lowest modes by
//! shift-invert Lanczos → `dλ/dθ`, `dX/dθ` per design variable (paper
//! §2.2, §3.1–3.2, §6.2), with each mode labelled by kind (flexural,
//! in-plane, drilling) and, for flexural modes, the symmetry of `w` under
//! the mirrors x → −x and y → −y (`SS`, `SA`, `AS`, `AA`; `-` where the
//! mesh has no mirror nodes or the correlation is weak).

use super::rigid::RigidFrame;
use crate::error::{Error, Result};
use crate::fe::{Derivatives, Panel, PanelSystem};
use crate::modal::{
    has_repeated, keep_whole_clusters, DerivativeOptions, DesignDerivative, MassDerivative,
    ModalOptions, ModalSolver, ModeUpdate, Modes, VariableDerivatives,
};
use std::collections::HashMap;
use std::time::Instant;

/// The result of one panel's analysis.
#[derive(Debug, Clone)]
pub struct PanelModes {
    /// Panel name.
    pub panel: String,
    /// Lay-up in degrees, e.g. `[0/90/90/0]`.
    pub layup: String,
    /// Reduced DOFs.
    pub dofs: usize,
    /// Eigen-solution.
    pub modes: Modes,
    /// One label pair (kind, symmetry) per mode.
    pub labels: Vec<(&'static str, &'static str)>,
    /// Derivatives per design variable (empty unless asked for).
    pub derivatives: Vec<VariableDerivatives>,
    /// Design-variable names: `theta_1_4` ties plies 1 and 4;
    /// `thickness_1_4` (after the angles) is their common thickness \[m\].
    pub variables: Vec<String>,
    /// Wall times \[s\]: assembly, modes, derivatives.
    pub seconds: [f64; 3],
    /// Reduced DOF → (node, component 0..6 = u, v, w, θx, θy, θz).
    pub dof_map: Vec<(usize, usize)>,
    /// Node coordinates, panel frame \[m\].
    pub nodes: Vec<[f64; 2]>,
    /// Rigid-body content per mode, `‖Pφ‖²_M / ‖φ‖²_M` in \[0, 1\]
    /// ([`super::rigid`]): ≈ 1 for the centre clamp's drilling mode, ≈ 0
    /// for free–free elastic modes.
    pub rigid_content: Vec<f64>,
    /// The panel's rigid frame (all node masses, `RᵀMR`) for this lay-up.
    pub frame: RigidFrame,
    /// The elastic modes asked for, when that count split a repeated
    /// eigenvalue at this lay-up and the cluster's kept members were
    /// dropped ([`crate::modal::keep_whole_clusters`]; `modes` holds the
    /// count used).
    pub asked: Option<usize>,
}

/// Lay-up as `[a/b/c]` in degrees (rounded to 0.01°).
pub fn layup_label(panel: &Panel) -> String {
    let a: Vec<String> = panel
        .laminate
        .angles()
        .iter()
        .map(|t| {
            let d = (t.to_degrees() * 100.0).round() / 100.0;
            format!("{}", d + 0.0)
        })
        .collect();
    format!("[{}]", a.join("/"))
}

/// A panel prepared for repeated modal analyses: mesh, sparsity pattern,
/// assembly buffers, symbolic factorization and mirror maps are built once
/// ([`PanelAnalysis::new`]); each [`PanelAnalysis::run`] for a lay-up then
/// costs one assembly (`K` and the lumped `M`, both of that lay-up's ply
/// angles and thicknesses), one numeric factorization, the Lanczos
/// iteration and (if asked) the derivatives. This is the shape an
/// optimization loop uses.
pub struct PanelAnalysis {
    pub(super) panel: Panel,
    pub(super) model: crate::fe::PanelModel,
    pub(super) sys: PanelSystem,
    pub(super) solver: ModalSolver,
    want: Option<ModeUpdate>,
    mirrors: [Option<Vec<usize>>; 2],
    /// The rigid frame of the last run, keyed by the laminate's mass and
    /// rotary inertia per area (it does not depend on the ply angles).
    frame: Option<([f64; 2], RigidFrame)>,
    /// Wall time of the set-up \[s\].
    pub setup_seconds: f64,
    /// Ply groups whose common thickness is a design variable after the
    /// ply angles (`thickness_<plies>`; empty: none), and their assembled
    /// derivatives (buffers reused across runs).
    thickness: Vec<Vec<usize>>,
    tsys: Option<crate::fe::ThicknessSystem>,
    /// The system with the second derivatives `K''` of the ply angles,
    /// assembled only for a run whose modes hold a cluster of repeated
    /// eigenvalues (the only case in which the updated-mode derivatives
    /// read them); buffers reused across such runs.
    second: Option<PanelSystem>,
}

impl PanelAnalysis {
    /// The largest number of modes this mesh and support give: its free
    /// DOFs (less the 6 rigid-body modes of a free–free panel).
    pub fn max_modes(&self) -> usize {
        let dofs = self.sys.m_diag.len();
        if self.panel.support == crate::fe::Support::FreeFree {
            dofs.saturating_sub(6)
        } else {
            dofs
        }
    }

    /// Build everything that does not depend on the ply angles. `want`:
    /// which derivatives later runs compute (none, fixed-mode λ', or
    /// updated-mode λ' and X'); only those matrices are ever assembled.
    pub fn new(panel: &Panel, want: Option<ModeUpdate>) -> Result<PanelAnalysis> {
        let t0 = Instant::now();
        let level = match want {
            None => Derivatives::None,
            Some(ModeUpdate::Fixed) => Derivatives::First,
            // K'' only on demand (`run`: clusters of repeated eigenvalues).
            Some(ModeUpdate::Updated) => Derivatives::First,
        };
        let model = panel.model()?;
        let sys = model.assemble(&panel.laminate, &panel.design, level)?;
        let solver = ModalSolver::new(&sys.k, &sys.m_diag)?;
        let mirrors = [
            mirror_map(&panel.mesh.nodes, [-1.0, 1.0]),
            mirror_map(&panel.mesh.nodes, [1.0, -1.0]),
        ];
        Ok(PanelAnalysis {
            panel: panel.clone(),
            model,
            sys,
            solver,
            want,
            mirrors,
            frame: None,
            setup_seconds: t0.elapsed().as_secs_f64(),
            thickness: Vec::new(),
            tsys: None,
            second: None,
        })
    }

    /// Differentiate later runs also with respect to the common thickness
    /// \[m\] of each ply group of `groups` (0-based plies; variables named
    /// `thickness_<plies>`, 1-based, after the ply angles), when the
    /// analysis computes derivatives at all. Stiffness and lumped mass
    /// both depend on a thickness ([`crate::fe::thickness`];
    /// [`crate::modal::derivatives`], "Mass derivative"). Errors: a ply
    /// outside the lay-up.
    pub fn set_thickness_groups(&mut self, groups: &[Vec<usize>]) -> Result<()> {
        let n = self.panel.laminate.plies().len();
        if let Some(&k) = groups.iter().flatten().find(|&&k| k >= n) {
            return Err(Error::input(
                "thickness_groups",
                k + 1,
                format!("ply numbers within the lay-up (1..={n})"),
            ));
        }
        if self.thickness != groups {
            self.thickness = groups.to_vec();
            self.tsys = None;
        }
        Ok(())
    }

    /// The ply groups whose thickness is differentiated
    /// ([`PanelAnalysis::set_thickness_groups`]).
    pub fn thickness_groups(&self) -> &[Vec<usize>] {
        &self.thickness
    }

    /// Modes (and derivatives) for `laminate` (same ply count as the
    /// panel's; ply angles and thicknesses may differ: `K` and `M` are
    /// both assembled for it). `n_modes` outside 1..=[`Self::max_modes`]
    /// is an input error on `n_modes` that names the largest allowed.
    pub fn run(
        &mut self,
        laminate: &crate::laminate::Laminate,
        n_modes: usize,
    ) -> Result<PanelModes> {
        self.check_mode_count(n_modes)?;
        let t0 = Instant::now();
        self.model
            .assemble_into(laminate, &self.panel.design, &mut self.sys)?;
        self.solver.set_stiffness(&self.sys.k)?;
        // The lumped M of this laminate: its ply thicknesses (design
        // variables `thickness_<plies>`) move μ = Σ ρ_k t_k and
        // I = Σ ρ_k ∫z² dz, so the mass given in `new` (the panel's own
        // lay-up) is stale for another thickness.
        self.solver.set_mass(&self.sys.m_diag)?;
        let t1 = Instant::now();
        let free = self.panel.support == crate::fe::Support::FreeFree;
        let mut opts = ModalOptions::new(if free { n_modes + 6 } else { n_modes });
        if free {
            opts.shift = FREE_FREE_SHIFT;
        }
        let mut modes = self.solver.solve(&opts)?;
        let t2 = Instant::now();
        if free {
            // The rigid-body modes go before the derivatives: they do not
            // depend on the ply angles, and their 6-fold cluster at λ = 0
            // would cost six factorizations and the adjacent-eigenvector
            // method for nothing. Each elastic mode's derivative is its own
            // solve, so the elastic derivatives are the same.
            remove_rigid_modes(&mut modes, &mut [], &self.sys)?;
        }
        // A count that splits a repeated eigenvalue at this lay-up drops
        // the cluster whole (with or without derivatives, so that an
        // evaluation with gradients uses the basis of one without).
        let asked = keep_whole_clusters(&mut modes, DerivativeOptions::default().cluster_tol);
        let derivatives = self.derivatives(laminate, &modes)?;
        let t3 = Instant::now();
        let labels = (0..modes.lambda.len())
            .map(|j| label_mode(&self.sys, &self.mirrors, &modes, j))
            .collect();
        let frame = self.rigid_frame(laminate)?;
        let rigid_content = (0..modes.lambda.len())
            .map(|j| {
                frame.content(
                    self.sys
                        .dof_map
                        .iter()
                        .enumerate()
                        .map(|(f, &(node, comp))| (node, comp, modes.modes[(f, j)])),
                )
            })
            .collect();
        let mut with_layup = self.panel.clone();
        with_layup.laminate = laminate.clone();
        Ok(PanelModes {
            panel: self.panel.name.clone(),
            layup: layup_label(&with_layup),
            dofs: self.sys.m_diag.len(),
            modes,
            labels,
            derivatives,
            variables: self.variable_names(),
            seconds: [
                (t1 - t0).as_secs_f64(),
                (t2 - t1).as_secs_f64(),
                (t3 - t2).as_secs_f64(),
            ],
            dof_map: self.sys.dof_map.clone(),
            nodes: self.panel.mesh.nodes.clone(),
            rigid_content,
            frame,
            asked,
        })
    }

    /// `n_modes` within 1..=[`Self::max_modes`], else an input error that
    /// names the largest allowed and why.
    fn check_mode_count(&self, n_modes: usize) -> Result<()> {
        let max = self.max_modes();
        if n_modes == 0 || n_modes > max {
            let dofs = self.sys.m_diag.len();
            let why = if self.panel.support == crate::fe::Support::FreeFree {
                format!("{dofs} free DOFs less the 6 rigid-body modes of a free-free panel")
            } else {
                format!("{dofs} free DOFs")
            };
            return Err(Error::input(
                "n_modes",
                n_modes,
                format!("between 1 and {max} for this mesh ({why})"),
            ));
        }
        Ok(())
    }

    /// The derivatives the analysis was built for (none, fixed-mode or
    /// updated-mode; [`PanelAnalysis::new`]) of `modes` with respect to the
    /// ply angles and then the ply-group thicknesses. The thickness
    /// system is assembled for every such run, `K''` of the ply angles
    /// only when the modes hold a repeated cluster.
    fn derivatives(
        &mut self,
        laminate: &crate::laminate::Laminate,
        modes: &Modes,
    ) -> Result<Vec<VariableDerivatives>> {
        if let (Some(update), false) = (self.want, self.thickness.is_empty()) {
            let second = update == ModeUpdate::Updated;
            match &mut self.tsys {
                Some(t) => self.model.assemble_thickness_into(laminate, t)?,
                None => {
                    self.tsys = Some(self.model.assemble_thickness(
                        laminate,
                        &self.thickness,
                        second,
                    )?)
                }
            }
        }
        let Some(update) = self.want else {
            return Ok(Vec::new());
        };
        let repeated = update == ModeUpdate::Updated
            && has_repeated(modes, DerivativeOptions::default().cluster_tol);
        if repeated {
            match &mut self.second {
                Some(s) => self.model.assemble_into(laminate, &self.panel.design, s)?,
                None => {
                    self.second = Some(self.model.assemble(
                        laminate,
                        &self.panel.design,
                        Derivatives::Second,
                    )?)
                }
            }
        }
        let sys = &self.sys;
        let d2k = |v: usize| {
            self.second
                .as_ref()
                .filter(|_| repeated)
                .and_then(|s| s.d2k.get(v))
        };
        let mut vars: Vec<DesignDerivative<'_>> = (0..sys.dk.len())
            .map(|v| DesignDerivative {
                dk: &sys.dk[v],
                d2k: d2k(v),
                mass: None,
            })
            .collect();
        if let Some(t) = &self.tsys {
            vars.extend((0..t.groups.len()).map(|v| DesignDerivative {
                dk: &t.dk[v],
                d2k: t.d2k.get(v),
                mass: Some(MassDerivative {
                    dm: &t.dm[v],
                    d2m: t.d2m.get(v).map(|m| &m[..]),
                }),
            }));
        }
        let opts = DerivativeOptions {
            update,
            ..DerivativeOptions::default()
        };
        self.solver.derivatives(modes, &vars, &opts)
    }

    /// The design variables' names: a `theta_<plies>` per ply group, then,
    /// with derivatives, a `thickness_<plies>` per thickness group.
    fn variable_names(&self) -> Vec<String> {
        let mut variables: Vec<String> = self
            .panel
            .design
            .groups()
            .iter()
            .map(|g| group_name("theta", g))
            .collect();
        if self.want.is_some() {
            variables.extend(self.thickness.iter().map(|g| group_name("thickness", g)));
        }
        variables
    }

    /// The panel's rigid frame for `laminate`, reused while the laminate's
    /// mass and rotary inertia per area stay the same.
    fn rigid_frame(&mut self, laminate: &crate::laminate::Laminate) -> Result<RigidFrame> {
        let key = [laminate.mass_per_area(), laminate.rotary_inertia_per_area()];
        Ok(match &self.frame {
            Some((k, f)) if *k == key => f.clone(),
            _ => {
                let f = RigidFrame::of_panel(&self.panel, laminate)?;
                self.frame = Some((key, f.clone()));
                f
            }
        })
    }
}

/// The name of a ply group's variable: `<kind>_<1-based plies>`, e.g.
/// `theta_1_4` or `thickness_2_3`.
pub fn group_name(kind: &str, group: &[usize]) -> String {
    let plies: Vec<String> = group.iter().map(|k| (k + 1).to_string()).collect();
    format!("{kind}_{}", plies.join("_"))
}

/// Shift σ [rad²/s²] for free–free panels: K − σM must be positive
/// definite although K has the six rigid-body modes (λ = 0) as null space.
/// −1 rad²/s² lifts them to 1 while keeping the pencil well conditioned and
/// the wanted eigenvalues (flexural λ of order 10–10⁴ for the SAR panel) far
/// from σ relative to the gaps the shift-invert Lanczos needs.
pub const FREE_FREE_SHIFT: f64 = -1.0;

/// Identify the six rigid-body modes among the computed ones by their
/// M-projection onto the rigid-body fields of the model (share of the mode's
/// M-norm in the rigid subspace > 1/2; elastic modes are M-orthogonal to it)
/// and remove them, with their derivatives (rigid motions do not depend on
/// the ply angles). Exactly six must be found, else it is a numerical error.
fn remove_rigid_modes(
    modes: &mut Modes,
    derivatives: &mut [VariableDerivatives],
    sys: &PanelSystem,
) -> Result<()> {
    let n = modes.modes.nrows();
    let k = modes.lambda.len();
    let rigid: Vec<bool> = (0..k)
        .map(|j| {
            let share: f64 = sys
                .rigid_modes
                .iter()
                .map(|r| {
                    (0..n)
                        .map(|i| r[i] * sys.m_diag[i] * modes.modes[(i, j)])
                        .sum::<f64>()
                        .powi(2)
                })
                .sum();
            share > 0.5
        })
        .collect();
    let found = rigid.iter().filter(|&&r| r).count();
    if found != 6 || sys.rigid_modes.len() != 6 {
        return Err(Error::numerical(
            "panels::remove_rigid_modes",
            format!(
                "free-free panel: {found} computed modes lie in the rigid-body subspace \
                 (expected 6); lowest eigenvalues {:?}",
                &modes.lambda[..k.min(8)]
            ),
        ));
    }
    let keep: Vec<usize> = (0..k).filter(|&j| !rigid[j]).collect();
    fn columns(m: &faer::Mat<f64>, keep: &[usize]) -> faer::Mat<f64> {
        faer::Mat::from_fn(m.nrows(), keep.len(), |i, c| m[(i, keep[c])])
    }
    modes.modes = columns(&modes.modes, &keep);
    modes.lambda = keep.iter().map(|&j| modes.lambda[j]).collect();
    modes.residuals = keep.iter().map(|&j| modes.residuals[j]).collect();
    for d in derivatives.iter_mut() {
        d.dlambda = keep.iter().map(|&j| d.dlambda[j]).collect();
        d.dmodes = d.dmodes.as_ref().map(|m| columns(m, &keep));
        // Clusters index the full list: keep those wholly among the
        // elastic modes, renumbered.
        d.clusters
            .retain(|c| (c.first..c.first + c.len).all(|j| !rigid[j]));
        for c in d.clusters.iter_mut() {
            c.first = keep.iter().position(|&j| j == c.first).unwrap_or(c.first);
        }
    }
    Ok(())
}

/// Analyse one panel once (set-up + one run).
pub fn analyse_panel(
    panel: &Panel,
    n_modes: usize,
    want: Option<ModeUpdate>,
) -> Result<PanelModes> {
    PanelAnalysis::new(panel, want)?.run(&panel.laminate, n_modes)
}

/// For every node, the node at its mirror image `(sx·x, sy·y)`, or `None`
/// if some node has no mirror (then symmetry is not labelled). Hashed on a
/// grid of 1e-9 of the panel size, checking neighbouring cells so rounding
/// at a cell edge cannot miss a node.
fn mirror_map(nodes: &[[f64; 2]], s: [f64; 2]) -> Option<Vec<usize>> {
    let size = nodes
        .iter()
        .fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
    let h = 1e-9 * size.max(f64::MIN_POSITIVE);
    let key = |p: [f64; 2]| ((p[0] / h).round() as i64, (p[1] / h).round() as i64);
    let index: HashMap<(i64, i64), usize> = nodes
        .iter()
        .enumerate()
        .map(|(i, &p)| (key(p), i))
        .collect();
    nodes
        .iter()
        .map(|&p| {
            let (kx, ky) = key([s[0] * p[0], s[1] * p[1]]);
            (-1..=1)
                .flat_map(|dx| (-1..=1).map(move |dy| (kx + dx, ky + dy)))
                .find_map(|k| index.get(&k).copied())
        })
        .collect()
}

/// Kind (where the kinetic energy sits) and symmetry of mode `j`.
fn label_mode(
    sys: &PanelSystem,
    mirrors: &[Option<Vec<usize>>; 2],
    modes: &Modes,
    j: usize,
) -> (&'static str, &'static str) {
    // Energy share per component class: u, v in-plane; w, θx, θy flexural;
    // θz drilling (the small drilling inertia makes it visible).
    let mut e = [0.0f64; 3];
    let mut w = vec![0.0f64; sys.nodes.len()];
    for (i, &(node, comp)) in sys.dof_map.iter().enumerate() {
        let x = modes.modes[(i, j)];
        let class = match comp {
            0 | 1 => 0,
            2..=4 => 1,
            _ => 2,
        };
        e[class] += sys.m_diag[i] * x * x;
        if comp == 2 {
            w[node] = x;
        }
    }
    let total: f64 = e.iter().sum();
    let kind = if e[1] >= 0.5 * total {
        "flexural"
    } else if e[0] >= e[2] {
        "in-plane"
    } else {
        "drilling"
    };
    if kind != "flexural" {
        return (kind, "-");
    }
    // Correlation of w with its mirror image: +1 symmetric, −1 antisymmetric.
    let letter = |map: &Option<Vec<usize>>| {
        let map = map.as_ref()?;
        let (mut c, mut n) = (0.0, 0.0);
        for (a, &b) in map.iter().enumerate() {
            c += w[a] * w[b];
            n += w[a] * w[a];
        }
        match c / n {
            r if r > 0.9 => Some('S'),
            r if r < -0.9 => Some('A'),
            _ => None,
        }
    };
    let symmetry = match (letter(&mirrors[0]), letter(&mirrors[1])) {
        (Some('S'), Some('S')) => "SS",
        (Some('S'), Some('A')) => "SA",
        (Some('A'), Some('S')) => "AS",
        (Some('A'), Some('A')) => "AA",
        _ => "-",
    };
    (kind, symmetry)
}

/// `df/dθ` [Hz/deg] from `dλ/dθ` [rad²/s² per rad] at `λ`: f = √λ/(2π),
/// df/dλ = 1/(4π√λ), and 1 rad = 180/π deg.
pub fn dfreq_hz_per_deg(lambda: f64, dlambda_per_rad: f64) -> f64 {
    if lambda <= 0.0 {
        return 0.0;
    }
    dlambda_per_rad / (4.0 * std::f64::consts::PI * lambda.sqrt()) * (std::f64::consts::PI / 180.0)
}

/// Prefix the place of a numerical error with the panel name.
pub fn in_panel(e: Error, panel: &str) -> Error {
    e.at_place(&format!("panel {panel}"))
}
