//! Panel bases shared by content within one scene build
//! (`plyscape::panels::shared`), on the coarse SAR scene of
//! studies/sar_optimize.toml (8 divisions, 4 modes). The shipped panels 2
//! and 3 have different attachment points and so different meshes; here
//! both list the union of the two sets (in different orders), which
//! makes their meshes, and at a design with the same angles their bases,
//! the same.

use crate::common::sar::{assert_gradients_match_central_differences, coarse_sar, replace};
use plyscape::explore::problem::scene_problem::SceneProblem;
use plyscape::laminate::Laminate;
use plyscape::panels::basis::RIGID_CONTENT_LIMIT;
use plyscape::scene::{BuildProfile, Scene, ScenePlan};
use plyscape::study::Study;

const STUDY: &str = include_str!("../../../studies/sar_optimize.toml");
const P2: &str =
    "[[0.153, -0.55], [0.153, 0.55], [0.853, 0.0], [-0.697, -0.55], [-0.697, 0.0], [-0.697, 0.55]]";
const P3: &str = "[[0.797, 0.45], [-0.797, 0.45], [0.797, -0.45], [-0.797, -0.45]]";

/// The coarse study with a constant load of 0.5 N along z on panel 2:
/// without a force panel 2 stays at rest in this scene and is built fixed
/// without modes (`scene::ground`), so nothing would be shared.
fn coarse() -> String {
    let t = replace(
        &coarse_sar(STUDY, 8, 4),
        "effects = [\"actuators\", \"damping\"",
        "effects = [\"actuators\", \"loads\", \"damping\"",
        1,
    );
    replace(
        &t,
        "\n[scene.integrator]",
        "\n[[scene.forces]]\ntype = \"load\"\nbody = \"B2\"\nframe = \"global\"\n\
         force = [0.0, 0.0, 0.5]\n\n[scene.integrator]",
        1,
    )
}

/// The coarse study with both panels' attachment points the union of the
/// shipped two sets (panel 2: its own first; panel 3: its own first).
fn same_mesh() -> String {
    let union = |a: &str, b: &str| format!("{}, {}", &a[..a.len() - 1], &b[1..]);
    let t = replace(
        &coarse(),
        &format!("attachment_points = {P2}"),
        &format!("attachment_points = {}", union(P2, P3)),
        1,
    );
    replace(
        &t,
        &format!("attachment_points = {P3}"),
        &format!("attachment_points = {}", union(P3, P2)),
        1,
    )
}

fn plan(text: &str) -> ScenePlan {
    ScenePlan::new(&Study::parse("sar_optimize.toml", text).unwrap()).unwrap()
}

/// The plan's scene at the panels' own lay-ups (`laminates` if given),
/// with the four ply-angle lanes when `gradients`.
fn build(
    plan: &ScenePlan,
    laminates: Option<Vec<Laminate>>,
    gradients: bool,
) -> (Scene, BuildProfile) {
    let own = || plan.panels().iter().map(|p| p.laminate.clone()).collect();
    let lanes: Vec<String> = if gradients {
        plan.spec().sensitivities.clone()
    } else {
        Vec::new()
    };
    plan.build_profiled(&laminates.unwrap_or_else(own), &lanes, false)
        .unwrap()
}

/// `[computed, with derivatives, shared]` of a build.
fn counts(p: &BuildProfile) -> [usize; 3] {
    [p.bases, p.derivative_bases, p.shared_bases]
}

/// The basis of body `name`, written out to the last bit.
fn basis_of(scene: &Scene, name: &str) -> String {
    let m = &scene.model;
    let flex = m.bodies[m.body(name).unwrap()].flex.as_ref().unwrap();
    format!("{:?}", flex.basis)
}

#[test]
fn panels_with_the_same_content_share_one_basis() {
    let plan = plan(&same_mesh());
    let (p2, p3) = (&plan.panels()[0], &plan.panels()[1]);
    assert_eq!((p2.name.as_str(), p3.name.as_str()), ("panel2", "panel3"));
    assert_ne!(
        p2.mesh.forced, p3.mesh.forced,
        "points listed in other orders"
    );
    for gradients in [false, true] {
        let (scene, profile) = build(&plan, None, gradients);
        assert_eq!(
            counts(&profile),
            [1, usize::from(gradients), 1],
            "{profile:?}"
        );
        assert_eq!(basis_of(&scene, "B2"), basis_of(&scene, "B3"));
        if gradients {
            let m = &scene.model;
            let names: Vec<&str> = m.bodies[m.body("B2").unwrap()]
                .flex
                .as_ref()
                .unwrap()
                .basis
                .derivatives
                .iter()
                .map(|d| d.name.as_str())
                .collect();
            assert_eq!(names, ["theta_1_4", "theta_2_3"]);
        } else {
            // The copy is bit for bit what panel 3 alone computes.
            let own = plyscape::panels::panel_basis(p3, 4, None)
                .unwrap()
                .screened(RIGID_CONTENT_LIMIT)
                .unwrap();
            assert_eq!(basis_of(&scene, "B3"), format!("{own:?}"));
        }
    }
}

#[test]
fn a_different_angle_mode_count_or_mesh_is_not_shared() {
    let text = same_mesh();
    let plan = plan(&text);
    // One ply angle of panel 3 moved by 1e-12 rad.
    let mut laminates: Vec<Laminate> = plan.panels().iter().map(|p| p.laminate.clone()).collect();
    let mut angles = laminates[1].angles();
    angles[0] += 1e-12;
    laminates[1] = laminates[1].with_angles(&angles).unwrap();
    let (scene, profile) = build(&plan, Some(laminates), false);
    assert_eq!(counts(&profile), [2, 0, 0]);
    assert_ne!(basis_of(&scene, "B2"), basis_of(&scene, "B3"));
    // B3 with 5 modes.
    let five = replace(
        &text,
        "panel = \"panel3\", modes = 4",
        "panel = \"panel3\", modes = 5",
        1,
    );
    assert_eq!(counts(&build(&self::plan(&five), None, true).1), [2, 2, 0]);
    // The shipped attachment points: two meshes.
    let shipped = self::plan(&coarse());
    assert_eq!(counts(&build(&shipped, None, false).1), [2, 0, 0]);
}

#[test]
fn gradients_with_a_shared_basis_match_central_differences() {
    // Both variables tied to panels 2 and 3, whose bases are one shared
    // computation: each body's derivative lanes still feed its own
    // variable sums (exact forward sensitivities against central
    // differences of `evaluate`, as tests/suite/explore/scene.rs does
    // for the shipped meshes).
    let study = Study::parse("sar_optimize.toml", &same_mesh()).unwrap();
    let p = SceneProblem::from_study(&study).unwrap();
    let x = [40.0, -25.0];
    let (e, profile) = p.evaluate_profiled(&x, true).unwrap();
    assert_eq!(counts(&profile.build), [1, 1, 1]);
    assert_gradients_match_central_differences(&p, x, &e);
}
