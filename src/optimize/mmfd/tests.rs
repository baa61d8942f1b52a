//! The MMFD polish against the Kuhn–Tucker certificate it is tuned for
//! ([`MmfdOptions::polish_for`]).

use super::{minimize, MmfdOptions};
use crate::optimize::kkt::{certify_at, EndClass, KktTolerances};
use crate::optimize::{testproblems, NoObserver};

/// HS 100 from its standard start with DOT's settings, then the polish
/// from that end: the polished end is certified and f is within 1e-6
/// relative of f* = 680.6300573 (Hock & Schittkowski 1981, problem 100).
#[test]
fn polish_after_dot_certifies_hs100() {
    let p = testproblems::hs100();
    let mut obs = NoObserver;
    let end = minimize(&p, &p.x0, &MmfdOptions::dot(), &mut obs).unwrap();
    let t = KktTolerances::default();
    let polished = minimize(&p, &end.x, &MmfdOptions::polish_for(&t), &mut obs).unwrap();
    let (_, c) = certify_at(&p, &polished.x, &t).unwrap();
    assert_eq!(c.class, EndClass::Converged, "{c:?} {polished:?}");
    assert!(
        (polished.f - p.f_opt).abs() <= 1e-6 * p.f_opt,
        "dot end f = {}, polished f = {} ({:?})",
        end.f,
        polished.f,
        polished.termination
    );
}
