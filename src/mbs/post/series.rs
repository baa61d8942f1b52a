//! The types of a response read over a run (`crate::simulate`): one
//! located point of it, and why a crossing has no time.

/// One located point of a response: time (s), value, gradient per
/// parameter.
pub type Sample = (f64, f64, Vec<f64>);

/// Why a series has no crossing time.
#[derive(Debug, Clone, PartialEq)]
pub enum NoCrossing {
    /// The series never crosses the level in the asked direction; its
    /// range is `(min, max)`.
    Never(f64, f64),
    /// It crosses at `t` (s) with zero slope: the crossing time has no
    /// derivative there.
    Flat(f64),
}
