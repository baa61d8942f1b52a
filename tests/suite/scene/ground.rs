//! Bodies that never move are built fixed (`scene::ground`): a pendulum
//! hung from a chain of two locked links swings as the same pendulum
//! hinged straight to the ground, and a link the study reads keeps its
//! lock; a group of bodies at rest that nothing acts on is built fixed
//! beside a spinning bob, which spins alike, unless something could move
//! the group or the study reads more of it than its energies.
use plyscape::scene::SceneSpec;
use plyscape::simulate::simulate;
use plyscape::study::Study;

/// A bob on a hinge about y at the origin, hinged to `arm`, which is
/// locked to `base`, itself locked to the ground (with `links`; without,
/// the hinge is on the ground); `outputs` lists the outputs besides the
/// hinge angle.
fn chain(links: bool, outputs: &str) -> SceneSpec {
    let link = |name: &str, x: f64| {
        format!(
            "[[scene.bodies]]\nname = \"{name}\"\nmass = 2.0\ncom = [{x}, 0.0, 0.5]\n\
             inertia = [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]]\n"
        )
    };
    let lock = |name: &str, i: &str, j: &str, x: f64| {
        format!(
            "[[scene.joints]]\nname = \"{name}\"\ntype = \"locked\"\nbody_i = \"{i}\"\n\
             body_j = \"{j}\"\npoint = [{x}, 0.0, 0.5]\naxis = [0.0, 1.0, 0.0]\n"
        )
    };
    let (bodies, locks, hinged_to) = if links {
        (
            link("base", -0.5) + &link("arm", -0.2),
            lock("lock1", "ground", "base", -0.5) + &lock("lock2", "base", "arm", -0.3),
            "arm",
        )
    } else {
        (String::new(), String::new(), "ground")
    };
    let text = format!(
        "[scene]\neffects = [\"gravity\"]\n{bodies}\
         [[scene.bodies]]\nname = \"bob\"\nmass = 1.0\ncom = [1.0, 0.0, 0.0]\n\
         inertia = [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]]\n{locks}\
         [[scene.joints]]\nname = \"hinge\"\ntype = \"revolute\"\nbody_i = \"{hinged_to}\"\n\
         body_j = \"bob\"\npoint = [0.0, 0.0, 0.0]\naxis = [0.0, 1.0, 0.0]\n\
         [scene.integrator]\nmethod = \"tsit45\"\nrtol = 1e-10\natol = 1e-12\n\
         t_end = 1.0\ndt_out = 0.05\n\
         [scene.outputs]\nquantities = [\"hinge.angle\"{outputs}]\n",
    );
    let study = Study::parse("chain.toml", &text).unwrap();
    study.require_section("scene", "the scene").unwrap()
}

#[test]
fn a_chain_locked_to_the_ground_is_built_fixed_and_swings_alike() {
    let grounded = chain(true, "").build().unwrap();
    let m = &grounded.model;
    assert!(m.bodies.iter().filter(|b| b.name != "bob").all(|b| b.fixed));
    assert_eq!(m.joints.len(), 1, "only the hinge is built");
    // Reading lock2's reaction keeps lock2, so arm stays a moving body
    // (held to base by lock2's equations); base is still grounded through
    // lock1.
    let kept = chain(true, ", \"lock2.reaction\"").build().unwrap();
    let m = &kept.model;
    let fixed: Vec<&str> = m
        .bodies
        .iter()
        .filter(|b| b.fixed)
        .map(|b| b.name.as_str())
        .collect();
    assert_eq!(fixed, ["base"]);
    assert_eq!(m.joints.len(), 2, "lock2 and the hinge");
    let (_, a) = simulate(&grounded).unwrap();
    let (_, b) = simulate(&kept).unwrap();
    let (_, c) = simulate(&chain(false, "").build().unwrap()).unwrap();
    assert_eq!(a.equations, 5);
    assert_eq!(b.equations, 11);
    assert_eq!(c.equations, 5);
    // The same swing (released horizontally, it falls through ~1 rad in
    // 1 s) as the pendulum hinged to the ground, whose equations the
    // grounded chain builds (to rounding), and as the chain whose lock2
    // holds arm by its equations (to their stabilisation accuracy:
    // measured 3.3e-11 rad, bound 1e-9); the energy is conserved to the
    // integration tolerance (measured 2.3e-9, bound 1e-8).
    let swing = a.rows.last().unwrap()[1] - a.rows[0][1];
    assert!(swing.abs() > 0.5, "{swing}");
    for ((ra, rb), rc) in a.rows.iter().zip(&b.rows).zip(&c.rows) {
        assert!(
            (ra[1] - rc[1]).abs() < 1e-12,
            "t = {}: {} vs {}",
            ra[0],
            ra[1],
            rc[1]
        );
        assert!(
            (ra[1] - rb[1]).abs() < 1e-9,
            "t = {}: {} vs {}",
            ra[0],
            ra[1],
            rb[1]
        );
    }
    let e = a.energy_error.expect("gravity only: conservative");
    assert!(e < 1e-8, "energy error {e:e}");
}

