//! Prescribed joint motion `f(t)`: the law a driven joint's angle follows
//! (rad, `t` in s), with its exact time derivatives `ḟ`, `f̈` (the
//! constraint row `θ − f(t) = 0` needs all three: value, velocity
//! right-hand side `ν = ḟ` and acceleration term `f̈`). Three forms:
//!
//! - **polynomial** `f(t) = Σ c_k t^k` (a locked joint is the constant
//!   polynomial);
//! - **pieces**: piece `p` holds on `[t_p, t_{p+1})` (`t_0 = 0`, the last
//!   piece open-ended) with its own time `τ = t − t_p`:
//!   `f = Σ c_k τ^k + Σ a_h sin(ω_h τ + φ_h)`. `f` and `ḟ` must be
//!   continuous at the joins (checked by [`Drive::pieces`]); `f̈` may jump.
//!   Before `t = 0` the first piece extends;
//! - **table**: rows `(t_i, θ_i)` with strictly increasing `t`, joined by
//!   the C² cubic spline with *not-a-knot* ends (the third derivative is
//!   continuous at the second and the next-to-last knot, so a cubic is
//!   reproduced exactly and the error is `O(h⁴)` in `f`, `O(h³)` in `ḟ`,
//!   `O(h²)` in `f̈` up to the ends). Outside the table `f` continues
//!   linearly with the end value and slope (`f`, `ḟ` continuous, `f̈ = 0`).
//!
//! Within a polynomial, a piece or a spline interval the derivatives are
//! those of the closed form, exact to rounding.

use crate::error::{Error, Result};

/// Relative size of a jump in `f` or `ḟ` at a join of pieces that
/// [`Drive::pieces`] accepts: `|jump| ≤ JOIN_TOLERANCE · max(1, |left|,
/// |right|)` (rad or rad/s). Laws typed with ten significant digits pass.
pub const JOIN_TOLERANCE: f64 = 1e-8;

/// A term `a sin(ωτ + φ)` of a piece.
#[derive(Debug, Clone, PartialEq)]
pub struct Harmonic {
    /// Amplitude `a` (rad).
    pub amplitude: f64,
    /// Angular frequency `ω` (rad/s).
    pub omega: f64,
    /// Phase `φ` at the piece's start (rad).
    pub phase: f64,
}

/// One piece of a piecewise law, from `start` to the next piece's start.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// Start time `t_p` (s); `τ = t − t_p`.
    pub start: f64,
    /// Polynomial coefficients `[c_0, c_1, …]` in powers of `τ`.
    pub poly: Vec<f64>,
    /// Harmonic terms (possibly none).
    pub harmonics: Vec<Harmonic>,
}

impl Piece {
    /// `(f, ḟ, f̈)` at the piece's own time `τ`.
    pub fn eval(&self, tau: f64) -> (f64, f64, f64) {
        let (mut f, mut d, mut dd) = poly_eval(&self.poly, tau);
        for h in &self.harmonics {
            let (s, c) = (h.omega * tau + h.phase).sin_cos();
            f += h.amplitude * s;
            d += h.amplitude * h.omega * c;
            dd -= h.amplitude * h.omega * h.omega * s;
        }
        (f, d, dd)
    }
}

/// A C² cubic spline through `(t_i, θ_i)` with not-a-knot ends (module
/// doc), stored as knots, values and second derivatives `M_i`.
#[derive(Debug, Clone, PartialEq)]
pub struct Spline {
    /// Knots `t_i` (s), strictly increasing, at least 4.
    pub t: Vec<f64>,
    /// Values `θ_i` (rad).
    pub y: Vec<f64>,
    /// Second derivatives `M_i = f̈(t_i)` (rad/s²).
    pub m: Vec<f64>,
}

