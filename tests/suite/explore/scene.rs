//! The scene problem (`[problem] name = "scene"`, explore::problem::scene_problem)
//! on a coarse version of studies/sar_optimize.toml made by text
//! replacement (8 mesh divisions, 4 modes, 0–0.5 s, tight integrator
//! tolerances) so that one evaluation takes a fraction of a second: its
//! gradients against central finite differences of its own `evaluate`,
//! its 180° periodicity, and input errors that name the key.

use crate::common::sar::{assert_gradients_match_central_differences, coarse_sar, replace};
use crate::common::temp_dir;
use plyscape::explore;
use plyscape::optimize::Problem;
use plyscape::study::Study;
use std::time::Instant;

const STUDY: &str = include_str!("../../../studies/sar_optimize.toml");

/// The coarse study text.
fn coarse() -> String {
    coarse_sar(STUDY, 8, 4)
}

fn build(text: &str) -> plyscape::Result<Box<dyn Problem>> {
    explore::problem(&Study::parse("sar_optimize.toml", text)?)
}

#[test]
fn gradients_match_central_differences_of_evaluate() {
    // Objective Ψ₀/Ψ₀(start) and constraint peak U3/peak U3(start) − 1,
    // both variables tied to panels 2 and 3: exact forward sensitivities
    // (summed over the B2 and B3 lanes, per degree) against central
    // differences of `evaluate` itself (panel bases rebuilt at x ± h).
    let p = build(&coarse()).unwrap();
    assert_eq!(p.variables().len(), 2);
    assert_eq!(p.n_constraints(), 1);
    // At the start design the normalized values are exactly 1 and 0
    // (same simulation as the reference values).
    let e0 = p.evaluate(&[55.0, -55.0], false).unwrap();
    assert!(
        (e0.f - 1.0).abs() < 1e-12 && e0.g[0].abs() < 1e-12,
        "{e0:?}"
    );
    let x = [40.0, -25.0];
    let t = Instant::now();
    let e = p.evaluate(&x, true).unwrap();
    println!(
        "evaluation with gradients: {:.3} s",
        t.elapsed().as_secs_f64()
    );
    assert_gradients_match_central_differences(p.as_ref(), x, &e);
}

/// The study text at design `x` [deg] by the old road: the ply angles
/// written into the `[[panels]]` text (plies 1 and 4 take x[0], plies 2
/// and 3 take x[1], in both panels), the scene's outputs dropped.
fn text_at(x: [f64; 2]) -> String {
    let plies = "plies = [{ angle = 55.0, thickness = 0.5e-3 }, { angle = -55.0, thickness = 0.5e-3 }, { angle = -55.0, thickness = 0.5e-3 }, { angle = 55.0, thickness = 0.5e-3 }]";
    let new = format!(
        "plies = [{{ angle = {a:?}, thickness = 0.5e-3 }}, {{ angle = {b:?}, thickness = 0.5e-3 }}, {{ angle = {b:?}, thickness = 0.5e-3 }}, {{ angle = {a:?}, thickness = 0.5e-3 }}]",
        a = x[0],
        b = x[1]
    );
    staggered(&replace(&coarse(), plies, &new, 2))
}

/// The study text with the staggered form of the sensitivities (the states
/// then do not depend on the sensitivity lanes, to the bit).
fn staggered(text: &str) -> String {
    replace(
        text,
        "method = \"tsit45\"",
        "method = \"tsit45\"\nsensitivity_form = \"staggered\"",
        1,
    )
}

/// Ψ₀, peak U3 and their gradients per degree (lanes of B2 and B3 summed
/// per variable) from a scene loaded from text.
fn responses_from_text(x: [f64; 2]) -> [(f64, [f64; 2]); 2] {
    let study = Study::parse("sar_optimize.toml", &text_at(x)).unwrap();
    let scene = plyscape::scene::load_scene(&study).unwrap();
    let names: Vec<&str> = scene.params.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "B3.design.theta_1_4",
            "B3.design.theta_2_3",
            "B2.design.theta_1_4",
            "B2.design.theta_2_3"
        ]
    );
    let sim = plyscape::simulate::simulate(&scene).unwrap().1;
    let deg = std::f64::consts::PI / 180.0;
    ["psi0", "u3_peak"].map(|name| {
        let r = sim.responses.iter().find(|r| r.name == name).unwrap();
        let g = &r.gradient;
        (r.value, [(g[0] + g[2]) * deg, (g[1] + g[3]) * deg])
    })
}

