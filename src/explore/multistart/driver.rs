//! Multistart: the local optimizer from every start, in parallel.
//!
//! A rayon pool of `threads` workers takes start indices in increasing
//! order from a shared counter; each run is single-threaded and counts its
//! own evaluations through [`Counted`]. Finished runs go through a channel to
//! the calling thread, which appends each to `runs.csv` at once (flushed) and
//! updates the progress bar. At the end the table is re-read from memory,
//! sorted by start index, clustered and rewritten atomically, so the final
//! tables do not depend on the thread count or on finishing order.
//!
//! Budgets stop launching new runs cleanly (runs in flight finish):
//! - `max_evaluations` (function calls): start `k` is launched unless the
//!   finished runs with a smaller index already used the budget. Every start
//!   below `p`, the first index where the cumulative count of starts
//!   `0..p` reaches the budget, is therefore always run; the final tables keep
//!   exactly the starts `0..p` (any later one that ran is dropped), which makes
//!   the result independent of timing.
//! - `max_wall_seconds`: stops launching after that time. This one depends
//!   on the machine; `--resume` continues where it stopped.

use super::cluster::{cluster, Optimum, Tolerances};
use crate::error::{Error, Result};
pub use crate::explore::context::Shard;
use crate::explore::local::settle::{return_to_best, settle, BestFeasible, EndPolicy};
use crate::explore::local::solvers::LocalSolver;
use crate::explore::persist::tables::{
    num, read_runs, write_atomic, ClassCounts, RunRecord, RunResult, RunsAppender,
};
use crate::optimize::{Counted, NoObserver, Observer, Problem, TimedHistory, Variable};
use crate::report::Progress;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// What the driver needs besides the problem and the starts.
#[derive(Debug, Clone)]
pub struct Settings {
    /// Worker threads (>= 1).
    pub threads: usize,
    /// Function-call budget (see the module doc).
    pub max_evaluations: Option<usize>,
    /// Wall-time budget \[s\].
    pub max_wall_seconds: Option<f64>,
    /// Clustering tolerances.
    pub tolerances: Tolerances,
    /// Continue from an existing `runs.csv`.
    pub resume: bool,
    /// Which starts to run.
    pub shard: Shard,
    /// No progress bar.
    pub quiet: bool,
    /// Keep the iteration records of this start (when it runs here).
    pub history_start: Option<usize>,
    /// Certificate and polish of every run's end.
    pub end: EndPolicy,
}

/// The result of a multistart.
#[derive(Debug, Clone)]
pub struct Report {
    /// Runs sorted by start index, with optimum ids.
    pub runs: Vec<RunRecord>,
    /// Distinct certified optima, best first.
    pub optima: Vec<Optimum>,
    /// How the runs ended, by class.
    pub classes: ClassCounts,
    /// The clustering tolerances the optima were formed with.
    pub tolerances: Tolerances,
    /// Function calls over all runs in the tables.
    pub function_calls: usize,
    /// Gradient calls over all runs in the tables.
    pub gradient_calls: usize,
    /// Wall time of this invocation \[s\].
    pub wall_seconds: f64,
    /// Runs done in this invocation (not read back from `runs.csv`).
    pub new_runs: usize,
    /// The iteration records of [`Settings::history_start`], with their
    /// wall times, when that start ran in this invocation.
    pub history: Option<TimedHistory>,
    /// The noise allowances the runs' ends were settled with, of f
    /// (relative) and of g (absolute; [`crate::explore::local::settle::EndPolicy`]),
    /// set by the multistart command; `None` where a report is read back,
    /// as by `merge`.
    pub noise: Option<(f64, f64)>,
}

impl Report {
    /// Fraction of runs that reached a best optimum: the certified optima
    /// whose f is within the clustering tolerance of the best's
    /// (`|f − f_best| <= f_tolerance · max(1, |f_best|)`) are equally good,
    /// and a start that reaches any of them counts. `None` without a
    /// certified optimum.
    pub fn p_single_start(&self) -> Option<f64> {
        let best = self.optima.first()?;
        let band = self.tolerances.f * best.f.abs().max(1.0);
        Some(
            self.optima
                .iter()
                .filter(|o| (o.f - best.f).abs() <= band)
                .map(|o| o.basin_share)
                .sum(),
        )
    }
}