impl Spline {
    /// The not-a-knot spline through the rows (at least 4, `t` strictly
    /// increasing: the caller checks). The conditions `M_1 − M_0 =
    /// h_0/h_1 (M_2 − M_1)` (and the same at the end) eliminate `M_0`
    /// and `M_{n−1}`; the interior system is tridiagonal and strictly
    /// diagonally dominant, solved without pivoting (Thomas).
    fn new(t: Vec<f64>, y: Vec<f64>) -> Spline {
        let n = t.len();
        let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let slope: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
        // Unknowns M_1 .. M_{n−2}: row r (knot i = r + 1) reads
        // h_{i−1} M_{i−1} + 2(h_{i−1} + h_i) M_i + h_i M_{i+1} = 6(s_i − s_{i−1}).
        let k = n - 2;
        let mut sub = vec![0.0; k];
        let mut diag = vec![0.0; k];
        let mut sup = vec![0.0; k];
        let mut rhs = vec![0.0; k];
        for r in 0..k {
            let i = r + 1;
            sub[r] = h[i - 1];
            diag[r] = 2.0 * (h[i - 1] + h[i]);
            sup[r] = h[i];
            rhs[r] = 6.0 * (slope[i] - slope[i - 1]);
        }
        // M_0 = ((h0 + h1) M_1 − h0 M_2) / h1 into the first row.
        let (h0, h1) = (h[0], h[1]);
        diag[0] += h0 * (h0 + h1) / h1;
        sup[0] -= h0 * h0 / h1;
        // M_{n−1} = ((a + b) M_{n−2} − a M_{n−3}) / b with a = h_{n−2},
        // b = h_{n−3}, into the last row.
        let (a, b) = (h[n - 2], h[n - 3]);
        diag[k - 1] += a * (a + b) / b;
        sub[k - 1] -= a * a / b;
        // Thomas elimination (k ≥ 2).
        for r in 1..k {
            let w = sub[r] / diag[r - 1];
            diag[r] -= w * sup[r - 1];
            rhs[r] -= w * rhs[r - 1];
        }
        let mut inner = vec![0.0; k];
        inner[k - 1] = rhs[k - 1] / diag[k - 1];
        for r in (0..k - 1).rev() {
            inner[r] = (rhs[r] - sup[r] * inner[r + 1]) / diag[r];
        }
        let mut m = vec![0.0; n];
        m[1..n - 1].copy_from_slice(&inner);
        m[0] = ((h0 + h1) * m[1] - h0 * m[2]) / h1;
        m[n - 1] = ((a + b) * m[n - 2] - a * m[n - 3]) / b;
        Spline { t, y, m }
    }

    /// `(f, ḟ, f̈)` at `t`: the cubic of the interval holding `t`, or the
    /// linear continuation outside the knots.
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        let n = self.t.len();
        if t < self.t[0] || t > self.t[n - 1] {
            let i = if t < self.t[0] { 0 } else { n - 1 };
            let (f, d, _) = self.interval(i.min(n - 2), self.t[i]);
            return (f + d * (t - self.t[i]), d, 0.0);
        }
        let i = self.t.partition_point(|&x| x <= t) - 1;
        self.interval(i.min(n - 2), t)
    }

    /// The cubic of interval `[t_i, t_{i+1}]` and its derivatives at `t`:
    /// `f = M_i (t_{i+1} − t)³/6h + M_{i+1} (t − t_i)³/6h
    ///    + (θ_i/h − M_i h/6)(t_{i+1} − t) + (θ_{i+1}/h − M_{i+1} h/6)(t − t_i)`.
    fn interval(&self, i: usize, t: f64) -> (f64, f64, f64) {
        let h = self.t[i + 1] - self.t[i];
        let (a, b) = (self.t[i + 1] - t, t - self.t[i]);
        let (m0, m1) = (self.m[i], self.m[i + 1]);
        let (c0, c1) = (
            self.y[i] / h - m0 * h / 6.0,
            self.y[i + 1] / h - m1 * h / 6.0,
        );
        let f = (m0 * a * a * a + m1 * b * b * b) / (6.0 * h) + c0 * a + c1 * b;
        let d = (-m0 * a * a + m1 * b * b) / (2.0 * h) - c0 + c1;
        let dd = (m0 * a + m1 * b) / h;
        (f, d, dd)
    }
}

