//! The `[multistart]` section ([`MultistartSection`]) and its checked
//! plan ([`MultistartPlan`]: the section, the start points of
//! [`super::sampling`] and the clustering tolerances of
//! [`super::cluster`]).
//!
//! Reading the section computes nothing; building the plan generates the
//! start points (and evaluates the problem when only feasible starts are
//! kept). Every check names the study file and the dotted key it refuses.

use super::cluster::Tolerances;
use super::sampling::{self, Sampler};
use crate::error::{Error, Result};
use crate::explore::local::solvers::{LocalMethod, MmfdPreset, MmfdSettings};
use crate::optimize::Problem;
use crate::study::Study;
use serde::Deserialize;

/// The `[multistart]` section: start points, local optimizer and budget
/// of the multistart driver.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MultistartSection {
    /// Local optimizer: `mmfd` (default) or `steepest`.
    #[serde(default)]
    pub method: LocalMethod,
    /// Sampler of the start points: `lhs` (default), `sobol`, `uniform`.
    #[serde(default)]
    pub sampler: Sampler,
    /// Number of sampled start points.
    #[serde(default)]
    pub starts: usize,
    /// Listed start points (run first).
    #[serde(default)]
    pub points: Vec<Vec<f64>>,
    /// Keep only feasible starts.
    #[serde(default)]
    pub feasible_only: bool,
    /// Stop launching runs once this many function calls are used.
    pub max_evaluations: Option<usize>,
    /// Stop launching runs after this wall time \[s\].
    pub max_wall_seconds: Option<f64>,
    /// Rows of `runs.csv` evaluated again on `--resume` (default 2; see
    /// [`crate::explore::persist::fingerprint`]).
    #[serde(default = "default_resume_checks")]
    pub resume_checks: usize,
    /// Same optimum: coordinates within this fraction of each range
    /// (default 1e-2: 1.8° on a 180° ply angle; MMFD with DOT's default
    /// DELOBJ = 1e-3 stops that far from the exact optimum on flat valleys).
    #[serde(default = "default_x_tol")]
    pub x_tolerance: f64,
    /// Same optimum: `|Δf| <= f_tolerance · max(1, |f|)` (default 1e-2:
    /// ten times DOT's DELOBJ, since runs that end on active constraints
    /// within CTMIN differ in f by that much; distinct optima are told apart
    /// by `x_tolerance`).
    #[serde(default = "default_f_tol")]
    pub f_tolerance: f64,
    /// Feasible: `max g <= feasibility_tolerance` (default 1e-6). The one
    /// tolerance of the study: MMFD's CTMIN, the certificate, the polish,
    /// CMA-ES's ranking and the tables' `feasible` columns all use it.
    #[serde(default = "default_feas_tol")]
    pub feasibility_tolerance: f64,
    /// The certificate's stationarity tolerance: a feasible end is
    /// `converged` when its relative Kuhn–Tucker residual is at most this
    /// (default 1e-4; see `optimize::kkt`).
    #[serde(default = "default_kt_tol")]
    pub kt_tolerance: f64,
    /// The certificate's active set: `g_j >= −active_tolerance` (default
    /// 1e-4).
    #[serde(default = "default_active_tol")]
    pub active_tolerance: f64,
    /// Polish every end that is not converged (default true; see
    /// [`crate::explore::local::settle`]).
    #[serde(default = "default_polish")]
    pub polish: bool,
    /// Rescue every run that ends infeasible by the pure descent on the
    /// violation from its start, then settle its end when it reaches the
    /// feasible set (default true; see [`crate::explore::local::settle`]).
    #[serde(default = "default_polish")]
    pub rescue: bool,
    /// Infeasible runs checked by a pure descent on the violation from
    /// their starts (default 0; see [`crate::explore::local::violation`]).
    #[serde(default)]
    pub violation_checks: usize,
    /// MMFD's settings before `[multistart.mmfd]`: `dot` (default, DOT's
    /// own, with its absolute-change exit) or `standard` (without it, the
    /// Kuhn–Tucker exit relative to the gradient).
    #[serde(default)]
    pub preset: MmfdPreset,
    /// MMFD convergence settings (`[multistart.mmfd]`; over the preset).
    #[serde(default)]
    pub mmfd: MmfdSettings,
    /// The rise of f, relative to `max(|f|, 1)`, that the polish tolerates
    /// among designs within the evaluation's noise: a number, or
    /// `"measured"` (the default: ECNoise at the first start before the
    /// runs, 8 function calls or more: 3σ of f, 0 where f is smooth at
    /// every step tried, as a closed form is; `crate::optimize::noise`),
    /// which also measures it at every certified optimum (`optima.csv`'s
    /// `noise_*` columns).
    #[serde(default)]
    pub noise: NoiseAllowance,
}

