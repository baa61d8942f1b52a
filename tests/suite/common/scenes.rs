//! Scene fixtures: the shipped study files (`studies/*.toml`) and scenes
//! given as study text (a `[scene]` table), built and simulated.

use plyscape::scene::{load_scene, Scene, SceneSpec};
use plyscape::simulate::{simulate, Simulation};
use plyscape::study::Study;
use std::path::PathBuf;

/// The path of the shipped study `studies/<file>`.
pub fn study_path(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("studies")
        .join(file)
}

/// The text of the shipped study `studies/<file>`.
pub fn shipped_text(file: &str) -> String {
    let path = study_path(file);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The shipped study `studies/<file>`, loaded.
pub fn shipped_study(file: &str) -> Study {
    Study::load(study_path(file)).unwrap()
}

/// The scene of the shipped study `studies/<file>`.
pub fn shipped_scene(file: &str) -> Scene {
    load_scene(&shipped_study(file)).unwrap()
}

/// The `[scene]` table of a study text, parsed but not built.
pub fn scene_spec(text: &str) -> SceneSpec {
    let table: toml::Table = toml::from_str(text).unwrap();
    table["scene"].clone().try_into().unwrap()
}

/// The scene of a study text, built.
pub fn scene(text: &str) -> Scene {
    scene_spec(text).build().unwrap()
}

/// The scene of a study text, simulated.
pub fn run(text: &str) -> Simulation {
    simulate(&scene(text)).unwrap().1
}

/// The history column `name` of a simulation (by header prefix, see
/// [`super::tables::column_index`]).
pub fn column(sim: &Simulation, name: &str) -> Vec<f64> {
    super::tables::column(&sim.headers, &sim.rows, name)
}
