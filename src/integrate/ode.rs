//! [`OdeModel`]: what the integrator needs of an ODE system.

/// An ODE system `ẏ = f(t, y; p)` as the integrator sees it: right-hand
/// side, exact directional derivatives (for implicit methods and forward
/// sensitivities), and the events that switch between its smooth pieces.
/// `n` is the state length; parameter lanes are named by
/// [`OdeModel::Param`] and carried with their values.
pub trait OdeModel {
    /// A parameter of the model (a sensitivity lane).
    type Param: Copy + std::fmt::Debug;
    /// Scratch reused by every evaluation of one integration.
    type Work;
    /// The state of the model's piece switching (which piece is frozen).
    type Events;
    /// An accepted change of piece.
    type Crossing: Copy;

    /// Scratch for states of length `n`.
    fn work(&self, n: usize) -> Self::Work;
    /// The model's value of parameter `p` (None: not a parameter of it).
    fn param_value(&self, p: Self::Param) -> Option<f64>;
    /// `dy = f(t, y)` with the parameters `params.0` set to the values
    /// `params.1` (both empty: the model's own values).
    fn rhs(
        &self,
        w: &mut Self::Work,
        t: f64,
        y: &[f64],
        params: (&[Self::Param], &[f64]),
        dy: &mut [f64],
    );
    /// The exact directional derivative `out = J v_y + (∂f/∂p) v_p` with
    /// the state seeds `seeds.0` and parameter seeds `seeds.1` (None: 0).
    fn rhs_dir(
        &self,
        w: &mut Self::Work,
        t: f64,
        y: &[f64],
        params: (&[Self::Param], &[f64]),
        seeds: (Option<&[f64]>, Option<&[f64]>),
        out: &mut [f64],
    );
    /// The fused sensitivity right-hand side at one point: `dy = f(t, y)`
    /// and, for each lane `i`, `dlanes_i = J s_i + ∂f/∂p_i`, with the state
    /// seed `s_i = lanes[i·n..(i+1)·n]` and the unit seed on parameter `i`
    /// of `params.0` (lane-major like `lanes`). Returns the number of
    /// dual-number evaluations made. The default makes one
    /// [`OdeModel::rhs`] and one [`OdeModel::rhs_dir`] per lane; a model
    /// may give them all from one multi-lane evaluation.
    #[allow(clippy::too_many_arguments)]
    fn rhs_lanes(
        &self,
        w: &mut Self::Work,
        t: f64,
        y: &[f64],
        params: (&[Self::Param], &[f64]),
        lanes: &[f64],
        dy: &mut [f64],
        dlanes: &mut [f64],
    ) -> usize {
        let n = y.len();
        self.rhs(w, t, y, params, dy);
        let mut e = vec![0.0; params.0.len()];
        for (i, (s, ds)) in lanes.chunks(n).zip(dlanes.chunks_mut(n)).enumerate() {
            e[i] = 1.0;
            self.rhs_dir(w, t, y, params, (Some(s), Some(&e)), ds);
            e[i] = 0.0;
        }
        params.0.len()
    }
    /// The event state at `y0` (every piece frozen where `y0` is); with
    /// `enabled = false`, no root function is active.
    fn events(&self, enabled: bool, y0: &[f64]) -> Self::Events;
    /// Make the right-hand side use the pieces frozen in `ev`.
    fn freeze(&self, ev: &Self::Events, w: &mut Self::Work);
    /// Number of root functions (≥ 1: diffsol needs one; a constant
    /// function where there are none).
    fn nroots(&self, ev: &Self::Events) -> usize;
    /// Root function values `g(t, y)` (sign change = a candidate crossing).
    fn roots(&self, ev: &Self::Events, w: &mut Self::Work, t: f64, y: &[f64], g: &mut [f64]);
    /// `g_y v` of every root function at `(t, y)`.
    fn roots_dir(&self, ev: &Self::Events, t: f64, y: &[f64], v: &[f64], g: &mut [f64]);
    /// Whether the sign change of root `idx` at `(t, y)` is a genuine crossing.
    fn classify(&self, ev: &Self::Events, idx: usize, t: f64, y: &[f64]) -> Option<Self::Crossing>;
    /// Why the integration must end at crossing `c` at `(t, y)` instead of
    /// switching (a guard of the model, e.g. a divergence bound), as
    /// `(place, detail)` of the numerical error; `None` (the default): go on.
    fn halt(
        &self,
        _ev: &Self::Events,
        _c: Self::Crossing,
        _t: f64,
        _y: &[f64],
    ) -> Option<(String, String)> {
        None
    }
    /// Switch to the piece after crossing `c` at `(t, y)`.
    fn switch(&self, ev: &mut Self::Events, c: Self::Crossing, t: f64, y: &[f64]);
    /// `g_y v` of the switching surface of crossing `c` at `(t, y)`.
    fn crossing_dir(
        &self,
        ev: &Self::Events,
        c: Self::Crossing,
        t: f64,
        y: &[f64],
        v: &[f64],
    ) -> f64;
    /// What switched, for messages (e.g. `actuator forces[3]`).
    fn crossing_label(&self, ev: &Self::Events, c: Self::Crossing) -> String;
}
