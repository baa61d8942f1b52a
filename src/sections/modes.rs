//! Panel modal analysis as a study: `[[panels]]` + `[modes]` (and optionally
//! `[convergence]`) → `modes.csv`, `mode_derivatives.csv`, `mode_shapes.csv`,
//! `convergence.csv`.
//!
//! This is the first link of the chain seen from the command line
//! (`plyscape modes <study.toml>`): laminate → shell FE → reduced `K`, lumped
//! `M` → lowest modes by shift-invert Lanczos → `dλ/dθ`, `dX/dθ` per design
//! variable (paper §2.2, §3.1–3.2, §6.2).
//!
//! Panels that share mesh, lay-up and support share one modal analysis
//! (computed once). Derivative matrices are assembled only when the study
//! asks for derivatives, and `d²K/dθ²` only for the updated-mode approach
//! (the adjacent-eigenvector method for repeated modes needs it).
//!
//! Each mode gets a label telling what it is: `kind` (flexural, in-plane or
//! drilling, from where its kinetic energy `xᵀMx` sits) and, for flexural
//! modes, the symmetry of the transverse deflection `w` under the mirrors
//! x → −x and y → −y (`SS`, `SA`, `AS`, `AA`; first letter for x). A
//! twisting mode (w ∝ xy) is `AA`; the first symmetric bending mode is `SS`.
//! Where the mesh has no mirror nodes (an asymmetric set of attachment
//! points) or the correlation is weak, the symmetry is `-`.
//!
//! `rigid_content` is the share `‖Pφ‖²_M / ‖φ‖²_M` (dimensionless, 0..1)
//! of the mode that is a rigid motion of the panel frame, `P` the
//! M-orthogonal projector on the six rigid motions about the panel centre
//! ([`crate::panels::rigid`]). The modal bases of flexible bodies drop
//! modes above 0.9 ([`crate::panels::basis`]); this table lists every
//! computed mode.
//!
//! The analysis itself is [`crate::panels`].

use super::stats::median;
use crate::error::{Error, Result};
use crate::modal::ModeUpdate;
use crate::panels::{analyse_panel, dfreq_hz_per_deg, in_panel, PanelAnalysis, PanelModes};
use crate::report::csv::Table;
use crate::study::Study;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn default_n_modes() -> usize {
    14
}
fn default_update() -> String {
    "updated".into()
}
fn default_repeats() -> usize {
    5
}

/// The `[modes]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModesSpec {
    /// Lowest modes per panel (default 14, the paper's).
    #[serde(default = "default_n_modes")]
    pub n_modes: usize,
    /// Write `mode_derivatives.csv` (default false).
    #[serde(default)]
    pub derivatives: bool,
    /// "updated" (λ' and X', Eq. 18) or "fixed" (λ' only, Eq. 19).
    #[serde(default = "default_update")]
    pub update: String,
    /// Write `mode_shapes.csv` (default false: it is large).
    #[serde(default)]
    pub mode_shapes: bool,
    /// Reference frequencies \[Hz\] per panel name, printed beside ours
    /// (e.g. the paper's Tables 2–3; cite the source in the study file).
    #[serde(default)]
    pub reference_hz: BTreeMap<String, Vec<f64>>,
}

/// The `[convergence]` section: the "what accuracy costs in time" table.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvergenceSpec {
    /// Name of the `[[panels]]` entry to refine (its `divisions` is ignored).
    pub panel: String,
    /// Mesh densities (cells along the length), ascending; the last one is
    /// the reference for the error column.
    pub divisions: Vec<usize>,
    /// Timing repeats per density; the median is reported (default 5).
    #[serde(default = "default_repeats")]
    pub repeats: usize,
}

