//! Minimum-Variance parameter Estimator (MVE) of [Parsons1980, sec. 5] (after Kotob & Kaufman)
//! that feeds the partial adaptation of the path controller
//! ([`super::path`]): recursive estimates of p = [f22, f23, f25, f32, f33, f35] from the measured
//! states z′ = [ψ′, r′, β′, η′] + v′ and the exact rudder angle δ′.
//!
//! # Source
//! [Parsons1980, sec. 5.1-5.2]: Euler discretisation [Parsons1980, eqs. (79)–(81)], regression form
//! [Parsons1980, eq. (84)] with the measured parts Ĉ, D̂ [Parsons1980, eqs. (85), (87)], pseudo-measurement and innovation
//! [Parsons1980, eqs. (90), (94)], gain and covariance [Parsons1980, eqs. (101)–(103)], the noise terms B [Parsons1980, eq. (104)], Γ′Q_wΓ′ᵀ
//! [Parsons1980, eq. (105)], U [Parsons1980, eq. (106)], the bias-correction gain G [Parsons1980, eqs. (112)–(113)] and the update [Parsons1980, eq. (114)];
//! settings of [Parsons1980, sec. 5.3]: [Parsons1980, Table 9] noise, γ̃ at H/T = 1.89, q′ of [Parsons1980, eqs. (115)–(116)], p̄, P0 of [Parsons1980, eq. (117)],
//! [Parsons1980, Table 17] Φ for time-varying runs.
//!
//! # Readings taken
//! * [Parsons1980, eq. (104)] B: the printed matrix has B14 = B41 = 0, a direct derivation from [Parsons1980, eq. (88)] gives
//!   Δtσ1². The printed form is the default (`b14_derived = false`), as the
//!   report used it.
//! * [Parsons1980, eq. (104)] (2,2) "σ²" read as σ2²; Q_w = diag(q′_N/Δt, q′_Y/Δt) (the printed Q_w is garbled);
//!   U of [Parsons1980, eq. (106)] with p̄_i² (OCR "p̄_1^{-2}"); "p_{k−1}" around [Parsons1980, eq. (102)] read as P_{k−ℓ}
//!   (the algorithm summary of [Parsons1980, sec. 5.2] prints the correct form). These are
//!   garbles of the OCR text.
//! * [Parsons1980, eq. (86)]: the noise part Č has zeros in the δ′ columns (the rudder angle is exact).

use super::ControlError;
use crate::error::{check_non_negative, check_positive};
use crate::hull::tokyo_maru::TokyoMaruCoefficients;
use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

type M4 = SMatrix<f64, 4, 4>;
type M6 = SMatrix<f64, 6, 6>;
type M46 = SMatrix<f64, 4, 6>;
type V4 = SVector<f64, 4>;
type V6 = SVector<f64, 6>;

/// [Parsons1980, Table 9] per-sample noise σ′ of ψ′, r′, β′, η′ (Δt′ = 0.005).
pub const SIGMA_TABLE_9: [f64; 4] = [5.0943e-4, 3.9298e-4, 4.0688e-4, 1.0065e-3];
/// [Parsons1980, eqs. (115)–(116)]: q′_N, q′_Y.
pub const Q_PRIME: [f64; 2] = [2.00e-10, 1.25e-9];
/// [Parsons1980, sec. 5.3]: p̄ for U (f22, f23, —, f32, f33, —; f25 and f35 do not enter U).
pub const P_BAR: [f64; 6] = [-1.750, 6.250, 0.0, 0.175, -0.785, 0.0];
/// [Parsons1980, eq. (117)]: P0 = squared differences of [Parsons1980, Table 2] between ∞ and 1.89.
pub const P0_EQ_117: [f64; 6] = [0.03452, 6.640, 0.02568, 0.02047, 0.01185, 0.00003091];
/// [Parsons1980, Table 17]: design diffusion φ_ii (ℓ = 10) for time-varying runs.
pub const PHI_TABLE_17: [f64; 6] = [1.726e-3, 3.319e-1, 1.284e-3, 1.023e-3, 5.924e-4, 1.545e-6];

