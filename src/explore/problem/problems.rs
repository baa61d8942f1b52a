//! Analytic problems named in study files (`[problem] name = "..."`), and a
//! wrapper that gives any of them a fixed CPU cost per evaluation.
//!
//! These problems have known landscapes, so the exploration drivers can be
//! checked against closed-form answers. From `optimize::testproblems`
//! (sources cited there): `himmelblau` (four global minima, `f = 0`),
//! `rosenbrock` and `rastrigin` (`dimension` variables), `hs21`, `hs35`,
//! `hs43`, `hs76`, `hs100`, `disc` and `seam`. Defined here:
//! - `hs22`: Hock–Schittkowski problem 22 (Hock & Schittkowski, *Test
//!   Examples for Nonlinear Programming Codes*, 1981), minimum `f = 1` at
//!   `(1, 1)` with both constraints active; box `[-5, 5]²` added (inactive at
//!   the optimum) so that samplers have a design box.
//! - `periodic2`: two periodic angles (degrees, period 180°) with four minima,
//!   one of them on the seam `θ₁ = ±90°`; see [`Periodic2`].
//!
//! [`Costly`] (and [`CostlyMulti`] for the fronts) burns a fixed time per
//! evaluation (a busy wait, so it occupies a core like a real simulation
//! would, or a sleep) for performance measurements of the drivers and for
//! runs slow enough to be killed in a test.

use crate::error::{Error, Result};
use crate::optimize::multiobjective::{MultiEvaluation, MultiProblem};
use crate::optimize::testproblems as tp;
use crate::optimize::{Evaluation, Problem, Variable};
use serde::Deserialize;
use std::time::{Duration, Instant};

/// The `[problem]` section of a study.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProblemSpec {
    /// A name from [`TEST_PROBLEMS`] (or `scene`).
    pub name: String,
    /// Number of variables (only `rosenbrock`, `rastrigin`; default 2).
    pub dimension: Option<usize>,
    /// Time each evaluation takes \[ms\] (default 0).
    #[serde(default)]
    pub cost_ms: f64,
    /// How that time is spent: `spin` (default: busy wait, occupies a core
    /// like a simulation) or `sleep` (the thread sleeps: measures the
    /// driver's parallel structure without competing for cores).
    #[serde(default = "default_cost_mode")]
    pub cost_mode: String,
    /// Replacement box `[[lower, upper], ...]`, one pair per variable
    /// (non-periodic variables only; periodic ones must repeat their box).
    pub bounds: Option<Vec<[f64; 2]>>,
}

fn default_cost_mode() -> String {
    "spin".into()
}

/// How a named test problem is built.
#[derive(Clone, Copy)]
pub enum Constructor {
    /// One objective, a fixed number of variables.
    Single(fn() -> Box<dyn Problem>),
    /// One objective, `[problem] dimension` variables (default 2).
    Sized(fn(usize) -> Box<dyn Problem>),
    /// Several objectives, for `[front]` (`optimize::mo_testproblems`).
    Multi(fn() -> Box<dyn MultiProblem>),
}

/// A test problem by the name study files use.
#[derive(Clone, Copy)]
pub struct TestProblem {
    /// The name (`[problem] name`).
    pub name: &'static str,
    /// Its constructor, which also says whether it has one objective.
    pub build: Constructor,
}

/// Every test problem, in the order error messages list them: the one
/// list of names; [`ProblemSpec::build`], [`ProblemSpec::build_multi`] and
/// their error messages read it.
pub const TEST_PROBLEMS: &[TestProblem] = {
    use crate::optimize::mo_testproblems as mo;
    use Constructor::{Multi, Single, Sized};
    const fn entry(name: &'static str, build: Constructor) -> TestProblem {
        TestProblem { name, build }
    }
    &[
        entry("himmelblau", Single(|| Box::new(tp::himmelblau()))),
        entry("rosenbrock", Sized(|n| Box::new(tp::rosenbrock(n)))),
        entry("rastrigin", Sized(|n| Box::new(tp::rastrigin(n)))),
        entry("hs21", Single(|| Box::new(tp::hs21()))),
        entry("hs22", Single(|| Box::new(Hs22::new()))),
        entry("hs35", Single(|| Box::new(tp::hs35()))),
        entry("hs43", Single(|| Box::new(tp::hs43()))),
        entry("hs76", Single(|| Box::new(tp::hs76()))),
        entry("hs100", Single(|| Box::new(tp::hs100()))),
        entry("disc", Single(|| Box::new(tp::disc()))),
        entry("seam", Single(|| Box::new(tp::seam()))),
        entry("periodic2", Single(|| Box::new(Periodic2::new()))),
        entry("zdt1", Multi(|| Box::new(mo::zdt1()))),
        entry("zdt2", Multi(|| Box::new(mo::zdt2()))),
        entry("zdt3", Multi(|| Box::new(mo::zdt3()))),
        entry("dtlz2", Multi(|| Box::new(mo::dtlz2()))),
    ]
};

