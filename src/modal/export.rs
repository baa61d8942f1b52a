//! Mode-shape export for plotting: one row per (mode, node, component).

use super::modes::Modes;
use crate::error::{Error, Result};

/// Where a reduced DOF lives: FE node number and component
/// (0..6 = u1, u2, u3, φ1, φ2, φ3 for the shell of §2.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DofLabel {
    /// Node number in the mesh.
    pub node: usize,
    /// Component index at the node.
    pub component: usize,
}

/// One value of one mode shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeShapeRow {
    /// Mode index (0 = lowest).
    pub mode: usize,
    /// Natural frequency of the mode \[Hz\].
    pub frequency_hz: f64,
    /// FE node.
    pub node: usize,
    /// Component at the node.
    pub component: usize,
    /// Mass-normalised amplitude \[m/√kg or rad/√kg\].
    pub value: f64,
}

/// Rows for every mode and DOF, in mode-major order. `dofs[i]` labels
/// reduced DOF `i`; its length must be the number of DOFs.
pub fn mode_shape_rows(modes: &Modes, dofs: &[DofLabel]) -> Result<Vec<ModeShapeRow>> {
    let n = modes.modes.nrows();
    if dofs.len() != n {
        return Err(Error::input(
            "dof_map",
            format!("{} entries", dofs.len()),
            format!("{n} entries (one per reduced DOF)"),
        ));
    }
    let freq = modes.frequencies_hz();
    let mut rows = Vec::with_capacity(n * modes.lambda.len());
    for (j, &f) in freq.iter().enumerate() {
        for (i, d) in dofs.iter().enumerate() {
            rows.push(ModeShapeRow {
                mode: j,
                frequency_hz: f,
                node: d.node,
                component: d.component,
                value: modes.modes[(i, j)],
            });
        }
    }
    Ok(rows)
}
