//! `[optimum_report]` (explore::multistart::optimum_report): the multistart's run from
//! its first start as the paper's Table 5 and Figs. 10–12. The history is
//! the run's own (its last row is the run's row in `runs.csv`), the summary
//! row repeats the run's numbers with the start's f and the reduction, and
//! the start curve of a scene output is a plain simulation of the study at
//! its start design. On HS 22 (optimum (1, 1), both constraints active,
//! Hock & Schittkowski 1981), Himmelblau with steepest descent, and a
//! coarse version of studies/sar_optimize.toml (8 mesh divisions, 4 modes,
//! 0–0.5 s).

use crate::common::explore::{column, ctx, study, table_without};
use crate::common::sar::replace;
use crate::common::temp_dir;
use plyscape::explore::DriveFlags;
use plyscape::study::Study;
use std::path::Path;

const HS22: &str = "[study]\nname = \"rep_hs22\"\nseed = 7\n\
    [problem]\nname = \"hs22\"\n\
    [multistart]\nmethod = \"mmfd\"\nsampler = \"sobol\"\nstarts = 8\nfeasible_only = true\npoints = [[0.0, 1.0]]\n\
    [optimum_report]\n";

/// A table as rows of text, header first.
fn table(path: &Path) -> Vec<Vec<String>> {
    table_without(path, &[])
}

/// The one value of column `name` in row `row` (1-based after the header).
fn cell<'a>(t: &'a [Vec<String>], row: usize, name: &str) -> &'a str {
    let c = t[0]
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", t[0]));
    &t[row][c]
}

fn float(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s:?}"))
}

/// The history's last row is the run's row of start 0 in `runs.csv`
/// (design, f, g, calls, iterations), its first row is the start with one
/// evaluation with gradients, and the calls and wall times never
/// decrease. Returns (history, runs).
fn history_is_the_run(dir: &Path, vars: &[&str], m: usize) -> (Vec<Vec<String>>, Vec<Vec<String>>) {
    let h = table(&dir.join("iterations.csv"));
    let runs = table(&dir.join("runs.csv"));
    assert_eq!(cell(&runs, 1, "start"), "0");
    let last = h.len() - 1;
    assert_eq!(cell(&h, 1, "record"), "start");
    assert_eq!(cell(&h, 1, "iteration"), "0");
    assert_eq!(
        (cell(&h, 1, "function_calls"), cell(&h, 1, "gradient_calls")),
        ("1", "1")
    );
    let mut same = vec![
        ("f", "f"),
        ("function_calls", "function_calls"),
        ("gradient_calls", "gradient_calls"),
        ("iteration", "iterations"),
    ];
    let g: Vec<String> = (1..=m).map(|j| format!("g{j}")).collect();
    same.extend(g.iter().map(|g| (g.as_str(), g.as_str())));
    let x: Vec<String> = vars.iter().map(|v| format!("x_{v}")).collect();
    same.extend(x.iter().map(|x| (x.as_str(), x.as_str())));
    for (hc, rc) in same {
        assert_eq!(
            cell(&h, last, hc),
            cell(&runs, 1, rc),
            "{hc} vs runs.csv {rc}"
        );
    }
    for v in vars {
        assert_eq!(
            cell(&h, 1, &format!("x_{v}")),
            cell(&runs, 1, &format!("x0_{v}"))
        );
    }
    for name in ["function_calls", "gradient_calls", "wall [s]"] {
        let c: Vec<f64> = column(&h, name).iter().map(|s| float(s)).collect();
        assert!(c.windows(2).all(|w| w[1] >= w[0]), "{name}: {c:?}");
    }
    (h, runs)
}

/// The summary row repeats the run's numbers, takes f at the start from
/// the history, and computes the reduction and the objective in its unit.
fn summary_is_the_run(
    dir: &Path,
    h: &[Vec<String>],
    runs: &[Vec<String>],
    unit: &str,
    divisor: f64,
) -> Vec<Vec<String>> {
    let s = table(&dir.join("optimum_summary.csv"));
    assert_eq!(s.len(), 2, "one row");
    for (sc, rc) in [
        ("f_optimum", "f"),
        ("exit", "exit"),
        ("function_calls", "function_calls"),
        ("gradient_calls", "gradient_calls"),
        ("iterations", "iterations"),
        ("wall_seconds", "wall_seconds"),
        ("max_g", "max_g"),
    ] {
        assert_eq!(cell(&s, 1, sc), cell(runs, 1, rc), "{sc} vs runs.csv {rc}");
    }
    assert_eq!(cell(&s, 1, "f_start"), cell(h, 1, "f"));
    let (f0, f1) = (
        float(cell(&s, 1, "f_start")),
        float(cell(&s, 1, "f_optimum")),
    );
    let reduction = float(cell(&s, 1, "reduction [%]"));
    assert!(
        (reduction - 100.0 * (f0 - f1) / f0).abs() < 1e-12,
        "{reduction}"
    );
    let o0 = float(cell(&s, 1, &format!("objective_start [{unit}]")));
    let o1 = float(cell(&s, 1, &format!("objective_optimum [{unit}]")));
    assert!(
        (o0 - f0 * divisor).abs() <= 1e-12 * o0.abs(),
        "{o0} vs {f0} x {divisor}"
    );
    assert!(
        (o1 - f1 * divisor).abs() <= 1e-12 * o1.abs(),
        "{o1} vs {f1} x {divisor}"
    );
    s
}

