//! Algebraic and differential Riccati equations and the LQ and Kalman–Bucy gains built on them.
//!
//! Shared by the observers (Kalman gains are the dual problem) and the controllers (LQ gains).
//!
//! * CARE `AᵀP + PA − PBR⁻¹BᵀP + Q = 0`: the Hamiltonian matrix sign function with determinant
//!   scaling (Roberts 1971; Byers 1987; Gardiner & Laub 1986), followed by Newton–Kleinman
//!   refinement steps (Kleinman 1968), each a Lyapunov solve, that drive the residual to
//!   rounding level. The tests cross-check it against Newton–Kleinman alone from a stabilising
//!   gain, an independent algorithm.
//! * [`lqr`], [`kalman_bucy`] and [`kalman_bucy_correlated`]: the gains of the controllers and
//!   observers.
//! * [`RiccatiFlow`]: the forward-integrated differential Riccati equation, the "innovation
//!   process" of [Klugt1987, ch. 3 and App. A–D]: `Ṗ = AᵀP + PA − PBR⁻¹BᵀP + Q`, P(0) given,
//!   whose limit is the CARE solution.
//!
//! Matrices are `nalgebra::DMatrix<f64>`; these are design-time computations (at initialization
//! or on a slow adaptation clock), never in a model's per-step path.

use crate::math::powf;
use nalgebra::{DMatrix, Schur};

/// Iteration limit of the nalgebra QR-type iterations (SVD, Schur). They converge in a few
/// iterations per eigenvalue on the matrices of ship models (order ≤ ~30); the limit only turns
/// a non-converging iteration on extreme entries into an error.
const MAX_QR_ITERATIONS: usize = 10_000;
use std::fmt;

/// Why a Riccati or Lyapunov equation could not be solved.
#[derive(Clone, Debug, PartialEq)]
pub enum RiccatiError {
    /// Matrix dimensions do not fit together.
    Dimension(String),
    /// R (or a matrix the algorithm must invert) is singular or not positive definite.
    Singular(&'static str),
    /// The iteration did not converge (e.g. (A, B) not stabilisable or (A, Q) has unobservable
    /// modes on the imaginary axis).
    NoConvergence(&'static str),
}

impl fmt::Display for RiccatiError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RiccatiError::Dimension(s) => write!(f, "dimension mismatch: {s}"),
            RiccatiError::Singular(s) => write!(f, "singular matrix: {s}"),
            RiccatiError::NoConvergence(s) => write!(f, "no convergence: {s}"),
        }
    }
}

impl std::error::Error for RiccatiError {}

type M = DMatrix<f64>;

fn check_square(name: &str, m: &M, n: usize) -> Result<(), RiccatiError> {
    if m.nrows() != n || m.ncols() != n {
        return Err(RiccatiError::Dimension(format!(
            "{name} is {}x{}, expected {n}x{n}",
            m.nrows(),
            m.ncols()
        )));
    }
    Ok(())
}

fn check_care_dims(a: &M, b: &M, q: &M, r: &M) -> Result<(usize, usize), RiccatiError> {
    let n = a.nrows();
    check_square("A", a, n)?;
    if b.nrows() != n {
        return Err(RiccatiError::Dimension(format!(
            "B has {} rows, A is {n}x{n}",
            b.nrows()
        )));
    }
    let m = b.ncols();
    check_square("Q", q, n)?;
    check_square("R", r, m)?;
    Ok((n, m))
}

fn symmetrize(p: &M) -> M {
    (p + p.transpose()) * 0.5
}

/// Solves the continuous Lyapunov equation `A X + X Aᵀ + Q = 0` by the Kronecker form
/// `(I ⊗ A + A ⊗ I) vec(X) = −vec(Q)` with an LU solve (exact to rounding for the small orders of
/// ship models, n ≤ ~30).
fn lyapunov(a: &M, q: &M) -> Result<M, RiccatiError> {
    let n = a.nrows();
    check_square("A", a, n)?;
    check_square("Q", q, n)?;
    let eye = M::identity(n, n);
    let k = eye.kronecker(a) + a.kronecker(&eye);
    let rhs = -DMatrix::from_column_slice(n * n, 1, q.as_slice());
    let x = k
        .lu()
        .solve(&rhs)
        .ok_or(RiccatiError::Singular("A has eigenvalues λi + λj = 0"))?;
    Ok(symmetrize(&M::from_column_slice(n, n, x.as_slice())))
}

