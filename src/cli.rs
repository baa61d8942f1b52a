//! Command-line interface: raw arguments resolved once into a [`RunConfig`],
//! then handed to the library. `main` only maps errors to exit codes.

use crate::error::{Error, Result};
use crate::study::Study;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// The built-in default study run by `plyscape run` without a file.
pub const DEFAULT_STUDY_NAME: &str = "studies/main.toml";
/// Its text, compiled into the binary so `plyscape run` works anywhere.
pub const DEFAULT_STUDY: &str = include_str!("../studies/main.toml");

/// plyscape: explore the ply-angle design space of flexible multibody systems.
#[derive(Debug, Parser)]
#[command(name = "plyscape", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// Options every study-driven command takes.
#[derive(Debug, Clone, Args)]
pub struct Common {
    /// Root directory for results (a subdirectory per study is created).
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    /// Worker threads for drivers (default: the study's, else all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bars or summaries beyond errors.
    #[arg(long, short)]
    pub quiet: bool,
    /// Discard an earlier runs.csv instead of keeping it as
    /// `runs-<UTC time>.csv` (multistart without --resume).
    #[arg(long)]
    pub force: bool,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run whatever the study file asks for (default: the built-in main study).
    Run {
        /// Study file (TOML). Omit to run the built-in main study.
        study: Option<PathBuf>,
        #[command(flatten)]
        common: Common,
    },
    /// Modes of the study's panels; modes.csv (+ mode_derivatives.csv,
    /// mode_shapes.csv, convergence.csv when the study asks).
    Modes {
        /// Study file (TOML) with `[[panels]]` and `[modes]`.
        study: PathBuf,
        #[command(flatten)]
        common: Common,
    },
    /// Simulate the multibody scene of a study (its `[scene]` section).
    Simulate {
        /// Study file (TOML) with a `[scene]` section.
        study: PathBuf,
        #[command(flatten)]
        common: Common,
    },
    /// Local optimizer from many start points; runs.csv, optima.csv.
    Multistart {
        /// Study file (TOML) with the sections `problem` and `multistart`.
        study: PathBuf,
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        drive: DriveArgs,
    },
    /// CMA-ES with restarts; evolution.csv.
    Evolve {
        /// Study file (TOML) with a `problem` section (`evolve` optional).
        study: PathBuf,
        #[command(flatten)]
        common: Common,
    },
    /// Multistart, then CMA-ES on the same budget, then comparison.csv.
    Compare {
        /// Study file (TOML) with the sections `problem` and `multistart`.
        study: PathBuf,
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        drive: DriveArgs,
    },
    /// Grid of f and constraints over two variables; map.csv, map.svg.
    Map {
        /// Study file (TOML) with a `problem` section (`map` optional).
        study: PathBuf,
        #[command(flatten)]
        common: Common,
    },
    /// Combine the shard directories of one multistart into one set of tables.
    Merge {
        /// Shard directories (`results/STUDY/shard-I-of-N`).
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Root directory for the merged tables (written to `OUT/STUDY/`).
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// No summary output.
        #[arg(long, short)]
        quiet: bool,
    },
}

/// Flags of the multistart drivers.
#[derive(Debug, Clone, Args)]
pub struct DriveArgs {
    /// Continue from the runs already in runs.csv.
    #[arg(long)]
    pub resume: bool,
    /// Run only every n-th start, beginning at i (0-based): `--shard i/n`.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
}

impl DriveArgs {
    fn resolve(&self) -> Result<crate::explore::DriveFlags> {
        let mut f = crate::explore::DriveFlags {
            resume: self.resume,
            ..Default::default()
        };
        if let Some(s) = &self.shard {
            f.shard = crate::explore::multistart::Shard::parse(s)?;
        }
        Ok(f)
    }
}

/// A resolved run: the study and the common options.
#[derive(Debug, Clone)]
pub struct RunConfig {
    pub study: Study,
    pub out: PathBuf,
    pub threads: usize,
    pub quiet: bool,
    /// `--force`: see [`Common::force`].
    pub force: bool,
}

/// The largest thread count accepted for a machine with `cores` cores.
pub fn max_threads(cores: usize) -> usize {
    (4 * cores).max(64)
}