/// One run from `x0`: counts, time, and the outcome settled by `end`
/// (certificate, polish: [`settle`]) as a table row; the solver's and the
/// polish's iteration records go to `observer`.
pub fn one_run(
    problem: &dyn Problem,
    solver: &dyn LocalSolver,
    end: &EndPolicy,
    start: usize,
    x0: &[f64],
    observer: &mut dyn Observer,
) -> RunRecord {
    let t = Instant::now();
    let counted = Counted::new(problem);
    // A panic inside one run (a solver bug) becomes that run's error
    // instead of ending a long campaign.
    let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let mut watch = BestFeasible::new(observer, end.tolerances.feasibility);
        let settled = solver
            .minimize(&counted, x0, &mut watch)
            .map(|o| settle(&counted, Some(x0), o, end, &mut watch));
        let visited = std::mem::take(&mut watch.visited);
        settled.map(|s| return_to_best(&counted, s, &visited, end, observer))
    }))
    .unwrap_or_else(|p| {
        let msg = p
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(Error::numerical(
            "explore::multistart",
            format!("solver panicked: {msg}"),
        ))
    });
    let wall_seconds = t.elapsed().as_secs_f64();
    let mut certificate = None;
    let mut polish = String::new();
    let (result, exit, iterations) = match out {
        Ok(s) => {
            let note = s.note();
            let o = s.outcome;
            if o.f.is_finite() && o.x.iter().chain(&o.g).all(|v| v.is_finite()) {
                polish = note;
                certificate = s.certificate;
                let exit = o.termination.to_string();
                let result = RunResult {
                    x: o.x,
                    f: o.f,
                    g: o.g,
                };
                (Some(result), exit, o.iterations)
            } else {
                let msg = format!("error: non-finite result f = {} at x = {:?}", o.f, o.x);
                (None, msg, o.iterations)
            }
        }
        Err(e) => (None, format!("error: {e}"), 0),
    };
    RunRecord {
        start,
        x0: x0.to_vec(),
        result,
        exit,
        iterations,
        function_calls: counted.function_calls(),
        gradient_calls: counted.gradient_calls(),
        wall_seconds,
        optimum: None,
        certificate,
        polish,
    }
}

/// The rows of an earlier `runs.csv` to continue from (`settings.resume`,
/// each checked against `starts` and the shard), or none: without resume
/// an earlier file is removed.
fn earlier_runs(
    problem: &dyn Problem,
    starts: &[Vec<f64>],
    settings: &Settings,
    path: &Path,
) -> Result<BTreeMap<usize, RunRecord>> {
    let (vars, m) = (problem.variables(), problem.n_constraints());
    let mut done: BTreeMap<usize, RunRecord> = BTreeMap::new();
    if settings.resume {
        for row in read_runs(path, vars, m)?.rows {
            check_row(&row, starts, settings.shard, path)?;
            if done.insert(row.start, row.clone()).is_some() {
                return Err(Error::csv(
                    path,
                    format!("start {} appears twice", row.start),
                ));
            }
        }
    } else if path.exists() {
        std::fs::remove_file(path).map_err(|e| Error::io(path, e))?;
    }
    Ok(done)
}

/// May start `k` be launched: the runs finished below `k` have not used
/// `max_evaluations` up, and `max_wall_seconds` has not passed since `t0`.
fn may_launch(
    settings: &Settings,
    k: usize,
    finished_evals: &Mutex<BTreeMap<usize, usize>>,
    t0: Instant,
) -> bool {
    if let Some(b) = settings.max_evaluations {
        let used: usize = finished_evals
            .lock()
            .expect("no panics")
            .range(..k)
            .map(|(_, e)| e)
            .sum();
        if used >= b {
            return false;
        }
    }
    !settings
        .max_wall_seconds
        .is_some_and(|w| t0.elapsed().as_secs_f64() >= w)
}