/// A bob spinning at 2 rad/s on a hinge about z at the origin (no
/// gravity), beside an idle group: a flexible beam clamped to the ground
/// at its root and a strut joining its tip to the ground. `extra` lists
/// more effects, `outputs` the outputs besides the hinge angle and the
/// beam's strain energy; `tail` is appended to the study.
fn idle_group(extra: &str, outputs: &str, tail: &str) -> String {
    format!(
        "[scene]\neffects = [\"flexibility\", \"quadratic_velocity\"{extra}]\n\
         [[scene.bodies]]\nname = \"bob\"\nmass = 1.0\ncom = [1.0, 0.0, 0.0]\n\
         inertia = [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]]\n\
         velocity = [0.0, 2.0, 0.0]\nangular_velocity = [0.0, 0.0, 2.0]\n\
         [[scene.bodies]]\nname = \"idle\"\nflexible = {{ kind = \"beam\", modes = 4, \
         origin = [0.0, 2.0, 0.0], length = 1.0, ei_y = 100.0, ei_z = 60.0, rho_a = 1.0, \
         rho_ip = 0.001 }}\n\
         [[scene.bodies]]\nname = \"strut\"\nmass = 0.5\ncom = [1.25, 2.0, 0.0]\n\
         inertia = [[1e-4, 0.0, 0.0], [0.0, 1e-3, 0.0], [0.0, 0.0, 1e-3]]\n\
         [[scene.joints]]\nname = \"hinge\"\ntype = \"revolute\"\nbody_i = \"ground\"\n\
         body_j = \"bob\"\npoint = [0.0, 0.0, 0.0]\naxis = [0.0, 0.0, 1.0]\n\
         [[scene.joints]]\nname = \"mount\"\ntype = \"fixed\"\nbody_i = \"ground\"\n\
         body_j = \"idle\"\npoint = [0.0, 2.0, 0.0]\naxis = [0.0, 0.0, 1.0]\n\
         [[scene.joints]]\nname = \"tip\"\ntype = \"spherical\"\nbody_i = \"idle\"\n\
         body_j = \"strut\"\npoint = [1.0, 2.0, 0.0]\n\
         [[scene.joints]]\nname = \"foot\"\ntype = \"spherical\"\nbody_i = \"strut\"\n\
         body_j = \"ground\"\npoint = [1.5, 2.0, 0.0]\n\
         [scene.integrator]\nmethod = \"tsit45\"\nrtol = 1e-10\natol = 1e-12\n\
         t_end = 1.0\ndt_out = 0.05\n\
         [scene.outputs]\nquantities = [\"hinge.angle\", \"idle.strain_energy\"{outputs}]\n\
         {tail}",
    )
}

/// The bodies a study's scene builds fixed.
fn fixed_bodies(text: &str) -> Vec<String> {
    let study = Study::parse("idle.toml", text).unwrap();
    let spec: SceneSpec = study.require_section("scene", "the scene").unwrap();
    let scene = spec.build().unwrap();
    let m = &scene.model;
    m.bodies
        .iter()
        .filter(|b| b.fixed)
        .map(|b| b.name.clone())
        .collect()
}

