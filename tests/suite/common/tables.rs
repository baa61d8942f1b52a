//! Columns of tables by name: the histories of simulations (headers with
//! units, `pin.angle [rad]`) and the CSV files the commands write.

use std::path::Path;

/// Index of column `name` in `headers`: the header equal to `name`, else
/// the first that starts with it (a history header carries its unit, so
/// `"pin.angle"` finds `pin.angle [rad]`). Panics naming the headers when
/// none matches.
pub fn column_index<S: AsRef<str>>(headers: &[S], name: &str) -> usize {
    headers
        .iter()
        .position(|h| h.as_ref() == name)
        .or_else(|| headers.iter().position(|h| h.as_ref().starts_with(name)))
        .unwrap_or_else(|| {
            let all: Vec<&str> = headers.iter().map(|h| h.as_ref()).collect();
            panic!("no column {name} in {all:?}")
        })
}

/// Column `name` ([`column_index`]) of `rows` under `headers`.
pub fn column<S: AsRef<str>, T: Clone>(headers: &[S], rows: &[Vec<T>], name: &str) -> Vec<T> {
    let c = column_index(headers, name);
    rows.iter().map(|r| r[c].clone()).collect()
}

/// A CSV file as rows of fields (the header row first), with the named
/// columns removed (wall times are not reproducible).
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
