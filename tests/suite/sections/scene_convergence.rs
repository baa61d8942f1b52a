//! `[scene_convergence]`: a grid of panel meshes × modes over a flexible
//! scene with responses; the finest variant is the reference.

use plyscape::sections::scene_convergence::{reference, run_grid, write_csv, ConvergenceSpec};
use plyscape::study::Study;

#[test]
fn grid_over_mesh_and_modes_writes_errors_against_the_finest() {
    let tmp = crate::common::temp_dir("scene-conv");
    let dir = tmp.path().to_path_buf();
    // The main study's scene, shortened to 0.3 s.
    let main = include_str!("../../../studies/main.toml");
    assert_eq!(
        main.matches("t_end = 3.0").count(),
        1,
        "main.toml changed: update this test"
    );
    std::fs::write(
        dir.join("scene.toml"),
        main.replace("t_end = 3.0", "t_end = 0.3"),
    )
    .unwrap();
    let text = "[scene_convergence]\nscene = \"scene.toml\"\ndivisions = [6, 8]\nmodes = [3, 5]\n";
    std::fs::write(dir.join("conv.toml"), text).unwrap();
    let study = Study::load(dir.join("conv.toml")).unwrap();
    let spec: ConvergenceSpec = study.require_section("scene_convergence", "").unwrap();
    let rows = run_grid(&study, &spec, |_| {}).unwrap();
    assert_eq!(rows.len(), 4);
    let r = reference(&rows).unwrap();
    assert_eq!((r.divisions, r.modes), (8, 5));
    for v in &rows {
        assert_eq!(v.responses.len(), 2);
        assert!(v.responses.iter().all(|(_, x)| x.is_finite() && *x > 0.0));
        assert!(v.build_ms > 0.0 && v.integrate_ms > 0.0 && v.rhs_calls > 0);
    }
    let path = write_csv(&rows, &dir).unwrap();
    let csv = std::fs::read_to_string(path).unwrap();
    let last = csv.lines().last().unwrap();
    assert!(last.starts_with("8,5,"));
    // The reference's own errors are zero.
    assert_eq!(
        last.split(',').filter(|c| *c == "0.000e0").count(),
        2,
        "{last}"
    );
    // Bad input names the key.
    let bad = Study::parse(
        dir.join("b.toml"),
        &text.replace("modes = [3, 5]", "modes = [0]"),
    )
    .unwrap();
    let spec: ConvergenceSpec = bad.require_section("scene_convergence", "").unwrap();
    let e = run_grid(&bad, &spec, |_| {}).unwrap_err().to_string();
    assert!(e.contains("scene_convergence.modes"), "{e}");
}