#[test]
fn design_as_numbers_matches_the_text_road() {
    // The scene problem takes a design as numbers through a plan built
    // once (pooled basis builders, no TOML written or parsed). The old
    // road rewrote the study's text, reloaded the scene and rebuilt both
    // panel analyses per design: with the same four sensitivity lanes
    // (tied_lanes = false) and form (staggered, whose states do not depend
    // on the lanes) it must give the same f, g and gradients to 1e-12
    // relative. f = Ψ₀/Ψ₀(start), g = U3peak/U3peak(start) − 1.
    let untied = replace(
        &coarse(),
        "[scene_problem]\n",
        "[scene_problem]\ntied_lanes = false\n",
        1,
    );
    let study = Study::parse("sar_optimize.toml", &staggered(&untied)).unwrap();
    let p = plyscape::explore::problem::scene_problem::SceneProblem::from_study(&study).unwrap();
    let [(psi_s, _), (u3_s, _)] = responses_from_text([55.0, -55.0]);
    let x = [40.0, -25.0];
    let [(psi, dpsi), (u3, du3)] = responses_from_text(x);
    let e = p.evaluate(&x, true).unwrap();
    let close = |a: f64, b: f64, what: &str| {
        let rel = (a - b).abs() / b.abs().max(1e-300);
        println!("{what}: plan {a:e}, text {b:e}, relative {rel:.1e}");
        assert!(rel <= 1e-12, "{what}: {a:e} vs {b:e} ({rel:e})");
    };
    close(p.objective_scale(), psi_s, "psi0 at start");
    close(p.bounds()[0], u3_s, "u3 peak at start");
    close(e.f, psi / psi_s, "f");
    close(e.g[0] + 1.0, u3 / u3_s, "g + 1");
    let (gf, gg) = (e.grad_f.unwrap(), e.grad_g.unwrap());
    for i in 0..2 {
        close(gf[i], dpsi[i] / psi_s, &format!("df/dx{i}"));
        close(gg[0][i], du3[i] / u3_s, &format!("dg/dx{i}"));
    }
}

#[test]
fn ply_angles_repeat_every_180_degrees() {
    // A ply at θ and θ ± 180° is the same laminate (docs/numerics.md): the
    // whole evaluation repeats to rounding.
    let p = build(&coarse()).unwrap();
    let a = p.evaluate(&[37.3, -61.7], false).unwrap();
    let b = p.evaluate(&[37.3 + 180.0, -61.7 - 180.0], false).unwrap();
    println!("f {} vs {}, g {} vs {}", a.f, b.f, a.g[0], b.g[0]);
    assert!((a.f - b.f).abs() < 1e-10 * a.f.abs(), "{} vs {}", a.f, b.f);
    assert!((a.g[0] - b.g[0]).abs() < 1e-10, "{} vs {}", a.g[0], b.g[0]);
    assert!(p.variables().iter().all(|v| v.period == Some(180.0)));
}

#[test]
fn bad_input_names_the_key() {
    let base = coarse();
    let cases = [
        (
            replace(&base, "response = \"psi0\"", "response = \"psi1\"", 1),
            "scene_problem.objective.response",
            "psi1",
        ),
        (
            replace(
                &base,
                "sets = [\"panel2:theta_1_4\", \"panel3:theta_1_4\"]",
                "sets = [\"panel2:theta_1_4\", \"panel3:theta_1_2\"]",
                1,
            ),
            "scene_problem.variables[0].sets[1]",
            "theta_2_3",
        ),
        (
            replace(
                &base,
                "sets = [\"panel2:theta_2_3\", \"panel3:theta_2_3\"]",
                "sets = [\"panel2:theta_2_3\", \"panel9:theta_2_3\"]",
                1,
            ),
            "scene_problem.variables[1].sets[1]",
            "panel9",
        ),
        (
            replace(&base, "\"B2.design.theta_1_4\", ", "", 1),
            "scene.sensitivities",
            "B2.design.theta_1_4",
        ),
        (
            replace(&base, "response = \"u3_peak\"", "response = \"u2_peak\"", 1),
            "scene_problem.constraints[0].response",
            "u2_peak",
        ),
        (
            replace(
                &base,
                "upper_relative = 1.0",
                "upper_relative = 1.0\nupper = 2.0",
                1,
            ),
            "scene_problem.constraints[0]",
            "exactly one",
        ),
        (
            replace(&base, "start = [55.0, -55.0]", "start = [55.0]", 1),
            "scene_problem.start",
            "2 finite angles",
        ),
    ];
    for (text, key, detail) in cases {
        let e = build(&text).err().expect(key);
        let s = e.to_string();
        println!("{s}");
        assert!(matches!(e, plyscape::Error::Input { .. }), "{s}");
        assert!(s.contains(&format!("`{key}`")) && s.contains(detail), "{s}");
        assert!(s.starts_with("sar_optimize.toml"), "{s}");
    }
}

