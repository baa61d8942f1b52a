//! Multistart driver: known optima, reproducibility over threads, resume,
//! bad input (its shards and `merge` in `shards.rs`).

use crate::common::explore::{column, ctx, study, table_without};
use crate::common::{errors, temp_dir};
use plyscape::explore::{self, DriveFlags};

/// Local method used by these tests.
const METHOD: &str = "mmfd";
/// MMFD converged far tighter than DOT's defaults (DELOBJ = 1e-3), so the
/// optima can be compared with the published minima to 1e-5.
const TIGHT: &str = "[multistart.mmfd]\ndelobj = 1e-12\ndabobj = 1e-14\nkt_tolerance = 1e-10\nmax_iterations = 500\n";

pub(super) fn himmelblau(starts: usize, extra: &str) -> String {
    format!(
        "[study]\nname = \"h\"\nseed = 11\n[problem]\nname = \"himmelblau\"\n\
         [multistart]\nmethod = \"{METHOD}\"\nsampler = \"lhs\"\nstarts = {starts}\n{extra}{TIGHT}"
    )
}

/// Himmelblau's four minima (Himmelblau 1972, p. 428; f = 0 at each).
const MINIMA: [[f64; 2]; 4] = [
    [3.0, 2.0],
    [-2.805118, 3.131312],
    [-3.779310, -3.283186],
    [3.584428, -1.848126],
];