/// A prescribed relative angle `f(t)` (rad, `t` in s): module doc for the
/// forms and their derivatives.
#[derive(Debug, Clone, PartialEq)]
pub enum Drive {
    /// `f(t) = Σ c_k t^k`: coefficients `[c_0, c_1, …]` (rad/s^k for
    /// `c_k`), in increasing powers of `t`.
    Polynomial(Vec<f64>),
    /// A piecewise law, pieces sorted by start, the first starting at 0.
    Pieces(Vec<Piece>),
    /// A not-a-knot cubic spline through a table.
    Table(Spline),
}

impl Drive {
    /// `(θ, θ̇, θ̈)` at time `t`.
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        match self {
            Drive::Polynomial(c) => poly_eval(c, t),
            Drive::Pieces(pieces) => {
                let k = pieces.partition_point(|p| p.start <= t).max(1) - 1;
                pieces[k].eval(t - pieces[k].start)
            }
            Drive::Table(s) => s.eval(t),
        }
    }

    /// Whether `f` is constant in time (a locked joint): energy is then
    /// conserved by the motion it allows.
    pub fn is_constant(&self) -> bool {
        match self {
            Drive::Polynomial(c) => c.len() <= 1,
            Drive::Pieces(pieces) => pieces
                .iter()
                .all(|p| p.poly.len() <= 1 && p.harmonics.is_empty()),
            Drive::Table(s) => s.y.iter().all(|&v| v == s.y[0]),
        }
    }

    /// A polynomial law; `key` names it in errors (non-empty, finite).
    pub fn polynomial(key: &str, c: Vec<f64>) -> Result<Drive> {
        if c.is_empty() || !c.iter().all(|v| v.is_finite()) {
            return Err(Error::input(
                key,
                format!("{c:?}"),
                "polynomial coefficients [c0, c1, ..] of θ(t) (rad, s), finite, at least one",
            ));
        }
        Ok(Drive::Polynomial(c))
    }

    /// A piecewise law from `(until, piece)` pairs as written: every piece
    /// but the last has an end time `until` (s), strictly increasing
    /// and > 0, the last has none; `f` and `ḟ` continuous at every join
    /// within [`JOIN_TOLERANCE`]. `key` (e.g. `joints[0].drive`) names
    /// the offending piece in errors (`<key>.pieces[p].until`, ...).
    pub fn pieces(key: &str, written: Vec<(Option<f64>, Piece)>) -> Result<Drive> {
        if written.is_empty() {
            return Err(Error::input(
                format!("{key}.pieces"),
                "[]",
                "at least one piece { until = <s>, poly = [..], harmonics = [..] }",
            ));
        }
        let last = written.len() - 1;
        let mut pieces: Vec<Piece> = Vec::with_capacity(written.len());
        let mut start = 0.0;
        for (p, (until, mut piece)) in written.into_iter().enumerate() {
            let pk = format!("{key}.pieces[{p}]");
            check_piece(&pk, &piece)?;
            piece.start = start;
            match (until, p == last) {
                (None, false) => {
                    return Err(Error::input(
                        format!("{pk}.until"),
                        "(missing)",
                        "the end time of this piece (s): every piece but the last has one",
                    ))
                }
                (Some(u), true) => {
                    return Err(Error::input(
                        format!("{pk}.until"),
                        u,
                        "no end time on the last piece (it holds to the end of the run)",
                    ))
                }
                (Some(u), false) if !(u.is_finite() && u > start) => {
                    return Err(Error::input(
                        format!("{pk}.until"),
                        u,
                        format!("a finite end time > {start} s (the piece's start)"),
                    ))
                }
                (Some(u), false) => start = u,
                (None, true) => {}
            }
            if let Some(prev) = pieces.last() {
                check_join(&pk, prev, &piece, p)?;
            }
            pieces.push(piece);
        }
        Ok(Drive::Pieces(pieces))
    }

    /// A table `[[t, θ], ..]`: at least 4 rows, finite, `t` strictly
    /// increasing; `key` (e.g. `joints[0].drive`) names the row in
    /// errors (`<key>.table[i]`).
    pub fn table(key: &str, rows: &[[f64; 2]]) -> Result<Drive> {
        if rows.len() < 4 {
            return Err(Error::input(
                format!("{key}.table"),
                format!("{} rows", rows.len()),
                "at least 4 rows [t, θ] (s, rad) for the not-a-knot cubic spline",
            ));
        }
        for (i, r) in rows.iter().enumerate() {
            if !(r[0].is_finite() && r[1].is_finite()) {
                return Err(Error::input(
                    format!("{key}.table[{i}]"),
                    format!("{r:?}"),
                    "finite [t, θ] (s, rad)",
                ));
            }
            if i > 0 && r[0] <= rows[i - 1][0] {
                return Err(Error::input(
                    format!("{key}.table[{i}]"),
                    format!("{r:?}"),
                    format!(
                        "a time t > {} s (the row before): t strictly increasing",
                        rows[i - 1][0]
                    ),
                ));
            }
        }
        Ok(Drive::Table(Spline::new(
            rows.iter().map(|r| r[0]).collect(),
            rows.iter().map(|r| r[1]).collect(),
        )))
    }
}

