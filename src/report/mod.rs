//! Reports: progress bars, the run manifest and SVG plots.
//!
//! Solvers and drivers never format output themselves: drivers hand numbers
//! to this module. Progress bars draw on stderr only when it is a terminal
//! and `--quiet` was not given. SVG plots use plotters' SVG backend (text is
//! laid out by the browser, so no font files are needed).

pub mod clock;
pub mod csv;
pub mod lock;

use crate::error::{Error, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use plotters::prelude::*;
use std::path::Path;

/// A progress bar (hidden when quiet or when stderr is not a terminal).
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar for `len` steps labelled `label`.
    pub fn new(label: &str, len: u64, quiet: bool) -> Progress {
        let target = if quiet {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        };
        let bar = ProgressBar::with_draw_target(Some(len), target);
        if let Ok(style) =
            ProgressStyle::with_template("{prefix} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}")
        {
            bar.set_style(style);
        }
        bar.set_prefix(label.to_string());
        Progress { bar }
    }

    /// One step done; `msg` replaces the message.
    pub fn inc(&self, msg: &str) {
        self.bar.set_message(msg.to_string());
        self.bar.inc(1);
    }

    /// Set the position and message.
    pub fn set(&self, pos: u64, msg: &str) {
        self.bar.set_message(msg.to_string());
        self.bar.set_position(pos);
    }

    /// Remove the bar (the drivers print a summary instead).
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// `(name, version)` of every direct dependency, from the `Cargo.lock` and
/// `Cargo.toml` this binary was built from. When the lock file holds several
/// versions of a crate, the one matching the requirement's caret prefix
/// (`0.9` -> `0.9.*`, `1.10` -> `1.*`) is taken.
pub fn crate_versions() -> Vec<(String, String)> {
    let lock = include_str!("../../Cargo.lock");
    let manifest = include_str!("../../Cargo.toml");
    let direct: Vec<(&str, String)> = manifest
        .split("[dependencies]")
        .nth(1)
        .unwrap_or("")
        .lines()
        .take_while(|l| !l.starts_with('['))
        .filter_map(|l| {
            let (name, rest) = l.split_once('=')?;
            let req = rest.split('"').nth(1)?;
            let mut parts = req.split('.');
            let major = parts.next()?;
            let prefix = if major == "0" {
                format!("0.{}.", parts.next()?)
            } else {
                format!("{major}.")
            };
            Some((name.trim(), prefix))
        })
        .collect();
    let mut out = Vec::new();
    for block in lock.split("[[package]]") {
        let field = |key: &str| {
            block
                .lines()
                .find_map(|l| l.strip_prefix(key))
                .map(|v| v.trim().trim_matches('"').to_string())
        };
        if let (Some(n), Some(v)) = (field("name = "), field("version = ")) {
            if direct
                .iter()
                .any(|(d, p)| *d == n && v.starts_with(p.as_str()))
            {
                out.push((n, v));
            }
        }
    }
    out
}

/// The git commit this binary was built from (`-dirty` when tracked files
/// differed from it; `unknown` without git), recorded by `build.rs`.
pub const GIT_COMMIT: &str = env!("PLYSCAPE_GIT_COMMIT");

/// When this process started its work (set by [`mark_start`], else at the
/// first manifest written).
static STARTED: std::sync::OnceLock<std::time::SystemTime> = std::sync::OnceLock::new();

/// Record now as the start of this process's work (the command line calls
/// it first thing; later calls keep the first time).
pub fn mark_start() {
    STARTED.get_or_init(std::time::SystemTime::now);
}

/// Update `manifest.json` in `dir`: everything needed to reproduce the
/// tables next to it. Common fields at the top (version, git commit, study,
/// seed, threads, crate versions, the study text, `top`), and one entry per
/// command under `commands`: the entries of earlier commands on the same
/// study text are kept, so `plyscape run` records every step. Each entry
/// gets `started` (when this process began) and `ended` (now) as UTC
/// timestamps.
pub fn record_command(
    dir: &Path,
    study: &crate::study::Study,
    threads: usize,
    command: &str,
    mut entry: serde_json::Map<String, serde_json::Value>,
    top: serde_json::Map<String, serde_json::Value>,
) -> Result<()> {
    use serde_json::json;
    mark_start();
    let started = *STARTED.get().expect("set just above");
    entry.insert("started".into(), json!(clock::iso_utc(started)));
    entry.insert(
        "ended".into(),
        json!(clock::iso_utc(std::time::SystemTime::now())),
    );
    let mut commands = read_manifest(dir)
        .ok()
        .filter(|m| m["study_text"].as_str() == Some(study.text.as_str()))
        .and_then(|m| m["commands"].as_object().cloned())
        .unwrap_or_default();
    commands.insert(command.into(), serde_json::Value::Object(entry));
    let crates: serde_json::Map<String, serde_json::Value> = crate_versions()
        .into_iter()
        .map(|(n, v)| (n, json!(v)))
        .collect();
    let mut m = serde_json::Map::new();
    m.insert("plyscape_version".into(), json!(env!("CARGO_PKG_VERSION")));
    m.insert("git_commit".into(), json!(GIT_COMMIT));
    m.insert("study_file".into(), json!(study.path.display().to_string()));
    m.insert("study_name".into(), json!(study.name()));
    m.insert("seed".into(), json!(study.meta.seed));
    m.insert("threads".into(), json!(threads));
    m.insert("crates".into(), serde_json::Value::Object(crates));
    m.extend(top);
    m.insert("last_command".into(), json!(command));
    m.insert("commands".into(), serde_json::Value::Object(commands));
    m.insert("study_text".into(), json!(study.text));
    let text = serde_json::to_string_pretty(&serde_json::Value::Object(m))
        .map_err(|e| Error::csv(dir.join("manifest.json"), e))?;
    csv::write_bytes_atomic(&dir.join("manifest.json"), text.as_bytes())
}

/// Read `manifest.json` from `dir`.
pub fn read_manifest(dir: &Path) -> Result<serde_json::Value> {
    let path = dir.join("manifest.json");
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::csv(&path, e))
}