/// The names of the test problems whose constructor `pick` accepts,
/// joined by `sep`.
fn names(pick: fn(&Constructor) -> bool, sep: &str) -> String {
    let list: Vec<&str> = TEST_PROBLEMS
        .iter()
        .filter(|t| pick(&t.build))
        .map(|t| t.name)
        .collect();
    list.join(sep)
}

/// The names [`ProblemSpec::build`] accepts, as its error message lists
/// them (`scene` is built from the study by `explore::problem`).
pub fn problem_names() -> String {
    let single = |c: &Constructor| !matches!(c, Constructor::Multi(_));
    format!("{}, scene (with [scene_problem])", names(single, ", "))
}

/// The names [`ProblemSpec::build_multi`] accepts (and `scene` for
/// `[front]`), as its error message lists them.
pub fn multi_problem_names() -> String {
    let multi = |c: &Constructor| matches!(c, Constructor::Multi(_));
    format!("{}, scene (with [scene_problem])", names(multi, ", "))
}

/// The row of `name` in [`TEST_PROBLEMS`].
fn lookup(name: &str) -> Option<Constructor> {
    TEST_PROBLEMS
        .iter()
        .find(|t| t.name == name)
        .map(|t| t.build)
}

impl ProblemSpec {
    /// Build the named multi-objective problem (`[front]`): one of
    /// [`multi_problem_names`], with none of the single-objective keys
    /// (`dimension`, `bounds`), wrapped in [`CostlyMulti`] when `cost_ms >
    /// 0`. Errors name the key within the `[problem]` section.
    pub fn build_multi(&self) -> Result<Box<dyn MultiProblem>> {
        let Some(Constructor::Multi(build)) = lookup(&self.name) else {
            return Err(Error::input(
                "name",
                format!("\"{}\"", self.name),
                format!(
                    "a problem with several objectives for [front]: {}",
                    multi_problem_names()
                ),
            ));
        };
        let unused = [
            ("dimension", self.dimension.is_some()),
            ("bounds", self.bounds.is_some()),
        ];
        if let Some((key, _)) = unused.iter().find(|(_, set)| *set) {
            return Err(Error::input(
                *key,
                "(given)",
                format!("no `{key}` for {} (its size and box are fixed)", self.name),
            ));
        }
        Ok(match self.cost()? {
            Some(cost) => Box::new(CostlyMulti {
                inner: build(),
                cost,
            }),
            None => build(),
        })
    }

    /// The time each evaluation burns (`cost_ms`, `cost_mode`); `None`
    /// for none.
    fn cost(&self) -> Result<Option<Cost>> {
        if !(self.cost_ms.is_finite() && self.cost_ms >= 0.0) {
            return Err(Error::input(
                "cost_ms",
                self.cost_ms,
                "a finite time >= 0 ms",
            ));
        }
        let sleep = match self.cost_mode.as_str() {
            "spin" => false,
            "sleep" => true,
            other => {
                return Err(Error::input(
                    "cost_mode",
                    format!("\"{other}\""),
                    "spin or sleep",
                ))
            }
        };
        Ok((self.cost_ms > 0.0).then(|| Cost {
            time: Duration::from_secs_f64(self.cost_ms * 1e-3),
            sleep,
        }))
    }

    /// Build the named problem (wrapped in [`Costly`] when `cost_ms > 0`).
    /// Errors name the key within the `[problem]` section.
    pub fn build(&self) -> Result<Box<dyn Problem>> {
        let cost = self.cost()?;
        let entry = lookup(&self.name);
        let sized = matches!(entry, Some(Constructor::Sized(_)));
        if self.dimension.is_some() && !sized {
            let takers = names(|c| matches!(c, Constructor::Sized(_)), " and ");
            return Err(Error::input(
                "dimension",
                self.dimension.unwrap_or(0),
                format!("no `dimension` (only {takers} take one)"),
            ));
        }
        let n = self.dimension.unwrap_or(2);
        if sized && !(2..=64).contains(&n) {
            return Err(Error::input("dimension", n, "2 <= dimension <= 64"));
        }
        let inner: Box<dyn Problem> = match entry {
            Some(Constructor::Single(build)) => build(),
            Some(Constructor::Sized(build)) => build(n),
            Some(Constructor::Multi(_)) => return Err(Error::input(
                "name",
                format!("\"{}\"", self.name),
                "a single-objective problem here: it has several objectives, use it with [front]",
            )),
            None if self.name == "scene" => {
                return Err(Error::input(
                    "name",
                    "\"scene\"",
                    "a study: build scene problems with explore::problem(study)",
                ))
            }
            None => {
                return Err(Error::input(
                    "name",
                    format!("\"{}\"", self.name),
                    format!("one of {}", problem_names()),
                ))
            }
        };
        let inner = match &self.bounds {
            None => inner,
            Some(b) => Box::new(Rebounded::new(inner, b)?),
        };
        Ok(match cost {
            Some(cost) => Box::new(Costly { inner, cost }),
            None => inner,
        })
    }
}

