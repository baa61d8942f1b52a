//! Tests of `plyscape::explore`: optimization drivers, multistart, shards, reports.
mod certified;
mod compare;
mod front;
mod kill;
mod multistart;
mod optimum_report;
mod resume;
mod scene;
mod scene_bounds;
mod studies;
