//! A study's multibody scene as an optimization [`Problem`]: the paper's
//! ply-angle optimization of the SAR antenna (Neto, Ambrósio, Leal §4–§6,
//! Eqs. 29–34, Table 4).
//!
//! A study selects it with `[problem] name = "scene"` and describes it in
//! the sibling section `[scene_problem]` (a sibling rather than
//! `[problem.scene]`, so that the analytic `[problem]` keys stay one flat,
//! strictly checked table):
//!
//! ```toml
//! [problem]
//! name = "scene"
//!
//! [scene_problem]
//! start = [55.0, -55.0]                  # degrees, one per variable (Table 4)
//!
//! [[scene_problem.variables]]
//! name = "theta1_deg"
//! bounds = [-90.0, 90.0]                 # degrees
//! periodic = true                        # then upper - lower = 180°
//! sets = ["panel2:theta_1_4", "panel3:theta_1_4"]   # [[panels]] name : design variable
//!
//! [scene_problem.objective]
//! response = "psi0"                      # a [[scene.responses]] name
//! normalize_at = [55.0, -55.0]           # optional: f = value / value at this design
//!
//! [[scene_problem.constraints]]
//! response = "u3_peak"
//! upper_relative = 1.0                   # c = 1.0 × value at `start` (or `upper`/`lower`, absolute)
//! ```
//!
//! Each problem variable is a ply angle in degrees written into every
//! listed `[[panels]]` design variable (all plies of its group, e.g. plies
//! 1 and 4 of `theta_1_4`; `design = [[1], [2], [3], [4]]` frees every
//! ply); tying one variable to both panels is the paper's shared θ1/θ2.
//! A variable may instead set scene parameters, `sets =
//! ["scene:forces[0].damping"]` (any `[scene] sensitivities` name but a
//! ply angle, in its SI unit; `crate::explore::problem::scene_vars`), so that ply angles
//! and mechanism parameters are designed together. The objective is `f = R₀(x) / R₀(x_ref)` (or
//! `R₀(x)` without `normalize_at`), each constraint
//! `g_j = R_j(x) / c_j − 1 <= 0` (Eq. 34 with `c_j` the bound) for an
//! upper bound, or an absolute upper or lower bound normalized by a scale
//! ([`crate::explore::problem::scene_bounds`]). A problem whose responses are all
//! frequencies builds the scene at each design without integrating it.
//!
//! Evaluation: a [`ScenePlan`] made once holds the parsed scene, the
//! resolved panels and, per panel, a basis builder (mesh, sparsity
//! pattern, symbolic factorization) reused for every design; a design
//! goes in as numbers (each variable's angle, converted once to radians,
//! written into the plies of its panel groups with
//! [`crate::laminate::Laminate`]), the panel modal bases are recomputed for
//! the new lay-ups, and the scene is built and simulated. Gradients come from the scene's forward sensitivities
//! (exact, `crate::mbs::responses`): with gradients asked, the scene runs
//! with exactly the lanes `<body>.design.<variable>` of the bodies built
//! from the tied panels (each must appear in `[scene] sensitivities`, so
//! that the study file shows what is differentiated); without, with none.
//! By default the lanes of one variable are tied into one
//! (`tied_lanes = true`: `B3.design.theta_1_4+B2.design.theta_1_4`, one
//! dual-number direction that moves every tied ply at once), so a shared
//! angle costs one sensitivity lane; with `tied_lanes = false` each body's
//! lane is integrated and the lanes are summed. A variable's derivative is
//! the sum over its lanes, times π/180 (the scene's lanes are per radian,
//! the variables in degrees). The output
//! columns of `[scene.outputs]` are dropped (responses need none). The
//! plan's builders are pooled, so drivers may evaluate in parallel.
//!
//! Ply angles repeat every 180° (docs/numerics.md): a periodic variable is
//! written as given, and `x` and `x + 180°` give the same laminate up to
//! the rounding of the rotation's sines and cosines.

use super::accuracy::{self, Choice, RtolSetting};
use super::scene_bounds::{self, Bound};
pub use super::scene_vars::VariableSpec;
use super::scene_vars::{problem_error, Ties};
use crate::error::{Error, Result};
use crate::integrate::SensitivityForm;
use crate::laminate::Laminate;
use crate::mbs::responses::{ResponseKindName, ResponseValue, Sense};
use crate::optimize::{Evaluation, Problem, Variable};
use crate::scene::{BuildProfile, ScenePlan};
use crate::simulate::sampled::frequencies;
use crate::simulate::{simulate, Simulation};
use crate::study::Study;
use serde::Deserialize;

