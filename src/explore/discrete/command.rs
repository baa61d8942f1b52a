//! `[discrete]` in `plyscape run`: the study's problem on its discrete
//! sets, searched by the exhaustive enumeration (when small enough), the
//! rounding and polish of the multistart's certified optima and CMA-ES on
//! the set ([`crate::explore::discrete`]); `discrete.csv` lists them side
//! by side, `discrete_grid.csv` every enumerated design. It runs after the
//! multistart, whose `optima.csv` it reads.

use crate::error::{Error, Result};
use crate::explore::context::Context;
use crate::explore::discrete::{self, Cache, Candidate, Found, Lattice};
use crate::explore::multistart::section::multistart_section;
use crate::explore::persist::journal::Journaled;
use crate::explore::problem::build::problem;
use crate::optimize::{Problem, Variable};
use crate::report::csv::num;
use crate::report::Progress;
use crate::study::Study;
use std::path::Path;

/// One row of `discrete.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscreteRow {
    /// `exhaustive`, `rounded`, `rounded_polished` or `cmaes_discrete`.
    pub method: String,
    /// The continuous optimum a rounded row comes from (its id in
    /// `optima.csv`).
    pub from_optimum: Option<usize>,
    /// The design and its values.
    pub design: Candidate,
    /// Distinct designs the method asked for.
    pub evaluations: usize,
    /// Designs asked for, repeats included.
    pub samples: usize,
}

/// Check `[discrete]`: its values, and that a `[multistart]` provides the
/// continuous optima it rounds.
pub fn check(study: &Study) -> Result<()> {
    let Some(section) = discrete::lattice::section(study)? else {
        return Ok(());
    };
    if !study.has("multistart") {
        return Err(study.error(
            "discrete",
            "(table)",
            "a [multistart] too: the gradient route rounds its certified optima",
        ));
    }
    // The sets against the variables (names, bounds, steps), before any
    // section runs.
    let vars = crate::explore::problem::build::variables(study)?;
    let generation = crate::optimize::cmaes::default_population(vars.len());
    if section.cmaes_samples < generation {
        return Err(study.error(
            "discrete.cmaes_samples",
            section.cmaes_samples,
            format!(
                "a budget of at least one CMA-ES generation: {generation} designs for {} \
                 variables",
                vars.len()
            ),
        ));
    }
    Lattice::new(&vars, &section)
        .map(|_| ())
        .map_err(study.locate(""))
}

/// The certified continuous optima of `optima.csv` in `dir`: (id, x).
pub fn read_optima(dir: &Path, vars: &[Variable]) -> Result<Vec<(usize, Vec<f64>)>> {
    let path = dir.join("optima.csv");
    let mut reader = csv::Reader::from_path(&path).map_err(|e| Error::csv(&path, e))?;
    let header = reader.headers().map_err(|e| Error::csv(&path, e))?.clone();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| Error::csv(&path, format!("no column `{name}`")))
    };
    let id = col("optimum")?;
    let xs: Vec<usize> = vars
        .iter()
        .map(|v| col(&format!("x_{}", v.name)))
        .collect::<Result<_>>()?;
    let mut out = Vec::new();
    for (r, rec) in reader.records().enumerate() {
        let rec = rec.map_err(|e| Error::csv(&path, e))?;
        let bad =
            |c: usize| Error::csv(&path, format!("row {}: column {c} is not a number", r + 1));
        let k: usize = rec[id].parse().map_err(|_| bad(id))?;
        let x = xs
            .iter()
            .map(|&c| rec[c].parse::<f64>().map_err(|_| bad(c)))
            .collect::<Result<Vec<f64>>>()?;
        out.push((k, x));
    }
    Ok(out)
}

