//! Forward sensitivities (direct differentiation with exact dual-number
//! products) against central finite differences of the simulation.
use crate::common::scenes::{scene, scene_spec, shipped_scene};
use plyscape::integrate::{integrate, integrate_sens, Method, Options, SensitivityForm};
use plyscape::mbs::{Force, Model, Param, System};

/// A rod pendulum (pin about y at the origin) with gravity, a spring-damper
/// from its tip to a ground point, and a rotational spring-damper-actuator
/// on the pin with a one-segment law `M = 0.2 + 1.5 (0.3 − θ)`.
const SCENE: &str = r#"
[scene]
effects = ["gravity", "springs", "damping", "actuators", "quadratic_velocity"]
[[scene.bodies]]
name = "rod"
mass = 1.2
com = [0.5, 0.0, 0.0]
inertia = [[1e-3, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]]
[[scene.joints]]
name = "pin"
type = "revolute"
body_i = "ground"
body_j = "rod"
point = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
[[scene.markers]]
name = "tip"
body = "rod"
point = [1.0, 0.0, 0.0]
[[scene.markers]]
name = "anchor"
body = "ground"
point = [1.2, 0.0, 0.5]
[[scene.forces]]
type = "spring"
marker_i = "tip"
marker_j = "anchor"
stiffness = 40.0
damping = 0.8
length = 0.3
[[scene.forces]]
type = "actuator"
joint = "pin"
damping = 0.05
segments = [{ lower = -10.0, upper = 10.0, value = 0.2, slope = 1.5, anchor = 0.3 }]
[scene.integrator]
t_end = 1.0
dt_out = 1.0
"#;

fn model() -> Model {
    scene(SCENE).model
}

fn options(method: Method) -> Options {
    Options {
        method,
        rtol: 1e-11,
        atol: 1e-13,
        t0: 0.0,
        times: vec![1.0],
        events: true,
        sensitivity: SensitivityForm::Staggered,
    }
}

fn final_state(model: Model, method: Method) -> Vec<f64> {
    let sys = System::new(model);
    let mut y0 = sys.initial_state();
    sys.project(0.0, &mut y0).unwrap();
    let mut out = vec![];
    integrate(&sys, &y0, &options(method), |_, y| {
        out = y.to_vec();
        Ok(())
    })
    .unwrap();
    out
}

#[test]
fn sensitivities_match_central_differences() {
    let m = model();
    let spring = m
        .forces
        .iter()
        .position(|f| matches!(f, Force::SpringDamper { .. }))
        .unwrap();
    let act = m
        .forces
        .iter()
        .position(|f| matches!(f, Force::Rotational { .. }))
        .unwrap();
    let params = [
        Param::Stiffness(spring),
        Param::Damping(spring),
        Param::Damping(act),
        Param::Mass(0),
        Param::Anchor(act, 0),
    ];
    // Both forms of the sensitivities: staggered and fused (J s + ∂f/∂p in
    // one dual evaluation per lane and stage or Newton iterate; the
    // implicit methods with the block-diagonal Newton matrix).
    for (method, form) in [
        (Method::Bdf, SensitivityForm::Staggered),
        (Method::Bdf, SensitivityForm::Fused),
        (Method::Esdirk34, SensitivityForm::Fused),
        (Method::Tsit45, SensitivityForm::Staggered),
        (Method::Tsit45, SensitivityForm::Fused),
    ] {
        let sys = System::new(m.clone());
        let mut y0 = sys.initial_state();
        sys.project(0.0, &mut y0).unwrap();
        let n = y0.len();
        let mut sens = vec![];
        let opts = Options {
            sensitivity: form,
            ..options(method)
        };
        let stats = integrate_sens(&sys, &y0, &opts, &params, |t, _y, s| {
            if t == 1.0 {
                sens = s.to_vec();
            }
            Ok(())
        })
        .unwrap();
        println!("{method:?} {form:?}: {stats:?}");
        for (i, p) in params.iter().enumerate() {
            let v = p.value(&m).unwrap();
            let h = 1e-4 * v.abs();
            let (mut mp, mut mm) = (m.clone(), m.clone());
            p.set(&mut mp, v + h);
            p.set(&mut mm, v - h);
            let (yp, ym) = (final_state(mp, method), final_state(mm, method));
            let lane = &sens[i * n..(i + 1) * n];
            let scale = lane.iter().map(|x| x.abs()).fold(0.0, f64::max);
            let err = (0..n)
                .map(|k| ((yp[k] - ym[k]) / (2.0 * h) - lane[k]).abs())
                .fold(0.0, f64::max);
            println!("  {p:?}: |dy/dp| {scale:.3e}, |FD − sens| {err:.3e}");
            assert!(scale > 1e-6, "{p:?}: sensitivity vanishes");
            // Measured at most 2.2e-7 of |dy/dp| (ESDIRK fused, Mass(0));
            // bound 6e-7.
            assert!(
                err < 6e-7 * scale,
                "{p:?}: relative error {:e}",
                err / scale
            );
        }
    }
}