/// The `[scene_problem]` section.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneProblemSpec {
    /// The design variables.
    pub variables: Vec<VariableSpec>,
    /// Start design \[deg\], one value per variable (reference of the
    /// relative constraint bounds).
    pub start: Vec<f64>,
    /// The objective.
    pub objective: ObjectiveSpec,
    /// Upper-bound constraints on responses.
    #[serde(default)]
    pub constraints: Vec<ConstraintSpec>,
    /// One sensitivity lane per problem variable (default): the bodies'
    /// design variables that a variable sets are tied into one lane
    /// (`"B3.design.theta_1_4+B2.design.theta_1_4"`, the derivative with
    /// respect to the shared angle), so a shared angle costs one lane.
    /// `false`: one lane per body and design variable, summed afterwards.
    #[serde(default = "yes")]
    pub tied_lanes: bool,
    /// The integration tolerance of the evaluations: a number (over
    /// `[scene.integrator] rtol`, atol following at the scene's ratio) or
    /// `"auto"`, the loosest whose measured noise sits a decade below the
    /// feasibility tolerance ([`super::accuracy`]). Default: the scene's.
    /// The constraint bounds and the objective's divisor are computed at
    /// it (with `"auto"`, again once it is chosen).
    pub rtol: Option<RtolSetting>,
}

fn yes() -> bool {
    true
}

/// `[scene_problem.objective]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectiveSpec {
    /// A `[[scene.responses]]` name.
    pub response: String,
    /// Divide by the response's value at this design \[deg\].
    pub normalize_at: Option<Vec<f64>>,
}

pub use super::scene_bounds::ConstraintSpec;

/// A scene response as an optimization problem (see the module doc).
pub struct SceneProblem {
    vars: Vec<Variable>,
    /// The scene prepared once; a design goes in as laminates.
    plan: ScenePlan,
    /// What each variable sets, and the sensitivity lanes.
    ties: Ties,
    /// Objective response and divisor.
    objective: (String, f64),
    /// Constraint bounds, in the order of `g`.
    constraints: Vec<Bound>,
    /// SI units of the objective's and the constraints' responses (from
    /// the start design's evaluation).
    units: Vec<String>,
    start: Vec<f64>,
    /// The study's name, for reports.
    study: String,
    /// The study's own (rtol, atol): [`Problem::set_tolerance`] keeps
    /// their ratio.
    study_tolerances: (f64, f64),
    /// What `rtol = "auto"` measured and chose.
    choice: Option<Choice>,
    /// Per flexible body, the mode counts `(asked, used)` of the
    /// evaluations whose lay-up had a repeated eigenvalue at the asked
    /// count (the cluster left out whole), with the number of evaluations.
    splits: std::sync::Mutex<std::collections::BTreeMap<(String, usize, usize), usize>>,
}

/// Raw response values (and their gradients per degree of each variable).
struct Raw {
    values: Vec<f64>,
    units: Vec<String>,
    gradients: Option<Vec<Vec<f64>>>,
    profile: EvalProfile,
}

/// Responses evaluated beside the problem's own
/// ([`SceneProblem::evaluate_with`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ExtraResponses {
    /// Values, in the responses' units.
    pub values: Vec<f64>,
    /// The responses' SI units.
    pub units: Vec<String>,
    /// Gradients per degree of each variable (one row per response), when
    /// asked.
    pub gradients: Option<Vec<Vec<f64>>>,
}

/// What one evaluation computed and where its time went.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EvalProfile {
    /// The scene build: panel bases (count, with derivatives, seconds).
    pub build: BuildProfile,
    /// Sensitivity lanes integrated with the motion (0 without gradients).
    pub lanes: usize,
    /// Accepted integration steps.
    pub steps: usize,
    /// Right-hand-side evaluations and Jacobian-vector products.
    pub rhs_calls: u64,
    /// Jacobian-vector products (each one dual-number evaluation).
    pub jvp_calls: u64,
    /// Wall time of the integration (states and sensitivities, outputs
    /// excluded) \[s\].
    pub integrate_seconds: f64,
    /// Wall time of the output and response evaluation \[s\].
    pub outputs_seconds: f64,
    /// Wall time of the whole evaluation \[s\].
    pub total_seconds: f64,
}

