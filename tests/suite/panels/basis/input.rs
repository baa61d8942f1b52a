//! Input errors of the basis: bad mode counts and the like reported by
//! key, and updated derivatives refused for repeated modes.

use super::fixtures::{panel, test_panel, PLY_T};
use plyscape::error::Error;
use plyscape::fe::Support;
use plyscape::laminate::{Laminate, Orthotropic, Ply};
use plyscape::modal::ModeUpdate;
use plyscape::panels::{basis_for_study, panel_basis};
use plyscape::study::Study;

#[test]
fn bad_input_is_reported() {
    let text = r#"
[[panels]]
name = "panel3"
length = 1.0
width = 0.6
divisions = 8
material = { e1 = 177e9, e2 = 10.8e9, g12 = 7.6e9, g13 = 7.6e9, g23 = 8.504e9, nu12 = 0.27, rho = 1600.0 }
plies = [{ angle = 0.0, thickness = 0.5e-3 }, { angle = 90.0, thickness = 0.5e-3 }]
"#;
    let study = Study::parse("basis.toml", text).unwrap();
    // The named panel works.
    let b = basis_for_study(&study, "panel3", 3, None, None).unwrap();
    assert_eq!(b.n_modes, 3);
    // Unknown name: input error naming file, key and value.
    match basis_for_study(&study, "panel9", 3, None, None) {
        Err(Error::Input {
            file,
            key,
            value,
            expected,
        }) => {
            assert_eq!(file, "basis.toml");
            assert_eq!(key, "panels.name");
            assert_eq!(value, "\"panel9\"");
            assert!(expected.contains("\"panel3\""), "{expected}");
        }
        other => panic!("expected an input error, got {other:?}"),
    }
    // No modes.
    let e = basis_for_study(&study, "panel3", 0, None, None).unwrap_err();
    assert!(
        matches!(&e, Error::Input { key, .. } if key == "n_modes"),
        "{e:?}"
    );
    let p = test_panel(Support::CentreClamp);
    let e = panel_basis(&p, 0, Some(ModeUpdate::Fixed)).unwrap_err();
    assert!(
        matches!(&e, Error::Input { key, .. } if key == "n_modes"),
        "{e:?}"
    );
    // More modes than free DOFs.
    let tiny = panel(1.0, 0.6, 1, &[0.0, 90.0, 90.0, 0.0], Support::CentreClamp);
    let dofs = 6 * (tiny.mesh.nodes.len() - 1);
    let e = panel_basis(&tiny, dofs + 1, None).unwrap_err();
    assert!(
        matches!(&e, Error::Input { key, .. } if key == "n_modes"),
        "{e:?}"
    );
}

#[test]
fn repeated_modes_refuse_updated_derivatives() {
    // A square plate of an isotropic material (E1 = E2, G = E/2(1+ν)) on the
    // union-jack mesh, which is invariant under a 90° rotation: the two
    // rocking modes of the centre clamp form an exactly repeated pair.
    let e = 70e9;
    let nu = 0.3;
    let g = e / (2.0 * (1.0 + nu));
    let iso = Orthotropic {
        e1: e,
        e2: e,
        g12: g,
        g13: g,
        g23: g,
        nu12: nu,
        rho: 2700.0,
    };
    let mut p = panel(1.0, 1.0, 8, &[0.0, 0.0, 0.0, 0.0], Support::CentreClamp);
    p.laminate = Laminate::new(
        (0..4)
            .map(|_| Ply {
                material: iso,
                thickness: PLY_T,
                angle: 0.0,
            })
            .collect(),
    )
    .unwrap();
    let fixed = panel_basis(&p, 4, Some(ModeUpdate::Fixed)).unwrap();
    let l = &fixed.eigenvalues;
    assert!((l[1] - l[0]).abs() < 1e-8 * l[1], "{l:?}");
    match panel_basis(&p, 4, Some(ModeUpdate::Updated)) {
        Err(Error::Numerical { place, detail, .. }) => {
            assert!(place.contains("panels::basis"), "{place}");
            assert!(detail.contains("modes 0..=1"), "{detail}");
        }
        other => panic!("expected a numerical error, got {other:?}"),
    }
}
