//! MMFD as a component: run by argmin's executor, its records reaching the
//! observer as they are made, and its input, numerical and infeasibility
//! errors.

use plyscape::optimize::mmfd::{self, MmfdOptions};
use plyscape::optimize::testproblems::{self as tp, Analytic};
use plyscape::optimize::{History, Problem, Termination};

/// The engine is a genuine argmin solver: argmin's own Executor drives it
/// to the same optimum as `minimize` (HS 35, f* = 1/9).
#[test]
fn argmin_executor_runs_the_mmfd_solver() {
    use argmin::core::{Executor, State};
    use plyscape::optimize::driver::OptState;
    use plyscape::optimize::Counted;
    let p = tp::hs35();
    let d = MmfdOptions::default();
    let solver = mmfd::Mmfd::new(&p, &p.x0, d.clone()).unwrap();
    let res = Executor::new(Counted::new(&p), solver)
        .configure(|s: OptState| s.max_iters(50))
        .run()
        .unwrap();
    let direct = mmfd::minimize(&p, &p.x0, &d, &mut History::default()).unwrap();
    let x = res.state().get_param().unwrap();
    assert_eq!(x, &direct.x);
    assert!((res.state().get_cost() - 1.0 / 9.0).abs() < 1e-4);
}

#[test]
fn each_record_reaches_the_observer_when_it_is_made() {
    // An observer that times records (iterations.csv's wall column) must
    // receive each one before the solver works on: the start's record
    // after its one evaluation, each iteration's before the next
    // iteration's gradient evaluation. Seen through the problem's own
    // count of evaluations at the moment a record arrives.
    use plyscape::optimize::{Counted, IterRecord, Observer};
    struct AtArrival<'a> {
        counted: &'a Counted<'a>,
        seen: Vec<(usize, usize)>,
    }
    impl Observer for AtArrival<'_> {
        fn observe(&mut self, r: &IterRecord) {
            self.seen
                .push((r.function_calls, self.counted.function_calls()));
        }
    }
    let p = tp::hs43();
    let counted = Counted::new(&p);
    let mut obs = AtArrival {
        counted: &counted,
        seen: Vec::new(),
    };
    let o = mmfd::minimize(&counted, &p.x0, &MmfdOptions::default(), &mut obs).unwrap();
    assert!(o.iterations > 2);
    assert_eq!(obs.seen[0], (1, 1), "the start arrives alone");
    for (made, arrived) in &obs.seen {
        assert_eq!(made, arrived, "{:?}", obs.seen);
    }
}

#[test]
fn bad_input_is_an_input_error() {
    let p = tp::hs35();
    let bad = MmfdOptions {
        ct: 0.1,
        ..MmfdOptions::default()
    };
    let e = mmfd::minimize(&p, &p.x0, &bad, &mut History::default()).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    let d = MmfdOptions::default();
    let e = mmfd::minimize(&p, &[1.0], &d, &mut History::default()).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    let e = mmfd::minimize(&p, &[f64::NAN, 0.0, 0.0], &d, &mut History::default()).unwrap_err();
    assert_eq!(e.exit_code(), 2);
}

/// A problem that returns NaN beyond x > 1 and too few constraint values
/// on request: the solver reports a numerical error instead of panicking.
struct Broken {
    vars: Vec<plyscape::optimize::Variable>,
    short_g: bool,
}

impl Problem for Broken {
    fn variables(&self) -> &[plyscape::optimize::Variable] {
        &self.vars
    }
    fn n_constraints(&self) -> usize {
        1
    }
    fn evaluate(
        &self,
        x: &[f64],
        gradients: bool,
    ) -> plyscape::Result<plyscape::optimize::Evaluation> {
        let f = if x[0] > 1.0 { f64::NAN } else { -x[0] };
        let g = if self.short_g { vec![] } else { vec![-1.0] };
        Ok(plyscape::optimize::Evaluation {
            f,
            g,
            grad_f: gradients.then(|| vec![-1.0]),
            grad_g: gradients.then(|| vec![vec![0.0]]),
        })
    }
}

#[test]
fn broken_problems_give_numerical_errors() {
    let vars = vec![plyscape::optimize::Variable::bounded("x", 0.0, 3.0).unwrap()];
    for short_g in [false, true] {
        let p = Broken {
            vars: vars.clone(),
            short_g,
        };
        let e = mmfd::minimize(&p, &[0.5], &MmfdOptions::default(), &mut History::default())
            .unwrap_err();
        assert_eq!(e.exit_code(), 3, "{e}");
    }
}

/// g = 1 − x <= 0 cannot hold for x in [−2, 0]: the restoration moves reach
/// the least-violating design x = 0 (closed form) and MMFD reports
/// `Infeasible` instead of looping.
#[test]
fn infeasible_problem_is_reported() {
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        (
            x[0] * x[0],
            vec![1.0 - x[0]],
            vec![2.0 * x[0]],
            vec![vec![-1.0]],
        )
    }
    let p = Analytic {
        name: "empty".into(),
        variables: vec![plyscape::optimize::Variable::bounded("x", -2.0, 0.0).unwrap()],
        n_constraints: 1,
        kernel: k,
        x0: vec![-1.5],
        optima: vec![],
        f_opt: f64::NAN,
    };
    let o = mmfd::minimize(&p, &p.x0, &MmfdOptions::default(), &mut History::default()).unwrap();
    assert_eq!(o.termination, Termination::Infeasible);
    assert!(o.x[0].abs() < 1e-9, "{o:?}");
    assert!(o.function_calls < 20);
}
