//! Tests of `plyscape::panels`: modal bases and panel modes.
mod basis;
mod geometric;
mod modes;
mod thickness;
