//! One local run and what its end is.
//!
//! - Section: `[multistart] method` and `preset`, `[multistart.mmfd]`
//!   (read in [`crate::explore::multistart::section`]), and the
//!   certificate's tolerances of `[multistart]`.
//! - Algorithms: the local solvers by the names study files use
//!   ([`solvers`]: MMFD, projected steepest descent); the end of a run
//!   settled ([`settle`]: the Kuhn–Tucker certificate, the polish when it
//!   stopped short, the rescue by a pure descent on the violation
//!   `V(x) = ½ Σ_j max(0, g_j(x))²`); the check of infeasible ends by that
//!   descent ([`violation`], `violation_checks.csv`).
//! - Command: none; the multistart, the fronts, the polish of the
//!   comparison and the gradient check call these.

pub mod settle;
pub mod solvers;
pub mod violation;
