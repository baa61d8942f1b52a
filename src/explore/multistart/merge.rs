//! `plyscape merge`: the shards of one multistart (`--shard i/n`, each in
//! its own `shard-i-of-n/` directory) put back together into the tables an
//! unsharded run gives.

use super::command::{noise_at_optima, print_optima};
use super::driver::{self, Shard};
use super::section::{multistart_plan, MultistartPlan, NoiseAllowance};
use crate::error::{Error, Result};
use crate::explore::context::{Context, DriveFlags};
use crate::explore::persist::fingerprint::{self, Fingerprint};
use crate::explore::persist::manifest::{DriverEntry, MergeEntry, MultistartEntry};
use crate::explore::persist::tables;
use crate::explore::problem::build::problem;
use crate::report::manifest::{Manifest, ShardRecord};
use crate::study::Study;
use std::path::{Path, PathBuf};

/// `plyscape merge`: combine the shard directories of one multistart into
/// the tables an unsharded run gives, in `out/<study>/` (with the
/// `[robustness]` columns of optima.csv when the study asks for them).
///
/// Strict by design: shards are only read, never modified (a torn last
/// line is refused, not repaired: finish that shard with `--resume`); a
/// directory of an unsharded run is not a shard; every start a shard owns
/// must have its row unless the study's `max_evaluations` budget stopped
/// the shard early (the missing starts are named); a shard whose recorded
/// fingerprint differs from this build's ([`fingerprint`]: computed by code
/// of another evaluation version) is refused with what differs.
pub fn merge(dirs: &[PathBuf], out: &Path, quiet: bool) -> Result<driver::Report> {
    if dirs.is_empty() {
        return Err(Error::input(
            "dirs",
            "(none)",
            "at least one shard directory",
        ));
    }
    let (text, file, n, indices) = shard_manifests(dirs)?;
    let study = Study::parse(&file, &text)?;
    // The shards' evaluations are this build's: the merged manifest
    // records this build's fingerprint, which a later --resume compares.
    let now = Fingerprint::of_study(&study);
    for d in dirs {
        fingerprint::check_recorded_for(
            &study,
            (d, &["multistart"]),
            &now,
            &d.join("runs.csv"),
            (
                "merge",
                "run that shard again with this build (without --resume)",
            ),
        )?;
    }
    let problem = problem(&study)?;
    let plan = multistart_plan(&study, problem.as_ref())?;
    let vars = problem.variables();
    let m = problem.n_constraints();
    let mut rows = Vec::new();
    for (d, &index) in dirs.iter().zip(&indices) {
        let shard = Shard { index, count: n };
        rows.extend(shard_rows(d, shard, &plan, vars, m)?);
    }
    let dir = study.output_dir(out)?;
    let _lock = crate::report::lock::DirLock::acquire(&dir, "merge")?;
    let manifests: Vec<Manifest> = dirs.iter().filter_map(|d| Manifest::read(d).ok()).collect();
    let wall = manifests
        .iter()
        .filter_map(|m| multistart_entry(m)?.detail.counts.map(|c| c.wall_seconds))
        .fold(0.0, f64::max);
    let mut report = driver::finish(vars, m, rows, plan.tolerances, &dir, wall)?;
    // The manifest's thread count: the largest any shard used.
    let threads = manifests.iter().map(|m| m.threads).max().unwrap_or(1);
    let ctx = Context {
        study: &study,
        out,
        threads,
        quiet,
        flags: DriveFlags::default(),
    };
    // The noise at the merged optima, as an unsharded run measures it (the
    // same seed: the same tables).
    if let NoiseAllowance::Measured(_) = plan.section.noise {
        noise_at_optima(&ctx, problem.as_ref(), &mut report, &dir)?;
    }
    let entry = MergeEntry {
        complete: true,
        merged_from: dirs.iter().map(|d| d.display().to_string()).collect(),
        wall_seconds: wall,
    };
    ctx.manifest(&dir, "merge", entry)?;
    if !quiet {
        println!(
            "merged {} shards into {} (runs.csv, optima.csv, manifest.json)",
            dirs.len(),
            dir.display()
        );
        print_optima(problem.as_ref(), &report);
    }
    // `[robustness]`: the merged optima.csv again with the worst-case
    // columns, as an unsharded run writes it.
    super::robustness::apply(&ctx, problem.as_ref(), &report.optima, &dir)?;
    Ok(report)
}

