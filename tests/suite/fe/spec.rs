//! The `[[panels]]` study section: parsing, resolution, mesh nodes at the
//! SAR support points, supports, and clear input errors.

use plyscape::fe::{Derivatives, PanelSpec, Support};
use plyscape::study::Study;
use plyscape::Error;

/// Panel 2 of the SAR antenna (docs/sar_reconstruction.md §4; the support
/// positions are reconstructed): 1.994 m × 1.3 m, support points S1/S2
/// (0.153, ∓0.55), S3 (0.853, 0), S4–S6 (−0.697, −0.55/0/0.55);
/// IM6/SC1081, [0/90/90/0] of 0.5 mm plies, design [θ1/θ2/θ2/θ1].
const PANEL2: &str = r#"
[[panels]]
name = "panel2"
length = 1.994
width = 1.3
divisions = 20
attachment_points = [[0.153, -0.55], [0.153, 0.55], [0.853, 0.0],
                     [-0.697, -0.55], [-0.697, 0.0], [-0.697, 0.55]]
support = "centre_clamp"
design = [[1, 4], [2, 3]]
material = { e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9, g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }
plies = [{ angle = 0.0, thickness = 0.5e-3 }, { angle = 90.0, thickness = 0.5e-3 },
         { angle = 90.0, thickness = 0.5e-3 }, { angle = 0.0, thickness = 0.5e-3 }]
"#;

fn specs(text: &str) -> (Study, Vec<PanelSpec>) {
    let study = Study::parse("test.toml", text).unwrap();
    let p = study
        .section::<Vec<PanelSpec>>("panels")
        .unwrap()
        .expect("panels section");
    (study, p)
}

/// The error of reading (a bad kind) or else of resolving the first panel.
fn resolve_err(text: &str) -> Error {
    let study = Study::parse("test.toml", text).unwrap();
    let p = match study.section::<Vec<PanelSpec>>("panels") {
        Ok(p) => p.expect("panels section"),
        Err(e) => return e,
    };
    p[0].resolve()
        .map_err(study.locate("panels[0]"))
        .unwrap_err()
}

fn key_of(e: &Error) -> String {
    match e {
        Error::Input { key, .. } => key.clone(),
        other => panic!("expected an input error, got {other}"),
    }
}