/// A piece's numbers are finite (`pk` = `<key>.pieces[p]`).
fn check_piece(pk: &str, piece: &Piece) -> Result<()> {
    if !piece.poly.iter().all(|v| v.is_finite()) {
        return Err(Error::input(
            format!("{pk}.poly"),
            format!("{:?}", piece.poly),
            "finite polynomial coefficients [c0, c1, ..] in powers of τ = t − start",
        ));
    }
    for (h, w) in piece.harmonics.iter().enumerate() {
        if ![w.amplitude, w.omega, w.phase]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(Error::input(
                format!("{pk}.harmonics[{h}]"),
                format!("{w:?}"),
                "finite amplitude (rad), omega (rad/s) and phase (rad)",
            ));
        }
    }
    Ok(())
}

/// `f` and `ḟ` continuous where `next` (piece `p`) starts after `prev`.
fn check_join(pk: &str, prev: &Piece, next: &Piece, p: usize) -> Result<()> {
    let t = next.start;
    let (fl, dl, _) = prev.eval(t - prev.start);
    let (fr, dr, _) = next.eval(0.0);
    let jump = |l: f64, r: f64| {
        let j = r - l;
        (j.abs() > JOIN_TOLERANCE * 1f64.max(l.abs()).max(r.abs())).then_some(j)
    };
    let what = match (jump(fl, fr), jump(dl, dr)) {
        (Some(j), _) => format!("θ jumps by {j:e} rad at t = {t} s ({fl} → {fr})"),
        (None, Some(j)) => format!("θ̇ jumps by {j:e} rad/s at t = {t} s ({dl} → {dr})"),
        (None, None) => return Ok(()),
    };
    Err(Error::input(
        pk,
        what,
        format!(
            "θ and θ̇ continuous where pieces[{}] ends (jumps ≤ {JOIN_TOLERANCE:e} relative)",
            p - 1
        ),
    ))
}

