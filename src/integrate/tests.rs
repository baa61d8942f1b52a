//! The integrator on a model with a closed form, through the trait.

use super::*;

/// `ẏ = p` below `y = 1`, `ẏ = 2p` above: a piecewise-smooth scalar
/// model with one switching surface `g = y − 1`, independent of `p`.
/// The event state is the piece (0, 1), frozen into the work.
struct Ramp;

impl OdeModel for Ramp {
    type Param = ();
    type Work = usize;
    type Events = usize;
    type Crossing = usize;
    fn work(&self, _n: usize) -> usize {
        0
    }
    fn param_value(&self, _p: ()) -> Option<f64> {
        Some(1.0)
    }
    fn rhs(&self, w: &mut usize, _t: f64, _y: &[f64], p: (&[()], &[f64]), dy: &mut [f64]) {
        let p = p.1.first().copied().unwrap_or(1.0);
        dy[0] = if *w == 0 { p } else { 2.0 * p };
    }
    fn rhs_dir(
        &self,
        w: &mut usize,
        _t: f64,
        _y: &[f64],
        _p: (&[()], &[f64]),
        seeds: (Option<&[f64]>, Option<&[f64]>),
        out: &mut [f64],
    ) {
        // f does not depend on y; ∂f/∂p = 1 or 2.
        let vp = seeds.1.map_or(0.0, |v| v[0]);
        out[0] = if *w == 0 { vp } else { 2.0 * vp };
    }
    fn events(&self, _enabled: bool, _y0: &[f64]) -> usize {
        0
    }
    fn freeze(&self, ev: &usize, w: &mut usize) {
        *w = *ev;
    }
    fn nroots(&self, _ev: &usize) -> usize {
        1
    }
    fn roots(&self, ev: &usize, _w: &mut usize, _t: f64, y: &[f64], g: &mut [f64]) {
        g[0] = if *ev == 0 { y[0] - 1.0 } else { -1.0 };
    }
    fn roots_dir(&self, ev: &usize, _t: f64, _y: &[f64], v: &[f64], g: &mut [f64]) {
        g[0] = if *ev == 0 { v[0] } else { 0.0 };
    }
    fn classify(&self, ev: &usize, _idx: usize, _t: f64, y: &[f64]) -> Option<usize> {
        (*ev == 0 && (y[0] - 1.0).abs() < 1e-8).then_some(1)
    }
    fn switch(&self, ev: &mut usize, c: usize, _t: f64, _y: &[f64]) {
        *ev = c;
    }
    fn crossing_dir(&self, _ev: &usize, _c: usize, _t: f64, _y: &[f64], v: &[f64]) -> f64 {
        v[0]
    }
    fn crossing_label(&self, _ev: &usize, _c: usize) -> String {
        "ramp".into()
    }
}

#[test]
fn piecewise_ramp_and_its_sensitivity_through_the_trait() {
    // Closed form at p = 1 from y(0) = 0: y = p t until the crossing
    // t_e = 1/p, then y = 1 + 2p (t − 1/p) = 2 p t − 1; so y(2) = 3
    // and s = ∂y/∂p = 2t after the event, s(2) = 4 (the jump at t_e
    // takes s from t_e = 1 to 2 t_e = 2: Hiskens & Pai with
    // dt_e/dp = −s⁻/f⁻ = −1 and f⁻ − f⁺ = −1).
    for (method, form) in [
        (Method::Tsit45, SensitivityForm::Staggered),
        (Method::Tsit45, SensitivityForm::Fused),
        (Method::Bdf, SensitivityForm::Staggered),
        (Method::Bdf, SensitivityForm::Fused),
        (Method::Esdirk34, SensitivityForm::Fused),
    ] {
        let opts = Options {
            method,
            rtol: 1e-10,
            atol: 1e-12,
            t0: 0.0,
            times: vec![0.5, 1.5, 2.0],
            events: true,
            sensitivity: form,
        };
        let mut out = Vec::new();
        let stats = integrate_sens(&Ramp, &[0.0], &opts, &[()], |t, y, s| {
            out.push((t, y[0], s[0]));
            Ok(())
        })
        .unwrap();
        assert_eq!(stats.events, 1, "{method:?} {form:?}");
        for (t, y, s) in out {
            let (ye, se) = if t < 1.0 {
                (t, t)
            } else {
                (2.0 * t - 1.0, 2.0 * t)
            };
            assert!((y - ye).abs() < 1e-8, "{method:?} {form:?} y({t}) = {y}");
            assert!((s - se).abs() < 1e-7, "{method:?} {form:?} s({t}) = {s}");
        }
        let mut end = 0.0;
        integrate(&Ramp, &[0.0], &opts, |_, y| {
            end = y[0];
            Ok(())
        })
        .unwrap();
        assert!((end - 3.0).abs() < 1e-8, "{method:?} y(2) = {end}");
    }
}

#[test]
fn output_times_that_do_not_increase_are_named_plainly() {
    let opts = Options {
        method: Method::Tsit45,
        rtol: 1e-6,
        atol: 1e-8,
        t0: 0.0,
        times: vec![1.0, 0.5],
        events: true,
        sensitivity: SensitivityForm::Staggered,
    };
    let e = opts.validate().unwrap_err().to_string();
    assert!(
        e.contains("2 output times from 1 s to 0.5 s") && !e.contains("Some("),
        "{e}"
    );
}
