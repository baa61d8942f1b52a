//! Kernel identities: exact Jacobian-vector products (dual numbers) against
//! central finite differences, projection of perturbed initial positions,
//! driven joints and their reactions against closed forms.
use crate::common::scenes::{scene, shipped_scene};
use num_dual::Dual64;
use plyscape::mbs::{System, Workspace};
use plyscape::simulate::simulate;

fn sar_system() -> System {
    System::new(shipped_scene("sar_phase1_rigid.toml").model)
}

/// A consistent state of `sys` with non-zero velocities (every velocity
/// term active) and a direction in the state space.
fn moving_state(sys: &System) -> (Vec<f64>, Vec<f64>) {
    let mut y = sys.initial_state();
    let vo = sys.voff();
    for (k, v) in y[vo..].iter_mut().enumerate() {
        *v = 0.05 * ((k as f64) * 0.7).sin();
    }
    sys.project(0.0, &mut y).unwrap();
    let dir = (0..y.len()).map(|k| ((k as f64) * 1.3).cos()).collect();
    (y, dir)
}

#[test]
fn dual_jacobian_vector_product_matches_central_differences() {
    // SAR scene at a state with non-zero velocities (all terms active):
    // J v from one Dual64 evaluation vs (f(y + hv) − f(y − hv)) / 2h.
    let sys = sar_system();
    let (y, dir) = moving_state(&sys);
    let n = y.len();
    let mut ws = Workspace::empty();
    let mut wsd = Workspace::empty();
    let yd: Vec<Dual64> = (0..n).map(|k| Dual64::new(y[k], dir[k])).collect();
    let mut fd = vec![Dual64::from(0.0); n];
    sys.rhs(0.0, &yd, &mut fd, &mut wsd);
    let h = 1e-6;
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let yp: Vec<f64> = (0..n).map(|k| y[k] + h * dir[k]).collect();
    let ym: Vec<f64> = (0..n).map(|k| y[k] - h * dir[k]).collect();
    sys.rhs(0.0, &yp, &mut fp, &mut ws);
    sys.rhs(0.0, &ym, &mut fm, &mut ws);
    let scale = fd.iter().map(|v| v.eps.abs()).fold(0.0, f64::max);
    let mut err = 0.0f64;
    for k in 0..n {
        let c = (fp[k] - fm[k]) / (2.0 * h);
        err = err.max((c - fd[k].eps).abs());
    }
    println!("max |Jv| {scale:e}, max |Jv − FD| {err:e}");
    assert!(err < 1e-6 * scale, "JVP error {err:e} (scale {scale:e})");
    // Values agree exactly with the f64 evaluation.
    let mut f = vec![0.0; n];
    sys.rhs(0.0, &y, &mut f, &mut ws);
    for k in 0..n {
        assert!((f[k] - fd[k].re).abs() <= 1e-12 * (1.0 + f[k].abs()));
    }
}

#[test]
fn mass_and_state_directions_match_central_differences() {
    // The tangent of the constraint-space solve (src/mbs/solve.rs: the
    // real solve reused, r₁ = Q' − M'v̇ + G'ᵀλ, r₂ = γ' − G'v̇) with a
    // parameter seed: the mass of panel B3 (it enters M, so M' ≠ 0, and
    // the weight) together with a state direction, on the rigid SAR with
    // its redundant rows left out; against central differences of plain
    // evaluations in y and m together.
    use plyscape::mbs::Param;
    let sys = sar_system();
    let b3 = sys.model.body("B3").unwrap();
    let m3 = sys.model.bodies[b3].mass;
    let (y, dir) = moving_state(&sys);
    let n = y.len();
    let dm = 0.8; // kg per unit of the direction
    let mut wsd = Workspace::empty();
    wsd.params = vec![(Param::Mass(b3), Dual64::new(m3, dm))];
    let yd: Vec<Dual64> = (0..n).map(|k| Dual64::new(y[k], dir[k])).collect();
    let mut fd = vec![Dual64::from(0.0); n];
    sys.rhs(0.0, &yd, &mut fd, &mut wsd);
    let h = 1e-6;
    let at = |sign: f64| {
        let mut ws = Workspace::empty();
        ws.params = vec![(Param::Mass(b3), m3 + sign * h * dm)];
        let yy: Vec<f64> = (0..n).map(|k| y[k] + sign * h * dir[k]).collect();
        let mut f = vec![0.0; n];
        sys.rhs(0.0, &yy, &mut f, &mut ws);
        f
    };
    let (fp, fm) = (at(1.0), at(-1.0));
    let scale = fd.iter().map(|v| v.eps.abs()).fold(0.0, f64::max);
    let err = (0..n)
        .map(|k| ((fp[k] - fm[k]) / (2.0 * h) - fd[k].eps).abs())
        .fold(0.0, f64::max);
    println!("max |f'| {scale:e}, max |f' − FD| {err:e}");
    assert!(
        err < 1e-6 * scale,
        "tangent error {err:e} (scale {scale:e})"
    );
    // (The multipliers are not compared: on this scene with its
    // redundant rows some of their split is set by the regularisation, and
    // central differences of it change sign and size with the step.)
}

