//! Timing of `panels::panel_basis` on SAR panel 3 (lay-up [0/90/90/0],
//! centre clamp, `studies/panel_convergence.toml`) at 32 divisions with 14
//! modes: one-shot `panel_basis` (set-up included) and the per-design cost
//! with a reused `BasisBuilder`, without derivatives and with updated-mode
//! derivatives for the 2 design variables; for comparison the bare
//! `PanelAnalysis::run` (no basis conversion). Wall time, one thread,
//! fastest and median of `REPEATS` runs.
//!
//! Run: `cargo bench --bench panel_basis_bench`

use plyscape::fe::PanelSpec;
use plyscape::modal::ModeUpdate;
use plyscape::panels::{panel_basis, BasisBuilder, PanelAnalysis};
use plyscape::study::Study;
use std::time::Instant;

const REPEATS: usize = 7;
const DIVISIONS: usize = 32;
const N_MODES: usize = 14;

fn stats(mut t: Vec<f64>) -> (f64, f64) {
    t.sort_by(f64::total_cmp);
    (1e3 * t[0], 1e3 * t[t.len() / 2])
}

fn time(mut f: impl FnMut()) -> (f64, f64) {
    f(); // warm-up
    stats(
        (0..REPEATS)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

fn main() -> plyscape::Result<()> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let study = Study::load(root.join("studies/panel_convergence.toml"))?;
    let specs: Vec<PanelSpec> = study.section("panels")?.unwrap_or_default();
    let mut spec = specs[0].clone();
    spec.divisions = DIVISIONS;
    let panel = spec.resolve()?;
    let dofs = panel.model()?.n_dof();
    println!(
        "{} at {DIVISIONS} divisions ({dofs} DOF), {N_MODES} modes; ms, fastest / median of {REPEATS}",
        panel.name
    );
    for (label, want) in [
        ("no derivatives", None),
        ("updated, 2 variables", Some(ModeUpdate::Updated)),
        ("fixed, 2 variables", Some(ModeUpdate::Fixed)),
    ] {
        let one_shot = time(|| {
            panel_basis(&panel, N_MODES, want).expect("basis");
        });
        let mut builder = BasisBuilder::new(&panel, want)?;
        let reused = time(|| {
            builder.basis(&panel.laminate, N_MODES).expect("basis");
        });
        let mut analysis = PanelAnalysis::new(&panel, want)?;
        let bare = time(|| {
            analysis.run(&panel.laminate, N_MODES).expect("modes");
        });
        println!(
            "  {label:<22} panel_basis {:>7.1} / {:>7.1}   BasisBuilder::basis {:>7.1} / {:>7.1}   \
             PanelAnalysis::run {:>7.1} / {:>7.1}",
            one_shot.0, one_shot.1, reused.0, reused.1, bare.0, bare.1
        );
    }
    Ok(())
}