impl SceneProblem {
    /// Build from a study with `[scene]`, `[[panels]]` and
    /// `[scene_problem]`; evaluates the start design (and the
    /// normalization design) once. Errors name the file and key.
    pub fn from_study(study: &Study) -> Result<SceneProblem> {
        let (spec, plan, ties) = Self::checked(study)?;
        let mut problem = SceneProblem {
            vars: ties.vars.clone(),
            plan,
            ties,
            objective: (spec.objective.response.clone(), 1.0),
            constraints: Vec::new(),
            units: Vec::new(),
            start: spec.start.clone(),
            study: study.name(),
            study_tolerances: (0.0, 0.0),
            choice: None,
            splits: Default::default(),
        };
        problem.study_tolerances = problem.tolerances();
        if let Some(RtolSetting::Given(r)) = spec.rtol {
            problem.set_tolerance(r);
        }
        problem.set_references(study, &spec)?;
        match spec.rtol {
            None | Some(RtolSetting::Given(_)) => {}
            Some(RtolSetting::Auto(_)) => {
                // τ of the study: [multistart]'s, read raw (the problem
                // sits below the drivers), else the drivers' default.
                let feasibility = study
                    .table
                    .get("multistart")
                    .and_then(|m| m.get("feasibility_tolerance"))
                    .and_then(|v| v.as_float())
                    .unwrap_or(1e-6);
                // Keyed by the study's full text; a study that does not
                // serialize is measured every time.
                let key = toml::to_string(&study.table).ok();
                let choice = match key.as_deref().and_then(accuracy::remembered) {
                    Some(c) => {
                        problem.set_tolerance(c.rtol);
                        c
                    }
                    None => {
                        let start = problem.start.clone();
                        let c =
                            accuracy::choose(&mut problem, &start, feasibility, study.meta.seed)
                                .map_err(study.locate("scene_problem.rtol"))?;
                        eprintln!("note: {}", c.summary());
                        if let Some(key) = key {
                            accuracy::remember(key, &c);
                        }
                        c
                    }
                };
                problem.choice = Some(choice);
                // The bounds and the divisor again, at the tolerance chosen:
                // a bound "at the start's value" then holds the start on
                // it, not 1e-5 off by the scene tolerance's error.
                problem.constraints.clear();
                problem.set_references(study, &spec)?;
            }
        }
        Ok(problem)
    }

    /// Check `[scene_problem]` against `[scene]` and `[[panels]]` without
    /// evaluating any design.
    pub fn check(study: &Study) -> Result<()> {
        Self::checked(study).map(|_| ())
    }

    /// The problem's variables, checked as [`SceneProblem::check`] does,
    /// without evaluating any design.
    pub fn variables_of(study: &Study) -> Result<Vec<Variable>> {
        Self::checked(study).map(|(_, _, ties)| ties.vars)
    }

    /// The parsed and checked spec, the scene plan and the ties.
    fn checked(study: &Study) -> Result<(SceneProblemSpec, ScenePlan, Ties)> {
        let spec: SceneProblemSpec = study.require_section(
            "scene_problem",
            "the scene problem (variables, start, objective)",
        )?;
        let plan = ScenePlan::new(study)?;
        if let Some(RtolSetting::Given(r)) = spec.rtol {
            if !(r.is_finite() && r > 0.0 && r <= 1e-2) {
                return Err(study.error(
                    "scene_problem.rtol",
                    r,
                    "a tolerance with 0 < rtol <= 1e-2, or \"auto\"",
                ));
            }
        }
        let ties = Ties::resolve(study, &spec.variables, spec.tied_lanes, &plan)?;
        check_objective_and_constraints(study, &spec, &plan, &ties.vars)?;
        Ok((spec, plan, ties))
    }

