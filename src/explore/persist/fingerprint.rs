//! What `--resume` trusts: the study's fingerprint, and a spot check of the
//! rows it reads back.
//!
//! **Fingerprint.** A table read back on `--resume` may only be continued
//! by the same evaluations. The parts of a study that change an
//! evaluation's result are hashed one by one ([`PARTS`]):
//!
//! | part | what |
//! |---|---|
//! | `problem` | `[problem]` without `cost_ms`, `cost_mode` (they cost time, they change no value) |
//! | `scene_problem` | `[scene_problem]` without its objective and constraints (variables, start, `tied_lanes`) |
//! | `objective` | `[scene_problem.objective]` |
//! | `constraints` | `[[scene_problem.constraints]]` |
//! | `scene` | `[scene]` without `responses` and `outputs` (a scene problem drops the output columns) |
//! | `responses` | `[[scene.responses]]` |
//! | `panels` | `[[panels]]` |
//! | `solver` | `[multistart]` without the keys that choose starts, budgets, clustering and checks (`starts`, `points`, `sampler`, `feasible_only`, `max_evaluations`, `max_wall_seconds`, `x_tolerance`, `f_tolerance`, `resume_checks`, `violation_checks`) and without `feasibility_tolerance`: the method and `[multistart.mmfd]` (a key added later counts here) |
//! | `feasibility_tolerance` | `[multistart] feasibility_tolerance` |
//!
//! With an analytic problem (`[problem] name` other than `scene`) the
//! scene's parts (`[scene_problem]`, `[scene]`, `[[panels]]`) do not enter
//! the evaluation and are hashed as absent. Beside the parts, the code's
//! [`EVALUATION_VERSION`] is recorded: it is raised by hand with every
//! change of the code that moves evaluation results.
//!
//! A part is hashed as its parsed TOML value by
//! [`crate::study::toml_value::hex`] (64-bit FNV-1a of a canonical
//! encoding: comments, key order and the spelling of a number do not
//! change it; any value does, and writing out a default value counts as a
//! change: the key was absent before).
//!
//! Every driver's entry in `manifest.json` carries the fingerprint of its
//! study ([`super::manifest::DriverEntry`]). `--resume` compares the
//! current fingerprint with the one the entry that wrote the table recorded
//! ([`check_recorded`]) and refuses a difference (exit code 2), naming the
//! parts that differ and, from the study text the manifest keeps, the
//! dotted keys (`scene changed (scene.bodies[1].flexible.modes: 8 → 12)`).
//! The settings outside the parts (starts, threads, budgets, output paths,
//! plots, map resolution) may change between a run and its resume.
//!
//! **Spot check.** A fingerprint cannot see a value edited in the table
//! itself, nor a change of the code that did not raise the version. On
//! resume a few rows ([`sample`]: the row of lowest f, then rows spread
//! evenly over the table; `resume_checks` of them, default 2) are evaluated
//! again at their end design ([`reproduces`]): `f` must agree to
//! [`RECHECK_RTOL`] relative, `|Δf| ≤ 1e-9 · max(|f_stored|,
//! |f_recomputed|)`, and each `g_j` to `|Δg_j| ≤ 1e-9 · max(1, |g_stored|,
//! |g_recomputed|)` (constraints are of order 1 and often cancel to near
//! zero at an active optimum). A row that is not reproduced is refused
//! (exit code 2) with its start, the stored and the recomputed values.
//! Evaluations are deterministic, so the same code reproduces a value to
//! the last bit; the tolerance only covers a value that a local solver
//! took from an evaluation with gradients, whose integration may step
//! differently (the row is then evaluated both ways).

use super::tables::{scan_runs, RunRecord};
use crate::error::{Error, Result};
use crate::optimize::Problem;
use crate::report::manifest::Manifest;
use crate::study::toml_value::{hex, insert, lookup, remove, same};
use crate::study::Study;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The version of the code's evaluations: raised by hand with every change
/// that moves the value of an evaluation (physics, integration, objective
/// or constraint formulas) or the end of a run, so that `--resume` refuses
/// tables computed before it. 2: every run's end certified and polished,
/// MMFD's CTMIN the study's feasibility tolerance (default 1e-6). 3:
/// MMFD's first trial from a BFGS curvature model; a peak whose largest
/// sample is at an end of the run located by the end samples' parabola.
/// 4: infeasible ends rescued by the pure descent on the violation from the
/// run's start (`[multistart] rescue`).
pub const EVALUATION_VERSION: u32 = 4;