/// Measurement (ignored): cost of one full-size evaluation (32 divisions,
/// 14 modes, 0–3 s) with and without gradients, bdf vs tsit45 at the
/// study's tolerances, and a tsit45 run at rtol 1e-9 as the accuracy
/// reference.
/// `cargo test --release --test explore_scene -- --ignored --nocapture`
#[test]
#[ignore]
fn measure_full_evaluation_cost() {
    for (method, rtol) in [("bdf", "1e-6"), ("tsit45", "1e-6"), ("tsit45", "1e-9")] {
        let text = replace(
            STUDY,
            "method = \"tsit45\"",
            &format!("method = \"{method}\""),
            1,
        );
        let text = replace(&text, "rtol = 1e-6", &format!("rtol = {rtol}"), 1);
        let atol = if rtol == "1e-6" { "1e-8" } else { "1e-11" };
        let text = replace(&text, "atol = 1e-8", &format!("atol = {atol}"), 1);
        let t = Instant::now();
        let p = build(&text).unwrap();
        let setup = t.elapsed().as_secs_f64();
        let x = [40.0, -25.0];
        let t = Instant::now();
        let a = p.evaluate(&x, false).unwrap();
        let plain = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let b = p.evaluate(&x, true).unwrap();
        let grad = t.elapsed().as_secs_f64();
        println!(
            "{method} rtol {rtol}: setup (start design) {setup:.2} s, f only {plain:.2} s, with gradients {grad:.2} s; f = {:.10}, g = {:.10}, grad f = {:?}",
            a.f, a.g[0], b.grad_f
        );
    }
}

#[test]
fn evaluations_compute_only_what_they_are_asked() {
    // f-only: one panel basis (panel 2 stays at rest in this scene and is
    // built fixed without modes, scene::ground), none with mode
    // derivatives, no sensitivity lanes and no Jacobian-vector products
    // (tsit45 is explicit); f+g: one tied lane per shared ply angle (two)
    // and panel 3's basis with derivatives. The section's CSV carries the
    // same counts.
    let tmp = temp_dir("eval-bench");
    let dir = tmp.path().to_path_buf();
    std::fs::write(dir.join("coarse.toml"), coarse()).unwrap();
    let bench = "[eval_bench]\nproblems = [\"coarse.toml\"]\nrepeats = 1\n";
    let path = dir.join("bench.toml");
    std::fs::write(&path, bench).unwrap();
    let study = Study::load(&path).unwrap();
    let spec: plyscape::sections::eval_bench::EvalBenchSpec =
        study.require_section("eval_bench", "").unwrap();
    let rows = plyscape::sections::eval_bench::run_eval_bench(&study, &spec, |_| {}).unwrap();
    let h = plyscape::sections::eval_bench::HEADERS;
    let col = |r: &Vec<String>, name: &str| r[h.iter().position(|c| *c == name).unwrap()].clone();
    assert_eq!(rows.len(), 2);
    let (f, fg) = (&rows[0], &rows[1]);
    assert_eq!(col(f, "mode"), "f");
    assert_eq!(col(f, "design [deg]"), "55 -55");
    assert_eq!(
        [
            col(f, "lanes"),
            col(f, "bases"),
            col(f, "derivative_bases"),
            col(f, "jvp_calls")
        ],
        ["0", "1", "0", "0"]
    );
    assert_eq!(
        [
            col(fg, "lanes"),
            col(fg, "bases"),
            col(fg, "derivative_bases")
        ],
        ["2", "1", "1"]
    );
    assert!(col(fg, "jvp_calls").parse::<u64>().unwrap() > 0);
    for r in &rows {
        let total: f64 = col(r, "total [ms]").parse().unwrap();
        let parts: f64 = [
            "bases [ms]",
            "build_other [ms]",
            "integrate [ms]",
            "outputs [ms]",
        ]
        .iter()
        .map(|c| col(r, c).parse::<f64>().unwrap())
        .sum();
        assert!(total > 0.0 && parts <= total * 1.01 + 0.01, "{r:?}");
        // One repeat: its total is the median, the smallest and the
        // largest.
        assert_eq!(col(r, "total_min [ms]"), col(r, "total [ms]"), "{r:?}");
        assert_eq!(col(r, "total_max [ms]"), col(r, "total [ms]"), "{r:?}");
    }
    // The f+g of the round over the f of the round (one round: the ratio
    // of the two totals; f over itself is 1).
    assert_eq!(col(f, "total_per_f"), "1.000");
    let total = |r: &Vec<String>| col(r, "total [ms]").parse::<f64>().unwrap();
    let per_f: f64 = col(fg, "total_per_f").parse().unwrap();
    assert!(
        (per_f - total(fg) / total(f)).abs() <= 1e-3 * per_f + 1e-3,
        "{per_f} vs {} / {}",
        total(fg),
        total(f)
    );
    assert!(rows.iter().all(|r| col(r, "method") == "tsit45"));
    // The same problem with BDF (`methods`): f has Jacobian columns, f+g
    // fused the same two lanes and the same steps as f (the lanes weigh
    // nothing in the error norm).
    let bench = format!("{bench}methods = [\"bdf\"]\nforms = [\"fused\"]\n");
    std::fs::write(&path, bench).unwrap();
    let study = Study::load(&path).unwrap();
    let spec: plyscape::sections::eval_bench::EvalBenchSpec =
        study.require_section("eval_bench", "").unwrap();
    let rows = plyscape::sections::eval_bench::run_eval_bench(&study, &spec, |_| {}).unwrap();
    assert_eq!(rows.len(), 2);
    let (f, fg) = (&rows[0], &rows[1]);
    assert_eq!([col(f, "method"), col(fg, "mode")], ["bdf", "f+g fused"]);
    assert!(col(f, "jvp_calls").parse::<u64>().unwrap() > 0);
    assert_eq!(col(fg, "lanes"), "2");
    assert_eq!(col(f, "steps"), col(fg, "steps"));
}

