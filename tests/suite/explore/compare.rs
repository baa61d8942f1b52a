//! Comparison (multistart + CMA-ES), evolution table and design-space map.

use crate::common::explore::{column, ctx, study, table_without};
use crate::common::temp_dir;
use plyscape::explore::{self, DriveFlags};

/// A compare study: the MMFD multistart (unless `extra` names the method;
/// CMA-ES gets its calls as budget), then CMA-ES.
fn text(name: &str, problem: &str, extra: &str) -> String {
    let method = if extra.contains("method") {
        ""
    } else {
        "method = \"mmfd\"\n"
    };
    format!(
        "[study]\nname = \"{name}\"\nseed = 4\n[problem]\nname = \"{problem}\"\n\
         [multistart]\n{method}sampler = \"sobol\"\nstarts = 16\n{extra}[compare]\n[map]\nresolution = 21\n"
    )
}

#[test]
fn compare_tables_are_identical_on_one_and_two_threads() {
    let tmp = temp_dir("cmp-threads");
    let dir = tmp.path().to_path_buf();
    let s = study("c", &text("c", "himmelblau", ""));
    let (d1, d2) = (dir.join("t1"), dir.join("t2"));
    explore::run_compare(&ctx(&s, &d1, 1, DriveFlags::default())).unwrap();
    explore::run_compare(&ctx(&s, &d2, 2, DriveFlags::default())).unwrap();
    for f in ["runs.csv", "optima.csv", "comparison.csv", "evolution.csv"] {
        assert_eq!(
            table_without(&d1.join("c").join(f), &["wall_seconds"]),
            table_without(&d2.join("c").join(f), &["wall_seconds"]),
            "{f}"
        );
    }
}

