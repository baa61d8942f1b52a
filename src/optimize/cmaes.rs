//! CMA-ES (covariance matrix adaptation evolution strategy) with IPOP or
//! BIPOP restarts, as an argmin [`Solver`]: the global comparison method of
//! the exploration (docs/numerics.md, "Responses and optimization").
//!
//! Method: N. Hansen, *The CMA Evolution Strategy: A Tutorial*
//! (arXiv:1604.00772, 2016), with the default parameters of its Table 1
//! (weights `ln((λ+1)/2) − ln i` on the best μ = ⌊λ/2⌋, cumulation `c_σ`,
//! `c_c`, rank-one `c_1`, rank-μ `c_μ`, damping `d_σ`) and the `h_σ` stall
//! of the evolution path. Option `active` (Jastrebski & Arnold, CEC 2006;
//! Hansen 2016 eqs. 46–47, 53): the λ − μ worst samples get the negative
//! weights `ln((λ+1)/2) − ln i`, scaled to
//! `min(1 + c₁/c_μ, 1 + 2μ⁻_eff/(μ_eff + 2), (1 − c₁ − c_μ)/(n c_μ)) / Σ|w⁻|`,
//! each times `n / |C^{−1/2} y_i|²`; C decays by `1 − c₁ − c_μ Σ_all w`.
//! Restarts ([`Restarts`]) start from a uniformly random mean in the box:
//! - IPOP (default; A. Auger, N. Hansen, "A restart CMA evolution strategy
//!   with increasing population size", CEC 2005): restart `i` has the
//!   population `λ_i = round(λ_def · F^i)` (F = `popsize_factor` = 2) and
//!   the initial step σ0.
//! - BIPOP (N. Hansen, "Benchmarking a BI-population CMA-ES on the
//!   BBOB-2009 function testbed", GECCO 2009 companion, BBOB workshop): after
//!   the first run (λ_def, σ0) two interlaced regimes share the budget. The
//!   large regime is IPOP: its i-th restart has
//!   `λ_large = round(λ_def · F^i)` and σ0. A small-regime run has
//!   `λ_s = ⌊λ_def · (½ λ_large / λ_def)^(U₁²)⌋` and
//!   `σ_s = σ0 · 10^(−2 U₂)`, with `U₁, U₂` uniform on [0, 1) and
//!   `λ_large = λ_def · F^i` the population of the *next* large restart
//!   (i large runs so far, the first run included), so that with F = 2
//!   `λ_def <= λ_s <= λ_large / 2` (the last large population) and
//!   `σ0 / 100 < σ_s <= σ0`. Before each restart the regime that has spent
//!   fewer evaluations so far runs: small while `E_small < E_large`, large
//!   otherwise; the first run is charged to the large regime (it is IPOP's
//!   run 0). `max_restarts` counts the large restarts only; the search ends
//!   when the large regime is due and has used them all (or at the budget).
//!   Charging the first run to the large regime makes the first restart a
//!   small one with `λ_s = λ_def`. Units: λ and the evaluation counts are
//!   numbers of designs, σ is a fraction of each variable's range.
//!
//! Search space: range-scaled `y = (x − lower)/range ∈ [0, 1]ⁿ`, so σ is a
//! fraction of each variable's range (σ0 = 0.3 by default) and every
//! generation's σ is what [`IterRecord::step`] reports. A periodic variable
//! is simply wrapped when a sample is evaluated (the distribution lives on
//! the line, the problem on the circle). A non-periodic sample outside its
//! box is evaluated at its projection onto the box, and the distance to the
//! box counts as a violation (below).
//!
//! Constraints by Deb's feasibility rules (K. Deb, *Comput. Methods Appl.
//! Mech. Engrg.* 186 (2000) 311): the violation `v = Σ_j max(0, g_j) + Σ_i
//! dist(y_i, [0, 1])` orders samples; any feasible sample (v = 0) beats any
//! infeasible one, feasible samples compare by f, infeasible ones by v.
//! No penalty constant is involved, and the reported best is the best
//! feasible design seen (the least violating one if none was feasible).
//!
//! Parallelism: each generation is one batch call; the batch evaluator is
//! the only place that uses rayon (`par_iter` then collect in index order),
//! and everything random happens before it, so a seed gives the same run
//! bit for bit on any number of threads.

