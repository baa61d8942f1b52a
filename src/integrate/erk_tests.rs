//! The explicit pairs stepped here (`super::erk`) on the harmonic
//! oscillator `ẍ = −ω² x`, `x(0) = 1`, `ẋ(0) = 0`, whose solution
//! `x = cos ωt`, `v = ẋ = −ω sin ωt` and sensitivities
//! `∂x/∂ω = −t sin ωt`, `∂v/∂ω = −sin ωt − ωt cos ωt` are closed forms.

use super::erk::Erk;
use super::pair::Pair;
use super::stepper::Stepper;
use super::*;
use diffsol::{FaerMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason, Tableau, Vector};

const OMEGA: f64 = 2.0;

/// The oscillator as a model: state `(x, v)`, one parameter `ω`, no
/// events (one constant root function, as the trait asks).
struct Oscillator;

impl OdeModel for Oscillator {
    type Param = ();
    type Work = ();
    type Events = ();
    type Crossing = ();
    fn work(&self, _n: usize) {}
    fn param_value(&self, _p: ()) -> Option<f64> {
        Some(OMEGA)
    }
    fn rhs(&self, _w: &mut (), _t: f64, y: &[f64], p: (&[()], &[f64]), dy: &mut [f64]) {
        let w = p.1.first().copied().unwrap_or(OMEGA);
        dy[0] = y[1];
        dy[1] = -w * w * y[0];
    }
    fn rhs_dir(
        &self,
        _w: &mut (),
        _t: f64,
        y: &[f64],
        p: (&[()], &[f64]),
        seeds: (Option<&[f64]>, Option<&[f64]>),
        out: &mut [f64],
    ) {
        let w = p.1.first().copied().unwrap_or(OMEGA);
        let (vx, vv) = seeds.0.map_or((0.0, 0.0), |v| (v[0], v[1]));
        let vp = seeds.1.map_or(0.0, |v| v[0]);
        out[0] = vv;
        out[1] = -w * w * vx - 2.0 * w * y[0] * vp;
    }
    fn events(&self, _enabled: bool, _y0: &[f64]) {}
    fn freeze(&self, _ev: &(), _w: &mut ()) {}
    fn nroots(&self, _ev: &()) -> usize {
        1
    }
    fn roots(&self, _ev: &(), _w: &mut (), _t: f64, _y: &[f64], g: &mut [f64]) {
        g[0] = 1.0;
    }
    fn roots_dir(&self, _ev: &(), _t: f64, _y: &[f64], _v: &[f64], g: &mut [f64]) {
        g[0] = 0.0;
    }
    fn classify(&self, _ev: &(), _idx: usize, _t: f64, _y: &[f64]) -> Option<()> {
        None
    }
    fn switch(&self, _ev: &mut (), _c: (), _t: f64, _y: &[f64]) {}
    fn crossing_dir(&self, _ev: &(), _c: (), _t: f64, _y: &[f64], _v: &[f64]) -> f64 {
        0.0
    }
    fn crossing_label(&self, _ev: &(), _c: ()) -> String {
        "none".into()
    }
}

fn exact(t: f64) -> [f64; 2] {
    [(OMEGA * t).cos(), -OMEGA * (OMEGA * t).sin()]
}

fn options(method: Method, rtol: f64, times: Vec<f64>) -> Options {
    Options {
        method,
        rtol,
        atol: rtol * 1e-3,
        t0: 0.0,
        times,
        events: true,
        sensitivity: SensitivityForm::Fused,
    }
}

/// The largest error of `x` at the output times (every 0.25 s over
/// 10 s) and the steps taken.
fn max_error(method: Method, rtol: f64) -> (f64, usize) {
    let times = (1..=40).map(|k| 0.25 * k as f64).collect();
    let mut worst = 0.0f64;
    let opts = options(method, rtol, times);
    let stats = integrate(&Oscillator, &[1.0, 0.0], &opts, |t, y| {
        worst = worst.max((y[0] - exact(t)[0]).abs());
        Ok(())
    })
    .unwrap();
    (worst, stats.steps)
}

#[test]
fn vern65_errs_in_proportion_to_the_tolerance_in_fewer_steps() {
    // The global error follows the tolerance (within a factor 30 of
    // rtol here) and falls much faster than the steps grow (order 6:
    // N^(−6) once asymptotic); tsit45 needs more steps at each tolerance
    // (measured: 59/104 steps at 1e-6 to 234/580 at 1e-10, with 4-8x
    // smaller errors).
    let rtols = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10];
    for rtol in rtols {
        let (v, t) = (
            max_error(Method::Vern65, rtol),
            max_error(Method::Tsit45, rtol),
        );
        assert!(
            v.0 < 30.0 * rtol && v.0 > 1e-3 * rtol,
            "rtol {rtol:e}: vern65 {v:?}"
        );
        assert!(
            v.1 < t.1,
            "rtol {rtol:e}: vern65 {v:?} against tsit45 {t:?}"
        );
    }
    let (coarse, fine) = (
        max_error(Method::Vern65, 1e-6),
        max_error(Method::Vern65, 1e-10),
    );
    let order = -(fine.0 / coarse.0).ln() / (fine.1 as f64 / coarse.1 as f64).ln();
    assert!(
        order > 5.5,
        "error against steps: order {order:.2} {coarse:?} {fine:?}"
    );
}