impl RunConfig {
    /// Resolve a study path (or the built-in default) and common options.
    pub fn resolve(study: Option<&PathBuf>, common: &Common) -> Result<RunConfig> {
        let study = match study {
            Some(p) => Study::load(p)?,
            None => Study::parse(DEFAULT_STUDY_NAME, DEFAULT_STUDY)?,
        };
        check_sections(&study)?;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let limit = max_threads(cores);
        let threads = match common.threads.or(study.meta.threads) {
            Some(0) => return Err(Error::input("--threads", 0, "a thread count >= 1")),
            Some(n) if n > limit => {
                return Err(Error::input(
                    "--threads",
                    n,
                    format!(
                        "at most {limit} threads (4 per core on this machine's {cores} cores, \
                         at least 64): evaluations are CPU-bound, more threads only share the cores"
                    ),
                ))
            }
            Some(n) => n,
            None => cores,
        };
        Ok(RunConfig {
            study,
            out: common.out.clone(),
            threads,
            quiet: common.quiet,
            force: common.force,
        })
    }
}

/// Execute a parsed command line. Every command that writes into a
/// results directory holds that directory's lock while it works
/// ([`crate::report::lock::DirLock`]).
pub fn execute(cli: Cli) -> Result<()> {
    crate::report::mark_start();
    match cli.command {
        Command::Run { study, common } => {
            let cfg = RunConfig::resolve(study.as_ref(), &common)?;
            let _lock = lock(&cfg, "run", None)?;
            run_study(&cfg)
        }
        Command::Modes { study, common } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let _lock = lock(&cfg, "modes", None)?;
            run_modes_handler(&cfg)
        }
        Command::Simulate { study, common } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let _lock = lock(&cfg, "simulate", None)?;
            run_scene(&cfg)
        }
        Command::Multistart {
            study,
            common,
            drive,
        } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let ctx = explore_context(&cfg, drive.resolve()?);
            let _lock = lock(&cfg, "multistart", Some(&ctx))?;
            crate::explore::run_multistart(&ctx).map(|_| ())
        }
        Command::Evolve { study, common } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let _lock = lock(&cfg, "evolve", None)?;
            crate::explore::run_evolve(&explore_context(&cfg, Default::default()), None).map(|_| ())
        }
        Command::Compare {
            study,
            common,
            drive,
        } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let ctx = explore_context(&cfg, drive.resolve()?);
            let _lock = lock(&cfg, "compare", Some(&ctx))?;
            crate::explore::run_compare(&ctx).map(|_| ())
        }
        Command::Map { study, common } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let _lock = lock(&cfg, "map", None)?;
            crate::explore::run_map(&explore_context(&cfg, Default::default())).map(|_| ())
        }
        Command::Merge { dirs, out, quiet } => {
            crate::explore::merge(&dirs, &out, quiet).map(|_| ())
        }
    }
}

/// The lock of the directory `command` writes into: the study's results
/// directory, or the shard's own directory for a sharded driver (shards of
/// one study run side by side).
fn lock(
    cfg: &RunConfig,
    command: &str,
    ctx: Option<&crate::explore::Context>,
) -> Result<crate::report::lock::DirLock> {
    let dir = match ctx {
        Some(c) => c.dir()?,
        None => cfg.study.output_dir(&cfg.out)?,
    };
    crate::report::lock::DirLock::acquire(&dir, command)
}

/// The exploration drivers' view of a resolved run.
fn explore_context(
    cfg: &RunConfig,
    mut flags: crate::explore::DriveFlags,
) -> crate::explore::Context<'_> {
    flags.force = cfg.force;
    crate::explore::Context {
        study: &cfg.study,
        out: &cfg.out,
        threads: cfg.threads,
        quiet: cfg.quiet,
        flags,
    }
}