#[test]
fn himmelblau_finds_all_four_minima_with_their_basin_counts() {
    let tmp = temp_dir("ms-himmelblau");
    let dir = tmp.path().to_path_buf();
    let s = study("h", &himmelblau(40, ""));
    let r = explore::run_multistart(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    assert_eq!(r.runs.len(), 40);
    assert_eq!(r.optima.len(), 4, "{:#?}", r.optima);
    // Each optimum is one of the known minima (to the 6 digits quoted).
    let mut counts = [0usize; 4];
    for o in &r.optima {
        assert!(o.f.abs() < 1e-9, "f = {}", o.f);
        let k = MINIMA
            .iter()
            .position(|m| (m[0] - o.x[0]).abs() < 1e-5 && (m[1] - o.x[1]).abs() < 1e-5)
            .unwrap_or_else(|| panic!("{:?} is not a known minimum", o.x));
        counts[k] = o.count;
    }
    // Basin counts: each run assigned to the nearest known minimum,
    // counted independently of the clustering.
    let mut direct = [0usize; 4];
    for run in &r.runs {
        let x = &run.result.as_ref().unwrap().x;
        let k = (0..4)
            .min_by(|&a, &b| {
                let d = |m: &[f64; 2]| (m[0] - x[0]).hypot(m[1] - x[1]);
                d(&MINIMA[a]).total_cmp(&d(&MINIMA[b]))
            })
            .unwrap();
        direct[k] += 1;
    }
    assert_eq!(counts, direct);
    assert!(direct.iter().all(|&c| c > 0));
    let shares: f64 = r.optima.iter().map(|o| o.basin_share).sum();
    assert!((shares - 1.0).abs() < 1e-12);
    // optima.csv repeats the counts; runs.csv names each run's optimum.
    let t = table_without(&dir.join("h/optima.csv"), &[]);
    let csv_counts: Vec<usize> = column(&t, "count")
        .iter()
        .map(|c| c.parse().unwrap())
        .collect();
    assert_eq!(
        csv_counts,
        r.optima.iter().map(|o| o.count).collect::<Vec<_>>()
    );
    let runs = table_without(&dir.join("h/runs.csv"), &[]);
    for (id, o) in r.optima.iter().enumerate() {
        let n = column(&runs, "optimum")
            .iter()
            .filter(|v| **v == id.to_string())
            .count();
        assert_eq!(n, o.count);
    }
}

#[test]
fn periodic_optima_merge_across_the_seam() {
    let tmp = temp_dir("ms-periodic");
    let dir = tmp.path().to_path_buf();
    let text = format!(
        "[study]\nname = \"p\"\nseed = 5\n[problem]\nname = \"periodic2\"\n\
         [multistart]\nmethod = \"{METHOD}\"\nsampler = \"sobol\"\nstarts = 64\n\
         points = [[89.0, -30.0], [-89.0, -30.0]]\n{TIGHT}"
    );
    let s = study("p", &text);
    let r = explore::run_multistart(&ctx(&s, &dir, 2, DriveFlags::default())).unwrap();
    // Closed-form landscape (Periodic2 doc): minima -5, -3, -1, 1.
    let fs: Vec<f64> = r.optima.iter().map(|o| o.f).collect();
    assert_eq!(r.optima.len(), 4, "{fs:?}");
    for (f, e) in fs.iter().zip([-5.0, -3.0, -1.0, 1.0]) {
        assert!((f - e).abs() < 1e-9, "{fs:?}");
    }
    // The global minimum sits on the seam theta1 = +-90: the two listed
    // starts approach it from both sides and land in one optimum.
    let best = &r.optima[0];
    assert_eq!(r.runs[0].optimum, Some(0));
    assert_eq!(r.runs[1].optimum, Some(0));
    let x0 = r.runs[0].result.as_ref().unwrap().x[0];
    let x1 = r.runs[1].result.as_ref().unwrap().x[0];
    assert!((89.0..=90.0).contains(&x0.abs()) && (89.0..=90.0).contains(&x1.abs()));
    assert!((best.x[1] + 30.0).abs() < 1e-3);
}

#[test]
fn one_and_two_threads_give_identical_tables() {
    let tmp = temp_dir("ms-threads");
    let dir = tmp.path().to_path_buf();
    let s = study("h", &himmelblau(24, ""));
    let (d1, d2) = (dir.join("t1"), dir.join("t2"));
    explore::run_multistart(&ctx(&s, &d1, 1, DriveFlags::default())).unwrap();
    explore::run_multistart(&ctx(&s, &d2, 2, DriveFlags::default())).unwrap();
    for f in ["runs.csv", "optima.csv"] {
        assert_eq!(
            table_without(&d1.join("h").join(f), &["wall_seconds"]),
            table_without(&d2.join("h").join(f), &["wall_seconds"]),
            "{f}"
        );
    }
}

#[test]
fn resume_after_a_kill_gives_the_uninterrupted_tables() {
    let tmp = temp_dir("ms-resume");
    let dir = tmp.path().to_path_buf();
    let s = study("h", &himmelblau(20, ""));
    let full = dir.join("full");
    explore::run_multistart(&ctx(&s, &full, 2, DriveFlags::default())).unwrap();
    let runs = std::fs::read_to_string(full.join("h/runs.csv")).unwrap();
    let lines: Vec<&str> = runs.lines().collect();
    // What a kill leaves: the header, some finished rows in completion
    // order (here: an arbitrary subset, shuffled, optimum ids still empty),
    // and half a line.
    let part = dir.join("part");
    std::fs::create_dir_all(part.join("h")).unwrap();
    let mut text = format!("{}\n", lines[0]);
    for k in [7, 2, 13, 1, 19, 4] {
        let mut fields: Vec<&str> = lines[k + 1].split(',').collect();
        *fields.last_mut().unwrap() = "";
        text.push_str(&fields.join(","));
        text.push('\n');
    }
    text.push_str(&lines[10][..lines[10].len() / 2]);
    std::fs::write(part.join("h/runs.csv"), &text).unwrap();
    let flags = DriveFlags {
        resume: true,
        ..Default::default()
    };
    let r = explore::run_multistart(&ctx(&s, &part, 1, flags)).unwrap();
    assert_eq!(r.new_runs, 14, "6 rows kept, the torn one runs again");
    for f in ["runs.csv", "optima.csv"] {
        assert_eq!(
            table_without(&full.join("h").join(f), &["wall_seconds"]),
            table_without(&part.join("h").join(f), &["wall_seconds"]),
            "{f}"
        );
    }
    // A budget stops launching cleanly; resuming without it completes.
    let budget = dir.join("budget");
    let sb = study("h", &himmelblau(20, "max_evaluations = 300\n"));
    let rb = explore::run_multistart(&ctx(&sb, &budget, 2, DriveFlags::default())).unwrap();
    let k = rb.runs.len();
    assert!(k < 20 && k > 0, "{k}");
    let used_before_last: usize = rb.runs[..k - 1].iter().map(|r| r.function_calls).sum();
    assert!(used_before_last < 300 && rb.function_calls >= 300);
    explore::run_multistart(&ctx(&s, &budget, 2, flags)).unwrap();
    for f in ["runs.csv", "optima.csv"] {
        assert_eq!(
            table_without(&full.join("h").join(f), &["wall_seconds"]),
            table_without(&budget.join("h").join(f), &["wall_seconds"]),
            "{f}"
        );
    }
    // Resuming with a changed study is refused, not mixed.
    let other = study("h", &himmelblau(20, "").replace("seed = 11", "seed = 12"));
    let e = explore::run_multistart(&ctx(&other, &part, 1, flags)).unwrap_err();
    assert!(e.to_string().contains("a start of this study"), "{e}");
    // The study changed: bad input (exit 2), not a damaged table (4).
    assert_eq!(e.exit_code(), 2, "{e}");
}

#[test]
fn wall_time_budget_stops_cleanly_and_resume_completes() {
    let tmp = temp_dir("ms-wall");
    let dir = tmp.path().to_path_buf();
    let costly = |extra: &str| {
        format!(
            "[study]\nname = \"w\"\nseed = 8\n[problem]\nname = \"himmelblau\"\ncost_ms = 1.0\n\
             [multistart]\nstarts = 16\n{extra}"
        )
    };
    let full = dir.join("full");
    let s = study("w", &costly(""));
    explore::run_multistart(&ctx(&s, &full, 2, DriveFlags::default())).unwrap();
    let part = dir.join("part");
    let sw = study("w", &costly("max_wall_seconds = 0.02\n"));
    let r = explore::run_multistart(&ctx(&sw, &part, 1, DriveFlags::default())).unwrap();
    assert!(
        r.runs.len() < 16,
        "{} runs in 20 ms at 1 ms per evaluation",
        r.runs.len()
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(part.join("w/manifest.json")).unwrap())
            .unwrap();
    assert_eq!(m["commands"]["multistart"]["complete"], false);
    let flags = DriveFlags {
        resume: true,
        ..Default::default()
    };
    let r2 = explore::run_multistart(&ctx(&s, &part, 2, flags)).unwrap();
    assert_eq!(r2.new_runs, 16 - r.runs.len());
    for f in ["runs.csv", "optima.csv"] {
        assert_eq!(
            table_without(&full.join("w").join(f), &["wall_seconds"]),
            table_without(&part.join("w").join(f), &["wall_seconds"]),
            "{f}"
        );
    }
}

#[test]
fn bad_study_input_gets_a_clear_error() {
    let message_of = |text: &str| {
        let tmp = temp_dir("ms-bad");
        errors::error_of("bad.toml", text, |s| {
            explore::run_multistart(&ctx(s, tmp.path(), 1, DriveFlags::default()))
        })
        .message
    };
    let base = "[problem]\nname = \"himmelblau\"\n[multistart]\nmethod = \"steepest\"\n";
    let e = message_of(&format!("{base}sampler = \"halton\"\nstarts = 4\n"));
    assert_eq!(
        e,
        "bad.toml: `multistart.sampler` = \"halton\": expected one of `lhs`, `sobol`, \
         `uniform` (unknown variant `halton`)"
    );
    let e = message_of(&format!("{base}starts = 0\n"));
    assert!(
        e.contains("multistart.starts") && e.contains("at least one start"),
        "{e}"
    );
    let e = message_of(
        "[problem]\nname = \"himmelblau\"\nbounds = [[-5.0, 5.0], [3.0, -3.0]]\n\
         [multistart]\nstarts = 4\n",
    );
    assert!(
        e.contains("problem.bounds[1]") && e.contains("lower < upper"),
        "{e}"
    );
    let e = message_of(&format!("[study]\nthreads = 0\n{base}starts = 4\n"));
    assert!(e.contains("study.threads") && e.contains(">= 1"), "{e}");
    let e = message_of(&format!("{base}starts = 4\npoints = [[9.0, 0.0]]\n"));
    assert!(
        e.contains("multistart.points[0][0]") && e.contains("[-5, 5]"),
        "{e}"
    );
    let e = message_of(&format!("{base}starts = 4\nmethod = \"newton\"\n"));
    // A key given twice is a TOML error: the file, the line and column of
    // the second one, the line itself and the parser's reason.
    assert!(
        e.starts_with("bad.toml: line 6, column 1: `method = \"newton\"`: ")
            && e.ends_with("expected valid TOML: duplicate key"),
        "{e}"
    );
    let e = message_of(
        "[problem]\nname = \"himmelblau\"\n[multistart]\nmethod = \"bfgs\"\nstarts = 4\n",
    );
    assert_eq!(
        e,
        "bad.toml: `multistart.method` = \"bfgs\": expected one of `mmfd`, `steepest`, \
         `sqp` (unknown variant `bfgs`)"
    );
    let e = message_of(&format!("{base}starts = 4\nstrats = 5\n"));
    assert!(e.contains("multistart") && e.contains("strats"), "{e}");
    // --threads 0 on the command line.
    let common = plyscape::cli::Common {
        out: "results".into(),
        threads: Some(0),
        quiet: true,
        force: false,
    };
    let e = plyscape::cli::RunConfig::resolve(None, &common)
        .unwrap_err()
        .to_string();
    assert!(e.contains("--threads") && e.contains(">= 1"), "{e}");
    // An unknown section is refused by every subcommand, before any work,
    // with the closest known section.
    let typo = plyscape::study::Study::parse(
        "typo.toml",
        "[problem]\nname = \"himmelblau\"\n[multistrat]\nstarts = 4\n",
    )
    .unwrap();
    let e = plyscape::cli::check_sections(&typo)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("typo.toml")
            && e.contains("`multistrat`")
            && e.contains("did you mean [multistart]?"),
        "{e}"
    );
    let fine =
        plyscape::study::Study::parse("ok.toml", "[problem]\nname = \"himmelblau\"\n[map]\n")
            .unwrap();
    assert!(plyscape::cli::check_sections(&fine).is_ok());
    // An absurd thread count is refused with the limit, not run (10000
    // threads hung the machine).
    let common = plyscape::cli::Common {
        threads: Some(10_000),
        ..common
    };
    let e = plyscape::cli::RunConfig::resolve(None, &common)
        .unwrap_err()
        .to_string();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let limit = plyscape::cli::max_threads(cores);
    assert!(
        e.contains("--threads") && e.contains("10000") && e.contains(&format!("at most {limit}")),
        "{e}"
    );
    let common = plyscape::cli::Common {
        threads: Some(limit),
        ..common
    };
    assert_eq!(
        plyscape::cli::RunConfig::resolve(None, &common)
            .unwrap()
            .threads,
        limit
    );
}