use super::driver::{self, OptState, Recorded};
use super::{Counted, Evaluation, GlobalOutcome, IterRecord, Observer, Problem, Termination};
use crate::error::{Error, Result};
use argmin::core::{
    Problem as ArgminProblem, Solver, State, TerminationReason, TerminationStatus, KV,
};
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// CMA-ES parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct CmaesOptions {
    /// Seed of the ChaCha8 generator: the same seed gives the same run.
    pub seed: u64,
    /// Evaluation budget over all restarts; a generation that would exceed
    /// it is not started.
    pub max_evaluations: usize,
    /// Initial step size as a fraction of each variable's range: 0.3
    /// (Hansen recommends about a quarter to a third of the search interval).
    pub sigma0: f64,
    /// Population of the first run; `None`: `4 + ⌊3 ln n⌋` (Hansen, Table 1).
    pub popsize: Option<usize>,
    /// Restart schedule: IPOP (default) or BIPOP (module doc).
    pub restarts: Restarts,
    /// Restarts with increased population after the first run: 9. Under
    /// BIPOP the large-regime restarts; small-regime runs do not count.
    pub max_restarts: usize,
    /// Population growth factor per restart: 2 (IPOP).
    pub popsize_factor: f64,
    /// Mean of the first run; `None`: uniformly random in the box. Restarts
    /// always start from a uniformly random mean.
    pub x0: Option<Vec<f64>>,
    /// Restart when the best f of the last `10 + ⌈30 n/λ⌉` generations and
    /// all f of the current one lie within this range (TolFun): 1e-12.
    pub tol_fun: f64,
    /// Restart when `σ · max(√C_ii, |p_c|)` falls below this (TolX, in
    /// range units): 1e-12.
    pub tol_x: f64,
    /// Stop when a feasible design reaches this objective (`None`: never).
    pub target: Option<f64>,
    /// A constraint counts as met when `g_j <= feasibility_tolerance`: the
    /// violation of Deb's rules is `Σ_j max(0, g_j − tol)` (default 0;
    /// the exploration passes the multistart's tolerance so that both
    /// methods search the same feasible set).
    pub feasibility_tolerance: f64,
    /// Active covariance update (module doc): the worst `λ − μ` samples
    /// enter the rank-μ update with negative weights. Default false.
    pub active: bool,
    /// Lower bounds of the standard deviation `σ √C_ii` of each coordinate,
    /// in range units (empty: none, the default): after each update σ is
    /// raised to `max_i min_std_i / √C_ii` when below it. The integer
    /// handling of discrete coordinates (`explore::discrete`, after
    /// N. Hansen, "A CMA-ES for mixed-integer nonlinear optimization",
    /// INRIA research report RR-7751, 2011): a coordinate whose spread has
    /// shrunk below its lattice step would freeze on one set member.
    pub min_std: Vec<f64>,
}

/// Restart schedule of [`Cmaes`] (module doc for the formulas); written
/// `ipop` or `bipop` in study files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Restarts {
    /// Every restart multiplies the population by `popsize_factor`.
    #[default]
    Ipop,
    /// Large (IPOP) and small-population restarts on equal budgets.
    Bipop,
}

impl Restarts {
    /// Every schedule.
    pub const ALL: [Restarts; 2] = [Restarts::Ipop, Restarts::Bipop];

    /// Names as written in study files, for messages (the serde names;
    /// a test checks them against [`Restarts::ALL`]).
    pub const NAMES: &'static str = "ipop, bipop";

    /// The schedule written `name`, by its serde name (for values that
    /// are not deserialized as a whole, e.g. one of a list); the error
    /// names the key `restarts` and lists [`Restarts::NAMES`].
    pub fn parse(name: &str) -> Result<Restarts> {
        use serde::de::{value, Deserialize, IntoDeserializer};
        let de: value::StrDeserializer<'_, value::Error> = name.into_deserializer();
        Restarts::deserialize(de).map_err(|_| {
            Error::input(
                "restarts",
                format!("\"{name}\""),
                format!("one of {}", Restarts::NAMES),
            )
        })
    }

    /// Name as written in study files.
    pub fn name(&self) -> &'static str {
        match self {
            Restarts::Ipop => "ipop",
            Restarts::Bipop => "bipop",
        }
    }

    /// The solver's name: `IPOP-CMA-ES` or `BIPOP-CMA-ES`.
    pub fn solver_name(&self) -> &'static str {
        match self {
            Restarts::Ipop => "IPOP-CMA-ES",
            Restarts::Bipop => "BIPOP-CMA-ES",
        }
    }
}

