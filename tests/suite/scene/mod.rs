//! Tests of `plyscape::scene`: study text read into a scene, the input
//! errors it names (file, key, value, expectation), the drive laws and
//! the panel bases shared by bodies of the same content, and rigid bodies
//! locked to the ground built fixed.
mod drives;
mod ground;
mod input;
mod shared_bases;
