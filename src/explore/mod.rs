//! Exploration: how many optima a ply-angle problem has, which is best,
//! how likely one start is to find it, what the landscape and the Pareto
//! front look like, and which designs on a discrete set of angles are best.
//!
//! A gradient-based local optimizer (MMFD) finds the optimum of the basin it
//! starts in; ply-angle problems have many basins. Each feature below is a
//! folder holding the study section it reads, its algorithm and its command:
//!
//! | folder | section | algorithm | command |
//! |---|---|---|---|
//! | [`problem`](mod@problem) | `[problem]`, `[scene_problem]` | analytic test problems, the scene as a problem (variables, bounds, objectives of a front) | (built by every command: [`problem()`]) |
//! | [`local`] | `[multistart] method`, `[multistart.mmfd]` | the local solvers, settling a run's end (certificate, polish, rescue), the violation check | (used by the commands) |
//! | [`multistart`] | `[multistart]`, `[optimum_report]`, `[robustness]`, `[scaling]` | start points, the parallel multistart, clustering into distinct optima, shard merging | `plyscape multistart`, `merge` |
//! | [`evolve`] | `[evolve]`, `[compare]` | CMA-ES with restarts on the multistart's budget | `plyscape evolve`, `compare` |
//! | [`front`] | `[front]` | certified Tchebycheff subproblems, NSGA-II, a grid of the box | `[front]` under `plyscape run` |
//! | [`map`] | `[map]` | f and the constraints on a grid over two variables | `plyscape map` |
//! | [`discrete`] | `[discrete]` | rounding and polishing, CMA-ES on the set, exhaustive search | `[discrete]` under `plyscape run` |
//! | [`persist`] | — | `runs.csv` that survives a kill, the stages' evaluation journals, the typed manifest entries, the study's fingerprint for `--resume` | — |
//!
//! Every table is reproducible from the study file: random choices come
//! from `[study] seed`, rows are sorted by start index, numbers round-trip
//! exactly, and `manifest.json` records the study text, seed, threads and
//! crate versions. `runs.csv` survives a kill ([`persist::tables`]);
//! `--resume` continues a stopped multistart (CMA-ES, `[discrete]` and
//! `[front]` from their evaluation journals, [`persist::journal`]) and
//! `--shard i/n` splits one
//! over machines, with `plyscape merge` ([`merge()`]) putting the pieces
//! back together. A command gets the command line as a [`Context`].
//!
//! A problem from a study, evaluated with its gradient (Himmelblau's
//! function has a minimum f = 0 at (3, 2)):
//!
//! ```
//! use plyscape::optimize::Problem;
//! use plyscape::study::Study;
//!
//! let study = Study::parse("himmelblau.toml", "[problem]\nname = \"himmelblau\"\n")?;
//! let problem = plyscape::explore::problem(&study)?;
//! let e = problem.evaluate(&[3.0, 2.0], true)?;
//! assert!(e.f.abs() < 1e-12);
//! assert!(e.grad_f.unwrap().iter().all(|g| g.abs() < 1e-10));
//! # Ok::<(), plyscape::Error>(())
//! ```
//!
//! # Where to add things
//!
//! - **An optimizer**: a local one is a function `(problem, x0, observer)
//!   -> LocalOutcome` in [`crate::optimize`] behind the
//!   [`crate::optimize::Problem`] interface; give it a variant of
//!   [`local::solvers::LocalMethod`] (the serde name is the study's
//!   `[multistart] method`) and a match arm in [`local::solvers::local`].
//!   An evolutionary one is a [`evolve::GlobalSolver`] built in
//!   [`evolve::global`].
//! - **A test problem**: one row of the table in [`problem::problems`].
//! - **A driver command** (a sweep of another kind): a new folder with its
//!   section struct and plan (`section.rs`), its algorithm and its run
//!   taking a [`Context`] (`command.rs`), its tables through
//!   [`persist::tables`] and [`crate::report`], its manifest entry as a
//!   typed struct in [`persist::manifest`] passed to [`Context::manifest`];
//!   the subcommand in `crate::cli`'s `Command` and `execute`.
//! - **A study section** `plyscape run` does: one entry in
//!   [`crate::sections::registry::SECTIONS`] (key, check, run); see
//!   [`crate::sections`].

pub mod context;
pub mod discrete;
pub mod evolve;
pub mod front;
pub mod local;
pub mod map;
pub mod multistart;
pub mod persist;
pub mod problem;

pub use context::{Context, DriveFlags};
pub use evolve::command::{regime_counts, run_evolve};
pub use evolve::compare::{comparison_table, run_compare, ComparisonRow};
pub use evolve::section::{
    compare_section, evolve_plan, schedules, CompareSection, EvolvePlan, EvolveSection,
};
pub use map::command::run_map;
pub use map::section::{map_section, MapSection};
pub use multistart::command::{keep_earlier_runs, run_multistart};
pub use multistart::merge::merge;
pub use multistart::section::{
    multistart_plan, multistart_section, MultistartPlan, MultistartSection,
};
pub use problem::build::{check_problem, problem};
