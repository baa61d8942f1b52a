//! Merge local optima that are the same design.
//!
//! Only certified runs (class `converged`: feasible, Kuhn–Tucker
//! conditions met; see [`crate::optimize::kkt`]) are optima; the others
//! keep an empty optimum id and are counted by class
//! ([`crate::explore::persist::tables::ClassCounts`]).
//!
//! Two run results are the same optimum when every coordinate differs by at
//! most `x_tolerance` times its variable's range (on the circle for periodic
//! variables, so 89.9° and −89.9° are 0.2° apart) and their objectives differ
//! by at most `f_tolerance · max(1, |f|)`.
//!
//! Method: sort the results by `(f, start index)` and sweep once; each
//! result joins the first optimum whose representative (its best member) is
//! within tolerance, else it founds a new optimum. The order is fixed by the
//! data alone, so the clusters do not depend on the order in which runs
//! finished, on the thread count or on sharding.

use crate::explore::persist::tables::RunRecord;
use crate::optimize::kkt::EndClass;
use crate::optimize::Variable;

/// Tolerances of the clustering (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Per-coordinate distance as a fraction of the variable's range.
    pub x: f64,
    /// Objective difference relative to `max(1, |f|)`.
    pub f: f64,
    /// A design is feasible when `max g <= feasibility`.
    pub feasibility: f64,
}

/// One distinct local optimum.
#[derive(Debug, Clone, PartialEq)]
pub struct Optimum {
    /// Id, 0 for the best (feasible first, then by `f`).
    pub id: usize,
    /// Design of the best member.
    pub x: Vec<f64>,
    /// Its objective.
    pub f: f64,
    /// Its constraints.
    pub g: Vec<f64>,
    /// Whether it satisfies the constraints within the tolerance.
    pub feasible: bool,
    /// Runs that reached it.
    pub count: usize,
    /// `count` / number of runs that finished (with or without error).
    pub basin_share: f64,
    /// Start index of the best member.
    pub best_start: usize,
    /// Mean function calls of the runs that reached it.
    pub mean_function_calls: f64,
    /// Mean gradient calls of the runs that reached it.
    pub mean_gradient_calls: f64,
    /// The noise of f and g measured at `x` (`[multistart] noise =
    /// "measured"`; `None` otherwise).
    pub noise: Option<crate::optimize::noise::Measured>,
}

/// Largest periodic-aware coordinate distance between `a` and `b`, each
/// divided by its variable's range.
pub fn scaled_distance(vars: &[Variable], a: &[f64], b: &[f64]) -> f64 {
    vars.iter()
        .zip(a.iter().zip(b))
        .map(|(v, (&p, &q))| v.difference(p, q).abs() / (v.upper - v.lower))
        .fold(0.0, f64::max)
}

/// Is the run a certified optimum (a result whose certificate says
/// `converged`)?
pub fn certified(r: &RunRecord) -> bool {
    r.result.is_some()
        && r.certificate
            .as_ref()
            .is_some_and(|c| c.class == EndClass::Converged)
}