/// BDF's two sensitivity forms compared directly on the pendulum above
/// (rtol 1e-11): the fused lanes (block-diagonal Newton matrix, the
/// states' own LU on every lane) and the staggered ones (diffsol's
/// sensitivity equations) take the same steps, since neither controls the
/// error of the lanes, and the lanes agree to a small multiple of rtol
/// relative to the largest |dy/dp| of each parameter. The difference is
/// the lanes' own integration error (the corrector of each form stops at a
/// different iterate), not rounding.
#[test]
fn bdf_fused_sensitivities_equal_the_staggered_ones() {
    let m = model();
    let spring = m
        .forces
        .iter()
        .position(|f| matches!(f, Force::SpringDamper { .. }))
        .unwrap();
    let act = m
        .forces
        .iter()
        .position(|f| matches!(f, Force::Rotational { .. }))
        .unwrap();
    let params = [
        Param::Stiffness(spring),
        Param::Damping(spring),
        Param::Damping(act),
        Param::Mass(0),
        Param::Anchor(act, 0),
    ];
    let run = |form| {
        let sys = System::new(m.clone());
        let mut y0 = sys.initial_state();
        sys.project(0.0, &mut y0).unwrap();
        let mut sens = vec![];
        let opts = Options {
            sensitivity: form,
            ..options(Method::Bdf)
        };
        let stats = integrate_sens(&sys, &y0, &opts, &params, |t, _y, s| {
            if t == 1.0 {
                sens = s.to_vec();
            }
            Ok(())
        })
        .unwrap();
        (sens, stats, y0.len())
    };
    let (fused, fs, n) = run(SensitivityForm::Fused);
    let (staggered, ss, _) = run(SensitivityForm::Staggered);
    println!("fused {fs:?}\nstaggered {ss:?}");
    assert_eq!(fs.steps, ss.steps, "same steps");
    assert_eq!(fs.error_test_failures, ss.error_test_failures);
    let mut worst = 0.0f64;
    for (i, p) in params.iter().enumerate() {
        let (a, b) = (&fused[i * n..(i + 1) * n], &staggered[i * n..(i + 1) * n]);
        let scale = b.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let diff = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        println!(
            "  {p:?}: |dy/dp| {scale:.3e}, |fused − staggered| / |dy/dp| {:.3e}",
            diff / scale
        );
        assert!(scale > 1e-6, "{p:?}: sensitivity vanishes");
        worst = worst.max(diff / scale);
    }
    // Measured 1.0e-11 (Mass(0); same 870 steps); bound 3×.
    assert!(
        worst < 3e-11,
        "fused and staggered differ by {worst:e} of |dy/dp|"
    );
}