#[test]
fn tied_lanes_give_the_summed_gradient() {
    // One lane per shared angle ("B3.design.theta_1_4+B2.design.theta_1_4",
    // both bodies seeded at once) is the derivative with respect to the
    // shared angle, i.e. the sum of the per-body lanes (linearity of the
    // sensitivity equations). The two runs integrate different sensitivity
    // systems, so they agree to rounding, not to the last bit, asserted at
    // the 1e-10 that results of a design must keep, relative to the largest
    // component of each gradient. Measured: 3e-13 and 6e-12 on ∇f, 1.5e-12
    // and 8e-12 on ∇g. The first component of ∇g is 72 times smaller than
    // the second: its 3e-14 absolute is 1.1e-10 of that component alone
    // (7.6e-11 before the tangent of the constraint-space solve was
    // written out, 6e-14 before the body-block solve; the rounding of the
    // regularised solve, amplified alike).
    let untied = replace(
        &coarse(),
        "[scene_problem]\n",
        "[scene_problem]\ntied_lanes = false\n",
        1,
    );
    let tied = build(&coarse()).unwrap();
    let summed = build(&untied).unwrap();
    let x = [40.0, -25.0];
    let (a, b) = (
        tied.evaluate(&x, true).unwrap(),
        summed.evaluate(&x, true).unwrap(),
    );
    let (ga, gb) = (a.grad_f.unwrap(), b.grad_f.unwrap());
    let (ca, cb) = (a.grad_g.unwrap(), b.grad_g.unwrap());
    for (tied, summed) in [(&ga, &gb), (&ca[0], &cb[0])] {
        let norm = summed.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (u, v) in tied.iter().zip(summed.iter()) {
            let rel = (u - v).abs() / norm;
            println!("tied {u:e}, summed {v:e}, relative to the gradient {rel:.1e}");
            assert!(rel < 1e-10, "{u:e} vs {v:e}");
        }
    }
    assert!((a.f - b.f).abs() < 1e-10 * b.f.abs(), "{} vs {}", a.f, b.f);
}

