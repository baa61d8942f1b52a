//! Tests of `plyscape::modal`: sparse eigen-solutions and their derivatives.
mod derivatives;
mod eigen;
mod thickness;