/// Relative tolerance of the spot check (see the module doc).
pub const RECHECK_RTOL: f64 = 1e-9;

/// Rows (or map cells) evaluated again on `--resume` unless the study says
/// otherwise (`resume_checks`).
pub const DEFAULT_RESUME_CHECKS: usize = 2;

/// One hashed part of a study: the dotted paths it takes from the study
/// and the dotted paths it leaves out of them.
#[derive(Debug, Clone, Copy)]
pub struct Part {
    /// Name, as in the manifest and in refusals.
    pub name: &'static str,
    /// Dotted paths of the study table that go in.
    pub paths: &'static [&'static str],
    /// Dotted paths below those that stay out.
    pub without: &'static [&'static str],
    /// Only with a scene problem (`[problem] name = "scene"`).
    pub scene_only: bool,
}

/// The parts of a study that change an evaluation (see the module doc).
pub const PARTS: [Part; 8] = [
    Part {
        name: "problem",
        paths: &["problem"],
        without: &["problem.cost_ms", "problem.cost_mode"],
        scene_only: false,
    },
    Part {
        name: "scene_problem",
        paths: &["scene_problem"],
        without: &["scene_problem.objective", "scene_problem.constraints"],
        scene_only: true,
    },
    Part {
        name: "objective",
        paths: &["scene_problem.objective"],
        without: &[],
        scene_only: true,
    },
    Part {
        name: "constraints",
        paths: &["scene_problem.constraints"],
        without: &[],
        scene_only: true,
    },
    Part {
        name: "scene",
        paths: &["scene"],
        without: &["scene.responses", "scene.outputs"],
        scene_only: true,
    },
    Part {
        name: "responses",
        paths: &["scene.responses"],
        without: &[],
        scene_only: true,
    },
    Part {
        name: "panels",
        paths: &["panels"],
        without: &[],
        scene_only: true,
    },
    Part {
        name: "solver",
        paths: &["multistart"],
        without: &[
            "multistart.starts",
            "multistart.points",
            "multistart.sampler",
            "multistart.feasible_only",
            "multistart.max_evaluations",
            "multistart.max_wall_seconds",
            "multistart.x_tolerance",
            "multistart.f_tolerance",
            "multistart.resume_checks",
            "multistart.violation_checks",
            "multistart.feasibility_tolerance",
        ],
        scene_only: false,
    },
];

/// The extra part of the multistart: its feasibility tolerance.
const FEASIBILITY: Part = Part {
    name: "feasibility_tolerance",
    paths: &["multistart.feasibility_tolerance"],
    without: &[],
    scene_only: false,
};

/// The parts a single evaluation depends on (a map's cells): all but the
/// solver's.
pub const EVALUATION_PARTS: [&str; 7] = [
    "problem",
    "scene_problem",
    "objective",
    "constraints",
    "scene",
    "responses",
    "panels",
];

/// The fingerprint of a study: the code's [`EVALUATION_VERSION`] and one
/// hash per part (16 hex digits each).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fingerprint {
    /// [`EVALUATION_VERSION`] of the code that computed the table.
    pub evaluation_version: u32,
    /// Hash of each part, by part name.
    pub parts: BTreeMap<String, String>,
}

impl Fingerprint {
    /// The fingerprint of every part of `study` (a multistart's runs).
    pub fn of_study(study: &Study) -> Fingerprint {
        let parts = all_parts()
            .map(|p| (p.name.to_string(), hex(&view(&study.table, p))))
            .collect();
        Fingerprint {
            evaluation_version: EVALUATION_VERSION,
            parts,
        }
    }

    /// Only the parts a single evaluation depends on
    /// ([`EVALUATION_PARTS`]: a map's cells).
    pub fn evaluation_only(&self) -> Fingerprint {
        Fingerprint {
            evaluation_version: self.evaluation_version,
            parts: self
                .parts
                .iter()
                .filter(|(k, _)| EVALUATION_PARTS.contains(&k.as_str()))
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect(),
        }
    }