/// Run `[discrete]`: the three searches, `discrete.csv`,
/// `discrete_grid.csv` (when enumerated), the manifest entry and a
/// summary.
pub fn run_discrete(ctx: &Context) -> Result<Vec<DiscreteRow>> {
    let t0 = std::time::Instant::now();
    let study = ctx.study;
    check(study)?;
    let section = discrete::lattice::section(study)?
        .ok_or_else(|| study.error("discrete", "(missing)", "a [discrete] table"))?;
    let built = problem(study)?;
    let journal = ctx.journal("discrete", "")?;
    let problem = Journaled::new(built.as_ref(), &journal)?;
    let vars = problem.variables();
    let lattice = Lattice::new(vars, &section).map_err(study.locate(""))?;
    let tol = multistart_section(study)?.feasibility_tolerance;
    let dir = ctx.dir()?;
    let optima = read_optima(&dir, vars)?;
    let cache = Cache::default();
    let pool = crate::explore::context::thread_pool(ctx.threads)?;
    let row = |method: &str, from: Option<usize>, found: &Found| DiscreteRow {
        method: method.into(),
        from_optimum: from,
        design: found.best.clone(),
        evaluations: found.evaluations,
        samples: found.samples,
    };
    let mut rows = Vec::new();
    let mut grid = None;
    pool.install(|| -> Result<()> {
        let small = lattice
            .size()
            .is_some_and(|n| n <= section.exhaustive_limit);
        // One line per stage on stderr (the stages run minutes on a
        // scene, and print their results only at the end), then a bar (or
        // a counter) of the stage's evaluations.
        let stage = |what: String, len: Option<usize>| {
            journal.watch(None);
            if !ctx.quiet {
                eprintln!(
                    "discrete: {what} ({:.1} s so far)",
                    t0.elapsed().as_secs_f64()
                );
            }
            journal.watch(Some(match len {
                Some(n) => Progress::new("discrete", n as u64, ctx.quiet),
                None => Progress::counter("discrete", "evaluations", ctx.quiet),
            }));
        };
        if small {
            stage(
                format!(
                    "exhaustive search over the {} designs of the set",
                    lattice.size().unwrap_or(0)
                ),
                lattice.size(),
            );
            if let Some((all, found)) = discrete::exhaustive(&problem, &lattice, &cache, tol)? {
                rows.push(row("exhaustive", None, &found));
                grid = Some(all);
            }
        }
        for (id, x) in &optima {
            stage(
                format!(
                    "optimum {id} of {}: rounded to the set, then a coordinate descent on it",
                    optima.len()
                ),
                None,
            );
            let (rounded, found) = discrete::round_and_polish(&problem, &lattice, &cache, x, tol)?;
            let once = Found {
                best: rounded,
                evaluations: 1,
                samples: 1,
            };
            rows.push(row("rounded", Some(*id), &once));
            rows.push(row("rounded_polished", Some(*id), &found));
        }
        stage(
            format!(
                "CMA-ES on the set, {} designs asked for",
                section.cmaes_samples
            ),
            None,
        );
        let found = discrete::cmaes_on_set(
            &problem,
            &lattice,
            &cache,
            section.cmaes_samples,
            section.min_std,
            study.meta.seed,
            tol,
        )?;
        rows.push(row("cmaes_discrete", None, &found));
        journal.watch(None);
        Ok(())
    })?;
    let m = problem.n_constraints();
    crate::explore::persist::tables::write_atomic(
        &dir.join("discrete.csv"),
        &table(vars, m, &rows, tol),
    )?;
    if let Some(all) = &grid {
        crate::explore::persist::tables::write_atomic(
            &dir.join("discrete_grid.csv"),
            &grid_table(vars, m, all, tol),
        )?;
    }
    let entry = serde_json::json!({
        "simulations": cache.len(),
        "designs_on_the_set": lattice.size(),
        "feasibility_tolerance": tol,
        "wall_seconds": t0.elapsed().as_secs_f64(),
        "replayed": journal.replayed(),
    });
    journal.report("discrete", ctx.quiet);
    ctx.manifest(&dir, "discrete", entry)?;
    if !ctx.quiet {
        println!(
            "discrete designs of {} ({} simulations, {:.1} s; discrete.csv):",
            problem.name(),
            cache.len(),
            t0.elapsed().as_secs_f64()
        );
        for r in &rows {
            let from = r
                .from_optimum
                .map(|k| format!(" of optimum {k}"))
                .unwrap_or_default();
            println!(
                "  {:<17}{from}: x = {:?}  f = {:.8e}  max g = {:.3e}  feasible = {}  {} evaluations",
                r.method,
                r.design.x,
                r.design.f,
                r.design.max_g(),
                r.design.violation(tol) <= 0.0,
                r.evaluations
            );
        }
    }
    Ok(rows)
}

/// The `x_…, f, g…, max_g, feasible` fields of a design.
fn design_fields(m: usize, c: &Candidate, tol: f64) -> Vec<String> {
    let mut r: Vec<String> = c.x.iter().map(|&v| num(v)).collect();
    r.push(num(c.f));
    r.extend(c.g.iter().map(|&v| num(v)));
    r.push(if m > 0 { num(c.max_g()) } else { String::new() });
    r.push((c.violation(tol) <= 0.0).to_string());
    r
}

fn design_header(vars: &[Variable], m: usize) -> Vec<String> {
    let mut h: Vec<String> = vars.iter().map(|v| format!("x_{}", v.name)).collect();
    h.push("f".into());
    h.extend((1..=m).map(|j| format!("g{j}")));
    h.extend(["max_g", "feasible"].map(String::from));
    h
}

/// `discrete.csv`: method, from_optimum, the design, evaluations, samples.
pub fn table(vars: &[Variable], m: usize, rows: &[DiscreteRow], tol: f64) -> Vec<Vec<String>> {
    let mut h = vec!["method".to_string(), "from_optimum".to_string()];
    h.extend(design_header(vars, m));
    h.extend(["evaluations", "samples"].map(String::from));
    let mut out = vec![h];
    for r in rows {
        let mut line = vec![
            r.method.clone(),
            r.from_optimum.map(|k| k.to_string()).unwrap_or_default(),
        ];
        line.extend(design_fields(m, &r.design, tol));
        line.extend([r.evaluations.to_string(), r.samples.to_string()]);
        out.push(line);
    }
    out
}

/// `discrete_grid.csv`: every enumerated design.
pub fn grid_table(vars: &[Variable], m: usize, all: &[Candidate], tol: f64) -> Vec<Vec<String>> {
    let mut out = vec![design_header(vars, m)];
    out.extend(all.iter().map(|c| design_fields(m, c, tol)));
    out
}
