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
//! [`Costly`] burns a fixed CPU time per evaluation (a busy wait, so it
//! occupies a core like a real simulation would) for performance
//! measurements of the drivers.

use crate::error::{Error, Result};
use crate::optimize::multiobjective::MultiProblem;
use crate::optimize::testproblems as tp;
use crate::optimize::{Evaluation, Problem, Variable};
use serde::Deserialize;
use std::time::{Duration, Instant};

/// The `[problem]` section of a study.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProblemSpec {
    /// A name from [`PROBLEM_NAMES`].
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

/// Names accepted by [`ProblemSpec::build_multi`] (the problems of
/// `optimize::mo_testproblems`, for `[front]`).
pub const MULTI_PROBLEM_NAMES: &str = "zdt1, zdt2, zdt3, dtlz2, scene (with [scene_problem])";

/// Names accepted by [`ProblemSpec::build`].
pub const PROBLEM_NAMES: &str =
    "himmelblau, rosenbrock, rastrigin, hs21, hs22, hs35, hs43, hs76, hs100, disc, seam, periodic2, scene (with [scene_problem])";

impl ProblemSpec {
    /// Build the named multi-objective problem (`[front]`): one of
    /// [`MULTI_PROBLEM_NAMES`], with none of the single-objective keys
    /// (`dimension`, `bounds`, `cost_ms`). Errors name the key within the
    /// `[problem]` section.
    pub fn build_multi(&self) -> Result<Box<dyn MultiProblem>> {
        let p = crate::optimize::mo_testproblems::by_name(&self.name).ok_or_else(|| {
            Error::input(
                "name",
                format!("\"{}\"", self.name),
                format!("a problem with several objectives for [front]: {MULTI_PROBLEM_NAMES}"),
            )
        })?;
        let unused = [
            ("dimension", self.dimension.is_some()),
            ("bounds", self.bounds.is_some()),
            ("cost_ms", self.cost_ms != 0.0),
        ];
        if let Some((key, _)) = unused.iter().find(|(_, set)| *set) {
            return Err(Error::input(
                *key,
                "(given)",
                format!("no `{key}` for {} (its size and box are fixed)", self.name),
            ));
        }
        Ok(Box::new(p))
    }

    /// Build the named problem (wrapped in [`Costly`] when `cost_ms > 0`).
    /// Errors name the key within the `[problem]` section.
    pub fn build(&self) -> Result<Box<dyn Problem>> {
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
        let sized = matches!(self.name.as_str(), "rosenbrock" | "rastrigin");
        if self.dimension.is_some() && !sized {
            return Err(Error::input(
                "dimension",
                self.dimension.unwrap_or(0),
                "no `dimension` (only rosenbrock and rastrigin take one)",
            ));
        }
        let n = self.dimension.unwrap_or(2);
        if sized && !(2..=64).contains(&n) {
            return Err(Error::input("dimension", n, "2 <= dimension <= 64"));
        }
        let inner: Box<dyn Problem> = match self.name.as_str() {
            "himmelblau" => Box::new(tp::himmelblau()),
            "rosenbrock" => Box::new(tp::rosenbrock(n)),
            "rastrigin" => Box::new(tp::rastrigin(n)),
            "hs21" => Box::new(tp::hs21()),
            "hs35" => Box::new(tp::hs35()),
            "hs43" => Box::new(tp::hs43()),
            "hs76" => Box::new(tp::hs76()),
            "hs100" => Box::new(tp::hs100()),
            "disc" => Box::new(tp::disc()),
            "seam" => Box::new(tp::seam()),
            "hs22" => Box::new(Hs22::new()),
            "periodic2" => Box::new(Periodic2::new()),
            multi @ ("zdt1" | "zdt2" | "zdt3" | "dtlz2") => return Err(Error::input(
                "name",
                format!("\"{multi}\""),
                "a single-objective problem here: it has several objectives, use it with [front]",
            )),
            "scene" => {
                return Err(Error::input(
                    "name",
                    "\"scene\"",
                    "a study: build scene problems with explore::problem(study)",
                ))
            }
            other => {
                return Err(Error::input(
                    "name",
                    format!("\"{other}\""),
                    format!("one of {PROBLEM_NAMES}"),
                ))
            }
        };
        let inner = match &self.bounds {
            None => inner,
            Some(b) => Box::new(Rebounded::new(inner, b)?),
        };
        if self.cost_ms > 0.0 {
            Ok(Box::new(Costly {
                inner,
                cost: Duration::from_secs_f64(self.cost_ms * 1e-3),
                sleep,
            }))
        } else {
            Ok(inner)
        }
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

/// Any problem plus a fixed time per evaluation: a busy wait on the
/// monotonic clock (the thread really occupies a core), or a sleep.
pub struct Costly {
    /// The problem that gives the numbers.
    pub inner: Box<dyn Problem>,
    /// Time burnt per evaluation (with or without gradients).
    pub cost: Duration,
    /// Sleep instead of spinning.
    pub sleep: bool,
}

impl Problem for Costly {
    fn variables(&self) -> &[Variable] {
        self.inner.variables()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn evaluate(&self, x: &[f64], gradients: bool) -> Result<Evaluation> {
        let start = Instant::now();
        let out = self.inner.evaluate(x, gradients);
        if self.sleep {
            std::thread::sleep(self.cost.saturating_sub(start.elapsed()));
        }
        while start.elapsed() < self.cost {
            std::hint::spin_loop();
        }
        out
    }
    fn name(&self) -> &str {
        self.inner.name()
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
