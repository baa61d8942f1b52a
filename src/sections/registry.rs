//! The one list of study sections: [`SECTIONS`], each with its key, its
//! check and its run. `plyscape run` checks every section of a study before
//! the first one runs ([`check_study`]), refuses a section nobody reads
//! ([`check_sections`]), then runs the sections in the order of the list
//! ([`run_study`]).

use crate::error::Result;
use crate::explore::{self, DriveFlags};
use crate::study::keys::{self, KeyProbe};
use crate::study::{Study, StudyMeta};
use serde::de::DeserializeOwned;
use std::collections::BTreeSet;
use std::path::PathBuf;

/// A resolved run: the study and the common options of the command line.
#[derive(Debug, Clone)]
pub struct RunConfig {
    /// The study.
    pub study: Study,
    /// Root directory of the results (`results/`).
    pub out: PathBuf,
    /// Worker threads.
    pub threads: usize,
    /// No progress bars or summaries.
    pub quiet: bool,
    /// Discard an earlier `runs.csv` instead of keeping it as
    /// `runs-<UTC time>.csv` (multistart without `--resume`).
    pub force: bool,
    /// `run --resume`: the multistart (also `[compare]`'s) and the map
    /// continue from their tables, CMA-ES, `[discrete]` and `[front]` from
    /// their evaluation journals
    /// ([`crate::explore::persist::journal`]).
    pub resume: bool,
}

impl RunConfig {
    /// The exploration drivers' view of this run, with `flags` (`--force`
    /// taken from the run, and `--resume` when the run resumes).
    pub fn explore(&self, mut flags: DriveFlags) -> explore::Context<'_> {
        flags.force = self.force;
        flags.resume |= self.resume;
        explore::Context {
            study: &self.study,
            out: &self.out,
            threads: self.threads,
            quiet: self.quiet,
            flags,
        }
    }
}

/// The largest thread count accepted for a machine with `cores` cores.
pub fn max_threads(cores: usize) -> usize {
    (4 * cores).max(64)
}

/// One top-level section of a study file.
#[derive(Debug, Clone, Copy)]
pub struct Section {
    /// The table's name in study files.
    pub key: &'static str,
    /// Record the keys the section accepts (its serde type, probed by
    /// [`keys::probe`]): the key reference of the docs is checked against
    /// these.
    pub keys: fn(&KeyProbe, &str),
    /// Read the section into its typed form and check it as far as that
    /// needs no computation (unknown keys, wrong types, bad values).
    pub check: fn(&Study) -> Result<()>,
    /// Do the section's work; `None` for a section that holds data other
    /// sections read.
    pub run: Option<fn(&RunConfig) -> Result<()>>,
    /// The section drives the study's `[problem]`, which is then checked
    /// once, before every section.
    pub uses_problem: bool,
}

/// A section that holds data for others, checked by them, read into `T`.
const fn data<T: DeserializeOwned>(key: &'static str) -> Section {
    Section {
        key,
        keys: keys::probe::<T>,
        check: |_| Ok(()),
        run: None,
        uses_problem: false,
    }
}

