//! The shipped multibody studies (studies/*.toml) run end to end through
//! `plyscape run` and write their files; the `[kernel_bench]` driver produces a consistent table. What each scene
//! shows is tested where the scene is derived: tests/suite/mbs/free.rs
//! (Dzhanibekov), tests/suite/mbs/mechanisms.rs (four-bar, Bricard),
//! tests/suite/mbs/andrews.rs (Andrews), tests/suite/mbs/sar.rs (SAR); those tests run
//! the same study files.
use crate::common::scenes::study_path;
use crate::common::temp_dir;
use plyscape::cli::{run_study, RunConfig};
use plyscape::integrate::Method;
use plyscape::sections::kernel_bench::{run_bench, write_csv, BenchSpec, HEADERS};
use plyscape::study::Study;
use std::path::Path;

/// Read a CSV written by the crate: header and numeric rows.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut rd = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header = rd.headers().unwrap().iter().map(String::from).collect();
    let rows = rd
        .records()
        .map(|r| {
            r.unwrap()
                .iter()
                .map(|v| v.parse::<f64>().unwrap())
                .collect()
        })
        .collect();
    (header, rows)
}

#[test]
fn shipped_scene_studies_run_and_write_history() {
    let tmp = temp_dir("mbs-studies");
    let out = tmp.path().to_path_buf();
    // (file, end time, output interval, extra files expected)
    let cases: [(&str, f64, f64, &[&str]); 5] = [
        ("dzhanibekov.toml", 10.0, 0.025, &["energy.svg"]),
        ("fourbar.toml", 10.0, 0.002, &["O4.rate.svg"]),
        ("bricard.toml", 10.0, 0.01, &["J0.angle.svg"]),
        ("andrews.toml", 0.03, 5e-4, &["sensitivities.csv"]),
        // The SAR study names its plot: outputs.plot_file = "theta".
        (
            "sar_phase1_rigid.toml",
            3.0,
            0.01,
            &["sensitivities.csv", "theta.svg"],
        ),
    ];
    for (file, t_end, dt, extra) in cases {
        let study = Study::load(study_path(file)).unwrap();
        let cfg = RunConfig {
            study: study.clone(),
            out: out.clone(),
            threads: 1,
            quiet: true,
            force: false,
            resume: false,
        };
        run_study(&cfg).unwrap_or_else(|e| panic!("{file}: {e}"));
        let dir = out.join(study.name());
        for f in ["history.csv", "stats.csv"].iter().chain(extra) {
            assert!(dir.join(f).is_file(), "{file}: no {f}");
        }
        let (header, rows) = read_csv(&dir.join("history.csv"));
        assert_eq!(header[0], "t [s]", "{file}");
        // One row per output time t0 + k·dt, k = 0..=t_end/dt.
        let n = (t_end / dt).round() as usize + 1;
        assert_eq!(rows.len(), n, "{file}: rows");
        assert!((rows[n - 1][0] - t_end).abs() < 1e-12, "{file}: end time");
        assert!(
            rows.iter().flatten().all(|v| v.is_finite()),
            "{file}: non-finite value"
        );
    }
}

