//! Certified optima: every run's end classified, stopped ends polished,
//! optima.csv certified only, class counts beside it.

use crate::common::explore::{column, ctx, study, table_without};
use crate::common::temp_dir;
use plyscape::explore::{self, DriveFlags};

/// HS 100's optimum f* = 680.6300573 (Hock & Schittkowski 1981, problem
/// 100) and its standard start (1, 2, 0, 4, 0, 1, 1).
const HS100_F: f64 = 680.630_057_3;

/// The HS 100 multistart with `extra` keys; MMFD (DOT's settings) unless
/// `extra` names the method.
fn hs100(extra: &str) -> String {
    let method = if extra.contains("method") {
        ""
    } else {
        "method = \"mmfd\"\n"
    };
    format!(
        "[study]\nname = \"hs100\"\nseed = 3\n[problem]\nname = \"hs100\"\n\
         [multistart]\n{method}sampler = \"lhs\"\nstarts = 19\npoints = [[1.0, 2.0, 0.0, 4.0, 0.0, 1.0, 1.0]]\n{extra}"
    )
}

/// With DOT's settings (the default preset) the runs stop up to hundreds
/// above f* (DABOBJ = 1e-4 |f(x0)|); the polish from every end makes them
/// one certified optimum at f* to 1e-6, and the counts add up.
#[test]
fn hs100_with_dot_settings_and_the_polish_has_one_optimum() {
    let tmp = temp_dir("cert-hs100");
    let dir = tmp.path().to_path_buf();
    let s = study("hs100", &hs100(""));
    let r = explore::run_multistart(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    let d = dir.join("hs100");
    let o = table_without(&d.join("optima.csv"), &[]);
    assert_eq!(o.len(), 2, "one optimum: {o:?}");
    let f: f64 = column(&o, "f")[0].parse().unwrap();
    assert!((f - HS100_F).abs() <= 1e-6 * HS100_F, "f = {f}");
    let max_g: f64 = column(&o, "max_g")[0].parse().unwrap();
    assert!(max_g <= 1e-6, "{max_g}");
    // Every run in the optimum is certified; runs.csv says so per row.
    let runs = table_without(&d.join("runs.csv"), &[]);
    let class = column(&runs, "class");
    let optimum = column(&runs, "optimum");
    for (c, o) in class.iter().zip(&optimum) {
        assert_eq!(c == "converged", o == "0", "{c} {o}");
    }
    let converged = class.iter().filter(|c| *c == "converged").count();
    assert_eq!(r.classes.converged, converged);
    assert_eq!(r.classes.runs, 20);
    assert!(converged >= 19, "{:?}", r.classes);
    // Multipliers of the active constraints (1 and 4 at x*) are reported
    // and non-negative on certified rows.
    for (k, c) in class.iter().enumerate() {
        if c == "converged" {
            for j in [1, 4] {
                let l: f64 = column(&runs, &format!("lambda{j}"))[k].parse().unwrap();
                assert!(l > 0.0, "start {k}: lambda{j} = {l}");
            }
            let kt: f64 = column(&runs, "kt_residual")[k].parse().unwrap();
            assert!(kt <= 1e-4);
        }
    }
    // The companion table and the manifest carry the same counts.
    let t = table_without(&d.join("run_classes.csv"), &[]);
    assert_eq!(column(&t, "class")[0], "converged");
    assert_eq!(column(&t, "count")[0], converged.to_string());
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("manifest.json")).unwrap()).unwrap();
    let counts = &m["commands"]["multistart"];
    assert_eq!(
        counts["classes"]["converged"].as_u64(),
        Some(converged as u64)
    );
    assert_eq!(counts["feasibility_tolerance"].as_f64(), Some(1e-6));
}

