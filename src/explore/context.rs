//! What a driver command gets from the command line ([`Context`],
//! [`DriveFlags`], [`Shard`]), the directory it writes into, its manifest
//! entry and its worker pool ([`thread_pool`]).

use crate::error::{Error, Result};
use crate::explore::persist::fingerprint::Fingerprint;
use crate::explore::persist::journal::Journal;
use crate::report::manifest::ShardRecord;
use crate::study::Study;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Run every `n`-th start beginning at `index` (`--shard index/count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// 0-based shard index, `< count`.
    pub index: usize,
    /// Number of shards, `>= 1`.
    pub count: usize,
}

impl Shard {
    /// Parse `i/n` with `0 <= i < n`.
    pub fn parse(s: &str) -> Result<Shard> {
        let bad = || Error::input("--shard", s, "i/n with integers 0 <= i < n");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// Does this shard run start `k`?
    pub fn owns(&self, k: usize) -> bool {
        k % self.count == self.index
    }
}

/// Flags of the driver commands beyond the common ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DriveFlags {
    /// Continue from an existing `runs.csv`.
    pub resume: bool,
    /// Which starts to run.
    pub shard: Shard,
    /// Without `resume`: discard an earlier `runs.csv` instead of keeping
    /// it under a timestamped name.
    pub force: bool,
}

impl Default for DriveFlags {
    fn default() -> Self {
        DriveFlags {
            resume: false,
            shard: Shard { index: 0, count: 1 },
            force: false,
        }
    }
}

/// What a driver command needs from the command line.
#[derive(Debug, Clone)]
pub struct Context<'a> {
    /// The study.
    pub study: &'a Study,
    /// Results root (`results/`).
    pub out: &'a Path,
    /// Worker threads.
    pub threads: usize,
    /// No progress bars or summaries.
    pub quiet: bool,
    /// Resume and shard.
    pub flags: DriveFlags,
}

impl Context<'_> {
    /// `out/<study>/`, or `out/<study>/shard-<i>-of-<n>/` for a shard.
    pub fn dir(&self) -> Result<PathBuf> {
        let base = self.study.output_dir(self.out)?;
        let s = self.flags.shard;
        if s.count == 1 {
            return Ok(base);
        }
        let dir = base.join(format!("shard-{}-of-{}", s.index, s.count));
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        Ok(dir)
    }

    /// The evaluation journal of `stage` in [`Context::dir`], continued
    /// under `--resume` ([`crate::explore::persist::journal`]); `scope`
    /// names what, beyond the study's evaluations, the stage's values
    /// depend on.
    pub fn journal(&self, stage: &str, scope: &str) -> Result<Journal> {
        Journal::open(self.study, &self.dir()?, stage, scope, self.flags.resume)
    }

    /// Update `manifest.json` ([`crate::report::record_command`]) with the
    /// shard, the threads, the resume flag, the study's fingerprint
    /// ([`Fingerprint::of_study`]) and the command's own `detail`
    /// ([`crate::explore::persist::manifest`]).
    pub fn manifest<D: Serialize>(&self, dir: &Path, command: &str, detail: D) -> Result<()> {
        let entry = crate::explore::persist::manifest::DriverEntry {
            threads: self.threads,
            resume: self.flags.resume,
            fingerprint: Some(Fingerprint::of_study(self.study)),
            detail,
        };
        let shard = ShardRecord {
            index: self.flags.shard.index,
            count: self.flags.shard.count,
        };
        crate::report::record_command(
            dir,
            self.study,
            self.threads,
            command,
            crate::report::manifest::entry_map(&entry)?,
            Some(shard),
        )
    }
}

/// A pool of `threads` workers for a driver's parallel work; a count the
/// system refuses is an input error on `threads`.
pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::input("threads", threads, format!("a usable count ({e})")))
}