/// The run from start `k` at `x0`, with its iteration history when it is
/// `settings.history_start`.
fn run_start(
    problem: &dyn Problem,
    solver: &dyn LocalSolver,
    settings: &Settings,
    k: usize,
    x0: &[f64],
) -> (RunRecord, Option<TimedHistory>) {
    if settings.history_start == Some(k) {
        let mut h = TimedHistory::start();
        let row = one_run(problem, solver, &settings.end, k, x0, &mut h);
        (row, Some(h))
    } else {
        let row = one_run(problem, solver, &settings.end, k, x0, &mut NoObserver);
        (row, None)
    }
}

/// Run the multistart from `starts` (all of the study's; the shard picks
/// its own), writing `runs.csv` and `optima.csv` into `dir`.
pub fn run(
    problem: &dyn Problem,
    solver: &dyn LocalSolver,
    starts: &[Vec<f64>],
    settings: &Settings,
    dir: &Path,
) -> Result<Report> {
    let t0 = Instant::now();
    let vars = problem.variables();
    let m = problem.n_constraints();
    let path = dir.join("runs.csv");
    let mine: Vec<usize> = (0..starts.len())
        .filter(|&k| settings.shard.owns(k))
        .collect();
    let mut done = earlier_runs(problem, starts, settings, &path)?;
    let todo: Vec<usize> = mine
        .iter()
        .copied()
        .filter(|k| !done.contains_key(k))
        .collect();
    let mut appender = RunsAppender::open(&path, vars, m)?;

    let pool = crate::explore::context::thread_pool(settings.threads)?;
    let finished_evals: Mutex<BTreeMap<usize, usize>> =
        Mutex::new(done.iter().map(|(&k, r)| (k, r.function_calls)).collect());
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let progress = Progress::new("multistart", todo.len() as u64, settings.quiet);
    let mut best = done
        .values()
        .filter_map(|r| r.result.as_ref().map(|x| x.f))
        .fold(f64::INFINITY, f64::min);
    let mut evals_now = 0usize;
    let mut write_error = None;
    let mut new_rows = Vec::new();
    let mut history = None;
    let (tx, rx) = std::sync::mpsc::channel::<(RunRecord, Option<TimedHistory>)>();
    std::thread::scope(|ts| {
        let (todo, next, stop, finished_evals, pool) =
            (&todo, &next, &stop, &finished_evals, &pool);
        ts.spawn(move || {
            pool.scope(|s| {
                for _ in 0..settings.threads {
                    let tx = tx.clone();
                    s.spawn(move |_| loop {
                        if stop.load(Ordering::SeqCst) {
                            break;
                        }
                        let i = next.fetch_add(1, Ordering::SeqCst);
                        let Some(&k) = todo.get(i) else { break };
                        if !may_launch(settings, k, finished_evals, t0) {
                            stop.store(true, Ordering::SeqCst);
                            break;
                        }
                        let (row, history) = run_start(problem, solver, settings, k, &starts[k]);
                        finished_evals
                            .lock()
                            .expect("no panics")
                            .insert(k, row.function_calls);
                        if tx.send((row, history)).is_err() {
                            break;
                        }
                    });
                }
            });
            drop(tx);
        });
        for (row, h) in rx {
            if h.is_some() {
                history = h;
            }
            if write_error.is_none() {
                if let Err(e) = appender.append(&row) {
                    write_error = Some(e);
                    stop.store(true, Ordering::SeqCst);
                }
            }
            evals_now += row.function_calls;
            if let Some(r) = &row.result {
                best = best.min(r.f);
            }
            let rate = evals_now as f64 / t0.elapsed().as_secs_f64().max(1e-9);
            progress.inc(&format!("best f {best:.6e}  {rate:.0} evals/s"));
            new_rows.push(row);
        }
    });
    progress.finish();
    if let Some(e) = write_error {
        return Err(e);
    }
    let new_runs = new_rows.len();
    for row in new_rows {
        done.insert(row.start, row);
    }
    let mut runs: Vec<RunRecord> = done.into_values().collect();
    if let Some(b) = settings.max_evaluations {
        runs = budget_prefix(runs, b);
    }
    let report = finish(
        vars,
        m,
        runs,
        settings.tolerances,
        dir,
        t0.elapsed().as_secs_f64(),
    )?;
    Ok(Report {
        new_runs,
        history,
        noise: Some((settings.end.noise, settings.end.noise_g)),
        ..report
    })
}

