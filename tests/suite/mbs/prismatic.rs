//! Prismatic and cylindrical joints against closed forms: a mass on a
//! spring along a tilted prismatic joint (x(t) = s0 + A cos ωt,
//! ω = √(k/m), and its exact stiffness and mass sensitivities), a bead
//! sliding on a rod spun at a constant rate (r(t) = r0 cosh Ωt), and a
//! spinning mass on a cylindrical joint (free spin θ = Ω t, the same
//! cosine along the axis). Each checks the constraint drift and, where
//! the scene is conservative, the energy. Every closed form is derived in
//! the test's comment from Newton's law along the joint axis.
use crate::common::scenes::{run, scene_spec};
use crate::common::tables::column;

/// A 2 kg block on a prismatic joint to the ground along the unit axis
/// (1, 2, 2)/3 through (0.3, −0.2, 0.1), with a joint spring k = 50 N/m
/// whose rest displacement is s0 = −0.1 m (so it starts stretched by
/// A = 0.1 m). The joint point is off the block's centre of mass.
fn spring_block(extra_effects: &str) -> String {
    format!(
        r#"
[scene]
effects = ["springs"{extra_effects}]
sensitivities = ["spring.stiffness", "block.mass"]
[[scene.bodies]]
name = "block"
mass = 2.0
com = [0.5, 0.1, -0.2]
inertia = [[0.02, 0.001, 0.0], [0.001, 0.03, 0.0], [0.0, 0.0, 0.04]]
[[scene.joints]]
name = "slide"
type = "prismatic"
body_i = "ground"
body_j = "block"
point = [0.3, -0.2, 0.1]
axis = [1.0, 2.0, 2.0]
[[scene.forces]]
type = "spring"
name = "spring"
joint = "slide"
stiffness = 50.0
length = -0.1
[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 2.0
dt_out = 0.05
[scene.outputs]
quantities = ["slide.displacement", "slide.velocity", "energy", "violation"]
"#
    )
}

#[test]
fn spring_mass_on_a_prismatic_joint_is_a_cosine() {
    let sim = run(&spring_block(""));
    let (m, k, a, s0) = (2.0f64, 50.0f64, 0.1, -0.1);
    let w = (k / m).sqrt();
    let (h, r) = (&sim.headers, &sim.rows);
    let (s, v) = (
        column(h, r, "slide.displacement"),
        column(h, r, "slide.velocity"),
    );
    let mut err = 0.0f64;
    for (row, (s, v)) in r.iter().zip(s.iter().zip(&v)) {
        let t = row[0];
        // m s̈ = −k (s − s0), s(0) = 0, ṡ(0) = 0.
        err = err.max((s - (s0 + a * (w * t).cos())).abs());
        err = err.max((v + a * w * (w * t).sin()).abs() / w);
    }
    println!(
        "error {err:e}, violation {:e}, energy {:?}, {:?}",
        sim.max_violation, sim.energy_error, sim.stats
    );
    assert_eq!(sim.equations, 5);
    // Measured: error 1.0e-11, drift 8e-13, energy 2.0e-10; bounds 3×
    // the documented 1e-11, 1e-11 and 3e-10.
    assert!(err < 3e-11, "displacement error {err:e}");
    assert!(sim.max_violation < 3e-11, "drift {:e}", sim.max_violation);
    let de = sim.energy_error.expect("conservative scene");
    assert!(de < 9e-10, "energy error {de:e}");
    // Sensitivities (sensitivities.csv, t = 2 s): s = s0 + A cos ωt with
    // ω = √(k/m) gives ∂s/∂k = −A t sin(ωt)/(2mω), ∂s/∂m = A t ω sin(ωt)/(2m).
    let last = sim.sens_rows.last().unwrap();
    let col = |name: &str| {
        let c = sim.sens_headers.iter().position(|x| x.starts_with(name));
        last[c.unwrap_or_else(|| panic!("{name} in {:?}", sim.sens_headers))]
    };
    let t = last[0];
    let dk = -a * t * (w * t).sin() / (2.0 * m * w);
    let dm = a * t * w * (w * t).sin() / (2.0 * m);
    let gk = col("d(slide.displacement)/d(spring.stiffness)");
    let gm = col("d(slide.displacement)/d(block.mass)");
    println!("ds/dk {gk:e} (closed form {dk:e}), ds/dm {gm:e} ({dm:e})");
    // Measured 2.2e-11 and 1.8e-12 relative; bound 3e-10.
    assert!((gk - dk).abs() < 3e-10 * dk.abs(), "ds/dk {gk:e} vs {dk:e}");
    assert!((gm - dm).abs() < 3e-10 * dm.abs(), "ds/dm {gm:e} vs {dm:e}");
}

#[test]
fn prismatic_without_its_spring_keeps_the_block_still_and_refuses_an_angle() {
    // Springs not listed: nothing moves the block (s ≡ 0); the spring's
    // parameters do not exist then.
    let text = spring_block("")
        .replace("effects = [\"springs\"]", "effects = []")
        .replace("\"spring.stiffness\", ", "");
    let sim = run(&text);
    let s = column(&sim.headers, &sim.rows, "slide.displacement");
    assert!(s.iter().all(|v| v.abs() < 1e-14), "{s:?}");
    // A prismatic joint's frames stay parallel: no initial angle.
    let spec = scene_spec(&spring_block("").replace(
        "axis = [1.0, 2.0, 2.0]",
        "axis = [1.0, 2.0, 2.0]\nangle = 0.3",
    ));
    let e = spec.build().unwrap_err().to_string();
    assert!(e.contains("joints[0].angle") && e.contains("0.3"), "{e}");
}

#[test]
fn bead_on_a_spinning_rod_slides_out_as_cosh() {
    // A rod turns about z at the prescribed rate Ω = 2 rad/s (driven
    // revolute); a 0.3 kg bead on a prismatic joint along the rod starts
    // at r0 = 0.5 m at rest relative to it. Along the rod, in the
    // rotating frame, r̈ = Ω² r, so r = r0 cosh Ωt and the joint
    // displacement is s = r0 (cosh Ωt − 1).
    let text = r#"
[scene]
effects = ["quadratic_velocity"]
[[scene.bodies]]
name = "rod"
mass = 1.0
com = [0.0, 0.0, 0.0]
inertia = [[0.001, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.2]]
angular_velocity = [0.0, 0.0, 2.0]
[[scene.bodies]]
name = "bead"
mass = 0.3
com = [0.5, 0.0, 0.0]
inertia = [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]]
velocity = [0.0, 1.0, 0.0]
angular_velocity = [0.0, 0.0, 2.0]
[[scene.joints]]
name = "spin"
type = "driven"
body_i = "ground"
body_j = "rod"
point = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
drive = [0.0, 2.0]
[[scene.joints]]
name = "slide"
type = "prismatic"
body_i = "rod"
body_j = "bead"
point = [0.5, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 1.0
dt_out = 0.05
[scene.outputs]
quantities = ["slide.displacement", "slide.velocity", "violation"]
"#;
    let sim = run(text);
    let (om, r0) = (2.0f64, 0.5);
    let s = column(&sim.headers, &sim.rows, "slide.displacement");
    let v = column(&sim.headers, &sim.rows, "slide.velocity");
    let mut err = 0.0f64;
    for ((row, s), v) in sim.rows.iter().zip(&s).zip(&v) {
        let t = row[0];
        err = err.max((s - r0 * ((om * t).cosh() - 1.0)).abs());
        err = err.max((v - r0 * om * (om * t).sinh()).abs() / om);
    }
    println!(
        "error {err:e} (s(1) = {:.6}), violation {:e}, {:?}",
        s.last().unwrap(),
        sim.max_violation,
        sim.stats
    );
    // Measured: error 2.7e-11, drift 1.2e-11; bounds 9e-11 and 3e-11.
    assert!(err < 9e-11, "cosh error {err:e}");
    assert!(sim.max_violation < 3e-11, "drift {:e}", sim.max_violation);
}

#[test]
fn spinning_mass_on_a_cylindrical_joint() {
    // A 1.5 kg disc (axial inertia 0.05) on a cylindrical joint along z,
    // spun at Ω = 3 rad/s about it, with a joint spring k = 60 N/m
    // stretched by A = 0.05 m: the spin is free (θ = Ω t, no torque about
    // the axis) and the slide is the cosine of the first test.
    let text = r#"
[scene]
effects = ["springs", "quadratic_velocity"]
[[scene.bodies]]
name = "disc"
mass = 1.5
com = [0.0, 0.0, 0.2]
inertia = [[0.03, 0.0, 0.0], [0.0, 0.03, 0.0], [0.0, 0.0, 0.05]]
angular_velocity = [0.0, 0.0, 3.0]
[[scene.joints]]
name = "shaft"
type = "cylindrical"
body_i = "ground"
body_j = "disc"
point = [0.0, 0.0, 0.2]
axis = [0.0, 0.0, 1.0]
[[scene.forces]]
type = "spring"
joint = "shaft"
stiffness = 60.0
length = 0.05
[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 3.0
dt_out = 0.05
[scene.outputs]
quantities = ["shaft.angle", "shaft.rate", "shaft.displacement", "energy", "violation"]
"#;
    let sim = run(text);
    let (m, k, a, om) = (1.5f64, 60.0f64, 0.05, 3.0);
    let w = (k / m).sqrt();
    let (h, r) = (&sim.headers, &sim.rows);
    let (th, rate, s) = (
        column(h, r, "shaft.angle"),
        column(h, r, "shaft.rate"),
        column(h, r, "shaft.displacement"),
    );
    let mut err = 0.0f64;
    for (i, row) in r.iter().enumerate() {
        let t = row[0];
        // s − s0 = −A cos ωt with s0 = A: s = A(1 − cos ωt).
        err = err.max((s[i] - a * (1.0 - (w * t).cos())).abs());
        err = err.max((th[i] - om * t).abs()).max((rate[i] - om).abs());
    }
    println!(
        "error {err:e}, violation {:e}, energy {:?}, {:?}",
        sim.max_violation, sim.energy_error, sim.stats
    );
    assert_eq!(sim.equations, 4);
    // Measured: error 3.3e-11, drift 0, energy 3.1e-10; bounds 3×.
    assert!(err < 1e-10, "error {err:e}");
    assert!(sim.max_violation < 3e-11, "drift {:e}", sim.max_violation);
    let de = sim.energy_error.expect("conservative scene");
    assert!(de < 9e-10, "energy error {de:e}");
}

#[test]
fn prismatic_joint_on_a_flexible_node_conserves_energy() {
    // A free flexible beam tumbling about a skew axis (its modes excited by
    // the centrifugal loads), with a 0.2 kg bead on a prismatic joint at
    // its tip node sliding across the beam (axis y) on a stretched joint
    // spring: the joint's rows follow the node's translation and rotation
    // with the modes. No external work: energy is an invariant of the
    // exact flow (the joint spring's potential included), and any error in
    // the rows' Jacobians or γ would show as drift or energy change.
    let text = r#"
[scene]
effects = ["flexibility", "springs", "quadratic_velocity"]
[[scene.bodies]]
name = "beam"
angular_velocity = [0.3, 0.2, 2.0]
velocity = [0.1, 0.0, 0.0]
flexible = { kind = "beam", modes = 4, origin = [0.0, 0.0, 0.0], length = 1.0, ei_y = 100.0, ei_z = 60.0, rho_a = 1.0, rho_ip = 0.01 }
[[scene.bodies]]
name = "bead"
mass = 0.2
com = [1.0, 0.0, 0.0]
inertia = [[1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0], [0.0, 0.0, 1e-3]]
[[scene.joints]]
name = "slot"
type = "prismatic"
body_i = "beam"
body_j = "bead"
point = [1.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
[[scene.forces]]
type = "spring"
joint = "slot"
stiffness = 30.0
length = 0.05
[scene.integrator]
method = "tsit45"
rtol = 1e-10
atol = 1e-12
t_end = 0.5
dt_out = 0.02
[scene.outputs]
quantities = ["slot.displacement", "beam.strain_energy", "energy", "violation"]
"#;
    let sim = run(text);
    let s = column(&sim.headers, &sim.rows, "slot.displacement");
    let u = column(&sim.headers, &sim.rows, "beam.strain_energy");
    let swing = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let umax = u.iter().fold(0.0f64, |m, v| m.max(*v));
    let de = sim.energy_error.expect("conservative scene");
    println!(
        "slide amplitude {swing:.4}, max U {umax:.3e}, energy error {de:e}, violation {:e}, {:?}",
        sim.max_violation, sim.stats
    );
    assert!(
        swing > 0.02 && umax > 1e-6,
        "the bead and the modes must move"
    );
    assert!(de < 1e-9, "energy error {de:e}");
    assert!(sim.max_violation < 1e-10, "drift {:e}", sim.max_violation);
}
