//! Tests of `plyscape::sections`: the shipped studies through
//! `plyscape run`, the `[kernel_bench]` and `[scene_convergence]` drivers.
mod noise;
mod scene_convergence;
mod studies;
