//! Kill the real `plyscape multistart` process mid-run, then `--resume`:
//! the final tables equal those of an uninterrupted run.

mod explore_common;

use explore_common::{table_without, temp_dir};
use std::process::Command;
use std::time::{Duration, Instant};

const STUDY: &str = "[study]\nname = \"k\"\nseed = 3\n\
    [problem]\nname = \"himmelblau\"\ncost_ms = 2.0\n\
    [multistart]\nsampler = \"sobol\"\nstarts = 24\n";

fn plyscape(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_plyscape"));
    c.args(args);
    c
}

#[test]
fn killed_multistart_resumes_to_the_same_tables() {
    let dir = temp_dir("kill");
    let study = dir.join("k.toml");
    std::fs::write(&study, STUDY).unwrap();
    let study = study.to_str().unwrap();
    let (full, part) = (dir.join("full"), dir.join("part"));
    let (full_s, part_s) = (full.to_str().unwrap(), part.to_str().unwrap());
    let st = plyscape(&["multistart", study, "--out", full_s, "--threads", "2", "-q"])
        .status()
        .unwrap();
    assert!(st.success());

    let mut child = plyscape(&["multistart", study, "--out", part_s, "--threads", "2", "-q"])
        .spawn()
        .unwrap();
    let runs = part.join("k/runs.csv");
    let t0 = Instant::now();
    // Kill once a few rows (header + 3) are on disk.
    loop {
        let lines = std::fs::read_to_string(&runs).map_or(0, |t| t.lines().count());
        if lines >= 4 || t0.elapsed() > Duration::from_secs(60) {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let rows_at_kill = std::fs::read_to_string(&runs).unwrap().lines().count() - 1;
    assert!(
        (3..24).contains(&rows_at_kill),
        "{rows_at_kill} rows at kill"
    );

    let out = plyscape(&[
        "multistart",
        study,
        "--out",
        part_s,
        "--threads",
        "1",
        "--resume",
        "-q",
    ])
    .output()
    .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in ["runs.csv", "optima.csv"] {
        assert_eq!(
            table_without(&full.join("k").join(f), &["wall_seconds"]),
            table_without(&part.join("k").join(f), &["wall_seconds"]),
            "{f}"
        );
    }
    // The manifest records what was run.
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(part.join("k/manifest.json")).unwrap())
            .unwrap();
    assert_eq!(m["seed"], 3);
    let ms = &m["commands"]["multistart"];
    assert_eq!(ms["resume"], true);
    assert_eq!(ms["threads"], 1);
    assert_eq!(ms["complete"], true);
    assert!(ms["runs_this_invocation"].as_u64().unwrap() <= 24 - 3);
    assert_eq!(m["study_text"], STUDY);
    std::fs::remove_dir_all(&dir).unwrap();
}
