//! Unit tests of the CMA-ES internals (the restart schedules, the
//! normal sampler), kept beside `cmaes.rs` so that it stays readable.

use super::*;

/// The message list is the serde names of every schedule, and each
/// parses back; an unknown name lists them.
#[test]
fn restart_names_are_the_serde_names() {
    let names: Vec<&str> = Restarts::ALL.iter().map(|r| r.name()).collect();
    assert_eq!(names.join(", "), Restarts::NAMES);
    for r in Restarts::ALL {
        assert_eq!(Restarts::parse(r.name()).unwrap(), r);
    }
    let e = Restarts::parse("ipopp").unwrap_err().to_string();
    assert!(
        e.contains("`restarts` = \"ipopp\"") && e.contains("ipop, bipop"),
        "{e}"
    );
}

/// Hansen (2016) Table 1 identities: positive decreasing weights that
/// sum to 1, `1 <= μ_eff <= μ`, learning rates with `c_1 + c_μ <= 1`;
/// for n = 10, λ = 10 the weights computed by hand from
/// `ln 5.5 − ln i` give μ_eff = 3.16726 (closed form derived here).
#[test]
fn strategy_parameters() {
    for (n, lambda) in [(2, 6), (10, 10), (5, 64)] {
        let p = Params::new(n, lambda, false);
        assert!((p.weights.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!(p.weights.windows(2).all(|w| w[0] > w[1] && w[1] > 0.0));
        assert!(p.mueff >= 1.0 && p.mueff <= (lambda / 2) as f64);
        assert!(p.c1 + p.cmu <= 1.0 && p.cs < 1.0 && p.cc < 1.0 && p.ds > 1.0);
    }
    let p = Params::new(10, 10, false);
    assert!((p.mueff - 3.16726).abs() < 1e-4, "{}", p.mueff);
}

/// Deb's rules: feasible beats infeasible regardless of f; feasible by
/// f; infeasible by violation.
#[test]
fn feasibility_rules_order() {
    let s = |f: f64, v: f64| Sample {
        y: vec![],
        x: vec![],
        f,
        g: vec![],
        violation: v,
    };
    use std::cmp::Ordering::*;
    assert_eq!(better(&s(10.0, 0.0), &s(-10.0, 0.1)), Less);
    assert_eq!(better(&s(1.0, 0.0), &s(2.0, 0.0)), Less);
    assert_eq!(better(&s(-5.0, 0.3), &s(5.0, 0.2)), Greater);
}

/// Box–Muller normals: sample mean ≈ 0 and variance ≈ 1 (standard
/// errors 1/√N and √(2/N) for N = 20 000; 5σ bounds).
#[test]
fn normal_samples_have_unit_variance() {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let n = 20_000;
    let xs: Vec<f64> = (0..n).map(|_| normal(&mut rng)).collect();
    let mean = xs.iter().sum::<f64>() / n as f64;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
    assert!(mean.abs() < 5.0 / (n as f64).sqrt());
    assert!((var - 1.0).abs() < 5.0 * (2.0 / n as f64).sqrt());
}

/// `f = Σ xᵢ²` on `[-1, 1]ⁿ`, minimum 0 at the origin.
struct Sphere(Vec<crate::optimize::Variable>);

impl Problem for Sphere {
    fn variables(&self) -> &[crate::optimize::Variable] {
        &self.0
    }
    fn n_constraints(&self) -> usize {
        0
    }
    fn evaluate(&self, x: &[f64], _gradients: bool) -> Result<Evaluation> {
        Ok(Evaluation {
            f: x.iter().map(|v| v * v).sum(),
            g: vec![],
            grad_f: None,
            grad_g: None,
        })
    }
}

/// The smallest `σ √C_ii / min_std_i` of the current run after `gens`
/// generations on the sphere (`min_std` empty: the plain `σ √C_ii`).
fn smallest_std(min_std: Vec<f64>, gens: usize) -> f64 {
    let vars = (0..2)
        .map(|i| crate::optimize::Variable::bounded(format!("x{i}"), -1.0, 1.0).unwrap())
        .collect();
    let p = Sphere(vars);
    let options = CmaesOptions {
        seed: 3,
        x0: Some(vec![0.5, -0.5]),
        min_std: min_std.clone(),
        ..CmaesOptions::default()
    };
    let mut solver = Cmaes::new(&p, options).unwrap();
    let mut ap = ArgminProblem::new(Counted::new(&p));
    let mut smallest = f64::INFINITY;
    for _ in 0..gens {
        solver.generation(&mut ap).unwrap();
        if let Some(run) = &solver.run {
            for i in 0..2 {
                let sd = run.sigma * run.cov[(i, i)].sqrt();
                smallest = smallest.min(sd / min_std.get(i).copied().unwrap_or(1.0));
            }
        }
    }
    smallest
}

/// The integer handling's floor (`min_std`): without it the spread on the
/// sphere shrinks far below 0.01 of the range in 80 generations; with
/// floors 0.05 and 0.02 it never falls below them.
#[test]
fn min_std_bounds_every_coordinates_spread() {
    assert!(smallest_std(Vec::new(), 80) < 1e-2);
    let ratio = smallest_std(vec![0.05, 0.02], 80);
    assert!(ratio >= 1.0 - 1e-12, "{ratio}");
}