/// One computed mode, as written to `modes.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeRow {
    /// Panel name (`[[panels]]` entry).
    pub panel: String,
    /// Lay-up in degrees, e.g. `[0/90/90/0]`.
    pub layup: String,
    /// Mode number, 1-based, in ascending frequency.
    pub mode: usize,
    /// Natural frequency \[Hz\].
    pub frequency_hz: f64,
    /// Scaled eigen-residual `‖Kx − λMx‖₂ / (max(|λ|, |σ|) ‖Mx‖₂)`
    /// (dimensionless).
    pub residual: f64,
    /// Where the kinetic energy sits: `flexural`, `in-plane` or `drilling`.
    pub kind: &'static str,
    /// Mirror symmetry of a flexural mode (`SS`, `SA`, `AS`, `AA`; first
    /// letter for x), `-` if none is found (module doc).
    pub symmetry: &'static str,
    /// Rigid-body content `‖Pφ‖²_M / ‖φ‖²_M` ([`crate::panels::rigid`]).
    pub rigid_content: f64,
}

impl ModesSpec {
    fn update(&self) -> Result<ModeUpdate> {
        match self.update.as_str() {
            "updated" => Ok(ModeUpdate::Updated),
            "fixed" => Ok(ModeUpdate::Fixed),
            other => Err(Error::input(
                "update",
                format!("\"{other}\""),
                "\"updated\" (eigenvalue and eigenvector derivatives) or \"fixed\" (eigenvalue derivatives only)",
            )),
        }
    }
}

/// Read and check `[modes]`, `[[panels]]` and `[convergence]` without
/// analysing anything.
pub fn check(study: &Study) -> Result<ModesSpec> {
    let spec: ModesSpec = study.require_section("modes", "what modal analysis to run")?;
    checked_panels(study, &spec)?;
    study.section::<ConvergenceSpec>("convergence")?;
    Ok(spec)
}

/// The study's panels and the derivatives `spec` asks for, checked: at
/// least one panel, a known derivative kind, reference names that exist.
fn checked_panels(
    study: &Study,
    spec: &ModesSpec,
) -> Result<(Vec<crate::fe::Panel>, Option<ModeUpdate>)> {
    let panels = crate::fe::panels_from_study(study)?;
    if panels.is_empty() {
        return Err(study.error("panels", "(missing)", "at least one [[panels]] entry"));
    }
    let want = if spec.derivatives {
        Some(spec.update().map_err(study.locate("modes"))?)
    } else {
        None
    };
    for name in spec.reference_hz.keys() {
        if !panels.iter().any(|p| &p.name == name) {
            return Err(study.error(
                format!("modes.reference_hz.{name}"),
                format!("\"{name}\""),
                "the name of a [[panels]] entry",
            ));
        }
    }
    Ok((panels, want))
}

/// Run the modal analysis of every panel of the study, sharing analyses of
/// identical panels. Returns one result per panel, in file order.
pub fn analyse_study(study: &Study, spec: &ModesSpec) -> Result<Vec<PanelModes>> {
    let (panels, want) = checked_panels(study, spec)?;
    let mut out: Vec<PanelModes> = Vec::with_capacity(panels.len());
    for (i, p) in panels.iter().enumerate() {
        // Same mesh, lay-up, design map and support: reuse (compute once).
        let twin = panels[..i].iter().position(|q| {
            q.mesh == p.mesh
                && q.laminate == p.laminate
                && q.support == p.support
                && q.design == p.design
        });
        let r = match twin {
            Some(k) => {
                let mut r = out[k].clone();
                r.panel = p.name.clone();
                r.seconds = [0.0; 3];
                r
            }
            None => analyse_panel(p, spec.n_modes, want).map_err(|e| match e {
                // The mode count is the [modes] section's key, not the panel's.
                Error::Input { key, expected, .. } if key == "n_modes" => study.error(
                    "modes.n_modes",
                    spec.n_modes,
                    format!("{expected} (panel {})", p.name),
                ),
                e => in_panel(e, &p.name).in_file(&study.path, &format!("panels[{i}]")),
            })?,
        };
        out.push(r);
    }
    Ok(out)
}