/// `plyscape run` handlers of the exploration drivers. Under `[compare]`
/// the multistart and evolution run as part of the comparison (and under
/// `[scaling]` the multistart runs once per thread count).
fn run_multistart_handler(cfg: &RunConfig) -> Result<()> {
    if cfg.study.has("compare") || cfg.study.has("scaling") {
        return Ok(());
    }
    crate::explore::run_multistart(&explore_context(cfg, Default::default())).map(|_| ())
}
fn run_evolve_handler(cfg: &RunConfig) -> Result<()> {
    if cfg.study.has("compare") {
        return Ok(());
    }
    crate::explore::run_evolve(&explore_context(cfg, Default::default()), None).map(|_| ())
}
fn run_compare_handler(cfg: &RunConfig) -> Result<()> {
    crate::explore::run_compare(&explore_context(cfg, Default::default())).map(|_| ())
}
fn run_scaling_handler(cfg: &RunConfig) -> Result<()> {
    crate::explore::scaling::run_scaling(&explore_context(cfg, Default::default())).map(|_| ())
}
fn run_map_handler(cfg: &RunConfig) -> Result<()> {
    crate::explore::run_map(&explore_context(cfg, Default::default())).map(|_| ())
}

/// Sections that hold data other sections use; they do no work themselves.
/// (`[optimum_report]` is read and written by the multistart.)
const DATA_SECTIONS: &[&str] = &[
    "problem",
    "panels",
    "convergence",
    "scene_problem",
    "optimum_report",
];

/// A kind of work a study can ask for: the top-level section that asks for
/// it, and the function that does it.
type Handler = fn(&RunConfig) -> Result<()>;

/// Every section `plyscape run` knows, in the order the work is done.
fn handlers() -> Vec<(&'static str, Handler)> {
    vec![
        ("modes", run_modes_handler),
        ("scene", run_scene),
        ("multistart", run_multistart_handler),
        ("evolve", run_evolve_handler),
        ("compare", run_compare_handler),
        ("scaling", run_scaling_handler),
        ("map", run_map_handler),
        ("kernel_bench", run_kernel_bench_handler),
        ("events_bench", run_events_bench_handler),
        ("scene_convergence", run_scene_convergence_handler),
        ("eval_bench", run_eval_bench_handler),
        ("gradient_check", run_gradient_check_handler),
        ("sens_bench", run_sens_bench_handler),
        ("support_compare", run_support_compare_handler),
    ]
}

/// The `[sens_bench]` section: plain run and both sensitivity forms timed.
fn run_sens_bench_handler(cfg: &RunConfig) -> Result<()> {
    crate::sections::sens_bench::run_sens_bench_section(&cfg.study, &cfg.out, cfg.quiet).map(|_| ())
}

/// The `[scene_convergence]` section: responses vs mesh and modes, with cost.
fn run_scene_convergence_handler(cfg: &RunConfig) -> Result<()> {
    crate::sections::scene_convergence::run_scene_convergence(&cfg.study, &cfg.out, cfg.quiet)
        .map(|_| ())
}

/// The `[support_compare]` section: a flexible scene per panel support
/// and integrator, cost and answers against the first support.
fn run_support_compare_handler(cfg: &RunConfig) -> Result<()> {
    crate::sections::support_compare::run_support_compare(&cfg.study, &cfg.out, cfg.quiet)
        .map(|_| ())
}

/// The `[eval_bench]` section: cost of one design evaluation, by stage.
fn run_eval_bench_handler(cfg: &RunConfig) -> Result<()> {
    crate::sections::eval_bench::run_eval_bench_section(&cfg.study, &cfg.out, cfg.quiet).map(|_| ())
}

/// The `[gradient_check]` section: fixed- against updated-mode gradients.
fn run_gradient_check_handler(cfg: &RunConfig) -> Result<()> {
    crate::sections::gradient_check::run_gradient_check(&cfg.study, &cfg.out, cfg.quiet).map(|_| ())
}

/// The `[events_bench]` section: Eq. 32 segment changes as events or not.
fn run_events_bench_handler(cfg: &RunConfig) -> Result<()> {
    crate::sections::events_bench::run_events_bench(&cfg.study, &cfg.out, cfg.quiet).map(|_| ())
}

/// The `[kernel_bench]` section: multibody kernel cost and accuracy table.
fn run_kernel_bench_handler(cfg: &RunConfig) -> Result<()> {
    crate::sections::kernel_bench::run_kernel_bench(&cfg.study, &cfg.out, cfg.quiet).map(|_| ())
}

