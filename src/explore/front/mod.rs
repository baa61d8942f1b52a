//! The Pareto front of two or three objectives (`[front]`).
//!
//! - Section: `[front]` ([`command::FrontSection`]): the subproblems, the
//!   NSGA-II budget and population, the optional grid.
//! - Algorithms: the gradient side ([`gradient`]: anchors, then certified
//!   Tchebycheff subproblems `min_x max_i w_i (f_i − z_i)/(N_i − z_i)`
//!   solved by MMFD or SQP and settled as a multistart run, with
//!   further subproblems in the largest gaps of its front, [`gaps`]); NSGA-II
//!   ([`crate::optimize::nsga2`]); a grid of `N` values per variable over
//!   the box ([`grid`]) as a yardstick. The objectives are an analytic
//!   multi-objective problem or the scene's responses
//!   ([`crate::explore::problem::scene_front`]).
//! - Command: `[front]` under `plyscape run` ([`command::run_front`]), its
//!   tables and plots in [`outputs`] (`front.csv`, `front_summary.csv`,
//!   `front.svg`, ...), with the hypervolume and IGD of each method.

mod anchors;
pub mod command;
pub mod gaps;
pub mod gradient;
pub mod grid;
pub mod hybrid;
pub mod outputs;
