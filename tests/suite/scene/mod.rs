//! Tests of `plyscape::scene`: study text read into a scene, the input
//! errors it names (file, key, value, expectation) and the drive laws.
mod drives;
mod input;
