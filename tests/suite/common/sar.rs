//! Helpers shared by the tests on the SAR study files: exact text
//! replacement, the coarse version of a SAR study, and the one builder of
//! the coarse flexible SAR scenes that the flexible, centre-clamp and
//! hold-down tests run ([`CoarseSar`]).
#![allow(dead_code)]

use plyscape::scene::{load_scene, Scene};
use plyscape::study::Study;

/// Replace every occurrence of `from` in `text`, requiring `count` of them
/// (so that a change of the study file cannot silently void a test).
pub fn replace(text: &str, from: &str, to: &str, count: usize) -> String {
    assert_eq!(
        text.matches(from).count(),
        count,
        "expected {count} × {from:?} in the study"
    );
    text.replace(from, to)
}

/// A SAR study text made coarse for tests: both panels on `divisions`
/// mesh divisions with `modes` modes, 0–0.5 s sampled every 5 ms, at
/// rtol 1e-10 and atol 1e-12 (the shipped studies: 32 divisions, 14
/// modes, 0–3 s every 10 ms, rtol 1e-6, atol 1e-8).
pub fn coarse_sar(text: &str, divisions: usize, modes: usize) -> String {
    coarsen(text, divisions, Some(modes))
}

/// [`coarse_sar`] with `modes = None` keeping the shipped 14 modes and the
/// 10 ms output step.
fn coarsen(text: &str, divisions: usize, modes: Option<usize>) -> String {
    let mut t = replace(
        text,
        "divisions = 32",
        &format!("divisions = {divisions}"),
        2,
    );
    if let Some(modes) = modes {
        t = replace(&t, "modes = 14", &format!("modes = {modes}"), 2);
    }
    t = replace(&t, "t_end = 3.0", "t_end = 0.5", 1);
    if modes.is_some() {
        t = replace(&t, "dt_out = 0.01", "dt_out = 0.005", 1);
    }
    t = replace(&t, "rtol = 1e-6", "rtol = 1e-10", 1);
    replace(&t, "atol = 1e-8", "atol = 1e-12", 1)
}

/// The SAR study `text` with the outer plies (1 and 4) of panel `panel`
/// (2 or 3, the panel of body `B<panel>`) at `theta_deg` degrees (shipped:
/// 55°), and the study's four ply-angle sensitivities cut to the one
/// `B<panel>.design.theta_1_4` when `sens`, else to none.
pub fn vary_panel(text: &str, panel: usize, theta_deg: f64, sens: bool) -> String {
    let lanes = "sensitivities = [\"B3.design.theta_1_4\", \"B3.design.theta_2_3\", \
                 \"B2.design.theta_1_4\", \"B2.design.theta_2_3\"]";
    let lane = if sens {
        format!("sensitivities = [\"B{panel}.design.theta_1_4\"]")
    } else {
        String::new()
    };
    let t = replace(text, lanes, &lane, 1);
    // The panel's plies: its entry, from its name to the next panel (or
    // the end of the file).
    let name = format!("name = \"panel{panel}\"");
    let (head, tail) = t.split_once(&name).expect("the panel's entry");
    let (entry, rest) = match tail.split_once("[[panels]]") {
        Some((entry, rest)) => (entry, Some(rest)),
        None => (tail, None),
    };
    let entry = replace(
        entry,
        "{ angle = 55.0, thickness",
        &format!("{{ angle = {theta_deg:.15}, thickness"),
        2,
    );
    match rest {
        Some(rest) => format!("{head}{name}{entry}[[panels]]{rest}"),
        None => format!("{head}{name}{entry}"),
    }
}

/// A coarse flexible SAR scene: a shipped SAR study made coarse (both
/// panels on `divisions` mesh divisions, 0–0.5 s at rtol 1e-10, atol
/// 1e-12; with `modes`, also that many modes per panel and output every
/// 5 ms, as [`coarse_sar`]), one panel's outer plies varied and at most one
/// sensitivity ([`vary_panel`]), run flexible or rigid.
pub struct CoarseSar<'a> {
    /// The shipped study's text.
    pub text: &'a str,
    /// Its file name, as errors and outputs name it.
    pub file: &'a str,
    /// Mesh divisions of both panels (shipped: 32).
    pub divisions: usize,
    /// Modes of both panels, with output every 5 ms; `None` keeps the
    /// shipped 14 modes and 10 ms.
    pub modes: Option<usize>,
    /// The panel (2 or 3) whose outer plies are at `theta_deg`.
    pub panel: usize,
    /// The angle of that panel's outer plies \[°\].
    pub theta_deg: f64,
    /// With the one sensitivity `B<panel>.design.theta_1_4` (else none).
    pub sens: bool,
    /// `false` drops the "flexibility" effect: the same scene run rigid.
    pub flexible: bool,
}

impl CoarseSar<'_> {
    /// The study text of the scene.
    pub fn text(&self) -> String {
        let mut t = coarsen(self.text, self.divisions, self.modes);
        t = vary_panel(&t, self.panel, self.theta_deg, self.sens);
        if !self.flexible {
            t = replace(
                &t,
                "effects = [\"actuators\", \"damping\", \"flexibility\", \"quadratic_velocity\"]",
                "effects = [\"actuators\", \"damping\", \"quadratic_velocity\"]",
                1,
            );
        }
        t
    }

    /// The scene, loaded.
    pub fn scene(&self) -> Scene {
        load_scene(&Study::parse(self.file, &self.text()).unwrap()).unwrap()
    }
}

/// The two-angle SAR problem's gradients at `x` (`e`, an evaluation with
/// gradients there) against central differences of `p`'s own `evaluate`
/// with a step of 0.01°: every component of ∂f and ∂g₁ within 1e-5 of
/// the largest component of its gradient (dg/dθ1 is far smaller than
/// dg/dθ2, and the differences carry the integrator's error over h).
pub fn assert_gradients_match_central_differences(
    p: &dyn plyscape::optimize::Problem,
    x: [f64; 2],
    e: &plyscape::optimize::Evaluation,
) {
    let (gf, gg) = (e.grad_f.as_ref().unwrap(), e.grad_g.as_ref().unwrap());
    let h = 0.01; // degrees
    let mut fd = [[0.0; 2]; 2];
    for i in 0..2 {
        let (mut xp, mut xm) = (x, x);
        xp[i] += h;
        xm[i] -= h;
        let (ep, em) = (
            p.evaluate(&xp, false).unwrap(),
            p.evaluate(&xm, false).unwrap(),
        );
        fd[0][i] = (ep.f - em.f) / (2.0 * h);
        fd[1][i] = (ep.g[0] - em.g[0]) / (2.0 * h);
    }
    for (k, (an, fd)) in [gf, &gg[0]].into_iter().zip(&fd).enumerate() {
        let scale = fd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..2 {
            let rel = (an[i] - fd[i]).abs() / scale;
            println!(
                "{} d/dx{i}: analytic {:e}, FD {:e}, error {rel:.1e} of the largest component",
                ["f", "g"][k],
                an[i],
                fd[i]
            );
            assert!(rel < 1e-5, "{} d/dx{i}: {rel:e}", ["f", "g"][k]);
        }
    }
}
