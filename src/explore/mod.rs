//! Exploration drivers: multistart, evolutionary comparison, design-space
//! maps, resumable and shardable tables (issue 5).
//!
//! A gradient-based local optimizer (MMFD) finds the optimum of the basin it
//! starts in; ply-angle problems have many basins. The drivers here answer
//! "how many optima are there, which is best, and how likely is one start to
//! find it?" by running the local optimizer from many seeded start points in
//! parallel ([`multistart`]), merging the results into distinct optima
//! ([`cluster`]), comparing with an evolutionary search on the same budget
//! ([`evolve`]) and drawing the landscape ([`map`]).
//!
//! Every table is reproducible from the study file: random choices come
//! from `[study] seed`, rows are sorted by start index, numbers round-trip
//! exactly, and `manifest.json` records the study text, seed, threads and
//! crate versions. `runs.csv` survives a kill (see [`tables`]); `--resume`
//! continues a stopped multistart and `--shard i/n` splits one over
//! machines, with `plyscape merge` putting the pieces back together.
//!
//! Study sections read here ([`config`]): `[problem]`
//! ([`problems::ProblemSpec`]; with `name = "scene"` also
//! `[scene_problem]`, [`scene_problem`]), `[multistart]`
//! ([`MultistartSection`]), `[evolve]` ([`EvolveSection`]), `[compare]` (no
//! keys), `[map]` ([`MapSection`]), `[scaling]`
//! ([`scaling::ScalingSection`]), `[optimum_report]`
//! ([`optimum_report`]: the run from the first start as the paper's
//! Table 5 and Figs. 10–12, written by the multistart), `[front]`
//! ([`commands::front`]: the Pareto front of two or three objectives, its
//! gradient side in [`front`], NSGA-II in [`crate::optimize::nsga2`], the
//! grid of the box in [`front_grid`], and with `[problem] name = "scene"`
//! the scene's responses as objectives in [`scene_front`]),
//! `[robustness]` ([`robustness`]: each certified optimum's worst case
//! under a tolerance per variable, in `optima.csv`) and `[discrete]`
//! ([`discrete`], [`commands::discrete`]: the problem on a finite set per
//! variable, searched exhaustively, by rounding and polishing the
//! certified optima, and by CMA-ES on the set).
//!
//! Layout: the algorithms are [`multistart`], [`cluster`], [`evolve`],
//! [`map`] and [`sampling`], over the problems of [`problems`] and
//! [`scene_problem`] and the optimizers named in [`solvers`]; [`config`]
//! reads the sections into checked plans; [`commands`] holds one file per
//! driver command (what `plyscape multistart`, `evolve`, `compare` and
//! `map` do around the algorithms); [`context`] is what a command gets
//! from the command line; [`manifest`] types the commands' entries in
//! `manifest.json`; [`merge`](mod@merge) joins the shards of a multistart;
//! [`tables`] reads and writes the CSV files.
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
//!   [`solvers::LocalMethod`] (the serde name is the study's `[multistart]
//!   method`) and a match arm in [`solvers::local`]. An evolutionary one is
//!   a [`evolve::GlobalSolver`] built in [`solvers::global`].
//! - **A driver command** (a sweep of another kind): its section struct and
//!   plan in [`config`] (or its own file beside [`scaling`]), its run in a
//!   new file of [`commands`] taking a [`Context`], its tables through
//!   [`tables`] and [`crate::report`], its manifest entry as a typed struct
//!   in [`manifest`] passed to [`Context::manifest`]; the subcommand in
//!   `crate::cli`'s `Command` and `execute`.
//! - **A study section** `plyscape run` does: one entry in
//!   [`crate::sections::registry::SECTIONS`] (key, check, run); see
//!   [`crate::sections`].

pub mod cluster;
pub mod commands;
pub mod config;
pub mod context;
pub mod discrete;
pub mod evolve;
pub mod fingerprint;
pub mod front;
pub mod front_grid;
pub mod manifest;
pub mod map;
pub mod merge;
pub mod multistart;
pub mod optimum_report;
pub mod problems;
pub mod robustness;
pub mod sampling;
pub mod scaling;
pub mod scene_bounds;
pub mod scene_front;
pub mod scene_problem;
mod scene_vars;
pub mod settle;
pub mod solvers;
pub mod tables;
pub mod violation;

pub use commands::compare::{comparison_table, run_compare, ComparisonRow};
pub use commands::evolve::{regime_counts, run_evolve};
pub use commands::map::run_map;
pub use commands::multistart::{keep_earlier_runs, run_multistart};
pub use config::{
    check_problem, compare_section, evolve_plan, map_section, multistart_plan, multistart_section,
    problem, schedules, CompareSection, EvolvePlan, EvolveSection, MapSection, MultistartPlan,
    MultistartSection,
};
pub use context::{Context, DriveFlags};
pub use merge::merge;