    /// The constraint bounds and the objective's divisor from the start
    /// design (and the normalization design).
    fn set_references(&mut self, study: &Study, spec: &SceneProblemSpec) -> Result<()> {
        let mut wanted = vec![(spec.objective.response.clone(), 0)];
        wanted.extend(spec.constraints.iter().map(|c| (c.response.clone(), 0)));
        let at_start = self.raw(&spec.start, &wanted, false)?;
        for (j, c) in spec.constraints.iter().enumerate() {
            let at = (at_start.values[j + 1], self.peak_sense(&c.response));
            let bounds = scene_bounds::resolve(study, j, c, at)?;
            self.constraints.extend(bounds);
        }
        self.units = at_start.units.clone();
        if let Some(r) = &spec.objective.normalize_at {
            let v = if *r == spec.start {
                at_start.values[0]
            } else {
                self.raw(r, &wanted[..1], false)?.values[0]
            };
            if !(v.is_finite() && v != 0.0) {
                return Err(problem_error(
                    study,
                    "objective.normalize_at".into(),
                    format!("{r:?}"),
                    format!(
                        "a design where {} is not zero (it is {v:e})",
                        spec.objective.response
                    ),
                ));
            }
            self.objective.1 = v;
        }
        Ok(())
    }

    /// Integrate the gradients' sensitivities in `form` from now on.
    pub fn set_sensitivity_form(&mut self, form: SensitivityForm) {
        self.plan.set_sensitivity_form(form);
    }

    /// Integrate with `method` from now on (overrides the scene's).
    pub fn set_method(&mut self, method: crate::integrate::Method) {
        self.plan.set_method(method);
    }

    /// Integrate with the tolerances `rtol` and `atol` from now on
    /// (overrides `[scene.integrator]`; the constraint bounds and the
    /// objective's divisor stay those the problem was built with: the
    /// problem is the same, evaluated more or less accurately; the
    /// study's `rtol` is set before they are computed).
    pub fn set_tolerances(&mut self, rtol: f64, atol: f64) {
        self.plan.set_tolerances(rtol, atol);
    }

    /// What `rtol = "auto"` measured and chose (`None` without it).
    pub fn accuracy_choice(&self) -> Option<&Choice> {
        self.choice.as_ref()
    }

    /// The relative and absolute tolerances the evaluations use.
    pub fn tolerances(&self) -> (f64, f64) {
        let i = &self.plan.spec().integrator;
        (i.rtol, i.atol)
    }

    /// The integration method the evaluations use.
    pub fn method(&self) -> crate::integrate::Method {
        self.plan.spec().integrator.method
    }

    /// Compute the panels' mode derivatives by `update` from now on
    /// (fixed: Eq. 19, eigenvalue derivatives only; updated: Eq. 18).
    pub fn set_mode_update(&mut self, update: crate::modal::ModeUpdate) {
        self.plan.set_mode_update(update);
    }

    /// The start design \[deg\].
    pub fn start(&self) -> &[f64] {
        &self.start
    }

    /// The divisor of the objective (1 without `normalize_at`).
    pub fn objective_scale(&self) -> f64 {
        self.objective.1
    }

    /// The constraint bounds `c_j` (response units), in the order of `g`.
    pub fn bounds(&self) -> Vec<f64> {
        self.constraints.iter().map(|c| c.c).collect()
    }

    /// The constraints in the order of `g` (response, side, bound, scale).
    pub fn constraint_bounds(&self) -> &[Bound] {
        &self.constraints
    }

    /// The objective's response name and its SI unit (`J*s` for an
    /// integral of energies, `s` for a crossing time, ..): the response
    /// is `f ×` [`SceneProblem::objective_scale`] in that unit.
    pub fn objective_response(&self) -> (&str, &str) {
        let unit = self.units.first().map_or("-", |u| u.as_str());
        (self.objective.0.as_str(), unit)
    }

    /// The constraints' labels, in the order of `g`: the response's name
    /// (followed by `(lower bound)` for a lower bound).
    pub fn constraint_responses(&self) -> Vec<String> {
        self.constraints.iter().map(|c| c.label()).collect()
    }

    /// Simulate design `x` \[deg\] without sensitivities, with exactly the
    /// output columns `quantities` (names as in `[scene.outputs]`).
    pub fn simulate_outputs(&self, x: &[f64], quantities: &[String]) -> Result<Simulation> {
        let at = |e: Error| at_design(e, &self.vars, x);
        let laminates = self.laminates_at(x)?;
        let mut scene = self
            .plan
            .build_outputs(&laminates, quantities)
            .map_err(at)?;
        self.ties.apply_scene(&self.plan, &mut scene, x)?;
        Ok(simulate(&scene).map_err(at)?.1)
    }

