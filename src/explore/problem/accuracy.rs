//! `[scene_problem] rtol`: the integration tolerance the evaluations need.
//!
//! An evaluation that integrates a motion with adaptive steps carries a
//! noise of about the tolerance's size (it jumps where the accepted step
//! sequence changes; `crate::optimize::noise`). The optimizer's answers
//! are only as good as that noise allows: a feasibility tolerance below
//! the noise of g cannot be met reliably, and a stop test on f below the
//! noise of f spends its calls among designs the evaluation cannot tell
//! apart. With `rtol = "auto"` the problem is evaluated at the loosest
//! tolerance whose measured noise sits a decade below the feasibility
//! tolerance the study asks for:
//!
//! ```text
//!   σ_f / max(|f|, 1) <= τ/10   and   σ_gj <= τ/10 for every j,
//! ```
//!
//! with σ from ECNoise at the scene problem's start and τ the
//! `[multistart] feasibility_tolerance` (1e-6 without a `[multistart]`).
//! The tolerances tried are the scene's own `[scene.integrator] rtol`,
//! then ten times tighter each, down to 1e-10 (the absolute tolerance
//! following at the scene's ratio atol/rtol). A function whose table is
//! smooth at every step tried ("h too small") meets the test; one whose
//! noise no step resolved ("h too large") does not. When no tolerance
//! meets the test, the tightest is kept and the choice says so.
//!
//! On the SAR problem (`studies/sar_accuracy.toml`, feasibility 1e-6) the
//! scene's rtol 1e-6 gives σ_f = 4.2e-7 of f and is refused; rtol 1e-7
//! gives 1.9e-8 and 1.8e-8 for g and is taken.
//!
//! The measurement is deterministic (a seeded direction, deterministic
//! evaluations), so a process that builds the same study's problem again
//! (`plyscape run`: the multistart, the optimum report, the map) reuses
//! the first choice ([`remembered`]) instead of measuring it again.

use crate::error::Result;
use crate::optimize::noise::{estimate, Measured, Noise, NoiseOptions};
use crate::optimize::Problem;
use serde::Deserialize;

/// `[scene_problem] rtol`: a tolerance, or `"auto"`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged, expecting = "a number, or \"auto\"")]
pub enum RtolSetting {
    /// This relative tolerance (atol at the scene's ratio).
    Given(f64),
    /// Chosen from the measured noise (see the module doc).
    Auto(Auto),
}

/// The word `auto`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub enum Auto {
    /// `"auto"`.
    #[serde(rename = "auto")]
    Auto,
}

/// The tightest tolerance `"auto"` tries.
pub const TIGHTEST: f64 = 1e-10;

/// What `"auto"` measured and chose.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// The tolerance the evaluations use.
    pub rtol: f64,
    /// Each tolerance tried, with its measurement.
    pub tried: Vec<(f64, Measured)>,
    /// The chosen tolerance met the test (else it is the tightest tried).
    pub met: bool,
    /// The noise level the test asked for (τ/10).
    pub target: f64,
}

impl Choice {
    /// Function calls spent on the measurements.
    pub fn evaluations(&self) -> usize {
        self.tried.iter().map(|(_, m)| m.evaluations).sum()
    }

    /// One line for the terminal.
    pub fn summary(&self) -> String {
        let (_, m) = self.tried.last().expect("at least one tolerance tried");
        let level = |n: Noise, scale: f64| match n.sigma() {
            Some(s) => format!("{:.1e}", s / scale),
            None => n.failure().unwrap_or("").to_string(),
        };
        let g = m
            .noise_g
            .iter()
            .map(|&n| level(n, 1.0))
            .collect::<Vec<_>>()
            .join(", ");
        format!(
            "scene_problem: rtol auto -> {:e} ({}; noise of f {} of max(|f|, 1), of g [{g}], \
             target {:.0e}; {} function calls)",
            self.rtol,
            if self.met {
                "met"
            } else {
                "NOT met: the tightest tried"
            },
            level(m.noise_f, m.f.abs().max(1.0)),
            self.target,
            self.evaluations()
        )
    }
}

/// The choices made in this process, by the full text of their study.
static CHOICES: std::sync::Mutex<Vec<(String, Choice)>> = std::sync::Mutex::new(Vec::new());

/// The choice made earlier in this process for the study whose full text
/// (every table, as TOML) is `key`.
pub fn remembered(key: &str) -> Option<Choice> {
    let memo = CHOICES.lock().unwrap_or_else(|p| p.into_inner());
    memo.iter().find(|(k, _)| k == key).map(|(_, c)| c.clone())
}

/// Keep `choice` for later builds of the study with text `key`.
pub fn remember(key: String, choice: &Choice) {
    let mut memo = CHOICES.lock().unwrap_or_else(|p| p.into_inner());
    if !memo.iter().any(|(k, _)| *k == key) {
        memo.push((key, choice.clone()));
    }
}

/// Does the measurement `m` meet the noise target `target`?
pub fn quiet_enough(m: &Measured, target: f64) -> bool {
    let ok = |n: Noise, scale: f64| match n {
        Noise::Level { sigma, .. } => sigma / scale <= target,
        Noise::StepTooSmall => true,
        Noise::StepTooLarge => false,
    };
    ok(m.noise_f, m.f.abs().max(1.0)) && m.noise_g.iter().all(|&n| ok(n, 1.0))
}

/// Choose the tolerance of `problem` at the design `x` for the
/// feasibility tolerance `feasibility` (see the module doc); the problem
/// is left at the chosen tolerance.
pub fn choose(problem: &mut dyn Problem, x: &[f64], feasibility: f64, seed: u64) -> Result<Choice> {
    let target = feasibility.max(1e-12) / 10.0;
    let mut rtol = problem.tolerance().unwrap_or(TIGHTEST);
    let mut tried = Vec::new();
    loop {
        problem.set_tolerance(rtol);
        let m = estimate(&*problem, x, seed, &NoiseOptions::default())?;
        let met = quiet_enough(&m, target);
        tried.push((rtol, m));
        if met || rtol <= TIGHTEST * 1.000001 {
            return Ok(Choice {
                rtol,
                tried,
                met,
                target,
            });
        }
        rtol = (rtol / 10.0).max(TIGHTEST);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measured(noise_f: Noise, noise_g: Vec<Noise>) -> Measured {
        Measured {
            x: vec![0.0],
            f: 2.0,
            g: vec![0.0; noise_g.len()],
            noise_f,
            noise_g,
            steps: vec![1e-4],
            evaluations: 8,
            first_order_f: 0.0,
        }
    }

    #[test]
    fn the_test_reads_f_relative_and_g_absolute() {
        let level = |sigma| Noise::Level { sigma, order: 3 };
        // σ_f = 1.8e-7 is 9e-8 of |f| = 2: within 1e-7.
        assert!(quiet_enough(
            &measured(level(1.8e-7), vec![level(9e-8)]),
            1e-7
        ));
        assert!(!quiet_enough(&measured(level(2.2e-7), vec![]), 1e-7));
        assert!(!quiet_enough(
            &measured(level(1e-9), vec![level(2e-7)]),
            1e-7
        ));
        assert!(quiet_enough(
            &measured(Noise::StepTooSmall, vec![Noise::StepTooSmall]),
            1e-7
        ));
        assert!(!quiet_enough(
            &measured(level(1e-9), vec![Noise::StepTooLarge]),
            1e-7
        ));
    }
}