fn plot_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::csv(path, format!("SVG drawing failed: {e}"))
}

/// A named curve for [`line_plot`].
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// Points `(x, y)`, finite.
    pub points: Vec<(f64, f64)>,
}

/// Axis labels and title of a line plot.
pub struct Axes<'a> {
    /// Title.
    pub title: &'a str,
    /// x label.
    pub x: &'a str,
    /// y label.
    pub y: &'a str,
}

/// Draw curves into an SVG (linear axes, legend).
pub fn line_plot(path: &Path, axes: &Axes, curves: &[Curve]) -> Result<()> {
    let pts = curves
        .iter()
        .flat_map(|c| c.points.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in pts {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return Ok(());
    }
    let pad = |a: f64, b: f64| {
        if b > a {
            0.05 * (b - a)
        } else {
            0.5 * a.abs().max(1.0)
        }
    };
    let (px, py) = (pad(x0, x1), pad(y0, y1));
    let root = SVGBackend::new(path, (800, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(axes.title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0 - px..x1 + px, y0 - py..y1 + py)
        .map_err(|e| plot_err(path, e))?;
    chart
        .configure_mesh()
        .x_desc(axes.x)
        .y_desc(axes.y)
        .draw()
        .map_err(|e| plot_err(path, e))?;
    for (i, c) in curves.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(
                c.points.iter().copied(),
                color.stroke_width(2),
            ))
            .map_err(|e| plot_err(path, e))?
            .label(c.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| plot_err(path, e))?;
    root.present().map_err(|e| plot_err(path, e))
}

/// A heat map: a regular grid of values, cells that violate constraints,
/// and marked points.
pub struct HeatMap<'a> {
    /// Title.
    pub title: &'a str,
    /// Axis names.
    pub names: (&'a str, &'a str),
    /// Grid coordinates along x (`nx`) and y (`ny`), increasing.
    pub xs: &'a [f64],
    /// Grid coordinates along y.
    pub ys: &'a [f64],
    /// Values, `values[i * ny + j]` at `(xs[i], ys[j])`.
    pub values: &'a [f64],
    /// Infeasible cells (same indexing), drawn greyed.
    pub infeasible: &'a [bool],
    /// Marked points: label, points, colour index.
    pub marks: Vec<(String, Vec<(f64, f64)>)>,
}

/// Colour for `t` in `[0, 1]` (a viridis-like ramp: dark blue, teal, yellow).
fn ramp(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let s = t.clamp(0.0, 1.0) * 4.0;
    let i = (s.floor() as usize).min(3);
    let w = s - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: f64, q: f64| (p + w * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Draw a heat map SVG. Colours follow `log(1 + (v - min) / s)` with
/// `s = (max - min) / 1000`, so the basins stay visible next to tall peaks.
pub fn heat_map(path: &Path, map: &HeatMap) -> Result<()> {
    let (nx, ny) = (map.xs.len(), map.ys.len());
    if nx < 2 || ny < 2 || map.values.len() != nx * ny {
        return Err(plot_err(path, "grid needs at least 2 x 2 values"));
    }
    let vmin = map.values.iter().copied().fold(f64::INFINITY, f64::min);
    let vmax = map.values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let s = ((vmax - vmin) / 1000.0).max(1e-300);
    let top = (1.0 + (vmax - vmin) / s).ln().max(1e-300);
    let half = |c: &[f64], i: usize| {
        let lo = if i == 0 {
            c[0]
        } else {
            0.5 * (c[i - 1] + c[i])
        };
        let hi = if i + 1 == c.len() {
            c[i]
        } else {
            0.5 * (c[i] + c[i + 1])
        };
        (lo, hi)
    };
    let root = SVGBackend::new(path, (760, 700)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(map.title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(map.xs[0]..map.xs[nx - 1], map.ys[0]..map.ys[ny - 1])
        .map_err(|e| plot_err(path, e))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(map.names.0)
        .y_desc(map.names.1)
        .draw()
        .map_err(|e| plot_err(path, e))?;
    let mut cells = Vec::with_capacity(nx * ny);
    for i in 0..nx {
        for j in 0..ny {
            let v = map.values[i * ny + j];
            let mut c = ramp((1.0 + (v - vmin) / s).ln() / top);
            if map.infeasible.get(i * ny + j).copied().unwrap_or(false) {
                let grey = |u: u8| ((u as f64 + 2.0 * 200.0) / 3.0) as u8;
                c = RGBColor(grey(c.0), grey(c.1), grey(c.2));
            }
            let ((x0, x1), (y0, y1)) = (half(map.xs, i), half(map.ys, j));
            cells.push(Rectangle::new([(x0, y0), (x1, y1)], c.filled()));
        }
    }
    chart.draw_series(cells).map_err(|e| plot_err(path, e))?;
    let colors = [RED, WHITE, MAGENTA, CYAN];
    for (k, (label, pts)) in map.marks.iter().enumerate() {
        let color = colors[k % colors.len()];
        chart
            .draw_series(pts.iter().map(|&p| Cross::new(p, 7, color.stroke_width(3))))
            .map_err(|e| plot_err(path, e))?
            .label(label.clone())
            .legend(move |(x, y)| Cross::new((x + 8, y), 5, color.stroke_width(3)));
    }
    if !map.marks.is_empty() {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| plot_err(path, e))?;
    }
    root.present().map_err(|e| plot_err(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crate_versions_come_from_the_lock_file() {
        let v = crate_versions();
        let names: Vec<&str> = v.iter().map(|(n, _)| n.as_str()).collect();
        for dep in ["nalgebra", "rayon", "rand_chacha", "plotters"] {
            assert!(names.contains(&dep), "{names:?}");
        }
        // One version per crate, the one Cargo.toml asks for (rand 0.9).
        assert_eq!(names.iter().filter(|n| **n == "rand").count(), 1);
        assert!(v
            .iter()
            .any(|(n, ver)| n == "rand" && ver.starts_with("0.9.")));
    }

    #[test]
    fn ramp_ends() {
        assert_eq!(ramp(0.0), RGBColor(68, 1, 84));
        assert_eq!(ramp(1.0), RGBColor(253, 231, 37));
    }
}