#[test]
fn kernel_bench_table_is_consistent() {
    let study = Study::load(study_path("kernel_bench.toml")).unwrap();
    let spec = BenchSpec {
        scenes: vec!["sar_phase1_rigid.toml".into(), "dzhanibekov.toml".into()],
        methods: vec![Method::Bdf],
        rtols: vec![1e-4],
        repeats: 1,
        sensitivities: true,
        max_sensitivities: None,
    };
    let rows = run_bench(&study, &spec, |_| {}).unwrap();
    // SAR lists 2 parameters: rows without and with; Dzhanibekov none.
    let cases: Vec<(String, usize)> = rows
        .iter()
        .map(|r| (r.case.scene.clone(), r.case.n_sens))
        .collect();
    assert_eq!(
        cases,
        [
            ("sar_phase1_rigid".to_string(), 0),
            ("sar_phase1_rigid".to_string(), 2),
            ("dzhanibekov".to_string(), 0)
        ]
    );
    for r in &rows {
        let m = r.outcome.as_ref().unwrap();
        assert!(m.wall_ms > 0.0 && m.rhs_calls > 0 && r.case.rhs_us > 0.0);
        // Definition: µs per rhs = wall / rhs calls.
        let u = r.us_per_rhs().unwrap();
        assert!((u * m.rhs_calls as f64 - m.wall_ms * 1e3).abs() < 1e-9 * m.wall_ms * 1e3);
    }
    // Sensitivities cost dual-number products on top of the Newton ones.
    let (a, b) = (
        rows[0].outcome.as_ref().unwrap(),
        rows[1].outcome.as_ref().unwrap(),
    );
    assert!(
        b.jvp_calls > a.jvp_calls,
        "{} vs {}",
        b.jvp_calls,
        a.jvp_calls
    );
    let tmp = temp_dir("kernel-bench");
    let dir = tmp.path().to_path_buf();
    let path = write_csv(&rows, &dir).unwrap();
    let mut rd = csv::Reader::from_path(&path).unwrap();
    assert_eq!(rd.headers().unwrap().iter().collect::<Vec<_>>(), HEADERS);
    let records: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert_eq!(records.len(), 3);
    for rec in &records {
        assert_eq!(&rec[4], "ok");
        assert!(rec.iter().all(|v| !v.to_lowercase().contains("nan")));
    }
}

#[test]
fn kernel_bench_rejects_bad_input() {
    let text = "[kernel_bench]\nscenes = [\"andrews.toml\"]\nmethods = [\"bdf\"]\nrtols = [2.0]\nrepeats = 1\n";
    let study = Study::parse(study_path("bad_bench.toml"), text).unwrap();
    let spec: BenchSpec = study.require_section("kernel_bench", "bench").unwrap();
    let msg = run_bench(&study, &spec, |_| {}).unwrap_err().to_string();
    assert!(
        msg.contains("bad_bench.toml")
            && msg.contains("kernel_bench.rtols[0]")
            && msg.contains('2'),
        "{msg}"
    );
    let text = text
        .replace("rtols = [2.0]", "rtols = [1e-6]")
        .replace("andrews", "missing");
    let study = Study::parse(study_path("bad_bench.toml"), &text).unwrap();
    let spec: BenchSpec = study.require_section("kernel_bench", "bench").unwrap();
    let msg = run_bench(&study, &spec, |_| {}).unwrap_err().to_string();
    assert!(msg.contains("missing.toml"), "{msg}");
    let text = text.replace("missing", "andrews") + "max_sensitivities = 0\n";
    let study = Study::parse(study_path("bad_bench.toml"), &text).unwrap();
    let spec: BenchSpec = study.require_section("kernel_bench", "bench").unwrap();
    let msg = run_bench(&study, &spec, |_| {}).unwrap_err().to_string();
    assert!(msg.contains("kernel_bench.max_sensitivities"), "{msg}");
}

#[test]
fn kernel_bench_max_sensitivities_keeps_the_first_parameters() {
    // The rigid SAR study lists 2 parameters; with max_sensitivities = 1
    // the sensitivity case integrates only the first.
    let study = Study::load(study_path("kernel_bench.toml")).unwrap();
    let spec = BenchSpec {
        scenes: vec!["sar_phase1_rigid.toml".into()],
        methods: vec![Method::Bdf],
        rtols: vec![1e-4],
        repeats: 1,
        sensitivities: true,
        max_sensitivities: Some(1),
    };
    let rows = run_bench(&study, &spec, |_| {}).unwrap();
    let n: Vec<usize> = rows.iter().map(|r| r.case.n_sens).collect();
    assert_eq!(n, [0, 1]);
}
