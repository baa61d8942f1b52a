//! Kill the real `plyscape multistart` process mid-run, then `--resume`:
//! the final tables equal those of an uninterrupted run.

use crate::common::explore::table_without;
use crate::common::temp_dir;
use std::process::Command;
use std::time::{Duration, Instant};

const STUDY: &str = "[study]\nname = \"k\"\nseed = 3\n\
    [problem]\nname = \"himmelblau\"\ncost_ms = 2.0\n\
    [multistart]\nsampler = \"sobol\"\nstarts = 24\n";

/// The same study with every evaluation sleeping 25 ms (`cost_mode =
/// "sleep"`: the child is slow whatever the load of the machine, and needs
/// no core for it). Its 24 starts take about 8 s on 2 threads (about 27
/// evaluations per start), so once 3 runs are on disk the test has seconds,
/// not milliseconds, to kill the child before it finishes: a stalled test
/// thread cannot make the kill come too late. The evaluation cost changes
/// no result, only the wall times (the runs of the killed study resume
/// with the fast one).
const SLOW: &str = "[study]\nname = \"k\"\nseed = 3\n\
    [problem]\nname = \"himmelblau\"\ncost_ms = 25.0\ncost_mode = \"sleep\"\n\
    [multistart]\nsampler = \"sobol\"\nstarts = 24\n";

fn plyscape(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_plyscape"));
    c.args(args);
    c
}

/// Spawn `cmd`, kill it once `runs` holds 3 rows (or after 120 s), and
/// return the rows on disk at the kill; the child must still have been
/// running.
fn kill_after_rows(cmd: Command, runs: &std::path::Path) -> usize {
    kill_at_lines(cmd, runs, 4) - 1
}

/// Spawn `cmd`, kill it once `file` holds `lines` lines (or after 120 s),
/// and return the lines on disk at the kill; the child must still have
/// been running.
fn kill_at_lines(mut cmd: Command, file: &std::path::Path, lines: usize) -> usize {
    let mut child = cmd.spawn().unwrap();
    let t0 = Instant::now();
    let count = || std::fs::read_to_string(file).map_or(0, |t| t.lines().count());
    while count() < lines && t0.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(5));
    }
    let waited = t0.elapsed();
    child.kill().unwrap();
    let killed = child.wait().unwrap();
    // Killed by the signal, not finished: the child was still running.
    assert!(!killed.success(), "the child finished before the kill");
    let at_kill = count();
    println!(
        "killed after {waited:?} with {at_kill} lines in {}",
        file.display()
    );
    at_kill
}

/// Run `command study --resume` on one thread into `part` and compare
/// `files` of study `k` with the uninterrupted run's in `full`.
fn resume_to_the_same_tables(
    [command, study]: [&str; 2],
    (full, part): (&std::path::Path, &std::path::Path),
    files: &[&str],
) {
    let part_s = part.to_str().unwrap();
    let args = [
        command,
        study,
        "--out",
        part_s,
        "--threads",
        "1",
        "--resume",
        "-q",
    ];
    let out = plyscape(&args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in files {
        assert_eq!(
            table_without(&full.join("k").join(f), &["wall_seconds"]),
            table_without(&part.join("k").join(f), &["wall_seconds"]),
            "{f}"
        );
    }
}

/// `plyscape run` killed in its multistart continues with `run --resume`:
/// the multistart from its rows, the CMA-ES stage after it again, and
/// every table equals an uninterrupted run's.
#[test]
fn killed_run_resumes_to_the_same_tables() {
    let tmp = temp_dir("kill-run");
    let dir = tmp.path().to_path_buf();
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, format!("{text}[evolve]\nmax_evaluations = 300\n")).unwrap();
        p.to_str().unwrap().to_string()
    };
    let (study, slow) = (write("k.toml", STUDY), write("slow.toml", SLOW));
    let (full, part) = (dir.join("full"), dir.join("part"));
    let (full_s, part_s) = (full.to_str().unwrap(), part.to_str().unwrap());
    let st = plyscape(&["run", &study, "--out", full_s, "--threads", "2", "-q"])
        .status()
        .unwrap();
    assert!(st.success());
    let rows = kill_after_rows(
        plyscape(&["run", &slow, "--out", part_s, "--threads", "2", "-q"]),
        &part.join("k/runs.csv"),
    );
    assert!((3..24).contains(&rows), "{rows} rows at kill");
    resume_to_the_same_tables(
        ["run", &study],
        (&full, &part),
        &["runs.csv", "optima.csv", "evolution.csv"],
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(part.join("k/manifest.json")).unwrap())
            .unwrap();
    assert_eq!(m["commands"]["multistart"]["resume"], true);
    assert!(
        m["commands"]["multistart"]["runs_this_invocation"]
            .as_u64()
            .unwrap()
            <= 21
    );
}