/// Forgetting `--resume` keeps the earlier table under a timestamped name;
/// `--force` discards it.
#[test]
fn rerun_without_resume_keeps_the_earlier_table_unless_forced() {
    let tmp = temp_dir("ms-keep");
    let dir = tmp.path().to_path_buf();
    let s = study("h", &himmelblau(5, ""));
    explore::run_multistart(&ctx(&s, &dir, 1, DriveFlags::default())).unwrap();
    let first = std::fs::read_to_string(dir.join("h/runs.csv")).unwrap();
    explore::run_multistart(&ctx(&s, &dir, 1, DriveFlags::default())).unwrap();
    let kept: Vec<_> = std::fs::read_dir(dir.join("h"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with("runs-") && n.ends_with("Z.csv"))
        .collect();
    assert_eq!(kept.len(), 1, "{kept:?}");
    assert_eq!(
        std::fs::read_to_string(dir.join("h").join(&kept[0])).unwrap(),
        first
    );
    let force = DriveFlags {
        force: true,
        ..Default::default()
    };
    explore::run_multistart(&ctx(&s, &dir, 1, force)).unwrap();
    let runs = std::fs::read_dir(dir.join("h"))
        .unwrap()
        .filter(|e| {
            let n = e.as_ref().unwrap().file_name().into_string().unwrap();
            n.starts_with("runs")
        })
        .count();
    assert_eq!(runs, 2, "--force kept nothing more");
}

/// `plyscape run` checks every section before any runs: a bad late section
/// (here `[map]` and `[evolve]`, which run after the multistart) is refused
/// with its key and nothing is written.
#[test]
fn a_bad_late_section_is_refused_before_any_work() {
    let tmp = temp_dir("ms-late");
    let dir = tmp.path().to_path_buf();
    for (late, key) in [
        ("[map]\nresolution = 1\n", "map.resolution"),
        ("[evolve]\nrestarts = \"bopop\"\n", "evolve.restarts"),
        ("[map]\nresolutoin = 11\n", "resolutoin"),
    ] {
        let s = study("late", &format!("{}{late}", himmelblau(6, "")));
        let cfg = plyscape::cli::RunConfig {
            study: s,
            out: dir.clone(),
            threads: 1,
            quiet: true,
            force: false,
            resume: false,
        };
        let e = plyscape::cli::run_study(&cfg).unwrap_err().to_string();
        assert!(e.starts_with("late.toml") && e.contains(key), "{e}");
        assert!(!dir.join("late/runs.csv").exists(), "{late}: work was done");
    }
    // A section nothing reads (with a NaN bound) is refused, not passed.
    let unused = "[scene_problem]\nstart = [0.0]\n[[scene_problem.variables]]\n\
        name = \"a\"\nbounds = [nan, 1.0]\nsets = [\"p:theta_1\"]\n";
    let s = study("late", &format!("{}{unused}", himmelblau(6, "")));
    let e = plyscape::sections::registry::check_study(&s)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("scene_problem") && e.contains("\"himmelblau\""),
        "{e}"
    );
}