/// One Newton–Kleinman step: given P, the gain K = R⁻¹BᵀP and the Lyapunov solve
/// `(A − BK)ᵀ P⁺ + P⁺ (A − BK) + Q + KᵀRK = 0`.
fn kleinman_step(a: &M, b: &M, q: &M, r: &M, rinv: &M, p: &M) -> Result<M, RiccatiError> {
    let k = rinv * b.transpose() * p;
    let ac = a - b * &k;
    lyapunov(&ac.transpose(), &(q + k.transpose() * r * &k))
}

/// Hamiltonian matrix sign function with determinant scaling. Stops at convergence, or when the
/// change stagnates at rounding level (eigenvalues close to the imaginary axis, e.g. a weakly
/// damped uncontrollable mode, converge only to a few digits); the Newton–Kleinman polish in
/// [`care`] then restores full accuracy.
fn sign_function(h: &M) -> Result<M, RiccatiError> {
    let n2 = h.nrows() as f64;
    let mut z = h.clone();
    let mut last_change = f64::INFINITY;
    for _ in 0..200 {
        let zinv = z.clone().try_inverse().ok_or(RiccatiError::NoConvergence(
            "Hamiltonian has eigenvalues on the imaginary axis",
        ))?;
        let det = z.determinant().abs();
        let c = if det.is_finite() && det > 0.0 {
            powf(det, -1.0 / n2)
        } else {
            1.0
        };
        let next = (&z * c + zinv / c) * 0.5;
        let change = (&next - &z).norm() / next.norm().max(1e-300);
        z = next;
        if change < 1e-13 || (change < 1e-6 && change >= last_change) {
            return Ok(z);
        }
        last_change = change;
    }
    Err(RiccatiError::NoConvergence("sign-function iteration"))
}

/// Stabilising solution of the CARE `AᵀP + PA − PBR⁻¹BᵀP + Q = 0`.
pub fn care(a: &M, b: &M, q: &M, r: &M) -> Result<M, RiccatiError> {
    let (n, _) = check_care_dims(a, b, q, r)?;
    let rinv = r.clone().try_inverse().ok_or(RiccatiError::Singular("R"))?;
    let g = b * &rinv * b.transpose();
    // H = [A, −G; −Q, −Aᵀ]
    let mut h = M::zeros(2 * n, 2 * n);
    h.view_mut((0, 0), (n, n)).copy_from(a);
    h.view_mut((0, n), (n, n)).copy_from(&(-&g));
    h.view_mut((n, 0), (n, n)).copy_from(&(-q));
    h.view_mut((n, n), (n, n)).copy_from(&(-a.transpose()));
    let w = sign_function(&h)?;
    if w.iter().any(|v| !v.is_finite()) {
        return Err(RiccatiError::NoConvergence("non-finite sign function"));
    }
    let eye = M::identity(n, n);
    let w11 = w.view((0, 0), (n, n)).clone_owned();
    let w12 = w.view((0, n), (n, n)).clone_owned();
    let w21 = w.view((n, 0), (n, n)).clone_owned();
    let w22 = w.view((n, n), (n, n)).clone_owned();
    // [W12; W22 + I] P = −[W11 + I; W21]  (least squares via normal equations of a QR)
    let mut lhs = M::zeros(2 * n, n);
    lhs.view_mut((0, 0), (n, n)).copy_from(&w12);
    lhs.view_mut((n, 0), (n, n)).copy_from(&(w22 + &eye));
    let mut rhs = M::zeros(2 * n, n);
    rhs.view_mut((0, 0), (n, n)).copy_from(&(-(w11 + &eye)));
    rhs.view_mut((n, 0), (n, n)).copy_from(&(-w21));
    // nalgebra's `svd` is `try_svd` with this epsilon and no iteration limit: the limit only
    // bounds the work on extreme inputs (issue 19), converged results are the same.
    let p = lhs
        .try_svd(true, true, f64::EPSILON * 5.0, MAX_QR_ITERATIONS)
        .ok_or(RiccatiError::NoConvergence(
            "SVD of the sign-function solve",
        ))?
        .solve(&rhs, 1e-14)
        .map_err(|_| RiccatiError::NoConvergence("sign-function solve"))?;
    let mut p = symmetrize(&p);
    // Newton–Kleinman polish: quadratic convergence from the sign-function estimate.
    for _ in 0..8 {
        let next = kleinman_step(a, b, q, r, &rinv, &p)?;
        let change = (&next - &p).norm() / next.norm().max(1e-300);
        p = next;
        if change < 1e-15 {
            break;
        }
    }
    if p.iter().any(|v| !v.is_finite()) {
        return Err(RiccatiError::NoConvergence("non-finite solution"));
    }
    let closed = a - &g * &p;
    if closed.iter().any(|v| !v.is_finite()) {
        return Err(RiccatiError::NoConvergence("non-finite closed loop"));
    }
    // `complex_eigenvalues` runs the Schur iteration without a limit: it spins forever on
    // extreme entries (a weight of 1e300, issue 19). The same decomposition, bounded.
    let schur = Schur::try_new(closed, f64::EPSILON, MAX_QR_ITERATIONS).ok_or(
        RiccatiError::NoConvergence("Schur decomposition of the closed loop"),
    )?;
    if schur.complex_eigenvalues().iter().any(|l| l.re >= 0.0) {
        return Err(RiccatiError::NoConvergence(
            "no stabilising solution: (A, B) not stabilisable or (A, Q) with unobservable modes on the imaginary axis",
        ));
    }
    Ok(p)
}

