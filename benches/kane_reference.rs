//! The independent reference of the Kane spin-up studies
//! (`studies/kane_spinup_ws4.toml`, `studies/kane_spinup_ws10.toml`): a
//! Hencky bar chain, geometrically exact, integrated with fixed-step RK4.
//!
//! Run: `cargo bench --bench kane_reference` (about a minute on a 2-core
//! VM); writes `results/kane_spinup/reference_ws4.csv` and
//! `reference_ws10.csv` with the tip deflection in the hub frame of chains
//! of 10, 20 and 40 links and its Richardson extrapolation, which
//! `tests/suite/mbs/stiffening.rs` reads.
//!
//! ## Model
//! The beam of Kane, Ryan & Banerjee (*J. Guidance* 10(2), 1987): `L =
//! 10 m`, `ρA = 1.2 kg/m`, `EI = 14 000 N·m²`, clamped to a hub whose
//! angle is prescribed, `Ω(t) = (ωs/T)(t − (T/2π) sin(2πt/T))` for
//! `t < T = 15 s` and `ωs` after. The chain has `N` rigid massless links
//! of length `ℓ = L/N` in the plane of rotation, point masses `ρAℓ` at the
//! interior joints and `ρAℓ/2` at the tip (the trapezoidal rule), and
//! rotational springs `k = EI/ℓ` at the interior joints and `2EI/ℓ` at the
//! root (the trapezoidal rule of the curvature integral: the tip
//! deflection under a tip load is `FL³/(3EI)(1 + 1/(2N²))`, second order).
//! With absolute link angles `α_k = θ(t) + φ_k`, the Lagrange equations
//! are `Σ_k M_jk α̈_k + Σ_k ℓ² μ_{max(j,k)} sin(α_j − α_k) α̇_k² =
//! −∂V/∂φ_j`, `M_jk = ℓ² μ_{max(j,k)} cos(α_j − α_k)`, `μ_q` the mass
//! beyond link `q`; the hub-frame tip deflection is `Σ_k ℓ sin φ_k`.
//! Nothing is linearized: the centrifugal stiffening is in the equations
//! themselves, not modelled.

use std::f64::consts::PI;
use std::fmt::Write as _;

const L: f64 = 10.0;
const RHO_A: f64 = 1.2;
const EI: f64 = 14_000.0;
const T_UP: f64 = 15.0;

/// Hub angle, rate and acceleration of the spin-up law.
fn hub(ws: f64, t: f64) -> (f64, f64, f64) {
    let c = T_UP / (2.0 * PI);
    if t < T_UP {
        let a = 2.0 * PI * t / T_UP;
        (
            ws / T_UP * (t * t / 2.0 + c * c * (a.cos() - 1.0)),
            ws / T_UP * (t - c * a.sin()),
            ws / T_UP * (1.0 - a.cos()),
        )
    } else {
        // θ(T) = ωs T / 2 (the cosine term vanishes at t = T).
        (ws * T_UP / 2.0 + ws * (t - T_UP), ws, 0.0)
    }
}

struct Chain {
    n: usize,
    l: f64,
    k: Vec<f64>,
    mu: Vec<f64>,
    ws: f64,
}

impl Chain {
    fn new(n: usize, ws: f64) -> Chain {
        let l = L / n as f64;
        let mut m = vec![RHO_A * l; n];
        m[n - 1] = RHO_A * l / 2.0;
        // μ_q: mass of the nodes beyond link q (nodes q+1..=n, node i at
        // the end of link i−1, i.e. m[q..]).
        let mu = (0..n).map(|q| m[q..].iter().sum()).collect();
        let mut k = vec![EI / l; n];
        k[0] = 2.0 * EI / l;
        Chain { n, l, k, mu, ws }
    }