/// Rows of `modes.csv`.
pub fn mode_rows(results: &[PanelModes]) -> Vec<ModeRow> {
    let mut rows = Vec::new();
    for r in results {
        for (j, f) in r.modes.frequencies_hz().into_iter().enumerate() {
            rows.push(ModeRow {
                panel: r.panel.clone(),
                layup: r.layup.clone(),
                mode: j + 1,
                frequency_hz: f,
                residual: r.modes.residuals[j],
                kind: r.labels[j].0,
                symmetry: r.labels[j].1,
                rigid_content: r.rigid_content[j],
            });
        }
    }
    rows
}

/// Write `modes.csv`, and `mode_derivatives.csv` when the spec asks for it.
/// Returns the files written.
pub fn write_results(dir: &Path, results: &[PanelModes], spec: &ModesSpec) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let path = dir.join("modes.csv");
    let mut w = Table::new(&path);
    w.row([
        "panel",
        "layup",
        "mode",
        "frequency_hz",
        "reference_hz",
        "residual",
        "kind",
        "symmetry",
        "rigid_content",
    ])?;
    for row in mode_rows(results) {
        let reference = spec
            .reference_hz
            .get(&row.panel)
            .and_then(|v| v.get(row.mode - 1))
            .map(|f| f.to_string())
            .unwrap_or_default();
        w.row([
            row.panel,
            row.layup,
            row.mode.to_string(),
            format!("{:.6}", row.frequency_hz),
            reference,
            format!("{:.2e}", row.residual),
            row.kind.to_string(),
            row.symmetry.to_string(),
            format!("{:.9}", row.rigid_content),
        ])?;
    }
    w.finish()?;
    files.push(path);

    if spec.derivatives {
        let path = dir.join("mode_derivatives.csv");
        let mut w = Table::new(&path);
        w.row([
            "panel",
            "mode",
            "variable",
            "dlambda_per_rad",
            "dfreq_hz_per_deg",
            "cluster_size",
        ])?;
        for r in results {
            for (v, d) in r.derivatives.iter().enumerate() {
                for (j, &dl) in d.dlambda.iter().enumerate() {
                    let cluster = d
                        .clusters
                        .iter()
                        .find(|c| j >= c.first && j < c.first + c.len)
                        .map_or(1, |c| c.len);
                    w.row([
                        r.panel.clone(),
                        (j + 1).to_string(),
                        r.variables[v].clone(),
                        format!("{dl:.9e}"),
                        format!("{:.9e}", dfreq_hz_per_deg(r.modes.lambda[j], dl)),
                        cluster.to_string(),
                    ])?;
                }
            }
        }
        w.finish()?;
        files.push(path);
    }
    Ok(files)
}

/// Write `mode_shapes.csv`: panel, mode, node, x, y, component, value.
pub fn write_mode_shapes(dir: &Path, results: &[PanelModes]) -> Result<PathBuf> {
    let path = dir.join("mode_shapes.csv");
    let mut w = Table::new(&path);
    w.row(["panel", "mode", "node", "x_m", "y_m", "component", "value"])?;
    for r in results {
        for j in 0..r.modes.lambda.len() {
            for (i, &(node, comp)) in r.dof_map.iter().enumerate() {
                let [x, y] = r.nodes[node];
                w.row([
                    r.panel.clone(),
                    (j + 1).to_string(),
                    node.to_string(),
                    format!("{x:.6}"),
                    format!("{y:.6}"),
                    comp.to_string(),
                    format!("{:.9e}", r.modes.modes[(i, j)]),
                ])?;
            }
        }
    }
    w.finish()?;
    Ok(path)
}

