//! The input error a bad study must give, in its parts: every test of a
//! bad input reads its file, dotted key, value, expectation or whole
//! message through [`error_of`].
use plyscape::study::Study;
use plyscape::Error;
use std::fmt::Debug;

/// The parts of an [`Error::Input`], and its message as the user reads it.
#[derive(Debug)]
pub struct InputError {
    /// The study file the error names.
    pub file: String,
    /// The dotted key of the bad value.
    pub key: String,
    /// The bad value as written.
    pub value: String,
    /// What was expected instead.
    pub expected: String,
    /// The whole message (`Display`).
    pub message: String,
}

/// The input error of the study `text`, read as file `file` and given to
/// `run`; panics when it parses and runs, or fails otherwise.
pub fn error_of<T: Debug>(
    file: &str,
    text: &str,
    run: impl FnOnce(&Study) -> plyscape::Result<T>,
) -> InputError {
    let e = match Study::parse(file, text).and_then(|study| run(&study)) {
        Err(e) => e,
        Ok(v) => panic!("expected an input error, got {v:?}"),
    };
    let message = e.to_string();
    match e {
        Error::Input {
            file,
            key,
            value,
            expected,
        } => InputError {
            file,
            key,
            value,
            expected,
            message,
        },
        other => panic!("expected an input error, got {other:?}"),
    }
}