/// A problem with a user-given box (`[problem] bounds`).
pub struct Rebounded {
    inner: Box<dyn Problem>,
    vars: Vec<Variable>,
}

impl Rebounded {
    /// Replace the box of `inner`; errors name `bounds[i]`.
    pub fn new(inner: Box<dyn Problem>, bounds: &[[f64; 2]]) -> Result<Self> {
        let old = inner.variables();
        if bounds.len() != old.len() {
            return Err(Error::input(
                "bounds",
                format!("(array of {})", bounds.len()),
                format!("{} pairs [lower, upper]", old.len()),
            ));
        }
        let mut vars = Vec::with_capacity(old.len());
        for (i, (v, &[lo, hi])) in old.iter().zip(bounds).enumerate() {
            let key = format!("bounds[{i}]");
            if v.period.is_some() {
                if lo != v.lower || hi != v.upper {
                    return Err(Error::input(
                        key,
                        format!("[{lo}, {hi}]"),
                        format!("[{}, {}]: {} is periodic", v.lower, v.upper, v.name),
                    ));
                }
                vars.push(v.clone());
            } else {
                vars.push(
                    Variable::bounded(v.name.clone(), lo, hi).map_err(|e| match e {
                        Error::Input {
                            file,
                            value,
                            expected,
                            ..
                        } => Error::Input {
                            file,
                            key: key.clone(),
                            value,
                            expected,
                        },
                        e => e,
                    })?,
                );
            }
        }
        Ok(Rebounded { inner, vars })
    }
}

impl Problem for Rebounded {
    fn variables(&self) -> &[Variable] {
        &self.vars
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        self.inner.evaluate(x, gradients)
    }
    fn name(&self) -> &str {
        self.inner.name()
    }
}

fn check_len(place: &str, x: &[f64], n: usize) -> Result<()> {
    if x.len() != n {
        return Err(Error::input(
            format!("{place}.x"),
            format!("a vector of length {}", x.len()),
            format!("length {n}"),
        ));
    }
    Ok(())
}

fn bounded(name: &str, lo: f64, hi: f64) -> Variable {
    Variable {
        name: name.into(),
        lower: lo,
        upper: hi,
        period: None,
    }
}

/// Hock–Schittkowski 22: `f = (x₁ − 2)² + (x₂ − 1)²` subject to
/// `g₁ = x₁ + x₂ − 2 <= 0`, `g₂ = x₁² − x₂ <= 0`; optimum `(1, 1)`, `f = 1`.
pub struct Hs22 {
    vars: Vec<Variable>,
}

impl Hs22 {
    /// The problem with the box `[-5, 5]²`.
    pub fn new() -> Self {
        Hs22 {
            vars: vec![bounded("x1", -5.0, 5.0), bounded("x2", -5.0, 5.0)],
        }
    }
}

impl Default for Hs22 {
    fn default() -> Self {
        Self::new()
    }
}

impl Problem for Hs22 {
    fn variables(&self) -> &[Variable] {
        &self.vars
    }
    fn n_constraints(&self) -> usize {
        2
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        check_len("hs22", x, 2)?;
        let f = (x[0] - 2.0).powi(2) + (x[1] - 1.0).powi(2);
        let g = vec![x[0] + x[1] - 2.0, x[0] * x[0] - x[1]];
        Ok(Evaluation {
            f,
            g,
            grad_f: gradients.then(|| vec![2.0 * (x[0] - 2.0), 2.0 * (x[1] - 1.0)]),
            grad_g: gradients.then(|| vec![vec![1.0, 1.0], vec![2.0 * x[0], -1.0]]),
        })
    }
    fn name(&self) -> &str {
        "hs22"
    }
}