/// `[multistart] noise`: given, or measured before the runs.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged, expecting = "a number, or \"measured\"")]
pub enum NoiseAllowance {
    /// A relative allowance.
    Given(f64),
    /// Measured by ECNoise at the first start.
    Measured(Measure),
}

/// The word `measured`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub enum Measure {
    /// `"measured"`.
    #[serde(rename = "measured")]
    Measured,
}

impl Default for NoiseAllowance {
    fn default() -> Self {
        NoiseAllowance::Measured(Measure::Measured)
    }
}

impl MultistartSection {
    /// The certificate's tolerances.
    pub fn kkt_tolerances(&self) -> crate::optimize::kkt::KktTolerances {
        crate::optimize::kkt::KktTolerances {
            feasibility: self.feasibility_tolerance,
            active: self.active_tolerance,
            stationarity: self.kt_tolerance,
        }
    }

    /// What happens at every run's end, with the noise allowances
    /// `(noise, noise_g)` of f (relative; given, or measured by the
    /// command) and of the constraints (absolute; 0 when not measured).
    pub fn end_policy(
        &self,
        (noise, noise_g): (f64, f64),
    ) -> crate::explore::local::settle::EndPolicy {
        crate::explore::local::settle::EndPolicy {
            tolerances: self.kkt_tolerances(),
            polish: self.polish,
            rescue: self.rescue,
            noise,
            noise_g,
        }
    }
}

fn default_resume_checks() -> usize {
    crate::explore::persist::fingerprint::DEFAULT_RESUME_CHECKS
}
fn default_x_tol() -> f64 {
    1e-2
}
fn default_f_tol() -> f64 {
    1e-2
}
fn default_feas_tol() -> f64 {
    1e-6
}
fn default_kt_tol() -> f64 {
    1e-4
}
fn default_active_tol() -> f64 {
    1e-4
}
fn default_polish() -> bool {
    true
}

/// Validated `[multistart]` with its start points.
pub struct MultistartPlan {
    /// The section.
    pub section: MultistartSection,
    /// Start points (all shards).
    pub starts: sampling::Starts,
    /// Clustering tolerances.
    pub tolerances: Tolerances,
}

/// Read and check `[multistart]` (keys and values; no start generated).
pub fn multistart_section(study: &Study) -> Result<MultistartSection> {
    let s: MultistartSection =
        study.require_section("multistart", "starts = ..., sampler = ...")?;
    let loc = study.locate("multistart");
    s.mmfd.check().map_err(study.locate("multistart.mmfd"))?;
    for (key, v) in [
        ("x_tolerance", s.x_tolerance),
        ("f_tolerance", s.f_tolerance),
        ("kt_tolerance", s.kt_tolerance),
        ("active_tolerance", s.active_tolerance),
    ] {
        crate::error::require_positive(key, v).map_err(&loc)?;
    }
    if !(s.feasibility_tolerance.is_finite() && s.feasibility_tolerance >= 0.0) {
        return Err(loc(Error::input(
            "feasibility_tolerance",
            s.feasibility_tolerance,
            "a finite value >= 0",
        )));
    }
    if let NoiseAllowance::Given(v) = s.noise {
        if !(v.is_finite() && v >= 0.0) {
            return Err(loc(Error::input(
                "noise",
                v,
                "a finite relative allowance >= 0, or \"measured\"",
            )));
        }
    }
    if let Some(w) = s.max_wall_seconds {
        crate::error::require_positive("max_wall_seconds", w).map_err(&loc)?;
    }
    if s.max_evaluations == Some(0) {
        return Err(loc(Error::input(
            "max_evaluations",
            0,
            "a budget >= 1 (or no key)",
        )));
    }
    Ok(s)
}

