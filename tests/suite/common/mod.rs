//! Helpers and fixtures shared by the test modules: temporary directories
//! (`tempfile`), columns of tables by name ([`tables`]), scenes from the
//! shipped studies or from text ([`scenes`]), the parts of an input error
//! ([`errors`]), and the helpers of the exploration, modal and SAR tests.
pub mod errors;
pub mod explore;
pub mod modal;
pub mod sar;
pub mod scenes;
pub mod tables;

/// A fresh temporary directory for one test, removed with everything in
/// it when the returned guard is dropped (`tag` goes into its name, so a
/// directory kept by a crash tells its test).
pub fn temp_dir(tag: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("plyscape-{tag}-"))
        .tempdir()
        .unwrap()
}
