//! Helpers and fixtures shared by the test modules.
pub mod explore;
pub mod modal;
pub mod sar;
