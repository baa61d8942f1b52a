//! Quality indicators of a front (minimization): hypervolume and IGD.
//!
//! - **Hypervolume** `HV(A; r)`: the Lebesgue measure of the region
//!   dominated by the set `A` and bounded by the reference point `r`,
//!   `⋃_{a ∈ A} [a_1, r_1] × … × [a_m, r_m]` (Zitzler & Thiele 1998). Points
//!   that do not dominate `r` strictly in every objective add nothing.
//!   Exact for two objectives (sorted sweep, `O(n log n)`) and three
//!   (slices between consecutive `f3` values, each the 2-D hypervolume of
//!   the points below it, `O(n² log n)`: fine for a few hundred points).
//! - **IGD** (inverted generational distance) of `A` against a reference
//!   front `R`: `IGD = (1/|R|) Σ_{r ∈ R} min_{a ∈ A} ‖r − a‖₂`, in the
//!   objectives' own units (Coello & Reyes Sierra 2004): small when `A` is
//!   close to every part of `R`.

use crate::error::{Error, Result};

/// 2-D hypervolume of `points` with reference `r`.
pub fn hypervolume_2d(points: &[Vec<f64>], r: [f64; 2]) -> f64 {
    let mut p: Vec<(f64, f64)> = points
        .iter()
        .filter(|a| a[0] < r[0] && a[1] < r[1])
        .map(|a| (a[0], a[1]))
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut hv = 0.0;
    let mut level = r[1];
    for (x, y) in p {
        if y < level {
            hv += (r[0] - x) * (level - y);
            level = y;
        }
    }
    hv
}

/// 3-D hypervolume of `points` with reference `r` (slicing along `f3`).
pub fn hypervolume_3d(points: &[Vec<f64>], r: [f64; 3]) -> f64 {
    let mut p: Vec<&Vec<f64>> = points
        .iter()
        .filter(|a| a[0] < r[0] && a[1] < r[1] && a[2] < r[2])
        .collect();
    p.sort_by(|a, b| a[2].total_cmp(&b[2]));
    let mut hv = 0.0;
    for k in 0..p.len() {
        let top = if k + 1 < p.len() { p[k + 1][2] } else { r[2] };
        let depth = top - p[k][2];
        if depth > 0.0 {
            let slice: Vec<Vec<f64>> = p[..=k].iter().map(|a| vec![a[0], a[1]]).collect();
            hv += depth * hypervolume_2d(&slice, [r[0], r[1]]);
        }
    }
    hv
}

/// Hypervolume for 2 or 3 objectives (`r.len()` of them).
pub fn hypervolume(points: &[Vec<f64>], r: &[f64]) -> Result<f64> {
    if points.iter().any(|p| p.len() != r.len()) {
        return Err(Error::numerical(
            "optimize::indicators",
            format!(
                "points with another dimension than the reference point's {}",
                r.len()
            ),
        ));
    }
    match r.len() {
        2 => Ok(hypervolume_2d(points, [r[0], r[1]])),
        3 => Ok(hypervolume_3d(points, [r[0], r[1], r[2]])),
        m => Err(Error::numerical(
            "optimize::indicators",
            format!("hypervolume of {m} objectives (2 or 3 are computed)"),
        )),
    }
}

/// IGD of `points` against `reference` (`None` when either is empty).
pub fn igd(points: &[Vec<f64>], reference: &[Vec<f64>]) -> Option<f64> {
    if points.is_empty() || reference.is_empty() {
        return None;
    }
    let dist = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y) * (x - y))
            .sum::<f64>()
            .sqrt()
    };
    let total: f64 = reference
        .iter()
        .map(|r| {
            points
                .iter()
                .map(|p| dist(p, r))
                .fold(f64::INFINITY, f64::min)
        })
        .sum();
    Some(total / reference.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hypervolume_2d_by_hand() {
        // Reference (4, 4); points (1, 3), (2, 2), (3, 1): a staircase of
        // three 1-wide columns of heights 1, 2, 3 (from x = 1) … by hand:
        // [1,2]×[3,4] + [2,3]×[2,4] + [3,4]×[1,4] = 1 + 2 + 3 = 6.
        let p = vec![vec![1.0, 3.0], vec![2.0, 2.0], vec![3.0, 1.0]];
        assert_eq!(hypervolume_2d(&p, [4.0, 4.0]), 6.0);
        // A dominated point, a duplicate and a point outside the reference
        // box change nothing.
        let mut q = p.clone();
        q.extend([vec![3.0, 3.0], vec![2.0, 2.0], vec![5.0, 0.0]]);
        assert_eq!(hypervolume_2d(&q, [4.0, 4.0]), 6.0);
        assert_eq!(hypervolume_2d(&[], [1.0, 1.0]), 0.0);
    }

    #[test]
    fn hypervolume_3d_by_hand() {
        // One point: a box. (0,0,0) with r = (1,2,3): 6.
        assert_eq!(hypervolume_3d(&[vec![0.0, 0.0, 0.0]], [1.0, 2.0, 3.0]), 6.0);
        // Two points, r = (2,2,2): a = (0,1,1) box 2·1·1 = 2, b = (1,0,0)
        // box 1·2·2 = 4, overlap [1,2]×[1,2]×[1,2] = 1: union 5.
        let p = vec![vec![0.0, 1.0, 1.0], vec![1.0, 0.0, 0.0]];
        assert_eq!(hypervolume_3d(&p, [2.0, 2.0, 2.0]), 5.0);
        // Three unit-cube corners (1,0,0), (0,1,0), (0,0,1) with r = (1,1,1)
        // ... each box has a zero side: 0. With r = (2,2,2): inclusion–
        // exclusion, each box 4, each pair overlap 1·1·2 = 2 (e.g. a∩b =
        // [1,2]×[1,2]×[0,2]), all three [1,2]³ = 1: 12 − 6 + 1 = 7.
        let c = vec![
            vec![1.0, 0.0, 0.0],
            vec![0.0, 1.0, 0.0],
            vec![0.0, 0.0, 1.0],
        ];
        assert_eq!(hypervolume_3d(&c, [1.0, 1.0, 1.0]), 0.0);
        assert_eq!(hypervolume_3d(&c, [2.0, 2.0, 2.0]), 7.0);
        assert!(hypervolume(&c, &[2.0, 2.0]).is_err());
        assert!(hypervolume(&[vec![0.0; 4]], &[1.0; 4]).is_err());
    }

    #[test]
    fn igd_by_hand() {
        // Reference (0,0), (1,0); set {(0,1)}: distances 1 and √2.
        let r = vec![vec![0.0, 0.0], vec![1.0, 0.0]];
        let v = igd(&[vec![0.0, 1.0]], &r).unwrap();
        assert!((v - 0.5 * (1.0 + 2f64.sqrt())).abs() < 1e-15);
        // The reference itself: 0.
        assert_eq!(igd(&r, &r), Some(0.0));
        assert_eq!(igd(&[], &r), None);
    }
}