/// The regime a run belongs to. Under IPOP every run is large.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regime {
    /// The first run and the IPOP restarts: `λ_def · F^i`, σ0.
    Large,
    /// BIPOP's small-population restarts: `λ_s`, `σ_s` (module doc).
    Small,
}

impl Regime {
    /// `large` or `small`, as reports write it.
    pub fn name(&self) -> &'static str {
        match self {
            Regime::Large => "large",
            Regime::Small => "small",
        }
    }
}

/// One CMA-ES run between restarts, in the order the runs were made.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRecord {
    /// Which regime scheduled the run.
    pub regime: Regime,
    /// Population size λ.
    pub lambda: usize,
    /// Initial step size, as a fraction of each variable's range.
    pub sigma0: f64,
    /// Function evaluations the run spent (λ per generation); 0 for a
    /// restart the remaining budget could not afford a generation of.
    pub evaluations: usize,
    /// Generations the run made.
    pub generations: usize,
}

/// Evaluations spent so far by the (large, small) regimes.
pub fn regime_evaluations(runs: &[RunRecord]) -> (usize, usize) {
    runs.iter().fold((0, 0), |(l, s), r| match r.regime {
        Regime::Large => (l + r.evaluations, s),
        Regime::Small => (l, s + r.evaluations),
    })
}

/// BIPOP's small-regime run (module doc): `λ_s = ⌊λ_def (½ λ_large /
/// λ_def)^(u₁²)⌋` (at least 2) and `σ_s = σ0 · 10^(−2 u₂)`, where
/// `λ_large / λ_def = F^i` after `large_runs = i` large runs; `u₁, u₂` in
/// [0, 1].
pub fn small_run(
    lambda_def: usize,
    factor: f64,
    large_runs: usize,
    sigma0: f64,
    u1: f64,
    u2: f64,
) -> (usize, f64) {
    let ratio = 0.5 * factor.powi(large_runs as i32);
    let lambda = ((lambda_def as f64) * ratio.powf(u1 * u1)).floor() as usize;
    (lambda.max(2), sigma0 * 10f64.powf(-2.0 * u2))
}

impl Default for CmaesOptions {
    fn default() -> Self {
        CmaesOptions {
            seed: 1,
            max_evaluations: 10_000,
            sigma0: 0.3,
            popsize: None,
            restarts: Restarts::Ipop,
            max_restarts: 9,
            popsize_factor: 2.0,
            x0: None,
            tol_fun: 1e-12,
            tol_x: 1e-12,
            target: None,
            feasibility_tolerance: 0.0,
            active: false,
            min_std: Vec::new(),
        }
    }
}

impl CmaesOptions {
    fn validate(&self, n: usize) -> Result<()> {
        let bad = |k: &str, v: String, e: &str| Err(Error::input(format!("cmaes.{k}"), v, e));
        if !(self.sigma0 > 0.0 && self.sigma0.is_finite()) {
            return bad("sigma0", self.sigma0.to_string(), "a finite value > 0");
        }
        if !(self.popsize_factor >= 1.0 && self.popsize_factor.is_finite()) {
            return bad(
                "popsize_factor",
                self.popsize_factor.to_string(),
                "a factor >= 1",
            );
        }
        if let Some(p) = self.popsize {
            if p < 2 {
                return bad("popsize", p.to_string(), "at least 2");
            }
        }
        if self.max_evaluations == 0 {
            return bad("max_evaluations", "0".into(), "at least one evaluation");
        }
        for (k, v) in [
            ("tol_fun", self.tol_fun),
            ("tol_x", self.tol_x),
            ("feasibility_tolerance", self.feasibility_tolerance),
        ] {
            if !(v >= 0.0 && v.is_finite()) {
                return bad(k, v.to_string(), "a finite value >= 0");
            }
        }
        if !(self.min_std.is_empty()
            || (self.min_std.len() == n && self.min_std.iter().all(|v| v.is_finite() && *v >= 0.0)))
        {
            return bad(
                "min_std",
                format!("{:?}", self.min_std),
                &format!("none, or {n} finite values >= 0"),
            );
        }
        if let Some(x0) = &self.x0 {
            if x0.len() != n || x0.iter().any(|v| !v.is_finite()) {
                return bad("x0", format!("{x0:?}"), &format!("{n} finite values"));
            }
        }
        if n == 0 {
            return bad("variables", "0".into(), "at least one design variable");
        }
        Ok(())
    }
}

