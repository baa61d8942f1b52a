//! What `--resume` trusts: the study fingerprint in the manifest (a change
//! of an evaluation is refused with what changed, exit code 2) and the spot
//! check of rows read back (a hand-edited f is refused). Settings that do
//! not change an evaluation (starts, budgets, threads) still resume.

use crate::common::explore::{ctx, study, table_without};
use crate::common::temp_dir;
use plyscape::explore::{self, DriveFlags};
use std::process::Command;

fn himmelblau(starts: usize, extra: &str) -> String {
    format!(
        "[study]\nname = \"r\"\nseed = 5\n[problem]\nname = \"himmelblau\"\n\
         [multistart]\nsampler = \"sobol\"\nstarts = {starts}\n{extra}\
         [multistart.mmfd]\ndelobj = 1e-8\n"
    )
}

const RESUME: DriveFlags = DriveFlags {
    resume: true,
    shard: plyscape::explore::multistart::Shard { index: 0, count: 1 },
    force: false,
};

fn plyscape(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_plyscape"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn a_changed_evaluation_is_refused_with_what_changed_and_more_starts_resume() {
    let tmp = temp_dir("resume-fp");
    let dir = tmp.path().to_path_buf();
    let file = dir.join("r.toml");
    std::fs::write(&file, himmelblau(6, "")).unwrap();
    let out = dir.join("out");
    let (file_s, out_s) = (file.to_str().unwrap(), out.to_str().unwrap());
    let r = plyscape(&["multistart", file_s, "--out", out_s, "-q"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("r/manifest.json")).unwrap())
            .unwrap();
    let fp = &m["commands"]["multistart"]["fingerprint"];
    assert_eq!(
        fp["evaluation_version"],
        plyscape::explore::persist::fingerprint::EVALUATION_VERSION
    );
    assert_eq!(fp["parts"]["solver"].as_str().unwrap().len(), 16);

    // The solver's settings changed: refused, exit code 2, the key named.
    std::fs::write(
        &file,
        himmelblau(6, "").replace("delobj = 1e-8", "# looser\ndelobj = 1e-3"),
    )
    .unwrap();
    let r = plyscape(&["multistart", file_s, "--out", out_s, "--resume", "-q"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("`--resume`")
            && err.contains("solver changed (multistart.mmfd.delobj: 1e-8 → 0.001)"),
        "{err}"
    );
    // The problem changed: named as well.
    std::fs::write(
        &file,
        himmelblau(6, "").replace(
            "himmelblau\"",
            "himmelblau\"\nbounds = [[-5.0, 5.0], [-5.0, 6.0]]",
        ),
    )
    .unwrap();
    let r = plyscape(&["multistart", file_s, "--out", out_s, "--resume", "-q"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("problem changed (problem.bounds: absent → "),
        "{err}"
    );

    // Comments, more starts, a budget and another thread count: resumed,
    // and the tables equal a run with those starts from scratch.
    let more = format!(
        "# twelve now\n{}",
        himmelblau(12, "max_wall_seconds = 600.0\n")
    );
    std::fs::write(&file, &more).unwrap();
    let r = plyscape(&[
        "multistart",
        file_s,
        "--out",
        out_s,
        "--resume",
        "--threads",
        "2",
        "-q",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let s = study("r", &more);
    let fresh = dir.join("fresh");
    explore::run_multistart(&ctx(&s, &fresh, 1, DriveFlags::default())).unwrap();
    for f in ["runs.csv", "optima.csv"] {
        assert_eq!(
            table_without(&out.join("r").join(f), &["wall_seconds"]),
            table_without(&fresh.join("r").join(f), &["wall_seconds"]),
            "{f}"
        );
    }

    // Tables of code with another evaluation version: refused.
    let path = out.join("r/manifest.json");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(
        &path,
        text.replace(
            &format!(
                "\"evaluation_version\": {}",
                plyscape::explore::persist::fingerprint::EVALUATION_VERSION
            ),
            "\"evaluation_version\": 0",
        ),
    )
    .unwrap();
    let e = explore::run_multistart(&ctx(&s, &out, 1, RESUME))
        .unwrap_err()
        .to_string();
    let changed = format!(
        "code changed (evaluation version 0 → {})",
        plyscape::explore::persist::fingerprint::EVALUATION_VERSION
    );
    assert!(e.contains(&changed), "{e}");
}

/// Change the `f` of the row of start `start` in `runs.csv` to `f`.
fn edit_f(path: &std::path::Path, start: usize, f: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let col = header.iter().position(|h| *h == "f").unwrap();
    for line in lines.iter_mut().skip(1) {
        let mut fields: Vec<String> = line.split(',').map(String::from).collect();
        if fields[0] == start.to_string() {
            fields[col] = f.to_string();
            *line = fields.join(",");
        }
    }
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
}

#[test]
fn a_hand_edited_f_is_caught_by_the_spot_check() {
    let tmp = temp_dir("resume-edit");
    let dir = tmp.path().to_path_buf();
    let s = study("r", &himmelblau(8, ""));
    let r = explore::run_multistart(&ctx(&s, &dir, 1, DriveFlags::default())).unwrap();
    let runs = dir.join("r/runs.csv");
    let intact = std::fs::read_to_string(&runs).unwrap();
    // Untouched: resumes (nothing to run).
    assert_eq!(
        explore::run_multistart(&ctx(&s, &dir, 1, RESUME))
            .unwrap()
            .new_runs,
        0
    );
    // Any row, with every row checked: start 5's f edited.
    let all = study("r", &himmelblau(8, "resume_checks = 100\n"));
    let stored = r.runs[5].result.as_ref().unwrap().f;
    edit_f(&runs, 5, "0.5");
    let e = explore::run_multistart(&ctx(&all, &dir, 1, RESUME)).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    let e = e.to_string();
    assert!(
        e.contains("row of start 5") && e.contains("f = 5e-1"),
        "{e}"
    );
    assert!(e.contains(&format!("f = {stored:e}")), "{e}");
    // With the default two checks the row of lowest f is always one of
    // them: an f edited below every other is caught.
    std::fs::write(&runs, &intact).unwrap();
    edit_f(&runs, 2, "-1");
    let e = explore::run_multistart(&ctx(&s, &dir, 1, RESUME))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("row of start 2") && e.contains("f = -1e0"),
        "{e}"
    );
    // The table is left as it was.
    assert!(std::fs::read_to_string(&runs).unwrap().contains(",-1,"));
}

const MAP: &str =
    "[study]\nname = \"m\"\nseed = 2\n[problem]\nname = \"hs22\"\n[map]\nresolution = 9\n";

/// Run `plyscape map` on `study` into `out` (with `--resume` if asked).
fn map(
    study: &plyscape::study::Study,
    out: &std::path::Path,
    resume: bool,
) -> plyscape::Result<()> {
    let flags = DriveFlags {
        resume,
        ..Default::default()
    };
    explore::run_map(&ctx(study, out, 2, flags)).map(|_| ())
}

#[test]
fn an_interrupted_map_resumes_to_the_same_table_byte_for_byte() {
    let tmp = temp_dir("resume-map");
    let dir = tmp.path().to_path_buf();
    let s = study("m", MAP);
    let full = dir.join("full");
    map(&s, &full, false).unwrap();
    let table = std::fs::read(full.join("m/map.csv")).unwrap();
    let text = String::from_utf8(table.clone()).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + 81);
    // What an interrupt leaves: the header, the first k cells in grid
    // order and half of the next line.
    let part = dir.join("part");
    std::fs::create_dir_all(part.join("m")).unwrap();
    let k = 30;
    let mut cut = lines[..=k].join("\n") + "\n";
    cut.push_str(&lines[k + 1][..lines[k + 1].len() / 2]);
    std::fs::write(part.join("m/map.csv"), &cut).unwrap();
    map(&s, &part, true).unwrap();
    assert_eq!(std::fs::read(part.join("m/map.csv")).unwrap(), table);
    assert_eq!(
        std::fs::read(part.join("m/map.svg")).unwrap(),
        std::fs::read(full.join("m/map.svg")).unwrap()
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(part.join("m/manifest.json")).unwrap())
            .unwrap();
    assert_eq!(m["commands"]["map"]["complete"], true);
    assert!(m["commands"]["map"]["fingerprint"]["parts"]["problem"].is_string());

    // A finished map resumes to itself, computing nothing.
    map(&s, &part, true).unwrap();
    assert_eq!(std::fs::read(part.join("m/map.csv")).unwrap(), table);

    // Another resolution: the rows are not its grid's cells.
    std::fs::write(part.join("m/map.csv"), lines[..=k].join("\n") + "\n").unwrap();
    let finer = study("m", &MAP.replace("resolution = 9", "resolution = 11"));
    let e = map(&finer, &part, true).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(e.to_string().contains("the grid (resolution"), "{e}");
    // Another problem: refused by the fingerprint.
    let other = study("m", &MAP.replace("hs22", "himmelblau"));
    let e = map(&other, &part, true).unwrap_err().to_string();
    assert!(
        e.contains("problem changed (problem.name: \"hs22\" → \"himmelblau\")"),
        "{e}"
    );
    // A hand-edited cell, every cell checked: refused with its values.
    let edited: Vec<String> = lines[..=k]
        .iter()
        .enumerate()
        .map(|(i, l)| {
            if i == 12 {
                let mut f: Vec<&str> = l.split(',').collect();
                f[2] = "7.25";
                f.join(",")
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(part.join("m/map.csv"), edited.join("\n") + "\n").unwrap();
    let all = study(
        "m",
        &MAP.replace("resolution = 9", "resolution = 9\nresume_checks = 1000"),
    );
    let e = map(&all, &part, true).unwrap_err().to_string();
    assert!(e.contains("(line 13)") && e.contains("f = 7.25e0"), "{e}");
}

/// Kill the real `plyscape map` process mid-run, then `map --resume` with
/// the fast study (the evaluation cost is no part of the fingerprint): the
/// table equals an uninterrupted run's byte for byte.
#[test]
fn a_killed_map_process_resumes_to_the_uninterrupted_table() {
    use std::time::{Duration, Instant};
    let tmp = temp_dir("resume-map-kill");
    let dir = tmp.path().to_path_buf();
    let fast = dir.join("m.toml");
    let text = MAP.replace("resolution = 9", "resolution = 11");
    std::fs::write(&fast, &text).unwrap();
    // 121 cells sleeping 40 ms each: about 2.4 s on 2 threads.
    let slow = dir.join("slow.toml");
    std::fs::write(
        &slow,
        text.replace("hs22\"", "hs22\"\ncost_ms = 40.0\ncost_mode = \"sleep\""),
    )
    .unwrap();
    let (full, part) = (dir.join("full"), dir.join("part"));
    let run = |study: &std::path::Path, out: &std::path::Path, resume: bool| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_plyscape"));
        c.args([
            "map",
            study.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(["--threads", "2", "-q"]);
        if resume {
            c.arg("--resume");
        }
        c
    };
    assert!(run(&fast, &full, false).status().unwrap().success());
    let mut child = run(&slow, &part, false).spawn().unwrap();
    let table = part.join("m/map.csv");
    let t0 = Instant::now();
    while std::fs::read_to_string(&table).map_or(0, |t| t.lines().count()) < 11
        && t0.elapsed() < Duration::from_secs(60)
    {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    assert!(!child.wait().unwrap().success(), "finished before the kill");
    let rows = std::fs::read_to_string(&table).unwrap().lines().count() - 1;
    assert!((10..121).contains(&rows), "{rows} rows at the kill");
    let out = run(&fast, &part, true).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read(&table).unwrap(),
        std::fs::read(full.join("m/map.csv")).unwrap()
    );
}