/// Cluster the certified runs (`runs` in any order); sets `optimum` on
/// each certified record (clears it on the others) and returns the optima
/// sorted by id.
pub fn cluster(vars: &[Variable], runs: &mut [RunRecord], tol: Tolerances) -> Vec<Optimum> {
    let total = runs.len();
    for r in runs.iter_mut() {
        r.optimum = None;
    }
    let mut order: Vec<usize> = (0..runs.len()).filter(|&i| certified(&runs[i])).collect();
    let key = |i: usize| runs[i].result.as_ref().map_or(f64::INFINITY, |r| r.f);
    order.sort_by(|&a, &b| {
        key(a)
            .total_cmp(&key(b))
            .then(runs[a].start.cmp(&runs[b].start))
    });
    // members[c] lists run indices; members[c][0] is the representative.
    let mut members: Vec<Vec<usize>> = Vec::new();
    for &i in &order {
        let r = runs[i].result.as_ref().expect("filtered");
        let found = members.iter().position(|m| {
            let rep = runs[m[0]].result.as_ref().expect("filtered");
            scaled_distance(vars, &rep.x, &r.x) <= tol.x
                && (rep.f - r.f).abs() <= tol.f * rep.f.abs().max(1.0)
        });
        match found {
            Some(c) => members[c].push(i),
            None => members.push(vec![i]),
        }
    }
    let optima: Vec<Optimum> = members
        .iter()
        .map(|m| {
            let rep = &runs[m[0]];
            let r = rep.result.as_ref().expect("filtered");
            let n = m.len() as f64;
            Optimum {
                id: 0,
                x: r.x.clone(),
                f: r.f,
                g: r.g.clone(),
                feasible: r.max_g() <= tol.feasibility,
                count: m.len(),
                basin_share: m.len() as f64 / total as f64,
                best_start: rep.start,
                mean_function_calls: m
                    .iter()
                    .map(|&i| runs[i].function_calls as f64)
                    .sum::<f64>()
                    / n,
                mean_gradient_calls: m
                    .iter()
                    .map(|&i| runs[i].gradient_calls as f64)
                    .sum::<f64>()
                    / n,
                noise: None,
            }
        })
        .collect();
    // Feasible optima first, then by f (stable: ties keep sweep order).
    let mut idx: Vec<usize> = (0..optima.len()).collect();
    idx.sort_by(|&a, &b| {
        optima[b]
            .feasible
            .cmp(&optima[a].feasible)
            .then(optima[a].f.total_cmp(&optima[b].f))
            .then(optima[a].best_start.cmp(&optima[b].best_start))
    });
    let mut sorted = Vec::with_capacity(optima.len());
    for (id, &c) in idx.iter().enumerate() {
        for &i in &members[c] {
            runs[i].optimum = Some(id);
        }
        let mut o = optima[c].clone();
        o.id = id;
        sorted.push(o);
    }
    sorted
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explore::persist::tables::RunResult;

    fn rec(start: usize, x: Vec<f64>, f: f64) -> RunRecord {
        let certificate = Some(crate::optimize::kkt::Certificate {
            class: EndClass::Converged,
            max_g: f64::NEG_INFINITY,
            kt_residual: Some(0.0),
            multipliers: vec![],
            violation_residual: None,
            violation_stationary: None,
            decrease_left: None,
            at_noise: None,
        });
        RunRecord {
            certificate,
            polish: String::new(),
            start,
            x0: x.clone(),
            result: Some(RunResult { x, f, g: vec![] }),
            exit: "test".into(),
            iterations: 1,
            function_calls: 10 + start,
            gradient_calls: 5,
            wall_seconds: 0.0,
            optimum: None,
        }
    }

    #[test]
    fn clusters_across_the_periodic_seam() {
        let vars = vec![
            Variable::periodic("t1", -90.0, 180.0).unwrap(),
            Variable::periodic("t2", -90.0, 180.0).unwrap(),
        ];
        let tol = Tolerances {
            x: 1e-3,
            f: 1e-6,
            feasibility: 0.0,
        };
        // 89.95 and -89.95 are 0.1 deg = 5.6e-4 of the 180 deg range apart
        // on the circle (< 1e-3: same optimum).
        let mut runs = vec![
            rec(0, vec![89.95, 10.0], -1.0),
            rec(1, vec![-89.95, 10.0], -1.0),
            rec(2, vec![0.0, 10.0], -0.5),
            rec(3, vec![89.99, -89.99], -1.0),
        ];
        let optima = cluster(&vars, &mut runs, tol);
        assert_eq!(optima.len(), 3);
        assert_eq!(runs[0].optimum, runs[1].optimum);
        assert_eq!(optima[0].count, 2);
        assert_eq!(optima[0].best_start, 0);
        assert_eq!(optima[0].mean_function_calls, 10.5);
        assert_eq!(optima[0].basin_share, 0.5);
        assert_eq!(runs[2].optimum, Some(2));
        // Non-periodic variables: the same numbers are 179.9 apart.
        let flat = vec![
            Variable::bounded("a", -90.0, 90.0).unwrap(),
            Variable::bounded("b", -90.0, 90.0).unwrap(),
        ];
        let optima = cluster(&flat, &mut runs, tol);
        assert_eq!(optima.len(), 4);
        assert_ne!(runs[0].optimum, runs[1].optimum);
    }

    #[test]
    fn cluster_ids_do_not_depend_on_input_order() {
        let vars = vec![Variable::bounded("a", 0.0, 1.0).unwrap()];
        let tol = Tolerances {
            x: 1e-2,
            f: 1e-3,
            feasibility: 0.0,
        };
        let mut a: Vec<RunRecord> = (0..20)
            .map(|i| rec(i, vec![(i % 3) as f64 * 0.3], (i % 3) as f64))
            .collect();
        let mut b = a.clone();
        b.reverse();
        let oa = cluster(&vars, &mut a, tol);
        let ob = cluster(&vars, &mut b, tol);
        assert_eq!(oa, ob);
        b.reverse();
        assert_eq!(a, b);
    }
}
