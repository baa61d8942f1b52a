//! Driven joints with a piecewise law or a table (`drive = { pieces = .. }`,
//! `drive = { table = .. }`): the rotor follows the law and the joint's
//! torque is `I θ̈`; bad laws name file, dotted key, value and expectation.
use crate::common::errors::{error_of, InputError};
use crate::common::scenes::{column, scene};
use plyscape::scene::load_scene;
use plyscape::simulate::simulate;
use std::f64::consts::PI;

/// A rotor (I_zz = 0.3 kg·m² about its centre, on the axis) driven about z
/// by `DRIVE`, with its angle, rate and reaction as outputs.
const ROTOR: &str = r#"
[scene]
effects = ["quadratic_velocity"]
[[scene.bodies]]
name = "rotor"
mass = 3.0
com = [1.0, 2.0, 0.0]
inertia = [[0.2, 0.0, 0.0], [0.0, 0.25, 0.0], [0.0, 0.0, 0.3]]
[[scene.joints]]
name = "motor"
type = "driven"
body_i = "ground"
body_j = "rotor"
point = [1.0, 2.0, 0.0]
axis = [0.0, 0.0, 1.0]
drive = DRIVE
[scene.integrator]
rtol = 1e-10
atol = 1e-12
t_end = 1.5
dt_out = 0.1
[scene.outputs]
quantities = ["motor.angle", "motor.rate", "motor.reaction"]
"#;

/// The spin-up law of Kane, Ryan and Banerjee (1987, J. Guidance 10(2),
/// Eq. 60) with ωs = 2 rad/s, T = 1 s: `θ̇ = (ωs/T)(t − (T/2π)
/// sin(2πt/T))`, `θ̈ = (ωs/T)(1 − cos(2πt/T))` for t < T, ωs after.
fn kane(t: f64) -> (f64, f64, f64) {
    let (ws, tt) = (2.0, 1.0);
    if t < tt {
        let x = 2.0 * PI * t / tt;
        let a = ws * tt / (4.0 * PI * PI);
        (
            ws * t * t / (2.0 * tt) + a * (x.cos() - 1.0),
            ws / tt * (t - tt / (2.0 * PI) * x.sin()),
            ws / tt * (1.0 - x.cos()),
        )
    } else {
        (ws * tt / 2.0 + ws * (t - tt), ws, 0.0)
    }
}

/// The same law as written in a study: two pieces, the first with a
/// harmonic (cos = sin with phase π/2), numbers printed to the last digit.
fn kane_pieces() -> String {
    let (ws, tt) = (2.0f64, 1.0f64);
    let a = ws * tt / (4.0 * PI * PI);
    format!(
        "{{ pieces = [ {{ until = {tt:?}, poly = [{:?}, 0.0, {:?}], harmonics = [{{ amplitude = {a:?}, \
         omega = {:?}, phase = {:?} }}] }}, {{ poly = [{:?}, {ws:?}] }} ] }}",
        -a,
        ws / (2.0 * tt),
        2.0 * PI / tt,
        PI / 2.0,
        ws * tt / 2.0
    )
}

/// Angle, rate and axial reaction torque against `law` (θ, θ̇, θ̈) with
/// I_zz = 0.3 kg·m² (closed form: the joint supplies I_zz θ̈).
fn check_rotor(drive: &str, law: impl Fn(f64) -> (f64, f64, f64), tol: f64) {
    let sim = simulate(&scene(&ROTOR.replace("DRIVE", drive))).unwrap().1;
    let t = column(&sim, "t");
    let (th, rate, tz) = (
        column(&sim, "motor.angle"),
        column(&sim, "motor.rate"),
        column(&sim, "motor.torque_z"),
    );
    assert_eq!(t.len(), 16);
    for k in 0..t.len() {
        let (f, d, dd) = law(t[k]);
        assert!((th[k] - f).abs() < tol, "t {}: θ {} vs {f}", t[k], th[k]);
        assert!(
            (rate[k] - d).abs() < tol,
            "t {}: θ̇ {} vs {d}",
            t[k],
            rate[k]
        );
        assert!(
            (tz[k] - 0.3 * dd).abs() < 10.0 * tol,
            "t {}: torque {} vs {}",
            t[k],
            tz[k],
            0.3 * dd
        );
    }
}

