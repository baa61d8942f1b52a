//! Helpers shared by the exploration tests.
#![allow(dead_code)]

use plyscape::explore::{Context, DriveFlags};
use plyscape::study::Study;
use std::path::{Path, PathBuf};

/// A fresh temporary directory for one test.
pub fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("plyscape-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Parse a study given as text.
pub fn study(name: &str, text: &str) -> Study {
    Study::parse(format!("{name}.toml"), text).unwrap()
}

/// A driver context.
pub fn ctx<'a>(study: &'a Study, out: &'a Path, threads: usize, flags: DriveFlags) -> Context<'a> {
    Context {
        study,
        out,
        threads,
        quiet: true,
        flags,
    }
}

/// A CSV file as rows of fields, with the named columns removed (wall
/// times are not reproducible).
pub fn table_without(path: &Path, drop: &[&str]) -> Vec<Vec<String>> {
    let mut rd = csv::ReaderBuilder::new()
        .has_headers(false)
        .from_path(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let rows: Vec<Vec<String>> = rd
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    let keep: Vec<usize> = (0..rows[0].len())
        .filter(|&c| !drop.contains(&rows[0][c].as_str()))
        .collect();
    rows.iter()
        .map(|r| keep.iter().map(|&c| r[c].clone()).collect())
        .collect()
}

/// Column `name` of a table from [`table_without`].
pub fn column(t: &[Vec<String>], name: &str) -> Vec<String> {
    let c = t[0].iter().position(|h| h == name).unwrap();
    t[1..].iter().map(|r| r[c].clone()).collect()
}