    /// The panels' lay-ups at design `x`: ply angles in degrees, ply
    /// thicknesses in millimetres, the other plies as in the study
    /// (`Ties::laminates_at` in `scene_vars`).
    pub fn laminates_at(&self, x: &[f64]) -> Result<Vec<Laminate>> {
        self.ties.laminates_at(self.plan.panels(), x)
    }

    /// The sense of `[[scene.responses]]` entry `name` when it is a peak.
    fn peak_sense(&self, name: &str) -> Option<Sense> {
        peak_sense(self.plan.spec(), name)
    }

    /// Whether `[[scene.responses]]` entry `name` is a frequency (no
    /// integration needed).
    fn is_frequency(&self, name: &str) -> bool {
        let spec = self.plan.spec().responses.iter().find(|r| r.name == name);
        spec.is_some_and(|r| r.kind == ResponseKindName::Frequency)
    }

    /// Simulate at `x` and return the named responses, each at its
    /// critical point (0: the response itself; `k`: a peak's `k+1`-th
    /// critical time point, [`Bound::point`]), with gradients per degree of
    /// each variable when asked.
    fn raw(&self, x: &[f64], names: &[(String, usize)], gradients: bool) -> Result<Raw> {
        let design = || design_label(&self.vars, x);
        let at = |e: Error| at_design(e, &self.vars, x);
        let t0 = std::time::Instant::now();
        let lanes: &[String] = if gradients { &self.ties.lanes } else { &[] };
        let laminates = self.laminates_at(x)?;
        let (mut scene, build) = self
            .plan
            .build_profiled(&laminates, lanes, false)
            .map_err(at)?;
        self.ties.apply_scene(&self.plan, &mut scene, x)?;
        self.note_splits(&scene);
        // Frequencies alone need no integration.
        let (responses, stats) = if names.iter().all(|n| self.is_frequency(&n.0)) {
            (frequencies(&scene).map_err(at)?, Default::default())
        } else {
            let sim = simulate(&scene).map_err(at)?.1;
            (sim.responses, sim.stats)
        };
        let find = |name: &str| -> Result<&ResponseValue> {
            responses
                .iter()
                .find(|r| r.name == name)
                .ok_or_else(|| Error::input("scene.responses", name, "a response of the scene"))
        };
        let mut values = Vec::new();
        let mut units = Vec::new();
        let mut grads = Vec::new();
        for (name, point) in names {
            let r = find(name)?;
            let (value, gradient) = at_point(r, *point);
            units.push(r.unit.clone());
            if !value.is_finite() {
                return Err(Error::numerical(
                    format!("scene problem at [{}]", design()),
                    format!("response {name} = {value}"),
                ));
            }
            values.push(value);
            if gradients {
                let g: Vec<f64> = self
                    .ties
                    .lanes_of
                    .iter()
                    .zip(&self.ties.scale)
                    .map(|(l, s)| l.iter().map(|&k| gradient[k]).sum::<f64>() * s)
                    .collect();
                if g.iter().any(|v| !v.is_finite()) {
                    return Err(Error::numerical(
                        format!("scene problem at [{}]", design()),
                        format!("gradient of {name} = {g:?}"),
                    ));
                }
                grads.push(g);
            }
        }
        let profile = EvalProfile {
            build,
            lanes: lanes.len(),
            steps: stats.steps,
            rhs_calls: stats.rhs_calls,
            jvp_calls: stats.jvp_calls,
            integrate_seconds: stats.wall,
            outputs_seconds: stats.observer_wall,
            total_seconds: t0.elapsed().as_secs_f64(),
        };
        Ok(Raw {
            values,
            units,
            gradients: gradients.then_some(grads),
            profile,
        })
    }

    /// Count the bodies of `scene` whose mode count split a repeated
    /// eigenvalue ([`crate::mbs::RigidScreen::split`]).
    fn note_splits(&self, scene: &crate::scene::Scene) {
        let Ok(mut splits) = self.splits.lock() else {
            return;
        };
        for b in &scene.model.bodies {
            if let Some((asked, used)) = b.flex.as_ref().and_then(|f| f.basis.rigid.split) {
                *splits.entry((b.name.clone(), asked, used)).or_default() += 1;
            }
        }
    }

    /// [`Problem::evaluate`] with what the evaluation computed and where
    /// its time went.
    pub fn evaluate_profiled(
        &self,
        x: &[f64],
        gradients: bool,
    ) -> Result<(Evaluation, EvalProfile)> {
        let (e, _, profile) = self.evaluate_with(x, gradients, &[])?;
        Ok((e, profile))
    }

