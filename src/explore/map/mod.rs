//! The design-space map: `f` and the constraints on a regular grid over
//! two design variables.
//!
//! - Section: `[map]` ([`section::MapSection`]: points per axis, the
//!   variable pairs, the cells `--resume` checks again).
//! - Algorithm: [`grid`]: with two variables the whole box, with more a
//!   2-D slice per pair through a base design; cells evaluated in parallel
//!   and written in grid order, a resumed map evaluating only the missing
//!   cells.
//! - Command: `plyscape map` ([`command::run_map`]: `map.csv` and
//!   `map.svg`, or `map_<i>_<j>.csv` and `.svg` per pair, with the local
//!   optima and the evolutionary best marked).

pub mod command;
pub mod grid;
pub mod section;
