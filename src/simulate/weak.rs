//! Constraint rows that are nearly dependent at the start of a run: kept
//! as independent by the rank test of the constraint-space factor
//! ([`crate::mbs::system::RANK_TOL`]) but close to the span of the rows
//! eliminated before them.
//!
//! The factor's scaled pivot of a row is its squared distance, in the
//! mass-weighted Gram sense and relative to its own length, from the span
//! of the rows before it (module doc of [`crate::mbs::math::sparse`]). A
//! pivot below [`WEAK_PIVOT`] (a row within 1 % of that span) is legal but
//! a sign of joints that nearly over-constrain a body: on a flexible body
//! whose modes reach a row only through small components (a spherical
//! joint beside a revolute hinge on the edge of a panel whose bending
//! modes move it in plane by about 1e-3 of their transverse entries), the
//! multipliers hold internal force loops far above the applied loads, the
//! run is stiff, its energy error does not fall with the tolerance, and
//! central differences of whole runs match the exact gradients only
//! roughly. Which rows of a nearly dependent set are named depends on the
//! elimination order, as for [`crate::mbs::Projection::dependent`].

use crate::mbs::system::{RANK_REG, RANK_TOL};
use crate::mbs::{System, Workspace};

/// Scaled pivot below which a kept constraint row is reported as nearly
/// dependent (a row within 1 % of the span of the rows before it).
pub const WEAK_PIVOT: f64 = 1e-4;

/// The kept rows whose scaled pivot lies between the rank tolerance and
/// [`WEAK_PIVOT`] at `(t, y)`, as `(label, pivot)` in row order.
pub fn weak_rows(sys: &System, t: f64, y: &[f64]) -> Vec<(String, f64)> {
    let mut ws = Workspace::<f64>::empty();
    sys.reactions(t, y, &mut ws);
    let m = ws.rows.len();
    if ws.inv_order.len() != m || ws.a.len() != m * m {
        return Vec::new();
    }
    (0..m)
        .filter(|&r| !sys.dropped(r))
        .filter_map(|r| {
            let p = ws.inv_order[r];
            let pivot = ws.a[p * m + p].powi(2) - RANK_REG;
            (pivot > RANK_TOL && pivot < WEAK_PIVOT).then(|| {
                let label = sys.model.row_label(r).unwrap_or_else(|| format!("row {r}"));
                (label, pivot)
            })
        })
        .collect()
}

/// The warning for the nearly dependent rows `weak` ([`weak_rows`]), if
/// any.
pub fn warning(weak: &[(String, f64)]) -> Option<String> {
    if weak.is_empty() {
        return None;
    }
    let rows: Vec<String> = weak
        .iter()
        .map(|(label, p)| format!("{label} (scaled pivot {p:.1e})"))
        .collect();
    Some(format!(
        "warning: constraint rows nearly dependent at the start: {}; they are kept (rank \
         tolerance {RANK_TOL:e}) but lie within 1 % of the span of the other rows, so the \
         joints nearly over-constrain the bodies (on a flexible body: its modes reach these \
         rows only through small components); expect large internal reactions, a stiff run, \
         an energy error that does not fall with the tolerance and gradients that central \
         differences of whole runs match only roughly",
        rows.join(", ")
    ))
}