/// `(f, ḟ, f̈)` of `Σ c_k t^k` at `t` (Horner, all three at once).
fn poly_eval(c: &[f64], t: f64) -> (f64, f64, f64) {
    let (mut f, mut d, mut dd) = (0.0, 0.0, 0.0);
    for &c in c.iter().rev() {
        dd = dd * t + d * 2.0;
        d = d * t + f;
        f = f * t + c;
    }
    (f, d, dd)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn drive_polynomial_derivatives() {
        // θ = 1 + 2t + 3t²: closed form derived in this test.
        let d = Drive::Polynomial(vec![1.0, 2.0, 3.0]);
        let (f, df, ddf) = d.eval(0.5);
        assert!((f - 2.75).abs() < 1e-15);
        assert!((df - 5.0).abs() < 1e-15);
        assert!((ddf - 6.0).abs() < 1e-15);
    }

    /// The spin-up law of Kane, Ryan and Banerjee (1987, J. Guidance 10(2)
    /// 139–151, Eq. 60): `Ω(t) = (ωs/T)(t − (T/2π) sin(2πt/T))` for
    /// `t < T`, `ωs` after; its integral from 0 is
    /// `θ = ωs t²/(2T) + (ωs T/4π²)(cos(2πt/T) − 1)`, `ωs T/2 + ωs(t − T)`
    /// after `T`; `θ̈ = (ωs/T)(1 − cos(2πt/T))`.
    #[test]
    fn kane_spin_up_as_pieces_matches_the_closed_form() {
        let (ws, tt) = (4.0, 15.0);
        let a = ws * tt / (4.0 * PI * PI);
        let drive = Drive::pieces(
            "d",
            vec![
                (
                    Some(tt),
                    Piece {
                        start: 0.0,
                        poly: vec![-a, 0.0, ws / (2.0 * tt)],
                        harmonics: vec![Harmonic {
                            amplitude: a,
                            omega: 2.0 * PI / tt,
                            phase: PI / 2.0,
                        }],
                    },
                ),
                (
                    None,
                    Piece {
                        start: 0.0,
                        poly: vec![ws * tt / 2.0, ws],
                        harmonics: vec![],
                    },
                ),
            ],
        )
        .unwrap();
        for i in 0..=400 {
            let t = 0.05 * i as f64;
            let (th, om, al) = if t < tt {
                let x = 2.0 * PI * t / tt;
                (
                    ws * t * t / (2.0 * tt) + a * (x.cos() - 1.0),
                    (ws / tt) * (t - tt / (2.0 * PI) * x.sin()),
                    (ws / tt) * (1.0 - x.cos()),
                )
            } else {
                (ws * tt / 2.0 + ws * (t - tt), ws, 0.0)
            };
            let (f, d, dd) = drive.eval(t);
            assert!((f - th).abs() < 1e-12, "θ at {t}: {f} vs {th}");
            assert!((d - om).abs() < 1e-12, "θ̇ at {t}: {d} vs {om}");
            assert!((dd - al).abs() < 1e-12, "θ̈ at {t}: {dd} vs {al}");
        }
    }

    #[test]
    fn spline_reproduces_a_cubic_and_converges_at_fourth_order() {
        // Not-a-knot reproduces any cubic exactly (de Boor, A Practical
        // Guide to Splines, ch. IV), on uneven knots too.
        let cubic = |t: f64| {
            (
                1.0 - 2.0 * t + 0.5 * t * t - 0.3 * t * t * t,
                -2.0 + t - 0.9 * t * t,
            )
        };
        let knots = [0.0, 0.3, 0.5, 1.1, 1.4, 2.0];
        let rows: Vec<[f64; 2]> = knots.iter().map(|&t| [t, cubic(t).0]).collect();
        let d = Drive::table("d", &rows).unwrap();
        for i in 0..=40 {
            let t = 0.05 * i as f64;
            let (f, df, ddf) = d.eval(t);
            assert!((f - cubic(t).0).abs() < 1e-13, "{t}");
            assert!((df - cubic(t).1).abs() < 1e-12, "{t}");
            assert!((ddf - (1.0 - 1.8 * t)).abs() < 1e-11, "{t}");
        }
        // sin t on [0, 3]: the error of f falls 16-fold (h⁴) when h halves,
        // of ḟ 8-fold (h³), of f̈ 4-fold (h²) (de Boor, ch. V); from 40 to
        // 80 intervals the measured ratios are 19.5, 9.6 and 4.7 (still
        // approaching the asymptotic ones from above).
        let err = |n: usize| {
            let rows: Vec<[f64; 2]> = (0..=n)
                .map(|i| {
                    let t = 3.0 * i as f64 / n as f64;
                    [t, t.sin()]
                })
                .collect();
            let d = Drive::table("d", &rows).unwrap();
            let mut e = [0.0f64; 3];
            for i in 0..=997 {
                let t = 3.0 * i as f64 / 997.0;
                let (f, df, ddf) = d.eval(t);
                e[0] = e[0].max((f - t.sin()).abs());
                e[1] = e[1].max((df - t.cos()).abs());
                e[2] = e[2].max((ddf + t.sin()).abs());
            }
            e
        };
        let (coarse, fine) = (err(40), err(80));
        assert!(fine[0] < 2e-8, "{fine:?}");
        for (k, want) in [16.0, 8.0, 4.0].iter().enumerate() {
            let ratio = coarse[k] / fine[k];
            assert!(ratio > 0.8 * want && ratio < 1.3 * want, "{k}: {ratio}");
        }
        // Outside the knots: linear continuation with the end slope.
        let rows: Vec<[f64; 2]> = (0..=20)
            .map(|i| [0.1 * i as f64, (0.1 * i as f64).sin()])
            .collect();
        let d = Drive::table("d", &rows).unwrap();
        let (f2, d2, _) = d.eval(2.0);
        let (f, df, ddf) = d.eval(2.5);
        assert!((f - (f2 + 0.5 * d2)).abs() < 1e-14 && df == d2 && ddf == 0.0);
    }

    fn piece(poly: Vec<f64>) -> Piece {
        Piece {
            start: 0.0,
            poly,
            harmonics: vec![],
        }
    }

    fn input_parts(e: Error) -> (String, String, String) {
        match e {
            Error::Input {
                key,
                value,
                expected,
                ..
            } => (key, value, expected),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn bad_laws_name_the_piece_or_row() {
        let (key, value, exp) = input_parts(
            Drive::pieces(
                "joints[0].drive",
                vec![(Some(1.0), piece(vec![0.0, 1.0])), (None, piece(vec![1.5]))],
            )
            .unwrap_err(),
        );
        assert_eq!(key, "joints[0].drive.pieces[1]");
        assert!(value.contains("θ jumps by 5e-1 rad at t = 1 s"), "{value}");
        assert!(exp.contains("where pieces[0] ends"), "{exp}");
        // θ continuous, θ̇ not: 1 → 0 rad/s.
        let (key, value, _) = input_parts(
            Drive::pieces(
                "d",
                vec![(Some(1.0), piece(vec![0.0, 1.0])), (None, piece(vec![1.0]))],
            )
            .unwrap_err(),
        );
        assert_eq!(key, "d.pieces[1]");
        assert!(value.contains("θ̇ jumps by -1e0 rad/s"), "{value}");
        let (key, value, _) = input_parts(
            Drive::pieces(
                "d",
                vec![(None, piece(vec![0.0])), (None, piece(vec![0.0]))],
            )
            .unwrap_err(),
        );
        assert_eq!(
            (key.as_str(), value.as_str()),
            ("d.pieces[0].until", "(missing)")
        );
        let (key, _, exp) = input_parts(
            Drive::pieces(
                "d",
                vec![
                    (Some(2.0), piece(vec![0.0])),
                    (Some(1.0), piece(vec![0.0])),
                    (None, piece(vec![0.0])),
                ],
            )
            .unwrap_err(),
        );
        assert_eq!(key, "d.pieces[1].until");
        assert!(exp.contains("> 2 s"), "{exp}");
        let (key, value, exp) = input_parts(
            Drive::table("d", &[[0.0, 0.0], [1.0, 1.0], [0.5, 2.0], [2.0, 3.0]]).unwrap_err(),
        );
        assert_eq!((key.as_str(), value.as_str()), ("d.table[2]", "[0.5, 2.0]"));
        assert!(exp.contains("t > 1 s"), "{exp}");
    }
}