#[test]
fn comparison_names_the_global_minimum() {
    let tmp = temp_dir("cmp-global");
    let dir = tmp.path().to_path_buf();
    // Himmelblau: four global minima, f* = 0 (Himmelblau 1972, p. 428).
    let s = study("h", &text("h", "himmelblau", ""));
    let rows = explore::run_compare(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    let minima = [
        [3.0, 2.0],
        [-2.805118, 3.131312],
        [-3.779310, -3.283186],
        [3.584428, -1.848126],
    ];
    // A tolerance row and a strict row per method; no constraints, so
    // both hold the method's best design.
    assert_eq!(rows.len(), 4);
    for r in &rows {
        assert!(r.best_f.unwrap().abs() < 1e-6, "{r:?}");
        assert!(
            minima
                .iter()
                .any(|m| (m[0] - r.best_x[0]).abs() < 1e-3 && (m[1] - r.best_x[1]).abs() < 1e-3),
            "{r:?}"
        );
        assert!(r.feasible);
    }
    let ms = &rows[0];
    assert_eq!(ms.method, "multistart-mmfd");
    assert_eq!(ms.distinct_optima, Some(4));
    // CMA-ES gets the multistart's function calls as its budget and stops
    // at the end of the generation that reaches it.
    let t = table_without(&dir.join("h/comparison.csv"), &[]);
    let calls: Vec<usize> = column(&t, "function_calls")
        .iter()
        .map(|c| c.parse().unwrap())
        .collect();
    assert!(calls[2] <= calls[0] + 64, "{calls:?}");
    // The four minima are equally good (f = 0 to the clustering
    // tolerance), so p_single_start counts every start that reaches any of
    // them: the certified runs, recomputed here from runs.csv.
    let runs = table_without(&dir.join("h/runs.csv"), &[]);
    let hits = column(&runs, "optimum")
        .iter()
        .filter(|o| !o.is_empty())
        .count();
    assert_eq!(
        column(&runs, "class")
            .iter()
            .filter(|c| *c == "converged")
            .count(),
        hits
    );
    assert_eq!(ms.p_single_start, Some(hits as f64 / 16.0));
    assert!(hits >= 15, "{hits} of 16 starts certified");

    // Periodic2: the unique global minimum f = -5 at theta1 = +-90 (seam),
    // theta2 = -30 (closed form, explore::problem::problems::Periodic2).
    let s = study("p", &text("p", "periodic2", ""));
    let rows = explore::run_compare(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    for r in &rows {
        assert!((r.best_f.unwrap() + 5.0).abs() < 1e-6, "{r:?}");
        assert!(
            (r.best_x[0].abs() - 90.0).abs() < 1e-2 && (r.best_x[1] + 30.0).abs() < 1e-2,
            "{r:?}"
        );
    }
}

#[test]
fn evolution_table_and_map_match_direct_evaluation() {
    let tmp = temp_dir("cmp-map");
    let dir = tmp.path().to_path_buf();
    // HS 22: constrained, so the map has infeasible cells.
    let s = study("m", &text("m", "hs22", ""));
    explore::run_compare(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    let slices = explore::run_map(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    assert_eq!(slices.len(), 1);
    let p = explore::problem(&s).unwrap();
    let map = table_without(&dir.join("m/map.csv"), &[]);
    assert_eq!(map.len(), 1 + 21 * 21);
    assert_eq!(map[0], ["x_x1", "x_x2", "f", "g1", "g2", "max_g"]);
    for row in &map[1..] {
        let x: Vec<f64> = row[..2].iter().map(|v| v.parse().unwrap()).collect();
        let e = p.evaluate(&x, false).unwrap();
        assert_eq!(row[2].parse::<f64>().unwrap(), e.f);
        assert_eq!(row[5].parse::<f64>().unwrap(), e.max_g());
    }
    let svg = std::fs::read_to_string(dir.join("m/map.svg")).unwrap();
    assert!(svg.contains("local optima") && svg.contains("CMA-ES best"));
    // evolution.csv: one row per generation, the evaluations grow, every
    // generation has a population mean.
    let ev = table_without(&dir.join("m/evolution.csv"), &[]);
    let best: Vec<f64> = column(&ev, "best_f")
        .iter()
        .map(|v| v.parse().unwrap())
        .collect();
    let calls: Vec<usize> = column(&ev, "function_calls")
        .iter()
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(best.len() > 5);
    assert!(calls.windows(2).all(|w| w[0] < w[1]));
    let mean = column(&ev, "mean_f");
    assert!(mean.iter().all(|m| !m.is_empty()));
}

#[test]
fn more_than_two_variables_get_slices_through_the_base_design() {
    let tmp = temp_dir("cmp-slices");
    let dir = tmp.path().to_path_buf();
    let s = study(
        "r",
        "[study]\nname = \"r\"\n[problem]\nname = \"rosenbrock\"\ndimension = 4\n\
         [map]\nresolution = 5\npairs = [[0, 1], [3, 2]]\n",
    );
    let slices = explore::run_map(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    assert_eq!(slices.len(), 2);
    let p = explore::problem(&s).unwrap();
    let centre: Vec<f64> = p
        .variables()
        .iter()
        .map(|v| 0.5 * (v.lower + v.upper))
        .collect();
    // Slice (3, 2): x3 along the first axis, x2 along the second, x0 and x1
    // at the box centre (no optima yet).
    let t = table_without(&dir.join("r/map_3_2.csv"), &[]);
    assert_eq!(t.len(), 1 + 25);
    for row in &t[1..] {
        let mut x = centre.clone();
        x[3] = row[0].parse().unwrap();
        x[2] = row[1].parse().unwrap();
        assert_eq!(
            row[2].parse::<f64>().unwrap(),
            p.evaluate(&x, false).unwrap().f
        );
    }
    assert!(dir.join("r/map_0_1.svg").exists());
    let bad = study(
        "b",
        "[problem]\nname = \"rosenbrock\"\ndimension = 4\n[map]\npairs = [[0, 4]]\n",
    );
    let e = explore::run_map(&ctx(&bad, &dir, 1, DriveFlags::default())).unwrap_err();
    assert!(e.to_string().contains("map.pairs[0]"), "{e}");
}

#[test]
fn bipop_is_chosen_in_the_study_and_reported() {
    let tmp = temp_dir("cmp-bipop");
    let dir = tmp.path().to_path_buf();
    // `[evolve] restarts = "bipop"`: the comparison names the method, the
    // manifest records the schedule and every run's regime, λ, σ0 and
    // evaluations, which add up to the evolution's function calls. (A
    // budget of its own, so that there are restarts.)
    let s = study(
        "b",
        &text(
            "b",
            "himmelblau",
            "[evolve]\nrestarts = \"bipop\"\nmax_evaluations = 3000\n",
        ),
    );
    let rows = explore::run_compare(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    assert_eq!(rows[2].method, "cmaes-bipop");
    assert!(rows[2].best_f.unwrap().abs() < 1e-6, "{:?}", rows[2]);
    let t = table_without(&dir.join("b/comparison.csv"), &[]);
    assert_eq!(
        column(&t, "method"),
        [
            "multistart-mmfd",
            "multistart-mmfd",
            "cmaes-bipop",
            "cmaes-bipop"
        ]
    );
    assert_eq!(
        column(&t, "basis"),
        ["tolerance", "strict", "tolerance", "strict"]
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("b/manifest.json")).unwrap())
            .unwrap();
    let ev = &m["commands"]["evolve"];
    assert_eq!(ev["restarts"], "bipop");
    assert_eq!(ev["solver"], "BIPOP-CMA-ES");
    let runs = ev["runs"].as_array().unwrap();
    let small = runs.iter().filter(|r| r["regime"] == "small").count();
    assert_eq!(ev["small_runs"].as_u64(), Some(small as u64));
    assert_eq!(ev["large_runs"].as_u64(), Some((runs.len() - small) as u64));
    assert!(small >= 1, "{runs:?}");
    let spent: u64 = runs
        .iter()
        .map(|r| r["evaluations"].as_u64().unwrap())
        .sum();
    assert_eq!(spent as usize, rows[2].function_calls);
    let svg = std::fs::read_to_string(dir.join("b/convergence.svg")).unwrap();
    assert!(svg.contains("BIPOP-CMA-ES (best so far)"));
    // The default stays IPOP, under the method name it always had.
    let s = study(
        "i",
        &text("i", "himmelblau", "[evolve]\nrestarts = \"ipop\"\n"),
    );
    let rows = explore::run_compare(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    assert_eq!(rows[2].method, "cmaes");
    // A bad value names the file, the key, the value and the choices, and
    // is refused before the multistart runs.
    let bad = study(
        "x",
        &text("x", "himmelblau", "[evolve]\nrestarts = \"lpop\"\n"),
    );
    let e = explore::run_compare(&ctx(&bad, &dir, 1, DriveFlags::default()))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("x.toml")
            && e.contains("evolve.restarts")
            && e.contains("\"lpop\"")
            && e.contains("one of ipop, bipop"),
        "{e}"
    );
    assert!(!dir.join("x/runs.csv").exists());
    let e = explore::run_evolve(&ctx(&bad, &dir, 1, DriveFlags::default()), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("evolve.restarts"), "{e}");
}

/// `[evolve] restarts = ["ipop", "bipop"]`: one comparison row per
/// schedule, each equal to the row of a study with that schedule alone
/// (same seed, same numbers), both on the multistart's function calls.
#[test]
fn listed_schedules_each_equal_their_run_alone_on_one_budget() {
    let tmp = temp_dir("cmp-both");
    let dir = tmp.path().to_path_buf();
    let without_wall = |p: &std::path::Path| table_without(p, &["wall_seconds"]);
    for problem in ["hs22", "himmelblau"] {
        let run = |name: &str, evolve: &str| {
            let s = study(name, &text(name, problem, evolve));
            let rows = explore::run_compare(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
            explore::run_map(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
            (rows, dir.join(name))
        };
        let both = "[evolve]\nrestarts = [\"ipop\", \"bipop\"]\n";
        let (rows, d) = run("both", both);
        let (_, ipop) = run("ipop", "");
        let (_, bipop) = run("bipop", "[evolve]\nrestarts = \"bipop\"\n");
        let methods: Vec<&str> = rows.iter().map(|r| r.method.as_str()).step_by(2).collect();
        assert_eq!(
            methods,
            ["multistart-mmfd", "cmaes", "cmaes-bipop"],
            "{problem}"
        );
        // comparison.csv: the multistart and IPOP rows (tolerance and
        // strict) of the IPOP study, then the BIPOP rows of the BIPOP study.
        let t = without_wall(&d.join("comparison.csv"));
        let (ti, tb) = (
            without_wall(&ipop.join("comparison.csv")),
            without_wall(&bipop.join("comparison.csv")),
        );
        let mut expect = ti[..5].to_vec();
        expect.extend(tb[3..5].iter().cloned());
        assert_eq!(t, expect);
        // evolution.csv: each schedule's rows, told apart by `method`,
        // equal the table of its study alone (which has no such column).
        let ev = table_without(&d.join("evolution.csv"), &[]);
        assert_eq!(ev[0][0], "method");
        for (method, alone) in [("cmaes", &ipop), ("cmaes-bipop", &bipop)] {
            let mine: Vec<Vec<String>> = ev[1..]
                .iter()
                .filter(|r| r[0] == method)
                .map(|r| r[1..].to_vec())
                .collect();
            let other = table_without(&alone.join("evolution.csv"), &[]);
            assert_eq!(other[0], ev[0][1..], "{problem} {method}");
            assert_eq!(mine, other[1..], "{problem} {method}");
        }
        // One budget, the multistart's function calls, that neither
        // schedule exceeds; the manifest lists both with their calls.
        let calls: Vec<usize> = column(&t, "function_calls")
            .iter()
            .map(|c| c.parse().unwrap())
            .collect();
        assert!(calls[2] <= calls[0] && calls[4] <= calls[0], "{calls:?}");
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("manifest.json")).unwrap())
                .unwrap();
        let e = &m["commands"]["evolve"];
        assert_eq!(e["max_evaluations"].as_u64(), Some(calls[0] as u64));
        assert_eq!(e["restarts"], serde_json::json!(["ipop", "bipop"]));
        let sched = e["schedules"].as_array().unwrap();
        for (k, (method, solver)) in [("cmaes", "IPOP-CMA-ES"), ("cmaes-bipop", "BIPOP-CMA-ES")]
            .into_iter()
            .enumerate()
        {
            assert_eq!(sched[k]["method"], method);
            assert_eq!(sched[k]["solver"], solver);
            assert_eq!(
                sched[k]["function_calls"].as_u64(),
                Some(calls[2 * k + 2] as u64)
            );
            let spent: u64 = sched[k]["runs"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| r["evaluations"].as_u64().unwrap())
                .sum();
            assert_eq!(spent as usize, calls[2 * k + 2], "{problem} {method}");
        }
        // Each schedule drawn on the convergence plot and marked on the map.
        let svg = std::fs::read_to_string(d.join("convergence.svg")).unwrap();
        assert!(
            svg.contains("IPOP-CMA-ES (best so far)") && svg.contains("BIPOP-CMA-ES (best so far)"),
            "{problem}"
        );
        let map = std::fs::read_to_string(d.join("map.svg")).unwrap();
        assert!(
            map.contains("IPOP-CMA-ES best") && map.contains("BIPOP-CMA-ES best"),
            "{problem}"
        );
    }
}

/// No `[evolve]`, `restarts = "ipop"` and `restarts = ["ipop"]` are one
/// and the same search: identical tables, no `method` column.
#[test]
fn the_default_schedule_is_ipop_however_written() {
    let tmp = temp_dir("cmp-default");
    let dir = tmp.path().to_path_buf();
    let mut tables = Vec::new();
    for (name, evolve) in [
        ("none", ""),
        ("one", "[evolve]\nrestarts = \"ipop\"\n"),
        ("list", "[evolve]\nrestarts = [\"ipop\"]\n"),
    ] {
        let s = study(name, &text(name, "hs22", evolve));
        explore::run_compare(&ctx(&s, &dir, 1, DriveFlags::default())).unwrap();
        let d = dir.join(name);
        tables.push((
            std::fs::read(d.join("evolution.csv")).unwrap(),
            table_without(&d.join("comparison.csv"), &["wall_seconds"]),
        ));
    }
    assert!(tables.iter().all(|t| *t == tables[0]));
    let header = String::from_utf8(tables[0].0.clone()).unwrap();
    assert!(header.starts_with("generation,function_calls,"), "{header}");
}

/// A bad schedule list names the file, the key, the value and what is
/// expected, and is refused before any work.
#[test]
fn bad_schedule_lists_are_refused_before_any_work() {
    let tmp = temp_dir("cmp-bad-list");
    let dir = tmp.path().to_path_buf();
    for (value, key, shown, expected) in [
        ("[]", "evolve.restarts", "[]", "a non-empty list"),
        ("3", "evolve.restarts", "3", "one of ipop, bipop"),
        (
            "[\"ipop\", \"lpop\"]",
            "evolve.restarts[1]",
            "\"lpop\"",
            "one of ipop, bipop",
        ),
        (
            "[\"ipop\", 2]",
            "evolve.restarts[1]",
            "2",
            "one of ipop, bipop",
        ),
        (
            "[\"bipop\", \"ipop\", \"bipop\"]",
            "evolve.restarts[2]",
            "\"bipop\"",
            "each schedule once",
        ),
    ] {
        let s = study(
            "bad",
            &text(
                "bad",
                "himmelblau",
                &format!("[evolve]\nrestarts = {value}\n"),
            ),
        );
        let e = plyscape::cli::check_study(&s).unwrap_err().to_string();
        let want = format!("bad.toml: `{key}` = {shown}: expected");
        assert!(e.starts_with(&want) && e.contains(expected), "{value}: {e}");
        let e = explore::run_compare(&ctx(&s, &dir, 1, DriveFlags::default()))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&want), "{value}: {e}");
        assert!(!dir.join("bad/runs.csv").exists(), "{value}: work was done");
    }
}

#[test]
fn tol_fun_is_read_from_the_study_and_ends_runs_earlier() {
    // `[evolve] tol_fun`: a run restarts once its recent best values and
    // current values lie within that range. On Himmelblau (exact
    // objective, 4 global minima at f = 0) with 3000 evaluations, a range
    // of 1e-3 ends each run long before 1e-12 does, so more runs fit the
    // same budget; the value is recorded, and a bad one is refused.
    let tmp = temp_dir("cmp-tolfun");
    let dir = tmp.path().to_path_buf();
    let runs = |name: &str, extra: &str| {
        let s = study(
            name,
            &text(
                name,
                "himmelblau",
                &format!("[evolve]\nmax_evaluations = 3000\n{extra}"),
            ),
        );
        explore::run_evolve(&ctx(&s, &dir, 1, DriveFlags::default()), None).unwrap();
        let m: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join(format!("{name}/manifest.json"))).unwrap(),
        )
        .unwrap();
        let ev = &m["commands"]["evolve"];
        (
            ev["runs"].as_array().unwrap().len(),
            ev["tol_fun"].as_f64().unwrap(),
        )
    };
    let (tight, t1) = runs("t", "");
    let (loose, t2) = runs("l", "tol_fun = 1e-3\n");
    assert_eq!((t1, t2), (1e-12, 1e-3));
    assert!(loose > tight, "runs: {loose} with 1e-3, {tight} with 1e-12");
    let bad = study("x", &text("x", "himmelblau", "[evolve]\ntol_fun = -1.0\n"));
    let e = explore::run_evolve(&ctx(&bad, &dir, 1, DriveFlags::default()), None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("x.toml") && e.contains("evolve.tol_fun") && e.contains(">= 0"),
        "{e}"
    );
}