/// Two angles `θ₁, θ₂` in degrees on `[-90, 90)`, period 180°:
/// `f = h(θ₁ − a₁; ε₁) + 2 h(θ₂ − a₂; ε₂)` with
/// `h(d; ε) = −cos 2d − ε cos 4d` (d in radians), `a = (90°, −30°)`,
/// `ε = (0.5, 0.75)`.
///
/// Landscape (closed form): `h' = 2 sin 2d (1 + 4ε cos 2d)` vanishes at
/// `d = 0` (minimum `−1 − ε`), `d = 90°` (minimum `1 − ε`, since
/// `h'' = −4 + 16ε > 0` for `ε > 1/4`) and at `cos 2d = −1/(4ε)` (maxima).
/// So the four minima are `θ₁ ∈ {±90°, 0°}`, `θ₂ ∈ {−30°, 60°}` with
/// `f = −5` at `(±90, −30)`, `−3` at `(0, −30)`, `−1` at `(±90, 60)`
/// and `1` at `(0, 60)` (the factor 2 keeps the four values distinct). The
/// global minimum sits on the seam of `θ₁`.
pub struct Periodic2 {
    vars: Vec<Variable>,
}

/// Centres `a` \[deg\] of [`Periodic2`].
pub const PERIODIC2_CENTRES: [f64; 2] = [90.0, -30.0];
/// Weights `ε` of [`Periodic2`].
pub const PERIODIC2_EPS: [f64; 2] = [0.5, 0.75];
/// Factors multiplying each term of [`Periodic2`].
pub const PERIODIC2_SCALE: [f64; 2] = [1.0, 2.0];

impl Periodic2 {
    /// The problem on `[-90, 90)²`.
    pub fn new() -> Self {
        let per = |name: &str| Variable {
            name: name.into(),
            lower: -90.0,
            upper: 90.0,
            period: Some(180.0),
        };
        Periodic2 {
            vars: vec![per("theta1_deg"), per("theta2_deg")],
        }
    }
}

impl Default for Periodic2 {
    fn default() -> Self {
        Self::new()
    }
}

impl Problem for Periodic2 {
    fn variables(&self) -> &[Variable] {
        &self.vars
    }
    fn n_constraints(&self) -> usize {
        0
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        check_len("periodic2", x, 2)?;
        let deg = std::f64::consts::PI / 180.0;
        let mut f = 0.0;
        let mut grad = vec![0.0; 2];
        for i in 0..2 {
            let d = (x[i] - PERIODIC2_CENTRES[i]) * deg;
            let e = PERIODIC2_EPS[i];
            let w = PERIODIC2_SCALE[i];
            f += w * (-(2.0 * d).cos() - e * (4.0 * d).cos());
            grad[i] = w * (2.0 * (2.0 * d).sin() + 4.0 * e * (4.0 * d).sin()) * deg;
        }
        Ok(Evaluation {
            f,
            g: vec![],
            grad_f: gradients.then_some(grad),
            grad_g: gradients.then(Vec::new),
        })
    }
    fn name(&self) -> &str {
        "periodic2"
    }
}

/// A fixed time per evaluation: a busy wait on the monotonic clock (the
/// thread really occupies a core), or a sleep.
#[derive(Debug, Clone, Copy)]
pub struct Cost {
    /// Time burnt per evaluation (with or without gradients).
    pub time: Duration,
    /// Sleep instead of spinning.
    pub sleep: bool,
}

impl Cost {
    /// Run `evaluate` and burn the rest of the time.
    fn around<T>(&self, evaluate: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = evaluate();
        if self.sleep {
            std::thread::sleep(self.time.saturating_sub(start.elapsed()));
        }
        while start.elapsed() < self.time {
            std::hint::spin_loop();
        }
        out
    }
}

/// Any problem plus a [`Cost`] per evaluation.
pub struct Costly {
    /// The problem that gives the numbers.
    pub inner: Box<dyn Problem>,
    /// The time each evaluation takes.
    pub cost: Cost,
}

impl Problem for Costly {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        self.cost.around(|| self.inner.evaluate(x, gradients))
    }
    fn name(&self) -> &str {
        self.inner.name()
    }
}

/// Any multi-objective problem plus a [`Cost`] per evaluation.
pub struct CostlyMulti {
    /// The problem that gives the numbers.
    pub inner: Box<dyn MultiProblem>,
    /// The time each evaluation takes.
    pub cost: Cost,
}