/// Keep the runs (sorted by start) before the cumulative function calls
/// reach `budget`.
pub fn budget_prefix(runs: Vec<RunRecord>, budget: usize) -> Vec<RunRecord> {
    let mut used = 0;
    runs.into_iter()
        .take_while(|r| {
            let keep = used < budget;
            used += r.function_calls;
            keep
        })
        .collect()
}

/// Cluster `runs` (sorted by start), rewrite `runs.csv` with optimum ids,
/// write `optima.csv` (certified optima only) and its companion
/// `run_classes.csv` (how many runs ended in each class); also used by
/// `merge`.
pub fn finish(
    vars: &[Variable],
    m: usize,
    mut runs: Vec<RunRecord>,
    tol: Tolerances,
    dir: &Path,
    wall_seconds: f64,
) -> Result<Report> {
    runs.sort_by_key(|r| r.start);
    let optima = cluster(vars, &mut runs, tol);
    let mut rows = vec![crate::explore::persist::tables::runs_header(vars, m)];
    rows.extend(runs.iter().map(|r| r.fields(vars.len(), m)));
    write_atomic(&dir.join("runs.csv"), &rows)?;
    write_atomic(&dir.join("optima.csv"), &optima_table(vars, m, &optima))?;
    let classes = ClassCounts::of(&runs);
    write_atomic(&dir.join("run_classes.csv"), &classes_table(&classes))?;
    Ok(Report {
        classes,
        tolerances: tol,
        function_calls: runs.iter().map(|r| r.function_calls).sum(),
        gradient_calls: runs.iter().map(|r| r.gradient_calls).sum(),
        runs,
        optima,
        wall_seconds,
        new_runs: 0,
        history: None,
        noise: None,
    })
}

/// `optima.csv`: header and one row per optimum.
pub fn optima_table(vars: &[Variable], m: usize, optima: &[Optimum]) -> Vec<Vec<String>> {
    let mut h = vec!["optimum".to_string()];
    h.extend(vars.iter().map(|v| format!("x_{}", v.name)));
    h.push("f".into());
    h.extend((1..=m).map(|j| format!("g{j}")));
    h.extend(
        [
            "max_g",
            "feasible",
            "count",
            "basin_share",
            "best_start",
            "mean_function_calls",
            "mean_gradient_calls",
        ]
        .map(String::from),
    );
    let mut rows = vec![h];
    for o in optima {
        let mut r = vec![o.id.to_string()];
        r.extend(o.x.iter().map(|&v| num(v)));
        r.push(num(o.f));
        r.extend(o.g.iter().map(|&v| num(v)));
        let max_g = o.g.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        r.push(if m > 0 { num(max_g) } else { String::new() });
        r.push(o.feasible.to_string());
        r.push(o.count.to_string());
        r.push(num(o.basin_share));
        r.push(o.best_start.to_string());
        r.push(num(o.mean_function_calls));
        r.push(num(o.mean_gradient_calls));
        rows.push(r);
    }
    if optima.iter().any(|o| o.noise.is_some()) {
        rows[0].extend(NOISE_COLUMNS.map(String::from));
        for (row, o) in rows[1..].iter_mut().zip(optima) {
            row.extend(noise_fields(o.noise.as_ref()));
        }
    }
    rows
}

/// The columns `optima.csv` has when the noise was measured at each
/// optimum (`[multistart] noise = "measured"`): σ of f, σ_f / max(|f|, 1),
/// the largest σ of the constraints (absolute: they are normalized), what
/// failed (`""` when every estimate succeeded; else `f: h_too_small`,
/// `g2: h_too_large`, …) and the function calls spent.
pub const NOISE_COLUMNS: [&str; 5] = [
    "noise_f",
    "noise_f_relative",
    "noise_max_g",
    "noise_failed",
    "noise_evaluations",
];