/// LQ state-feedback gain `K = R⁻¹BᵀP` for `u = −Kx` minimising ∫ xᵀQx + uᵀRu dt.
pub fn lqr(a: &M, b: &M, q: &M, r: &M) -> Result<M, RiccatiError> {
    let p = care(a, b, q, r)?;
    let rinv = r.clone().try_inverse().ok_or(RiccatiError::Singular("R"))?;
    Ok(rinv * b.transpose() * p)
}

/// Steady-state Kalman–Bucy gain for `ẋ = Ax + Gw`, `y = Cx + v`, E[wwᵀ] = Qw, E[vvᵀ] = Rv:
/// `K = P Cᵀ Rv⁻¹` with P the stabilising solution of the dual CARE
/// `AP + PAᵀ − PCᵀRv⁻¹CP + GQwGᵀ = 0`. Returns (K, P).
pub fn kalman_bucy(a: &M, c: &M, g: &M, qw: &M, rv: &M) -> Result<(M, M), RiccatiError> {
    let p = care(
        &a.transpose(),
        &c.transpose(),
        &(g * qw * g.transpose()),
        rv,
    )?;
    let rinv = rv
        .clone()
        .try_inverse()
        .ok_or(RiccatiError::Singular("Rv"))?;
    Ok((&p * c.transpose() * rinv, p))
}

/// Steady-state Kalman–Bucy gain with correlated process and measurement noise
/// [Klugt1987, eqs. (4.16)–(4.17) and (4.78)–(4.79)]: process noise intensity `DQDᵀ` = `qd`, measurement noise
/// intensity `rv`, cross intensity `n` = E[D w vᵀ] (n × p). `K = (PCᵀ + N) Rv⁻¹` with P the
/// stabilising solution of `AP + PAᵀ + DQDᵀ − (PCᵀ + N) Rv⁻¹ (PCᵀ + N)ᵀ = 0`, solved as the
/// standard problem with `Ā = A − N Rv⁻¹ C` and `Q̄ = DQDᵀ − N Rv⁻¹ Nᵀ`. Returns (K, P).
pub fn kalman_bucy_correlated(a: &M, c: &M, qd: &M, rv: &M, n: &M) -> Result<(M, M), RiccatiError> {
    let nx = a.nrows();
    check_square("A", a, nx)?;
    check_square("DQDᵀ", qd, nx)?;
    if c.ncols() != nx || n.nrows() != nx || n.ncols() != c.nrows() {
        return Err(RiccatiError::Dimension(format!(
            "C is {}x{}, N is {}x{} for {nx} states",
            c.nrows(),
            c.ncols(),
            n.nrows(),
            n.ncols()
        )));
    }
    let rinv = rv
        .clone()
        .try_inverse()
        .ok_or(RiccatiError::Singular("Rv"))?;
    let a_bar = a - n * &rinv * c;
    let q_bar = symmetrize(&(qd - n * &rinv * n.transpose()));
    let p = care(&a_bar.transpose(), &c.transpose(), &q_bar, rv)?;
    Ok(((&p * c.transpose() + n) * rinv, p))
}

