//! Kernel identities of flexible bodies: Jacobian-vector products (dual
//! numbers) against central differences, the fused multi-lane right-hand
//! side against one lane at a time, and design seeds lifting the basis.

use super::scenes::{panel_scene, spinup, study};
use num_dual::Dual64;
use plyscape::mbs::{System, Workspace};
use plyscape::scene::load_scene;

#[test]
fn flexible_jacobian_vector_product_matches_central_differences() {
    // The spin-up scene (fixed joint on a flexible node, revolute, load) at
    // a state with deformation and velocities: J v from one Dual64
    // evaluation vs central finite differences.
    let sys = System::new(load_scene(&spinup()).unwrap().model);
    let mut y = sys.initial_state();
    let n = y.len();
    for (k, v) in y.iter_mut().enumerate() {
        *v += 1e-3 * ((k as f64) * 0.37).sin();
    }
    sys.project(0.0, &mut y).unwrap();
    let dir: Vec<f64> = (0..n).map(|k| ((k as f64) * 1.3).cos()).collect();
    let yd: Vec<Dual64> = (0..n).map(|k| Dual64::new(y[k], dir[k])).collect();
    let mut fd = vec![Dual64::from(0.0); n];
    sys.rhs(0.5, &yd, &mut fd, &mut Workspace::empty());
    let h = 1e-6;
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let mut ws = Workspace::empty();
    let yp: Vec<f64> = (0..n).map(|k| y[k] + h * dir[k]).collect();
    let ym: Vec<f64> = (0..n).map(|k| y[k] - h * dir[k]).collect();
    sys.rhs(0.5, &yp, &mut fp, &mut ws);
    sys.rhs(0.5, &ym, &mut fm, &mut ws);
    let scale = fd.iter().map(|v| v.eps.abs()).fold(0.0, f64::max);
    let err = (0..n)
        .map(|k| ((fp[k] - fm[k]) / (2.0 * h) - fd[k].eps).abs())
        .fold(0.0, f64::max);
    println!("max |Jv| {scale:e}, max |Jv − FD| {err:e}");
    assert!(err < 1e-6 * scale, "JVP error {err:e} (scale {scale:e})");
}

#[test]
fn multi_lane_evaluations_equal_one_lane_at_a_time() {
    // The fused sensitivity right-hand side (`rhs_lanes`: one multi-lane
    // dual evaluation of width 1, 2, 4 or 8 for up to 8 lanes, chunks of
    // 8 beyond) against the plain right-hand side and one single-lane
    // `rhs_dir` per lane, for 1 to 9 lanes (parameters: the bodies'
    // masses, repeated when there are more lanes than bodies, each lane seeding
    // its own parameter and state direction).
    use plyscape::integrate::OdeModel;
    use plyscape::mbs::Param;
    let sys = System::new(load_scene(&spinup()).unwrap().model);
    let mut y = sys.initial_state();
    let n = y.len();
    for (k, v) in y.iter_mut().enumerate() {
        *v += 1e-3 * ((k as f64) * 0.37).sin();
    }
    sys.project(0.0, &mut y).unwrap();
    let bodies: Vec<usize> = sys.moving.clone();
    let mut w = sys.work(n);
    for np in 1..=9 {
        let names: Vec<Param> = (0..np)
            .map(|i| Param::Mass(bodies[i % bodies.len()]))
            .collect();
        let p: Vec<f64> = names.iter().map(|q| sys.param_value(*q).unwrap()).collect();
        let lanes: Vec<f64> = (0..n * np).map(|k| ((k as f64) * 0.71).cos()).collect();
        let (mut dy, mut dl) = (vec![0.0; n], vec![0.0; n * np]);
        let duals = sys.rhs_lanes(&mut w, 0.5, &y, (&names, &p), &lanes, &mut dy, &mut dl);
        assert_eq!(duals, if np <= 4 { 1 } else { np.div_ceil(8) });
        let mut f = vec![0.0; n];
        OdeModel::rhs(&sys, &mut w, 0.5, &y, (&names, &p), &mut f);
        let scale = f.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        for k in 0..n {
            assert!(
                (dy[k] - f[k]).abs() <= 1e-12 * scale,
                "f[{k}] with {np} lanes"
            );
        }
        for i in 0..np {
            let mut e = vec![0.0; np];
            e[i] = 1.0;
            let mut one = vec![0.0; n];
            let s = &lanes[i * n..(i + 1) * n];
            sys.rhs_dir(&mut w, 0.5, &y, (&names, &p), (Some(s), Some(&e)), &mut one);
            let sc = one.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            for k in 0..n {
                let err = (dl[i * n + k] - one[k]).abs();
                assert!(err <= 1e-12 * sc, "lane {i} of {np}, row {k}: {err:e}");
            }
        }
    }
}

#[test]
fn design_seeds_with_the_same_variables_but_new_values_lift_the_basis_again() {
    // Regression: the lifted invariants and node shapes are cached while
    // a body's design seeds stay the same. num-dual's `==` compares real
    // parts only (zero for every seed), so two directions seeding the same
    // design variables with other values compared equal and the second
    // evaluation used the first one's lifted basis. Here one workspace
    // takes direction (0.3, 0.7) and then (0.5, -0.2) in the plies
    // (θ₁₄, θ₂₃): the second result must equal a fresh workspace's, and,
    // the product being linear in the direction, 0.5 e₁ − 0.2 e₂.
    use plyscape::integrate::OdeModel;
    let text = panel_scene(30.0).replace(
        "sensitivities = [\"panel.design.theta_1_4\"]",
        "sensitivities = [\"panel.design.theta_1_4\", \"panel.design.theta_2_3\"]",
    );
    let scene = load_scene(&study(&text)).unwrap();
    let names: Vec<_> = scene.params.iter().map(|(_, p)| *p).collect();
    assert_eq!(names.len(), 2);
    let sys = System::new(scene.model);
    let mut y = sys.initial_state();
    let n = y.len();
    for (k, v) in y.iter_mut().enumerate() {
        *v += 1e-3 * ((k as f64) * 0.37).sin();
    }
    sys.project(0.0, &mut y).unwrap();
    let p: Vec<f64> = names.iter().map(|q| sys.param_value(*q).unwrap()).collect();
    let dir = |w: &mut _, vp: [f64; 2]| {
        let mut out = vec![0.0; n];
        sys.rhs_dir(w, 0.2, &y, (&names, &p), (None, Some(&vp)), &mut out);
        out
    };
    let mut reused = sys.work(n);
    let first = dir(&mut reused, [0.3, 0.7]);
    let second = dir(&mut reused, [0.5, -0.2]);
    let fresh = dir(&mut sys.work(n), [0.5, -0.2]);
    let e1 = dir(&mut sys.work(n), [1.0, 0.0]);
    let e2 = dir(&mut sys.work(n), [0.0, 1.0]);
    let scale = fresh.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0, "the design seeds move the right-hand side");
    let moved = first
        .iter()
        .zip(&fresh)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        moved > 1e-3 * scale,
        "the two directions give different products"
    );
    for k in 0..n {
        assert!(
            (second[k] - fresh[k]).abs() <= 1e-13 * scale,
            "row {k}: reused workspace {:e}, fresh {:e}",
            second[k],
            fresh[k]
        );
        let lin = 0.5 * e1[k] - 0.2 * e2[k];
        // Linear to the rounding of the regularised constraint-space
        // solve (measured 5e-12 of the largest entry).
        assert!(
            (fresh[k] - lin).abs() <= 1e-10 * scale,
            "row {k}: {:e} against 0.5 e1 - 0.2 e2 = {lin:e}",
            fresh[k]
        );
    }
}