/// Print the frequency table, with reference columns where given.
pub fn print_table(results: &[PanelModes], spec: &ModesSpec) {
    for r in results {
        println!(
            "{} {} ({} DOF; assembly {:.1} ms, modes {:.1} ms, derivatives {:.1} ms)",
            r.panel,
            r.layup,
            r.dofs,
            1e3 * r.seconds[0],
            1e3 * r.seconds[1],
            1e3 * r.seconds[2]
        );
        let reference = spec.reference_hz.get(&r.panel);
        println!(
            "  mode  f [Hz]     {}kind      symmetry  rigid content",
            if reference.is_some() {
                "ref [Hz]  ratio  "
            } else {
                ""
            }
        );
        for (j, f) in r.modes.frequencies_hz().iter().enumerate() {
            let refcol = match reference.and_then(|v| v.get(j)) {
                Some(fr) => format!("{fr:<9.3} {:<6.3} ", f / fr),
                None if reference.is_some() => format!("{:<17}", ""),
                None => String::new(),
            };
            println!(
                "  {:>4}  {:<9.4}  {refcol}{:<9} {:<9} {:.7}",
                j + 1,
                f,
                r.labels[j].0,
                r.labels[j].1,
                r.rigid_content[j]
            );
        }
    }
}

/// One row of `convergence.csv`.
#[derive(Debug, Clone)]
pub struct ConvergenceRow {
    /// Mesh density: cells along the panel's length.
    pub divisions: usize,
    /// Reduced degrees of freedom of the mesh.
    pub dofs: usize,
    /// First flexural mode with symmetry SS \[Hz\].
    pub symmetric_hz: Option<f64>,
    /// First flexural mode with symmetry AA (twisting) \[Hz\].
    pub twisting_hz: Option<f64>,
    /// Median wall times per design \[s\] (set-up excluded): assembly +
    /// modes; assembly with derivative matrices + modes + derivatives for
    /// every design variable.
    pub modes_seconds: f64,
    /// Median wall time per design with derivative matrices and the
    /// derivatives for every design variable \[s\] (see `modes_seconds`).
    pub with_derivatives_seconds: f64,
    /// Median split of the second timing \[s\]: assembly, modes, derivatives.
    pub split_seconds: [f64; 3],
    /// One-off set-up with derivative matrices (mesh, pattern, symbolic
    /// factorization) \[s\].
    pub setup_seconds: f64,
}

fn first_with(r: &PanelModes, symmetry: &str) -> Option<f64> {
    let f = r.modes.frequencies_hz();
    r.labels
        .iter()
        .position(|&(k, s)| k == "flexural" && s == symmetry)
        .map(|j| f[j])
}

/// The convergence-and-cost table for one panel over mesh densities.
pub fn convergence(
    study: &Study,
    spec: &ConvergenceSpec,
    n_modes: usize,
) -> Result<Vec<ConvergenceRow>> {
    let specs: Vec<crate::fe::PanelSpec> = study.section("panels")?.unwrap_or_default();
    let Some(i) = specs.iter().position(|p| p.name == spec.panel) else {
        return Err(study.error(
            "convergence.panel",
            format!("\"{}\"", spec.panel),
            "the name of a [[panels]] entry",
        ));
    };
    if spec.divisions.is_empty() || spec.divisions.windows(2).any(|w| w[0] >= w[1]) {
        return Err(study.error(
            "convergence.divisions",
            format!("{:?}", spec.divisions),
            "a non-empty, strictly ascending list of mesh densities",
        ));
    }
    if spec.repeats == 0 {
        return Err(study.error("convergence.repeats", 0, "at least 1"));
    }
    let mut rows = Vec::new();
    for &d in &spec.divisions {
        let mut s = specs[i].clone();
        s.divisions = d;
        let panel = s.resolve().map_err(study.locate(&format!("panels[{i}]")))?;
        let mut plain_a = PanelAnalysis::new(&panel, None)?;
        let mut full_a = PanelAnalysis::new(&panel, Some(ModeUpdate::Updated))?;
        let mut plain = Vec::new();
        let mut full = Vec::new();
        let mut splits = [Vec::new(), Vec::new(), Vec::new()];
        let mut last = None;
        for _ in 0..spec.repeats {
            let t = Instant::now();
            let r = plain_a.run(&panel.laminate, n_modes)?;
            plain.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            let rd = full_a.run(&panel.laminate, n_modes)?;
            full.push(t.elapsed().as_secs_f64());
            for (k, s) in splits.iter_mut().enumerate() {
                s.push(rd.seconds[k]);
            }
            last = Some(r);
        }
        let r = last.expect("repeats >= 1");
        rows.push(ConvergenceRow {
            divisions: d,
            dofs: r.dofs,
            symmetric_hz: first_with(&r, "SS"),
            twisting_hz: first_with(&r, "AA"),
            modes_seconds: median(plain),
            with_derivatives_seconds: median(full),
            split_seconds: splits.map(median),
            setup_seconds: full_a.setup_seconds,
        });
    }
    Ok(rows)
}