/// Read and check `[multistart]`, generate the starts.
pub fn multistart_plan(study: &Study, problem: &dyn Problem) -> Result<MultistartPlan> {
    let s = multistart_section(study)?;
    let loc = study.locate("multistart");
    let spec = sampling::StartsSpec {
        sampler: s.sampler,
        count: s.starts,
        points: s.points.clone(),
        feasible_only: s.feasible_only,
    };
    let starts = spec.generate(problem, study.meta.seed).map_err(|e| {
        // `count` is called `starts` in the study file.
        match e {
            Error::Input {
                key,
                value,
                expected,
                file,
            } if key == "count" => loc(Error::Input {
                key: "starts".into(),
                value,
                expected,
                file,
            }),
            e => loc(e),
        }
    })?;
    Ok(MultistartPlan {
        tolerances: Tolerances {
            x: s.x_tolerance,
            f: s.f_tolerance,
            feasibility: s.feasibility_tolerance,
        },
        section: s,
        starts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explore::problem;

    fn study(text: &str) -> Study {
        Study::parse("plan.toml", text).unwrap()
    }

    const HIMMELBLAU: &str = "[study]\nseed = 7\n[problem]\nname = \"himmelblau\"\n";

    #[test]
    fn multistart_plan_lists_points_first_then_samples_with_defaults() {
        let s = study(&format!(
            "{HIMMELBLAU}[multistart]\nstarts = 5\npoints = [[1.0, 2.0]]\n"
        ));
        let p = problem(&s).unwrap();
        let plan = multistart_plan(&s, p.as_ref()).unwrap();
        assert_eq!(plan.section.method, LocalMethod::Sqp);
        assert_eq!(plan.section.sampler, Sampler::Lhs);
        assert_eq!(plan.starts.points.len(), 6);
        assert_eq!(plan.starts.points[0], [1.0, 2.0]);
        assert_eq!(plan.starts.filter_evaluations, 0);
        assert_eq!(
            (
                plan.tolerances.x,
                plan.tolerances.f,
                plan.tolerances.feasibility
            ),
            (1e-2, 1e-2, 1e-6)
        );
        // The same study gives the same starts; another seed other ones.
        let again = multistart_plan(&s, p.as_ref()).unwrap();
        assert_eq!(again.starts, plan.starts);
        let other = study(
            "[study]\nseed = 8\n[problem]\nname = \"himmelblau\"\n[multistart]\nstarts = 5\n\
             points = [[1.0, 2.0]]\n",
        );
        let q = multistart_plan(&other, p.as_ref()).unwrap();
        assert_ne!(q.starts.points[1..], plan.starts.points[1..]);
    }

    #[test]
    fn multistart_kinds_are_read_by_name_and_bad_names_are_refused() {
        let s = study(&format!(
            "{HIMMELBLAU}[multistart]\nstarts = 4\nmethod = \"steepest\"\nsampler = \"sobol\"\n"
        ));
        let sec = multistart_section(&s).unwrap();
        assert_eq!(
            (sec.method, sec.sampler),
            (LocalMethod::Steepest, Sampler::Sobol)
        );
        for (key, bad, names) in [
            ("sampler", "halton", "`lhs`, `sobol`, `uniform`"),
            ("method", "bfgs", "`mmfd`, `steepest`, `sqp`"),
        ] {
            let s = study(&format!(
                "{HIMMELBLAU}[multistart]\nstarts = 4\n{key} = \"{bad}\"\n"
            ));
            let e = multistart_section(&s).unwrap_err().to_string();
            assert!(e.starts_with("plan.toml") && e.contains(bad), "{e}");
            // The dotted key, the value and the accepted names.
            assert!(
                e.contains(names) && e.contains(&format!("`multistart.{key}`")),
                "{e}"
            );
        }
        // `starts` (the sampler's `count`) is named as in the study file.
        let s = study(&format!("{HIMMELBLAU}[multistart]\nstarts = 0\n"));
        let p = problem(&s).unwrap();
        let e = multistart_plan(&s, p.as_ref()).err().unwrap().to_string();
        assert!(e.contains("multistart.starts"), "{e}");
    }
}
