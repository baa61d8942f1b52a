//! Reports: progress bars, the run manifest and SVG plots.
//!
//! Solvers and drivers never format output themselves: drivers hand numbers
//! to this module. Progress bars draw on stderr only when it is a terminal
//! and `--quiet` was not given. SVG plots use plotters' SVG backend (text is
//! laid out by the browser, so no font files are needed).

pub mod clock;
pub mod csv;
pub mod lock;
pub mod manifest;
pub mod plot;

pub use plot::{
    heat_map, line_plot, line_plot_floored, scatter_plot, Axes, Curve, HeatMap, Scale, Series,
};

use crate::error::{Error, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::Path;

/// A progress bar (hidden when quiet or when stderr is not a terminal).
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar for `len` steps labelled `label`.
    pub fn new(label: &str, len: u64, quiet: bool) -> Progress {
        let template = "{prefix} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}";
        Self::styled(label, Some(len), template, quiet)
    }

    /// A counter of steps whose total is not known beforehand (a
    /// gradient front's evaluations), labelled `label`, counting `unit`.
    pub fn counter(label: &str, unit: &str, quiet: bool) -> Progress {
        let template = format!("{{prefix}} [{{elapsed_precise}}] {{pos}} {unit} {{msg}}");
        Self::styled(label, None, &template, quiet)
    }

    /// A bar of `len` steps (`None`: not known) drawn with `template`.
    fn styled(label: &str, len: Option<u64>, template: &str, quiet: bool) -> Progress {
        let target = if quiet {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        };
        let bar = ProgressBar::with_draw_target(len, target);
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style);
        }
        bar.set_prefix(label.to_string());
        Progress { bar }
    }

    /// One step done, the message kept.
    pub fn tick(&self) {
        self.bar.inc(1);
    }

    /// One step done; `msg` replaces the message.
    pub fn inc(&self, msg: &str) {
        self.bar.set_message(msg.to_string());
        self.bar.inc(1);
    }

    /// Set the position and message.
    pub fn set(&self, pos: u64, msg: &str) {
        self.bar.set_message(msg.to_string());
        self.bar.set_position(pos);
    }

    /// Remove the bar (the drivers print a summary instead).
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// `(name, version)` of every direct dependency, from the `Cargo.lock` and
/// `Cargo.toml` this binary was built from. When the lock file holds several
/// versions of a crate, the one matching the requirement's caret prefix
/// (`0.9` -> `0.9.*`, `1.10` -> `1.*`) is taken.
pub fn crate_versions() -> Vec<(String, String)> {
    let lock = include_str!("../../Cargo.lock");
    let manifest = include_str!("../../Cargo.toml");
    let direct: Vec<(&str, String)> = manifest
        .split("[dependencies]")
        .nth(1)
        .unwrap_or("")
        .lines()
        .take_while(|l| !l.starts_with('['))
        .filter_map(|l| {
            let (name, rest) = l.split_once('=')?;
            let req = rest.split('"').nth(1)?;
            let mut parts = req.split('.');
            let major = parts.next()?;
            let prefix = if major == "0" {
                format!("0.{}.", parts.next()?)
            } else {
                format!("{major}.")
            };
            Some((name.trim(), prefix))
        })
        .collect();
    let mut out = Vec::new();
    for block in lock.split("[[package]]") {
        let field = |key: &str| {
            block
                .lines()
                .find_map(|l| l.strip_prefix(key))
                .map(|v| v.trim().trim_matches('"').to_string())
        };
        if let (Some(n), Some(v)) = (field("name = "), field("version = ")) {
            if direct
                .iter()
                .any(|(d, p)| *d == n && v.starts_with(p.as_str()))
            {
                out.push((n, v));
            }
        }
    }
    out
}

/// The git commit this binary was built from (`-dirty` when tracked files
/// differed from it; `unknown` without git), recorded by `build.rs`.
pub const GIT_COMMIT: &str = env!("PLYSCAPE_GIT_COMMIT");

/// When this process started its work (set by [`mark_start`], else at the
/// first manifest written).
static STARTED: std::sync::OnceLock<std::time::SystemTime> = std::sync::OnceLock::new();

/// Record now as the start of this process's work (the command line calls
/// it first thing; later calls keep the first time).
pub fn mark_start() {
    STARTED.get_or_init(std::time::SystemTime::now);
}

/// Update `manifest.json` in `dir`: everything needed to reproduce the
/// tables next to it ([`manifest::Manifest`]). Common fields at the top
/// (version, git commit, study, seed, threads, crate versions, the study
/// text, the `shard` of a driver), and one entry per command under
/// `commands`: the entries of earlier commands on the same study text are
/// kept, so `plyscape run` records every step. Each entry gets `started`
/// (when this process began) and `ended` (now) as UTC timestamps.
pub fn record_command(
    dir: &Path,
    study: &crate::study::Study,
    threads: usize,
    command: &str,
    mut entry: serde_json::Map<String, serde_json::Value>,
    shard: Option<manifest::ShardRecord>,
) -> Result<()> {
    use serde_json::json;
    mark_start();
    let started = *STARTED.get().expect("set just above");
    entry.insert("started".into(), json!(clock::iso_utc(started)));
    entry.insert(
        "ended".into(),
        json!(clock::iso_utc(std::time::SystemTime::now())),
    );
    let mut commands = manifest::Manifest::read(dir)
        .ok()
        .filter(|m| m.study_text == study.text)
        .map(|m| m.commands)
        .unwrap_or_default();
    commands.insert(command.into(), serde_json::Value::Object(entry));
    let m = manifest::Manifest {
        plyscape_version: env!("CARGO_PKG_VERSION").into(),
        git_commit: GIT_COMMIT.into(),
        study_file: study.path.display().to_string(),
        study_name: study.name(),
        seed: study.meta.seed,
        threads,
        crates: crate_versions().into_iter().collect(),
        shard,
        last_command: command.into(),
        commands,
        study_text: study.text.clone(),
    };
    let text = m
        .to_text()
        .map_err(|e| Error::csv(dir.join("manifest.json"), e))?;
    csv::write_bytes_atomic(&dir.join("manifest.json"), text.as_bytes())
}

/// Read `manifest.json` from `dir`.
pub fn read_manifest(dir: &Path) -> Result<serde_json::Value> {
    let path = dir.join("manifest.json");
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::csv(&path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crate_versions_come_from_the_lock_file() {
        let v = crate_versions();
        let names: Vec<&str> = v.iter().map(|(n, _)| n.as_str()).collect();
        for dep in ["nalgebra", "rayon", "rand_chacha", "plotters"] {
            assert!(names.contains(&dep), "{names:?}");
        }
        // One version per crate, the one Cargo.toml asks for (rand 0.9).
        assert_eq!(names.iter().filter(|n| **n == "rand").count(), 1);
        assert!(v
            .iter()
            .any(|(n, ver)| n == "rand" && ver.starts_with("0.9.")));
    }
}
