//! Helpers shared by the tests on the SAR study files: exact text
//! replacement and the coarse version of a SAR scene.
#![allow(dead_code)]

/// Replace every occurrence of `from` in `text`, requiring `count` of them
/// (so that a change of the study file cannot silently void a test).
pub fn replace(text: &str, from: &str, to: &str, count: usize) -> String {
    assert_eq!(
        text.matches(from).count(),
        count,
        "expected {count} × {from:?} in the study"
    );
    text.replace(from, to)
}

/// A SAR study text made coarse for tests: both panels on `divisions`
/// mesh divisions with `modes` modes, 0–0.5 s sampled every 5 ms, at
/// rtol 1e-10 and atol 1e-12 (the shipped studies: 32 divisions, 14
/// modes, 0–3 s every 10 ms, rtol 1e-6, atol 1e-8).
pub fn coarse_sar(text: &str, divisions: usize, modes: usize) -> String {
    let mut t = replace(
        text,
        "divisions = 32",
        &format!("divisions = {divisions}"),
        2,
    );
    t = replace(&t, "modes = 14", &format!("modes = {modes}"), 2);
    t = replace(&t, "t_end = 3.0", "t_end = 0.5", 1);
    t = replace(&t, "dt_out = 0.01", "dt_out = 0.005", 1);
    t = replace(&t, "rtol = 1e-6", "rtol = 1e-10", 1);
    replace(&t, "atol = 1e-8", "atol = 1e-12", 1)
}
