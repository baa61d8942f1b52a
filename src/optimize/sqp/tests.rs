//! SQP on the Hock–Schittkowski problems of [`crate::optimize::testproblems`]
//! (optima from Hock & Schittkowski 1981, as cited there) and HS 22.

use super::*;
use crate::optimize::testproblems::{self, Analytic};
use crate::optimize::{NoObserver, Variable};

/// HS 22: `f = (x1 − 2)² + (x2 − 1)²`, `x1 + x2 <= 2`, `x1² <= x2`;
/// optimum (1, 1), f* = 1 (HS 22), both constraints active.
fn hs22() -> Analytic {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        (
            (x[0] - 2.0).powi(2) + (x[1] - 1.0).powi(2),
            vec![x[0] + x[1] - 2.0, x[0] * x[0] - x[1]],
            vec![2.0 * (x[0] - 2.0), 2.0 * (x[1] - 1.0)],
            vec![vec![1.0, 1.0], vec![2.0 * x[0], -1.0]],
        )
    }
    Analytic {
        name: "hs22".into(),
        variables: vec![
            Variable::bounded("x1", -5.0, 5.0).unwrap(),
            Variable::bounded("x2", -5.0, 5.0).unwrap(),
        ],
        n_constraints: 2,
        kernel: k,
        x0: vec![2.0, 2.0],
        optima: vec![vec![1.0, 1.0]],
        f_opt: 1.0,
    }
}

/// The six problems with the starts of the peer comparison.
fn cases() -> Vec<(Analytic, Vec<f64>)> {
    vec![
        (testproblems::hs21(), vec![2.0, -1.0]),
        (testproblems::hs35(), vec![0.5, 0.5, 0.5]),
        (testproblems::hs43(), vec![0.0; 4]),
        (testproblems::hs76(), vec![0.5; 4]),
        (
            testproblems::hs100(),
            vec![1.0, 2.0, 0.0, 4.0, 0.0, 1.0, 1.0],
        ),
        (hs22(), vec![2.0, 2.0]),
    ]
}

/// Every run ends feasible within 1e-6 (relative to max(|f*|, 1)) of the
/// published optimum, with a Kuhn–Tucker or change exit.
#[test]
fn hock_schittkowski_runs_reach_the_published_optima() {
    let mut total = (0, 0);
    for (p, x0) in cases() {
        let out = minimize(&p, &x0, &SqpOptions::default(), &mut NoObserver).unwrap();
        let err = (out.f - p.f_opt).abs() / p.f_opt.abs().max(1.0);
        eprintln!(
            "{}: f {} err {:.1e} max g {:.1e} {} f + {} g, {} it, {}",
            p.name,
            out.f,
            err,
            out.g.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            out.function_calls,
            out.gradient_calls,
            out.iterations,
            out.termination
        );
        total.0 += out.function_calls;
        total.1 += out.gradient_calls;
        assert!(err <= 1e-6, "{}: f = {} against {}", p.name, out.f, p.f_opt);
        assert!(
            out.g.iter().all(|&g| g <= 1e-6),
            "{}: g = {:?}",
            p.name,
            out.g
        );
    }
    eprintln!("total {} f + {} g", total.0, total.1);
    // Measured 54 f + 51 g with the first step a fiftieth of the range (50
    // f + 48 g with a tenth, 54 f + 53 g before the model's self-scaling);
    // scipy 1.17.1's SLSQP on the same problems and starts takes 114 f +
    // 53 g (scripts/peers/slsqp_hs.py, results/sqp_peers/slsqp.csv). A
    // rise past these pins is a regression.
    assert!(total.0 <= 54 && total.1 <= 51, "{total:?}");
}

/// A line search never accepts a step that leaves the design or the merit
/// unchanged: from x = 1 along a direction far below the round-off of x,
/// every trial is x itself, and Armijo's bound rounds to φ(0).
#[test]
fn a_step_below_round_off_is_no_step() {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        (x[0], vec![], vec![1.0], vec![])
    }
    let p = Analytic {
        name: "linear".into(),
        variables: vec![Variable::bounded("x", -10.0, 10.0).unwrap()],
        n_constraints: 0,
        kernel: k,
        x0: vec![1.0],
        optima: vec![vec![-10.0]],
        f_opt: -10.0,
    };
    let mut solver = Sqp::new(&p, &[1.0], SqpOptions::default()).unwrap();
    let mut ap = ArgminProblem::new(Counted::new(&p));
    solver.start(&mut ap).unwrap();
    let cur = solver.current.clone().unwrap();
    let found = solver.line_search(&mut ap, &cur, &[-1e-20]).unwrap();
    assert!(
        found.is_none(),
        "accepted {:?}",
        found.map(|(a, q)| (a, q.x))
    );
    // A real step is still taken.
    let found = solver.line_search(&mut ap, &cur, &[-0.01]).unwrap();
    assert!(found.is_some_and(|(_, q)| q.f < cur.f));
}