/// The error for a directory without a manifest: it names the shard
/// directories below it when there are any (a study's folder or a
/// results root given instead of its shards).
fn not_a_shard(d: &Path) -> Error {
    let mut below: Vec<String> = std::fs::read_dir(d)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.join("manifest.json").is_file())
        .map(|p| p.display().to_string())
        .collect();
    below.sort();
    let expected = if below.is_empty() {
        "a shard directory (`results/STUDY/shard-I-of-N`, with its manifest.json)".to_string()
    } else {
        format!(
            "a shard directory, not a folder of them: name the shards, \
             `plyscape merge {}`",
            below.join(" ")
        )
    };
    Error::input(d.display().to_string(), "(no manifest.json)", expected)
}

/// The study text, study file name and shard count shared by the shard
/// directories `dirs`, and their shard indices; refuses a directory that
/// is not a finished shard, shards of different studies, and a set that
/// does not hold each shard exactly once.
fn shard_manifests(dirs: &[PathBuf]) -> Result<(String, String, usize, Vec<usize>)> {
    let mut first: Option<(String, String, usize)> = None;
    let mut seen = Vec::new();
    for d in dirs {
        if !d.join("manifest.json").is_file() {
            return Err(not_a_shard(d));
        }
        let m = Manifest::read(d)?;
        let t = m.study_text.clone();
        let Some(ShardRecord { index: i, count: n }) = m.shard else {
            return Err(Error::input(
                d.display().to_string(),
                "manifest.json",
                "a shard manifest",
            ));
        };
        if n < 2 {
            return Err(Error::input(
                d.display().to_string(),
                "an unsharded run (shard 0/1)",
                "a shard directory written by `plyscape multistart --shard I/N` with N >= 2",
            ));
        }
        if !multistart_entry(&m).is_some_and(|e| e.detail.complete) {
            return Err(Error::input(
                d.display().to_string(),
                format!("shard {i}/{n} (incomplete)"),
                "a finished shard (finish it with --resume first)",
            ));
        }
        match &first {
            None => first = Some((t, m.study_file.clone(), n)),
            Some((t0, _, n0)) if *t0 == t && *n0 == n => {}
            Some(_) => {
                return Err(Error::input(
                    d.display().to_string(),
                    format!("shard {i}/{n}"),
                    "shards of the same study text and shard count",
                ))
            }
        }
        seen.push(i);
    }
    let (text, file, n) = first.expect("dirs is not empty");
    let mut sorted = seen.clone();
    sorted.sort_unstable();
    if sorted != (0..n).collect::<Vec<_>>() {
        return Err(Error::input(
            "dirs",
            format!("shards {seen:?}"),
            format!("each of the shards 0..{n} exactly once"),
        ));
    }
    Ok((text, file, n, seen))
}

/// The rows of one shard's `runs.csv`, read without modifying it: each row
/// must be a start of the study that this shard owns, and every start it
/// owns must be there unless the study's function-call budget stopped it.
fn shard_rows(
    d: &Path,
    shard: Shard,
    plan: &MultistartPlan,
    vars: &[crate::optimize::Variable],
    m: usize,
) -> Result<Vec<tables::RunRecord>> {
    let path = d.join("runs.csv");
    let (read, _) = tables::scan_runs(&path, vars, m)?;
    if read.repaired_bytes > 0 {
        return Err(Error::csv(
            &path,
            format!(
                "torn last line ({} bytes) in a finished shard; the shard is left as it is: \
                 run it again with --resume to finish it, then merge",
                read.repaired_bytes
            ),
        ));
    }
    let starts = &plan.starts.points;
    for row in &read.rows {
        let ok = shard.owns(row.start)
            && starts.get(row.start).is_some_and(|x0| {
                x0.iter()
                    .zip(&row.x0)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            });
        if !ok {
            return Err(Error::csv(
                &path,
                format!(
                    "row for start {} does not match the study or is not shard {}/{}'s",
                    row.start, shard.index, shard.count
                ),
            ));
        }
    }
    let have: std::collections::BTreeSet<usize> = read.rows.iter().map(|r| r.start).collect();
    let missing: Vec<usize> = (0..starts.len())
        .filter(|&k| shard.owns(k) && !have.contains(&k))
        .collect();
    if !missing.is_empty() && plan.section.max_evaluations.is_none() {
        return Err(Error::csv(
            &path,
            format!(
                "shard {}/{} lacks the rows of starts {missing:?}; run it again with --resume",
                shard.index, shard.count
            ),
        ));
    }
    Ok(read.rows)
}

