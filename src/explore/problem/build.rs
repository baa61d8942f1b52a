//! The study's problem: `[problem]` ([`super::problems::ProblemSpec`]: a
//! test problem by name) or, with `name = "scene"`, the study's own scene
//! under `[scene_problem]` ([`super::scene_problem`]).

use super::problems;
use super::scene_problem;
use crate::error::Result;
use crate::optimize::{Problem, Variable};
use crate::study::Study;

/// Build the study's `[problem]`.
pub fn problem(study: &Study) -> Result<Box<dyn Problem>> {
    let spec: problems::ProblemSpec =
        study.require_section("problem", "the problem to explore (name = ...)")?;
    if spec.name == "scene" {
        // The study's own scene (`[scene_problem]`, scene_problem.rs).
        if spec.dimension.is_some() || spec.bounds.is_some() || spec.cost_ms != 0.0 {
            return Err(study.error(
                "problem",
                "(table)",
                "only `name = \"scene\"`: variables and bounds are in [scene_problem]",
            ));
        }
        return Ok(Box::new(scene_problem::SceneProblem::from_study(study)?));
    }
    spec.build().map_err(study.locate("problem"))
}

/// Check `[problem]` without doing any work (`plyscape run` checks every
/// section before the first one runs). A `scene` problem is only parsed
/// here: building it evaluates a design.
pub fn check_problem(study: &Study) -> Result<()> {
    let spec: problems::ProblemSpec =
        study.require_section("problem", "the problem to explore (name = ...)")?;
    if spec.name == "scene" {
        scene_problem::SceneProblem::check(study)
    } else {
        problem(study).map(|_| ())
    }
}

/// The study's variables without evaluating anything: a test problem is
/// built (cheap), a scene problem's `[scene_problem]` only read and
/// checked. For the checks of sections that depend on the variables
/// (`[discrete]`, `[robustness]`) before any section runs.
pub fn variables(study: &Study) -> Result<Vec<Variable>> {
    let spec: problems::ProblemSpec =
        study.require_section("problem", "the problem to explore (name = ...)")?;
    if spec.name == "scene" {
        scene_problem::SceneProblem::variables_of(study)
    } else {
        Ok(problem(study)?.variables().to_vec())
    }
}
