//! Evolutionary search (CMA-ES with restarts) with per-generation records.
//!
//! The solver itself lives in `optimize::cmaes`; this driver gives it the
//! budget and the seed, runs it inside a rayon pool of the study's thread
//! count (so a solver that evaluates its population with rayon uses exactly
//! those threads), and turns its per-generation [`IterRecord`]s into the
//! rows of `evolution.csv` ([`table`]: one schedule's generations, or
//! several schedules' one after another with a `method` column).
//!
//! The solver reports best-so-far `f` and σ per generation, not the mean of
//! the population; the driver therefore records every objective value the
//! solver asks for and, at each generation record, takes the mean of the
//! values requested since the previous record (sorted before summing, so the
//! mean does not depend on the order in which parallel evaluations finish).

use crate::error::{Error, Result};
use crate::explore::persist::tables::num;
use crate::optimize::cmaes::Restarts;
use crate::optimize::{
    Counted, Evaluation, GlobalOutcome, IterRecord, Observer, Problem, Variable,
};
use crate::report::Progress;
use std::sync::Mutex;
use std::time::Instant;

/// What the evolutionary solver is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Request {
    /// Seed of every random choice of the solver.
    pub seed: u64,
    /// Function-evaluation budget.
    pub max_evaluations: usize,
    /// CMA-ES restart schedule (IPOP or BIPOP).
    pub restarts: Restarts,
    /// A constraint is met when `g <= feasibility_tolerance` (the
    /// multistart's tolerance, so both methods search the same set).
    pub feasibility_tolerance: f64,
    /// A run restarts when its recent best values and current values of f
    /// lie within this range (CMA-ES TolFun).
    pub tol_fun: f64,
    /// Stop when a design feasible to `feasibility_tolerance` reaches
    /// `f <= target` (stop reason `target_reached`); `None`: never.
    pub target: Option<f64>,
    /// Active covariance update (negative weights for the worst samples,
    /// `optimize::cmaes` module doc).
    pub active: bool,
}

/// An evolutionary solver: CMA-ES in the binary, anything in tests.
pub type GlobalSolver<'a> =
    dyn Fn(&dyn Problem, &Request, &mut dyn Observer) -> Result<GlobalOutcome> + Sync + 'a;

/// CMA-ES with the request's restart schedule, seeded and budgeted by it.
pub fn global() -> Box<GlobalSolver<'static>> {
    Box::new(
        |p: &dyn Problem, r: &Request, obs: &mut dyn crate::optimize::Observer| {
            let options = crate::optimize::cmaes::CmaesOptions {
                seed: r.seed,
                max_evaluations: r.max_evaluations,
                restarts: r.restarts,
                feasibility_tolerance: r.feasibility_tolerance,
                tol_fun: r.tol_fun,
                target: r.target,
                active: r.active,
                ..Default::default()
            };
            crate::optimize::cmaes::minimize(p, &options, obs)
        },
    )
}

/// One row of `evolution.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct Generation {
    /// Generation number from the solver (over all restarts).
    pub generation: usize,
    /// Function evaluations so far (driver's count).
    pub function_calls: usize,
    /// Best-so-far objective.
    pub best_f: f64,
    /// Largest constraint at the best-so-far design.
    pub best_max_g: f64,
    /// Mean objective of the designs evaluated in this generation.
    pub mean_f: Option<f64>,
    /// Step size σ.
    pub sigma: f64,
    /// Best-so-far design.
    pub best_x: Vec<f64>,
}

/// The result of an evolutionary search.
#[derive(Debug, Clone)]
pub struct Report {
    /// The solver's outcome.
    pub outcome: GlobalOutcome,
    /// Per-generation rows.
    pub generations: Vec<Generation>,
    /// Function calls (driver's count).
    pub function_calls: usize,
    /// Gradient calls (driver's count; CMA-ES uses none).
    pub gradient_calls: usize,
    /// Wall time \[s\].
    pub wall_seconds: f64,
    /// The restart schedule the solver was asked for.
    pub restarts: Restarts,
}

/// Records every objective value requested, in request order.
struct Recorder<'a> {
    inner: &'a dyn Problem,
    values: Mutex<Vec<f64>>,
}

impl Problem for Recorder<'_> {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        let e = self.inner.evaluate(x, gradients)?;
        if e.f.is_finite() {
            self.values.lock().expect("no panics").push(e.f);
        }
        Ok(e)
    }
    fn name(&self) -> &str {
        self.inner.name()
    }
}

struct GenObserver<'a> {
    recorder: &'a Recorder<'a>,
    counted: &'a Counted<'a>,
    seen: usize,
    rows: Vec<Generation>,
    progress: Progress,
    budget: usize,
}

