//! The multistart: the local optimizer from many seeded start points, in
//! parallel, its ends merged into distinct optima.
//!
//! - Sections: `[multistart]` ([`section::MultistartSection`], checked
//!   into a [`section::MultistartPlan`] with its start points);
//!   `[optimum_report]` ([`optimum_report`]: the run from the first start
//!   as the paper's Table 5 and Figs. 10–14); `[robustness]`
//!   ([`robustness`]: each certified optimum's first-order worst case
//!   `f + Σ_i |∂f/∂x_i| δ_i` under a tolerance `δ_i` per variable, checked
//!   at the corners or a Latin-hypercube sample of the box); `[scaling]`
//!   ([`scaling`]: the same multistart per thread count, timed).
//! - Algorithms: start points over the design box ([`sampling`]: listed
//!   points, then Latin hypercube, scrambled Sobol or uniform, optionally
//!   only feasible ones); the parallel runs with their budgets
//!   ([`driver`]); clustering of the settled ends into distinct optima
//!   within `x_tolerance` (range-scaled) and `f_tolerance` ([`cluster`]);
//!   the shards of a `--shard i/n` run put back together ([`merge`]).
//! - Command: `plyscape multistart` ([`command::run_multistart`]: `runs.csv`,
//!   `optima.csv`, `classes.csv`, `violation_checks.csv`, the manifest
//!   entry) and `plyscape merge` ([`merge::merge`]).

pub mod cluster;
pub mod command;
pub mod driver;
pub mod merge;
pub mod optimum_report;
pub mod robustness;
pub mod sampling;
pub mod scaling;
pub mod section;

pub use driver::{one_run, run, Report, Settings, Shard};
