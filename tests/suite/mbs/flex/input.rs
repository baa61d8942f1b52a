//! Input errors of flexible bodies: each names the file and the key, the
//! mode count its largest allowed value, a size that cannot fit its
//! memory estimate.

use super::scenes::{panel_scene, study, FREE_BEAM};
use plyscape::scene::load_scene;

#[test]
fn flexible_input_errors_name_the_key() {
    let cases = [
        (
            FREE_BEAM.replace("rho_ip = 0.01", "rho_ip = 0.0"),
            "bodies[0].flexible.rho_ip",
        ),
        (FREE_BEAM.replace("modes = 4", "modes = 0"), "bodies[0].flexible.modes"),
        (
            FREE_BEAM.replace("kind = \"beam\"", "kind = \"shell\""),
            "bodies[0].flexible.kind",
        ),
        (
            FREE_BEAM.replace("length = 1.0,", "length = -1.0,"),
            "bodies[0].flexible.length",
        ),
        (
            FREE_BEAM.replace(
                "[scene.integrator]",
                "[[scene.markers]]\nname = \"m\"\nbody = \"beam\"\npoint = [0.55, 0.0, 0.0]\n[scene.integrator]",
            ),
            "markers[0].point",
        ),
        (
            FREE_BEAM.replace("effects = [", "sensitivities = [\"beam.design.theta\"]\neffects = ["),
            "sensitivities[0]",
        ),
        (
            FREE_BEAM.replace("\"flexibility\", ", ""),
            "bodies[0].mass",
        ),
        (
            FREE_BEAM.replace(
                "[scene.integrator]",
                "[[scene.responses]]\nname = \"r\"\nkind = \"integral\"\nof = [\"beam.energy\"]\n[scene.integrator]",
            ),
            "responses[0].of[0]",
        ),
        (
            FREE_BEAM.replace(
                "[scene.integrator]",
                "[[scene.responses]]\nname = \"r\"\nkind = \"mean\"\nof = [\"beam.strain_energy\"]\n[scene.integrator]",
            ),
            "responses[0].kind",
        ),
    ];
    for (text, key) in cases {
        let err = load_scene(&study(&text)).unwrap_err().to_string();
        assert!(err.contains(key), "expected key {key} in: {err}");
        assert!(err.contains("flex.toml"), "file not named: {err}");
    }
}

#[test]
fn too_many_panel_modes_name_the_body_key_and_the_largest_allowed() {
    // The mode count is the body's key (not the panel's), with the value
    // as written and the largest count the mesh gives: 6 divisions of a
    // 1 × 0.6 plate clamped at the centre.
    let text = panel_scene(30.0).replace("modes = 4", "modes = 100000");
    let err = load_scene(&study(&text)).unwrap_err().to_string();
    println!("{err}");
    assert!(
        err.contains("`scene.bodies[1].flexible.modes` = 100000")
            && err.contains("expected between 1 and")
            && err.contains("free DOFs"),
        "{err}"
    );
}

/// A size that cannot fit is refused before anything is allocated, with
/// the key, the estimate and the machine's available memory (100 000 beam
/// modes per plane: about 24 TB by the measured scaling in
/// `study::memory`, more than any machine this runs on).
#[test]
fn a_size_that_cannot_fit_is_refused_with_the_estimate() {
    let s = study(&FREE_BEAM.replace("modes = 4,", "modes = 100000,"));
    let e = load_scene(&s).unwrap_err().to_string();
    assert!(
        e.contains("`scene.bodies[0].flexible.modes` = 100000")
            && e.contains("fits in memory")
            && e.contains("GiB available"),
        "{e}"
    );
}
