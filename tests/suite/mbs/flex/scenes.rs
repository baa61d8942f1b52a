//! The scenes the flexible-body tests share: a tumbling free beam, the
//! shipped spin-up study and a swung composite panel.

use crate::common::scenes::shipped_study;
use plyscape::study::Study;

pub(super) fn study(text: &str) -> Study {
    Study::parse("flex.toml", text).unwrap()
}

pub(super) const FREE_BEAM: &str = r#"
[scene]
effects = ["flexibility", "quadratic_velocity"]
[[scene.bodies]]
name = "beam"
angular_velocity = [0.3, 0.2, 2.0]
velocity = [0.1, 0.0, 0.0]
flexible = { kind = "beam", modes = 4, origin = [0.0, 0.0, 0.0], length = 1.0, ei_y = 100.0, ei_z = 60.0, rho_a = 1.0, rho_ip = 0.01 }
[scene.integrator]
method = "bdf"
rtol = 1e-9
atol = 1e-11
t_end = 1.0
dt_out = 0.1
[scene.outputs]
quantities = ["beam.modal", "beam.strain_energy", "energy"]
"#;

pub(super) fn spinup() -> Study {
    shipped_study("beam_spinup.toml")
}

/// A composite panel (1.0 m × 0.6 m, [30/−45/−45/30], centre clamp basis)
/// clamped at its centre to a hub swung about x by a prescribed angle
/// θ(t) = t² (like the SAR panel's deployment), with its first ply pair at
/// `theta1` degrees. The frame is held at the clamped node (the panel is
/// welded to the hub there), so the clamp's nearly rigid rocking modes are
/// real compliance and are kept (`rigid_limit = 1`).
pub(super) fn panel_scene(theta1: f64) -> String {
    format!(
        r#"
[[panels]]
name = "p"
length = 1.0
width = 0.6
divisions = 6
support = "centre_clamp"
design = [[1, 4], [2, 3]]
material = {{ e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9, g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }}
plies = [{{ angle = {theta1}, thickness = 0.5e-3 }}, {{ angle = -45.0, thickness = 0.5e-3 }}, {{ angle = -45.0, thickness = 0.5e-3 }}, {{ angle = {theta1}, thickness = 0.5e-3 }}]

[scene]
effects = ["flexibility", "quadratic_velocity"]
sensitivities = ["panel.design.theta_1_4"]
[[scene.bodies]]
name = "hub"
mass = 0.5
com = [0.0, 0.0, 0.0]
inertia = [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]]
[[scene.bodies]]
name = "panel"
flexible = {{ kind = "panel", panel = "p", modes = 4, origin = [0.0, 0.5, 0.0], derivatives = "updated", rigid_limit = 1.0 }}
[[scene.joints]]
name = "hinge"
type = "driven"
body_i = "ground"
body_j = "hub"
point = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
drive = [0.0, 0.0, 1.0]
[[scene.joints]]
name = "mount"
type = "fixed"
body_i = "hub"
body_j = "panel"
point = [0.0, 0.5, 0.0]
axis = [0.0, 0.0, 1.0]
[scene.integrator]
method = "bdf"
rtol = 1e-10
atol = 1e-13
t_end = 0.4
dt_out = 0.1
[scene.outputs]
quantities = ["panel.strain_energy", "panel.modal"]
"#
    )
}

/// [`panel_scene`] with `geometric_stiffening` in its effects.
pub(super) fn stiffened_panel_scene(theta1: f64) -> String {
    panel_scene(theta1).replace(
        r#"effects = ["flexibility", "quadratic_velocity"]"#,
        r#"effects = ["flexibility", "quadratic_velocity", "geometric_stiffening"]"#,
    )
}
