//! Command-line interface: the clap types, raw arguments resolved once into
//! a [`RunConfig`], and [`execute`] mapping each subcommand to the library.
//! `main` only maps errors to exit codes. What `plyscape run` does with a
//! study's sections is [`crate::sections::registry`].

use crate::error::{Error, Result};
use crate::study::Study;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

pub use crate::sections::registry::{
    check_sections, check_study, max_threads, run_scene, run_study, RunConfig,
};

/// The built-in default study run by `plyscape run` without a file.
pub const DEFAULT_STUDY_NAME: &str = "studies/main.toml";
/// Its text, compiled into the binary so `plyscape run` works anywhere.
pub const DEFAULT_STUDY: &str = include_str!("../studies/main.toml");

/// plyscape: explore the ply-angle design space of flexible multibody systems.
#[derive(Debug, Parser)]
#[command(name = "plyscape", version, about, long_about = None)]
pub struct Cli {
    /// The subcommand to run.
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
        /// Output, thread and overwrite options.
        #[command(flatten)]
        common: Common,
        /// Continue a killed run: the multistart (also `[compare]`'s) and
        /// the map from their tables, CMA-ES, `[discrete]`, `[front]` and
        /// the violation checks from their evaluation journals.
        #[arg(long)]
        resume: bool,
    },
    /// Modes of the study's panels; modes.csv (+ mode_derivatives.csv,
    /// mode_shapes.csv, convergence.csv when the study asks).
    Modes {
        /// Study file (TOML) with `[[panels]]` and `[modes]`.
        study: PathBuf,
        /// Output, thread and overwrite options.
        #[command(flatten)]
        common: Common,
    },
    /// Simulate the multibody scene of a study (its `[scene]` section).
    Simulate {
        /// Study file (TOML) with a `[scene]` section.
        study: PathBuf,
        /// Output, thread and overwrite options.
        #[command(flatten)]
        common: Common,
    },
    /// Local optimizer from many start points; runs.csv, optima.csv.
    Multistart {
        /// Study file (TOML) with the sections `problem` and `multistart`.
        study: PathBuf,
        /// Output, thread and overwrite options.
        #[command(flatten)]
        common: Common,
        /// Resume and shard flags of the multistart driver.
        #[command(flatten)]
        drive: DriveArgs,
    },
    /// CMA-ES with restarts; evolution.csv.
    Evolve {
        /// Study file (TOML) with a `problem` section (`evolve` optional).
        study: PathBuf,
        /// Output, thread and overwrite options.
        #[command(flatten)]
        common: Common,
    },
    /// Multistart, then CMA-ES on the same budget, then comparison.csv.
    Compare {
        /// Study file (TOML) with the sections `problem` and `multistart`.
        study: PathBuf,
        /// Output, thread and overwrite options.
        #[command(flatten)]
        common: Common,
        /// Resume and shard flags of the multistart driver.
        #[command(flatten)]
        drive: DriveArgs,
    },
    /// Grid of f and constraints over two variables; map.csv, map.svg.
    Map {
        /// Study file (TOML) with a `problem` section (`map` optional).
        study: PathBuf,
        /// Output, thread and overwrite options.
        #[command(flatten)]
        common: Common,
        /// Continue from the cells already in the map's tables.
        #[arg(long)]
        resume: bool,
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
            resume: false,
        })
    }
}

/// Execute a parsed command line. Every command that writes into a
/// results directory holds that directory's lock while it works
/// ([`crate::report::lock::DirLock`]).
pub fn execute(cli: Cli) -> Result<()> {
    crate::report::mark_start();
    match cli.command {
        Command::Run {
            study,
            common,
            resume,
        } => {
            let cfg = RunConfig {
                resume,
                ..RunConfig::resolve(study.as_ref(), &common)?
            };
            let _lock = lock(&cfg, "run", None)?;
            run_study(&cfg)
        }
        Command::Modes { study, common } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let _lock = lock(&cfg, "modes", None)?;
            crate::sections::registry::run_modes(&cfg)
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
            let ctx = cfg.explore(drive.resolve()?);
            let _lock = lock(&cfg, "multistart", Some(&ctx))?;
            crate::explore::run_multistart(&ctx)?;
            crate::explore::persist::journal::clear(&ctx.dir()?)
        }
        Command::Evolve { study, common } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let _lock = lock(&cfg, "evolve", None)?;
            crate::explore::run_evolve(&cfg.explore(Default::default()), None)?;
            crate::explore::persist::journal::clear(&cfg.study.output_dir(&cfg.out)?)
        }
        Command::Compare {
            study,
            common,
            drive,
        } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let ctx = cfg.explore(drive.resolve()?);
            let _lock = lock(&cfg, "compare", Some(&ctx))?;
            crate::explore::run_compare(&ctx)?;
            crate::explore::persist::journal::clear(&ctx.dir()?)
        }
        Command::Map {
            study,
            common,
            resume,
        } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            let _lock = lock(&cfg, "map", None)?;
            let flags = crate::explore::DriveFlags {
                resume,
                ..Default::default()
            };
            crate::explore::run_map(&cfg.explore(flags)).map(|_| ())
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
