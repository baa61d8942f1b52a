//! Points over a design box: Latin hypercube, scrambled Sobol and uniform
//! random, in the box of a list of [`Variable`]s (periodic variables on
//! `[lower, lower + period)`), every random choice from the caller's
//! `ChaCha8Rng`.
//!
//! - **Latin hypercube** (McKay, Beckman & Conover 1979): each coordinate's
//!   range is cut into `n` equal strata, each stratum holds exactly one point
//!   (an independent random permutation per coordinate, uniform within the
//!   stratum).
//! - **Scrambled Sobol**: the Sobol sequence with Joe & Kuo's direction
//!   numbers (`new-joe-kuo-6.21201`, Joe & Kuo, SIAM J. Sci. Comput. 30,
//!   2635–2654, 2008), randomised by Matoušek's linear matrix scrambling plus
//!   a digital shift (Matoušek, J. Complexity 14, 527–556, 1998). Each point
//!   is uniform on the box and the (t, m, s)-net structure is kept: any
//!   `2^m` consecutive points from index 0 put one point in every
//!   elementary interval of the first two coordinates. Up to
//!   [`SOBOL_MAX_DIM`] variables.
//! - **Uniform**: independent uniform coordinates.

use crate::optimize::Variable;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;

/// Samplers, by the names study files use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampler {
    /// Latin hypercube.
    #[default]
    Lhs,
    /// Scrambled Sobol.
    Sobol,
    /// Uniform random.
    Uniform,
}
/// `n` points of `sampler` over the box of `vars`. `offset` is the index of
/// the first Sobol point (later batches continue the sequence).
pub fn sample(
    sampler: Sampler,
    vars: &[Variable],
    n: usize,
    rng: &mut ChaCha8Rng,
    offset: usize,
) -> Vec<Vec<f64>> {
    let d = vars.len();
    let unit: Vec<Vec<f64>> = match sampler {
        Sampler::Uniform => (0..n)
            .map(|_| (0..d).map(|_| rng.random::<f64>()).collect())
            .collect(),
        Sampler::Lhs => latin_hypercube(n, d, rng),
        Sampler::Sobol => {
            let sobol = ScrambledSobol::new(d, rng);
            (offset..offset + n)
                .map(|i| sobol.point(i as u64))
                .collect()
        }
    };
    unit.into_iter()
        .map(|u| {
            u.iter()
                .zip(vars)
                .map(|(&t, v)| v.wrap(v.lower + t * (v.upper - v.lower)))
                .collect()
        })
        .collect()
}

/// `n` Latin hypercube points in `[0, 1)^d`.
pub fn latin_hypercube(n: usize, d: usize, rng: &mut ChaCha8Rng) -> Vec<Vec<f64>> {
    let mut pts = vec![vec![0.0; d]; n];
    let mut perm: Vec<usize> = (0..n).collect();
    for j in 0..d {
        // Fisher–Yates shuffle.
        for i in (1..n).rev() {
            let k = rng.random_range(0..=i);
            perm.swap(i, k);
        }
        for (i, p) in pts.iter_mut().enumerate() {
            p[j] = (perm[i] as f64 + rng.random::<f64>()) / n as f64;
        }
    }
    pts
}

/// Largest dimension with direction numbers here.
pub const SOBOL_MAX_DIM: usize = 21;

/// Joe & Kuo `new-joe-kuo-6.21201`, dimensions 2..=21: (s, a, m_1..m_s).
const JOE_KUO: [(u32, u32, &[u32]); SOBOL_MAX_DIM - 1] = [
    (1, 0, &[1]),
    (2, 1, &[1, 3]),
    (3, 1, &[1, 3, 1]),
    (3, 2, &[1, 1, 1]),
    (4, 1, &[1, 1, 3, 3]),
    (4, 4, &[1, 3, 5, 13]),
    (5, 2, &[1, 1, 5, 5, 17]),
    (5, 4, &[1, 1, 5, 5, 5]),
    (5, 7, &[1, 1, 7, 11, 19]),
    (5, 11, &[1, 1, 5, 1, 1]),
    (5, 13, &[1, 1, 1, 3, 11]),
    (5, 14, &[1, 3, 5, 5, 31]),
    (6, 1, &[1, 3, 3, 9, 7, 49]),
    (6, 13, &[1, 1, 1, 15, 21, 21]),
    (6, 16, &[1, 3, 1, 13, 27, 49]),
    (6, 19, &[1, 1, 1, 15, 7, 5]),
    (6, 22, &[1, 3, 1, 15, 13, 25]),
    (6, 25, &[1, 1, 5, 5, 19, 61]),
    (7, 1, &[1, 3, 7, 11, 23, 15, 103]),
    (7, 4, &[1, 3, 7, 13, 13, 15, 69]),
];

/// The 32 direction numbers `v_k` (as 32-bit binary fractions) of dimension
/// `j` (0-based; dimension 0 is the van der Corput sequence).
pub fn direction_numbers(j: usize) -> [u32; 32] {
    let mut v = [0u32; 32];
    if j == 0 {
        for (k, vk) in v.iter_mut().enumerate() {
            *vk = 1 << (31 - k);
        }
        return v;
    }
    let (s, a, m) = JOE_KUO[j - 1];
    let s = s as usize;
    for k in 0..32 {
        v[k] = if k < s {
            m[k] << (31 - k)
        } else {
            let mut x = v[k - s] ^ (v[k - s] >> s);
            for l in 1..s {
                if (a >> (s - 1 - l)) & 1 == 1 {
                    x ^= v[k - l];
                }
            }
            x
        };
    }
    v
}

