//! Geometric stiffening by the joint loads (`plyscape::mbs::model::geometric`,
//! "Joint-load prestress"; the solve in `plyscape::mbs::constraints::prestress`):
//! a cantilever pulled (or pushed) at its tip through a spherical joint.

use crate::common::scenes::{column, run};

/// A cantilever (L = 1 m, EI = 1 N·m², ρA = 1 kg/m, both planes, `modes`
/// modes) clamped to ground at its root, its tip held by a spherical
/// joint to a small body of mass `m` that carries a constant axial force
/// `t_axial` (N, + pulls: tension) and a short transverse triangle pulse
/// (peak 0.02 N over 0.3 s); the tip deflection along y is written.
fn scene(t_axial: f64, m: f64, modes: usize, effect: bool) -> String {
    let effects = if effect {
        r#"["flexibility", "loads", "geometric_stiffening"]"#
    } else {
        r#"["flexibility", "loads"]"#
    };
    let row = |t: f64, fy: f64| format!("[{t}, {t_axial}, {fy}, 0.0, 0.0, 0.0, 0.0]");
    let table = [
        row(0.0, 0.0),
        row(0.15, 0.02),
        row(0.3, 0.0),
        row(100.0, 0.0),
    ]
    .join(", ");
    format!(
        r#"
[scene]
effects = {effects}
baumgarte = 10.0

[[scene.bodies]]
name = "beam"
flexible = {{ kind = "beam", modes = {modes}, origin = [0.0, 0.0, 0.0], length = 1.0, ei_y = 1.0, ei_z = 1.0, rho_a = 1.0, rho_ip = 0.001 }}

[[scene.bodies]]
name = "puller"
mass = {m}
com = [1.0, 0.0, 0.0]
inertia = [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]]

[[scene.joints]]
name = "root"
type = "fixed"
body_i = "ground"
body_j = "beam"
point = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]

[[scene.joints]]
name = "tip"
type = "spherical"
body_i = "beam"
body_j = "puller"
point = [1.0, 0.0, 0.0]

[[scene.markers]]
name = "end"
body = "beam"
point = [1.0, 0.0, 0.0]

[[scene.forces]]
type = "load"
body = "puller"
table = [{table}]

[scene.integrator]
method = "bdf"
rtol = 1e-9
atol = 1e-11
t_end = 10.0
dt_out = 0.002

[scene.outputs]
quantities = ["end.deflection"]
"#
    )
}

/// The first bending frequency (rad/s) of the free vibration after the
/// pulse: twice the mean interval between the zero crossings of the tip
/// deflection after t = 0.5 s (linear interpolation between the output
/// times).
fn measured_frequency(text: &str) -> f64 {
    let sim = run(text);
    let t = column(&sim, "t");
    let y = column(&sim, "end.deflection_y");
    let zeros: Vec<f64> = (1..t.len())
        .filter(|&k| t[k - 1] > 0.5 && (y[k - 1] < 0.0) != (y[k] < 0.0))
        .map(|k| t[k - 1] + (t[k] - t[k - 1]) * (-y[k - 1]) / (y[k] - y[k - 1]))
        .collect();
    assert!(zeros.len() >= 4, "{} zero crossings", zeros.len());
    let period = 2.0 * (zeros[zeros.len() - 1] - zeros[0]) / (zeros.len() - 1) as f64;
    2.0 * std::f64::consts::PI / period
}

/// The exact first frequency (rad/s) of the clamped–free Euler–Bernoulli
/// beam under the dead axial tip load `t` (tension > 0) with a tip mass
/// `m`: `EI v'''' − T v'' = ρA ω² v`, `v(0) = v'(0) = 0`, `v''(L) = 0`,
/// `EI v'''(L) − T v'(L) = −m ω² v(L)` (the natural boundary conditions
/// of `½∫EI v''² + ½∫T v'² − ½ω²(∫ρA v² + m v(L)²)`; Bokaian, "Natural
/// frequencies of beams under tensile axial loads", J. Sound Vib. 142(3),
/// 1990, gives the same equation without the tip mass). With
/// `α², −β² = (T ± √(T² + 4 EI ρA ω²)) / 2EI` the solution is
/// `C₁(cosh αx − cos βx) + C₂(sinh αx − (α/β) sin βx)`, and ω is the
/// lowest root of the 2 × 2 determinant of the tip conditions (scan and
/// bisection).
fn exact_frequency(t: f64, m: f64) -> f64 {
    let (ei, rho_a, l) = (1.0, 1.0, 1.0);
    let det = |w: f64| {
        let root = (t * t + 4.0 * ei * rho_a * w * w).sqrt();
        let a = ((t + root) / (2.0 * ei)).sqrt();
        let b = ((root - t) / (2.0 * ei)).sqrt();
        let (ch, sh) = ((a * l).cosh(), (a * l).sinh());
        let (c, s) = ((b * l).cos(), (b * l).sin());
        // Columns C₁, C₂: v, v', v'', v''' at L.
        let v = [ch - c, sh - a / b * s];
        let d1 = [a * sh + b * s, a * ch - a * c];
        let d2 = [a * a * ch + b * b * c, a * a * sh + a * b * s];
        let d3 = [
            a.powi(3) * sh - b.powi(3) * s,
            a.powi(3) * ch + a * b * b * c,
        ];
        let r2 = [
            ei * d3[0] - t * d1[0] + m * w * w * v[0],
            ei * d3[1] - t * d1[1] + m * w * w * v[1],
        ];
        d2[0] * r2[1] - d2[1] * r2[0]
    };
    let (mut lo, mut step) = (1e-3, 1e-3);
    while det(lo).signum() == det(lo + step).signum() {
        lo += step;
        step *= 1.001;
        assert!(lo < 1e3, "no root");
    }
    let mut hi = lo + step;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if det(mid).signum() == det(lo).signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn exact_reference_without_load_is_the_cantilever() {
    // T = 0, m = 0: (β₁L)² √(EI/ρAL⁴) = 1.875104² = 3.516015 rad/s
    // (Blevins, Table 8-1, clamped–free).
    let w = exact_frequency(0.0, 0.0);
    assert!((w - 3.516_015).abs() < 1e-5, "{w}");
}

#[test]
fn axial_joint_load_stiffens_and_softens_as_the_taut_beam() {
    let m = 0.05;
    for t in [4.0, -1.5] {
        let want = exact_frequency(t, m);
        let got = measured_frequency(&scene(t, m, 12, true));
        let plain = measured_frequency(&scene(t, m, 12, false));
        let free = exact_frequency(0.0, m);
        println!(
            "T = {t}: ω = {got:.5} rad/s with the effect, {plain:.5} without; exact {want:.5} \
             (unloaded {free:.5})"
        );
        // Measured: 1.0e-4 (T = 4) and 0.8e-4 (T = −1.5) relative.
        assert!((got / want - 1.0).abs() < 0.005, "T = {t}: {got} vs {want}");
        // Without the effect the load changes nothing.
        assert!(
            (plain / free - 1.0).abs() < 0.01,
            "T = {t}: {plain} vs {free}"
        );
        // Tension stiffens, compression softens.
        assert_eq!(got > plain, t > 0.0);
    }
}