#[test]
fn fused_sensitivities_give_the_staggered_gradient() {
    // The fused form (the default with tsit45: lanes in the state,
    // J s + ∂f/∂p as one dual evaluation per lane and stage) integrates the same sensitivity
    // equations on the same steps (states alone error-controlled, norm
    // rescaled to the plain one): f, g and the gradients agree with the
    // staggered form (diffsol's sensitivity equations) to 1e-10 (measured
    // 6e-12 for f and g, 3e-12 of the largest gradient component).
    let fused = build(&coarse()).unwrap();
    let staggered = build(&staggered(&coarse())).unwrap();
    let x = [40.0, -25.0];
    let (a, b) = (
        fused.evaluate(&x, true).unwrap(),
        staggered.evaluate(&x, true).unwrap(),
    );
    let close = |u: f64, v: f64, scale: f64, what: &str| {
        let rel = (u - v).abs() / scale;
        println!("{what}: fused {u:e}, staggered {v:e}, relative {rel:.1e}");
        assert!(rel < 1e-10, "{what}: {u:e} vs {v:e}");
    };
    close(a.f, b.f, b.f.abs(), "f");
    close(a.g[0], b.g[0], b.g[0].abs(), "g");
    // Gradients relative to their largest component (dg/dθ1 is 70 times
    // smaller than dg/dθ2 here).
    let grads = [
        (a.grad_f.unwrap(), b.grad_f.unwrap()),
        (a.grad_g.unwrap()[0].clone(), b.grad_g.unwrap()[0].clone()),
    ];
    for (k, (ga, gb)) in grads.iter().enumerate() {
        let scale = gb.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..2 {
            close(ga[i], gb[i], scale, &format!("{} d/dx{i}", ["f", "g"][k]));
        }
    }
}