/// Sobol point `i` of dimension `j` as a 32-bit fraction, unscrambled
/// (Gray-code-free direct form: XOR of `v_k` over the set bits of
/// `i XOR (i >> 1)`).
pub fn sobol_raw(i: u64, v: &[u32; 32]) -> u32 {
    let g = i ^ (i >> 1);
    let mut x = 0;
    for (k, vk) in v.iter().enumerate() {
        if (g >> k) & 1 == 1 {
            x ^= vk;
        }
    }
    x
}

/// A scrambled Sobol sequence in `[0, 1)^d`.
pub struct ScrambledSobol {
    /// Scrambled direction numbers, one set per dimension.
    v: Vec<[u32; 32]>,
    /// Digital shift per dimension.
    shift: Vec<u32>,
}

impl ScrambledSobol {
    /// Draw a random lower-triangular (unit diagonal) binary matrix and a
    /// digital shift per dimension; `d <= SOBOL_MAX_DIM` (callers check).
    pub fn new(d: usize, rng: &mut ChaCha8Rng) -> Self {
        let mut v = Vec::with_capacity(d);
        let mut shift = Vec::with_capacity(d);
        for j in 0..d.min(SOBOL_MAX_DIM) {
            // Row r acts on digits 0..=r (digit r is bit 31 - r).
            let rows: Vec<u32> = (0..32)
                .map(|r| {
                    let diag = 1u32 << (31 - r);
                    let above = if r == 0 { 0 } else { !((1u32 << (32 - r)) - 1) };
                    diag | (rng.random::<u32>() & above)
                })
                .collect();
            let raw = direction_numbers(j);
            let mut sc = [0u32; 32];
            for (k, s) in sc.iter_mut().enumerate() {
                for (r, row) in rows.iter().enumerate() {
                    if (row & raw[k]).count_ones() & 1 == 1 {
                        *s |= 1 << (31 - r);
                    }
                }
            }
            v.push(sc);
            shift.push(rng.random::<u32>());
        }
        ScrambledSobol { v, shift }
    }

    /// Point `i` (coordinates in `[0, 1)`, centred in their 2⁻³² cell).
    pub fn point(&self, i: u64) -> Vec<f64> {
        self.v
            .iter()
            .zip(&self.shift)
            .map(|(v, &e)| ((sobol_raw(i, v) ^ e) as f64 + 0.5) / 4294967296.0)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn sobol_first_points_match_the_sequence() {
        // Dimension 1: van der Corput 0, 1/2, 3/4, 1/4, 3/8, 7/8, 5/8, 1/8;
        // dimension 2 (s=1, m=1): 0, 1/2, 1/4, 3/4, 3/8, 7/8, 1/8, 5/8.
        // Closed form derived in this test: v = (.1, .11, .101) in binary,
        // point i = XOR of v_k over the bits of the Gray code i ^ (i >> 1).
        let d0: Vec<f64> = (0..8)
            .map(|i| sobol_raw(i, &direction_numbers(0)) as f64 / 4294967296.0)
            .collect();
        assert_eq!(d0, [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125]);
        let d1: Vec<f64> = (0..8)
            .map(|i| sobol_raw(i, &direction_numbers(1)) as f64 / 4294967296.0)
            .collect();
        assert_eq!(d1, [0.0, 0.5, 0.25, 0.75, 0.375, 0.875, 0.125, 0.625]);
    }

    /// (0, m, 2)-net: for every k, the 2^k x 2^(m-k) grid holds one point
    /// per cell (definition of a net; kept by linear scrambling + shift).
    #[test]
    fn scrambled_sobol_is_a_net_in_two_dimensions() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let s = ScrambledSobol::new(2, &mut rng);
        let m = 8;
        let pts: Vec<Vec<f64>> = (0..1u64 << m).map(|i| s.point(i)).collect();
        for k in 0..=m {
            let (nx, ny) = (1usize << k, 1usize << (m - k));
            let mut cells = vec![0; nx * ny];
            for p in &pts {
                let (cx, cy) = ((p[0] * nx as f64) as usize, (p[1] * ny as f64) as usize);
                cells[cx * ny + cy] += 1;
            }
            assert!(cells.iter().all(|&c| c == 1), "k = {k}");
        }
    }

    #[test]
    fn lhs_has_one_point_per_stratum() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let n = 37;
        let pts = latin_hypercube(n, 3, &mut rng);
        for j in 0..3 {
            let mut seen = vec![false; n];
            for p in &pts {
                seen[(p[j] * n as f64) as usize] = true;
            }
            assert!(seen.iter().all(|&s| s));
        }
    }

    #[test]
    fn periodic_coordinates_stay_in_their_box() {
        let vars = vec![Variable::periodic("t", -90.0, 180.0).unwrap()];
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        for s in [Sampler::Lhs, Sampler::Sobol, Sampler::Uniform] {
            for p in sample(s, &vars, 50, &mut rng, 0) {
                assert!((-90.0..90.0).contains(&p[0]));
            }
        }
    }
}