    /// What differs between `earlier` and `self`, for the parts of `self`:
    /// one phrase per differing part (`scene changed
    /// (scene.integrator.rtol: 1e-6 → 1e-7)`), with the dotted keys when
    /// the earlier study's table `earlier_table` is known.
    pub fn differences(
        &self,
        earlier: &Fingerprint,
        earlier_table: Option<&toml::Table>,
        now_table: &toml::Table,
    ) -> Vec<String> {
        let mut out = Vec::new();
        if earlier.evaluation_version != self.evaluation_version {
            out.push(format!(
                "code changed (evaluation version {} → {})",
                earlier.evaluation_version, self.evaluation_version
            ));
        }
        for part in all_parts() {
            let Some(h) = self.parts.get(part.name) else {
                continue;
            };
            if earlier.parts.get(part.name) == Some(h) {
                continue;
            }
            let keys = earlier_table.map(|t| {
                let mut keys = Vec::new();
                diff(
                    &toml::Value::Table(view(t, part)),
                    &toml::Value::Table(view(now_table, part)),
                    "",
                    &mut keys,
                );
                keys
            });
            out.push(match keys {
                Some(k) if !k.is_empty() => {
                    let shown = k.len().min(3);
                    let more = if k.len() > shown {
                        format!(", and {} more", k.len() - shown)
                    } else {
                        String::new()
                    };
                    format!("{} changed ({}{more})", part.name, k[..shown].join("; "))
                }
                _ => format!("{} changed", part.name),
            });
        }
        out
    }
}

/// [`PARTS`] and the feasibility tolerance.
fn all_parts() -> impl Iterator<Item = &'static Part> {
    PARTS.iter().chain(std::iter::once(&FEASIBILITY))
}

/// Is the study's problem its scene (`[problem] name = "scene"`)?
fn scene_problem(table: &toml::Table) -> bool {
    table
        .get("problem")
        .and_then(|p| p.get("name"))
        .and_then(toml::Value::as_str)
        == Some("scene")
}

/// The part of `table` that `part` hashes, as a table of the same dotted
/// layout (so that differences print as the study's dotted keys).
fn view(table: &toml::Table, part: &Part) -> toml::Table {
    let mut out = toml::Table::new();
    if part.scene_only && !scene_problem(table) {
        return out;
    }
    for path in part.paths {
        if let Some(v) = lookup(table, path) {
            insert(&mut out, path, v.clone());
        }
    }
    for path in part.without {
        remove(&mut out, path);
    }
    out
}

/// A short rendering of a value for a refusal.
fn show(v: Option<&toml::Value>) -> String {
    let s = match v {
        None => return "absent".into(),
        Some(toml::Value::Table(_)) => "(table)".to_string(),
        Some(toml::Value::Array(a)) if a.len() > 4 => format!("(array of {})", a.len()),
        Some(toml::Value::Float(x)) => super::tables::num(*x),
        Some(v) => v.to_string(),
    };
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(39).collect::<String>())
    } else {
        s
    }
}

