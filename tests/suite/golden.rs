//! Golden output: the main study (`plyscape run` without a file, the text
//! of studies/main.toml built into the binary) run into a temporary
//! directory writes every CSV of the committed `results/main/` again, field
//! for field: the same files, the same headers, every number the same to
//! its last written digit. A change that moves any number of the main
//! study fails here; if the change is meant, run `plyscape run` and commit
//! the new `results/main/`.
//!
//! No CSV of the study holds a wall-clock time: the times of the run
//! (whole commands, the integration, the output) are in `manifest.json`
//! only, which is not compared and not tracked by git for `results/main/`
//! (`.gitignore`), so running the main study in a fresh clone leaves the
//! tree clean.

use crate::common::tables::table_without;
use crate::common::temp_dir;
use std::path::{Path, PathBuf};

/// The CSV files in `dir`, by name, sorted.
fn csv_files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".csv"))
        .collect();
    names.sort();
    names
}

/// Every difference between two tables (rows of fields, header first),
/// as `row, column: expected → got` lines, at most `max` of them.
fn differences(expected: &[Vec<String>], got: &[Vec<String>], max: usize) -> Vec<String> {
    let mut out = Vec::new();
    if expected.len() != got.len() {
        out.push(format!("{} rows, expected {}", got.len(), expected.len()));
    }
    for (i, (e, g)) in expected.iter().zip(got).enumerate() {
        if e.len() != g.len() {
            out.push(format!("row {i}: {} fields, expected {}", g.len(), e.len()));
            continue;
        }
        for (c, (x, y)) in e.iter().zip(g).enumerate() {
            if x != y {
                out.push(format!("row {i}, column {:?}: {x} -> {y}", expected[0][c]));
            }
        }
    }
    out.truncate(max);
    out
}

#[test]
fn main_study_reproduces_results_main() {
    let committed = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("results/main");
    let tmp = temp_dir("golden-main");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_plyscape"))
        .args(["run", "--quiet", "--out"])
        .arg(tmp.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "plyscape run failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fresh = tmp.path().join("main");
    let names = csv_files(&committed);
    assert!(
        names.len() >= 6 && names.contains(&"history.csv".to_string()),
        "{names:?}"
    );
    assert_eq!(csv_files(&fresh), names, "the study's CSV files");
    let mut report = Vec::new();
    for name in &names {
        let expected = table_without(&committed.join(name), &[]);
        let got = table_without(&fresh.join(name), &[]);
        for d in differences(&expected, &got, 10) {
            report.push(format!("{name}: {d}"));
        }
    }
    assert!(
        report.is_empty(),
        "the main study no longer reproduces results/main/:\n{}",
        report.join("\n")
    );
}

#[test]
fn differences_are_found_and_named() {
    // The comparison must be able to fail: one changed digit, a missing
    // row and a missing field are each reported with their place.
    let t = |rows: &[&[&str]]| -> Vec<Vec<String>> {
        rows.iter()
            .map(|r| r.iter().map(|s| s.to_string()).collect())
            .collect()
    };
    let a = t(&[
        &["t [s]", "x [m]"],
        &["0", "1.000000000000e0"],
        &["1", "2.5e-1"],
    ]);
    assert!(differences(&a, &a, 10).is_empty());
    let b = t(&[
        &["t [s]", "x [m]"],
        &["0", "1.000000000001e0"],
        &["1", "2.5e-1"],
    ]);
    assert_eq!(
        differences(&a, &b, 10),
        vec!["row 1, column \"x [m]\": 1.000000000000e0 -> 1.000000000001e0"]
    );
    let c = t(&[&["t [s]", "x [m]"], &["0"]]);
    assert_eq!(
        differences(&a, &c, 10),
        vec!["2 rows, expected 3", "row 1: 1 fields, expected 2"]
    );
}
