//! Study sections: the panel modes table (`plyscape modes`: `[modes]`,
//! `[convergence]`), the kernel benchmark
//! (`[kernel_bench]`), the Eq. 32 events benchmark (`[events_bench]`) and
//! the flexible-scene convergence grid (`[scene_convergence]`), the
//! cost of one design evaluation (`[eval_bench]`), the cost of a scene's
//! sensitivities in both forms (`[sens_bench]`), the fixed- against
//! updated-mode gradients (`[gradient_check]`) and the panel
//! reference-condition comparison (`[support_compare]`). Each
//! reads its section, runs scenes through [`crate::scene`] and
//! [`crate::simulate`], and writes its table through [`crate::report`].
//!
//! [`registry`] holds the one list of every study section `plyscape run`
//! knows (these, the exploration drivers' of [`crate::explore`], `[scene]`
//! and the data sections), with the run configuration they get.
//!
//! # Where to add things
//!
//! A new study section: a file here with its serde spec
//! (`#[serde(deny_unknown_fields)]`, kinds as serde enums), a `check`
//! reading it without computing, a `run_*` entry point writing its table
//! through [`crate::report`]; then ONE entry in [`registry::SECTIONS`]
//! (key, check, run, whether it drives `[problem]`), placed where its
//! work must happen in the order of `plyscape run`. The unknown-section
//! check, the check before any work and the "no work" message follow from
//! that list. A section that only holds data for others is a `data(key)`
//! entry. A section that is also its own subcommand gets a variant of
//! `crate::cli::Command` mapped in `crate::cli::execute`.

pub mod eval_bench;
pub mod events_bench;
pub mod gradient_check;
pub mod kernel_bench;
pub mod modes;
pub mod noise;
pub mod registry;
pub mod scene_convergence;
pub mod sens_bench;
pub mod stats;
pub mod support_compare;