/// Evaluate a batch of designs, in parallel, results in input order. The
/// only parallel code of the solver.
pub fn evaluate_batch(problem: &dyn Problem, xs: &[Vec<f64>]) -> Result<Vec<Evaluation>> {
    xs.par_iter().map(|x| problem.evaluate(x, false)).collect()
}

/// A ranked sample.
#[derive(Debug, Clone)]
struct Sample {
    /// Scaled, unrepaired point (what the distribution produced).
    y: Vec<f64>,
    /// The design evaluated (wrapped / clamped).
    x: Vec<f64>,
    f: f64,
    g: Vec<f64>,
    violation: f64,
}

/// Deb's order: feasible by f before infeasible by violation.
fn better(a: &Sample, b: &Sample) -> std::cmp::Ordering {
    match (a.violation <= 0.0, b.violation <= 0.0) {
        (true, true) => a.f.total_cmp(&b.f),
        (true, false) => std::cmp::Ordering::Less,
        (false, true) => std::cmp::Ordering::Greater,
        (false, false) => a.violation.total_cmp(&b.violation),
    }
}

/// Strategy parameters for one population size (Hansen 2016, Table 1).
struct Params {
    lambda: usize,
    weights: Vec<f64>,
    /// Negative weights of ranks μ+1..λ (active update; empty otherwise).
    negative: Vec<f64>,
    mueff: f64,
    cs: f64,
    ds: f64,
    cc: f64,
    c1: f64,
    cmu: f64,
    chi_n: f64,
}

impl Params {
    fn new(n: usize, lambda: usize, active: bool) -> Params {
        let nf = n as f64;
        let mu = lambda / 2;
        let raw: Vec<f64> = (1..=mu)
            .map(|i| ((lambda as f64 + 1.0) / 2.0).ln() - (i as f64).ln())
            .collect();
        let sum: f64 = raw.iter().sum();
        let weights: Vec<f64> = raw.iter().map(|w| w / sum).collect();
        let mueff = 1.0 / weights.iter().map(|w| w * w).sum::<f64>();
        let cs = (mueff + 2.0) / (nf + mueff + 5.0);
        let ds = 1.0 + 2.0 * (((mueff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + cs;
        let cc = (4.0 + mueff / nf) / (nf + 4.0 + 2.0 * mueff / nf);
        let c1 = 2.0 / ((nf + 1.3).powi(2) + mueff);
        let cmu = (1.0 - c1).min(2.0 * (mueff - 2.0 + 1.0 / mueff) / ((nf + 2.0).powi(2) + mueff));
        let chi_n = nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf));
        // Hansen (2016) eq. (53): raw `ln((λ+1)/2) − ln i` for i > μ,
        // scaled to min(α_μ⁻, α_μeff⁻, α_posdef⁻) / Σ|w⁻|.
        let raw_neg: Vec<f64> = if active {
            (mu + 1..=lambda)
                .map(|i| ((lambda as f64 + 1.0) / 2.0).ln() - (i as f64).ln())
                .collect()
        } else {
            Vec::new()
        };
        let sum_neg: f64 = raw_neg.iter().map(|w| w.abs()).sum();
        let negative = if sum_neg > 0.0 {
            let sq: f64 = raw_neg.iter().map(|w| w * w).sum();
            let mueff_neg = sum_neg * sum_neg / sq;
            let scale = (1.0 + c1 / cmu)
                .min(1.0 + 2.0 * mueff_neg / (mueff + 2.0))
                .min((1.0 - c1 - cmu) / (nf * cmu));
            raw_neg.iter().map(|w| w * scale / sum_neg).collect()
        } else {
            Vec::new()
        };
        Params {
            lambda,
            weights,
            negative,
            mueff,
            cs,
            ds,
            cc,
            c1,
            cmu,
            chi_n,
        }
    }
}

/// The state of one CMA-ES run (between restarts).
struct Run {
    p: Params,
    mean: DVector<f64>,
    sigma: f64,
    cov: DMatrix<f64>,
    /// Eigenvectors B and axis lengths D of C = B D² Bᵀ.
    b: DMatrix<f64>,
    d: DVector<f64>,
    ps: DVector<f64>,
    pc: DVector<f64>,
    generation: usize,
    best_history: Vec<f64>,
}

impl Run {
    fn new(n: usize, lambda: usize, mean: Vec<f64>, sigma: f64, active: bool) -> Run {
        Run {
            p: Params::new(n, lambda, active),
            mean: DVector::from_vec(mean),
            sigma,
            cov: DMatrix::identity(n, n),
            b: DMatrix::identity(n, n),
            d: DVector::from_element(n, 1.0),
            ps: DVector::zeros(n),
            pc: DVector::zeros(n),
            generation: 0,
            best_history: Vec::new(),
        }
    }
}

/// CMA-ES engine; one `next_iter` is one generation.
pub struct Cmaes {
    options: CmaesOptions,
    rng: ChaCha8Rng,
    lower: Vec<f64>,
    range: Vec<f64>,
    periodic: Vec<bool>,
    run: Option<Run>,
    lambda0: usize,
    restarts: usize,
    /// One record per run started, the current one last.
    runs: Vec<RunRecord>,
    /// The regime of the next run to start.
    next_regime: Regime,
    generations: usize,
    best: Option<Sample>,
    termination: Option<Termination>,
    record: Option<IterRecord>,
}

/// One standard normal number by the Box–Muller transform.
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// The default population of the first run on `n` variables,
/// `4 + ⌊3 ln n⌋` (Hansen, Table 1): the fewest evaluations of one
/// generation.
pub fn default_population(n: usize) -> usize {
    4 + (3.0 * (n.max(1) as f64).ln()).floor() as usize
}

impl Cmaes {
    /// A solver for `problem` (validates the options).
    pub fn new(problem: &dyn Problem, options: CmaesOptions) -> Result<Cmaes> {
        let vars = problem.variables();
        let n = vars.len();
        options.validate(n)?;
        let lambda0 = options.popsize.unwrap_or(default_population(n));
        Ok(Cmaes {
            rng: ChaCha8Rng::seed_from_u64(options.seed),
            lower: vars.iter().map(|v| v.lower).collect(),
            range: vars.iter().map(|v| v.upper - v.lower).collect(),
            periodic: vars.iter().map(|v| v.period.is_some()).collect(),
            options,
            run: None,
            lambda0,
            restarts: 0,
            runs: Vec::new(),
            next_regime: Regime::Large,
            generations: 0,
            best: None,
            termination: None,
            record: None,
        })
    }