impl MultiProblem for CostlyMulti {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn objective_names(&self) -> Vec<String> {
        self.inner.objective_names()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<MultiEvaluation> {
        self.cost.around(|| self.inner.evaluate(x, gradients))
    }
    fn objective_pieces(&self, i: usize) -> usize {
        self.inner.objective_pieces(i)
    }
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn known_front(&self) -> Option<Vec<Vec<f64>>> {
        self.inner.known_front()
    }
    fn start(&self) -> Vec<f64> {
        self.inner.start()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central finite differences of f and g against the analytic gradients.
    fn check_gradients(p: &dyn Problem, x: &[f64]) {
        let e = p.evaluate(x, true).unwrap();
        let gf = e.grad_f.unwrap();
        let gg = e.grad_g.unwrap();
        for i in 0..x.len() {
            let h = 1e-6 * (1.0 + x[i].abs());
            let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
            xp[i] += h;
            xm[i] -= h;
            let (ep, em) = (
                p.evaluate(&xp, false).unwrap(),
                p.evaluate(&xm, false).unwrap(),
            );
            let fd = (ep.f - em.f) / (2.0 * h);
            assert!(
                (fd - gf[i]).abs() < 1e-6 * (1.0 + fd.abs()),
                "{} df/dx{i}",
                p.name()
            );
            for (j, row) in gg.iter().enumerate() {
                let fd = (ep.g[j] - em.g[j]) / (2.0 * h);
                assert!((fd - row[i]).abs() < 1e-6 * (1.0 + fd.abs()));
            }
        }
    }

    #[test]
    fn gradients_match_central_differences() {
        check_gradients(&Hs22::new(), &[0.3, -1.7]);
        check_gradients(&Periodic2::new(), &[37.0, -71.0]);
    }

    #[test]
    fn known_minima() {
        // HS 22 (Hock & Schittkowski 1981): f* = 1 at (1, 1), both active.
        let e = Hs22::new().evaluate(&[1.0, 1.0], false).unwrap();
        assert_eq!((e.f, e.g[0], e.g[1]), (1.0, 0.0, 0.0));
        // Periodic2: closed-form minima derived in the type's doc.
        let p = Periodic2::new();
        for (x, f) in [
            ([-90.0, -30.0], -5.0),
            ([0.0, -30.0], -3.0),
            ([-90.0, 60.0], -1.0),
            ([0.0, 60.0], 1.0),
        ] {
            assert!((p.evaluate(&x, false).unwrap().f - f).abs() < 1e-12);
        }
    }

    #[test]
    fn the_name_lists_come_from_the_table() {
        assert_eq!(
            problem_names(),
            "himmelblau, rosenbrock, rastrigin, hs21, hs22, hs35, hs43, hs76, hs100, disc, \
             seam, periodic2, scene (with [scene_problem])"
        );
        assert_eq!(
            multi_problem_names(),
            "zdt1, zdt2, zdt3, dtlz2, scene (with [scene_problem])"
        );
        let spec = |name: &str, dimension| ProblemSpec {
            name: name.into(),
            dimension,
            cost_ms: 0.0,
            cost_mode: "spin".into(),
            bounds: None,
        };
        for t in TEST_PROBLEMS {
            let multi = matches!(t.build, Constructor::Multi(_));
            assert_eq!(spec(t.name, None).build().is_ok(), !multi, "{}", t.name);
            assert_eq!(spec(t.name, None).build_multi().is_ok(), multi);
        }
        let e = spec("hs21", Some(3)).build().err().unwrap().to_string();
        assert!(e.contains("only rosenbrock and rastrigin take one"), "{e}");
        let p = spec("rastrigin", Some(3)).build().unwrap();
        assert_eq!(p.variables().len(), 3);
    }

    #[test]
    fn unknown_name_and_bad_cost_rejected() {
        let spec = |name: &str, cost_ms| ProblemSpec {
            name: name.into(),
            dimension: None,
            cost_ms,
            cost_mode: "spin".into(),
            bounds: None,
        };
        let e = spec("himmelbau", 0.0).build().err().unwrap().to_string();
        assert!(e.contains("himmelbau") && e.contains("himmelblau"), "{e}");
        assert!(spec("himmelblau", -1.0).build().is_err());
        assert!(spec("himmelblau", 1.0).build().is_ok());
        let mut s = spec("himmelblau", 1.0);
        s.cost_mode = "nap".into();
        assert!(s
            .build()
            .err()
            .unwrap()
            .to_string()
            .contains("spin or sleep"));
        let mut s = spec("himmelblau", 0.0);
        s.bounds = Some(vec![[-1.0, 1.0], [2.0, -2.0]]);
        let e = s.build().err().unwrap().to_string();
        assert!(
            e.contains("bounds[1]") && e.contains("lower < upper"),
            "{e}"
        );
    }
}
