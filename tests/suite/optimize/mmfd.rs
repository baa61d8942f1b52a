//! MMFD on problems with known optima: five Hock–Schittkowski problems from
//! feasible and infeasible starts, a curved constraint, an active bound, a
//! periodic seam, and Himmelblau's four minima. Optima and their sources
//! are documented on each problem in `plyscape::optimize::testproblems`.
//!
//! Call counts are snapshots of the current implementation (like diffsol's
//! solver statistics): a change that makes MMFD slower fails here and must
//! update the numbers knowingly.

use plyscape::optimize::mmfd::{self, MmfdOptions};
use plyscape::optimize::testproblems::{self as tp, Analytic};
use plyscape::optimize::{History, LocalOutcome, Problem, Termination};

/// Run MMFD and check the optimum to `1e-4` relative in f, the constraints
/// to CTMIN, and that the observer saw every iteration.
fn solve(p: &Analytic, x0: &[f64], options: &MmfdOptions) -> LocalOutcome {
    let mut h = History::default();
    let out = mmfd::minimize(p, x0, options, &mut h).expect("mmfd runs");
    // Relative to |f*| (absolute when f* = 0).
    let scale = if p.f_opt == 0.0 { 1.0 } else { p.f_opt.abs() };
    let rel = (out.f - p.f_opt).abs() / scale;
    assert!(
        rel <= 1e-4,
        "{} from {x0:?}: f = {} vs published {} (rel {rel:.2e}), {out:?}",
        p.name(),
        out.f,
        p.f_opt
    );
    let max_g = out.g.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(max_g <= options.ctmin, "{}: max g = {max_g}", p.name());
    assert!(!matches!(
        out.termination,
        Termination::Infeasible | Termination::MaxIterations
    ));
    check_records(p, x0, &h, &out);
    out
}

/// The records tell the run as `IterRecord` documents: the start first
/// (iteration 0, its one evaluation with gradients), iterations counted
/// up by one (a final check repeats the last number), calls never
/// decreasing, and the last record is the outcome: design, f, g, calls,
/// iterations and the active constraints (g >= the final CT).
fn check_records(p: &Analytic, x0: &[f64], h: &History, out: &LocalOutcome) {
    let first = h.0.first().expect("records");
    let x0: Vec<f64> = p
        .variables()
        .iter()
        .zip(x0)
        .map(|(v, &x)| v.wrap(x))
        .collect();
    assert_eq!(
        (first.iteration, &first.x, first.step),
        (0, &x0, 0.0),
        "{}",
        p.name()
    );
    assert_eq!((first.function_calls, first.gradient_calls), (1, 1));
    assert_eq!(first.f, p.evaluate(&x0, false).unwrap().f);
    for w in h.0.windows(2) {
        let d = w[1].iteration - w[0].iteration;
        assert!(d <= 1, "{}: {:?}", p.name(), w);
        assert!(w[1].function_calls >= w[0].function_calls);
        assert!(w[1].gradient_calls >= w[0].gradient_calls);
        assert!(w[1].ct.unwrap() >= w[0].ct.unwrap());
        assert_eq!(w[1].g.len(), p.n_constraints());
    }
    let last = h.0.last().unwrap();
    assert_eq!(
        (&last.x, last.f, &last.g),
        (&out.x, out.f, &out.g),
        "{}",
        p.name()
    );
    assert_eq!(
        (last.iteration, last.function_calls, last.gradient_calls),
        (out.iterations, out.function_calls, out.gradient_calls),
        "{}",
        p.name()
    );
    assert_eq!(last.active().len(), out.active_constraints, "{}", p.name());
}

/// (iterations, function calls, gradient calls)
fn counts(o: &LocalOutcome) -> (usize, usize, usize) {
    (o.iterations, o.function_calls, o.gradient_calls)
}

#[test]
fn hs21_bound_active() {
    // HS 21: optimum on the bound x1 = 2 with the constraint inactive.
    let p = tp::hs21();
    let d = MmfdOptions::default();
    let o = solve(&p, &p.x0, &d);
    assert_eq!(o.active_side_constraints, 1);
    assert_eq!(o.active_constraints, 0);
    assert!((o.x[0] - 2.0).abs() < 1e-12 && o.x[1].abs() < 1e-6);
    assert_eq!(o.termination, Termination::KuhnTucker);
    assert_eq!(counts(&o), (1, 3, 2));
    // Infeasible start: 10·3 − 30 − 10 < 0 violates the constraint.
    assert!(p.evaluate(&[3.0, 30.0], false).unwrap().g[0] > 0.0);
    let o = solve(&p, &[3.0, 30.0], &d);
    assert_eq!(counts(&o), (4, 14, 5));
}