/// Without the polish, DOT's exits leave runs stopped short: they are
/// classified `stopped`, belong to no optimum, and optima.csv lists only
/// certified designs (so fewer runs, never a stopped one).
#[test]
fn stopped_runs_are_counted_and_never_listed_as_optima() {
    let tmp = temp_dir("cert-stopped");
    let dir = tmp.path().to_path_buf();
    let s = study("hs100", &hs100("polish = false\n"));
    let r = explore::run_multistart(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    let runs = table_without(&dir.join("hs100/runs.csv"), &[]);
    let class = column(&runs, "class");
    let stopped = class.iter().filter(|c| *c == "stopped").count();
    assert!(stopped >= 5, "DOT's exits stop most runs short: {class:?}");
    assert_eq!(r.classes.stopped, stopped);
    for (c, o) in class.iter().zip(column(&runs, "optimum")) {
        assert_eq!(c == "converged", !o.is_empty(), "{c} {o}");
    }
    assert!(column(&runs, "polish").iter().all(|p| p.is_empty()));
    // Every listed optimum is one of the certified runs' designs.
    let certified: usize = r.optima.iter().map(|o| o.count).sum();
    assert_eq!(certified, r.classes.converged);
}

/// `[multistart] method = "sqp"` on the same 20 HS 100 starts: every run
/// certified at the one optimum f* (to 1e-6), with fewer function calls
/// in all than MMFD with DOT's settings and the polish spend there.
#[test]
fn hs100_with_sqp_certifies_every_run_for_fewer_calls() {
    let tmp = temp_dir("cert-hs100-sqp");
    let dir = tmp.path().to_path_buf();
    let calls = |extra: &str, name: &str| -> (usize, f64, usize) {
        let s = study(
            name,
            &hs100(extra).replace(
                "name = \"hs100\"\nseed",
                &format!("name = \"{name}\"\nseed"),
            ),
        );
        let r = explore::run_multistart(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
        let runs = table_without(&dir.join(name).join("runs.csv"), &[]);
        let total: usize = column(&runs, "function_calls")
            .iter()
            .map(|c| c.parse::<usize>().unwrap())
            .sum();
        let o = table_without(&dir.join(name).join("optima.csv"), &[]);
        let f: f64 = column(&o, "f")[0].parse().unwrap();
        (total, f, r.classes.converged)
    };
    let (sqp, f, converged) = calls("method = \"sqp\"\n", "hs100_sqp");
    let (mmfd, _, _) = calls("", "hs100_mmfd");
    eprintln!("HS 100, 20 starts: SQP {sqp} function calls, MMFD + polish {mmfd}");
    assert_eq!(converged, 20);
    assert!((f - HS100_F).abs() <= 1e-6 * HS100_F, "f = {f}");
    assert!(sqp < mmfd, "SQP {sqp} calls, MMFD {mmfd}");
    // Measured 633 with the first step a fiftieth of the range (599 with a
    // tenth, 1919 before the model's self-scaling, optimize::sqp step 5);
    // a rise past it is a regression.
    assert!(sqp <= 633, "SQP {sqp} calls");
}

/// `[multistart] noise = "measured"` on HS 100: the allowance is rounding
/// (σ_f ≈ 1e-13), and still every run ends certified at its own end:
/// step 4 compares an end only with visited designs no less feasible
/// than it (before, all 20 runs went back to designs using up to 1e-6 of
/// the feasibility tolerance, f lower by up to 4e-5, 4 uncertified).
/// optima.csv carries the noise measured at the optimum; without the key
/// it has no noise columns.
#[test]
fn measured_noise_is_reported_at_the_optima_and_keeps_every_end() {
    let tmp = temp_dir("cert-hs100-noise");
    let dir = tmp.path().to_path_buf();
    let text = hs100("method = \"sqp\"\nnoise = \"measured\"\n")
        .replace("name = \"hs100\"\nseed", "name = \"hs100_noise\"\nseed");
    let s = study("hs100_noise", &text);
    let r = explore::run_multistart(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    assert_eq!(r.classes.converged, 20, "{:?}", r.classes);
    let d = dir.join("hs100_noise");
    let runs = table_without(&d.join("runs.csv"), &[]);
    for p in column(&runs, "polish") {
        assert!(!p.contains("returned"), "{p}");
    }
    let o = table_without(&d.join("optima.csv"), &[]);
    assert_eq!(o.len(), 2, "one optimum: {o:?}");
    let rel: f64 = column(&o, "noise_f_relative")[0].parse().unwrap();
    assert!(rel > 0.0 && rel < 1e-12, "{rel}");
    let g: f64 = column(&o, "noise_max_g")[0].parse().unwrap();
    assert!(g > 0.0 && g < 1e-12, "{g}");
    assert_eq!(column(&o, "noise_failed")[0], "");
    let n: usize = column(&o, "noise_evaluations")[0].parse().unwrap();
    assert!(n >= 8, "{n}");
    // The same study with an allowance given: no noise columns.
    let plain = hs100("method = \"sqp\"\nnoise = 1e-9\n")
        .replace("name = \"hs100\"\nseed", "name = \"hs100_plain\"\nseed");
    let s = study("hs100_plain", &plain);
    explore::run_multistart(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    let header = std::fs::read_to_string(dir.join("hs100_plain/optima.csv")).unwrap();
    assert!(
        !header.lines().next().unwrap().contains("noise"),
        "{header}"
    );
}

/// Issue 38's comparison with scipy's SLSQP: HS 21/35/43/76/100/22, one
/// `[multistart] method = "sqp"` run each from the starts 2,−1 /
/// 0.5,0.5,0.5 / 0,0,0,0 / 0.5,0.5,0.5,0.5 / 1,2,0,4,0,1,1 / 2,2, the
/// noise measured, every end certified: every run converged within 1e-6
/// of the published f* (Hock & Schittkowski 1981; HS 22's f* = 1), and
/// all six at most 1.3× the calls (f + g) scipy 1.17.1's SLSQP at ftol
/// 1e-12 takes from the same starts (`results/sqp_peers/slsqp.csv`,
/// written by `scripts/peers/slsqp_hs.py`). Measured: 58 f + 53 g against
/// SLSQP's 114 f + 53 g, 0.66×.
#[test]
fn six_hock_schittkowski_runs_cost_less_than_slsqp() {
    use plyscape::optimize::testproblems as tp;
    let tmp = temp_dir("cert-hs-six");
    let dir = tmp.path().to_path_buf();
    let cases = [
        ("hs21", "2.0, -1.0", tp::hs21().f_opt),
        ("hs35", "0.5, 0.5, 0.5", tp::hs35().f_opt),
        ("hs43", "0.0, 0.0, 0.0, 0.0", tp::hs43().f_opt),
        ("hs76", "0.5, 0.5, 0.5, 0.5", tp::hs76().f_opt),
        (
            "hs100",
            "1.0, 2.0, 0.0, 4.0, 0.0, 1.0, 1.0",
            tp::hs100().f_opt,
        ),
        ("hs22", "2.0, 2.0", 1.0),
    ];
    let mut ours = 0;
    for (name, x0, f_opt) in cases {
        let text = format!(
            "[study]\nname = \"{name}\"\nseed = 1\n[problem]\nname = \"{name}\"\n\
             [multistart]\npoints = [[{x0}]]\nstarts = 0\nmethod = \"sqp\"\nnoise = \"measured\"\n"
        );
        let s = study(name, &text);
        let r = explore::run_multistart(&ctx(&s, &dir, 1, DriveFlags::default())).unwrap();
        assert_eq!(r.classes.converged, 1, "{name}: {:?}", r.classes);
        let runs = table_without(&dir.join(name).join("runs.csv"), &[]);
        let f: f64 = column(&runs, "f")[0].parse().unwrap();
        assert!(
            (f - f_opt).abs() <= 1e-6 * f_opt.abs().max(1.0),
            "{name}: f = {f}"
        );
        for c in ["function_calls", "gradient_calls"] {
            ours += column(&runs, c)[0].parse::<usize>().unwrap();
        }
    }
    let peer = std::fs::read_to_string("results/sqp_peers/slsqp.csv").unwrap();
    let mut rows = peer.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    let at = |k: &str| header.iter().position(|h| *h == k).unwrap();
    let (fc, gc) = (at("function_calls"), at("gradient_calls"));
    let slsqp: usize = rows
        .map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            v[fc].parse::<usize>().unwrap() + v[gc].parse::<usize>().unwrap()
        })
        .sum();
    eprintln!("six HS runs: {ours} calls, SLSQP {slsqp}");
    assert_eq!(slsqp, 167, "results/sqp_peers/slsqp.csv changed");
    assert!(ours as f64 <= 1.3 * slsqp as f64, "{ours} against {slsqp}");
    assert!(
        ours <= 111,
        "{ours} calls: a rise past the measured 111 is a regression"
    );
}