/// The [`NOISE_COLUMNS`] fields of one optimum (empty without a
/// measurement; a failed estimate is its reason, never a number).
fn noise_fields(m: Option<&crate::optimize::noise::Measured>) -> Vec<String> {
    let Some(m) = m else {
        return vec![String::new(); NOISE_COLUMNS.len()];
    };
    let opt = |v: Option<f64>| v.map(num).unwrap_or_default();
    let failed: Vec<String> = std::iter::once(("f".to_string(), m.noise_f))
        .chain(
            m.noise_g
                .iter()
                .enumerate()
                .map(|(j, n)| (format!("g{}", j + 1), *n)),
        )
        .filter_map(|(name, n)| n.failure().map(|w| format!("{name}: {w}")))
        .collect();
    vec![
        opt(m.noise_f.sigma()),
        opt(m.noise_f.sigma().map(|s| s / m.f.abs().max(1.0))),
        opt(m.max_g()),
        failed.join("; "),
        m.evaluations.to_string(),
    ]
}

/// `run_classes.csv`: one row per class (`converged`, `stopped`,
/// `infeasible`, `infeasible_stationary` (of the infeasible, those at a
/// stationary point of the violation), `infeasible_stalled` (the other
/// infeasible ends where descent on the violation stalled), `failed`) with
/// count and share of all runs.
pub fn classes_table(c: &ClassCounts) -> Vec<Vec<String>> {
    let mut rows = vec![["class", "count", "share"].map(String::from).to_vec()];
    for (name, k) in [
        ("converged", c.converged),
        ("stopped", c.stopped),
        ("infeasible", c.infeasible),
        ("infeasible_stationary", c.infeasible_stationary),
        ("infeasible_stalled", c.infeasible_stalled),
        ("failed", c.failed),
    ] {
        rows.push(vec![name.into(), k.to_string(), num(c.share(k))]);
    }
    rows
}

/// A row read back must belong to this study and shard.
fn check_row(row: &RunRecord, starts: &[Vec<f64>], shard: Shard, path: &Path) -> Result<()> {
    let ok = row.start < starts.len()
        && shard.owns(row.start)
        && starts[row.start]
            .iter()
            .zip(&row.x0)
            .all(|(a, b)| a.to_bits() == b.to_bits());
    if ok {
        Ok(())
    } else {
        // The study changed (its seed, sampler, starts or points): bad
        // input for a resume (exit 2), not a damaged table.
        Err(Error::Input {
            file: path.display().to_string(),
            key: format!("start {}", row.start),
            value: format!("x0 = {:?}", row.x0),
            expected: "a start of this study/shard: the study changed since (its seed, \
                       sampler, starts or points); rerun without --resume"
                .into(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failing_and_panicking_runs_become_rows_with_an_error() {
        let p = crate::optimize::testproblems::himmelblau();
        let fails: &dyn LocalSolver = &|_: &dyn Problem, _: &[f64], _: &mut dyn Observer| {
            Err(Error::numerical("test", "singular"))
        };
        let end = crate::explore::local::settle::EndPolicy {
            tolerances: Default::default(),
            polish: true,
            rescue: true,
            noise: 1e-6,
            noise_g: 0.0,
        };
        let row = one_run(&p, fails, &end, 3, &[0.0, 1.0], &mut NoObserver);
        assert!(row.result.is_none() && row.exit.contains("singular"));
        let panics: &dyn LocalSolver = &|q: &dyn Problem, x: &[f64], _: &mut dyn Observer| {
            q.evaluate(x, true)?;
            panic!("index out of bounds")
        };
        let row = one_run(&p, panics, &end, 4, &[0.0, 1.0], &mut NoObserver);
        assert!(
            row.exit.contains("solver panicked: index out of bounds"),
            "{}",
            row.exit
        );
        assert_eq!((row.function_calls, row.gradient_calls), (1, 1));
    }

    #[test]
    fn shard_parsing() {
        assert_eq!(Shard::parse("1/3").unwrap(), Shard { index: 1, count: 3 });
        for bad in ["3/3", "1", "a/2", "0/0", "-1/2"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        let s = Shard::parse("2/3").unwrap();
        assert!(s.owns(5) && !s.owns(4));
    }
}
