//! Configuration of the exploration drivers: the study sections they read
//! (`[multistart]`, `[evolve]`, `[compare]`, `[map]`, and `[problem]` through
//! [`problem`]) and the checked plans built from them.
//!
//! Reading a section never computes anything beyond building the problem
//! ([`problem`]) and generating the start points ([`multistart_plan`]);
//! every check names the study file and the dotted key it refuses.

use super::cluster::Tolerances;
use super::problems;
use super::sampling::{self, Sampler};
use super::scene_problem;
use super::solvers::{LocalMethod, MmfdPreset, MmfdSettings};
use crate::error::{Error, Result};
use crate::optimize::cmaes::Restarts;
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
    /// [`super::fingerprint`]).
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
    /// [`super::settle`]).
    #[serde(default = "default_polish")]
    pub polish: bool,
    /// Rescue every run that ends infeasible by the pure descent on the
    /// violation from its start, then settle its end when it reaches the
    /// feasible set (default true; see [`super::settle`]).
    #[serde(default = "default_polish")]
    pub rescue: bool,
    /// Infeasible runs checked by a pure descent on the violation from
    /// their starts (default 0; see [`super::violation`]).
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

    /// What happens at every run's end.
    pub fn end_policy(&self) -> super::settle::EndPolicy {
        super::settle::EndPolicy {
            tolerances: self.kkt_tolerances(),
            polish: self.polish,
            rescue: self.rescue,
        }
    }
}

fn default_resume_checks() -> usize {
    super::fingerprint::DEFAULT_RESUME_CHECKS
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

/// The `[evolve]` section.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct EvolveSection {
    /// Evaluation budget of each schedule. Default: under `compare`, the
    /// function calls the multistart used; alone, 100 per start of
    /// `[multistart]`, else 10 000.
    pub max_evaluations: Option<usize>,
    /// CMA-ES restart schedule ([`crate::optimize::cmaes::Restarts`]):
    /// `ipop` (default), `bipop`, or a list of distinct names
    /// (`["ipop", "bipop"]`), run one after another on the same budget and
    /// seed; read by [`schedules`].
    pub restarts: Option<toml::Value>,
    /// CMA-ES TolFun: a run restarts when its best f of the recent
    /// generations and every f of the current one lie within this range.
    /// Default 1e-12, for exact objectives; an objective from a simulation
    /// carries the integrator's noise (adaptive steps: about 1e-8 of f at
    /// rtol 1e-6), below which no progress is real, and a run whose f
    /// never settles within 1e-12 never restarts: set it above the noise.
    pub tol_fun: Option<f64>,
    /// Stop a schedule when a design feasible to the tolerance reaches
    /// `f <= target` (stop reason `target_reached`). Default: none.
    pub target: Option<f64>,
    /// Active CMA-ES (negative weights for the worst samples). Default
    /// false.
    #[serde(default)]
    pub active: bool,
}

/// A checked `[evolve]`.
#[derive(Debug, Clone)]
pub struct EvolvePlan {
    /// The section.
    pub section: EvolveSection,
    /// The restart schedules, in the order they run (at least one).
    pub schedules: Vec<Restarts>,
}

/// Read and check `[evolve]` (absent: defaults). Errors name the file and
/// `evolve.<key>`.
pub fn evolve_plan(study: &Study) -> Result<EvolvePlan> {
    let section: EvolveSection = study.section("evolve")?.unwrap_or_default();
    if section.max_evaluations == Some(0) {
        return Err(study.error("evolve.max_evaluations", 0, "a budget >= 1"));
    }
    if let Some(t) = section.tol_fun {
        if !(t.is_finite() && t >= 0.0) {
            return Err(study.error("evolve.tol_fun", t, "a finite range >= 0"));
        }
    }
    if let Some(t) = section.target {
        if !t.is_finite() {
            return Err(study.error("evolve.target", t, "a finite objective value"));
        }
    }
    let schedules = schedules(section.restarts.as_ref()).map_err(study.locate("evolve"))?;
    Ok(EvolvePlan { section, schedules })
}