    fn n(&self) -> usize {
        self.lower.len()
    }

    /// Start the next run in `next_regime`: population and step size from
    /// the schedule (small regime: `u₁`, `u₂` drawn first), then the mean
    /// (`x0` for the first run if given, else uniform in the box).
    fn start_run(&mut self) {
        let n = self.n();
        let large_runs = self
            .runs
            .iter()
            .filter(|r| r.regime == Regime::Large)
            .count();
        let (lambda, sigma0) = match self.next_regime {
            Regime::Large => {
                let lambda = ((self.lambda0 as f64)
                    * self.options.popsize_factor.powi(large_runs as i32))
                .round() as usize;
                (lambda.max(2), self.options.sigma0)
            }
            Regime::Small => {
                let u1: f64 = self.rng.random();
                let u2: f64 = self.rng.random();
                let o = &self.options;
                small_run(self.lambda0, o.popsize_factor, large_runs, o.sigma0, u1, u2)
            }
        };
        let mean: Vec<f64> = match (&self.options.x0, self.runs.is_empty()) {
            (Some(x0), true) => (0..n)
                .map(|i| (x0[i] - self.lower[i]) / self.range[i])
                .collect(),
            _ => (0..n).map(|_| self.rng.random::<f64>()).collect(),
        };
        self.runs.push(RunRecord {
            regime: self.next_regime,
            lambda,
            sigma0,
            evaluations: 0,
            generations: 0,
        });
        self.run = Some(Run::new(n, lambda, mean, sigma0, self.options.active));
    }

    /// The regime of the run after the current one, or `None` when the
    /// restarts are used up. IPOP: large while `restarts < max_restarts`.
    /// BIPOP: small while the small regime has spent fewer evaluations than
    /// the large one, else large while the large restarts (runs after the
    /// first) are fewer than `max_restarts`.
    fn following_regime(&self) -> Option<Regime> {
        let large_restarts = self
            .runs
            .iter()
            .filter(|r| r.regime == Regime::Large)
            .count()
            .saturating_sub(1);
        let large = (large_restarts < self.options.max_restarts).then_some(Regime::Large);
        match self.options.restarts {
            Restarts::Ipop => large,
            Restarts::Bipop => {
                let (spent_large, spent_small) = regime_evaluations(&self.runs);
                if spent_small < spent_large {
                    Some(Regime::Small)
                } else {
                    large
                }
            }
        }
    }