/// Settings of the MVE.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MveParams {
    /// Sample step Δt′ (0.005).
    pub dt: f64,
    /// Estimation interval ℓ in samples (10; must be > 1).
    pub interval: u32,
    /// Per-sample measurement-noise σ′ of ψ′, r′, β′, η′.
    pub sigma: [f64; 4],
    /// γ̃21, γ̃22, γ̃31, γ̃32 (H/T = 1.89).
    pub gamma: [f64; 4],
    /// Disturbance intensities q′_N, q′_Y.
    pub q: [f64; 2],
    /// Parameter means p̄ and variances α² for U [Parsons1980, eq. (106)].
    pub p_bar: [f64; 6],
    pub alpha2: [f64; 6],
    /// Diffusion Φ (diagonal) and initial covariance P0 (diagonal).
    pub phi: [f64; 6],
    pub p0: [f64; 6],
    /// Use the derived B14 = B41 = Δtσ1² instead of the printed 0.
    pub b14_derived: bool,
}

impl Default for MveParams {
    /// The time-invariant design of [Parsons1980, sec. 5.3] (α = 0, Φ = 0, P0 of [Parsons1980, eq. (117)]).
    fn default() -> Self {
        let g = TokyoMaruCoefficients::at_depth_ratio(1.89);
        MveParams {
            dt: 0.005,
            interval: 10,
            sigma: SIGMA_TABLE_9,
            gamma: [g.g21, g.g22, g.g31, g.g32],
            q: Q_PRIME,
            p_bar: P_BAR,
            alpha2: [0.0; 6],
            phi: [0.0; 6],
            p0: P0_EQ_117,
            b14_derived: false,
        }
    }
}

/// The precomputed matrices of one design [Parsons1980, eqs. (101)–(106), (113)].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MveMatrices {
    pub r: M4,
    pub b: M4,
    pub gqg: M4,
    pub u: M4,
    pub r_eq: M4,
    pub g: M6,
}

impl MveParams {
    pub fn validate(&self) -> Result<(), ControlError> {
        check_positive("dt", self.dt)?;
        if self.interval < 2 {
            return Err(ControlError(format!(
                "parameter interval = {} must be > 1 (the derivation needs l > 1)",
                self.interval
            )));
        }
        for (i, s) in self.sigma.iter().enumerate() {
            check_positive(["sigma_psi", "sigma_r", "sigma_beta", "sigma_eta"][i], *s)?;
        }
        for (name, values) in [
            ("q", &self.q[..]),
            ("alpha2", &self.alpha2[..]),
            ("phi", &self.phi[..]),
            ("p0", &self.p0[..]),
        ] {
            for v in values {
                check_non_negative(name, *v)?;
            }
        }
        Ok(())
    }

