//! plyscape's integration tests, in one binary: one module per module of
//! `src/` (`mbs` tests `plyscape::mbs`, and so on) and `common` for the
//! helpers and fixtures they share.
mod common;
mod docs_reference;
mod docs_validation;
mod explore;
mod extension_points;
mod fe;
mod golden;
mod integrate;
mod laminate;
mod mbs;
mod modal;
mod optimize;
mod panels;
mod repo_self_contained;
mod scene;
mod sections;
mod simulate;
