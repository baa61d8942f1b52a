//! Exploration drivers: multistart, evolutionary comparison, design-space
//! maps, resumable and shardable tables.
pub mod cluster;
pub mod multistart;
pub mod problems;
pub mod sampling;
pub mod tables;
