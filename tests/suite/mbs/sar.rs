//! Rigid SAR antenna, phase 1 (studies/sar_phase1_rigid.toml; the geometry
//! is a reconstruction, see docs/sar_reconstruction.md).
use crate::common::scenes::shipped_scene;
use plyscape::integrate::Method;
use plyscape::mbs::Workspace;
use plyscape::simulate::simulate;

fn sar() -> plyscape::scene::Scene {
    shipped_scene("sar_phase1_rigid.toml")
}

#[test]
fn sar_phase1_rank_deployment_and_reaction() {
    let scene = sar();
    let (sys, sim) = simulate(&scene).unwrap();
    // docs/sar_reconstruction.md §4: 65 equations, rank 59 (6 redundant)
    // when folded; mobility 7 (θ_R3 and the spins of six bars). B4 and
    // B12 are locked to the fixed satellite B1 (R1, R2) and built fixed
    // (scene::ground), so their 2 × 6 lock equations are not built: 53.
    // Panel 2 (B2) and its struts B5–B7 then reach only fixed bodies and
    // carry no force: they stay at rest and are built fixed too, which
    // leaves R3 (5) and the seven spherical joints of panel 3's side
    // (21): 26 equations, none redundant (the six were all in B2's group).
    assert_eq!(sim.equations, 26);
    assert_eq!(sim.redundant, 0);
    // Reading one of B2's joints keeps the group built: the whole folded
    // mechanism. Both deploy alike: at rtol 1e-10 θ_R3(3 s) agrees to
    // the integration error (at the shipped 1e-6 the two differ by
    // 1.5e-7 rad: the step choices differ).
    let shipped = crate::common::scenes::shipped_text("sar_phase1_rigid.toml")
        .replace("rtol = 1e-6", "rtol = 1e-10")
        .replace("atol = 1e-8", "atol = 1e-12");
    let read = shipped.replace(
        "quantities = [\"R3.angle\"",
        "quantities = [\"S1.reaction\", \"R3.angle\"",
    );
    let (_, fixed) = simulate(&crate::common::scenes::scene(&shipped)).unwrap();
    let (_, full) = simulate(&crate::common::scenes::scene(&read)).unwrap();
    assert_eq!((fixed.equations, full.equations), (26, 65 - 12));
    assert_eq!(full.redundant, 6);
    let angle = |s: &plyscape::simulate::Simulation| {
        let c = s
            .headers
            .iter()
            .position(|x| x.starts_with("R3.angle"))
            .unwrap();
        s.rows.last().unwrap()[c]
    };
    let d = (angle(&fixed) - angle(&full)).abs();
    println!(
        "θ_R3(3 s) at rtol 1e-10: {} (B2 group fixed), {} (built); difference {d:e}",
        angle(&fixed),
        angle(&full)
    );
    // Measured 4.9e-11 rad.
    assert!(d < 1e-9, "difference {d:e}");
    let h = &sim.headers;
    let col = |name: &str| h.iter().position(|x| x.starts_with(name)).unwrap();
    let (ca, cr, ctx) = (col("R3.angle"), col("R3.rate"), col("R3.torque_x"));
    // Starts at rest at θ = 3.12 rad; the actuator (τ = −M > 0 opening
    // torque in −θ) deploys monotonically: θ̇ ≤ 0, θ decreasing.
    assert!((sim.rows[0][ca] - 3.12).abs() < 1e-12);
    assert!(sim.rows[0][cr].abs() < 1e-12);
    for w in sim.rows.windows(2) {
        assert!(
            w[1][ca] <= w[0][ca] + 1e-12,
            "θ increased at t = {}",
            w[1][0]
        );
        assert!(w[1][cr] <= 1e-12);
    }
    // A revolute joint transmits no torque about its own axis (x): the
    // actuator torque is an applied force, not a reaction.
    let tx = sim.rows.iter().map(|r| r[ctx].abs()).fold(0.0, f64::max);
    assert!(tx < 1e-9, "reaction torque about the R3 axis {tx:e}");
    // Drift stays bounded (Baumgarte).
    assert!(
        sim.max_violation < 1e-7,
        "violation {:e}",
        sim.max_violation
    );
    // Work–energy: with no gravity, KE(t) = −∫ M(θ, θ̇) θ̇ dt. Trapezoid
    // rule on the 0.01 s output grid (relative error ~h² ≈ 1e-4).
    let mut ws = Workspace::empty();
    let ke = sys.energy(&sim.y_end, &mut ws);
    let law = |th: f64, thd: f64| {
        let seg = match &sys.model.forces[0] {
            plyscape::mbs::Force::Rotational { law, damping, .. } => {
                (law.clone().unwrap(), *damping)
            }
            other => panic!("unexpected force {other:?}"),
        };
        let s = seg.0.segment(th).clone();
        seg.1 * thd + s.value + s.slope * (s.anchor - th)
    };
    let mut work = 0.0;
    for w in sim.rows.windows(2) {
        let p0 = -law(w[0][ca], w[0][cr]) * w[0][cr];
        let p1 = -law(w[1][ca], w[1][cr]) * w[1][cr];
        work += 0.5 * (p0 + p1) * (w[1][0] - w[0][0]);
    }
    println!(
        "KE {ke:e} J, actuator work {work:e} J, θ(3) = {}",
        sim.rows.last().unwrap()[ca]
    );
    assert!(ke > 0.0);
    // Measured 1.2e-5 relative (the trapezoid rule's error); bound 3e-5.
    assert!((ke - work).abs() < 3e-5 * ke, "KE {ke} vs work {work}");
}

#[test]
fn sar_phase1_methods_agree() {
    // The three integrators at tight tolerance agree on θ(3 s) and θ̇(3 s).
    let mut scene = sar();
    scene.params.clear();
    let mut finals = vec![];
    for method in [Method::Bdf, Method::Tsit45, Method::Esdirk34] {
        scene.options.method = method;
        scene.options.rtol = 1e-9;
        scene.options.atol = 1e-11;
        let (_, sim) = simulate(&scene).unwrap();
        let last = sim.rows.last().unwrap().clone();
        println!(
            "{method:?}: θ(3) = {:.12}, θ̇(3) = {:.12}, {:?}",
            last[1], last[2], sim.stats
        );
        finals.push(last);
    }
    for f in &finals[1..] {
        assert!(
            (f[1] - finals[0][1]).abs() < 1e-7,
            "θ {} vs {}",
            f[1],
            finals[0][1]
        );
        assert!(
            (f[2] - finals[0][2]).abs() < 1e-7,
            "θ̇ {} vs {}",
            f[2],
            finals[0][2]
        );
    }
}
