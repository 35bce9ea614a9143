//! Continuous LQ state feedback in the sources' sign convention.
//!
//! [Klugt1987] and [Parsons1980] write the control law as u = C x [Parsons1980, eq. (29)] with
//! `C = −B⁻¹GᵀS∞` [Parsons1980, eq. (34)], S∞ the stabilising solution of the steady-state
//! Riccati equation `0 = −SF − FᵀS + SGB⁻¹GᵀS − A` [Parsons1980, eq. (35)], minimising
//! `J = ½∫(xᵀAx + uᵀBu)dt` [Parsons1980, eq. (30)]. Potter's eigenvector method
//! [Parsons1980, eqs. (36)–(38)] and the sign-function CARE of [`crate::riccati::care`] give the
//! same S∞ (both give the unique stabilising solution); this module uses the latter.

use crate::riccati;
use nalgebra::DMatrix;

use super::ControlError;

/// Steady-state LQ design: returns (C, S∞) for `u = C x`, `ẋ = F x + G u`, weights `A` (state)
/// and `B` (control).
pub fn lq_gain(
    f: &DMatrix<f64>,
    g: &DMatrix<f64>,
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), ControlError> {
    let s = riccati::care(f, g, a, b)?;
    let binv = b
        .clone()
        .try_inverse()
        .ok_or_else(|| ControlError("control weight B is singular".into()))?;
    let c = -(binv * g.transpose() * &s);
    Ok((c, s))
}

/// Steady-state LQ design for a plant with an uncontrollable, unweighted exogenous part
/// (disturbance states with their own dynamics, measured or estimated):
///
/// ```text
/// ẋ₁ = F₁₁x₁ + F₁₂x₂ + G₁u,   ẋ₂ = F₂₂x₂,   J = ½∫(x₁ᵀA₁₁x₁ + uᵀBu)dt
/// ```
///
/// The stabilising Riccati solution of the full system is block-structured: S₁₁ solves the CARE
/// of (F₁₁, G₁, A₁₁, B); S₁₂ solves the Sylvester equation `F_clᵀS₁₂ + S₁₂F₂₂ + S₁₁F₁₂ = 0`
/// with `F_cl = F₁₁ − G₁B⁻¹G₁ᵀS₁₁`; C = −B⁻¹G₁ᵀ[S₁₁ S₁₂] (feedback + disturbance feedforward).
/// This equals the full CARE solution whenever that exists, and also works when F₂₂ has
/// eigenvalues at or next to 0 (the random-walk disturbance of [Parsons1980, sec. 3.3] with ε → 0), where the Hamiltonian
/// has eigenvalues ±ε on/near the imaginary axis and a generic CARE solver (the sign function of
/// [`riccati::care`]) stops converging. Well posed whenever λᵢ(F_cl) + λⱼ(F₂₂) ≠ 0, i.e. always
/// for F₂₂ with eigenvalues of non-positive real part.
///
/// Returns the gain row(s) C (m × (n₁+n₂)) and S₁₁.
pub fn lq_gain_feedforward(
    f11: &DMatrix<f64>,
    f12: &DMatrix<f64>,
    f22: &DMatrix<f64>,
    g1: &DMatrix<f64>,
    a11: &DMatrix<f64>,
    b: &DMatrix<f64>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), ControlError> {
    let n1 = f11.nrows();
    let n2 = f22.nrows();
    if f12.nrows() != n1 || f12.ncols() != n2 || f22.ncols() != n2 {
        return Err(ControlError(format!(
            "feedforward LQ: F12 is {}x{}, expected {n1}x{n2}",
            f12.nrows(),
            f12.ncols()
        )));
    }
    let (c1, s11) = lq_gain(f11, g1, a11, b)?;
    let fcl = f11 + g1 * &c1;
    let eye1 = DMatrix::<f64>::identity(n1, n1);
    let eye2 = DMatrix::<f64>::identity(n2, n2);
    let k = eye2.kronecker(&fcl.transpose()) + f22.transpose().kronecker(&eye1);
    let rhs = -(&s11 * f12);
    let rhs = DMatrix::from_column_slice(n1 * n2, 1, rhs.as_slice());
    let x = k.lu().solve(&rhs).ok_or_else(|| {
        ControlError("feedforward LQ: Sylvester equation singular (λ(F_cl) + λ(F22) = 0)".into())
    })?;
    let s12 = DMatrix::from_column_slice(n1, n2, x.as_slice());
    let binv = b
        .clone()
        .try_inverse()
        .ok_or_else(|| ControlError("control weight B is singular".into()))?;
    let c2 = -(binv * g1.transpose() * s12);
    let m = c1.nrows();
    let mut c = DMatrix::zeros(m, n1 + n2);
    c.view_mut((0, 0), (m, n1)).copy_from(&c1);
    c.view_mut((0, n1), (m, n2)).copy_from(&c2);
    Ok((c, s11))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Double integrator with unit weights: closed form S = [[√3, 1], [1, √3]], C = −[1, √3].
    #[test]
    fn double_integrator_closed_form() {
        let f = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let g = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        let a = DMatrix::identity(2, 2);
        let b = DMatrix::identity(1, 1);
        let (c, s) = lq_gain(&f, &g, &a, &b).unwrap();
        let r3 = 3f64.sqrt();
        assert!(
            (c[0] + 1.0).abs() < 1e-12 && (c[1] + r3).abs() < 1e-12,
            "{c}"
        );
        assert!((s[(0, 0)] - r3).abs() < 1e-12 && (s[(0, 1)] - 1.0).abs() < 1e-12);
    }

    /// The feedforward design equals the full CARE where the latter converges (stable,
    /// well-separated exogenous dynamics).
    #[test]
    fn feedforward_equals_full_care() {
        let f11 = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -0.5, -0.3]);
        let f12 = DMatrix::from_row_slice(2, 1, &[0.2, 1.0]);
        let f22 = DMatrix::from_row_slice(1, 1, &[-0.7]);
        let g1 = DMatrix::from_row_slice(2, 1, &[0.0, 2.0]);
        let a11 = DMatrix::from_row_slice(2, 2, &[3.0, 0.0, 0.0, 1.0]);
        let b = DMatrix::from_element(1, 1, 0.5);
        let (c, _) = lq_gain_feedforward(&f11, &f12, &f22, &g1, &a11, &b).unwrap();
        let mut f = DMatrix::zeros(3, 3);
        f.view_mut((0, 0), (2, 2)).copy_from(&f11);
        f.view_mut((0, 2), (2, 1)).copy_from(&f12);
        f[(2, 2)] = -0.7;
        let mut g = DMatrix::zeros(3, 1);
        g.view_mut((0, 0), (2, 1)).copy_from(&g1);
        let mut a = DMatrix::zeros(3, 3);
        a.view_mut((0, 0), (2, 2)).copy_from(&a11);
        let (cf, _) = lq_gain(&f, &g, &a, &b).unwrap();
        assert!((c - cf).norm() < 1e-10);
    }
}