    /// R, B, Γ′Q_wΓ′ᵀ, U, R_eq and G.
    pub fn matrices(&self) -> Result<MveMatrices, ControlError> {
        self.validate()?;
        let dt = self.dt;
        let s2: [f64; 4] = self.sigma.map(|s| s * s);
        let r = M4::from_diagonal(&V4::from(s2));
        let mut b = M4::zeros();
        b[(0, 0)] = s2[0] + dt * dt * s2[1];
        b[(0, 1)] = dt * s2[1];
        b[(1, 0)] = dt * s2[1];
        b[(1, 1)] = s2[1];
        b[(2, 2)] = s2[2];
        b[(2, 3)] = -dt * s2[2];
        b[(3, 2)] = -dt * s2[2];
        b[(3, 3)] = s2[3] + dt * dt * (s2[0] + s2[2]);
        if self.b14_derived {
            b[(0, 3)] = dt * s2[0];
            b[(3, 0)] = dt * s2[0];
        }
        let [g21, g22, g31, g32] = self.gamma;
        let [qn, qy] = self.q;
        let mut gqg = M4::zeros();
        gqg[(1, 1)] = dt * (qn * g21 * g21 + qy * g22 * g22);
        gqg[(1, 2)] = dt * (qn * g21 * g31 + qy * g22 * g32);
        gqg[(2, 1)] = gqg[(1, 2)];
        gqg[(2, 2)] = dt * (qn * g31 * g31 + qy * g32 * g32);
        let (p, a) = (&self.p_bar, &self.alpha2);
        let mut u = M4::zeros();
        u[(1, 1)] = dt * dt * (s2[1] * (a[0] + p[0] * p[0]) + s2[2] * (a[1] + p[1] * p[1]));
        u[(1, 2)] = dt * dt * (s2[1] * p[0] * p[3] + s2[2] * p[1] * p[4]);
        u[(2, 1)] = u[(1, 2)];
        u[(2, 2)] = dt * dt * (s2[1] * (a[3] + p[3] * p[3]) + s2[2] * (a[4] + p[4] * p[4]));
        let r_eq = u + b + r + gqg;
        let t = r_eq
            .try_inverse()
            .ok_or_else(|| ControlError("R_eq is singular".into()))?;
        let mut g = M6::zeros();
        let d2 = dt * dt;
        g[(0, 0)] = d2 * t[(1, 1)] * s2[1];
        g[(0, 3)] = d2 * t[(1, 2)] * s2[1];
        g[(1, 1)] = d2 * t[(1, 1)] * s2[2];
        g[(1, 4)] = d2 * t[(1, 2)] * s2[2];
        g[(3, 0)] = d2 * t[(2, 1)] * s2[1];
        g[(3, 3)] = d2 * t[(2, 2)] * s2[1];
        g[(4, 1)] = d2 * t[(2, 1)] * s2[2];
        g[(4, 4)] = d2 * t[(2, 2)] * s2[2];
        Ok(MveMatrices {
            r,
            b,
            gqg,
            u,
            r_eq,
            g,
        })
    }
}

/// Packs the six estimated coefficients.
pub fn parameters_of(c: &TokyoMaruCoefficients) -> [f64; 6] {
    [c.f22, c.f23, c.f25, c.f32, c.f33, c.f35]
}

/// The recursive estimator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Mve {
    pub params: MveParams,
    matrices: MveMatrices,
    phi: M6,
    p_hat: V6,
    p_cov: M6,
    prev: Option<(V4, f64)>,
    samples: u64,
    estimates: u64,
}

impl Mve {
    /// Starts from the estimate `p0_hat` with covariance diag(params.p0).
    pub fn new(params: MveParams, p0_hat: [f64; 6]) -> Result<Self, ControlError> {
        Ok(Mve {
            matrices: params.matrices()?,
            phi: M6::from_diagonal(&V6::from(params.phi)),
            p_hat: V6::from(p0_hat),
            p_cov: M6::from_diagonal(&V6::from(params.p0)),
            prev: None,
            samples: 0,
            estimates: 0,
            params,
        })
    }

    pub fn matrices(&self) -> &MveMatrices {
        &self.matrices
    }

    /// Changes the sample step Δt′ (recomputes R_eq and G; p̂ and P carry over).
    pub fn set_dt(&mut self, dt: f64) -> Result<(), ControlError> {
        let params = MveParams { dt, ..self.params };
        self.matrices = params.matrices()?;
        self.params = params;
        Ok(())
    }

    /// Replaces the settings (recomputes the matrices; p̂ and P carry over).
    pub fn set_params(&mut self, params: MveParams) -> Result<(), ControlError> {
        self.matrices = params.matrices()?;
        self.phi = M6::from_diagonal(&V6::from(params.phi));
        self.params = params;
        Ok(())
    }

    /// p̂ = [f22, f23, f25, f32, f33, f35].
    pub fn estimate(&self) -> [f64; 6] {
        self.p_hat.into()
    }

    pub fn covariance(&self) -> &M6 {
        &self.p_cov
    }

    /// Number of updates so far.
    pub fn estimates(&self) -> u64 {
        self.estimates
    }