/// The schedules of a `restarts` value: absent, IPOP; a name, that
/// schedule; a non-empty list of distinct names, those in order. Errors
/// name the key `restarts` (`restarts[k]` for the k-th list entry).
pub fn schedules(value: Option<&toml::Value>) -> Result<Vec<Restarts>> {
    let names = Restarts::NAMES;
    let list = match value {
        None => return Ok(vec![Restarts::default()]),
        Some(toml::Value::String(name)) => return Ok(vec![Restarts::parse(name)?]),
        Some(toml::Value::Array(list)) if !list.is_empty() => list,
        Some(other) => {
            return Err(Error::input(
                "restarts",
                other,
                format!(
                    "one of {names}, or a non-empty list of them (\"ipop\", [\"ipop\", \"bipop\"])"
                ),
            ))
        }
    };
    let mut out: Vec<Restarts> = Vec::new();
    for (k, v) in list.iter().enumerate() {
        let key = format!("restarts[{k}]");
        let r = v
            .as_str()
            .and_then(|name| Restarts::parse(name).ok())
            .ok_or_else(|| Error::input(&key, v, format!("one of {names}")))?;
        if let Some(j) = out.iter().position(|&earlier| earlier == r) {
            return Err(Error::input(
                key,
                v,
                format!("each schedule once (it is restarts[{j}] already)"),
            ));
        }
        out.push(r);
    }
    Ok(out)
}

/// The `[compare]` section (no keys).
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CompareSection {}

/// The `[map]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapSection {
    /// Grid points per axis (default 61).
    #[serde(default = "default_resolution")]
    pub resolution: usize,
    /// Variable pairs for more than two variables (default: consecutive
    /// pairs (0,1), (2,3), ...).
    pub pairs: Option<Vec<[usize; 2]>>,
    /// Cells evaluated again on `--resume` (default 2; see
    /// [`super::fingerprint`]).
    #[serde(default = "default_resume_checks")]
    pub resume_checks: usize,
}

fn default_resolution() -> usize {
    61
}

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

/// Read and check `[map]` (default: 61 points per axis, consecutive pairs).
pub fn map_section(study: &Study) -> Result<MapSection> {
    let sec: MapSection = study.section("map")?.unwrap_or(MapSection {
        resolution: default_resolution(),
        pairs: None,
        resume_checks: default_resume_checks(),
    });
    if !(2..=2001).contains(&sec.resolution) {
        return Err(study.error("map.resolution", sec.resolution, "2 <= resolution <= 2001"));
    }
    Ok(sec)
}

/// Read `[compare]` (no keys; absent is fine).
pub fn compare_section(study: &Study) -> Result<Option<CompareSection>> {
    study.section::<CompareSection>("compare")
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

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(plan.section.method, LocalMethod::Mmfd);
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
            ("method", "bfgs", "`mmfd` or `steepest`"),
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

    #[test]
    fn evolve_plan_reads_schedules_and_refuses_repeats() {
        let s = study(HIMMELBLAU);
        let plan = evolve_plan(&s).unwrap();
        assert_eq!(plan.schedules, [Restarts::Ipop]);
        let s = study(&format!(
            "{HIMMELBLAU}[evolve]\nrestarts = [\"bipop\", \"ipop\"]\n"
        ));
        assert_eq!(
            evolve_plan(&s).unwrap().schedules,
            [Restarts::Bipop, Restarts::Ipop]
        );
        let s = study(&format!(
            "{HIMMELBLAU}[evolve]\nrestarts = [\"ipop\", \"ipop\"]\n"
        ));
        let e = evolve_plan(&s).unwrap_err().to_string();
        assert!(
            e.contains("evolve.restarts[1]") && e.contains("restarts[0]"),
            "{e}"
        );
        let s = study(&format!(
            "{HIMMELBLAU}[evolve]\ntarget = 1e-6\nactive = true\n"
        ));
        let plan = evolve_plan(&s).unwrap();
        assert_eq!(
            (plan.section.target, plan.section.active),
            (Some(1e-6), true)
        );
        let s = study(&format!("{HIMMELBLAU}[evolve]\ntarget = nan\n"));
        let e = evolve_plan(&s).unwrap_err().to_string();
        assert!(e.contains("evolve.target"), "{e}");
        let s = study(&format!("{HIMMELBLAU}[evolve]\nmax_evaluations = 0\n"));
        let e = evolve_plan(&s).unwrap_err().to_string();
        assert!(e.contains("evolve.max_evaluations"), "{e}");
    }

    #[test]
    fn map_section_defaults_and_bounds() {
        let sec = map_section(&study(HIMMELBLAU)).unwrap();
        assert_eq!((sec.resolution, sec.pairs), (61, None));
        let e = map_section(&study(&format!("{HIMMELBLAU}[map]\nresolution = 1\n")))
            .unwrap_err()
            .to_string();
        assert!(e.contains("map.resolution"), "{e}");
    }
}
