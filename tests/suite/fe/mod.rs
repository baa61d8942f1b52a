//! Tests of `plyscape::fe`: the shell element, meshes, panel models and specs.
mod element;
mod modes;
mod plate;
mod spec;
mod thickness;