/// The dotted keys where `a` and `b` differ, with both values
/// (`scene.integrator.rtol: 1e-6 → 1e-7`).
fn diff(a: &toml::Value, b: &toml::Value, path: &str, out: &mut Vec<String>) {
    let join = |k: &str| {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    };
    match (a, b) {
        (toml::Value::Table(x), toml::Value::Table(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            for k in keys {
                match (x.get(k.as_str()), y.get(k.as_str())) {
                    (Some(p), Some(q)) => diff(p, q, &join(k), out),
                    (p, q) => out.push(format!("{}: {} → {}", join(k), show(p), show(q))),
                }
            }
        }
        (toml::Value::Array(x), toml::Value::Array(y)) => {
            for k in 0..x.len().max(y.len()) {
                let at = format!("{path}[{k}]");
                match (x.get(k), y.get(k)) {
                    (Some(p), Some(q)) => diff(p, q, &at, out),
                    (p, q) => out.push(format!("{at}: {} → {}", show(p), show(q))),
                }
            }
        }
        _ if same(a, b) => {}
        _ => out.push(format!("{path}: {} → {}", show(Some(a)), show(Some(b)))),
    }
}

/// The fingerprints recorded by the entries `commands` of
/// `dir/manifest.json`, with the study text the manifest keeps (all its
/// entries were written with that text). No manifest: none.
pub fn recorded(dir: &Path, commands: &[&str]) -> Result<(Vec<(String, Fingerprint)>, String)> {
    if !dir.join("manifest.json").exists() {
        return Ok((Vec::new(), String::new()));
    }
    let m = Manifest::read(dir)?;
    let found = commands
        .iter()
        .filter_map(|c| {
            let v = m.commands.get(*c)?.get("fingerprint")?.clone();
            Some((c.to_string(), serde_json::from_value(v).ok()?))
        })
        .collect();
    Ok((found, m.study_text))
}

/// Refuse `--resume` of `table` when a fingerprint recorded in the entries
/// `commands` of `dir/manifest.json` differs from `now` on the parts `now`
/// has (exit code 2, naming the parts and keys). Returns whether any
/// fingerprint was recorded (tables written before fingerprints have none).
pub fn check_recorded(
    study: &Study,
    dir: &Path,
    commands: &[&str],
    now: &Fingerprint,
    table: &Path,
) -> Result<bool> {
    check_recorded_for(
        study,
        (dir, commands),
        now,
        table,
        ("--resume", "rerun without --resume, or undo the change"),
    )
}

/// [`check_recorded`] for the action `key` (`--resume`, `merge`), with
/// `advice` at the end of a refusal.
pub fn check_recorded_for(
    study: &Study,
    (dir, commands): (&Path, &[&str]),
    now: &Fingerprint,
    table: &Path,
    (key, advice): (&str, &str),
) -> Result<bool> {
    let (found, text) = recorded(dir, commands)?;
    let earlier_table: Option<toml::Table> = toml::from_str(&text).ok();
    for (command, fp) in &found {
        let what = now.differences(fp, earlier_table.as_ref(), &study.table);
        if !what.is_empty() {
            return Err(Error::input(
                key,
                table.display(),
                format!(
                    "a table computed with this study's evaluations, but since `{command}` \
                     wrote it: {}; {advice}",
                    what.join(", ")
                ),
            )
            .in_file(&study.path, ""));
        }
    }
    Ok(!found.is_empty())
}

/// Which of the values `fs` (`None`: no value, e.g. a failed run) a resume
/// evaluates again: the lowest, then values spread evenly over the list,
/// `count` in all (all when there are fewer). Deterministic: the same list
/// gives the same choice.
pub fn sample(fs: &[Option<f64>], count: usize) -> Vec<usize> {
    let cand: Vec<usize> = (0..fs.len()).filter(|&k| fs[k].is_some()).collect();
    if count >= cand.len() {
        return cand;
    }
    if count == 0 {
        return Vec::new();
    }
    let lowest = cand
        .iter()
        .copied()
        .min_by(|&a, &b| {
            fs[a]
                .partial_cmp(&fs[b])
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .expect("count < cand.len() so cand is not empty");
    let mut chosen = vec![lowest];
    let slots = count - 1;
    let evenly = (0..slots).map(|s| cand[((2 * s + 1) * cand.len()) / (2 * slots.max(1))]);
    for k in evenly.chain(cand.iter().copied()) {
        if chosen.len() == count {
            break;
        }
        if !chosen.contains(&k) {
            chosen.push(k);
        }
    }
    chosen.sort_unstable();
    chosen
}

/// Does `(f, g)` agree with the stored `(f0, g0)` to [`RECHECK_RTOL`]
/// (see the module doc)?
pub fn agrees(f0: f64, g0: &[f64], f: f64, g: &[f64]) -> bool {
    let close = |a: f64, b: f64, floor: f64| {
        a.to_bits() == b.to_bits()
            || (a - b).abs() <= RECHECK_RTOL * a.abs().max(b.abs()).max(floor)
    };
    g0.len() == g.len() && close(f0, f, 0.0) && g0.iter().zip(g).all(|(&a, &b)| close(a, b, 1.0))
}

/// Evaluate `problem` at `x` again, without gradients and, if that does
/// not agree, with them (`with_gradients`): `Ok(None)` when one of them
/// reproduces the stored `(f0, g0)`, else the values recomputed without
/// gradients.
pub fn reproduces(
    problem: &dyn Problem,
    x: &[f64],
    (f0, g0): (f64, &[f64]),
    with_gradients: bool,
) -> Result<Option<(f64, Vec<f64>)>> {
    let e = problem.evaluate(x, false)?;
    if agrees(f0, g0, e.f, &e.g) {
        return Ok(None);
    }
    if with_gradients {
        let d = problem.evaluate(x, true)?;
        if agrees(f0, g0, d.f, &d.g) {
            return Ok(None);
        }
    }
    Ok(Some((e.f, e.g)))
}

/// Everything `multistart --resume` checks before it continues `runs.csv`
/// in `dir`: the fingerprint recorded by the `multistart` or `merge` entry
/// ([`check_recorded`]), then `checks` rows evaluated again ([`sample`],
/// [`reproduces`]). Reads `runs.csv` without changing it. A table without a
/// recorded fingerprint is said so on stderr (unless `quiet`) and relies on
/// the spot check.
pub fn check_runs(
    study: &Study,
    dir: &Path,
    problem: &dyn Problem,
    checks: usize,
    quiet: bool,
) -> Result<()> {
    let path = dir.join("runs.csv");
    if !path.exists() {
        return Ok(());
    }
    let now = Fingerprint::of_study(study);
    let vars = problem.variables();
    let (read, _) = scan_runs(&path, vars, problem.n_constraints())?;
    let known = check_recorded(study, dir, &["multistart", "merge"], &now, &path)?;
    if !known && !read.rows.is_empty() && !quiet {
        eprintln!(
            "note: {}: no study fingerprint recorded (written before fingerprints, or the \
             manifest was rewritten for another study text); {} row(s) are evaluated again",
            path.display(),
            checks.min(read.rows.len())
        );
    }
    check_rows(study, &path, problem, &read.rows, checks)
}

/// The spot check of `rows` of the table `path` (see [`check_runs`]).
fn check_rows(
    study: &Study,
    path: &Path,
    problem: &dyn Problem,
    rows: &[RunRecord],
    checks: usize,
) -> Result<()> {
    let fs: Vec<Option<f64>> = rows
        .iter()
        .map(|r| r.result.as_ref().map(|x| x.f))
        .collect();
    for k in sample(&fs, checks) {
        let row = &rows[k];
        let Some(res) = &row.result else { continue };
        if let Some((f, g)) = reproduces(problem, &res.x, (res.f, &res.g), true)? {
            return Err(Error::input(
                "--resume",
                format!("{} (row of start {})", path.display(), row.start),
                format!(
                    "rows that this study reproduces, but at its x = {:?} the row has f = {:e}, g = {:?} \
                     and an evaluation now gives f = {f:e}, g = {g:?} (not within {RECHECK_RTOL:e} \
                     relative): the table was edited or the evaluations changed; rerun without --resume",
                    res.x, res.f, res.g
                ),
            )
            .in_file(&study.path, ""));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn study(text: &str) -> Study {
        Study::parse("f.toml", text).unwrap()
    }

    const SCENE: &str = "[study]\nseed = 1\n[problem]\nname = \"scene\"\n\
        [scene_problem]\nstart = [55.0]\n[scene_problem.objective]\nresponse = \"psi0\"\n\
        [scene]\neffects = [\"flexibility\"]\n[scene.integrator]\nrtol = 1e-6\n\
        [[scene.responses]]\nname = \"psi0\"\nkind = \"integral\"\n\
        [[scene.bodies]]\nname = \"B1\"\nmass = 2000\n\
        [[scene.bodies]]\nname = \"B2\"\nflexible = { modes = 8 }\n\
        [multistart]\nstarts = 4\n";

    #[test]
    fn comments_order_and_spelling_do_not_change_the_fingerprint_values_do() {
        let a = Fingerprint::of_study(&study(SCENE));
        // Comments, whitespace, key order, number spelling: no change.
        let same_text = SCENE
            .replace("rtol = 1e-6", "# tighter later\nrtol   = 0.000001")
            .replace("mass = 2000", "mass = 2000.0")
            .replace(
                "[study]\nseed = 1\n[problem]\nname = \"scene\"\n",
                "[problem]\nname = \"scene\"\n[study]\nseed = 1\n",
            );
        assert_eq!(Fingerprint::of_study(&study(&same_text)), a);
        // Settings that do not change an evaluation: no change.
        let more = SCENE
            .replace(
                "starts = 4",
                "starts = 40\nmax_evaluations = 9\nx_tolerance = 0.1",
            )
            .replace("seed = 1", "seed = 2\nthreads = 3");
        assert_eq!(Fingerprint::of_study(&study(&more)), a);
        // A value: that part only, named with its dotted key.
        let modes = study(&SCENE.replace("modes = 8", "modes = 12"));
        let b = Fingerprint::of_study(&modes);
        let changed: Vec<&String> = a
            .parts
            .keys()
            .filter(|k| a.parts[*k] != b.parts[*k])
            .collect();
        assert_eq!(changed, ["scene"]);
        let earlier = study(SCENE).table;
        let what = b.differences(&a, Some(&earlier), &modes.table);
        assert_eq!(
            what,
            ["scene changed (scene.bodies[1].flexible.modes: 8 → 12)"]
        );
        // Each part on its own.
        for (edit, part) in [
            (("rtol = 1e-6", "rtol = 1e-7"), "scene"),
            (("kind = \"integral\"", "kind = \"peak\""), "responses"),
            (("response = \"psi0\"", "response = \"u3\""), "objective"),
            (("start = [55.0]", "start = [50.0]"), "scene_problem"),
            (
                ("starts = 4", "starts = 4\nmethod = \"steepest\""),
                "solver",
            ),
            (
                ("starts = 4", "starts = 4\nfeasibility_tolerance = 0.0"),
                "feasibility_tolerance",
            ),
            (
                ("starts = 4", "starts = 4\n[multistart.mmfd]\ndelobj = 1e-6"),
                "solver",
            ),
        ] {
            let s = study(&SCENE.replace(edit.0, edit.1));
            let c = Fingerprint::of_study(&s);
            let what = c.differences(&a, Some(&earlier), &s.table);
            assert_eq!(what.len(), 1, "{what:?}");
            assert!(
                what[0].starts_with(&format!("{part} changed (")),
                "{what:?}"
            );
        }
        // The code's version, and a missing earlier text (parts only).
        let mut old = a.clone();
        old.evaluation_version = 0;
        let what = b.differences(&old, None, &modes.table);
        assert_eq!(
            what,
            [
                format!("code changed (evaluation version 0 → {EVALUATION_VERSION})"),
                "scene changed".to_string()
            ]
        );
        // The map's evaluation parts leave the solver out.
        let e = b.evaluation_only();
        assert!(!e.parts.contains_key("solver") && e.parts.contains_key("scene"));
    }

    #[test]
    fn an_analytic_problem_ignores_the_scene_and_its_cost() {
        let base = "[problem]\nname = \"himmelblau\"\n[multistart]\nstarts = 3\n";
        let a = Fingerprint::of_study(&study(base));
        let with_scene = format!("{base}[scene]\nbaumgarte = 3.0\n");
        let cost = base.replace(
            "himmelblau\"",
            "himmelblau\"\ncost_ms = 2.0\ncost_mode = \"sleep\"",
        );
        assert_eq!(Fingerprint::of_study(&study(&with_scene)), a);
        assert_eq!(Fingerprint::of_study(&study(&cost)), a);
        let other = study(&base.replace("himmelblau", "hs22"));
        let what =
            Fingerprint::of_study(&other).differences(&a, Some(&study(base).table), &other.table);
        assert_eq!(
            what,
            ["problem changed (problem.name: \"himmelblau\" → \"hs22\")"]
        );
    }

    #[test]
    fn the_sample_takes_the_lowest_then_spreads_and_skips_missing_values() {
        let fs = [
            Some(3.0),
            None,
            Some(1.0),
            Some(5.0),
            Some(4.0),
            Some(2.0),
            Some(6.0),
        ];
        assert_eq!(sample(&fs, 0), Vec::<usize>::new());
        assert_eq!(sample(&fs, 1), [2]);
        // Lowest (index 2), then the middle of the six values (index 4).
        assert_eq!(sample(&fs, 2), [2, 4]);
        assert_eq!(sample(&fs, 3).len(), 3);
        assert_eq!(sample(&fs, 99), [0, 2, 3, 4, 5, 6]);
        assert_eq!(sample(&fs, 2), sample(&fs, 2));
    }

    #[test]
    fn agreement_is_relative_with_a_unit_floor_for_constraints() {
        assert!(agrees(1.0, &[1e-12], 1.0 + 1e-10, &[2e-12]));
        assert!(!agrees(1.0, &[0.0], 1.0 + 1e-8, &[0.0]));
        assert!(!agrees(1e-14, &[], 2e-14, &[]));
        assert!(agrees(1e-14, &[], 1e-14, &[]));
        assert!(!agrees(1.0, &[0.5], 1.0, &[0.5 + 1e-8]));
        assert!(!agrees(1.0, &[0.5], 1.0, &[]));
    }
}
