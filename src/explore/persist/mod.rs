//! What the commands keep on disk and what `--resume` trusts.
//!
//! - [`tables`]: the rows of `runs.csv` (one complete line appended per
//!   finished run, a truncated last line cut off on reading), and the
//!   final tables written whole and renamed; numbers in shortest
//!   round-trip form, so a table read back gives the same `f64` bits.
//! - [`manifest`]: every driver's entry in `manifest.json`, typed.
//! - [`fingerprint`]: the hash of the parts of a study that change an
//!   evaluation's result (64-bit FNV-1a of the parsed TOML values), and the
//!   spot check of rows read back.
//!
//! - [`journal`]: every evaluation of a stage without tables of its own
//!   (CMA-ES, `[discrete]`, `[front]`), appended as it finishes, served
//!   back on `run --resume` so that the stage retraces its path without
//!   simulating.
//!
//! No section and no command of its own: every command writes through it.

pub mod fingerprint;
pub mod journal;
pub mod manifest;
pub mod tables;