    /// [`Problem::evaluate`] and, from the same simulation, the raw values
    /// of the `[[scene.responses]]` named `extra` (response units) with
    /// their gradients per degree of each variable when asked.
    pub fn evaluate_with(
        &self,
        x: &[f64],
        gradients: bool,
        extra: &[String],
    ) -> Result<(Evaluation, ExtraResponses, EvalProfile)> {
        let at: Vec<(String, usize)> = extra.iter().map(|n| (n.clone(), 0)).collect();
        self.evaluate_at_points(x, gradients, &at)
    }

    /// [`SceneProblem::evaluate_with`] with each extra response at a
    /// critical point, `(name, point)` (0: the response itself; `k`: a
    /// peak's `k+1`-th critical time point, the peak where it has fewer).
    pub fn evaluate_at_points(
        &self,
        x: &[f64],
        gradients: bool,
        extra: &[(String, usize)],
    ) -> Result<(Evaluation, ExtraResponses, EvalProfile)> {
        if x.len() != self.vars.len() || x.iter().any(|v| !v.is_finite()) {
            return Err(Error::input(
                "scene_problem.x",
                format!("{x:?}"),
                format!("{} finite angles [deg]", self.vars.len()),
            ));
        }
        let mut names = vec![(self.objective.0.clone(), 0)];
        names.extend(
            self.constraints
                .iter()
                .map(|c| (c.response.clone(), c.point)),
        );
        let own = names.len();
        names.extend(extra.iter().cloned());
        let raw = self.raw(x, &names, gradients)?;
        let extra = ExtraResponses {
            values: raw.values[own..].to_vec(),
            units: raw.units[own..].to_vec(),
            gradients: (raw.gradients.as_ref()).map(|g| g[own..].to_vec()),
        };
        let s = self.objective.1;
        let f = raw.values[0] / s;
        let g = self
            .constraints
            .iter()
            .zip(&raw.values[1..])
            .map(|(c, v)| c.g(*v))
            .collect();
        let (grad_f, grad_g) = match raw.gradients {
            None => (None, None),
            Some(gr) => {
                let gf = gr[0].iter().map(|v| v / s).collect();
                let gg = self
                    .constraints
                    .iter()
                    .zip(&gr[1..])
                    .map(|(c, row)| row.iter().map(|v| c.dg(*v)).collect())
                    .collect();
                (Some(gf), Some(gg))
            }
        };
        Ok((
            Evaluation {
                f,
                g,
                grad_f,
                grad_g,
            },
            extra,
            raw.profile,
        ))
    }
}

/// The objective's and constraints' responses exist, their bounds are
/// valid, and the start and normalization designs are within the bounds.
fn check_objective_and_constraints(
    study: &Study,
    spec: &SceneProblemSpec,
    plan: &ScenePlan,
    vars: &[Variable],
) -> Result<()> {
    let names: Vec<&str> = plan
        .spec()
        .responses
        .iter()
        .map(|r| r.name.as_str())
        .collect();
    let check_response = |key: String, r: &str| {
        if names.contains(&r) {
            Ok(())
        } else {
            Err(problem_error(
                study,
                key,
                format!("\"{r}\""),
                format!("a [[scene.responses]] name ({})", names.join(", ")),
            ))
        }
    };
    check_response("objective.response".into(), &spec.objective.response)?;
    let check_design = |key: &str, x: &[f64]| -> Result<()> {
        if x.len() != vars.len()
            || x.iter()
                .zip(vars)
                .any(|(&x, v)| !x.is_finite() || (v.period.is_none() && v.wrap(x) != x))
        {
            return Err(problem_error(
                study,
                key.into(),
                format!("{x:?}"),
                format!("{} finite angles [deg] within the bounds", vars.len()),
            ));
        }
        Ok(())
    };
    check_design("start", &spec.start)?;
    if let Some(r) = &spec.objective.normalize_at {
        check_design("objective.normalize_at", r)?;
    }
    for (j, c) in spec.constraints.iter().enumerate() {
        check_response(format!("constraints[{j}].response"), &c.response)?;
        scene_bounds::check(study, j, c, peak_sense(plan.spec(), &c.response))?;
    }
    Ok(())
}

