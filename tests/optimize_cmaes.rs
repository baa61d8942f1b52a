//! IPOP-CMA-ES on functions with known minima (sources on each problem in
//! `plyscape::optimize::testproblems`), a constrained problem, a periodic
//! seam, and reproducibility across thread counts.

use plyscape::optimize::cmaes::{self, CmaesOptions};
use plyscape::optimize::testproblems as tp;
use plyscape::optimize::{GlobalOutcome, History, NoObserver, Termination};

fn run(p: &tp::Analytic, options: &CmaesOptions) -> GlobalOutcome {
    cmaes::minimize(p, options, &mut NoObserver).expect("cmaes runs")
}

#[test]
fn rosenbrock_2_and_10_dimensions_to_1e8() {
    // Minimum f* = 0 at (1, …, 1) (Rosenbrock 1960).
    for (n, budget) in [(2, 5_000), (10, 30_000)] {
        let p = tp::rosenbrock(n);
        let o = run(
            &p,
            &CmaesOptions {
                seed: 7,
                max_evaluations: budget,
                target: Some(1e-8),
                ..CmaesOptions::default()
            },
        );
        assert_eq!(o.termination, Termination::TargetReached, "n = {n}: {o:?}");
        assert!(o.f <= 1e-8 && o.feasible);
        assert!(o.x.iter().all(|&x| (x - 1.0).abs() < 1e-3), "{:?}", o.x);
        assert!(o.function_calls <= budget);
    }
}

#[test]
fn rastrigin_global_minimum_in_9_of_10_seeds() {
    // Global minimum f* = 0 at the origin among ~11ⁿ local minima
    // (Rastrigin 1974). Budgets: 10 000 evaluations in 2-D, 60 000 in 5-D.
    for (n, budget) in [(2, 10_000), (5, 60_000)] {
        let p = tp::rastrigin(n);
        let mut hits = 0;
        for seed in 0..10 {
            let o = run(
                &p,
                &CmaesOptions {
                    seed,
                    max_evaluations: budget,
                    target: Some(1e-8),
                    ..CmaesOptions::default()
                },
            );
            assert!(o.function_calls <= budget);
            if o.f <= 1e-8 && o.x.iter().all(|x| x.abs() < 1e-3) {
                hits += 1;
            }
        }
        assert!(hits >= 9, "rastrigin{n}: {hits} of 10 seeds");
    }
}

#[test]
fn constrained_optimum_by_feasibility_rules() {
    // HS 35: f* = 1/9 at (4/3, 7/9, 4/9) with the constraint active.
    let p = tp::hs35();
    let o = run(
        &p,
        &CmaesOptions {
            seed: 3,
            max_evaluations: 6_000,
            ..CmaesOptions::default()
        },
    );
    assert!(o.feasible && o.g[0] <= 0.0, "{o:?}");
    assert!((o.f - p.f_opt).abs() <= 1e-6 * p.f_opt, "{o:?}");
    for (x, xs) in o.x.iter().zip(&p.optima[0]) {
        assert!((x - xs).abs() < 1e-3, "{:?}", o.x);
    }
    // Disc: f* = −√2 on a curved constraint (closed form).
    let p = tp::disc();
    let o = run(
        &p,
        &CmaesOptions {
            seed: 3,
            max_evaluations: 6_000,
            ..CmaesOptions::default()
        },
    );
    assert!(o.feasible, "{o:?}");
    assert!((o.f - p.f_opt).abs() <= 1e-6 * p.f_opt.abs(), "{o:?}");
}

#[test]
fn periodic_optimum_across_the_seam() {
    // Closed-form optimum (88°, −85°), f* = 0, across the ±90° seam.
    let p = tp::seam();
    let mut h = History::default();
    let o = cmaes::minimize(
        &p,
        &CmaesOptions {
            seed: 11,
            max_evaluations: 3_000,
            x0: Some(vec![-80.0, 80.0]),
            sigma0: 0.1,
            ..CmaesOptions::default()
        },
        &mut h,
    )
    .unwrap();
    assert!(o.f < 1e-10, "{o:?}");
    assert!((o.x[0] - 88.0).abs() < 1e-3 && (o.x[1] + 85.0).abs() < 1e-3);
    // One record per generation, σ recorded, counts increasing.
    assert_eq!(h.0.len(), o.generations);
    assert!(h.0.iter().all(|r| r.step > 0.0 && r.step.is_finite()));
    assert!(h
        .0
        .windows(2)
        .all(|w| w[1].function_calls > w[0].function_calls));
}

#[test]
fn same_seed_same_result_on_1_and_2_threads() {
    let p = tp::hs35();
    let options = CmaesOptions {
        seed: 42,
        max_evaluations: 3_000,
        ..CmaesOptions::default()
    };
    let mut runs = Vec::new();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut h = History::default();
        let o = pool
            .install(|| cmaes::minimize(&p, &options, &mut h))
            .unwrap();
        runs.push((o, h));
    }
    let (a, ha) = &runs[0];
    let (b, hb) = &runs[1];
    assert_eq!(a, b);
    assert_eq!(a.f.to_bits(), b.f.to_bits());
    assert_eq!(ha.0.len(), hb.0.len());
    for (ra, rb) in ha.0.iter().zip(&hb.0) {
        assert_eq!(ra.step.to_bits(), rb.step.to_bits());
        assert_eq!(ra.x, rb.x);
    }
    // A different seed gives a different run.
    let other = cmaes::minimize(
        &p,
        &CmaesOptions {
            seed: 43,
            ..options.clone()
        },
        &mut NoObserver,
    )
    .unwrap();
    assert_ne!(other.x, a.x);
}

#[test]
fn budget_is_respected_and_bad_options_rejected() {
    let p = tp::rastrigin(5);
    let o = run(
        &p,
        &CmaesOptions {
            seed: 0,
            max_evaluations: 500,
            ..CmaesOptions::default()
        },
    );
    assert!(o.function_calls <= 500);
    assert_eq!(o.termination, Termination::MaxEvaluations);
    let e = cmaes::minimize(
        &p,
        &CmaesOptions {
            sigma0: -1.0,
            ..CmaesOptions::default()
        },
        &mut NoObserver,
    )
    .unwrap_err();
    assert_eq!(e.exit_code(), 2);
}
