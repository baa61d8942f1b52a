//! The problem a study explores, behind [`crate::optimize::Problem`]
//! (design variables with bounds or periods, `f`, `g_j <= 0` and their
//! gradients).
//!
//! - Section: `[problem]` ([`problems::ProblemSpec`]): a test problem by
//!   name, or `name = "scene"` for the study's own scene under
//!   `[scene_problem]` ([`scene_problem::SceneProblemSpec`]).
//! - Algorithms: the analytic test problems with known landscapes
//!   ([`problems`], one table of name and constructor); the scene as a
//!   problem ([`scene_problem`]: ply angles and other design variables in
//!   their SI units (degrees for angles), responses of a simulation as
//!   objective and constraints, exact gradients by forward sensitivities),
//!   its variables (`scene_vars`, private) and bounds
//!   ([`scene_bounds`]); several responses as the objectives of a Pareto
//!   front ([`scene_front`]).
//! - Command: none of its own; every driver builds the study's problem
//!   with [`build::problem`] and `plyscape run` checks it with
//!   [`build::check_problem`] before any section runs.

pub mod accuracy;
pub mod build;
pub mod problems;
pub mod scene_bounds;
pub mod scene_front;
pub mod scene_problem;
mod scene_vars;
