//! A dense grid of the design box as a yardstick for fronts (`[front]
//! grid = N`): every grid design evaluated (objectives and constraints,
//! no gradients), in parallel, and the grid's non-dominated feasible
//! designs as a third "method".
//!
//! Grid: `N` values per variable. A bounded variable gets `N` evenly
//! spaced values with both ends, `lower + (upper − lower)·k/(N − 1)`; a
//! periodic one `N` values without the duplicate end,
//! `lower + period·k/N`, `k = 0..N−1` (its upper end is its lower end).
//! Designs are enumerated with the first variable slowest. A design whose
//! evaluation fails (a numerical error of the simulation) is kept with its
//! message and left out of the front.

use crate::error::{Error, Result};
use crate::optimize::multiobjective::{non_dominated_pairs, MultiEvaluation, MultiProblem};
use crate::optimize::Variable;
use crate::report::Progress;
use rayon::prelude::*;
use std::time::Instant;

/// Most grid designs `[front] grid` may ask for.
pub const MAX_GRID_DESIGNS: usize = 1_000_000;

/// One grid design and what its evaluation gave.
#[derive(Debug, Clone)]
pub struct GridPoint {
    /// The design.
    pub x: Vec<f64>,
    /// Its evaluation, or the error's message.
    pub result: std::result::Result<MultiEvaluation, String>,
}

/// The evaluated grid.
#[derive(Debug, Clone)]
pub struct GridFront {
    /// Every design, first variable slowest.
    pub points: Vec<GridPoint>,
    /// Its non-dominated feasible designs and their objectives (minimized
    /// orientation), in grid order.
    pub front: Vec<(Vec<f64>, Vec<f64>)>,
    /// Wall time \[s\].
    pub wall_seconds: f64,
}

impl GridFront {
    /// Designs whose evaluation failed.
    pub fn failures(&self) -> usize {
        self.points.iter().filter(|p| p.result.is_err()).count()
    }
}

/// The `n` grid values of one variable (see the module doc).
pub fn axis(v: &Variable, n: usize) -> Vec<f64> {
    match v.period {
        Some(p) => (0..n).map(|k| v.lower + p * k as f64 / n as f64).collect(),
        None => (0..n)
            .map(|k| {
                if k + 1 == n {
                    v.upper
                } else {
                    v.lower + (v.upper - v.lower) * k as f64 / (n - 1) as f64
                }
            })
            .collect(),
    }
}

/// The number of grid designs, `n^variables`, when at most
/// [`MAX_GRID_DESIGNS`].
pub fn grid_size(variables: usize, n: usize) -> Option<usize> {
    let mut count: usize = 1;
    for _ in 0..variables {
        count = count.checked_mul(n)?;
        if count > MAX_GRID_DESIGNS {
            return None;
        }
    }
    Some(count)
}

/// Evaluate the grid of `n` values per variable with `threads` threads
/// (a progress bar unless `quiet`); feasible is `max g <= tol`.
pub fn evaluate_grid(
    problem: &dyn MultiProblem,
    n: usize,
    threads: usize,
    quiet: bool,
    tol: f64,
) -> Result<GridFront> {
    let t0 = Instant::now();
    let vars = problem.variables();
    let count = grid_size(vars.len(), n).ok_or_else(|| {
        Error::input(
            "grid",
            n,
            format!(
                "at most {MAX_GRID_DESIGNS} designs ({n}^{} is more)",
                vars.len()
            ),
        )
    })?;
    let axes: Vec<Vec<f64>> = vars.iter().map(|v| axis(v, n)).collect();
    let design = |mut c: usize| -> Vec<f64> {
        let mut x = vec![0.0; vars.len()];
        for (xi, a) in x.iter_mut().zip(&axes).rev() {
            *xi = a[c % n];
            c /= n;
        }
        x
    };
    let pool = crate::explore::context::thread_pool(threads)?;
    let progress = Progress::new("grid", count as u64, quiet);
    let points: Vec<GridPoint> = pool.install(|| {
        (0..count)
            .into_par_iter()
            .map(|c| {
                let x = design(c);
                let result = match problem.evaluate(&x, false) {
                    Ok(e) if e.f.iter().chain(&e.g).all(|v| v.is_finite()) => Ok(e),
                    Ok(e) => Err(format!("non-finite f = {:?} or g = {:?}", e.f, e.g)),
                    Err(e) => Err(e.to_string()),
                };
                progress.inc("");
                GridPoint { x, result }
            })
            .collect()
    });
    progress.finish();
    let feasible: Vec<(Vec<f64>, Vec<f64>)> = points
        .iter()
        .filter_map(|p| {
            let e = p.result.as_ref().ok()?;
            (e.max_g() <= tol).then(|| (p.x.clone(), e.f.clone()))
        })
        .collect();
    let front = non_dominated_pairs(&feasible);
    Ok(GridFront {
        points,
        front,
        wall_seconds: t0.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_axes_leave_out_the_duplicate_end() {
        let p = Variable::periodic("a", -90.0, 180.0).unwrap();
        let a = axis(&p, 4);
        assert_eq!(a, vec![-90.0, -45.0, 0.0, 45.0]);
        let b = Variable::bounded("b", 0.0, 1.0).unwrap();
        assert_eq!(axis(&b, 3), vec![0.0, 0.5, 1.0]);
        assert_eq!(grid_size(2, 37), Some(1369));
        assert_eq!(grid_size(30, 37), None);
    }
}