#[test]
fn hs35_feasible_and_infeasible_starts() {
    let p = tp::hs35();
    let d = MmfdOptions::default();
    let o = solve(&p, &p.x0, &d);
    assert_eq!(o.active_constraints, 1);
    assert_eq!(counts(&o), (7, 12, 7));
    assert!(p.evaluate(&[2.0; 3], false).unwrap().g[0] > 0.0);
    let o = solve(&p, &[2.0; 3], &d);
    assert_eq!(counts(&o), (6, 9, 6));
}

#[test]
fn hs43_curved_constraints_are_followed() {
    // Two curved constraints active at the optimum: every tangent step
    // leaves them and is pulled back.
    let p = tp::hs43();
    let d = MmfdOptions::default();
    let o = solve(&p, &p.x0, &d);
    assert_eq!(o.active_constraints, 2);
    for (xi, oi) in o.x.iter().zip(&p.optima[0]) {
        assert!((xi - oi).abs() < 5e-3, "{:?}", o.x);
    }
    assert_eq!(counts(&o), (5, 20, 5));
    assert!(p.evaluate(&[2.0; 4], false).unwrap().g[0] > 0.0);
    let o = solve(&p, &[2.0; 4], &d);
    assert_eq!(counts(&o), (9, 37, 9));
}

#[test]
fn hs76_linear_constraints_and_bound() {
    let p = tp::hs76();
    let d = MmfdOptions::default();
    let o = solve(&p, &p.x0, &d);
    assert_eq!(o.active_side_constraints, 1); // x3 = 0
    assert_eq!(counts(&o), (7, 12, 7));
    assert!(p.evaluate(&[2.0; 4], false).unwrap().g[0] > 0.0);
    let o = solve(&p, &[2.0; 4], &d);
    assert_eq!(counts(&o), (8, 14, 8));
}

#[test]
fn hs100_seven_variables() {
    // DOT's DELOBJ = 1e-3 and DABOBJ = 1e-4·|f0| stop HS 100 in its flat
    // valley at 2e-4 relative error; the published optimum needs tighter
    // change criteria.
    let p = tp::hs100();
    let d = MmfdOptions {
        delobj: 1e-6,
        dabobj: Some(1e-6),
        ..MmfdOptions::default()
    };
    let o = solve(&p, &p.x0, &d);
    assert_eq!(o.active_constraints, 2);
    assert_eq!(counts(&o), (17, 58, 19));
    let x_bad = [3.0, 3.0, 0.0, 5.0, 0.0, 1.0, 1.0];
    assert!(p.evaluate(&x_bad, false).unwrap().g[0] > 0.0);
    let o = solve(&p, &x_bad, &d);
    assert_eq!(counts(&o), (15, 48, 16));
}

#[test]
fn disc_constraint_following() {
    // f = x + y on the unit disc; closed-form optimum −√2.
    let p = tp::disc();
    let d = MmfdOptions::default();
    let o = solve(&p, &p.x0, &d);
    assert_eq!(o.active_constraints, 1);
    assert_eq!(counts(&o), (6, 29, 7));
    // Infeasible start outside the disc: restoration first.
    let o = solve(&p, &[1.5, 1.5], &d);
    assert_eq!(o.termination, Termination::KuhnTucker);
    assert_eq!(counts(&o), (5, 11, 7));
}

#[test]
fn periodic_variables_wrap_across_the_seam() {
    let p = tp::seam();
    let mut h = History::default();
    let o = mmfd::minimize(&p, &p.x0, &MmfdOptions::default(), &mut h).unwrap();
    assert!(o.f < 1e-6, "{o:?}");
    // Closed-form optimum (88°, −85°): reached across ±90°, not at a bound.
    assert!(
        (o.x[0] - 88.0).abs() < 0.05 && (o.x[1] + 85.0).abs() < 0.05,
        "{:?}",
        o.x
    );
    assert_eq!(o.active_side_constraints, 0);
    // Every recorded design is inside the box.
    for r in &h.0 {
        assert!(r.x.iter().all(|&t| (-90.0..90.0).contains(&t)));
    }
    assert_eq!(counts(&o), (4, 10, 4));
}