/// Write `convergence.csv` (errors relative to the finest mesh).
pub fn write_convergence(dir: &Path, rows: &[ConvergenceRow]) -> Result<PathBuf> {
    let path = dir.join("convergence.csv");
    let mut w = Table::new(&path);
    w.row([
        "divisions",
        "dofs",
        "symmetric_hz",
        "symmetric_error",
        "twisting_hz",
        "twisting_error",
        "modes_ms",
        "modes_and_derivatives_ms",
        "assembly_ms",
        "eigen_ms",
        "derivatives_ms",
        "setup_ms",
    ])?;
    let fin = rows.last();
    let err = |v: Option<f64>, r: Option<f64>| match (v, r) {
        (Some(v), Some(r)) => format!("{:.3e}", (v - r).abs() / r),
        _ => String::new(),
    };
    let opt = |v: Option<f64>| v.map(|v| format!("{v:.6}")).unwrap_or_default();
    for row in rows {
        w.row([
            row.divisions.to_string(),
            row.dofs.to_string(),
            opt(row.symmetric_hz),
            err(row.symmetric_hz, fin.and_then(|f| f.symmetric_hz)),
            opt(row.twisting_hz),
            err(row.twisting_hz, fin.and_then(|f| f.twisting_hz)),
            format!("{:.2}", 1e3 * row.modes_seconds),
            format!("{:.2}", 1e3 * row.with_derivatives_seconds),
            format!("{:.2}", 1e3 * row.split_seconds[0]),
            format!("{:.2}", 1e3 * row.split_seconds[1]),
            format!("{:.2}", 1e3 * row.split_seconds[2]),
            format!("{:.2}", 1e3 * row.setup_seconds),
        ])?;
    }
    w.finish()?;
    Ok(path)
}

/// `plyscape modes` / the `[modes]` handler of `plyscape run`.
pub fn run_modes(study: &Study, out_root: &Path, quiet: bool) -> Result<()> {
    // The panels are checked by `analyse_study`, the rest below.
    let spec: ModesSpec = study.require_section("modes", "what modal analysis to run")?;
    let results = analyse_study(study, &spec)?;
    let dir = study.output_dir(out_root)?;
    let mut files = write_results(&dir, &results, &spec)?;
    if spec.mode_shapes {
        files.push(write_mode_shapes(&dir, &results)?);
    }
    if let Some(conv) = study.section::<ConvergenceSpec>("convergence")? {
        let rows = convergence(study, &conv, spec.n_modes)?;
        files.push(write_convergence(&dir, &rows)?);
        if !quiet {
            println!(
                "mesh convergence of {} (median of {} runs):",
                conv.panel, conv.repeats
            );
            println!("  div   DOF     f_SS [Hz]  f_AA [Hz]  modes [ms]  +derivs [ms]");
            for r in &rows {
                println!(
                    "  {:>4}  {:>6}  {:<9}  {:<9}  {:>9.2}  {:>11.2}",
                    r.divisions,
                    r.dofs,
                    r.symmetric_hz.map_or("-".into(), |f| format!("{f:.4}")),
                    r.twisting_hz.map_or("-".into(), |f| format!("{f:.4}")),
                    1e3 * r.modes_seconds,
                    1e3 * r.with_derivatives_seconds
                );
            }
        }
    }
    if !quiet {
        print_table(&results, &spec);
        for f in &files {
            println!("wrote {}", f.display());
        }
    }
    Ok(())
}
