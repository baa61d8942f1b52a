//! Start points over the design box: Latin hypercube, scrambled Sobol,
//! uniform random, plus points the user lists; optionally only feasible ones.
//!
//! Every random choice comes from a `ChaCha8Rng` seeded with the study seed
//! (stream [`SAMPLER_STREAM`]), so a study always gets the same starts.
//!
//! The samplers themselves (Latin hypercube, scrambled Sobol, uniform)
//! are [`crate::optimize::sampling`]'s; here the study's `[multistart]`
//! keys become start points: the listed points first, then `count`
//! sampled ones, optionally only feasible ones.
//!
//! Periodic variables are sampled on `[lower, lower + period)`.

use crate::error::{Error, Result};
pub use crate::optimize::sampling::Sampler;
use crate::optimize::sampling::{sample, SOBOL_MAX_DIM};
use crate::optimize::{Problem, Variable};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;

/// ChaCha stream used for start points (CMA-ES uses its own seed).
pub const SAMPLER_STREAM: u64 = 1;

/// The `[starts]` section of a study.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartsSpec {
    /// `lhs` (default), `sobol` or `uniform`.
    #[serde(default)]
    pub sampler: Sampler,
    /// Number of sampled starts (after the listed points).
    #[serde(default)]
    pub count: usize,
    /// Listed start points, used first (start indices 0, 1, ...).
    #[serde(default)]
    pub points: Vec<Vec<f64>>,
    /// Keep only starts with every `g_j <= 0` (listed points included).
    #[serde(default)]
    pub feasible_only: bool,
}
/// Start points and the evaluations the feasibility filter used.
#[derive(Debug, Clone, PartialEq)]
pub struct Starts {
    /// Start points in design units, in start-index order.
    pub points: Vec<Vec<f64>>,
    /// Function evaluations spent on filtering (0 without the filter).
    pub filter_evaluations: usize,
}

impl StartsSpec {
    /// Validate against the problem's variables and generate the starts.
    /// Errors name keys inside `[starts]`.
    pub fn generate(&self, problem: &dyn Problem, seed: u64) -> Result<Starts> {
        let vars = problem.variables();
        let sampler = self.sampler;
        if self.count + self.points.len() == 0 {
            return Err(Error::input(
                "count",
                0,
                "at least one start (count >= 1 or listed points)",
            ));
        }
        if sampler == Sampler::Sobol && vars.len() > SOBOL_MAX_DIM {
            return Err(Error::input(
                "sampler",
                "\"sobol\"",
                format!("lhs or uniform for more than {SOBOL_MAX_DIM} variables"),
            ));
        }
        let mut listed = Vec::with_capacity(self.points.len());
        for (i, p) in self.points.iter().enumerate() {
            listed.push(check_point(vars, p).map_err(|e| e.in_file("", &format!("points[{i}]")))?);
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(SAMPLER_STREAM);
        if !self.feasible_only {
            let mut points = listed;
            points.extend(sample(sampler, vars, self.count, &mut rng, 0));
            return Ok(Starts {
                points,
                filter_evaluations: 0,
            });
        }
        let mut evaluations = 0;
        let mut feasible = |x: &[f64]| -> Result<bool> {
            evaluations += 1;
            Ok(problem.evaluate(x, false)?.max_g() <= 0.0)
        };
        let mut points = Vec::new();
        for p in listed {
            if feasible(&p)? {
                points.push(p);
            }
        }
        // Draw batches of `count` candidates until `count` are feasible.
        const MAX_BATCHES: usize = 100;
        let mut kept = 0;
        for batch in 0..MAX_BATCHES {
            if kept == self.count {
                break;
            }
            for p in sample(sampler, vars, self.count, &mut rng, batch * self.count) {
                if kept < self.count && feasible(&p)? {
                    points.push(p);
                    kept += 1;
                }
            }
        }
        if kept < self.count || points.is_empty() {
            return Err(Error::input(
                "feasible_only",
                true,
                format!(
                    "a problem where {} of {} sampled candidates are feasible (found {kept})",
                    self.count,
                    MAX_BATCHES * self.count
                ),
            ));
        }
        Ok(Starts {
            points,
            filter_evaluations: evaluations,
        })
    }
}

/// Check a listed point: right length, finite, inside the box (periodic
/// coordinates are wrapped).
fn check_point(vars: &[Variable], p: &[f64]) -> Result<Vec<f64>> {
    if p.len() != vars.len() {
        return Err(Error::input(
            "",
            format!("(array of {})", p.len()),
            format!("{} coordinates", vars.len()),
        ));
    }
    let mut out = Vec::with_capacity(p.len());
    for (i, (v, &x)) in vars.iter().zip(p).enumerate() {
        if !x.is_finite() || (v.period.is_none() && !(v.lower..=v.upper).contains(&x)) {
            return Err(Error::input(
                format!("[{i}]"),
                x,
                format!("a value in [{}, {}] ({})", v.lower, v.upper, v.name),
            ));
        }
        out.push(v.wrap(x));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feasible_filter_keeps_only_feasible_starts_and_is_seeded() {
        use crate::explore::problem::problems::Hs22;
        let p = Hs22::new();
        let spec = StartsSpec {
            sampler: Sampler::Sobol,
            count: 20,
            points: vec![vec![0.0, 1.0], vec![4.0, 4.0]],
            feasible_only: true,
        };
        let s = spec.generate(&p, 9).unwrap();
        // The listed (0, 1) is feasible and kept first; (4, 4) is not.
        assert_eq!(s.points.len(), 21);
        assert_eq!(s.points[0], vec![0.0, 1.0]);
        for x in &s.points {
            assert!(p.evaluate(x, false).unwrap().max_g() <= 0.0);
        }
        assert!(s.filter_evaluations > 21);
        assert_eq!(spec.generate(&p, 9).unwrap(), s);
        assert_ne!(spec.generate(&p, 10).unwrap(), s);
    }
}