#[test]
fn sar_panel_resolves_with_nodes_at_support_points_and_centre() {
    let (_, p) = specs(PANEL2);
    let panel = p[0].resolve().unwrap();
    assert_eq!(panel.support, Support::CentreClamp);
    // degrees → radians once
    let a = panel.laminate.angles();
    assert!((a[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert_eq!(panel.design.groups(), &[vec![0, 3], vec![1, 2]]);
    assert!((panel.laminate.thickness() - 2e-3).abs() < 1e-15);
    let mesh = &panel.mesh;
    for (k, q) in p[0].attachment_points.iter().enumerate() {
        let n = mesh.node_at(q[0], q[1]).expect("node at support point");
        assert_eq!(mesh.forced[k], n);
    }
    assert_eq!(mesh.nodes[mesh.centre], [0.0, 0.0]);
    // Corners exact, elements well shaped (structured cells within 2:1).
    assert!(mesh.node_at(-0.997, -0.65).is_some() && mesh.node_at(0.997, 0.65).is_some());
    assert!(mesh.worst_aspect() < 4.0, "aspect {}", mesh.worst_aspect());
    // Paper condition: exactly the 6 DOF of the centre node removed.
    let model = panel.model().unwrap();
    assert_eq!(model.n_dof(), 6 * mesh.nodes.len() - 6);
    assert!((0..6).all(|c| model.free_dof(mesh.centre, c).is_none()));
    let sys = model
        .assemble(&panel.laminate, &panel.design, Derivatives::First)
        .unwrap();
    assert_eq!(sys.dk.len(), 2);
    assert!(sys.d2k.is_empty() && sys.rigid_modes.is_empty());
}

#[test]
fn panels_from_study_reads_all_and_rejects_duplicate_names() {
    let study = Study::parse(
        "two.toml",
        &format!("{PANEL2}\n{}", PANEL2.replace("panel2", "panel3")),
    )
    .unwrap();
    let panels = plyscape::fe::panels_from_study(&study).unwrap();
    assert_eq!(panels.len(), 2);
    assert_eq!(panels[1].name, "panel3");
    let dup = Study::parse("dup.toml", &format!("{PANEL2}\n{PANEL2}")).unwrap();
    let e = plyscape::fe::panels_from_study(&dup).unwrap_err();
    assert_eq!(key_of(&e), "panels[1].name");
    assert!(e.to_string().starts_with("dup.toml:"), "{e}");
    let bad = Study::parse("bad.toml", &PANEL2.replace("e1 = 177e9", "e1 = -177e9")).unwrap();
    let e = plyscape::fe::panels_from_study(&bad).unwrap_err();
    assert_eq!(key_of(&e), "panels[0].material.e1");
    let none = Study::parse("none.toml", "[study]\nname = \"x\"\n").unwrap();
    assert!(plyscape::fe::panels_from_study(&none).unwrap().is_empty());
}

#[test]
fn central_patch_clamps_the_patch_nodes() {
    let text = PANEL2.replace(
        "support = \"centre_clamp\"",
        "support = \"central_patch\"\npatch_size = [0.2, 0.1]",
    );
    let (_, p) = specs(&text);
    let panel = p[0].resolve().unwrap();
    assert_eq!(
        panel.support,
        Support::CentralPatch {
            length: 0.2,
            width: 0.1
        }
    );
    let model = panel.model().unwrap();
    let mesh = model.mesh();
    let inside: Vec<usize> = (0..mesh.nodes.len())
        .filter(|&i| {
            mesh.nodes[i][0].abs() <= 0.1 + 1e-12 && mesh.nodes[i][1].abs() <= 0.05 + 1e-12
        })
        .collect();
    assert!(inside.len() >= 4, "patch corners are nodes");
    assert_eq!(model.n_dof(), 6 * (mesh.nodes.len() - inside.len()));
    for &i in &inside {
        assert!((0..6).all(|c| model.free_dof(i, c).is_none()));
    }
}

#[test]
fn bad_panel_input_names_key_and_expectation() {
    let e = resolve_err(&PANEL2.replace("[0.853, 0.0]", "[1.2, 0.0]"));
    assert_eq!(key_of(&e), "panels[0].attachment_points[2]");
    assert!(e.to_string().starts_with("test.toml:"), "{e}");

    let e = resolve_err(&PANEL2.replace("\"centre_clamp\"", "\"clamped\""));
    assert_eq!(key_of(&e), "panels[0].support");
    assert!(e.to_string().contains("central_patch"), "{e}");

    let e = resolve_err(&PANEL2.replace("\"centre_clamp\"", "\"central_patch\""));
    assert_eq!(key_of(&e), "panels[0].patch_size");

    let e = resolve_err(&PANEL2.replace(
        "support = \"centre_clamp\"",
        "support = \"central_patch\"\npatch_size = [3.0, 0.1]",
    ));
    assert_eq!(key_of(&e), "panels[0].patch_size");

    let e = resolve_err(&PANEL2.replace("e2 = 10.8e9", "e2 = 0.0"));
    assert_eq!(key_of(&e), "panels[0].material.e2");

    // ν12² ≥ E1/E2: E1/E2 = 16.39, so ν12 = 4.1 > √16.39 = 4.048 must fail.
    let e = resolve_err(&PANEL2.replace("nu12 = 0.27", "nu12 = 4.1"));
    assert_eq!(key_of(&e), "panels[0].material.nu12");

    let e = resolve_err(&PANEL2.replace(
        "{ angle = 90.0, thickness = 0.5e-3 },\n         { angle = 90.0",
        "{ angle = 90.0, thickness = -0.5e-3 },\n         { angle = 90.0",
    ));
    assert_eq!(key_of(&e), "panels[0].plies[1].thickness");

    let text = PANEL2
        .lines()
        .filter(|l| !l.contains("angle ="))
        .collect::<Vec<_>>()
        .join("\n")
        .replace("\"centre_clamp\"", "\"centre_clamp\"\nplies = []");
    let e = resolve_err(&text);
    assert_eq!(key_of(&e), "panels[0].plies");

    let e = resolve_err(&PANEL2.replace("[[1, 4], [2, 3]]", "[[1, 5]]"));
    assert_eq!(key_of(&e), "panels[0].design[0]");

    let e = resolve_err(&PANEL2.replace("divisions = 20", "divisions = 0"));
    assert_eq!(key_of(&e), "panels[0].divisions");

    let e = resolve_err(&PANEL2.replace("width = 1.3", "width = -1.3"));
    assert_eq!(key_of(&e), "panels[0].width");
}
