//! Design-space maps: `f` and the constraints on a regular grid over two
//! design variables, as CSV and as an SVG heat map with the local optima
//! and the evolutionary best marked.
//!
//! With two variables the grid covers the whole box (`map.csv`,
//! `map.svg`). With more, each listed pair `(i, j)` gets a 2-D slice through
//! a base design (the best optimum found, else the box centre), the other
//! variables held fixed (`map_<i>_<j>.csv`, `.svg`). Grid points include both
//! ends of each range; for a periodic variable the two ends are the same
//! angle, which keeps the picture closed at the seam. Cells are evaluated in
//! parallel (rayon, one evaluation per task) and written in grid order.

use super::tables::{num, write_atomic};
use crate::error::{Error, Result};
use crate::optimize::{Evaluation, Problem};
use crate::report::{heat_map, HeatMap};
use rayon::prelude::*;
use std::path::Path;

/// What to map.
#[derive(Debug, Clone)]
pub struct MapRequest {
    /// Grid points per axis (>= 2).
    pub resolution: usize,
    /// Variable pairs; for two variables `[(0, 1)]`.
    pub pairs: Vec<(usize, usize)>,
    /// Design the slices pass through (length n).
    pub base: Vec<f64>,
    /// Points to mark (label, designs of length n).
    pub marks: Vec<(String, Vec<Vec<f64>>)>,
}

/// One evaluated slice.
#[derive(Debug, Clone)]
pub struct Slice {
    /// Variables on the axes.
    pub pair: (usize, usize),
    /// Grid coordinates along each axis.
    pub xs: Vec<f64>,
    /// Grid coordinates along the second axis.
    pub ys: Vec<f64>,
    /// Evaluations, `cells[i * ny + j]`.
    pub cells: Vec<Evaluation>,
}

fn axis(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            if k + 1 == n {
                hi
            } else {
                lo + (hi - lo) * k as f64 / (n - 1) as f64
            }
        })
        .collect()
}

/// Evaluate one slice in the current rayon pool.
pub fn evaluate_slice(
    problem: &dyn Problem,
    pair: (usize, usize),
    base: &[f64],
    res: usize,
) -> Result<Slice> {
    let vars = problem.variables();
    let (a, b) = (&vars[pair.0], &vars[pair.1]);
    let xs = axis(a.lower, a.upper, res);
    let ys = axis(b.lower, b.upper, res);
    let cells: Vec<Evaluation> = (0..res * res)
        .into_par_iter()
        .map(|c| {
            let mut x = base.to_vec();
            x[pair.0] = xs[c / res];
            x[pair.1] = ys[c % res];
            let e = problem.evaluate(&x, false)?;
            if !(e.f.is_finite() && e.g.iter().all(|v| v.is_finite())) {
                return Err(Error::numerical(
                    "explore::map",
                    format!("non-finite f = {} or g = {:?} at x = {x:?}", e.f, e.g),
                ));
            }
            Ok(e)
        })
        .collect::<Result<_>>()?;
    Ok(Slice {
        pair,
        xs,
        ys,
        cells,
    })
}

/// Evaluate every requested slice with `threads` threads and write the CSV
/// and SVG files into `dir`. Returns the slices.
pub fn run(
    problem: &dyn Problem,
    req: &MapRequest,
    threads: usize,
    dir: &Path,
) -> Result<Vec<Slice>> {
    let vars = problem.variables();
    let n = vars.len();
    let m = problem.n_constraints();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::input("threads", threads, format!("a usable count ({e})")))?;
    let mut out = Vec::new();
    for &pair in &req.pairs {
        let slice = pool.install(|| evaluate_slice(problem, pair, &req.base, req.resolution))?;
        let stem = if n == 2 {
            "map".to_string()
        } else {
            format!("map_{}_{}", pair.0, pair.1)
        };
        let (na, nb) = (&vars[pair.0].name, &vars[pair.1].name);
        let mut rows = vec![{
            let mut h = vec![format!("x_{na}"), format!("x_{nb}"), "f".into()];
            h.extend((1..=m).map(|j| format!("g{j}")));
            h.push("max_g".into());
            h
        }];
        let ny = slice.ys.len();
        for (c, e) in slice.cells.iter().enumerate() {
            let mut r = vec![num(slice.xs[c / ny]), num(slice.ys[c % ny]), num(e.f)];
            r.extend(e.g.iter().map(|&v| num(v)));
            r.push(if m > 0 { num(e.max_g()) } else { String::new() });
            rows.push(r);
        }
        write_atomic(&dir.join(format!("{stem}.csv")), &rows)?;
        let values: Vec<f64> = slice.cells.iter().map(|e| e.f).collect();
        let infeasible: Vec<bool> = slice.cells.iter().map(|e| e.max_g() > 0.0).collect();
        let marks = req
            .marks
            .iter()
            .map(|(label, pts)| {
                (
                    label.clone(),
                    pts.iter().map(|p| (p[pair.0], p[pair.1])).collect(),
                )
            })
            .collect();
        let title = format!("{}: f over ({na}, {nb})", problem.name());
        let (la, lb) = (
            problem.variable_label(pair.0),
            problem.variable_label(pair.1),
        );
        heat_map(
            &dir.join(format!("{stem}.svg")),
            &HeatMap {
                title: &title,
                subtitle: &fixed_values(problem, pair, &req.base),
                names: (&la, &lb),
                value_label: &problem.objective_label(),
                xs: &slice.xs,
                ys: &slice.ys,
                values: &values,
                infeasible: &infeasible,
                marks,
            },
        )?;
        out.push(slice);
    }
    Ok(out)
}

/// The variables a slice holds fixed and their values, for its plot
/// (empty with two variables): `held at x3 = 1, x4 = -0.5`.
pub fn fixed_values(problem: &dyn Problem, pair: (usize, usize), base: &[f64]) -> String {
    let held: Vec<String> = (problem.variables().iter().zip(base).enumerate())
        .filter(|&(k, _)| k != pair.0 && k != pair.1)
        .map(|(_, (v, x))| format!("{} = {}", v.name, round6(*x)))
        .collect();
    if held.is_empty() {
        String::new()
    } else {
        format!("held at {}", held.join(", "))
    }
}

/// `x` rounded to six significant digits (for titles; files keep `x`).
fn round6(x: f64) -> f64 {
    format!("{x:.5e}").parse().unwrap_or(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explore::problems::Hs22;

    #[test]
    fn grid_covers_the_box_and_matches_direct_evaluation() {
        let p = Hs22::new();
        let s = evaluate_slice(&p, (0, 1), &[0.0, 0.0], 5).unwrap();
        assert_eq!(s.xs, vec![-5.0, -2.5, 0.0, 2.5, 5.0]);
        // Cell (i, j) = (3, 1) is x = (2.5, -2.5): f = 0.25 + 12.25 (closed form).
        assert_eq!(s.cells[3 * 5 + 1].f, 12.5);
        assert_eq!(s.cells[3 * 5 + 1].g, vec![-2.0, 8.75]);
    }
}