    /// Map a scaled sample to the design evaluated and its box violation.
    fn to_design(&self, y: &[f64]) -> (Vec<f64>, f64) {
        let mut viol = 0.0;
        let x = y
            .iter()
            .enumerate()
            .map(|(i, &yi)| {
                if self.periodic[i] {
                    let p = self.range[i];
                    let v = self.lower[i] + (yi * p).rem_euclid(p);
                    if v >= self.lower[i] + p {
                        self.lower[i]
                    } else {
                        v
                    }
                } else {
                    let c = yi.clamp(0.0, 1.0);
                    viol += (yi - c).abs();
                    self.lower[i] + c * self.range[i]
                }
            })
            .collect();
        (x, viol)
    }

    /// One generation: sample, evaluate as a batch, rank, update; then the
    /// target test and, when the run stops, the restart (or the end).
    fn generation(&mut self, problem: &mut ArgminProblem<Counted<'_>>) -> Result<()> {
        if self.run.is_none() {
            self.start_run();
        }
        let lambda = self.run.as_ref().map(|r| r.p.lambda).unwrap_or(2);
        let used = problem
            .problem
            .as_ref()
            .map(|c| c.function_calls())
            .unwrap_or(0);
        if used + lambda > self.options.max_evaluations {
            self.termination = Some(Termination::MaxEvaluations);
            return Ok(());
        }
        let samples = self.evaluate_population(problem, lambda)?;
        let mut order: Vec<usize> = (0..lambda).collect();
        order.sort_by(|&a, &b| better(&samples[a], &samples[b]).then(a.cmp(&b)));
        let top = &samples[order[0]];
        if self.best.as_ref().is_none_or(|b| better(top, b).is_lt()) {
            self.best = Some(top.clone());
        }
        self.update(&samples, &order);
        self.generations += 1;
        if let Some(r) = self.runs.last_mut() {
            r.evaluations += lambda;
            r.generations += 1;
        }
        let best = self.best.as_ref().expect("a best sample");
        let (fc, gc) = problem
            .problem
            .as_ref()
            .map(|c| (c.function_calls(), c.gradient_calls()))
            .unwrap_or((0, 0));
        let sigma = self.run.as_ref().map(|r| r.sigma).unwrap_or(0.0);
        self.record = Some(IterRecord {
            iteration: self.generations - 1,
            x: best.x.clone(),
            f: best.f,
            g: best.g.clone(),
            max_g: best.g.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            ct: None,
            step: sigma,
            function_calls: fc,
            gradient_calls: gc,
        });
        if let Some(t) = self.options.target {
            if best.violation <= 0.0 && best.f <= t {
                self.termination = Some(Termination::TargetReached);
                return Ok(());
            }
        }
        if let Some(stop) = self.run_should_stop(&samples) {
            match self.following_regime() {
                None => self.termination = Some(stop),
                Some(regime) => {
                    self.next_regime = regime;
                    self.restarts += 1;
                    self.run = None;
                }
            }
        }
        Ok(())
    }

    /// Sample λ points of the current run (sequential, seeded), evaluate
    /// them as one batch and compute their violations.
    fn evaluate_population(
        &mut self,
        problem: &mut ArgminProblem<Counted<'_>>,
        lambda: usize,
    ) -> Result<Vec<Sample>> {
        let n = self.n();
        let mut ys = Vec::with_capacity(lambda);
        {
            let run = self.run.as_ref().expect("run started");
            for _ in 0..lambda {
                let z = DVector::from_fn(n, |_, _| normal(&mut self.rng));
                ys.push(&run.mean + run.sigma * (&run.b * run.d.component_mul(&z)));
            }
        }
        let designs: Vec<(Vec<f64>, f64)> =
            ys.iter().map(|y| self.to_design(y.as_slice())).collect();
        let xs: Vec<Vec<f64>> = designs.iter().map(|d| d.0.clone()).collect();
        let evals = problem
            .bulk_problem("cost_count", lambda, |c| {
                evaluate_batch(c, &xs).map_err(argmin::core::Error::from)
            })
            .map_err(driver::from_argmin)?;
        let m = driver::constraint_count(problem);
        let mut samples: Vec<Sample> = Vec::with_capacity(lambda);
        for (k, ev) in evals.into_iter().enumerate() {
            driver::check_evaluation(&ev, &xs[k], m, false, "optimize::cmaes")?;
            let tol = self.options.feasibility_tolerance;
            let violation = designs[k].1 + ev.g.iter().map(|g| (g - tol).max(0.0)).sum::<f64>();
            samples.push(Sample {
                y: ys[k].as_slice().to_vec(),
                x: xs[k].clone(),
                f: ev.f,
                g: ev.g,
                violation,
            });
        }
        Ok(samples)
    }