/// A study whose `[problem]` lines are `problem`, and the same study
/// with every evaluation sleeping 20 ms: (fast, slow) paths in `dir`.
fn fast_and_slow(dir: &std::path::Path, problem: &str, rest: &str) -> (String, String) {
    let write = |name: &str, cost: &str| {
        let p = dir.join(name);
        let text = format!("[study]\nname = \"k\"\nseed = 3\n[problem]\n{problem}{cost}{rest}");
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    (
        write("k.toml", ""),
        write("slow.toml", "cost_ms = 20.0\ncost_mode = \"sleep\"\n"),
    )
}

/// `plyscape run` killed in its CMA-ES stage, its `[discrete]` search and
/// its `[front]` continues with `run --resume` from the stage's
/// evaluation journal: the tables equal an uninterrupted run's, the
/// journal served the evaluations done before the kill, and the finished
/// run leaves no journal behind.
#[test]
fn a_run_killed_in_cmaes_discrete_or_front_resumes_to_the_same_tables() {
    let tmp = temp_dir("kill-stages");
    let dir = tmp.path().to_path_buf();
    let single = "[multistart]\nsampler = \"sobol\"\nstarts = 4\n\
        [evolve]\nmax_evaluations = 300\n\
        [discrete]\ncmaes_samples = 60\n\
        [[discrete.variables]]\nname = \"x1\"\nstep = 0.5\n\
        [[discrete.variables]]\nname = \"x2\"\nstep = 0.5\n";
    let front = "[front]\nobjectives = [{ name = \"f1\" }, { name = \"f2\" }]\n\
        subproblems = 4\npopulation = 20\nevaluations = 200\n";
    let cases = [
        (
            "himmelblau",
            single,
            "evolve",
            &["runs.csv", "evolution.csv", "discrete.csv"][..],
        ),
        (
            "himmelblau",
            single,
            "discrete",
            &["evolution.csv", "discrete.csv", "discrete_grid.csv"],
        ),
        (
            "zdt1",
            front,
            "front",
            &["front.csv", "front_ends.csv", "front_summary.csv"],
        ),
    ];
    for (problem, rest, stage, files) in cases {
        let case = dir.join(stage);
        std::fs::create_dir_all(&case).unwrap();
        let (study, slow) = fast_and_slow(&case, &format!("name = \"{problem}\"\n"), rest);
        let (full, part) = (case.join("full"), case.join("part"));
        let (full_s, part_s) = (full.to_str().unwrap(), part.to_str().unwrap());
        let st = plyscape(&["run", &study, "--out", full_s, "--threads", "2", "-q"])
            .status()
            .unwrap();
        assert!(st.success());
        assert!(
            !full.join("k/journal").exists(),
            "a finished run keeps no journal"
        );
        let journal = part.join(format!("k/journal/{stage}.log"));
        let lines = kill_at_lines(
            plyscape(&["run", &slow, "--out", part_s, "--threads", "2", "-q"]),
            &journal,
            40,
        );
        assert!(lines >= 40, "{stage}: {lines} lines");
        resume_to_the_same_tables(["run", &study], (&full, &part), files);
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(part.join("k/manifest.json")).unwrap())
                .unwrap();
        let replayed = m["commands"][stage]["replayed"].as_u64().unwrap_or(0);
        assert!(
            replayed as usize >= lines - 2,
            "{stage}: {replayed} served of {lines}"
        );
        assert!(!part.join("k/journal").exists());
    }
}