#[test]
fn perturbed_positions_are_projected_and_reported() {
    // Move panel B3 by 1 mm and rotate B8 slightly: the projection restores
    // the joints and reports the correction (mass-weighted minimum norm).
    let sys = sar_system();
    let mut y = sys.initial_state();
    let s3 = sys.slot[sys.model.body("B3").unwrap()].unwrap();
    y[sys.pos_off(s3)] += 1e-3;
    let s8 = sys.slot[sys.model.body("B8").unwrap()].unwrap();
    y[sys.pos_off(s8) + 4] += 1e-3;
    let p = sys.project(0.0, &mut y).unwrap();
    println!("{p:?}");
    assert!(p.phi_before > 5e-4);
    assert!(p.phi_after < 1e-12);
    assert!(p.position_correction > 1e-4 && p.position_correction < 1e-2);
    let mut ws = Workspace::empty();
    assert!(sys.violation(0.0, &y, &mut ws) < 1e-12);
}

#[test]
fn driven_rotor_follows_law_and_reaction_torque_is_inertial() {
    // A rotor (I_zz = 0.3 kg·m² about its centre) on a driven revolute
    // joint with θ(t) = 0.2 + 0.5 t + 1.5 t²: the joint must supply the
    // torque I_zz·θ̈ = 0.9 N·m about z and no force (centre on the axis).
    // Closed form derived in this test.
    let text = r#"
[scene]
effects = ["quadratic_velocity"]
[[scene.bodies]]
name = "rotor"
mass = 3.0
com = [1.0, 2.0, 0.0]
inertia = [[0.2, 0.0, 0.0], [0.0, 0.25, 0.0], [0.0, 0.0, 0.3]]
angular_velocity = [0.0, 0.0, 0.5]
[[scene.joints]]
name = "motor"
type = "driven"
body_i = "ground"
body_j = "rotor"
point = [1.0, 2.0, 0.0]
axis = [0.0, 0.0, 1.0]
angle = 0.2
drive = [0.2, 0.5, 1.5]
[scene.integrator]
method = "bdf"
rtol = 1e-10
atol = 1e-12
t_end = 1.0
dt_out = 0.25
[scene.outputs]
quantities = ["motor.angle", "motor.rate", "motor.reaction"]
"#;
    let (_, sim) = simulate(&scene(text)).unwrap();
    assert_eq!(sim.redundant, 0);
    for r in &sim.rows {
        let t = r[0];
        let th = 0.2 + 0.5 * t + 1.5 * t * t;
        let th = th - std::f64::consts::TAU * (th / std::f64::consts::TAU).round();
        assert!((r[1] - th).abs() < 1e-8, "t {t}: θ {} vs {th}", r[1]);
        assert!((r[2] - (0.5 + 3.0 * t)).abs() < 1e-8, "t {t}: θ̇ {}", r[2]);
        for k in 0..3 {
            assert!(r[3 + k].abs() < 1e-8, "t {t}: force {}", r[3 + k]);
        }
        assert!(
            r[6].abs() < 1e-8 && r[7].abs() < 1e-8,
            "t {t}: bending torque"
        );
        assert!((r[8] - 0.9).abs() < 1e-8, "t {t}: axial torque {}", r[8]);
    }
}
