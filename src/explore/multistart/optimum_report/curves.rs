//! `start_optimum_<q>.csv` and `.svg`: a scene output `q(t)` simulated at
//! the start design and at the optimum (the paper's Fig. 12 for the R3
//! actuator angle, Figs. 13–14 for the panels' strain energies).
//!
//! Columns: `t [s]`, `<q> at start [unit]`, `<q> at optimum [unit]`,
//! `optimum - start [unit]`, 12 significant digits as in `history.csv`.
//! Both simulations write at the scene's output times (`dt_out`); times
//! that differ between them are a numerical error, not a table.

use crate::error::{Error, Result};
use crate::report::csv::{sci, write_table};
use crate::report::{line_plot, Axes, Curve, Scale};
use crate::simulate::Simulation;
use std::path::{Path, PathBuf};

/// A design \[its variables' unit\] and its simulation.
pub struct Design<'a> {
    /// Design variables \[the problem's variable unit, e.g. deg\].
    pub x: &'a [f64],
    /// The scene simulated at `x`; its outputs give the curves.
    pub sim: &'a Simulation,
}

impl Design<'_> {
    /// `[55.00, -55.00] deg`.
    fn label(&self, unit: &str) -> String {
        let parts: Vec<String> = self.x.iter().map(|v| format!("{v:.2}")).collect();
        format!("[{}] {unit}", parts.join(", "))
    }
}

/// File stem of output `q`: `R3.angle` → `start_optimum_R3_angle`.
pub fn stem(q: &str) -> String {
    let safe: String = q
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    format!("start_optimum_{safe}")
}

/// The column of output `q` in a simulation and its unit (`R3.angle
/// [rad]` → `rad`).
fn column(sim: &Simulation, q: &str) -> Result<(usize, String)> {
    let prefix = format!("{q} [");
    sim.headers
        .iter()
        .position(|h| h.starts_with(&prefix))
        .map(|c| {
            let unit = sim.headers[c][prefix.len()..].trim_end_matches(']');
            (c, unit.to_string())
        })
        .ok_or_else(|| {
            Error::numerical(
                "optimum_report",
                format!("no column {q} among {:?}", sim.headers),
            )
        })
}

/// The output times are the same in both simulations (to 1e-12 s).
fn same_times(a: &Simulation, b: &Simulation) -> Result<()> {
    let same = a.rows.len() == b.rows.len()
        && a.rows
            .iter()
            .zip(&b.rows)
            .all(|(r, s)| (r[0] - s[0]).abs() <= 1e-12 * r[0].abs().max(1.0));
    if same {
        Ok(())
    } else {
        Err(Error::numerical(
            "optimum_report",
            format!(
                "output times differ between start and optimum ({} and {} rows)",
                a.rows.len(),
                b.rows.len()
            ),
        ))
    }
}

/// Write the table and plot of every output in `quantities` into `dir`.
pub fn write(
    dir: &Path,
    quantities: &[String],
    x_unit: &str,
    start: &Design,
    optimum: &Design,
) -> Result<Vec<PathBuf>> {
    same_times(start.sim, optimum.sim)?;
    let mut files = Vec::new();
    for q in quantities {
        let (c, unit) = column(start.sim, q)?;
        let (d, _) = column(optimum.sim, q)?;
        let header = [
            "t [s]".to_string(),
            format!("{q} at start [{unit}]"),
            format!("{q} at optimum [{unit}]"),
            format!("optimum - start [{unit}]"),
        ];
        let rows: Vec<Vec<String>> = start
            .sim
            .rows
            .iter()
            .zip(&optimum.sim.rows)
            .map(|(a, b)| [a[0], a[c], b[d], b[d] - a[c]].map(|v| sci(v, 12)).to_vec())
            .collect();
        let base = dir.join(stem(q));
        let csv = base.with_extension("csv");
        write_table(&csv, &header, &rows)?;
        let svg = base.with_extension("svg");
        let curve = |label: String, sim: &Simulation, col: usize| Curve {
            label,
            points: sim.rows.iter().map(|r| (r[0], r[col])).collect(),
        };
        line_plot(
            &svg,
            &Axes {
                title: &format!("{q} at the start and at the optimum"),
                x: "t [s]",
                y: &format!("{q} [{unit}]"),
                scale: Scale::Linear,
            },
            &[
                curve(format!("start {}", start.label(x_unit)), start.sim, c),
                curve(format!("optimum {}", optimum.label(x_unit)), optimum.sim, d),
            ],
        )?;
        files.extend([csv, svg]);
    }
    Ok(files)
}