/// Every section `plyscape run` knows: first those that do work, in the
/// order the work is done, then those that hold data. A new section is one
/// entry here.
pub static SECTIONS: &[Section] = &[
    Section {
        key: "modes",
        keys: keys::probe::<super::modes::ModesSpec>,
        check: |s| super::modes::check(s).map(|_| ()),
        run: Some(run_modes),
        uses_problem: false,
    },
    Section {
        key: "scene",
        keys: keys::probe::<crate::scene::spec::SceneSpec>,
        check: |s| crate::scene::ScenePlan::new(s).map(|_| ()),
        run: Some(run_scene),
        uses_problem: false,
    },
    Section {
        key: "multistart",
        keys: keys::probe::<explore::MultistartSection>,
        check: |s| explore::multistart_section(s).map(|_| ()),
        // Under [compare] the multistart runs as part of the comparison,
        // under [scaling] once per thread count.
        run: Some(|cfg| {
            if cfg.study.has("compare") || cfg.study.has("scaling") {
                return Ok(());
            }
            explore::run_multistart(&cfg.explore(DriveFlags::default())).map(|_| ())
        }),
        uses_problem: true,
    },
    Section {
        key: "evolve",
        keys: keys::probe::<explore::EvolveSection>,
        check: |s| explore::evolve_plan(s).map(|_| ()),
        // Under [compare] the evolution runs as part of the comparison.
        run: Some(|cfg| {
            if cfg.study.has("compare") {
                return Ok(());
            }
            explore::run_evolve(&cfg.explore(DriveFlags::default()), None).map(|_| ())
        }),
        uses_problem: true,
    },
    Section {
        key: "compare",
        keys: keys::probe::<explore::CompareSection>,
        check: |s| explore::compare_section(s).map(|_| ()),
        run: Some(|cfg| explore::run_compare(&cfg.explore(DriveFlags::default())).map(|_| ())),
        uses_problem: true,
    },
    Section {
        key: "scaling",
        keys: keys::probe::<explore::multistart::scaling::ScalingSection>,
        check: |s| explore::multistart::scaling::check(s).map(|_| ()),
        run: Some(|cfg| {
            explore::multistart::scaling::run_scaling(&cfg.explore(DriveFlags::default()))
                .map(|_| ())
        }),
        uses_problem: true,
    },
    Section {
        key: "discrete",
        keys: keys::probe::<explore::discrete::DiscreteSection>,
        check: explore::discrete::command::check,
        run: Some(|cfg| {
            explore::discrete::command::run_discrete(&cfg.explore(DriveFlags::default()))
                .map(|_| ())
        }),
        uses_problem: true,
    },
    Section {
        key: "map",
        keys: keys::probe::<explore::MapSection>,
        check: |s| explore::map_section(s).map(|_| ()),
        run: Some(|cfg| explore::run_map(&cfg.explore(DriveFlags::default())).map(|_| ())),
        uses_problem: true,
    },
    Section {
        key: "front",
        keys: keys::probe::<explore::front::command::FrontSection>,
        check: |s| explore::front::command::check(s).map(|_| ()),
        run: Some(run_front),
        uses_problem: false,
    },
    Section {
        key: "kernel_bench",
        keys: keys::probe::<super::kernel_bench::BenchSpec>,
        check: |s| super::kernel_bench::check(s).map(|_| ()),
        run: Some(|c| super::kernel_bench::run_kernel_bench(&c.study, &c.out, c.quiet).map(|_| ())),
        uses_problem: false,
    },
    Section {
        key: "events_bench",
        keys: keys::probe::<super::events_bench::EventsSpec>,
        check: |s| super::events_bench::check(s).map(|_| ()),
        run: Some(|c| super::events_bench::run_events_bench(&c.study, &c.out, c.quiet).map(|_| ())),
        uses_problem: false,
    },
    Section {
        key: "scene_convergence",
        keys: keys::probe::<super::scene_convergence::ConvergenceSpec>,
        check: |s| super::scene_convergence::check(s).map(|_| ()),
        run: Some(|c| {
            super::scene_convergence::run_scene_convergence(&c.study, &c.out, c.quiet).map(|_| ())
        }),
        uses_problem: false,
    },
    Section {
        key: "eval_bench",
        keys: keys::probe::<super::eval_bench::EvalBenchSpec>,
        check: |s| super::eval_bench::check(s).map(|_| ()),
        run: Some(|c| {
            super::eval_bench::run_eval_bench_section(&c.study, &c.out, c.quiet).map(|_| ())
        }),
        uses_problem: false,
    },
    Section {
        key: "gradient_check",
        keys: keys::probe::<super::gradient_check::GradientCheckSpec>,
        check: |s| super::gradient_check::check(s).map(|_| ()),
        run: Some(|c| {
            super::gradient_check::run_gradient_check(&c.study, &c.out, c.quiet).map(|_| ())
        }),
        uses_problem: false,
    },
    Section {
        key: "sens_bench",
        keys: keys::probe::<super::sens_bench::SensBenchSpec>,
        check: |s| super::sens_bench::check(s).map(|_| ()),
        run: Some(|c| {
            super::sens_bench::run_sens_bench_section(&c.study, &c.out, c.quiet).map(|_| ())
        }),
        uses_problem: false,
    },
    Section {
        key: "support_compare",
        keys: keys::probe::<super::support_compare::CompareSpec>,
        check: |s| super::support_compare::check(s).map(|_| ()),
        run: Some(|c| {
            super::support_compare::run_support_compare(&c.study, &c.out, c.quiet).map(|_| ())
        }),
        uses_problem: false,
    },
    Section {
        key: "noise",
        keys: keys::probe::<super::noise::NoiseSpec>,
        check: |s| super::noise::check(s).map(|_| ()),
        run: Some(|c| super::noise::run_noise(&c.study, &c.out, c.quiet).map(|_| ())),
        uses_problem: true,
    },
    // Data: the drivers' problem (checked through `uses_problem`), the
    // panels and their convergence grid (read by [modes] and scenes), the
    // scene problem's design (read with [problem] name = "scene").
    data::<explore::problem::problems::ProblemSpec>("problem"),
    data::<Vec<crate::fe::spec::PanelSpec>>("panels"),
    data::<super::modes::ConvergenceSpec>("convergence"),
    data::<explore::problem::scene_problem::SceneProblemSpec>("scene_problem"),
    // Read and written by the multistart.
    Section {
        key: "robustness",
        keys: keys::probe::<explore::multistart::robustness::RobustnessSection>,
        check: |s| explore::multistart::robustness::section(s).map(|_| ()),
        run: None,
        uses_problem: true,
    },
    Section {
        key: "optimum_report",
        keys: keys::probe::<explore::multistart::optimum_report::OptimumReportSection>,
        check: |s| explore::multistart::optimum_report::check(s).map(|_| ()),
        run: None,
        uses_problem: true,
    },
];

