//! `convergence.svg`, drawn by `evolve` and `compare`.

use super::search;
use crate::error::Result;
use crate::explore::multistart;
use crate::optimize::cmaes::Restarts;
use crate::optimize::Problem;
use std::path::Path;

/// (runs in start order) and each evolution's best-so-far per generation.
/// `convergence.svg`: multistart best-so-far over cumulative function calls
/// (runs in start order) and each evolution's best-so-far per generation.
pub fn convergence_plot(
    problem: &dyn Problem,
    dir: &Path,
    ms: Option<&multistart::Report>,
    evs: &[search::Report],
) -> Result<()> {
    let mut curves = Vec::new();
    if let Some(ms) = ms {
        let (mut calls, mut best) = (0usize, f64::INFINITY);
        let mut pts = Vec::new();
        for r in &ms.runs {
            calls += r.function_calls;
            if let Some(res) = &r.result {
                best = best.min(res.f);
            }
            if best.is_finite() {
                pts.push((calls as f64, best));
            }
        }
        curves.push(crate::report::Curve {
            label: "multistart (best so far)".into(),
            points: pts,
        });
    }
    for ev in evs {
        // One schedule keeps the labels it always had (IPOP as plain
        // CMA-ES); several are named in full.
        let name = match ev.restarts {
            Restarts::Ipop if evs.len() == 1 => "CMA-ES",
            r => r.solver_name(),
        };
        curves.push(crate::report::Curve {
            label: format!("{name} (best so far)"),
            points: ev
                .generations
                .iter()
                .filter(|g| g.best_f.is_finite())
                .map(|g| (g.function_calls as f64, g.best_f))
                .collect(),
        });
    }
    // Log–log: the gap of each best-so-far to the lowest f any method
    // found, raised to a floor (marked in the plot) so that a gap of zero,
    // the winner's final point, shows.
    let lowest = curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.1))
        .fold(f64::INFINITY, f64::min);
    let floor = 1e-12 * lowest.abs().max(1.0);
    for c in &mut curves {
        for p in &mut c.points {
            p.1 = (p.1 - lowest).max(floor);
        }
    }
    let y = format!(
        "best f − lowest f found ({lowest:.6e}), {}",
        problem.objective_label()
    );
    crate::report::line_plot_floored(
        &dir.join("convergence.svg"),
        &crate::report::Axes {
            title: &format!(
                "{}: best objective vs function calls (log–log)",
                problem.name()
            ),
            x: "function calls [-]",
            y: &y,
            scale: crate::report::Scale::LogLog,
        },
        &curves,
        floor,
    )
}