#[test]
fn the_dense_output_is_as_accurate_as_the_steps() {
    // Between steps (θ = 0.1 .. 0.9 of every step) the order-5 extension
    // errs no more than a few times the solution at the steps' ends.
    let opts = options(Method::Vern65, 1e-9, vec![10.0]);
    let (mut at_ends, mut between) = (0.0f64, 0.0f64);
    let mut steps = 0;
    let mut watch = |step: &Step<'_>| {
        let (a, b) = step.span;
        steps += 1;
        let (y, _) = step.at(b)?;
        at_ends = at_ends.max((y[0] - exact(b)[0]).abs());
        for j in 1..10 {
            let t = a + (b - a) * j as f64 / 10.0;
            let (y, _) = step.at(t)?;
            between = between.max(
                (y[0] - exact(t)[0])
                    .abs()
                    .max((y[1] - exact(t)[1]).abs() / OMEGA),
            );
        }
        Ok(())
    };
    integrate_stepped(&Oscillator, &[1.0, 0.0], &opts, |_, _| Ok(()), &mut watch).unwrap();
    assert!(steps > 20, "{steps} steps");
    assert!(
        at_ends > 0.0 && at_ends < 1e-7,
        "error at the ends {at_ends:e}"
    );
    assert!(
        between < 3.0 * at_ends,
        "between steps {between:e}, at the ends {at_ends:e}"
    );
}

#[test]
fn fused_sensitivities_of_vern65_match_the_closed_form() {
    let times: Vec<f64> = (1..=10).map(|k| k as f64).collect();
    let opts = options(Method::Vern65, 1e-10, times);
    let mut worst = 0.0f64;
    integrate_sens(&Oscillator, &[1.0, 0.0], &opts, &[()], |t, y, s| {
        let (wt, (sn, cs)) = (OMEGA * t, (OMEGA * t).sin_cos());
        let ds = [-t * sn, -sn - wt * cs];
        worst = worst.max((s[0] - ds[0]).abs().max((s[1] - ds[1]).abs()) / (1.0 + t * OMEGA));
        assert!((y[0] - cs).abs() < 1e-7, "x({t}) = {}", y[0]);
        Ok(())
    })
    .unwrap();
    assert!(worst > 0.0 && worst < 1e-7, "sensitivity error {worst:e}");
    // The staggered form is diffsol's own and has no pair stepped here.
    let staggered = Options {
        sensitivity: SensitivityForm::Staggered,
        ..opts
    };
    let e = integrate_sens(
        &Oscillator,
        &[1.0, 0.0],
        &staggered,
        &[()],
        |_, _, _| Ok(()),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("integrator.sensitivity"), "{e}");
}

#[test]
fn of_tableau_steps_as_diffsol() {
    // The driver with tsit45's tableau takes the steps of diffsol's own
    // tsit45 solver (the same first step, norm, controller and stop).
    let problem = OdeBuilder::<FaerMat<f64>>::new()
        .rtol(1e-8)
        .atol([1e-11])
        .rhs_implicit(
            |y: &[f64], _p: &[f64], _t: f64, dy: &mut [f64]| {
                dy[0] = y[1];
                dy[1] = -OMEGA * OMEGA * y[0];
            },
            |_y: &[f64], _p: &[f64], _t: f64, v: &[f64], out: &mut [f64]| {
                out[0] = v[1];
                out[1] = -OMEGA * OMEGA * v[0];
            },
        )
        .init(
            |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&[1.0, 0.0]),
            2,
        )
        .build()
        .unwrap();
    let mut theirs = problem.tsit45().unwrap();
    theirs.set_stop_time(10.0).unwrap();
    let mut ours = Erk::new(&problem, Pair::of_tableau(&Tableau::tsit45())).unwrap();
    ours.set_stop_time(10.0).unwrap();
    let (mut steps, mut t0) = (0, 0.0);
    loop {
        let (a, b) = (theirs.step().unwrap(), ours.step().unwrap());
        steps += 1;
        let (ta, tb) = (theirs.state().t, ours.time());
        // To rounding: the error estimate is a sum with cancellation (of
        // h kᵢ against an estimate 10⁻⁸ of it), added in another order
        // here, so its last digits and the next step's length differ.
        assert!(
            (ta - tb).abs() <= 1e-6 * ta,
            "step {steps}: t {ta} against {tb}"
        );
        // The same dense output (tsit45's own interpolant) mid-step.
        let tm = 0.5 * (t0 + ta);
        let (ya, yb) = (
            theirs.interpolate(tm).unwrap(),
            ours.interpolate(tm).unwrap(),
        );
        assert!(
            (ya[0] - yb[0]).abs() < 1e-12,
            "at {tm}: {ya:?} against {yb:?}"
        );
        t0 = ta;
        match (a, b) {
            (OdeSolverStopReason::TstopReached, OdeSolverStopReason::TstopReached) => break,
            (OdeSolverStopReason::InternalTimestep, OdeSolverStopReason::InternalTimestep) => {}
            other => panic!("step {steps}: {other:?}"),
        }
    }
    let (ya, yb) = (theirs.state().y.clone_as_vec(), ours.state());
    assert!((ya[0] - yb[0]).abs() < 1e-12, "{ya:?} against {yb:?}");
    assert_eq!(theirs.get_statistics().number_of_steps, ours.stats().steps);
    assert!(steps > 50, "{steps} steps");
}
