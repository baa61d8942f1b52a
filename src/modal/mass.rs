//! The lumped-mass derivative of a design variable (a ply thickness) in
//! the eigen-derivatives ([`super::derivatives`], "Mass derivative").

use faer::Mat;

/// Derivatives of the lumped diagonal mass with respect to one design
/// variable (a ply thickness), length `n` each.
#[derive(Clone, Copy, Debug)]
pub struct MassDerivative<'a> {
    /// `∂M/∂θ_v` (diagonal).
    pub dm: &'a [f64],
    /// `∂²M/∂θ_v²` (diagonal); needed only for the eigenvector derivatives
    /// of repeated clusters.
    pub d2m: Option<&'a [f64]>,
}

/// `kpx −= λ̄ M' X` column by column, λ̄ the mean eigenvalue of the
/// column's cluster (the eigenvalue itself for a distinct one): then
/// `X_Cᵀ kpx_C = X_Cᵀ(K' − λ̄M')X_C`, whose eigenvalues are the `λ'` of
/// the cluster, and `kpx` is the `(K' − λ̄M')ψ` of the right-hand sides
/// and of the in-cluster coefficients (module doc, "Mass derivative").
pub(crate) fn subtract_mass_term(
    kpx: &mut Mat<f64>,
    modes: &Mat<f64>,
    (lambda, dm): (&[f64], &[f64]),
    clusters: &[(usize, usize)],
) {
    for &(first, r) in clusters {
        let lambda_bar = lambda[first..first + r].iter().sum::<f64>() / r as f64;
        for j in first..first + r {
            for (i, &m) in dm.iter().enumerate() {
                kpx[(i, j)] -= lambda_bar * m * modes[(i, j)];
            }
        }
    }
}
