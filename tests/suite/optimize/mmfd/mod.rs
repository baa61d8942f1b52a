//! MMFD on problems with known optima ([`optima`]), as a solver behind
//! argmin, an observer and its errors ([`interface`]), and its line search,
//! restoration and polish ([`steps`]). Optima and their sources are
//! documented on each problem in `plyscape::optimize::testproblems`.
//!
//! Call counts are snapshots of the current implementation (like diffsol's
//! solver statistics): a change that makes MMFD slower fails here and must
//! update the numbers knowingly.
mod interface;
mod optima;
mod steps;
