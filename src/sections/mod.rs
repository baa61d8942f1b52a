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
//! A new study section goes here: a file with its serde spec, a `run_*`
//! entry point called from [`crate::cli`], and its writer.

pub mod eval_bench;
pub mod events_bench;
pub mod gradient_check;
pub mod kernel_bench;
pub mod modes;
pub mod scene_convergence;
pub mod sens_bench;
pub mod stats;
pub mod support_compare;
