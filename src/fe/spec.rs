//! The `[[panels]]` study-file section: serde spec and its validated,
//! unit-converted form.
//!
//! ```toml
//! [[panels]]
//! name = "panel3"
//! length = 1.994                 # m, along x (e1)
//! width = 1.3                    # m, along y (e2)
//! divisions = 64                 # cells along the length (mesh density)
//! attachment_points = [[0.797, 0.45], [-0.797, 0.45], [0.797, -0.45], [-0.797, -0.45]]
//! support = "centre_clamp"       # or "central_patch", "simply_supported", "free_free"
//! # patch_size = [0.1, 0.1]      # m, for "central_patch"
//! design = [[1, 4], [2, 3]]      # design variables as 1-based ply numbers
//! material = { e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9, g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }
//! plies = [{ angle = 0.0, thickness = 0.5e-3 }, { angle = 90.0, thickness = 0.5e-3 },
//!          { angle = 90.0, thickness = 0.5e-3 }, { angle = 0.0, thickness = 0.5e-3 }]
//! ```
//!
//! Ply angles are in degrees in the file and radians after `resolve`.

use super::assembly::{PanelModel, Support, SupportKind};
use super::mesh::{Mesh, MeshParams};
use crate::error::{Error, Result};
use crate::laminate::spec::{resolve_laminate, MaterialSpec, PlySpec};
use crate::laminate::{DesignMap, Laminate};
use serde::Deserialize;

/// Default mesh density: cells along the panel length. Measured on SAR
/// panel 3 ([0/90/90/0], ignored measurement test `sar_panel_mode_convergence`
/// in `tests/suite/fe/modes.rs`):
/// at 64 divisions (≈16 000 DOF) the 14 lowest flexural modes are within
/// about 0.5 % of the 160-division values (≈1 % at 40, ≈0.2 % at 80;
/// second-order convergence). The two near-rigid rocking modes and the
/// drilling mode of the point clamp do not converge (docs/numerics.md).
pub const DEFAULT_DIVISIONS: usize = 64;

fn default_divisions() -> usize {
    DEFAULT_DIVISIONS
}

/// One `[[panels]]` entry as written in a study file.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PanelSpec {
    /// Panel name (used in reports).
    pub name: String,
    /// Length along x \[m\].
    pub length: f64,
    /// Width along y \[m\].
    pub width: f64,
    /// Ply material.
    pub material: MaterialSpec,
    /// Plies bottom to top (angles in degrees).
    pub plies: Vec<PlySpec>,
    /// Cells along the length (default [`DEFAULT_DIVISIONS`]).
    #[serde(default = "default_divisions")]
    pub divisions: usize,
    /// Points that must be mesh nodes (panel coordinates, origin at the
    /// centre) \[m\].
    #[serde(default)]
    pub attachment_points: Vec<[f64; 2]>,
    /// Reference condition: `centre_clamp` (default, the paper's),
    /// `central_patch`, `simply_supported` or `free_free`.
    #[serde(default)]
    pub support: SupportKind,
    /// [length, width] of the clamped patch for "central_patch" \[m\].
    pub patch_size: Option<[f64; 2]>,
    /// Design variables as lists of 1-based ply numbers (default: one per
    /// ply).
    pub design: Option<Vec<Vec<usize>>>,
}

/// A validated panel: laminate (radians), design map (0-based), mesh and
/// support.
#[derive(Debug, Clone)]
pub struct Panel {
    /// The `[[panels]] name`.
    pub name: String,
    /// The lay-up, angles in radians.
    pub laminate: Laminate,
    /// Design variables → plies (0-based).
    pub design: DesignMap,
    /// The structured mesh, with nodes at the attachment points, the
    /// centre and the patch corners.
    pub mesh: Mesh,
    /// The reference condition of the modes.
    pub support: Support,
}

impl PanelSpec {
    /// Validate and convert (degrees → radians, 1-based → 0-based plies),
    /// build the mesh with nodes at the attachment points, the centre and
    /// the patch corners. Error keys are relative to the panel entry
    /// (`material.e1`, `plies[2].thickness`, `attachment_points[1]`,
    /// `support`, ...); the caller adds `panels[i]` and the file with
    /// [`crate::study::Study::locate`].
    pub fn resolve(&self) -> Result<Panel> {
        if self.name.trim().is_empty() {
            return Err(Error::input("name", "\"\"", "a non-empty panel name"));
        }
        let laminate = resolve_laminate(&self.material, &self.plies)?;
        let n = laminate.plies().len();
        let design = match &self.design {
            None => DesignMap::per_ply(n),
            Some(groups) => {
                let mut g0 = Vec::with_capacity(groups.len());
                for (v, g) in groups.iter().enumerate() {
                    let mut h = Vec::with_capacity(g.len());
                    for &k in g {
                        if k == 0 || k > n {
                            return Err(Error::input(
                                format!("design[{v}]"),
                                k,
                                format!("1-based ply numbers in 1..={n}"),
                            ));
                        }
                        h.push(k - 1);
                    }
                    g0.push(h);
                }
                DesignMap::new(g0, n)?
            }
        };
        let support = Support::new(self.support, self.patch_size)?;
        let mut points = self.attachment_points.clone();
        let n_attach = points.len();
        points.extend(support.forced_points());
        let mesh = Mesh::structured(&MeshParams {
            length: self.length,
            width: self.width,
            divisions: self.divisions,
            points,
        })
        .map_err(|e| match e {
            // a patch corner outside the panel is a patch_size problem
            Error::Input { key, value, .. }
                if key.starts_with("attachment_points[")
                    && key
                        .trim_start_matches("attachment_points[")
                        .trim_end_matches(']')
                        .parse::<usize>()
                        .is_ok_and(|k| k >= n_attach) =>
            {
                Error::input(
                    "patch_size",
                    value,
                    format!(
                        "a patch within the panel ({} x {})",
                        self.length, self.width
                    ),
                )
            }
            other => other,
        })?;
        Ok(Panel {
            name: self.name.clone(),
            laminate,
            design,
            mesh,
            support,
        })
    }
}

impl Panel {
    /// The assembly model (pattern and scatter map built once).
    pub fn model(&self) -> Result<PanelModel> {
        PanelModel::new(self.mesh.clone(), self.support)
    }
}

/// Read and resolve every `[[panels]]` entry of a study. Errors name the
/// file and `panels[i].key`; panel names must be unique. An absent section
/// gives an empty list.
pub fn panels_from_study(study: &crate::study::Study) -> Result<Vec<Panel>> {
    let specs: Vec<PanelSpec> = study.section("panels")?.unwrap_or_default();
    let mut out: Vec<Panel> = Vec::with_capacity(specs.len());
    for (i, spec) in specs.iter().enumerate() {
        let prefix = format!("panels[{i}]");
        let panel = spec.resolve().map_err(study.locate(&prefix))?;
        if out.iter().any(|p| p.name == panel.name) {
            return Err(study.error(
                format!("{prefix}.name"),
                format!("\"{}\"", panel.name),
                "a panel name not used by another panel",
            ));
        }
        out.push(panel);
    }
    Ok(out)
}
