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
    /// Simulate the multibody scene of a study (its `[scene]` section).
    Simulate {
        /// Study file (TOML) with a `[scene]` section.
        study: PathBuf,
        #[command(flatten)]
        common: Common,
    },
}

/// A resolved run: the study and the common options.
#[derive(Debug, Clone)]
pub struct RunConfig {
    pub study: Study,
    pub out: PathBuf,
    pub threads: usize,
    pub quiet: bool,
}

impl RunConfig {
    /// Resolve a study path (or the built-in default) and common options.
    pub fn resolve(study: Option<&PathBuf>, common: &Common) -> Result<RunConfig> {
        let study = match study {
            Some(p) => Study::load(p)?,
            None => Study::parse(DEFAULT_STUDY_NAME, DEFAULT_STUDY)?,
        };
        let threads = match common.threads.or(study.meta.threads) {
            Some(0) => return Err(Error::input("--threads", 0, "a thread count >= 1")),
            Some(n) => n,
            None => std::thread::available_parallelism().map_or(1, |n| n.get()),
        };
        Ok(RunConfig {
            study,
            out: common.out.clone(),
            threads,
            quiet: common.quiet,
        })
    }
}

/// Execute a parsed command line.
pub fn execute(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run { study, common } => {
            let cfg = RunConfig::resolve(study.as_ref(), &common)?;
            run_study(&cfg)
        }
        Command::Simulate { study, common } => {
            let cfg = RunConfig::resolve(Some(&study), &common)?;
            run_scene(&cfg)
        }
    }
}

/// A kind of work a study can ask for: the top-level section that asks for
/// it, and the function that does it.
type Handler = fn(&RunConfig) -> Result<()>;

/// Every section `plyscape run` knows, in the order the work is done.
fn handlers() -> Vec<(&'static str, Handler)> {
    vec![("scene", run_scene)]
}

/// The `[scene]` handler: simulate the multibody scene and write
/// `history.csv`, `stats.csv` (and an SVG) into the study's output folder.
pub fn run_scene(cfg: &RunConfig) -> Result<()> {
    use crate::mbs::simulate;
    let scene = simulate::load_scene(&cfg.study)?;
    let (_, sim) = simulate::simulate(&scene).map_err(cfg.study.locate("scene"))?;
    let dir = cfg.study.output_dir(&cfg.out)?;
    let files = simulate::write_results(&scene, &sim, &dir)?;
    if !cfg.quiet {
        println!("{}", simulate::summary(&sim));
        for f in files {
            println!("wrote {}", f.display());
        }
    }
    Ok(())
}

/// `plyscape run`: do every kind of work the study has a section for.
/// Unknown sections are an error (a typo must not silently do nothing).
pub fn run_study(cfg: &RunConfig) -> Result<()> {
    let handlers = handlers();
    let mut known: Vec<&str> = vec!["study"];
    known.extend(handlers.iter().map(|(k, _)| *k));
    for key in cfg.study.table.keys() {
        if !known.contains(&key.as_str()) {
            return Err(cfg.study.error(
                key.as_str(),
                "(table)",
                format!("one of the known sections: {}", known.join(", ")),
            ));
        }
    }
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
            format!("at least one of the sections: {}", known[1..].join(", ")),
        ));
    }
    Ok(())
}