#[test]
fn himmelblau_multistart_finds_all_four_minima() {
    let p = tp::himmelblau();
    let d = MmfdOptions {
        delobj: 1e-8,
        dabobj: Some(1e-10),
        ..MmfdOptions::default()
    };
    let mut found = [0usize; 4];
    let mut converged = 0;
    let grid: Vec<f64> = (0..6).map(|i| -4.5 + 1.8 * i as f64).collect();
    for &a in &grid {
        for &b in &grid {
            let o = mmfd::minimize(&p, &[a, b], &d, &mut History::default()).unwrap();
            for (k, m) in p.optima.iter().enumerate() {
                if (o.x[0] - m[0]).abs() < 1e-3 && (o.x[1] - m[1]).abs() < 1e-3 {
                    found[k] += 1;
                    converged += 1;
                    assert!(o.f < 1e-8, "{o:?}");
                }
            }
        }
    }
    assert!(found.iter().all(|&c| c > 0), "minima found: {found:?}");
    assert!(
        converged >= 32,
        "{converged} of 36 starts reached a minimum"
    );
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

/// The line search's frugality on the Hock–Schittkowski problems of
/// `benches/mmfd_peers.rs` with DOT's defaults (issue 23): at most 79
/// function calls in all (110 with the first line search,
/// results/mmfd_peers/line_search_before.csv, counted then with a call
/// for every evaluation), a median of at most 2 function calls per
/// gradient call (the target; 3.17 before), and every optimum to
/// 3.1e-4 relative in f (the published optima are cited in
/// `plyscape::optimize::testproblems`).
#[test]
fn hs_function_calls_with_the_fitted_step() {
    let d = MmfdOptions::default();
    let mut ratios = Vec::new();
    let mut total = 0;
    for p in [tp::hs21(), tp::hs35(), tp::hs43(), tp::hs76(), tp::hs100()] {
        let o = mmfd::minimize(&p, &p.x0, &d, &mut History::default()).unwrap();
        let rel = (o.f - p.f_opt).abs() / p.f_opt.abs().max(1.0);
        // DOT's change exits (DELOBJ 1e-3) stop HS 100 in its flat
        // valley at 3.1e-4 (2.0e-4 with the first line search); the polish
        // takes it to 2e-9 (results/mmfd_peers).
        assert!(rel <= 3.1e-4, "{}: rel {rel:.3e}", p.name());
        println!(
            "{}: {} f, {} g, rel {rel:.3e}",
            p.name(),
            o.function_calls,
            o.gradient_calls
        );
        total += o.function_calls;
        ratios.push(o.function_calls as f64 / o.gradient_calls as f64);
    }
    ratios.sort_by(f64::total_cmp);
    assert!(total <= 79, "{total} function calls");
    assert!(ratios[2] <= 2.0, "median {} ({ratios:?})", ratios[2]);
}

/// The paper's problem (studies/sar_optimize.toml, full model) from its
/// start 55°/−55° with DOT's defaults, as the study's first MMFD run:
/// at most 16 function and 5 gradient calls (issue 23's target; 24 f + 5 g
/// with the first line search, 12 f + 5 g measured), and the best design
/// known, found independently by IPOP-CMA-ES and made strictly feasible
/// by the polish (the first sweep's results/sar_explore/comparison.csv, of
/// 2026-11-26 in the repository's history, row `cmaes,strict`:
/// 50.95189259307°/−48.92301018699°, f = 0.9089481415), to 0.01° and 1e-6
/// in f. (The sweep of 2026-11-27 ends all three methods at
/// 50.9497°/−48.9097°, f = 0.90894853: the same optimum within the
/// evaluation noise.) About 2 s in release.
#[test]
fn sar_from_55_minus_55_in_16_function_and_5_gradient_calls() {
    let study = plyscape::study::Study::load("studies/sar_optimize.toml").unwrap();
    let p = plyscape::explore::problem(&study).unwrap();
    let o = mmfd::minimize(
        p.as_ref(),
        &[55.0, -55.0],
        &MmfdOptions::default(),
        &mut History::default(),
    )
    .unwrap();
    println!(
        "SAR: {:?} f = {:.10} g = {:?}, {} f + {} g, {}",
        o.x, o.f, o.g, o.function_calls, o.gradient_calls, o.termination
    );
    assert!(o.function_calls <= 16 && o.gradient_calls <= 5, "{o:?}");
    assert!(
        (o.x[0] - 50.95189259307).abs() < 0.01 && (o.x[1] + 48.92301018699).abs() < 0.01,
        "{o:?}"
    );
    assert!((o.f - 0.9089481415).abs() < 1e-6, "{o:?}");
    assert!(o.g[0] <= MmfdOptions::default().ctmin, "{o:?}");
}

/// The restoration on a violation with many local minima
/// (`testproblems::ripple`, SAR-like): from a 12 × 12 grid of starts on the
/// torus, every run that ends infeasible ends at a stationary point of the
/// violation (its Kuhn–Tucker test, `optimize::kkt`), and MMFD reaches the
/// feasible set from at least as many starts as a pure steepest descent on
/// the violation (`explore::local::violation::descend`) from the same starts.
/// Before restorations that stall switched to descent on the violation, a
/// stall rule (three Newton restorations lowering the violation by less
/// than 1 %) ended runs at non-stationary points here (residuals up to
/// 1.8e-2). Measured: 44 and 32 of 144 starts reach the feasible set.
#[test]
fn restoration_ends_only_where_the_violation_is_stationary() {
    use plyscape::explore::local::violation::descend;
    use plyscape::optimize::kkt::{certify_at, KktTolerances};
    let p = tp::ripple();
    let d = MmfdOptions::default();
    let n = 12;
    let (mut feasible_mmfd, mut feasible_descent) = (0, 0);
    let pi = std::f64::consts::PI;
    for i in 0..n {
        for j in 0..n {
            let at = |k: usize| -pi + (k as f64 + 0.5) * 2.0 * pi / n as f64;
            let x0 = [at(i), at(j)];
            let o = mmfd::minimize(&p, &x0, &d, &mut plyscape::optimize::NoObserver).unwrap();
            if o.g[0] <= d.ctmin {
                feasible_mmfd += 1;
            } else {
                assert_eq!(o.termination, Termination::Infeasible, "{x0:?}");
                let (_, c) = certify_at(&p, &o.x, &KktTolerances::default()).unwrap();
                assert_eq!(
                    c.violation_stationary,
                    Some(true),
                    "{x0:?} ends at {:?}, residual {:?}",
                    o.x,
                    c.violation_residual
                );
            }
            if descend(&p, &x0, d.ctmin).unwrap().1.max_g() <= d.ctmin {
                feasible_descent += 1;
            }
        }
    }
    assert!(
        feasible_mmfd >= feasible_descent,
        "{feasible_mmfd} vs {feasible_descent}"
    );
    assert_eq!((feasible_mmfd, feasible_descent), (44, 32));
}

/// The polish's slope search (module doc of `optimize::mmfd`, step 5b)
/// leaves an end that an f-based line search cannot: the start (0.3003,
/// −0.1999) of `f = (x1 − 0.3)² + (x2 + 0.2)²` sits 5e-7 below every other
/// design (a jump of f's noise in its favour, as MMFD's ends on the SAR
/// problem sit where the adaptive integrator's step sequence favours
/// them), while the exact gradient still points to the minimum at
/// (0.3, −0.2): the best decrease, 1e-7, is below the noise.
#[test]
fn the_polish_leaves_a_noise_minimum_by_the_slope() {
    const X0: [f64; 2] = [0.3003, -0.1999];
    fn k(x: &[f64]) -> (f64, Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let noise = if x == X0 { 0.0 } else { 5e-7 };
        let (a, b) = (x[0] - 0.3, x[1] + 0.2);
        (
            a * a + b * b + noise,
            vec![],
            vec![2.0 * a, 2.0 * b],
            vec![],
        )
    }
    let p = Analytic {
        name: "noisy bowl".into(),
        variables: vec![
            plyscape::optimize::Variable::bounded("x1", -1.0, 1.0).unwrap(),
            plyscape::optimize::Variable::bounded("x2", -1.0, 1.0).unwrap(),
        ],
        n_constraints: 0,
        kernel: k,
        x0: X0.to_vec(),
        optima: vec![vec![0.3, -0.2]],
        f_opt: 5e-7,
    };
    // Scaled gradient at the start: 2 (range) × 2 × (3e-4, 1e-4), |.| =
    // 1.26e-3, above the polish's Kuhn–Tucker exit 5e-5.
    let f_based = MmfdOptions {
        slope_search: false,
        ..MmfdOptions::polish()
    };
    let o = mmfd::minimize(&p, &X0, &f_based, &mut History::default()).unwrap();
    assert_eq!(o.termination, Termination::NoFeasibleDirection, "{o:?}");
    assert_eq!(o.x, X0.to_vec());
    let o = mmfd::minimize(&p, &X0, &MmfdOptions::polish(), &mut History::default()).unwrap();
    assert_eq!(o.termination, Termination::KuhnTucker, "{o:?}");
    // |∇f| scaled <= 5e-5 means |x − x*| <= 1.25e-5.
    assert!(
        (o.x[0] - 0.3).abs() < 1.3e-5 && (o.x[1] + 0.2).abs() < 1.3e-5,
        "{o:?}"
    );
}