impl Observer for GenObserver<'_> {
    fn observe(&mut self, r: &IterRecord) {
        let values = self.recorder.values.lock().expect("no panics");
        let mut gen: Vec<f64> = values[self.seen.min(values.len())..].to_vec();
        self.seen = values.len();
        drop(values);
        gen.sort_by(f64::total_cmp);
        let mean_f = (!gen.is_empty()).then(|| gen.iter().sum::<f64>() / gen.len() as f64);
        let calls = self.counted.function_calls();
        self.progress.set(
            calls.min(self.budget) as u64,
            &format!("generation {}  best f {:.6e}", r.iteration, r.f),
        );
        self.rows.push(Generation {
            generation: r.iteration,
            function_calls: calls,
            best_f: r.f,
            best_max_g: r.max_g,
            mean_f,
            sigma: r.step,
            best_x: r.x.clone(),
        });
    }
}

/// Run `solver` on `problem` with `threads` rayon threads (the caller
/// writes the rows with [`table`]).
pub fn run(
    problem: &dyn Problem,
    solver: &GlobalSolver,
    request: &Request,
    threads: usize,
    quiet: bool,
) -> Result<Report> {
    let t0 = Instant::now();
    let pool = crate::explore::context::thread_pool(threads)?;
    let recorder = Recorder {
        inner: problem,
        values: Mutex::new(Vec::new()),
    };
    let counted = Counted::new(&recorder);
    let mut obs = GenObserver {
        recorder: &recorder,
        counted: &counted,
        seen: 0,
        rows: Vec::new(),
        progress: Progress::new(
            request.restarts.solver_name(),
            request.max_evaluations as u64,
            quiet,
        ),
        budget: request.max_evaluations,
    };
    let outcome = pool.install(|| solver(&counted, request, &mut obs))?;
    obs.progress.finish();
    if !(outcome.f.is_finite() && outcome.x.iter().chain(&outcome.g).all(|v| v.is_finite())) {
        return Err(Error::numerical(
            "explore::evolve",
            format!(
                "non-finite best design f = {} at x = {:?}",
                outcome.f, outcome.x
            ),
        ));
    }
    Ok(Report {
        function_calls: counted.function_calls(),
        gradient_calls: counted.gradient_calls(),
        generations: std::mem::take(&mut obs.rows),
        outcome,
        wall_seconds: t0.elapsed().as_secs_f64(),
        restarts: request.restarts,
    })
}

/// The evolutionary method's name in `comparison.csv`: `cmaes` (IPOP, the
/// name it had before BIPOP existed) or `cmaes-bipop`.
pub fn global_method(restarts: Restarts) -> &'static str {
    match restarts {
        Restarts::Ipop => "cmaes",
        Restarts::Bipop => "cmaes-bipop",
    }
}

/// The restart schedule of an evolutionary method name of
/// [`global_method`] (`None`: not such a name).
pub fn global_schedule(method: &str) -> Option<Restarts> {
    [Restarts::Ipop, Restarts::Bipop]
        .into_iter()
        .find(|&r| global_method(r) == method)
}

/// `evolution.csv`: header and one row per generation of each report, the
/// reports one after another. With more than one report a first column
/// `method` names each row's schedule ([`global_method`],
/// as in `comparison.csv`); one report's table has no such column, as
/// before schedules could be listed. Non-finite entries are left empty.
pub fn table(problem: &dyn Problem, reports: &[Report]) -> Vec<Vec<String>> {
    let tagged = reports.len() > 1;
    let mut out = vec![header(problem, tagged)];
    for r in reports {
        let method = global_method(r.restarts);
        for g in &r.generations {
            let mut row = if tagged {
                vec![method.to_string()]
            } else {
                vec![]
            };
            row.extend(generation_row(g, problem.n_constraints() > 0));
            out.push(row);
        }
    }
    out
}

fn header(problem: &dyn Problem, tagged: bool) -> Vec<String> {
    let mut h: Vec<String> = if tagged {
        vec!["method".into()]
    } else {
        vec![]
    };
    h.extend(
        [
            "generation",
            "function_calls",
            "best_f",
            "best_max_g",
            "mean_f",
            "sigma",
        ]
        .map(String::from),
    );
    h.extend(
        problem
            .variables()
            .iter()
            .map(|v| format!("best_x_{}", v.name)),
    );
    h
}

/// One generation's fields (`best_max_g` empty without constraints).
fn generation_row(g: &Generation, constrained: bool) -> Vec<String> {
    let fin = |v: f64| if v.is_finite() { num(v) } else { String::new() };
    let mut r = vec![
        g.generation.to_string(),
        g.function_calls.to_string(),
        fin(g.best_f),
        if constrained {
            fin(g.best_max_g)
        } else {
            String::new()
        },
        g.mean_f.map(fin).unwrap_or_default(),
        fin(g.sigma),
    ];
    r.extend(g.best_x.iter().map(|&v| fin(v)));
    r
}
