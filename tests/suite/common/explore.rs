//! Helpers shared by the exploration tests.
#![allow(dead_code)]

pub use super::tables::table_without;
use plyscape::explore::{Context, DriveFlags};
use plyscape::study::Study;
use std::path::Path;

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

/// Column `name` of a table from [`table_without`] (header row first).
pub fn column(t: &[Vec<String>], name: &str) -> Vec<String> {
    super::tables::column(&t[0], &t[1..], name)
}
