//! The evolutionary search on the multistart's budget, and the comparison
//! of the two.
//!
//! - Sections: `[evolve]` ([`section::EvolveSection`]: budget, restart
//!   schedules, TolFun, target, active CMA-ES; checked into a
//!   [`section::EvolvePlan`]) and `[compare]` ([`section::CompareSection`],
//!   no keys).
//! - Algorithm: CMA-ES with IPOP or BIPOP restarts
//!   ([`crate::optimize::cmaes`]) run by [`search`] in a pool of the
//!   study's threads, with the mean objective per generation
//!   (`evolution.csv`).
//! - Commands: `plyscape evolve` ([`command::run_evolve`]) and
//!   `plyscape compare` ([`compare::run_compare`]: the multistart and the
//!   evolutionary search on the same evaluation budget, their best designs
//!   polished and moved strictly inside the feasible set, side by side in
//!   `comparison.csv`, with the convergence plot of [`convergence`]).

pub mod command;
pub mod compare;
pub mod convergence;
pub mod search;
pub mod section;

pub use search::{
    global, global_method, global_schedule, run, table, Generation, GlobalSolver, Report, Request,
};