#[test]
fn killed_multistart_resumes_to_the_same_tables() {
    let tmp = temp_dir("kill");
    let dir = tmp.path().to_path_buf();
    let study = dir.join("k.toml");
    std::fs::write(&study, STUDY).unwrap();
    let study = study.to_str().unwrap();
    let slow = dir.join("slow.toml");
    std::fs::write(&slow, SLOW).unwrap();
    let slow = slow.to_str().unwrap();
    let (full, part) = (dir.join("full"), dir.join("part"));
    let (full_s, part_s) = (full.to_str().unwrap(), part.to_str().unwrap());
    let st = plyscape(&["multistart", study, "--out", full_s, "--threads", "2", "-q"])
        .status()
        .unwrap();
    assert!(st.success());

    let runs = part.join("k/runs.csv");
    let rows_at_kill = kill_after_rows(
        plyscape(&["multistart", slow, "--out", part_s, "--threads", "2", "-q"]),
        &runs,
    );
    assert!(
        (3..24).contains(&rows_at_kill),
        "{rows_at_kill} rows at kill"
    );

    resume_to_the_same_tables(
        ["multistart", study],
        (&full, &part),
        &["runs.csv", "optima.csv"],
    );
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
    // Built from a git checkout: a 40-hex commit (maybe `-dirty`).
    let commit = m["git_commit"].as_str().unwrap();
    assert!(
        commit == "unknown" || commit[..40].chars().all(|c| c.is_ascii_hexdigit()),
        "{commit}"
    );
    assert!(ms["started"].as_str().unwrap() <= ms["ended"].as_str().unwrap());
}

/// A second command on a results directory that a running one holds is
/// refused with who holds it (exit code 4), and nothing of the holder's is
/// touched; another results root is free.
#[test]
fn a_held_results_directory_is_refused_with_its_holder() {
    let tmp = temp_dir("lock");
    let dir = tmp.path().to_path_buf();
    let study = dir.join("k.toml");
    std::fs::write(&study, STUDY).unwrap();
    let out = dir.join("out");
    let held = plyscape::report::lock::DirLock::acquire(&out.join("k"), "compare").unwrap();
    let r = plyscape(&[
        "multistart",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "-q",
    ])
    .output()
    .unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(4), "{err}");
    assert!(err.contains("in use by plyscape compare"), "{err}");
    assert!(
        err.contains(&format!("process {}", std::process::id())),
        "{err}"
    );
    assert!(!out.join("k/runs.csv").exists());
    drop(held);
}

/// The Slurm scripts in `scripts/` (shown verbatim in the README) run as a
/// job array would: one shard per task id, then the merge script; the
/// merged tables equal an unsharded run's.
#[test]
fn the_documented_slurm_array_runs_and_merges() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let tmp = temp_dir("slurm");
    let dir = tmp.path().to_path_buf();
    let study = dir.join("k.toml");
    std::fs::write(&study, STUDY).unwrap();
    let bin = env!("CARGO_BIN_EXE_plyscape");
    let script = |name: &str| {
        let path = root.join("scripts").join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            readme.contains(&text),
            "README does not show {name} verbatim"
        );
        let mut c = Command::new("bash");
        c.arg(path)
            .current_dir(&dir)
            .env("STUDY", &study)
            .env("NAME", "k")
            .env("SHARDS", "3")
            .env("PLYSCAPE", bin);
        c
    };
    for task in 0..3 {
        let r = script("slurm_multistart.sh")
            .env("SLURM_ARRAY_TASK_ID", task.to_string())
            .env("SLURM_CPUS_PER_TASK", "1")
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    }
    let r = script("slurm_merge.sh").output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let st = plyscape(&["multistart", study.to_str().unwrap(), "--out"])
        .arg(dir.join("full"))
        .arg("-q")
        .status()
        .unwrap();
    assert!(st.success());
    for f in ["runs.csv", "optima.csv"] {
        assert_eq!(
            table_without(&dir.join("full/k").join(f), &["wall_seconds"]),
            table_without(&dir.join("results/k").join(f), &["wall_seconds"]),
            "{f}"
        );
    }
    assert!(dir.join("results/k/comparison.csv").exists());
}