#[test]
fn hs22_history_and_summary_are_the_runs() {
    let tmp = temp_dir("optrep-hs22");
    let out = tmp.path().to_path_buf();
    let st = study("rep_hs22", HS22);
    plyscape::explore::run_multistart(&ctx(&st, &out, 2, DriveFlags::default())).unwrap();
    let dir = out.join("rep_hs22");
    let (h, runs) = history_is_the_run(&dir, &["x1", "x2"], 2);
    assert!(runs.len() > 2, "more starts than the reported one");
    assert_eq!(h[0][3], "objective [-]");
    // From (0, 1), f = 4, to the optimum (1, 1), f* = 1, on both limits.
    let s = summary_is_the_run(&dir, &h, &runs, "-", 1.0);
    assert_eq!(cell(&s, 1, "f_start"), "4");
    assert!((float(cell(&s, 1, "reduction [%]")) - 75.0).abs() < 1e-6);
    for v in ["x_x1", "x_x2"] {
        assert!((float(cell(&s, 1, v)) - 1.0).abs() < 1e-6, "{v}");
    }
    assert_eq!(cell(&s, 1, "active_constraints"), "2");
    assert_eq!(cell(&s, 1, "active"), "g1; g2");
    assert_eq!(cell(&s, 1, "feasibility_tolerance"), "1e-6");
    assert_eq!(
        (cell(&s, 1, "variables"), cell(&s, 1, "constraints")),
        ("2", "2")
    );
    // The solver's active set at its last design (g >= its CT).
    assert_eq!(cell(&h, h.len() - 1, "active"), "g1; g2");
    for f in [
        "iterations.svg",
        "iterations_constraints.svg",
        "iterations_design.svg",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let manifest = plyscape::report::read_manifest(&dir).unwrap();
    assert_eq!(manifest["commands"]["optimum_report"]["start"], 0);
}

#[test]
fn steepest_descent_history_is_the_run_too() {
    let tmp = temp_dir("optrep-steepest");
    let out = tmp.path().to_path_buf();
    let text = "[study]\nname = \"rep_himmelblau\"\nseed = 3\n[problem]\nname = \"himmelblau\"\n\
                [multistart]\nmethod = \"steepest\"\nstarts = 3\npoints = [[0.0, 0.0]]\n[optimum_report]\n";
    let st = study("rep_himmelblau", text);
    plyscape::explore::run_multistart(&ctx(&st, &out, 2, DriveFlags::default())).unwrap();
    let dir = out.join("rep_himmelblau");
    let (h, runs) = history_is_the_run(&dir, &["x1", "x2"], 0);
    // From (0, 0) (f = 170) to the minimum (3, 2), f* = 0 (Himmelblau 1972).
    let s = summary_is_the_run(&dir, &h, &runs, "-", 1.0);
    assert_eq!(cell(&s, 1, "f_start"), "170");
    assert!(float(cell(&s, 1, "f_optimum")) < 1e-12);
    assert_eq!(cell(&s, 1, "active"), "");
    // No constraints, no constraint plot.
    assert!(!dir.join("iterations_constraints.svg").exists());
}

#[test]
fn bad_sections_are_refused_before_any_work() {
    let check = |text: &str| {
        let s = Study::parse("rep.toml", text).unwrap();
        plyscape::cli::check_study(&s).err().map(|e| e.to_string())
    };
    assert_eq!(check(HS22), None);
    let e = check(&format!("{HS22}quantity = \"R3.angle\"\n")).unwrap();
    assert!(
        e.contains("optimum_report") && e.contains("unknown field `quantity`"),
        "{e}"
    );
    let e = check(&format!("{HS22}quantities = [\"R3.angle\"]\n")).unwrap();
    assert!(
        e.contains("`optimum_report.quantities`") && e.contains("scene"),
        "{e}"
    );
    let alone = "[study]\nname = \"rep\"\n[problem]\nname = \"hs22\"\n[optimum_report]\n";
    let e = check(alone).unwrap();
    assert!(
        e.contains("`optimum_report`") && e.contains("[multistart]"),
        "{e}"
    );
    let scene = sar_text(&[]);
    assert_eq!(check(&scene), None);
    for (q, expected) in [
        ("\"R3.reaction\"", "one-column"),
        ("\"R3.angle\", \"R3.angle\"", "each output once"),
    ] {
        let bad = scene.replace(QUANTITIES, &format!("quantities = [{q}]"));
        let e = check(&bad).unwrap();
        assert!(
            e.contains("`optimum_report.quantities[") && e.contains(expected),
            "{e}"
        );
    }
}

/// The `quantities` line of studies/sar_optimize.toml.
const QUANTITIES: &str = "quantities = [\"R3.angle\", \"B2.strain_energy\", \"B3.strain_energy\"]";

/// studies/sar_optimize.toml, coarse (8 divisions, 4 modes, 0–0.5 s),
/// with one sampled start besides the paper's, the staggered sensitivity
/// form (the states do not depend on the gradient lanes, to the bit), no
/// [compare] or [map], and these changes.
fn sar_text(changes: &[(&str, &str)]) -> String {
    let mut t = include_str!("../../../studies/sar_optimize.toml").to_string();
    for (from, to, n) in [
        ("divisions = 32", "divisions = 8", 2),
        ("modes = 14", "modes = 4", 2),
        ("t_end = 3.0", "t_end = 0.5", 1),
        ("starts = 3", "starts = 1", 1),
        ("\n[compare]\n", "\n", 1),
        ("[map]\nresolution = 19\n", "", 1),
        (
            "method = \"tsit45\"",
            "method = \"tsit45\"\nsensitivity_form = \"staggered\"",
            1,
        ),
    ] {
        t = replace(&t, from, to, n);
    }
    for (from, to) in changes {
        t = replace(&t, from, to, 1);
    }
    t
}

#[test]
fn sar_start_curve_is_a_plain_simulation_at_the_start() {
    let tmp = temp_dir("optrep-sar");
    let out = tmp.path().to_path_buf();
    let text = sar_text(&[(
        QUANTITIES,
        "quantities = [\"R3.angle\", \"B3.strain_energy\"]",
    )]);
    let st = study("sar_optimize", &text);
    plyscape::explore::run_multistart(&ctx(&st, &out, 2, DriveFlags::default())).unwrap();
    let dir = out.join("sar_optimize");
    let (h, runs) = history_is_the_run(&dir, &["theta1_deg", "theta2_deg"], 1);
    assert_eq!(
        (cell(&h, 1, "x_theta1_deg"), cell(&h, 1, "x_theta2_deg")),
        ("55", "-55")
    );
    // The plain simulation of the study (its [[panels]] plies are the start
    // design 55/-55/-55/55): its Ψ₀ is the divisor of f (normalize_at =
    // start), so f = 1 at the start and the objective there is Ψ₀ in J*s.
    let scene = plyscape::scene::load_scene(&st).unwrap();
    let plain = plyscape::simulate::simulate(&scene).unwrap().1;
    let psi0 = plain
        .responses
        .iter()
        .find(|r| r.name == "psi0")
        .unwrap()
        .value;
    assert!((float(cell(&h, 1, "f")) - 1.0).abs() < 1e-12);
    let s = summary_is_the_run(&dir, &h, &runs, "J*s", psi0);
    assert!((float(cell(&s, 1, "objective_start [J*s]")) - psi0).abs() <= 1e-12 * psi0);
    let g1 = float(cell(&runs, 1, "g1"));
    let active = if g1 >= -3e-3 { "g1 (u3_peak)" } else { "" };
    assert_eq!(cell(&s, 1, "active"), active);
    // Fig. 12: the start column is the plain simulation's R3 angle, row by
    // row at the same 12 digits; the optimum differs from it.
    let c = plain
        .headers
        .iter()
        .position(|x| x == "R3.angle [rad]")
        .unwrap();
    let fig = table(&dir.join("start_optimum_R3_angle.csv"));
    assert_eq!(
        fig[0],
        [
            "t [s]",
            "R3.angle at start [rad]",
            "R3.angle at optimum [rad]",
            "optimum - start [rad]"
        ]
    );
    assert_eq!(fig.len() - 1, plain.rows.len());
    let mut largest = 0.0f64;
    for (row, p) in fig[1..].iter().zip(&plain.rows) {
        assert_eq!(row[0], format!("{:.12e}", p[0]));
        assert_eq!(row[1], format!("{:.12e}", p[c]));
        let (a, b, d) = (float(&row[1]), float(&row[2]), float(&row[3]));
        assert!((d - (b - a)).abs() <= 1e-11 * a.abs().max(b.abs()));
        largest = largest.max(d.abs());
    }
    assert!(largest > 1e-9, "the optimum's angle differs: {largest}");
    for f in [
        "start_optimum_R3_angle.svg",
        "start_optimum_B3_strain_energy.csv",
        "start_optimum_B3_strain_energy.svg",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
}

#[test]
fn unknown_scene_output_is_refused_before_the_multistart() {
    let tmp = temp_dir("optrep-sar-bad");
    let out = tmp.path().to_path_buf();
    let text = sar_text(&[(QUANTITIES, "quantities = [\"R9.angle\"]")]);
    let st = study("sar_optimize", &text);
    let e = plyscape::explore::run_multistart(&ctx(&st, &out, 2, DriveFlags::default()))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`optimum_report.quantities[0]`") && e.contains("R9.angle"),
        "{e}"
    );
    assert!(!out.join("sar_optimize/runs.csv").exists());
}