#[test]
fn a_group_at_rest_is_built_fixed_and_the_rest_moves_alike() {
    let run = |text: &str| {
        let study = Study::parse("idle.toml", text).unwrap();
        let spec: SceneSpec = study.require_section("scene", "the scene").unwrap();
        simulate(&spec.build().unwrap()).unwrap().1
    };
    // Nothing acts on the beam and the strut and they start at rest: both
    // are built fixed, only the hinge is built (5 equations).
    let idle = idle_group("", "", "");
    assert_eq!(fixed_bodies(&idle), ["idle", "strut"]);
    // Reading the mount's reaction keeps the group built: 5 + 6 + 3 + 3.
    let read = idle_group("", ", \"mount.reaction\"", "");
    assert!(fixed_bodies(&read).is_empty());
    let (a, b) = (run(&idle), run(&read));
    assert_eq!((a.equations, b.equations), (5, 17));
    // The bob spins at its 2 rad/s (closed form θ = 2t; measured error
    // 1e-15 rad in both, bound 1e-9), and the beam's strain energy is
    // exactly 0 when fixed, 0 to rounding when integrated.
    for (ra, rb) in a.rows.iter().zip(&b.rows) {
        let t = ra[0];
        assert!((ra[1] - 2.0 * t).abs() < 1e-9, "t = {t}: {}", ra[1]);
        assert!((rb[1] - 2.0 * t).abs() < 1e-9, "t = {t}: {}", rb[1]);
        assert_eq!(ra[2], 0.0);
        assert!(rb[2].abs() < 1e-20, "t = {t}: U = {:e}", rb[2]);
    }
    // A sensitivity to the strut's mass leaves the group fixed: the
    // derivatives of the bob's angle and of the beam's strain energy are
    // exactly 0 (the mass of a body at rest moves nothing).
    let sens = idle.replace("[scene]\n", "[scene]\nsensitivities = [\"strut.mass\"]\n");
    assert_eq!(fixed_bodies(&sens), ["idle", "strut"]);
    let s = run(&sens);
    assert!(!s.sens_rows.is_empty() && s.sens_headers.len() > 1);
    assert!(s.sens_rows.iter().all(|r| r[1..].iter().all(|&v| v == 0.0)));
    // Anything that could move the group keeps it built: a load on the
    // strut, an initial velocity, gravity, a reading of its modes.
    let load = idle_group(
        ", \"loads\"",
        "",
        "[[scene.forces]]\ntype = \"load\"\nbody = \"strut\"\nforce = [0.0, 0.0, 1.0]\n",
    );
    let moving = idle.replace(
        "com = [1.25, 2.0, 0.0]",
        "com = [1.25, 2.0, 0.0]\nangular_velocity = [0.1, 0.0, 0.0]",
    );
    let gravity = idle_group(", \"gravity\"", "", "");
    let modal = idle_group("", ", \"idle.modal\"", "");
    for text in [load, moving, gravity, modal] {
        assert!(fixed_bodies(&text).is_empty(), "{text}");
    }
}

/// The coarse SAR problem (8 divisions, 4 modes) with a thickness lane on
/// panel 2, which stays at rest: loading the study resolves the lane on
/// the basis without modes (the names come from the study's thickness
/// variables, not from an eigen-analysis), panel 2 is built fixed, and
/// every derivative with respect to its thickness is exactly 0.
#[test]
fn a_panel_at_rest_resolves_its_thickness_lane() {
    use crate::common::sar::{coarse_sar, replace};
    let text = replace(
        &coarse_sar(include_str!("../../../studies/sar_optimize.toml"), 8, 4),
        "sensitivities = [\"B3.design.theta_1_4\", \"B3.design.theta_2_3\", \
         \"B2.design.theta_1_4\", \"B2.design.theta_2_3\"]",
        "sensitivities = [\"B3.design.theta_1_4\", \"B2.design.thickness_1_4\"]",
        1,
    );
    let study = Study::parse("sar_optimize.toml", &text).unwrap();
    let scene = plyscape::scene::load_scene(&study).unwrap();
    let m = &scene.model;
    let b2 = &m.bodies[m.body("B2").unwrap()];
    assert!(b2.fixed);
    let names: Vec<&str> = (b2.flex.as_ref().unwrap().basis.derivatives.iter())
        .map(|d| d.name.as_str())
        .collect();
    assert_eq!(names, ["theta_1_4", "theta_2_3", "thickness_1_4"]);
    let (_, sim) = simulate(&scene).unwrap();
    let lane: Vec<usize> = (sim.sens_headers.iter().enumerate())
        .filter(|(_, h)| h.contains("/d(B2.design.thickness_1_4)"))
        .map(|(c, _)| c)
        .collect();
    assert!(!lane.is_empty(), "{:?}", sim.sens_headers);
    assert!(sim
        .sens_rows
        .iter()
        .all(|r| lane.iter().all(|&c| r[c] == 0.0)));
}