#[test]
fn sar_sensitivities_of_deployment_angle() {
    // Rigid SAR phase 1: ∂θ(3 s)/∂p for the actuator damping c, the Eq. 32
    // breakpoint 3.12 of the first segment, and the panel-3 mass, against
    // central finite differences (BDF, rtol 1e-10).
    let m = shipped_scene("sar_phase1_rigid.toml").model;
    let law = match &m.forces[0] {
        Force::Rotational { law: Some(l), .. } => l.clone(),
        other => panic!("{other:?}"),
    };
    let top = law.segment_index(3.12);
    assert_eq!(law.segments[top].anchor, 3.12);
    let params = [
        Param::Damping(0),
        Param::Anchor(0, top),
        Param::Mass(m.body("B3").unwrap()),
    ];
    let opts = Options {
        method: Method::Bdf,
        rtol: 1e-10,
        atol: 1e-12,
        t0: 0.0,
        times: vec![3.0],
        events: true,
        sensitivity: SensitivityForm::Staggered,
    };
    let sys = System::new(m.clone());
    let y0 = sys.initial_state();
    let r3 = m.joint("R3").unwrap();
    let angle =
        |sys: &System, y: &[f64]| sys.angle(y, r3, &mut plyscape::mbs::Workspace::empty()).0;
    let (mut sens, mut y_end) = (vec![], vec![]);
    integrate_sens(&sys, &y0, &opts, &params, |_, y, s| {
        sens = s.to_vec();
        y_end = y.to_vec();
        Ok(())
    })
    .unwrap();
    let n = y0.len();
    // dθ/dp from the state sensitivity by a directional derivative of θ(y).
    let eps = 1e-7;
    for (i, p) in params.iter().enumerate() {
        let lane = &sens[i * n..(i + 1) * n];
        let yp: Vec<f64> = (0..n).map(|k| y_end[k] + eps * lane[k]).collect();
        let ym: Vec<f64> = (0..n).map(|k| y_end[k] - eps * lane[k]).collect();
        let dth_sens = (angle(&sys, &yp) - angle(&sys, &ym)) / (2.0 * eps);
        let v = p.value(&m).unwrap();
        let h = 1e-4 * v.abs();
        let mut fd = [0.0; 2];
        for (s, sign) in [1.0, -1.0].iter().enumerate() {
            let mut mm = m.clone();
            p.set(&mut mm, v + sign * h);
            let sys2 = System::new(mm);
            integrate(&sys2, &y0, &opts, |_, y| {
                fd[s] = angle(&sys2, y);
                Ok(())
            })
            .unwrap();
        }
        let dth_fd = (fd[0] - fd[1]) / (2.0 * h);
        println!("{p:?}: dθ(3)/dp sens {dth_sens:.9e}, FD {dth_fd:.9e}");
        assert!((dth_sens - dth_fd).abs() < 1e-5 * dth_fd.abs(), "{p:?}");
    }
}

#[test]
fn scene_sensitivities_of_outputs_match_differences() {
    // The same pendulum with `sensitivities` in the scene: ∂θ_pin(1 s)/∂p
    // written by `simulate` vs central differences of the simulation.
    let text = SCENE
        .replace(
            "[scene.integrator]\nt_end = 1.0\ndt_out = 1.0\n",
            "[scene.integrator]\nrtol = 1e-11\natol = 1e-13\nt_end = 1.0\ndt_out = 0.5\n\
             [scene.outputs]\nquantities = [\"pin.angle\", \"pin.rate\"]\n",
        )
        .replacen(
            "\n[[scene.bodies]]",
            "\nsensitivities = [\"forces[0].stiffness\", \"rod.mass\", \"forces[1].segments[0].anchor\", \"forces[1].damping\"]\n[[scene.bodies]]",
            1,
        );
    let spec = scene_spec(&text);
    let scene = spec.build().unwrap();
    assert_eq!(scene.params.len(), 4);
    let (_, sim) = plyscape::simulate::simulate(&scene).unwrap();
    assert_eq!(sim.sens_headers.len(), 1 + 4 * 2);
    assert_eq!(sim.sens_rows.len(), 3);
    assert!(sim.sens_headers[1].starts_with("d(pin.angle)/d(forces[0].stiffness)"));
    let last = sim.sens_rows.last().unwrap();
    for (i, (_, p)) in scene.params.iter().enumerate() {
        let v = p.value(&scene.model).unwrap();
        let h = 1e-4 * v.abs();
        let mut th = [0.0; 2];
        for (k, sign) in [1.0, -1.0].iter().enumerate() {
            let mut sc = spec.build().unwrap();
            p.set(&mut sc.model, v + sign * h);
            sc.params.clear();
            let (_, s) = plyscape::simulate::simulate(&sc).unwrap();
            th[k] = s.rows.last().unwrap()[1];
        }
        let fd = (th[0] - th[1]) / (2.0 * h);
        let exact = last[1 + 2 * i];
        println!("{p:?}: dθ/dp {exact:.9e} vs FD {fd:.9e}");
        assert!((exact - fd).abs() < 1e-5 * fd.abs(), "{p:?}");
    }
    // Bad names are input errors naming the key.
    let bad = text.replace("\"rod.mass\"", "\"rod.masss\"");
    match scene_spec(&bad).build() {
        Err(plyscape::Error::Input { key, .. }) => assert_eq!(key, "sensitivities[1]"),
        other => panic!("{other:?}"),
    }
}
