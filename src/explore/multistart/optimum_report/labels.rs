//! How the optimum report names and scales the problem's values.

use crate::explore::problem::scene_problem::SceneProblem;

/// How the report names and scales the problem's values.
#[derive(Debug, Clone, PartialEq)]
pub struct Labels {
    /// The objective in its unit is `f × divisor` (1 unless the scene
    /// problem normalizes its response).
    pub divisor: f64,
    /// Unit of `f × divisor` (`-` for a dimensionless problem).
    pub unit: String,
    /// Unit of the design variables (`deg` for a scene's ply angles).
    pub x_unit: String,
    /// Constraint labels in the order of `g`: `g1 (u3_peak)`, or `g1`.
    pub constraints: Vec<String>,
}

impl Labels {
    /// Labels of a dimensionless problem with `m` constraints.
    pub fn plain(m: usize) -> Labels {
        Labels {
            divisor: 1.0,
            unit: "-".into(),
            x_unit: "-".into(),
            constraints: (1..=m).map(|j| format!("g{j}")).collect(),
        }
    }

    /// Labels of a scene problem: its objective response's unit and
    /// divisor, angles in degrees, constraints named by their responses.
    pub fn scene(p: &SceneProblem) -> Labels {
        let names = p.constraint_responses();
        Labels {
            divisor: p.objective_scale(),
            unit: p.objective_response().1.into(),
            x_unit: "deg".into(),
            constraints: (1..=names.len())
                .zip(names)
                .map(|(j, n)| format!("g{j} ({n})"))
                .collect(),
        }
    }
}
