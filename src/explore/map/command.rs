//! `plyscape map`: the design-space map of `[map]` ([`crate::explore::map::grid`]
//! draws it), marked with the optima and evolutions found before.

use super::grid;
use super::section::map_section;
use crate::error::{Error, Result};
use crate::explore::context::Context;
use crate::explore::evolve::search::global_schedule;
use crate::explore::persist::fingerprint::{self, Fingerprint};
use crate::explore::persist::manifest::{DriverEntry, MapEntry};
use crate::explore::problem::build::problem;
use crate::report::manifest::Manifest;
use std::collections::BTreeMap;
use std::path::Path;

/// `plyscape map`: the grid(s), marked with the optima in `optima.csv` and
/// each evolution's best in `evolution.csv` when those exist in the study's
/// output directory. With `--resume` the cells already in the tables are
/// kept (after the checks of `check_resume` and [`grid::run`]) and only the
/// missing ones computed.
pub fn run_map(ctx: &Context) -> Result<Vec<grid::Slice>> {
    let problem = problem(ctx.study)?;
    let sec = map_section(ctx.study)?;
    let loc = ctx.study.locate("map");
    let vars = problem.variables();
    let n = vars.len();
    let pairs: Vec<(usize, usize)> = match &sec.pairs {
        Some(p) => {
            for (k, &[a, b]) in p.iter().enumerate() {
                if a >= n || b >= n || a == b {
                    return Err(loc(Error::input(
                        format!("pairs[{k}]"),
                        format!("[{a}, {b}]"),
                        format!("two different variable indices < {n}"),
                    )));
                }
            }
            p.iter().map(|&[a, b]| (a, b)).collect()
        }
        None => (0..n / 2).map(|k| (2 * k, 2 * k + 1)).collect(),
    };
    let dir = ctx.dir()?;
    let optima: Vec<Vec<f64>> = read_points(&dir.join("optima.csv"), "x_", vars)?
        .into_iter()
        .map(|(_, x)| x)
        .collect();
    let evo = read_points(&dir.join("evolution.csv"), "best_x_", vars)?;
    let base = optima
        .first()
        .cloned()
        .unwrap_or_else(|| vars.iter().map(|v| 0.5 * (v.lower + v.upper)).collect());
    let mut marks = Vec::new();
    if !optima.is_empty() {
        marks.push(("local optima".to_string(), optima));
    }
    marks.extend(evolution_marks(evo));
    let req = grid::MapRequest {
        resolution: sec.resolution,
        pairs,
        base,
        marks,
    };
    // With more than two variables, the design the slices pass through.
    let slices_through: Option<BTreeMap<String, f64>> = (n > 2).then(|| {
        vars.iter()
            .zip(&req.base)
            .map(|(v, &x)| (v.name.clone(), x))
            .collect()
    });
    if ctx.flags.resume {
        check_resume(ctx, &dir, slices_through.as_ref())?;
    }
    let entry = |complete| MapEntry {
        complete,
        resolution: sec.resolution,
        slices_through: slices_through.clone(),
    };
    ctx.manifest(&dir, "map", entry(false))?;
    let opts = grid::MapOptions {
        threads: ctx.threads,
        resume: ctx.flags.resume,
        quiet: ctx.quiet,
        checks: sec.resume_checks,
    };
    let slices = grid::run(problem.as_ref(), &req, &opts, &dir)?;
    ctx.manifest(&dir, "map", entry(true))?;
    if !ctx.quiet {
        println!(
            "map of {}: {} slice(s) of {}^2 points in {}",
            problem.name(),
            slices.len(),
            sec.resolution,
            dir.display()
        );
    }
    Ok(slices)
}

/// What `map --resume` checks before it reads the tables back: the
/// fingerprint of the evaluations ([`Fingerprint::evaluation_only`]: the
/// solver's settings do not enter a map) recorded by the `map` entry, and
/// with more than two variables the design the slices pass through (it
/// follows the best optimum of `optima.csv`). The grid itself is checked
/// row by row ([`grid::run`]).
fn check_resume(
    ctx: &Context,
    dir: &Path,
    slices_through: Option<&BTreeMap<String, f64>>,
) -> Result<()> {
    let now = Fingerprint::of_study(ctx.study).evaluation_only();
    let table = dir.join("map.csv");
    fingerprint::check_recorded(ctx.study, dir, &["map"], &now, &table)?;
    if !dir.join("manifest.json").exists() {
        return Ok(());
    }
    let recorded: Option<DriverEntry<MapEntry>> = Manifest::read(dir)?.entry("map");
    if let Some(e) = recorded {
        if e.detail.slices_through.as_ref() != slices_through {
            return Err(ctx.study.error(
                "--resume",
                dir.display(),
                format!(
                    "slices through the design they were computed at ({:?}), but they now pass \
                     through {:?} (the best optimum changed); rerun without --resume",
                    e.detail.slices_through, slices_through
                ),
            ));
        }
    }
    Ok(())
}

/// `CMA-ES best` for a table of one schedule and `<solver> best`
/// (`IPOP-CMA-ES best`, `BIPOP-CMA-ES best`) for each schedule of a table
/// with a `method` column.
fn evolution_marks(rows: Vec<(String, Vec<f64>)>) -> Vec<(String, Vec<Vec<f64>>)> {
    let mut out: Vec<(String, Vec<Vec<f64>>)> = Vec::new();
    for (method, x) in rows {
        let label = if method.is_empty() {
            "CMA-ES best".to_string()
        } else {
            match global_schedule(&method) {
                Some(r) => format!("{} best", r.solver_name()),
                None => format!("{method} best"),
            }
        };
        match out.iter_mut().find(|(l, _)| *l == label) {
            Some(mark) => mark.1 = vec![x],
            None => out.push((label, vec![x])),
        }
    }
    out
}

/// Designs from the `<prefix><name>` columns of a CSV, if the file exists,
/// each with its `method` field (empty when there is no such column).
fn read_points(
    path: &Path,
    prefix: &str,
    vars: &[crate::optimize::Variable],
) -> Result<Vec<(String, Vec<f64>)>> {
    if !path.exists() {
        return Ok(vec![]);
    }
    let mut rd = csv::Reader::from_path(path).map_err(|e| Error::csv(path, e))?;
    let headers = rd.headers().map_err(|e| Error::csv(path, e))?.clone();
    let cols: Option<Vec<usize>> = vars
        .iter()
        .map(|v| {
            headers
                .iter()
                .position(|h| h == format!("{prefix}{}", v.name))
        })
        .collect();
    let Some(cols) = cols else { return Ok(vec![]) };
    let method = headers.iter().position(|h| h == "method");
    let mut out = Vec::new();
    for r in rd.records() {
        let r = r.map_err(|e| Error::csv(path, e))?;
        let x: Option<Vec<f64>> = cols.iter().map(|&c| r.get(c)?.parse().ok()).collect();
        let tag = method.and_then(|c| r.get(c)).unwrap_or_default();
        if let Some(x) = x {
            out.push((tag.to_string(), x));
        }
    }
    Ok(out)
}