/// Every key a study file accepts, as dotted paths (`scene.bodies.name`),
/// and the top-level tables: `[study]` and every section of [`SECTIONS`],
/// probed through their serde types.
pub fn accepted_keys() -> (BTreeSet<String>, BTreeSet<String>) {
    let probe = KeyProbe::default();
    keys::probe::<StudyMeta>(&probe, "study");
    for s in SECTIONS {
        (s.keys)(&probe, s.key);
    }
    probe.into_keys()
}

/// The section called `key`, if there is one.
pub fn section(key: &str) -> Option<&'static Section> {
    SECTIONS.iter().find(|s| s.key == key)
}

/// The `[front]` section: the Pareto front of both methods, its tables and
/// plot, and its manifest entry (wall time, points and calls per method).
pub fn run_front(cfg: &RunConfig) -> Result<()> {
    let t0 = std::time::Instant::now();
    let dir = cfg.study.output_dir(&cfg.out)?;
    let ctx = cfg.explore(DriveFlags::default());
    let report = explore::front::command::run_front(&ctx)?;
    let mut entry = serde_json::Map::new();
    entry.insert("wall_seconds".into(), t0.elapsed().as_secs_f64().into());
    entry.insert("replayed".into(), report.replayed.into());
    for mf in &report.methods {
        let mut m = serde_json::json!({
            "points": mf.points.len(),
            "function_calls": mf.function_calls,
            "gradient_calls": mf.gradient_calls,
        });
        if let Some(s) = mf.simulations {
            m["simulations"] = s.into();
        }
        entry.insert(mf.method.clone(), m);
    }
    crate::report::record_command(&dir, &cfg.study, cfg.threads, "front", entry, None)
}

/// The `[modes]` section: panel modal analysis (and its manifest entry).
pub fn run_modes(cfg: &RunConfig) -> Result<()> {
    let t0 = std::time::Instant::now();
    super::modes::run_modes(&cfg.study, &cfg.out, cfg.quiet)?;
    let dir = cfg.study.output_dir(&cfg.out)?;
    let mut entry = serde_json::Map::new();
    entry.insert("wall_seconds".into(), t0.elapsed().as_secs_f64().into());
    crate::report::record_command(&dir, &cfg.study, 1, "modes", entry, None)
}

/// The `[scene]` section: simulate the multibody scene and write
/// `history.csv`, `stats.csv` (and an SVG) into the study's output folder;
/// the wall-clock times (whole command, integration, output) go to the
/// command's entry in `manifest.json`.
pub fn run_scene(cfg: &RunConfig) -> Result<()> {
    use crate::simulate;
    let t0 = std::time::Instant::now();
    let scene = crate::scene::load_scene(&cfg.study)?;
    // A numerical failure keeps the rows computed before it: they are
    // written, the failure goes into stats.csv and the manifest, and the
    // run then ends with the failure (exit code 3).
    let (_, mut sim) = simulate::simulate_partial(&scene).map_err(cfg.study.locate("scene"))?;
    for w in &sim.warnings {
        eprintln!("{w}");
    }
    let dir = cfg.study.output_dir(&cfg.out)?;
    let files = simulate::write_results(&scene, &sim, &dir)?;
    let mut entry = serde_json::Map::new();
    if let Some(e) = &sim.failure {
        entry.insert("status".into(), "failed".into());
        entry.insert("failure".into(), e.to_string().into());
        entry.insert("rows_written".into(), sim.rows.len().into());
    }
    if !sim.warnings.is_empty() {
        entry.insert("warnings".into(), sim.warnings.clone().into());
    }
    entry.insert("wall_seconds".into(), t0.elapsed().as_secs_f64().into());
    // The integration's own wall-clock times live here, not in stats.csv
    // (which holds only reproducible numbers; see simulate::write_results).
    entry.insert("wall_time_s".into(), sim.stats.wall.into());
    entry.insert("output_wall_time_s".into(), sim.stats.observer_wall.into());
    entry.insert(
        "files".into(),
        files
            .iter()
            .filter_map(|f| f.file_name()?.to_str().map(String::from))
            .collect::<Vec<_>>()
            .into(),
    );
    crate::report::record_command(&dir, &cfg.study, 1, "simulate", entry, None)?;
    if let Some(e) = sim.failure.take() {
        if !cfg.quiet {
            for f in &files {
                println!("wrote {} (up to the failure)", f.display());
            }
        }
        return Err(e);
    }
    let (rigid_lines, warnings) = simulate::rigid_summary(&scene);
    for w in &warnings {
        eprintln!("{w}");
    }
    if !cfg.quiet {
        println!("{}", simulate::summary(&sim));
        for l in &rigid_lines {
            println!("{l}");
        }
        for f in files {
            println!("wrote {}", f.display());
        }
    }
    Ok(())
}

