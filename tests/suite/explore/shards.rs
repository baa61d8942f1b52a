//! Sharded multistarts (`--shard i/n`) and `plyscape merge`: the merged
//! shards give the unsharded tables, and `merge` is strict and read-only.

use super::multistart::himmelblau;
use crate::common::explore::{ctx, study, table_without};
use crate::common::temp_dir;
use plyscape::explore::multistart::Shard;
use plyscape::explore::{self, DriveFlags};

#[test]
fn merged_shards_equal_the_unsharded_run() {
    let tmp = temp_dir("ms-shards");
    let dir = tmp.path().to_path_buf();
    // With `[robustness]`: the merged optima.csv carries the worst-case
    // columns as the unsharded one does (compared below, cell by cell).
    let text = himmelblau(17, "") + "[robustness]\ntolerance = [0.05, 0.05]\n";
    let s = study("h", &text);
    let full = dir.join("full");
    explore::run_multistart(&ctx(&s, &full, 2, DriveFlags::default())).unwrap();
    let sharded = dir.join("sharded");
    let mut dirs = Vec::new();
    for i in 0..3 {
        let flags = DriveFlags {
            resume: false,
            shard: Shard { index: i, count: 3 },
            force: false,
        };
        let r = explore::run_multistart(&ctx(&s, &sharded, 1, flags)).unwrap();
        assert_eq!(r.runs.len(), [6, 6, 5][i]);
        dirs.push(sharded.join(format!("h/shard-{i}-of-3")));
    }
    // Incomplete set of shards is refused.
    assert!(explore::merge(&dirs[..2], &sharded, true).is_err());
    dirs.reverse();
    explore::merge(&dirs, &sharded, true).unwrap();
    // Compare is not sharded; after the merge, --resume runs nothing new.
    let shard = DriveFlags {
        resume: false,
        shard: Shard { index: 0, count: 3 },
        force: false,
    };
    let e = explore::run_compare(&ctx(&s, &sharded, 1, shard)).unwrap_err();
    assert!(e.to_string().contains("--shard"), "{e}");
    let flags = DriveFlags {
        resume: true,
        ..Default::default()
    };
    assert_eq!(
        explore::run_multistart(&ctx(&s, &sharded, 1, flags))
            .unwrap()
            .new_runs,
        0
    );
    for f in ["runs.csv", "optima.csv"] {
        assert_eq!(
            table_without(&full.join("h").join(f), &["wall_seconds"]),
            table_without(&sharded.join("h").join(f), &["wall_seconds"]),
            "{f}"
        );
    }
    let merged = table_without(&sharded.join("h/optima.csv"), &[]);
    for c in plyscape::explore::multistart::robustness::COLUMNS {
        assert!(
            merged[0].iter().any(|h| h == c),
            "{c} missing: {:?}",
            merged[0]
        );
    }
}

/// `merge` never modifies a shard, refuses a shard that lacks rows (naming
/// the starts) and refuses a directory that is not a shard.
#[test]
fn merge_is_strict_and_read_only() {
    let tmp = temp_dir("ms-merge-strict");
    let dir = tmp.path().to_path_buf();
    let s = study("h", &himmelblau(7, ""));
    let mut dirs = Vec::new();
    for i in 0..2 {
        let flags = DriveFlags {
            shard: Shard { index: i, count: 2 },
            ..Default::default()
        };
        explore::run_multistart(&ctx(&s, &dir, 1, flags)).unwrap();
        dirs.push(dir.join(format!("h/shard-{i}-of-2")));
    }
    let runs = dirs[1].join("runs.csv");
    let intact = std::fs::read(&runs).unwrap();
    // A torn last line: refused, the file left byte for byte.
    let mut torn = intact.clone();
    torn.extend_from_slice(b"5,0.1");
    std::fs::write(&runs, &torn).unwrap();
    let e = explore::merge(&dirs, &dir, true).unwrap_err().to_string();
    assert!(e.contains("torn last line"), "{e}");
    assert_eq!(std::fs::read(&runs).unwrap(), torn);
    // A missing row: refused, naming the start (shard 1 owns 1, 3, 5).
    let text = String::from_utf8(intact.clone()).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let without_3: String = lines
        .iter()
        .filter(|l| !l.starts_with("3,"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(without_3.lines().count(), lines.len() - 1);
    std::fs::write(&runs, &without_3).unwrap();
    let e = explore::merge(&dirs, &dir, true).unwrap_err().to_string();
    assert!(e.contains("lacks the rows of starts [3]"), "{e}");
    std::fs::write(&runs, &intact).unwrap();
    // An unsharded run's directory is not a shard.
    let whole = dir.join("whole");
    explore::run_multistart(&ctx(&s, &whole, 1, DriveFlags::default())).unwrap();
    let e = explore::merge(&[whole.join("h")], &dir, true)
        .unwrap_err()
        .to_string();
    assert!(e.contains("unsharded"), "{e}");
    // The study's folder instead of its shards: refused as bad input,
    // naming the shards to give.
    let e = explore::merge(&[dir.join("h")], &dir, true).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    let e = e.to_string();
    assert!(
        e.contains("name the shards") && e.contains("shard-0-of-2"),
        "{e}"
    );
    explore::merge(&dirs, &dir, true).unwrap();
}