    /// `[φ, φ̇]` → `[φ̇, φ̈]`.
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let n = self.n;
        let (_, om, al) = hub(self.ws, t);
        let (phi, dphi) = y.split_at(n);
        let l2 = self.l * self.l;
        // Absolute angles relative to the hub: only differences enter.
        let mut m = vec![0.0; n * n];
        let mut b = vec![0.0; n];
        for j in 0..n {
            // Spring moments −∂V/∂φ_j.
            let mut q = -self.k[j] * (phi[j] - if j > 0 { phi[j - 1] } else { 0.0 });
            if j + 1 < n {
                q += self.k[j + 1] * (phi[j + 1] - phi[j]);
            }
            for kk in 0..n {
                let g = l2 * self.mu[j.max(kk)];
                let d = phi[j] - phi[kk];
                let (s, c) = d.sin_cos();
                m[j * n + kk] = g * c;
                let ak = om + dphi[kk];
                q -= g * s * ak * ak + g * c * al;
            }
            b[j] = q;
        }
        cholesky_solve(&mut m, &mut b, n);
        out[..n].copy_from_slice(dphi);
        out[n..].copy_from_slice(&b);
    }

    fn tip(&self, y: &[f64]) -> f64 {
        y[..self.n].iter().map(|p| self.l * p.sin()).sum()
    }
}

fn cholesky_solve(a: &mut [f64], b: &mut [f64], n: usize) {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= a[i * n + k] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[k * n + i] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
}

/// Tip deflection every `dt_out` up to `t_end` with RK4 steps of
/// `dt_out / sub`.
fn run(n: usize, ws: f64, t_end: f64, dt_out: f64, sub: usize) -> Vec<f64> {
    let c = Chain::new(n, ws);
    let mut y = vec![0.0; 2 * n];
    let (mut k1, mut k2, mut k3, mut k4) = (y.clone(), y.clone(), y.clone(), y.clone());
    let mut tmp = y.clone();
    let h = dt_out / sub as f64;
    let steps = (t_end / dt_out).round() as usize;
    let mut out = vec![c.tip(&y)];
    for s in 0..steps {
        for i in 0..sub {
            let t = s as f64 * dt_out + i as f64 * h;
            c.rhs(t, &y, &mut k1);
            for e in 0..2 * n {
                tmp[e] = y[e] + 0.5 * h * k1[e];
            }
            c.rhs(t + 0.5 * h, &tmp, &mut k2);
            for e in 0..2 * n {
                tmp[e] = y[e] + 0.5 * h * k2[e];
            }
            c.rhs(t + 0.5 * h, &tmp, &mut k3);
            for e in 0..2 * n {
                tmp[e] = y[e] + h * k3[e];
            }
            c.rhs(t + h, &tmp, &mut k4);
            for e in 0..2 * n {
                y[e] += h / 6.0 * (k1[e] + 2.0 * k2[e] + 2.0 * k3[e] + k4[e]);
            }
        }
        out.push(c.tip(&y));
    }
    out
}

fn main() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("results/kane_spinup");
    std::fs::create_dir_all(&dir).expect("results directory");
    let (t_end, dt_out) = (25.0, 0.05);
    for ws in [4.0, 10.0] {
        // RK4 steps: 2e-4 s for 40 links (highest chain frequency about
        // 2√(EI/ρA)/ℓ² = 3.5e3 rad/s, ω h = 0.7), coarser chains alike.
        let chains: Vec<(usize, Vec<f64>)> = [(10, 16), (20, 63), (40, 250)]
            .iter()
            .map(|&(n, sub)| (n, run(n, ws, t_end, dt_out, sub)))
            .collect();
        let mut csv = String::from("t,tip_y_n10,tip_y_n20,tip_y_n40,tip_y_extrapolated\n");
        for (i, ((a, b), c)) in chains[0]
            .1
            .iter()
            .zip(&chains[1].1)
            .zip(&chains[2].1)
            .enumerate()
        {
            // Second-order Richardson extrapolation from 20 and 40 links.
            let ext = c + (c - b) / 3.0;
            writeln!(
                csv,
                "{:.2},{a:.9e},{b:.9e},{c:.9e},{ext:.9e}",
                i as f64 * dt_out
            )
            .unwrap();
        }
        let peak = |v: &[f64]| {
            v.iter()
                .copied()
                .fold(0.0, |m: f64, x| if x.abs() > m.abs() { x } else { m })
        };
        println!(
            "ws = {ws}: peak tip deflection n10 {:.5} n20 {:.5} n40 {:.5}",
            peak(&chains[0].1),
            peak(&chains[1].1),
            peak(&chains[2].1)
        );
        let path = dir.join(format!("reference_ws{}.csv", ws as u32));
        std::fs::write(&path, csv).expect("write reference CSV");
    }
}
