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

use crate::error::{Error, Result};
use crate::explore::persist::tables::num;
use crate::optimize::{Evaluation, Problem};
use crate::report::csv::read_csv_lines;
use crate::report::{heat_map, HeatMap, Progress};
use rayon::prelude::*;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

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

/// How [`run`] runs: threads, resume, progress, spot checks.
#[derive(Debug, Clone, Copy)]
pub struct MapOptions {
    /// Worker threads (>= 1).
    pub threads: usize,
    /// Continue the tables already on disk (`--resume`).
    pub resume: bool,
    /// No progress bar.
    pub quiet: bool,
    /// Cells read back that are evaluated again on resume
    /// ([`crate::explore::persist::fingerprint::sample`]).
    pub checks: usize,
}

/// The header of a slice's table.
fn header(problem: &dyn Problem, pair: (usize, usize)) -> Vec<String> {
    let vars = problem.variables();
    let (na, nb) = (&vars[pair.0].name, &vars[pair.1].name);
    let mut h = vec![format!("x_{na}"), format!("x_{nb}"), "f".into()];
    h.extend((1..=problem.n_constraints()).map(|j| format!("g{j}")));
    h.push("max_g".into());
    h
}

/// One row of a slice's table: the cell's coordinates and values.
fn row(x: f64, y: f64, e: &Evaluation, m: usize) -> Vec<String> {
    let mut r = vec![num(x), num(y), num(e.f)];
    r.extend(e.g.iter().map(|&v| num(v)));
    r.push(if m > 0 { num(e.max_g()) } else { String::new() });
    r
}

/// The cells of a slice table written before (`--resume`): the complete
/// rows in grid order. A torn last line (no newline, wrong field count or
/// a field that is not a number) is cut off the file, with a warning; a
/// row that is not the grid's cell at its place is refused (the grid
/// changed), as is a header of another problem.
fn read_cells(
    path: &Path,
    header: &[String],
    xs: &[f64],
    ys: &[f64],
    m: usize,
) -> Result<Vec<Evaluation>> {
    let Some(lines) = read_csv_lines(path, header, "is not this study's map")? else {
        return Ok(Vec::new());
    };
    let mut keep = lines.keep;
    let ny = ys.len();
    let mut cells = Vec::new();
    for (i, (r, at)) in lines.rows.iter().enumerate() {
        let k = i + 1; // the header is record 0
        let nums: Option<Vec<f64>> = (r.len() == header.len())
            .then(|| (0..3 + m).map(|i| r.get(i)?.parse().ok()).collect())
            .flatten();
        let Some(v) = nums else {
            if i + 1 == lines.rows.len() {
                keep = *at;
                break;
            }
            return Err(Error::csv(path, format!("line {}: not a map row", k + 1)));
        };
        let c = k - 1;
        let on_grid = c < xs.len() * ny
            && v[0].to_bits() == xs[c / ny].to_bits()
            && v[1].to_bits() == ys[c % ny].to_bits();
        if !on_grid {
            return Err(Error::input(
                "--resume",
                format!("{} (line {})", path.display(), k + 1),
                format!(
                    "the cells of this map's grid in order, but the row is at ({}, {}): \
                     the grid (resolution, bounds or pairs) changed; rerun without --resume",
                    v[0], v[1]
                ),
            ));
        }
        cells.push(Evaluation {
            f: v[2],
            g: v[3..].to_vec(),
            grad_f: None,
            grad_g: None,
        });
    }
    if keep < lines.len {
        crate::report::csv::cut_torn_line(path, keep)?;
        eprintln!(
            "warning: {}: removed a torn last line ({} bytes) left by an interrupted map; \
             that cell is evaluated again",
            path.display(),
            lines.len - keep
        );
    }
    Ok(cells)
}