    /// One sample k of z′ = [ψ′, r′, β′, η′] and the rudder δ′ (at the same instant). Every ℓ-th
    /// sample runs the 8-step recursion of [Parsons1980, sec. 5.2] with the previous sample (k − 1). Returns whether
    /// an update was made.
    pub fn sample(&mut self, z: [f64; 4], rudder: f64) -> bool {
        let z = V4::from(z);
        let k = self.samples;
        self.samples += 1;
        let mut updated = false;
        if k > 0 && k % self.params.interval as u64 == 0 {
            if let Some((zp, dp)) = self.prev {
                self.update(&zp, dp, &z);
                updated = true;
            }
        }
        self.prev = Some((z, rudder));
        updated
    }

    fn update(&mut self, zp: &V4, dp: f64, z: &V4) {
        let dt = self.params.dt;
        // Ĉ_{k−1} [Parsons1980, eq. (85)] and D̂_{k−1} s [Parsons1980, eq. (87)]
        let mut c = M46::zeros();
        c[(1, 0)] = dt * zp[1];
        c[(1, 1)] = dt * zp[2];
        c[(1, 2)] = dt * dp;
        c[(2, 3)] = dt * zp[1];
        c[(2, 4)] = dt * zp[2];
        c[(2, 5)] = dt * dp;
        let d = V4::new(
            zp[0] + dt * zp[1],
            zp[1],
            zp[2],
            zp[3] + dt * (zp[0] - zp[2]),
        );
        let z_tilde = z - d; // [Parsons1980, eq. (90)]
        let pc = self.p_cov;
        let s = c * pc * c.transpose() + self.matrices.r_eq;
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let gain = pc * c.transpose() * s_inv; // [Parsons1980, eq. (102)]
        let p_new = pc + self.phi - gain * c * pc; // [Parsons1980, eq. (103)]
        let innovation = z_tilde - c * self.p_hat; // [Parsons1980, eq. (94)]
        let bias = (p_new - self.phi) * self.matrices.g * self.p_hat;
        self.p_hat += gain * innovation + bias; // [Parsons1980, eq. (114)]
        self.p_cov = (p_new + p_new.transpose()) * 0.5;
        self.estimates += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// The precomputed matrices ([DERIVED] from [Parsons1980, sec. 5.1], time-invariant design,
    /// [Parsons1980, Table 9] noise, Δt = 0.005), to the 4–5 digits of the reference values (0.05 % relative).
    #[test]
    fn precomputed_matrices_of_section_2_13() {
        let m = MveParams::default().matrices().unwrap();
        let tol = 5e-4;
        for (i, v) in [2.5952e-7, 1.5443e-7, 1.6555e-7, 1.0130e-6]
            .iter()
            .enumerate()
        {
            assert!(rel(m.r[(i, i)], *v) < tol, "R{i}");
        }
        assert!(rel(m.b[(3, 3)], 1.0131e-6) < tol);
        assert!(rel(m.b[(0, 1)], 7.7217e-10) < tol && rel(m.b[(2, 3)], -8.2776e-10) < tol);
        assert_eq!(m.b[(0, 3)], 0.0);
        assert!(rel(m.gqg[(1, 1)], 2.2833e-7) < tol);
        assert!(rel(m.gqg[(1, 2)], 1.0982e-8) < tol);
        assert!(rel(m.gqg[(2, 2)], 5.4288e-9) < tol);
        assert!(rel(m.u[(1, 1)], 1.7350e-10) < tol);
        assert!(rel(m.u[(1, 2)], -2.1488e-11) < tol);
        assert!(rel(m.u[(2, 2)], 2.6687e-12) < tol);
        for (i, v) in [5.1904e-7, 5.3737e-7, 3.3653e-7, 2.0261e-6]
            .iter()
            .enumerate()
        {
            assert!(rel(m.r_eq[(i, i)], *v) < tol, "R_eq{i}");
        }
        assert!(rel(m.r_eq[(1, 2)], 1.0960e-8) < tol);
        for ((i, j), v) in [
            ((0, 0), 7.1894e-6),
            ((0, 3), -2.3414e-7),
            ((1, 1), 7.707e-6),
            ((1, 4), -2.510e-7),
            ((3, 0), -2.3414e-7),
            ((3, 3), 1.148e-5),
            ((4, 1), -2.510e-7),
            ((4, 4), 1.2306e-5),
        ] {
            assert!(
                rel(m.g[(i, j)], v) < 1e-3,
                "G({i},{j}) = {} vs {v}",
                m.g[(i, j)]
            );
        }
        // time-varying design: α² = (half the [Parsons1980, Table 2] range)²
        let alpha = [0.1504f64, 3.0783, 0.2431, 0.1427, 0.2556, 0.0332];
        let tv = MveParams {
            alpha2: alpha.map(|a| a * a),
            phi: PHI_TABLE_17,
            p0: [0.0; 6],
            ..Default::default()
        };
        let m = tv.matrices().unwrap();
        assert!(rel(m.u[(1, 1)], 2.1280e-10) < 1e-3 && rel(m.u[(2, 2)], 3.0176e-12) < 1e-3);
    }

    /// Noise-free data from the exact Euler model with the true coefficients: the estimator moves
    /// from the deep-water values toward the truth (f23, f25, f32 are the identifiable ones).
    #[test]
    fn converges_on_noise_free_data() {
        use crate::hull::tokyo_maru::{TABLE_2, T_R};
        let truth = TABLE_2[2];
        let (f, g, _) = truth.eq11(T_R);
        let mut mve = Mve::new(MveParams::default(), parameters_of(&TABLE_2[4])).unwrap();
        let mut x = SVector::<f64, 5>::zeros();
        let dt = 0.005;
        for k in 0..2000 {
            let t = k as f64 * dt;
            let u = if ((t / 0.25).floor() as i64) % 2 == 0 {
                -0.5
            } else {
                0.5
            };
            mve.sample([x[0], x[1], x[2], x[3]], x[4]);
            x += (f * x + g * u) * dt;
        }
        let p = mve.estimate();
        eprintln!("noise-free MVE after 10 L: {p:?}");
        assert_eq!(mve.estimates(), 199);
        assert!((p[1] - truth.f23).abs() < 0.1 * truth.f23, "f23 {}", p[1]);
        assert!(
            (p[2] - truth.f25).abs() < 0.1 * truth.f25.abs(),
            "f25 {}",
            p[2]
        );
    }

    /// S14 ([Parsons1980, Table 16, Figs. 28–31]): truth at H/T = 1.89 from t′ = 0; controller, filter model and
    /// estimator initialised for ∞; dither ±0.5 rad, period 0.5 L, in the first 2.5 L of every
    /// 6.25 L; the path controller applies the estimates at the end of each dither window ([Parsons1980, Table 10]
    /// rule) and the path Kalman filter takes the same coefficients; [Parsons1980, Table 3] noise in the control
    /// loop, [Parsons1980, Table 9] noise for the estimator; ℓ = 10, P0 of [Parsons1980, eq. (117)], Φ = 0, α = 0; 10 L (200
    /// estimates). Results are seed-dependent (the report's seeds are unknown); asserted against
    /// the ranges of an independent implementation (3 seeds) and the printed values:
    /// max η′ 0.178–0.205 derived / 0.1738 printed (OCR "0.01738") → asserted 0.15–0.23;
    /// final f̂23 5.47–6.41 derived / 5.4886 printed → 4.9–6.8; RMS(118) of f̂23 11.7–17.0 / 12.83
    /// → 8–20; f22, f33, f35 "slow and generally ineffective": stay within 0.25 of their initial
    /// values (printed final −1.93, −0.66, −0.162 from −1.95, −0.64, −0.162).
    #[test]
    fn s14_constant_bottom_with_noise() {
        use crate::controllers::path::{
            Adaptation, Dither, PathController, PathControllerParams, PathInputs,
        };
        use crate::hull::tokyo_maru::{L, TABLE_2, T_R, U};
        use crate::observers::path_kalman::PathKalmanFilter;
        use crate::observers::path_model::PathDesignModel;
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let truth = TABLE_2[2];
        let deep = TABLE_2[4];
        let (fs, gs, _) = truth.eq11(T_R);
        for seed in [1u64, 2, 3] {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let n01 = Normal::new(0.0, 1.0).unwrap();
            let params = PathControllerParams {
                design_depth_ratio: f64::INFINITY,
                adaptation: Adaptation::Estimated,
                dither: Dither {
                    enabled: true,
                    ..Dither::default()
                },
                ..Default::default()
            };
            let mut ctl = PathController::new(params).unwrap();
            let design = |c| PathDesignModel {
                coefficients: c,
                ..params.design
            };
            let mut kf = PathKalmanFilter::new(design(deep), [0.0; 7]).unwrap();
            let mut mve = Mve::new(MveParams::default(), parameters_of(&deep)).unwrap();
            let dt = 0.005;
            let h = dt * L / U;
            let mut x = SVector::<f64, 5>::zeros();
            let (mut eta_max, mut t_max) = (0.0f64, 0.0);
            let mut sq = [0.0f64; 6];
            let truth_p = parameters_of(&truth);
            let mut updates = 0;
            let sigma3 = [1.611e-3, 7.563e-3, 9.549e-3];
            for k in 0..2000 {
                let xh = *kf.estimate();
                let inputs = PathInputs {
                    heading: xh[0],
                    yaw_rate: xh[1] * U / L,
                    drift_angle: xh[2],
                    cross_track: xh[3] * L,
                    rudder: xh[4],
                    yaw_moment_prime: xh[5],
                    sway_force_prime: xh[6],
                    depth_ratio: 1.89,
                    estimates: mve.estimate(),
                };
                if k == 0 {
                    ctl.start(&inputs);
                }
                let u = ctl.command(&inputs);
                let z = SVector::<f64, 3>::new(
                    x[0] + sigma3[0] * n01.sample(&mut rng),
                    x[1] + sigma3[1] * n01.sample(&mut rng),
                    x[3] + sigma3[2] * n01.sample(&mut rng),
                );
                let zm: [f64; 4] =
                    std::array::from_fn(|i| x[i] + SIGMA_TABLE_9[i] * n01.sample(&mut rng));
                if mve.sample(zm, x[4]) {
                    let p = mve.estimate();
                    for i in 0..6 {
                        sq[i] += (p[i] - truth_p[i]).powi(2);
                    }
                }
                x += (fs * x + gs * u) * dt;
                kf.euler_step_prime(&z, u, dt);
                ctl.step(&inputs, h).unwrap();
                if ctl.updates() != updates {
                    updates = ctl.updates();
                    kf.set_design(design(*ctl.coefficients())).unwrap();
                }
                if x[3].abs() > eta_max {
                    eta_max = x[3].abs();
                    t_max = (k + 1) as f64 * dt;
                }
            }
            let p = mve.estimate();
            let rms: [f64; 6] = sq.map(f64::sqrt);
            eprintln!(
                "S14 seed {seed}: max eta' {eta_max:.4} at {t_max:.2}, updates {updates}, final {p:.4?}, RMS(118) {rms:.3?}"
            );
            assert!((0.15..=0.23).contains(&eta_max), "eta {eta_max}");
            assert!((4.9..=6.8).contains(&p[1]), "f23 {}", p[1]);
            assert!((8.0..=20.0).contains(&rms[1]), "RMS f23 {}", rms[1]);
            assert!((p[0] - deep.f22).abs() < 0.25 && (p[4] - deep.f33).abs() < 0.25);
            assert!((p[5] - deep.f35).abs() < 0.01);
            assert!(updates >= 1);
        }
    }

    #[test]
    fn bad_settings_are_errors() {
        let p = MveParams {
            interval: 1,
            ..Default::default()
        };
        assert!(Mve::new(p, [0.0; 6]).is_err());
    }
}