/// The value and gradient of response `r` at its critical point `point`
/// ([`Bound::point`]): a peak's `point+1`-th critical time point, the peak
/// itself where it has fewer; the response itself for other kinds.
fn at_point(r: &ResponseValue, point: usize) -> (f64, &[f64]) {
    match r.critical.get(point) {
        Some((_, v, g)) if point > 0 => (*v, g),
        _ => (r.value, &r.gradient),
    }
}

/// The sense of response `name` of `scene` when it is a `peak`.
pub(crate) fn peak_sense(scene: &crate::scene::SceneSpec, name: &str) -> Option<Sense> {
    let r = scene.responses.iter().find(|r| r.name == name)?;
    (r.kind == ResponseKindName::Peak).then(|| r.sense.unwrap_or_default())
}

/// `theta1_deg = 55, theta2_deg = -55`.
fn design_label(vars: &[Variable], x: &[f64]) -> String {
    let parts: Vec<String> = vars
        .iter()
        .zip(x)
        .map(|(v, x)| format!("{} = {x}", v.name))
        .collect();
    parts.join(", ")
}

/// A numerical failure of the scene, with the design in its place; other
/// errors unchanged.
fn at_design(e: Error, vars: &[Variable], x: &[f64]) -> Error {
    e.at_place(&format!("scene problem at [{}]", design_label(vars, x)))
}

impl Problem for SceneProblem {
    fn variables(&self) -> &[Variable] {
        &self.vars
    }
    fn n_constraints(&self) -> usize {
        self.constraints.len()
    }
    /// `f = R₀/s`, `g_j = R_j/c_j − 1`, gradients per degree.
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        Ok(self.evaluate_profiled(x, gradients)?.0)
    }
    fn name(&self) -> &str {
        &self.study
    }
    /// One line per body and mode count whose count split a repeated
    /// eigenvalue at some evaluated lay-up.
    fn notes(&self) -> Vec<String> {
        let Ok(splits) = self.splits.lock() else {
            return Vec::new();
        };
        splits
            .iter()
            .map(|((body, asked, used), n)| {
                format!(
                    "{body}: {asked} elastic modes split a repeated eigenvalue at the lay-up of \
                     {n} evaluation(s); {used} modes were used there (the cluster left out \
                     whole)"
                )
            })
            .collect()
    }
    fn tolerance(&self) -> Option<f64> {
        Some(self.tolerances().0)
    }
    /// rtol as given, atol at the study's own ratio atol/rtol (a fixed
    /// atol floors the accuracy: on the SAR scene atol 1e-8 keeps the
    /// noise of f near 4e-7 of f at any rtol, `[noise]`).
    fn set_tolerance(&mut self, rtol: f64) -> bool {
        let (r0, a0) = self.study_tolerances;
        let atol = if rtol == r0 { a0 } else { a0 * (rtol / r0) };
        self.set_tolerances(rtol, atol);
        true
    }
    /// Ply angles in degrees (`theta1_deg` is `θ1 [deg]`), ply
    /// thicknesses in millimetres, scene parameters in SI units
    /// (`Ties::variable_label` in `scene_vars`).
    fn variable_label(&self, i: usize) -> String {
        self.ties.variable_label(i, &self.vars[i].name)
    }
    fn objective_label(&self) -> String {
        let (response, divisor) = &self.objective;
        if *divisor == 1.0 {
            format!("f = {response} [SI unit of the response]")
        } else {
            format!("f = {response} / {divisor:.4e} [-]")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numerical_failures_carry_the_design() {
        let vars = vec![
            Variable::periodic("theta1_deg", -90.0, 180.0).unwrap(),
            Variable::periodic("theta2_deg", -90.0, 180.0).unwrap(),
        ];
        let e = at_design(
            Error::numerical_at("integrate: bdf", 0.026, "step size underflow"),
            &vars,
            &[55.0, -55.0],
        );
        let s = e.to_string();
        assert!(matches!(e, Error::Numerical { time: Some(t), .. } if t == 0.026));
        assert!(
            s.contains("scene problem at [theta1_deg = 55, theta2_deg = -55]: integrate: bdf")
                && s.contains("step size underflow"),
            "{s}"
        );
        let e = at_design(Error::input("k", 1, "2"), &vars, &[0.0, 0.0]);
        assert!(matches!(e, Error::Input { .. }));
    }
}