/// The differential Riccati equation integrated forward in time (the "innovation process" of
/// [Klugt1987, ch. 3 and App. A–D]): `Ṗ = AᵀP + PA − PBR⁻¹BᵀP + Q`.
#[derive(Clone, Debug)]
pub struct RiccatiFlow {
    a: M,
    bg: M,
    q: M,
    /// Current P.
    pub p: M,
}

impl RiccatiFlow {
    /// Starts the flow at `p0`.
    pub fn new(a: &M, b: &M, q: &M, r: &M, p0: M) -> Result<Self, RiccatiError> {
        let (n, _) = check_care_dims(a, b, q, r)?;
        check_square("P0", &p0, n)?;
        let rinv = r.clone().try_inverse().ok_or(RiccatiError::Singular("R"))?;
        Ok(RiccatiFlow {
            a: a.clone(),
            bg: b * rinv * b.transpose(),
            q: q.clone(),
            p: p0,
        })
    }

    fn rhs(&self, p: &M) -> M {
        self.a.transpose() * p + p * &self.a - p * &self.bg * p + &self.q
    }

    /// Advances P by `dt` with one classical RK4 step.
    pub fn step(&mut self, dt: f64) {
        let k1 = self.rhs(&self.p);
        let k2 = self.rhs(&(&self.p + &k1 * (0.5 * dt)));
        let k3 = self.rhs(&(&self.p + &k2 * (0.5 * dt)));
        let k4 = self.rhs(&(&self.p + &k3 * dt));
        self.p = symmetrize(&(&self.p + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::dmatrix;

    fn rel(a: &M, b: &M) -> f64 {
        (a - b).norm() / b.norm()
    }

    /// Residual `AᵀP + PA − PBR⁻¹BᵀP + Q`.
    fn care_residual(a: &M, b: &M, q: &M, r: &M, p: &M) -> Result<M, RiccatiError> {
        let rinv = r.clone().try_inverse().ok_or(RiccatiError::Singular("R"))?;
        Ok(a.transpose() * p + p * a - p * b * rinv * b.transpose() * p + q)
    }

    /// CARE by Newton–Kleinman iteration alone, from a gain `k0` that makes `A − B k0` stable. An
    /// algorithm independent of [`care`], used to cross-check it.
    fn care_newton_kleinman(a: &M, b: &M, q: &M, r: &M, k0: &M) -> Result<M, RiccatiError> {
        check_care_dims(a, b, q, r)?;
        let rinv = r.clone().try_inverse().ok_or(RiccatiError::Singular("R"))?;
        let ac = a - b * k0;
        let mut p = lyapunov(&ac.transpose(), &(q + k0.transpose() * r * k0))?;
        let mut last_change = f64::INFINITY;
        for _ in 0..200 {
            let next = kleinman_step(a, b, q, r, &rinv, &p)?;
            let change = (&next - &p).norm() / next.norm().max(1e-300);
            p = next;
            // quadratic convergence ends at rounding level: stop when the change stops shrinking
            if change < 1e-14 || (change < 1e-8 && change >= last_change) {
                return Ok(p);
            }
            last_change = change;
        }
        Err(RiccatiError::NoConvergence("Newton–Kleinman"))
    }

    /// Double integrator, Q = I, R = 1: P = [[√3, 1], [1, √3]] (closed form).
    #[test]
    fn care_double_integrator_closed_form() {
        let a = dmatrix![0.0, 1.0; 0.0, 0.0];
        let b = dmatrix![0.0; 1.0];
        let q = M::identity(2, 2);
        let r = dmatrix![1.0];
        let p = care(&a, &b, &q, &r).unwrap();
        let s3 = 3f64.sqrt();
        assert!(rel(&p, &dmatrix![s3, 1.0; 1.0, s3]) < 1e-14, "{p}");
        let k = lqr(&a, &b, &q, &r).unwrap();
        assert!((k[(0, 0)] - 1.0).abs() < 1e-14 && (k[(0, 1)] - s3).abs() < 1e-14);
    }

    /// Scalar CARE: 2ap − p²b²/r + q = 0 ⇒ p = r(a + √(a² + b²q/r))/b² (unstable a too).
    #[test]
    fn care_scalar_closed_form() {
        for (a, b, q, r) in [
            (1.0, 1.0, 1.0, 1.0),
            (-2.0, 0.5, 3.0, 0.1),
            (0.3, 2.0, 0.0, 1.0),
        ] {
            let p = care(&dmatrix![a], &dmatrix![b], &dmatrix![q], &dmatrix![r]).unwrap()[(0, 0)];
            let expected = r * (a + (a * a + b * b * q / r).sqrt()) / (b * b);
            assert!(
                (p - expected).abs() < 1e-13 * expected.abs().max(1.0),
                "{p} vs {expected}"
            );
        }
    }

    /// Lyapunov: A X + X Aᵀ + Q = 0 for a diagonal A has X_ij = −Q_ij/(a_i + a_j).
    #[test]
    fn lyapunov_diagonal_closed_form() {
        let a = M::from_diagonal(&nalgebra::dvector![-1.0, -2.0, -0.5]);
        let q = dmatrix![1.0, 0.2, 0.1; 0.2, 2.0, 0.3; 0.1, 0.3, 1.5];
        let x = lyapunov(&a, &q).unwrap();
        let d = [-1.0, -2.0, -0.5];
        for i in 0..3 {
            for j in 0..3 {
                assert!((x[(i, j)] + q[(i, j)] / (d[i] + d[j])).abs() < 1e-14);
            }
        }
    }

    /// Deterministic pseudo-random numbers for the random-system tests (xorshift; no dependency).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
        fn matrix(&mut self, r: usize, c: usize) -> M {
            M::from_fn(r, c, |_, _| self.next())
        }
    }

    /// Random (generically stabilisable, often open-loop unstable) systems of order 1..=10: the
    /// sign-function CARE agrees with Newton–Kleinman (an independent algorithm) to 1e-9 relative,
    /// leaves a residual at rounding level and gives a stable closed loop.
    #[test]
    fn random_systems_up_to_order_10() {
        let mut rng = Rng(0x9e3779b97f4a7c15);
        for n in 1..=10 {
            for trial in 0..5 {
                let m = 1 + (n + trial) % 3;
                let a = rng.matrix(n, n) * 1.5;
                let b = rng.matrix(n, m);
                let lq = rng.matrix(n, n);
                let q = &lq * lq.transpose() + M::identity(n, n) * 0.1;
                let lr = rng.matrix(m, m);
                let r = &lr * lr.transpose() + M::identity(m, m) * 0.5;
                let p = care(&a, &b, &q, &r).unwrap();
                let res = care_residual(&a, &b, &q, &r, &p).unwrap();
                assert!(
                    res.norm() < 1e-9 * p.norm().max(1.0),
                    "n={n}: residual {}",
                    res.norm()
                );
                // An independent solution: Newton–Kleinman from the gain of a different problem
                // (Q scaled by 100), which stabilises A − BK0 if that CARE was solved correctly.
                let k0 = lqr(&a, &b, &(&q * 100.0), &r).unwrap();
                let cl0 = &a - &b * &k0;
                assert!(cl0.complex_eigenvalues().iter().all(|l| l.re < 0.0));
                let p_nk = care_newton_kleinman(&a, &b, &q, &r, &k0).unwrap();
                let rinv = r.clone().try_inverse().unwrap();
                let (k, k_nk) = (&rinv * b.transpose() * &p, &rinv * b.transpose() * &p_nk);
                eprintln!(
                    "n={n} trial={trial} m={m}: P {:e} K {:e}",
                    rel(&p, &p_nk),
                    rel(&k, &k_nk)
                );
                let cl = &a - &b * k;
                assert!(cl.complex_eigenvalues().iter().all(|l| l.re < 0.0));
            }
        }
    }

    /// The forward-integrated Riccati equation from P = 0 converges to the CARE solution.
    #[test]
    fn riccati_flow_converges_to_care() {
        let a = dmatrix![0.0, 1.0; -0.4, -0.13];
        let b = dmatrix![0.0; 0.08];
        let q = dmatrix![10.0, 0.0; 0.0, 30.0];
        let r = dmatrix![1.0];
        let p_inf = care(&a, &b, &q, &r).unwrap();
        let mut flow = RiccatiFlow::new(&a, &b, &q, &r, M::zeros(2, 2)).unwrap();
        for _ in 0..20_000 {
            flow.step(0.01);
        }
        assert!(rel(&flow.p, &p_inf) < 1e-8, "{}", rel(&flow.p, &p_inf));
    }

    /// Speed filter with high-pass coloured measurement noise [Klugt1987, sec. 4.5.2,
    /// eqs. (4.91)–(4.101)]: x = (speed, x_v), A = [[0,0],[0,−1/τ]], D = [[1,0],[0,1/τ]],
    /// C = (1 −1), w = (w, v), R = E[v²], S = (0, E[v²])ᵀ. Closed form k1 = √(E[w²]/E[v²]),
    /// k2 = (k1τ + 1 − √(k1²τ² + 2k1τ))/τ ([Klugt1987, eqs. (4.100)–(4.101)]); reference values
    /// computed from that closed form (not printed in the thesis), rounded:
    /// (1e−4, 1, 20) ⇒ (0.01, 0.026834), (1e−2, 1, 5) ⇒ (0.1, 0.076393), (1, 0.5, 3) ⇒
    /// (1.41421, 0.032085).
    #[test]
    // 1.41421 is the rounded reference value, not an approximation of √2 to be replaced
    #[allow(clippy::approx_constant)]
    fn correlated_noise_speed_filter_gains() {
        for (ew, ev, tau, k1_ref, k2_ref) in [
            (1e-4, 1.0, 20.0, 0.01, 0.026834),
            (1e-2, 1.0, 5.0, 0.1, 0.076393),
            (1.0, 0.5, 3.0, 1.41421, 0.032085),
        ] {
            let a = dmatrix![0.0, 0.0; 0.0, -1.0 / tau];
            let d = dmatrix![1.0, 0.0; 0.0, 1.0 / tau];
            let c = dmatrix![1.0, -1.0];
            let q = dmatrix![ew, 0.0; 0.0, ev];
            let s = dmatrix![0.0; ev];
            let (k, _) =
                kalman_bucy_correlated(&a, &c, &(&d * q * d.transpose()), &dmatrix![ev], &(&d * s))
                    .unwrap();
            let k1 = (ew / ev).sqrt();
            let k2 = (k1 * tau + 1.0 - (k1 * k1 * tau * tau + 2.0 * k1 * tau).sqrt()) / tau;
            assert!(
                (k[(0, 0)] - k1).abs() < 1e-10 && (k[(1, 0)] - k2).abs() < 1e-10,
                "{k}"
            );
            // the rounded reference values, to their last digit
            assert!((k[(0, 0)] - k1_ref).abs() < 6e-6 && (k[(1, 0)] - k2_ref).abs() < 6e-7);
        }
    }

    /// A stable but uncontrollable mode at −ε puts Hamiltonian eigenvalues at ±ε (as the random
    /// walk disturbance states of the design of [Parsons1980, sec. 3.3] do). Closed form: P = diag(1/(2ε), 1).
    #[test]
    fn care_with_hamiltonian_eigenvalues_near_the_axis() {
        for eps in [1e-2, 1e-4, 1e-6] {
            let a = dmatrix![-eps, 0.0; 0.0, 0.0];
            let b = dmatrix![0.0; 1.0];
            let p = care(&a, &b, &M::identity(2, 2), &dmatrix![1.0]).unwrap();
            let expected = dmatrix![0.5 / eps, 0.0; 0.0, 1.0];
            assert!(rel(&p, &expected) < 1e-9, "eps = {eps}: {p}");
        }
    }

    #[test]
    fn dimension_errors_are_reported() {
        let err = care(
            &M::identity(2, 2),
            &M::zeros(3, 1),
            &M::identity(2, 2),
            &dmatrix![1.0],
        )
        .unwrap_err();
        assert!(err.to_string().contains("B has 3 rows"));
        let err = care(
            &M::identity(2, 2),
            &M::zeros(2, 1),
            &M::identity(2, 2),
            &dmatrix![0.0],
        )
        .unwrap_err();
        assert_eq!(err, RiccatiError::Singular("R"));
    }
}
