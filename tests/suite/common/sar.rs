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
