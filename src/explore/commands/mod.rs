//! The driver commands, one file each: what `plyscape multistart`,
//! `evolve`, `compare` and `map` (and the same sections under
//! `plyscape run`) do around the algorithms of [`crate::explore`]'s
//! [`multistart`](crate::explore::multistart),
//! [`evolve`](crate::explore::evolve) and [`map`](crate::explore::map):
//! read the plan, run, print, write the tables, the plot and the manifest
//! entry.

pub mod compare;
pub mod convergence;
pub mod discrete;
pub mod evolve;
pub mod front;
pub mod front_outputs;
pub mod map;
pub mod multistart;
