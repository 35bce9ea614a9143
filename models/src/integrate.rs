//! Fixed-step integrators shared by the hull models.
//!
//! Every nonlinear hull advances a co-simulation step of length `h` by `n = ceil(h / h_max)`
//! classical fourth-order Runge-Kutta sub-steps of equal length `h / n`, with the inputs held
//! constant over the whole step (zero-order hold, as every FMI master delivers them).
//! Consequences, stated once here and referred to by each model:
//! * when `h` is a multiple of `h_max` the sub-step is exactly `h_max`, so two runs with
//!   communication steps that are both multiples of `h_max` (and the same held inputs) execute the
//!   *same* sequence of floating-point operations and agree bit for bit;
//! * otherwise the sub-step is slightly smaller than `h_max` and the results differ only by the
//!   RK4 truncation error (O(h_max⁴) per unit time).
//!
//! Linear time-invariant models are instead discretised exactly (zero-order hold) with
//! [`zoh_discretise`], which uses the block-matrix exponential (Van Loan).
//!
//! Nothing here allocates: states are fixed-size arrays or statically sized nalgebra matrices.

use nalgebra::SMatrix;

/// The passes a sampling or noise-grid loop has due when it lags `ahead` of its intervals behind
/// the time it advances to (for the work bound of one FMU step, `FmuModel::internal_steps`):
/// `ahead` when positive, 0 when negative (nothing due), and NaN kept. `ahead.max(0.0)` would
/// turn NaN into 0: an infinite interval in a restored state gives (t − ∞)/∞ = NaN, and the
/// loop that compares t₀ + k·∞ ≤ t + 1e-9·∞ never ends (the fuzzer's `replay state Sensors
/// 2186 39`); a NaN count is refused by the bound.
pub fn due_passes(ahead: f64) -> f64 {
    if ahead < 0.0 {
        0.0
    } else {
        ahead
    }
}

/// Number of equal sub-steps used to cover `h` with sub-steps no longer than `h_max`.
/// Returns 0 for `h <= 0` (and for non-finite input), so a zero-length step is a no-op.
pub fn substeps(h: f64, h_max: f64) -> usize {
    if !(h > 0.0) || !h.is_finite() || !(h_max > 0.0) {
        return 0;
    }
    // The small relative tolerance makes h = k·h_max (up to round-off) give exactly k sub-steps.
    let n = (h / h_max * (1.0 - 1e-12)).ceil();
    (n.max(1.0)) as usize
}

/// One classical RK4 step of length `h` for `ẋ = f(x)` on a fixed-size array state.
#[inline]
pub fn rk4<const N: usize, F>(x: &mut [f64; N], h: f64, f: &F)
where
    F: Fn(&[f64; N]) -> [f64; N],
{
    let k1 = f(x);
    let mut tmp = [0.0; N];
    for i in 0..N {
        tmp[i] = x[i] + 0.5 * h * k1[i];
    }
    let k2 = f(&tmp);
    for i in 0..N {
        tmp[i] = x[i] + 0.5 * h * k2[i];
    }
    let k3 = f(&tmp);
    for i in 0..N {
        tmp[i] = x[i] + h * k3[i];
    }
    let k4 = f(&tmp);
    for i in 0..N {
        x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// Advances `x` by `h` seconds with [`substeps`]`(h, h_max)` equal RK4 sub-steps.
pub fn rk4_advance<const N: usize, F>(x: &mut [f64; N], h: f64, h_max: f64, f: F)
where
    F: Fn(&[f64; N]) -> [f64; N],
{
    let n = substeps(h, h_max);
    if n == 0 {
        return;
    }
    let hs = h / n as f64;
    for _ in 0..n {
        rk4(x, hs, &f);
    }
}

/// Exact zero-order-hold discretisation of `ẋ = A x + B u` over `h`:
/// returns `(Φ, Γ)` with `Φ = e^{A h}`, `Γ = ∫₀ʰ e^{A s} ds B`, so `x⁺ = Φ x + Γ u` for `u` held
/// constant. Computed from the exponential of the block matrix `[[A, B], [0, 0]]·h` (Van Loan).
pub fn zoh_discretise<const N: usize, const M: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, M>,
    h: f64,
) -> (SMatrix<f64, N, N>, SMatrix<f64, N, M>) {
    // Padé-free scaling-and-squaring Taylor series on the augmented matrix, done block-wise so
    // that only statically sized matrices are needed. E = [[A h, B h], [0, 0]];
    // E^k = [[(Ah)^k, (Ah)^(k-1) B h], [0, 0]] for k >= 1.
    let ah = a * h;
    let bh = b * h;
    // Scale so that ||A h / 2^s|| < 0.5.
    let norm = ah.abs().row_sum().max();
    let mut s = 0i32;
    let mut scale = 1.0;
    while norm * scale > 0.5 {
        scale *= 0.5;
        s += 1;
    }
    let asc = ah * scale;
    let bsc = bh * scale;
    // Taylor series for exp of the scaled block matrix.
    let mut phi = SMatrix::<f64, N, N>::identity();
    let mut gam = SMatrix::<f64, N, M>::zeros();
    let mut term_a = SMatrix::<f64, N, N>::identity(); // (A h)^k / k!
    let mut term_b = bsc; // (A h)^(k-1) B h / k!
    gam += term_b;
    for k in 1..30 {
        term_a = term_a * asc / k as f64;
        phi += term_a;
        term_b = asc * term_b / (k + 1) as f64;
        gam += term_b;
        if term_a.abs().max() < 1e-18 && term_b.abs().max() < 1e-18 {
            break;
        }
    }
    // Squaring: exp(2E) = exp(E)^2, block-wise [[Φ, Γ],[0, I]]^2 = [[Φ², ΦΓ + Γ],[0, I]].
    for _ in 0..s {
        gam = phi * gam + gam;
        phi = phi * phi;
    }
    (phi, gam)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{cos, exp, sin};
    use nalgebra::{Matrix2, Vector2};

    #[test]
    fn substep_count() {
        assert_eq!(substeps(0.1, 0.05), 2);
        assert_eq!(substeps(0.05, 0.05), 1);
        assert_eq!(substeps(0.3, 0.1), 3);
        assert_eq!(substeps(0.07, 0.05), 2);
        assert_eq!(substeps(0.0, 0.05), 0);
        assert_eq!(substeps(f64::NAN, 0.05), 0);
    }

    /// RK4 on ẋ = −x over 1 s: error against e^{-1} is O(h⁴).
    #[test]
    fn rk4_decay() {
        let mut x = [1.0];
        rk4_advance(&mut x, 1.0, 0.01, |x: &[f64; 1]| [-x[0]]);
        assert!((x[0] - exp(-1.0f64)).abs() < 1e-10);
    }

    /// ZOH of a harmonic oscillator against the closed form cos/sin.
    #[test]
    fn zoh_oscillator() {
        let w = 2.0;
        let a = Matrix2::new(0.0, 1.0, -w * w, 0.0);
        let b = Vector2::new(0.0, 1.0);
        let h = 0.7;
        let (phi, gam) = zoh_discretise(&a, &b, h);
        let (c, s) = (cos(w * h), sin(w * h));
        assert!((phi[(0, 0)] - c).abs() < 1e-13);
        assert!((phi[(0, 1)] - s / w).abs() < 1e-13);
        assert!((phi[(1, 0)] + w * s).abs() < 1e-13);
        // Γ = [(1 − cos wh)/w², sin(wh)/w]
        assert!((gam[0] - (1.0 - c) / (w * w)).abs() < 1e-13);
        assert!((gam[1] - s / w).abs() < 1e-13);
    }
}