/// The `multistart` entry of a manifest, typed (`None`: absent or not of
/// that form).
fn multistart_entry(m: &Manifest) -> Option<DriverEntry<MultistartEntry>> {
    m.entry("multistart")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh directory under the system's temp directory.
    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("plyscape-merge-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    const STUDY: &str = "[study]\nname = \"m\"\nseed = 5\n[problem]\nname = \"himmelblau\"\n\
                         [multistart]\nmethod = \"steepest\"\nstarts = 7\n";

    /// Run shard `index` of `count` (or the whole multistart with
    /// `count = 1`) into `out`; returns the directory written.
    fn run(study: &Study, out: &Path, index: usize, count: usize) -> PathBuf {
        let ctx = Context {
            study,
            out,
            threads: 1,
            quiet: true,
            flags: DriveFlags {
                shard: Shard { index, count },
                ..DriveFlags::default()
            },
        };
        crate::explore::multistart::command::run_multistart(&ctx).unwrap();
        ctx.dir().unwrap()
    }

    fn read(path: &Path) -> String {
        std::fs::read_to_string(path).unwrap()
    }

    #[test]
    fn shards_merge_into_the_unsharded_tables_and_bad_sets_are_refused() {
        let root = scratch("ok");
        let study = Study::parse("m.toml", STUDY).unwrap();
        let whole = run(&study, &root.join("whole"), 0, 1);
        let sharded = root.join("sharded");
        let dirs: Vec<PathBuf> = (0..3).map(|i| run(&study, &sharded, i, 3)).collect();
        // A shard missing, a shard twice, an unsharded run: refused.
        let e = merge(&dirs[..2], &sharded, true).unwrap_err().to_string();
        assert!(e.contains("each of the shards 0..3 exactly once"), "{e}");
        let twice = [dirs[0].clone(), dirs[0].clone(), dirs[1].clone()];
        assert!(merge(&twice, &sharded, true).is_err());
        let e = merge(std::slice::from_ref(&whole), &sharded, true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("unsharded run"), "{e}");
        assert!(merge(&[], &sharded, true).is_err());
        // The merge gives the unsharded run's tables.
        let report = merge(&dirs, &sharded, true).unwrap();
        assert_eq!(report.runs.len(), 7);
        let merged = sharded.join("m");
        // (runs.csv differs in its wall times only.)
        assert_eq!(
            read(&merged.join("optima.csv")),
            read(&whole.join("optima.csv"))
        );
        // The manifest says where the rows came from; shards are untouched.
        let m = Manifest::read(&merged).unwrap();
        let entry: DriverEntry<MergeEntry> = m.entry("merge").unwrap();
        assert!(entry.detail.complete);
        assert_eq!(entry.detail.merged_from.len(), 3);
        assert_eq!(m.shard, Some(ShardRecord { index: 0, count: 1 }));
        let shard0 = Manifest::read(&dirs[0]).unwrap();
        assert_eq!(shard0.shard, Some(ShardRecord { index: 0, count: 3 }));
        assert_eq!(shard0.last_command, "multistart");
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn an_unfinished_or_foreign_shard_is_refused() {
        let root = scratch("bad");
        let study = Study::parse("m.toml", STUDY).unwrap();
        let dirs: Vec<PathBuf> = (0..2).map(|i| run(&study, &root, i, 2)).collect();
        // A shard of another study text.
        let other = Study::parse("m.toml", &format!("{STUDY}x_tolerance = 0.02\n")).unwrap();
        let foreign = run(&other, &root.join("other"), 1, 2);
        let e = merge(&[dirs[0].clone(), foreign], &root, true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("same study text"), "{e}");
        // A shard whose manifest says it did not finish.
        let ctx = Context {
            study: &study,
            out: &root,
            threads: 1,
            quiet: true,
            flags: DriveFlags {
                shard: Shard { index: 1, count: 2 },
                ..DriveFlags::default()
            },
        };
        let unfinished = MultistartEntry {
            complete: false,
            counts: None,
        };
        ctx.manifest(&dirs[1], "multistart", unfinished).unwrap();
        let e = merge(&dirs, &root, true).unwrap_err().to_string();
        assert!(e.contains("incomplete"), "{e}");
        // A shard's row removed: the missing start is named.
        ctx.manifest(
            &dirs[1],
            "multistart",
            MultistartEntry {
                complete: true,
                counts: None,
            },
        )
        .unwrap();
        let runs = dirs[1].join("runs.csv");
        let text = read(&runs);
        let kept: Vec<&str> = text.lines().take(text.lines().count() - 1).collect();
        std::fs::write(&runs, kept.join("\n") + "\n").unwrap();
        let e = merge(&dirs, &root, true).unwrap_err().to_string();
        assert!(e.contains("lacks the rows of starts"), "{e}");
        std::fs::remove_dir_all(&root).unwrap();
    }
}