    /// Hansen's update of mean, paths, covariance and step size.
    fn update(&mut self, samples: &[Sample], order: &[usize]) {
        let n = self.n();
        let run = self.run.as_mut().expect("run started");
        let p = &run.p;
        let old_mean = run.mean.clone();
        let steps: Vec<DVector<f64>> = order
            .iter()
            .take(p.weights.len())
            .map(|&k| (DVector::from_column_slice(&samples[k].y) - &old_mean) / run.sigma)
            .collect();
        let mut yw = DVector::zeros(n);
        for (w, s) in p.weights.iter().zip(&steps) {
            yw += *w * s;
        }
        run.mean = &old_mean + run.sigma * &yw;
        // C^{-1/2} y_w = B D⁻¹ Bᵀ y_w
        let bt_yw = run.b.transpose() * &yw;
        let inv_sqrt = &run.b * bt_yw.component_div(&run.d);
        run.ps = (1.0 - p.cs) * &run.ps + (p.cs * (2.0 - p.cs) * p.mueff).sqrt() * inv_sqrt;
        let gen = (run.generation + 1) as f64;
        let ps_norm = run.ps.norm();
        let hsig = ps_norm / (1.0 - (1.0 - p.cs).powf(2.0 * gen)).sqrt()
            < (1.4 + 2.0 / (n as f64 + 1.0)) * p.chi_n;
        let h = if hsig { 1.0 } else { 0.0 };
        run.pc = (1.0 - p.cc) * &run.pc + h * (p.cc * (2.0 - p.cc) * p.mueff).sqrt() * &yw;
        let mut rank_mu = DMatrix::zeros(n, n);
        for (w, s) in p.weights.iter().zip(&steps) {
            rank_mu += *w * (s * s.transpose());
        }
        // Active update: ranks μ+1..λ with `w_i n / |C^{-1/2} y_i|²`
        // (Hansen 2016, eqs. 46–47), and Σw over all λ weights in the decay.
        let worst = order.iter().skip(p.weights.len()).take(p.negative.len());
        for (w, &k) in p.negative.iter().zip(worst) {
            let s = (DVector::from_column_slice(&samples[k].y) - &old_mean) / run.sigma;
            let white = (run.b.transpose() * &s)
                .component_div(&run.d)
                .norm_squared();
            rank_mu += (*w * n as f64 / white.max(1e-300)) * (&s * s.transpose());
        }
        let wsum = 1.0 + p.negative.iter().sum::<f64>();
        let decay = 1.0 - p.c1 - p.cmu * wsum + (1.0 - h) * p.c1 * p.cc * (2.0 - p.cc);
        run.cov = decay * &run.cov + p.c1 * (&run.pc * run.pc.transpose()) + p.cmu * rank_mu;
        run.cov = 0.5 * (&run.cov + run.cov.transpose());
        run.sigma *= ((p.cs / p.ds) * (ps_norm / p.chi_n - 1.0)).exp();
        for (i, &floor) in self.options.min_std.iter().enumerate() {
            let sd = run.cov[(i, i)].max(1e-300).sqrt();
            run.sigma = run.sigma.max(floor / sd);
        }
        let eig = run.cov.clone().symmetric_eigen();
        run.b = eig.eigenvectors;
        run.d = eig.eigenvalues.map(|l| l.max(1e-300).sqrt());
        run.generation += 1;
        let best = &samples[order[0]];
        run.best_history.push(if best.violation <= 0.0 {
            best.f
        } else {
            f64::INFINITY
        });
    }