/// Refuse a study with a top-level section no part of the tool reads (a
/// typo must not silently do nothing), naming the known sections and the
/// closest one. Every subcommand checks this before any work starts.
pub fn check_sections(study: &Study) -> Result<()> {
    let mut known: Vec<&str> = vec!["study"];
    known.extend(SECTIONS.iter().map(|s| s.key));
    for key in study.table.keys() {
        if !known.contains(&key.as_str()) {
            let closest = known
                .iter()
                .min_by_key(|k| crate::study::edit_distance(k, key))
                .copied()
                .unwrap_or("study");
            return Err(study.error(
                key.as_str(),
                "(table)",
                format!(
                    "a known section (did you mean [{closest}]?): {}",
                    known.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// Check every section the study has before any of them runs, so that a
/// bad late section is found before earlier ones write results: each
/// section is read into its typed form (unknown keys, wrong types and bad
/// values refused) and checked as far as that needs no computation. The
/// drivers' `[problem]` is checked first, once for all of them.
pub fn check_study(study: &Study) -> Result<()> {
    // `[scene_problem]` is read only through `[problem] name = "scene"`:
    // beside another problem nothing would check it (a NaN bound in it
    // passed silently).
    let problem = study.table.get("problem").and_then(|p| p.get("name"));
    if study.has("scene_problem") && problem.and_then(|n| n.as_str()) != Some("scene") {
        let shown = problem.map_or("(none)".to_string(), |n| n.to_string());
        return Err(study.error(
            "scene_problem",
            "(table)",
            format!(
                "no [scene_problem] unless [problem] name = \"scene\" reads it (`problem.name` \
                 is {shown}): remove the section or set the name"
            ),
        ));
    }
    let present = || study.table.keys().filter_map(|k| section(k));
    if present().any(|s| s.uses_problem) {
        explore::check_problem(study)?;
    }
    for s in present() {
        (s.check)(study)?;
    }
    Ok(())
}

/// `plyscape run`: every section the study asks for, in the order of
/// [`SECTIONS`] (unknown sections were refused by [`check_sections`]).
pub fn run_study(cfg: &RunConfig) -> Result<()> {
    check_study(&cfg.study)?;
    let mut ran = 0;
    for s in SECTIONS {
        if let (Some(run), true) = (s.run, cfg.study.has(s.key)) {
            run(cfg)?;
            ran += 1;
        }
    }
    // Every stage ran to its end: their journals served their purpose.
    explore::persist::journal::clear(&cfg.study.output_dir(&cfg.out)?)?;
    if ran == 0 {
        let working: Vec<&str> = SECTIONS
            .iter()
            .filter(|s| s.run.is_some())
            .map(|s| s.key)
            .collect();
        return Err(cfg.study.error(
            "",
            "(no work)",
            format!("at least one of the sections: {}", working.join(", ")),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_unique_and_working_sections_come_first() {
        for (k, s) in SECTIONS.iter().enumerate() {
            assert!(
                SECTIONS[..k].iter().all(|t| t.key != s.key),
                "{} twice",
                s.key
            );
        }
        let first_data = SECTIONS.iter().position(|s| s.run.is_none()).unwrap();
        assert!(SECTIONS[first_data..].iter().all(|s| s.run.is_none()));
        assert_eq!(section("map").map(|s| s.uses_problem), Some(true));
        assert!(section("study").is_none());
    }

    #[test]
    fn unknown_sections_are_named_with_the_closest_one() {
        let s = Study::parse("t.toml", "[mutlistart]\nstarts = 2\n").unwrap();
        let e = check_sections(&s).unwrap_err().to_string();
        assert!(
            e.contains("mutlistart") && e.contains("did you mean [multistart]?"),
            "{e}"
        );
        assert!(e.contains("study, modes, scene, multistart"), "{e}");
        assert_eq!(crate::study::edit_distance("kitten", "sitting"), 3);
    }
}
