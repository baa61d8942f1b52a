//! MMFD's steps at work: the fitted line search's function calls on the
//! Hock–Schittkowski problems and the SAR problem, the restoration ending
//! only where the violation is stationary, and the polish's slope search.
//!
//! Call counts are snapshots of the current implementation (like diffsol's
//! solver statistics): a change that makes MMFD slower fails here and must
//! update the numbers knowingly.

use plyscape::optimize::mmfd::{self, MmfdOptions};
use plyscape::optimize::testproblems::{self as tp, Analytic};
use plyscape::optimize::{Counted, History, Problem, Termination};

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

/// The paper's problem (studies/sar_optimize.toml, full model, evaluated
/// at the tolerance its `rtol = "auto"` chooses: 1e-7) from its start
/// 55°/−55° with DOT's defaults, as the study's first MMFD run: at most 16
/// function and 5 gradient calls (the paper's DOT run takes 14 f + 4 g),
/// and the optimum of the same problem evaluated at rtol 1e-10
/// (results/sar_accuracy/accuracy.csv, row 1e-10, the certified run:
/// 50.94809287°/−48.90730433°) to 0.01°, and its f to 1e-6: the study
/// normalizes Ψ₀ by its value at the start computed at the tolerance in
/// use, so the reference is Ψ₀(optimum)/Ψ₀(start) both at rtol 1e-10:
/// accuracy.csv's f there, 0.9088906548362731, over noise.csv's f at the
/// start at rtol 1e-10, 0.9999450347938379 (both normalized by the start's
/// Ψ₀ at rtol 1e-6, which cancels). Measured 7e-8 apart. About 2 s in
/// release.
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
        (o.x[0] - 50.94809287).abs() < 0.01 && (o.x[1] + 48.90730433).abs() < 0.01,
        "{o:?}"
    );
    let f_ref = 0.9088906548362731 / 0.9999450347938379;
    assert!((o.f - f_ref).abs() < 1e-6, "{o:?} against {f_ref}");
    assert!(o.g[0] <= MmfdOptions::default().ctmin, "{o:?}");
}

/// The study's whole first run, as `plyscape multistart` makes it: the
/// noise measured at the start (ECNoise, the study's seed 4), MMFD with
/// that allowance, and the end settled (certificate, polish if needed):
/// certified converged within 13 f + 5 g in all. Issue 38's target was
/// 16 f + 5 g. History: with the scene of issue 38 MMFD stopped at the
/// noise at x4 (σ_f = 1.87e-8 at the start); once B4 and B12, locked to
/// the fixed satellite, were built fixed the noise was 2.2e-9 and MMFD
/// took one more step, to a Kuhn–Tucker residual of 5.0e-6 (15 f + 6 g).
/// Since panel 2's group, which stays at rest, is built fixed too
/// (`scene::ground`), the start's noise is 9.1e-9 and MMFD stops at the
/// noise at x4 again: 1.72e-8 of decrease left against an allowance of
/// 2.74e-8 (Kuhn–Tucker residual 1.4e-3, which the exit at the noise does
/// not need). Its f is within the noise allowance of the study's start
/// 3, which reaches the same optimum from elsewhere: 0.9089401593497987
/// (residual 1.2e-4; results/sar_optimize/runs.csv as committed with
/// the bodies at rest). About 2 s in release.
#[test]
fn sar_first_run_is_certified_in_13_f_and_5_g() {
    use plyscape::explore::local::settle::{settle, EndPolicy};
    use plyscape::optimize::kkt::{EndClass, KktTolerances};
    use plyscape::optimize::noise::{estimate, NoiseOptions};
    let study = plyscape::study::Study::load("studies/sar_optimize.toml").unwrap();
    let p = plyscape::explore::problem(&study).unwrap();
    let x0 = [55.0, -55.0];
    let m = estimate(p.as_ref(), &x0, study.meta.seed, &NoiseOptions::default()).unwrap();
    let noise = m.allowance();
    assert!(noise > 0.0 && noise < 1e-6, "{m:?}");
    // The study's method: DOT's preset with CTMIN its feasibility 1e-6.
    let options = MmfdOptions::dot().with_feasibility(1e-6).with_noise(noise);
    // One counter for the run and its settling, as the driver has: the
    // certificate reuses the run's last evaluation with gradients.
    let counted = Counted::new(p.as_ref());
    let o = mmfd::minimize(&counted, &x0, &options, &mut History::default()).unwrap();
    let policy = EndPolicy {
        tolerances: KktTolerances::default(),
        polish: true,
        rescue: true,
        noise,
        noise_g: m.allowance_g(),
    };
    let s = settle(&counted, Some(&x0), o, &policy, &mut History::default());
    let (o, c) = (&s.outcome, s.certificate.as_ref().unwrap());
    println!("SAR run 0: {o:?}\n{c:?}\n{}", s.note());
    assert_eq!(c.class, EndClass::Converged, "{c:?}");
    assert!(o.function_calls <= 13 && o.gradient_calls <= 5, "{o:?}");
    let start3 = 0.9089401593497987;
    assert!((o.f - start3).abs() <= noise * start3.max(1.0), "{o:?}");
    assert!(c.decrease_left.unwrap() <= noise, "{c:?}");
    // The end at the noise is a near-stationary point: Kuhn–Tucker
    // residual measured 1.4e-3 (5.0e-6 when the run took one more step).
    assert!(c.kt_residual.unwrap() <= 2e-3, "{c:?}");
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
/// (0.3, −0.2): the best decrease, 1e-7, is below the noise. Told the
/// noise, the polish leaves the start by the slope and ends at the noise
/// (exit `at_noise`), closer to the minimum.
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
    // The polish told the noise it may meet: the jumps of this f are 5e-7.
    let polish = MmfdOptions::polish().with_noise(1e-6);
    let f_based = MmfdOptions {
        slope_search: false,
        ..polish
    };
    let o = mmfd::minimize(&p, &X0, &f_based, &mut History::default()).unwrap();
    assert_eq!(o.termination, Termination::NoFeasibleDirection, "{o:?}");
    assert_eq!(o.x, X0.to_vec());
    // The slope search leaves the start; then the decrease its curvature
    // model sees left (about 1.1e-8, the pair's curvature 2 exactly) is
    // below the allowance, and the run ends at the noise (step 6): at a
    // third of the start's distance from x*, with a true decrease left
    // (|x − x*|², the noise aside) of 1.1e-8.
    let o = mmfd::minimize(&p, &X0, &polish, &mut History::default()).unwrap();
    assert_eq!(o.termination, Termination::AtNoise, "{o:?}");
    let left = (o.x[0] - 0.3).powi(2) + (o.x[1] + 0.2).powi(2);
    assert!(left < 0.15 * 1e-7 && left > 0.0, "{o:?}");
    // Without the allowance the slope search refuses the jump of 5e-7
    // too: the run stays at the start.
    let exact = MmfdOptions {
        noise: 0.0,
        ..polish
    };
    let o = mmfd::minimize(&p, &X0, &exact, &mut History::default()).unwrap();
    assert_eq!(o.termination, Termination::NoFeasibleDirection, "{o:?}");
    assert_eq!(o.x, X0.to_vec());
}