/// The `[modes]` section: panel modal analysis (and its manifest entry).
fn run_modes_handler(cfg: &RunConfig) -> Result<()> {
    let t0 = std::time::Instant::now();
    crate::sections::modes::run_modes(&cfg.study, &cfg.out, cfg.quiet)?;
    let dir = cfg.study.output_dir(&cfg.out)?;
    let mut entry = serde_json::Map::new();
    entry.insert("wall_seconds".into(), t0.elapsed().as_secs_f64().into());
    crate::report::record_command(&dir, &cfg.study, 1, "modes", entry, Default::default())
}

/// The `[scene]` handler: simulate the multibody scene and write
/// `history.csv`, `stats.csv` (and an SVG) into the study's output folder;
/// the wall-clock times (whole command, integration, output) go to the
/// command's entry in `manifest.json`.
pub fn run_scene(cfg: &RunConfig) -> Result<()> {
    use crate::simulate;
    let t0 = std::time::Instant::now();
    let scene = crate::scene::load_scene(&cfg.study)?;
    let (_, sim) = simulate::simulate(&scene).map_err(cfg.study.locate("scene"))?;
    let dir = cfg.study.output_dir(&cfg.out)?;
    let files = simulate::write_results(&scene, &sim, &dir)?;
    let mut entry = serde_json::Map::new();
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
    crate::report::record_command(&dir, &cfg.study, 1, "simulate", entry, Default::default())?;
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

/// `plyscape run`: do every kind of work the study has a section for.
/// Refuse a study with a top-level section no part of the tool reads (a
/// typo must not silently do nothing), naming the known sections and the
/// closest one. Every subcommand checks this before any work starts.
pub fn check_sections(study: &Study) -> Result<()> {
    let mut known: Vec<&str> = vec!["study"];
    known.extend(handlers().iter().map(|(k, _)| *k));
    known.extend(DATA_SECTIONS);
    for key in study.table.keys() {
        if !known.contains(&key.as_str()) {
            let closest = known
                .iter()
                .min_by_key(|k| edit_distance(k, key))
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
/// values refused) and checked as far as that needs no computation.
pub fn check_study(study: &Study) -> Result<()> {
    use crate::sections;
    const EXPLORE: &[&str] = &[
        "multistart",
        "evolve",
        "compare",
        "map",
        "scaling",
        "optimum_report",
    ];
    if study.table.keys().any(|k| EXPLORE.contains(&k.as_str())) {
        // The drivers' problem, once for all of them.
        crate::explore::check(study, "problem")?;
    }
    for key in study.table.keys() {
        match key.as_str() {
            "modes" => sections::modes::check(study).map(|_| ())?,
            "scene" => crate::scene::ScenePlan::new(study).map(|_| ())?,
            "kernel_bench" => sections::kernel_bench::check(study).map(|_| ())?,
            "events_bench" => sections::events_bench::check(study).map(|_| ())?,
            "eval_bench" => sections::eval_bench::check(study).map(|_| ())?,
            "gradient_check" => sections::gradient_check::check(study).map(|_| ())?,
            "sens_bench" => sections::sens_bench::check(study).map(|_| ())?,
            "support_compare" => sections::support_compare::check(study).map(|_| ())?,
            "scene_convergence" => sections::scene_convergence::check(study).map(|_| ())?,
            k if EXPLORE.contains(&k) => crate::explore::check(study, k)?,
            _ => {}
        }
    }
    Ok(())
}

/// Levenshtein distance of two names (insertions, deletions, substitutions).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// Run every section the study asks for, in the order of `handlers`
/// (unknown sections were refused by [`RunConfig::resolve`]).
pub fn run_study(cfg: &RunConfig) -> Result<()> {
    check_study(&cfg.study)?;
    let handlers = handlers();
    let mut ran = 0;
    for (key, handler) in &handlers {
        if cfg.study.has(key) {
            handler(cfg)?;
            ran += 1;
        }
    }
    if ran == 0 {
        return Err(cfg.study.error(
            "",
            "(no work)",
            format!(
                "at least one of the sections: {}",
                handlers
                    .iter()
                    .map(|(k, _)| *k)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    Ok(())
}
