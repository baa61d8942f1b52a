//! Rigid SAR antenna, phase 1 (studies/sar_phase1_rigid.toml, geometry
//! from /work/shared/design/sar_geometry.json, a reconstruction).
use plyscape::mbs::simulate::{load_scene, simulate};
use plyscape::mbs::{System, Workspace};
use plyscape::study::Study;
use std::time::Instant;

fn sar() -> plyscape::mbs::scene::Scene {
    let study = Study::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/studies/sar_phase1_rigid.toml"
    ))
    .unwrap();
    load_scene(&study).unwrap()
}

/// Timing of the right-hand side and of the whole 0–3 s run (release;
/// run with `--ignored --nocapture`).
#[test]
#[ignore]
fn sar_timing() {
    let scene = sar();
    let sys = System::new(scene.model.clone());
    let mut y = sys.initial_state();
    sys.project(0.0, &mut y).unwrap();
    let mut dy = vec![0.0; y.len()];
    let mut ws = Workspace::empty();
    let n = 20000;
    let t = Instant::now();
    for _ in 0..n {
        sys.rhs(0.0, &y, &mut dy, &mut ws);
    }
    println!(
        "rhs f64: {:.2} us",
        t.elapsed().as_secs_f64() / n as f64 * 1e6
    );
    let yd: Vec<num_dual::Dual64> = y.iter().map(|&v| num_dual::Dual64::new(v, 1.0)).collect();
    let mut dyd = yd.clone();
    let mut wsd = Workspace::empty();
    let t = Instant::now();
    for _ in 0..n {
        sys.rhs(0.0, &yd, &mut dyd, &mut wsd);
    }
    println!(
        "rhs dual: {:.2} us",
        t.elapsed().as_secs_f64() / n as f64 * 1e6
    );
    let mut times = vec![];
    for _ in 0..5 {
        let t = Instant::now();
        let (_, sim) = simulate(&scene).unwrap();
        times.push(t.elapsed().as_secs_f64());
        println!("{:?}", sim.stats);
    }
    times.sort_by(f64::total_cmp);
    println!("simulate 0-3 s median: {:.2} ms", times[2] * 1e3);
}
