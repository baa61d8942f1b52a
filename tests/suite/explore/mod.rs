//! Tests of `plyscape::explore`: optimization drivers, multistart, shards, reports.
mod certified;
mod compare;
mod critical_points;
mod design_vars;
mod discrete;
mod front;
mod front_pieces;
mod kill;
mod multistart;
mod optimum_report;
mod resume;
mod robustness;
mod scene;
mod scene_bounds;
mod scene_front;
mod shards;
mod studies;