#[test]
fn rotor_follows_the_kane_spin_up_written_as_pieces() {
    check_rotor(&kane_pieces(), kane, 1e-8);
}

#[test]
fn rotor_follows_a_table_to_the_splines_accuracy() {
    // θ = sin(2t) tabulated every 0.05 s on [0, 1.6]: the not-a-knot
    // spline's error is O(h⁴) in θ, O(h³) in θ̇, O(h²) in θ̈ (de Boor, A
    // Practical Guide to Splines, ch. V); with h = 0.05 below 1e-5, 2e-4
    // and 2e-2 (×0.3 kg·m² for the torque).
    let rows: Vec<String> = (0..=32)
        .map(|i| {
            let t = 0.05 * i as f64;
            format!("[{t:?}, {:?}]", (2.0 * t).sin())
        })
        .collect();
    let drive = format!("{{ table = [{}] }}", rows.join(", "));
    let sim = simulate(&scene(&ROTOR.replace("DRIVE", &drive))).unwrap().1;
    let t = column(&sim, "t");
    let (th, rate, tz) = (
        column(&sim, "motor.angle"),
        column(&sim, "motor.rate"),
        column(&sim, "motor.torque_z"),
    );
    for k in 0..t.len() {
        let x = 2.0 * t[k];
        assert!((th[k] - x.sin()).abs() < 1e-5, "t {}: θ {}", t[k], th[k]);
        assert!(
            (rate[k] - 2.0 * x.cos()).abs() < 2e-4,
            "t {}: θ̇ {}",
            t[k],
            rate[k]
        );
        assert!(
            (tz[k] + 0.3 * 4.0 * x.sin()).abs() < 6e-3,
            "t {}: torque {}",
            t[k],
            tz[k]
        );
    }
}

#[test]
fn polynomial_drive_is_unchanged() {
    // θ(t) = 0.2 + 0.5 t + 1.5 t² (closed form): the array form.
    check_rotor(
        "[0.0, 0.5, 1.5]",
        |t| (0.5 * t + 1.5 * t * t, 0.5 + 3.0 * t, 3.0),
        1e-8,
    );
}

/// The input error of the rotor scene driven by `drive`.
fn bad_drive(drive: &str) -> InputError {
    let text = format!("[study]\nname = \"d\"\n{}", ROTOR.replace("DRIVE", drive));
    error_of("drive.toml", &text, load_scene)
}

#[test]
fn bad_drives_name_file_key_value_and_expectation() {
    let InputError {
        file,
        key,
        value,
        expected,
        ..
    } = bad_drive("{ pieces = [ { until = 1.0, poly = [0.0, 1.0] }, { poly = [1.2, 1.0] } ] }");
    assert_eq!(file, "drive.toml");
    assert_eq!(key, "scene.joints[0].drive.pieces[1]");
    assert!(
        value.contains("θ jumps by 1.9999999999999996e-1 rad at t = 1 s"),
        "{value}"
    );
    assert!(
        expected.contains("θ and θ̇ continuous where pieces[0] ends"),
        "{expected}"
    );

    let InputError {
        key,
        value,
        expected,
        ..
    } = bad_drive("{ pieces = [ { poly = [0.0, 1.0] }, { poly = [1.0, 1.0] } ] }");
    assert_eq!(
        (key.as_str(), value.as_str()),
        ("scene.joints[0].drive.pieces[0].until", "(missing)")
    );
    assert!(expected.contains("every piece but the last"), "{expected}");

    let InputError {
        key,
        value,
        expected,
        ..
    } = bad_drive("{ table = [[0.0, 0.0], [1.0, 1.0], [0.9, 1.0], [2.0, 0.0]] }");
    assert_eq!(
        (key.as_str(), value.as_str()),
        ("scene.joints[0].drive.table[2]", "[0.9, 1.0]")
    );
    assert!(expected.contains("strictly increasing"), "{expected}");

    let InputError { key, expected, .. } =
        bad_drive("{ pieces = [ { poly = [0.0], until_t = 1.0 } ] }");
    assert_eq!(key, "scene.joints[0].drive.pieces[0].until_t");
    assert!(expected.contains("until"), "{expected}");

    let InputError { key, expected, .. } = bad_drive("\"fast\"");
    assert_eq!(key, "scene.joints[0].drive");
    assert!(expected.contains("{ pieces = [..] }"), "{expected}");
}