/// Evaluate every requested slice with `opts.threads` threads and write the
/// CSV and SVG files into `dir`. Returns the slices.
///
/// Each slice's table is written as it is computed: cells are evaluated in
/// parallel but appended in grid order, one line per cell, flushed, so an
/// interrupted map leaves a prefix of its final table (and at worst a torn
/// last line). With `opts.resume` the cells already in the table are read
/// back (a torn line is cut, a row off the grid refused),
/// `opts.checks` of them are evaluated again
/// ([`crate::explore::persist::fingerprint::reproduces`]), and only the missing cells are
/// computed: the final table is byte for byte the uninterrupted one.
pub fn run(
    problem: &dyn Problem,
    req: &MapRequest,
    opts: &MapOptions,
    dir: &Path,
) -> Result<Vec<Slice>> {
    let vars = problem.variables();
    let n = vars.len();
    let m = problem.n_constraints();
    let pool = crate::explore::context::thread_pool(opts.threads)?;
    let res = req.resolution;
    let progress = Progress::new("map", (req.pairs.len() * res * res) as u64, opts.quiet);
    let mut out = Vec::new();
    for &pair in &req.pairs {
        let stem = if n == 2 {
            "map".to_string()
        } else {
            format!("map_{}_{}", pair.0, pair.1)
        };
        let path = dir.join(format!("{stem}.csv"));
        let (a, b) = (&vars[pair.0], &vars[pair.1]);
        let xs = axis(a.lower, a.upper, res);
        let ys = axis(b.lower, b.upper, res);
        let head = header(problem, pair);
        let mut cells = if opts.resume {
            read_cells(&path, &head, &xs, &ys, m)?
        } else {
            Vec::new()
        };
        let design = |c: usize| {
            let mut x = req.base.clone();
            x[pair.0] = xs[c / res];
            x[pair.1] = ys[c % res];
            x
        };
        let fs: Vec<Option<f64>> = cells.iter().map(|e| Some(e.f)).collect();
        for c in crate::explore::persist::fingerprint::sample(&fs, opts.checks) {
            let e = &cells[c];
            if let Some((f, g)) = crate::explore::persist::fingerprint::reproduces(
                problem,
                &design(c),
                (e.f, &e.g),
                false,
            )? {
                return Err(Error::input(
                    "--resume",
                    format!("{} (line {})", path.display(), c + 2),
                    format!(
                        "cells that this study reproduces, but at x = {:?} the table has f = {:e}, \
                         g = {:?} and an evaluation now gives f = {f:e}, g = {g:?} (not within {:e} \
                         relative): the table was edited or the evaluations changed; rerun without \
                         --resume",
                        design(c),
                        e.f,
                        e.g,
                        crate::explore::persist::fingerprint::RECHECK_RTOL
                    ),
                ));
            }
        }
        let mut table = crate::report::csv::Appender::open(&path, &head, cells.is_empty())?;
        progress.set(progress_pos(&out, res) + cells.len() as u64, "");
        let first = cells.len();
        evaluate_from(problem, &pool, first, res * res, &design, |c, e| {
            table.row(&row(xs[c / res], ys[c % res], &e, m))?;
            cells.push(e);
            progress.inc(&format!("slice {}/{}", out.len() + 1, req.pairs.len()));
            Ok(())
        })?;
        let slice = Slice {
            pair,
            xs,
            ys,
            cells,
        };
        plot(problem, req, &slice, dir, &stem)?;
        out.push(slice);
    }
    progress.finish();
    Ok(out)
}

/// Cells of the slices done before, for the progress bar.
fn progress_pos(done: &[Slice], res: usize) -> u64 {
    (done.len() * res * res) as u64
}

/// Evaluate the cells `first..count` of a slice (`design(c)` is cell `c`'s
/// design) in `pool`, handing each to `write` in increasing order of `c`
/// as soon as every cell before it is done. Workers take cells in order
/// from a shared counter, so the cells waiting for an earlier one are at
/// most about one per thread. An error (of an evaluation or of `write`)
/// stops the launching of further cells and is returned.
fn evaluate_from(
    problem: &dyn Problem,
    pool: &rayon::ThreadPool,
    first: usize,
    count: usize,
    design: &(dyn Fn(usize) -> Vec<f64> + Sync),
    mut write: impl FnMut(usize, Evaluation) -> Result<()>,
) -> Result<()> {
    let next = AtomicUsize::new(first);
    let stop = AtomicBool::new(false);
    let threads = pool.current_num_threads();
    let (tx, rx) = std::sync::mpsc::channel::<(usize, Result<Evaluation>)>();
    let mut failure = None;
    std::thread::scope(|ts| {
        let (next, stop) = (&next, &stop);
        ts.spawn(move || {
            pool.scope(|s| {
                for _ in 0..threads {
                    let tx = tx.clone();
                    s.spawn(move |_| loop {
                        if stop.load(Ordering::SeqCst) {
                            break;
                        }
                        let c = next.fetch_add(1, Ordering::SeqCst);
                        if c >= count {
                            break;
                        }
                        if tx.send((c, evaluate_cell(problem, &design(c)))).is_err() {
                            break;
                        }
                    });
                }
            });
            drop(tx);
        });
        let mut waiting = std::collections::BTreeMap::new();
        let mut due = first;
        for (c, e) in rx {
            if failure.is_some() {
                continue;
            }
            match e {
                Err(e) => {
                    failure = Some(e);
                    stop.store(true, Ordering::SeqCst);
                }
                Ok(e) => {
                    waiting.insert(c, e);
                    while let Some(e) = waiting.remove(&due) {
                        if let Err(e) = write(due, e) {
                            failure = Some(e);
                            stop.store(true, Ordering::SeqCst);
                            break;
                        }
                        due += 1;
                    }
                }
            }
        }
    });
    failure.map_or(Ok(()), Err)
}

/// One cell: f and g at `x`, refused when not finite.
fn evaluate_cell(problem: &dyn Problem, x: &[f64]) -> Result<Evaluation> {
    let e = problem.evaluate(x, false)?;
    if !(e.f.is_finite() && e.g.iter().all(|v| v.is_finite())) {
        return Err(Error::numerical(
            "explore::map",
            format!("non-finite f = {} or g = {:?} at x = {x:?}", e.f, e.g),
        ));
    }
    Ok(e)
}

/// The heat map of one slice, `<stem>.svg`.
fn plot(
    problem: &dyn Problem,
    req: &MapRequest,
    slice: &Slice,
    dir: &Path,
    stem: &str,
) -> Result<()> {
    let pair = slice.pair;
    let vars = problem.variables();
    let (na, nb) = (&vars[pair.0].name, &vars[pair.1].name);
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
    )
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
    use crate::explore::problem::problems::Hs22;

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