/// `[gradient_check]` on the coarse problem: the updated-mode gradient
/// agrees with the section's central differences (tight tolerances here),
/// the fixed-mode one is the approximation it is (its error is larger than
/// the updated one's), and both tables are written with every row.
#[test]
fn gradient_check_section_compares_fixed_and_updated_modes() {
    let tmp = temp_dir("gradcheck");
    let dir = tmp.path().to_path_buf();
    std::fs::write(dir.join("coarse.toml"), coarse()).unwrap();
    let text = "[study]\nname = \"gc\"\n[gradient_check]\nproblems = [\"coarse.toml\"]\n\
                step_deg = 1e-3\nrepeats = 1\n";
    std::fs::write(dir.join("gc.toml"), text).unwrap();
    let s = Study::load(dir.join("gc.toml")).unwrap();
    plyscape::sections::gradient_check::run_gradient_check(&s, &dir, true).unwrap();
    let csv = std::fs::read_to_string(dir.join("gc/gradient_check.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    // 3 kinds (central, updated, fixed) × 2 functions × 2 variables.
    assert_eq!(rows.len(), 12, "{csv}");
    let max_rel = |kind: &str| {
        rows.iter()
            .filter(|r| r[2] == kind)
            .map(|r| r[8].parse::<f64>().unwrap())
            .fold(0.0f64, f64::max)
    };
    let (updated, fixed) = (max_rel("updated"), max_rel("fixed"));
    assert!(
        updated < 1e-4,
        "updated-mode gradient vs central: {updated}"
    );
    assert!(fixed > 10.0 * updated, "fixed {fixed} vs updated {updated}");
}

/// `studies/sar_sweep64.toml` makes panel 2 a rigid body because in this
/// phase 1 it carries no load (R1 and R2 locked: it hangs between grounded
/// bodies). Its problem must then be sar_explore's, whose panel 2 is
/// flexible, to the integration tolerance: the same f, the same two
/// critical-point constraints and the same gradients (panel 2's lanes are
/// zero). Both coarse (8 divisions, 4 modes, the whole 0–3 s, rtol
/// 1e-10). Measured at 40°/−25°: f agrees to 7e-12 of itself, g to 8e-11,
/// ∇f to 9e-11 and ∇g to 1.6e-8 of each gradient's largest component.
#[test]
fn a_panel_that_carries_no_load_can_be_rigid() {
    // The whole 3 s, so that U3 has two local maxima in time.
    let flexible = replace(
        &coarse_sar(include_str!("../../../studies/sar_explore.toml"), 8, 4),
        "t_end = 0.5",
        "t_end = 3.0",
        1,
    );
    let mut rigid = include_str!("../../../studies/sar_sweep64.toml").to_string();
    for (from, to) in [
        ("divisions = 32", "divisions = 8"),
        ("modes = 14", "modes = 4"),
        ("dt_out = 0.01", "dt_out = 0.005"),
        ("rtol = 1e-6", "rtol = 1e-10"),
        ("atol = 1e-8", "atol = 1e-12"),
        ("rtol = \"auto\"\n", ""),
    ] {
        rigid = replace(&rigid, from, to, 1);
    }
    let parse =
        |name: &str, text: &str| explore::problem(&Study::parse(name, text).unwrap()).unwrap();
    let (a, b) = (
        parse("sar_sweep64.toml", &rigid),
        parse("sar_explore.toml", &flexible),
    );
    assert_eq!(a.n_constraints(), 2);
    assert_eq!(b.n_constraints(), 2);
    let x = [40.0, -25.0];
    let (ea, eb) = (a.evaluate(&x, true).unwrap(), b.evaluate(&x, true).unwrap());
    println!("rigid panel 2: {ea:?}\nflexible panel 2: {eb:?}");
    assert!(
        (ea.f - eb.f).abs() < 1e-9 * eb.f.abs(),
        "f {} vs {}",
        ea.f,
        eb.f
    );
    for j in 0..2 {
        assert!(
            (ea.g[j] - eb.g[j]).abs() < 1e-9,
            "g{j} {} vs {}",
            ea.g[j],
            eb.g[j]
        );
    }
    let mut pairs = vec![(ea.grad_f.unwrap(), eb.grad_f.unwrap())];
    pairs.extend(ea.grad_g.unwrap().into_iter().zip(eb.grad_g.unwrap()));
    for (ga, gb) in pairs {
        let scale = gb.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (u, v) in ga.iter().zip(&gb) {
            assert!((u - v).abs() < 1e-7 * scale, "gradient {u:e} vs {v:e}");
        }
    }
}

/// `[eval_bench] rtols` runs each case at those tolerances, and
/// `reference_rtol` gives every row its distance from an evaluation at
/// that tolerance: on the coarse problem at 40°/−25° the errors of f, g and
/// the gradients fall as rtol tightens from 1e-5 to 1e-8 (against 1e-11),
/// an f row has no gradient error, and a tolerance out of range is an
/// error naming its key.
#[test]
fn eval_bench_runs_at_each_tolerance_against_a_reference() {
    let tmp = temp_dir("eval-bench-rtols");
    let dir = tmp.path().to_path_buf();
    std::fs::write(dir.join("coarse.toml"), coarse()).unwrap();
    let bench = |rtols: &str| {
        format!(
            "[eval_bench]\nproblems = [\"coarse.toml\"]\nrepeats = 1\ndesigns = [[40.0, -25.0]]\n\
             rtols = {rtols}\nreference_rtol = 1e-11\n"
        )
    };
    let path = dir.join("bench.toml");
    let run = |text: String| {
        std::fs::write(&path, text).unwrap();
        let study = Study::load(&path).unwrap();
        let spec: plyscape::sections::eval_bench::EvalBenchSpec =
            study.require_section("eval_bench", "").unwrap();
        plyscape::sections::eval_bench::run_eval_bench(&study, &spec, |_| {})
    };
    let rows = run(bench("[1e-5, 1e-8]")).unwrap();
    let h = plyscape::sections::eval_bench::HEADERS;
    let col = |r: &Vec<String>, name: &str| r[h.iter().position(|c| *c == name).unwrap()].clone();
    let num = |r: &Vec<String>, name: &str| col(r, name).parse::<f64>().unwrap();
    assert_eq!(rows.len(), 4);
    let (f5, fg5, f8, fg8) = (&rows[0], &rows[1], &rows[2], &rows[3]);
    assert_eq!([col(f5, "rtol"), col(f8, "rtol")], ["1e-5", "1e-8"]);
    assert_eq!([col(f5, "mode"), col(fg5, "mode")], ["f", "f+g"]);
    assert_eq!(col(f5, "gradient_rel_error"), "");
    for name in ["f_rel_error", "g_max_error"] {
        println!(
            "{name}: {} at 1e-5, {} at 1e-8",
            col(f5, name),
            col(f8, name)
        );
        assert!(num(f8, name) < num(f5, name), "{name}");
    }
    let (g5, g8) = (
        num(fg5, "gradient_rel_error"),
        num(fg8, "gradient_rel_error"),
    );
    println!("gradient_rel_error: {g5:e} at 1e-5, {g8:e} at 1e-8");
    assert!(g8 < g5 && g8 < 1e-4, "{g8:e} vs {g5:e}");
    assert!(num(fg8, "steps") > num(fg5, "steps"));
    let e = run(bench("[1e-6, 0.5]")).unwrap_err().to_string();
    assert!(e.contains("eval_bench.rtols[1]"), "{e}");
}
