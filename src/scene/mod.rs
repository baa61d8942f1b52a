//! Scenes: the `[scene]` section of a study file, from data to a
//! multibody model.
//!
//! The stages: [`spec`] (the section as parsed, plain data),
//! [`build`] (data → [`Scene`]: a [`crate::mbs::Model`] with integrator
//! options, output plan and sensitivity parameters; [`parts`] holds its
//! pieces), [`quantity`] (the output plan), [`responses`] (the
//! response functionals), and [`load`] (a study →
//! scene, with the panels' modal bases; [`ScenePlan`] keeps everything
//! that does not depend on the ply angles and takes a design as numbers).
//!
//! Where things go: a new joint type is a [`crate::mbs::JointKind`]
//! variant with its row blocks (`JointKind::blocks`, see [`crate::mbs`]),
//! given a `type` name in [`build`] (`joint_kind`); a new output is a
//! [`QuantityKind`] variant with its row of [`QuantityKind::info`] (name,
//! subject, unit, columns, sensitivities) and its evaluation in
//! [`crate::simulate`]; a new response kind is a
//! [`crate::mbs::responses::ResponseKind`] variant with its own
//! parameters, read from its keys in [`responses`], and its one
//! evaluation in [`crate::simulate`].
//!
//!
//! ```toml
//! [scene]
//! effects = ["gravity", "actuators", "damping", "springs", "loads",
//!            "flexibility", "quadratic_velocity"]   # what is not listed is not built
//! gravity = [0.0, 0.0, -9.81]                       # m/s²
//! baumgarte = 10.0                                  # 1/s
//! sensitivities = ["forces[0].damping", "forces[0].segments[0].anchor", "B4.mass",
//!                  "B3.design.theta_1_4",            # ply angle of a flexible body
//!                  "spring.stiffness", "spring.damping"]   # of a named force
//! [[scene.bodies]]
//! name = "B4"; mass = 1.5; com = [1.2, 0.0, -0.3]   # kg, m (global, initial)
//! inertia = [[..], [..], [..]]                      # kg·m², about com, global axes
//! fixed = false; velocity = [..]; angular_velocity = [..]   # m/s, rad/s (global)
//! [[scene.bodies]]                                  # floating-frame flexible body
//! name = "B3"; mass, com, inertia                   # rigid stand-in without "flexibility"
//! flexible = { kind = "panel", panel = "panel3", modes = 14, origin = [..],
//!              x_axis = [..], y_axis = [..], derivatives = "updated", damping = 0.0 }
//! # kind = "beam": length, ei_y, ei_z, rho_a, rho_ip (closed-form cantilever modes)
//! [[scene.joints]]
//! name = "R3"; type = "revolute"   # spherical | revolute | locked | driven | fixed |
//!                                  # prismatic | cylindrical (slide along the axis)
//! body_i = "B12"; body_j = "B8"    # "ground" allowed
//! point = [..]; axis = [..]; angle = 3.12   # global initial point, axis, θ0 (rad; 0 if prismatic)
//! drive = [c0, c1, ..]             # driven: θ(t) = Σ c_k t^k
//! [[scene.markers]]  name, body, point       # extra points (springs, loads, outputs);
//!                                            # each joint also makes <joint>.i, <joint>.j
//! [[scene.forces]]
//! type = "actuator"; name = "M3"; joint = "R3"; damping = 0.5
//! segments = [{ lower, upper, value, slope, anchor }, ..]  # Eq. 32
//! type = "spring"; name = "spring"; marker_i, marker_j, stiffness, damping, length
//! type = "spring"; joint = "slide"; stiffness, damping, length = s0, force = f
//!                                  # along a prismatic/cylindrical joint: T = k(s − s0) − f + c ṡ
//! type = "load"; body | marker; frame = "global" | "body"; force, torque
//!                                  # or table = [[t, fx, fy, fz, tx, ty, tz], ..]
//! [scene.integrator]  method = "bdf", rtol, atol, t_end, dt_out, events = true,
//!                     sensitivity_form = "fused" | "staggered"   # default: fused
//! [scene.outputs]  quantities = ["R3.angle", "R3.rate", "R3.reaction", "energy", "violation",
//!                                "B3.strain_energy", "B3.modal", "<marker>.deflection",
//!                                "slide.displacement", "slide.velocity",
//!                                "B4.kinetic_energy", "kinetic_energy"]
//!                  plot = "R3.angle"; plot_file = "theta"   # theta.svg
//! [[scene.responses]]  name = "G"; kind = "integral" | "peak" | "final" | "value_at" |
//!                      "crossing" | "frequency"
//!                      of = ["kinetic_energy", "B3.strain_energy", ..]; scale = 1.0
//!                      # or one unit: "R3.angle", "B4.position_z", "tip.deflection_x", ..
//!                      sense = "max" | "min"                  # peak
//!                      time = 0.5                             # value_at (s)
//!                      level = 1.2; direction = "up"          # crossing (time in s)
//!                      mode = 1                               # frequency of of = ["B3"] (Hz)
//! ```
//! A rigid body locked (`type = "locked"`) to a fixed body or to the
//! ground, directly or through other such bodies, is built as a fixed body
//! without its lock, unless the study reads it or its lock (`ground`
//! module): it never moves, so integrating it would only cost time. So is
//! a group of bodies joined to each other and to fixed bodies that starts
//! at rest with no force, drive or gravity acting on it (a flexible one
//! without modes, and no eigen-analysis), unless the study reads more of
//! it than its energies, positions, masses and ply-angle sensitivities.
//!
//! Rigid bodies start with their axes along the global axes, so `inertia`
//! is both the global and the body-frame tensor at `t = 0`. A flexible
//! body's frame is its basis frame (the beam's root, the panel's centre),
//! placed at `origin` with its x and y axes along `x_axis`, `y_axis`;
//! points on it (joints, markers) must be nodes of its basis.
//!
//! From data to a model, stage by stage (a pendulum: a point-like bob on
//! a horizontal hinge about y, released horizontally):
//!
//! ```
//! use plyscape::scene::{Quantity, QuantityKind, SceneSpec};
//! use plyscape::study::Study;
//!
//! let text = r#"
//! [scene]
//! effects = ["gravity"]
//! [[scene.bodies]]
//! name = "bob"
//! mass = 1.0
//! com = [1.0, 0.0, 0.0]
//! inertia = [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]]
//! [[scene.joints]]
//! name = "hinge"
//! type = "revolute"
//! body_i = "ground"
//! body_j = "bob"
//! point = [0.0, 0.0, 0.0]
//! axis = [0.0, 1.0, 0.0]
//! [scene.integrator]
//! t_end = 0.5
//! dt_out = 0.05
//! [scene.outputs]
//! quantities = ["hinge.angle", "energy"]
//! "#;
//! let study = Study::parse("pendulum.toml", text)?;
//! let spec: SceneSpec = study.require_section("scene", "the multibody scene")?;
//! let scene = spec.build()?;
//! assert_eq!(scene.model.bodies.len(), 1);
//! assert_eq!(scene.outputs[0].1, Quantity::new(QuantityKind::Angle, 0));
//! assert_eq!(scene.outputs[0].1.headers("hinge.angle"), ["hinge.angle [rad]"]);
//! # Ok::<(), plyscape::Error>(())
//! ```

pub mod build;
pub mod forces;
mod ground;
pub mod load;
pub mod parts;
pub mod quantity;
pub mod responses;
pub mod spec;

pub use build::Scene;
pub use load::{load_scene, BuildProfile, ScenePlan};
pub use parts::{PanelBases, Stiffening};
pub use quantity::{Quantity, QuantityKind, Response, ScalarOutput};
pub use spec::{Effect, SceneSpec};
