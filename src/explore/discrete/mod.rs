//! Discrete designs (`[discrete]`, [`lattice::DiscreteSection`]): ply angles as manufacturers
//! lay them up, on a finite set per variable (`values = [-45, 0, 45, 90]`
//! or `step = 15.0` from the lower bound), searched three ways and written
//! side by side in `discrete.csv`:
//!
//! - **Gradient route** (`rounded`, `rounded_polished`): every certified
//!   continuous optimum of the study's multistart (`optima.csv`) rounded to
//!   the nearest set member in each discrete coordinate (on the circle for
//!   a periodic variable), then polished by a discrete coordinate descent:
//!   evaluate the designs one set member away in each discrete coordinate
//!   (2 per coordinate, cyclic for a periodic set), move to the best of
//!   them when it is better, repeat until no neighbour improves. The 2n
//!   axis neighbours per step (against the 2ⁿ corners of the rounding
//!   cell) keep the polish linear in n; it ends at a point no single
//!   member change improves.
//! - **Evolutionary route** (`cmaes_discrete`): IPOP-CMA-ES whose samples
//!   are evaluated at their rounding, the distribution staying continuous,
//!   with a lower bound `min_std` (in lattice steps, default 0.25) on the
//!   standard deviation `σ√C_ii` of each discrete coordinate. This is the
//!   integer handling of N. Hansen, "A CMA-ES for mixed-integer nonlinear
//!   optimization", INRIA research report RR-7751 (2011): without the
//!   bound, once σ√C_ii falls well below the lattice step every sample
//!   rounds to the same member and the coordinate freezes while still
//!   undecided; with it, a sample leaves the current member with
//!   probability `2Φ(−0.5/0.25) ≈ 4.6 %` per coordinate. (That report also
//!   adds an integer mutation for such coordinates; it is not done here.)
//!   Chosen over a genetic algorithm because it reuses the tested CMA-ES
//!   (restarts, Deb's constraint rules, seeded determinism) and handles
//!   mixed continuous/discrete designs unchanged; a GA suits long stacking
//!   sequences with symmetric/balance rules, which these problems do not
//!   have. `cmaes_samples` budgets the designs asked for.
//! - **Exhaustive** (`exhaustive`): when every variable is discrete and the
//!   set has at most `exhaustive_limit` designs, all of them (2 ply angles
//!   on 15° steps: 12 × 12 = 144), written to `discrete_grid.csv`: the
//!   true discrete optimum the other two are measured against.
//!
//! Designs are compared by Deb's rules at the study's feasibility tolerance
//! (`[multistart] feasibility_tolerance`): feasible by f before infeasible
//! by violation. Every design is simulated once ([`lattice::Cache`], shared
//! by the methods); a method's `evaluations` column counts the distinct
//! designs it asked for, its cost had it run alone, and `samples` the
//! designs asked for with repeats (CMA-ES samples often round to a design
//! seen before).
//!
//! The command is `[discrete]` under `plyscape run`
//! ([`command::run_discrete`]), after the study's multistart.

pub mod command;
pub mod lattice;
pub mod search;

pub use lattice::{Cache, DiscreteSection, DiscreteVariable, Lattice, OnSet};
pub use search::{cmaes_on_set, exhaustive, round_and_polish, Candidate, Found};
