//! Tests of `plyscape::optimize`: CMA-ES and MMFD.
mod cmaes;
mod mmfd;