    /// Restart criteria of one run (Hansen 2016, App. B.3): TolFun, TolX,
    /// condition of C above 1e14, no effect of an axis or a coordinate,
    /// generation limit `100 + 150 (n+3)²/√λ`.
    fn run_should_stop(&self, samples: &[Sample]) -> Option<Termination> {
        let run = self.run.as_ref()?;
        let n = self.n();
        let lambda = run.p.lambda;
        let hist_len = 10 + (30.0 * n as f64 / lambda as f64).ceil() as usize;
        let all_feasible = samples.iter().all(|s| s.violation <= 0.0);
        if all_feasible && run.best_history.len() >= hist_len {
            let recent = &run.best_history[run.best_history.len() - hist_len..];
            let (lo, hi) = recent
                .iter()
                .chain(samples.iter().map(|s| &s.f))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                });
            if hi - lo <= self.options.tol_fun {
                return Some(Termination::Stagnation);
            }
        }
        let max_sd = (0..n).map(|i| run.cov[(i, i)].sqrt()).fold(0.0, f64::max);
        if run.sigma * max_sd.max(run.pc.amax()) < self.options.tol_x {
            return Some(Termination::Stagnation);
        }
        let dmax = run.d.max();
        let dmin = run.d.min();
        if dmin.is_nan() || dmin <= 0.0 || (dmax / dmin).powi(2) > 1e14 || !run.sigma.is_finite() {
            return Some(Termination::Stagnation);
        }
        // No effect of the principal axis of this generation / coordinates.
        let axis = run.generation % n;
        let shift = 0.1 * run.sigma * run.d[axis] * run.b.column(axis);
        if (0..n).all(|i| run.mean[i] + shift[i] == run.mean[i]) {
            return Some(Termination::Stagnation);
        }
        if (0..n).any(|i| run.mean[i] + 0.2 * run.sigma * run.cov[(i, i)].sqrt() == run.mean[i]) {
            return Some(Termination::Stagnation);
        }
        let max_gen = 100.0 + 150.0 * ((n + 3) as f64).powi(2) / (lambda as f64).sqrt();
        if run.generation as f64 >= max_gen {
            return Some(Termination::Stagnation);
        }
        None
    }
}

impl Recorded for Cmaes {
    fn take_record(&mut self) -> Option<IterRecord> {
        self.record.take()
    }
}

impl<'a> Solver<Counted<'a>, OptState> for Cmaes {
    fn name(&self) -> &str {
        self.options.restarts.solver_name()
    }

    fn next_iter(
        &mut self,
        problem: &mut ArgminProblem<Counted<'a>>,
        state: OptState,
    ) -> std::result::Result<(OptState, Option<KV>), argmin::core::Error> {
        self.generation(problem)
            .map_err(argmin::core::Error::from)?;
        let state = match &self.best {
            Some(b) => state.param(b.x.clone()).cost(b.f),
            None => state,
        };
        Ok((state, None))
    }

    fn terminate(&mut self, _state: &OptState) -> TerminationStatus {
        match &self.termination {
            Some(t) => TerminationStatus::Terminated(TerminationReason::SolverExit(t.to_string())),
            None => TerminationStatus::NotTerminated,
        }
    }
}

/// Minimize `problem` with IPOP- or BIPOP-CMA-ES (`options.restarts`)
/// within `options.max_evaluations`; one record per generation
/// (best-so-far design, σ in `step`) goes to `observer`, one record per
/// run is in the outcome's `runs`.
pub fn minimize(
    problem: &dyn Problem,
    options: &CmaesOptions,
    observer: &mut dyn Observer,
) -> Result<GlobalOutcome> {
    let mut solver = Cmaes::new(problem, options.clone())?;
    let mut ap = ArgminProblem::new(Counted::new(problem));
    driver::run(&mut solver, &mut ap, OptState::new(), observer)?;
    let function_calls = ap.problem.as_ref().map(|c| c.function_calls()).unwrap_or(0);
    let best = solver.best.clone().ok_or_else(|| {
        Error::input(
            "cmaes.max_evaluations",
            options.max_evaluations,
            "a budget of at least one generation",
        )
    })?;
    Ok(GlobalOutcome {
        feasible: best.violation <= 0.0,
        x: best.x,
        f: best.f,
        g: best.g,
        function_calls,
        generations: solver.generations,
        restarts: solver.restarts,
        termination: solver.termination.unwrap_or(Termination::MaxEvaluations),
        runs: solver.runs,
    })
}

#[cfg(test)]
#[path = "cmaes_tests.rs"]
mod tests;
