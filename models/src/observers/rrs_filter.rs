//! The RRS filters of [Klugt1987]: roll filter [Klugt1987, App. E], yaw filter [Klugt1987, App. F]
//! and adaptive speed filter [Klugt1987, sec. 4.5 and 5.5.3], discretised with the forward-Euler
//! scheme of [Klugt1987, eqs. (6.2)-(6.4)].
//!
//! # Source
//! [Klugt1987, sec. 4.4-4.5, 5.5 and 6.3, App. E-F, Tables 5.2-5.4].
//!
//! # Discretisation [Klugt1987, eqs. (6.1)-(6.4)]
//! 1/s → T/(z − 1): `x̂(k) = x̂(k−1) + T [A x̂(k−1) + B u(k−1) + K e(k−1)]`,
//! `e(k) = y(k) − C x̂(k)`: a one-step predictor, so the estimate at k uses only data up to k−1.
//! The sample time T is not given in the thesis; default 0.1 s, a parameter. A
//! co-simulation step h is covered by ⌈h/T⌉ equal sub-steps with the inputs held.
//!
//! # Roll filter [Klugt1987, App. E, sec. 4.4.2 and 6.3.1]
//! Reduced model x = (φ, φ̇, x_v) with the constant heel x_v as integrated white noise in the
//! *measurement*: `y = φ + x_v + v`; A = [[0,1,0],[−ω_n²,−2z_nω_n,0],[0,0,0]],
//! B = (0, ω_n², 0)ᵀ, D = [[0,0],[ω_n²,0],[0,1]], C = (1 0 1), Q = diag(q1, q2) normalised by
//! E[v²] (R = 1); K = PCᵀ from the dual CARE (equals the limit of [Klugt1987, eqs. (E.11)-(E.16)], tested). The
//! noise-free rudder→sway submodel v̂_δ' = (−v̂_δ + k_dv δ_φ)/τ_v is propagated open loop, and the
//! roll-moment input is u_φ = k_dp δ_φ + k_vp v̂_δ (our reading of [Klugt1987, Figs. 4.9 and 6.3]).
//! The input is the roll controller's output δ_φ [Klugt1987, sec. 4.4.1]. Gains fixed (computed
//! at initialization, [Klugt1987, sec. 6.3.1]).
//!
//! # Yaw filter [Klugt1987, App. F, sec. 4.4.3, 5.5.4 and 6.3.2]
//! State (ψ, ψ̇, x3 = yaw-moment bias in rate units, x4 = high-frequency state), realised
//! second-order Nomoto model: A = [[0,1,0,0],[0,−1/τ_r,1/τ_r,0],[0,0,0,0],[0,0,0,−1/τ_f]],
//! B = (0, 1/τ_r, 0, 0)ᵀ with u = k_dr δ_ψ (+ k_vr x̂1 with the optional noise-free sway
//! submodel), D = [[0,0,0],[1/τ_r,0,0],[0,1,0],[0,0,1/τ_f]], C = (1 0 0 −1), F = (1 1),
//! y = Cx + w3 + v (w3 shared with the process ⇒ correlated noise S). Gains
//! K = (PCᵀ + DSFᵀ)(FRFᵀ)⁻¹ [Klugt1987, eqs. (F.7)-(F.11)] computed on line by the innovation
//! process ([Klugt1987, eqs. (6.5)-(6.6)],
//! L = 1/T: one Euler step of the Riccati ODE per sample), started from the CARE solution.
//! Adaptive E[w3²] [Klugt1987, eq. (5.12)]: E_c = E[z_hf²]/E[z_lf²] from the prediction error z
//! split by a complementary first-order filter at 1/τ_f (the split filter of
//! [Klugt1987, Fig. 5.13] is lost in the OCR; this is our reading), variances by first-order
//! low-pass filtered squares; E*[w3²] = E_c/d with d = 1 as realised [Klugt1987, sec. 6.3.2] or
//! 7 [Klugt1987, sec. 5.5.4]. The input is the course controller's output δ_ψ
//! [Klugt1987, sec. 4.4.1].
//!
//! **τ_f reading.** The thesis writes τ_f = a·τ_r [Klugt1987, eq. (5.13)] and τ_f = a/τ_r
//! [Klugt1987, eq. (6.7)]; the text (cut-off a/τ_r rad/s [Klugt1987, sec. 6.3.2], corner 1/τ_f
//! [Klugt1987, sec. 4.4.3], and the adjustment rule after [Klugt1987, eq. (5.13)]) supports
//! **τ_f = τ_r/a**, a = 5 [Klugt1987, eq. (6.7)]: that is the default, with a a parameter. The
//! [DERIVED] gain check K = (0.29589, 0.04623, 0.00995, 0.02601) (computed from [Klugt1987, App. F], not
//! printed in the thesis) uses τ_f = 5.9 s = 5·τ_r (τ_r = 1.18 s), i.e. a = 0.2 in this reading.
//!
//! **L matrix.** [Klugt1987, eq. (6.5)] prints L = diag(5/T, 5/T, 1/T, 1/T) for a 10-element
//! x_m: the mapping is unrecoverable; L = 1/T for all elements is used.
//!
//! # Speed filter [Klugt1987, sec. 4.5.1, 5.5.3 and 6.3.3]
//! C-filter: first-order low-pass with τ0 = sqrt(E[v²]/E[w²]) [Klugt1987, eqs. (4.90), (5.9)].
//! Adaptation on the prediction error e_z = U_meas − Û with threshold p1 = c·σ_z
//! [Klugt1987, eq. (5.10)]: |e_z| ≤ p1 ⇒
//! τ_f = τ0, else τ_f = τ0 (p1/|e_z|)^n (Q → Q(|e_z|/p1)^{2n}), τ_f ≥ τ_f,min (Q ≤ Q_max);
//! n = 0 C, 1 L, 2 Q, ∞ S (switch to τ_f,min). Update Û(k) = Û(k−1) + T/τ_f (U(k−1) − Û(k−1)).
//! The realised autopilot is the L-filter with p1 = 2 [Klugt1987, sec. 6.3.3]; the study of
//! [Klugt1987, Tables 5.2-5.4] used τ0 = 100 s, τ_f,min = 10 s. The second-order (HF-coloured
//! noise) gains of [Klugt1987, eqs. (4.100)-(4.101)] are [`second_order_speed_gains`].

use crate::error::{check_finite, check_non_negative, check_positive, require, ParamError};
use crate::riccati::{self, RiccatiError};
use nalgebra::{DMatrix, SMatrix, SVector};
use serde::{Deserialize, Serialize};

// ---------------------------------------------------------------------------------------------
// Roll filter
// ---------------------------------------------------------------------------------------------

/// Roll-filter parameters (model of [Klugt1987, Table 2.4] at the design speed, noise ratios q1, q2).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RollFilterParams {
    /// Roll natural frequency ω_n [rad/s] and relative damping z_n.
    pub omega_n: f64,
    pub z_n: f64,
    /// Rudder→roll gain k_dp, sway→roll gain k_vp, rudder→sway gain k_dv, sway time constant τ_v.
    pub k_dp: f64,
    pub k_vp: f64,
    pub k_dv: f64,
    pub tau_v: f64,
    /// q1 = E[w1²]/E[v²] (roll system noise) and q2 = E[w2²]/E[v²] (heel-offset drift).
    pub q1: f64,
    pub q2: f64,
}

impl RollFilterParams {
    /// [Klugt1987, Table 2.4] at speed `u` [m/s] with noise ratios (q1, q2). (No numeric q1, q2 are given in
    /// the thesis; (1, 0.01) is the first case of the [DERIVED] gain check in the tests.)
    pub fn table_2_4(u: f64, q1: f64, q2: f64) -> Self {
        let c = crate::hull::rrs_ship::RrsSpeedLaws::table_2_4().at(u);
        RollFilterParams {
            omega_n: c.omega_n,
            z_n: c.z_n,
            k_dp: c.k_dp,
            k_vp: c.k_vp,
            k_dv: c.k_dv,
            tau_v: c.tau_v,
            q1,
            q2,
        }
    }

    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("omega_n", self.omega_n)?;
        check_non_negative("z_n", self.z_n)?;
        check_finite("k_dp", self.k_dp)?;
        check_finite("k_vp", self.k_vp)?;
        check_finite("k_dv", self.k_dv)?;
        check_positive("tau_v", self.tau_v)?;
        check_positive("roll_q1", self.q1)?;
        check_positive("roll_q2", self.q2)?;
        Ok(())
    }
}

/// [Klugt1987, App. E] steady-state roll-filter gains (k1, k2, k3) for (ω_n, z_n, q1, q2), R = 1.
pub fn roll_filter_gains(
    omega_n: f64,
    z_n: f64,
    q1: f64,
    q2: f64,
) -> Result<[f64; 3], RiccatiError> {
    let w2 = omega_n * omega_n;
    #[rustfmt::skip]
    let a = DMatrix::from_row_slice(3, 3, &[
        0.0, 1.0, 0.0,
        -w2, -2.0 * z_n * omega_n, 0.0,
        0.0, 0.0, 0.0,
    ]);
    let d = DMatrix::from_row_slice(3, 2, &[0.0, 0.0, w2, 0.0, 0.0, 1.0]);
    let c = DMatrix::from_row_slice(1, 3, &[1.0, 0.0, 1.0]);
    let q = DMatrix::from_row_slice(2, 2, &[q1, 0.0, 0.0, q2]);
    let r = DMatrix::from_element(1, 1, 1.0);
    let (k, _) = riccati::kalman_bucy(&a, &c, &d, &q, &r)?;
    Ok([k[0], k[1], k[2]])
}

/// The roll filter. State (φ̂, φ̂̇, x̂_v, v̂_δ).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RollFilter {
    params: RollFilterParams,
    k: [f64; 3],
    x: [f64; 4],
    innovation: f64,
}

impl RollFilter {
    pub fn new(params: RollFilterParams) -> Result<Self, String> {
        params.validate()?;
        let k = roll_filter_gains(params.omega_n, params.z_n, params.q1, params.q2)
            .map_err(|e| format!("roll-filter gains: {e}"))?;
        Ok(RollFilter {
            params,
            k,
            x: [0.0; 4],
            innovation: 0.0,
        })
    }

    pub fn params(&self) -> &RollFilterParams {
        &self.params
    }

    /// Gains (k1, k2, k3).
    pub fn gains(&self) -> [f64; 3] {
        self.k
    }

    /// (φ̂, φ̂̇, x̂_v, v̂_δ).
    pub fn state(&self) -> [f64; 4] {
        self.x
    }

    pub fn set_state(&mut self, x: [f64; 4]) {
        self.x = x;
    }

    /// Prediction error e = y − (φ̂ + x̂_v) of the last sample.
    pub fn innovation(&self) -> f64 {
        self.innovation
    }

    /// One sample [Klugt1987, eq. (6.2)]: measured roll `y` and roll-controller output `delta_phi`, both of
    /// sample k−1; advances the estimate to k.
    #[inline]
    pub fn sample(&mut self, y: f64, delta_phi: f64, t: f64) {
        let p = &self.params;
        let [phi, dphi, xv, vd] = self.x;
        let e = y - (phi + xv);
        let w2 = p.omega_n * p.omega_n;
        let u = p.k_dp * delta_phi + p.k_vp * vd;
        let d_phi = dphi + self.k[0] * e;
        let d_dphi = -w2 * phi - 2.0 * p.z_n * p.omega_n * dphi + w2 * u + self.k[1] * e;
        let d_xv = self.k[2] * e;
        let d_vd = (-vd + p.k_dv * delta_phi) / p.tau_v;
        self.x = [
            phi + t * d_phi,
            dphi + t * d_dphi,
            xv + t * d_xv,
            vd + t * d_vd,
        ];
        self.innovation = e;
    }
}

// ---------------------------------------------------------------------------------------------
// Yaw filter
// ---------------------------------------------------------------------------------------------

/// Yaw-filter parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct YawFilterParams {
    /// Nomoto time constant τ_r [s] and rudder gain k_dr (u = k_dr δ_ψ).
    pub tau_r: f64,
    pub k_dr: f64,
    /// τ_f = τ_r / a (reading of the module docs); a = 5 by default.
    pub a: f64,
    /// E[w1²] (yaw system noise), E[w2²] (bias drift), E[v²] (white measurement noise).
    pub e_w1: f64,
    pub e_w2: f64,
    pub e_v: f64,
    /// E[w3²]: the fixed value, or the start value when adaptive.
    pub e_w3: f64,
    /// Adapt E*[w3²] = E_c / `ec_divisor` [Klugt1987, eq. (5.12)].
    pub adaptive: bool,
    /// 1 as realised [Klugt1987, sec. 6.3.2]; 7 as suggested in [Klugt1987, sec. 5.5.4].
    pub ec_divisor: f64,
    /// Time constant [s] of the low-pass filters that estimate E[z_hf²] and E[z_lf²].
    pub variance_time_constant: f64,
    /// Bounds on the adapted E*[w3²].
    pub e_w3_min: f64,
    pub e_w3_max: f64,
    /// Optional noise-free rudder→sway submodel (third-order yaw model, [Klugt1987, sec. 4.4.3]): u = k_dr δ_ψ +
    /// k_vr x̂1, x̂1' = (−x̂1 + k_dv δ_ψ)/τ_v. With `third_order` false (the realised second-order
    /// model, [Klugt1987, sec. 6.3.2]) k_vr is not used.
    pub third_order: bool,
    pub k_vr: f64,
    pub k_dv: f64,
    pub tau_v: f64,
}

impl YawFilterParams {
    /// The realised settings [Klugt1987, sec. 6.3.2]: E[v²] = 0.01, E[w1²] = 0.1, E[w2²] = 1e-4, adaptive E[w3²]
    /// (start 1), a = 5, with the [Klugt1987, Table 2.4] Nomoto parameters at speed `u` [m/s].
    pub fn realised(u: f64) -> Self {
        let c = crate::hull::rrs_ship::RrsSpeedLaws::table_2_4().at(u);
        YawFilterParams {
            tau_r: c.tau_r,
            k_dr: c.k_dr,
            a: 5.0,
            e_w1: 0.1,
            e_w2: 1e-4,
            e_v: 0.01,
            e_w3: 1.0,
            adaptive: true,
            ec_divisor: 1.0,
            variance_time_constant: 60.0,
            e_w3_min: 1e-6,
            e_w3_max: 1e6,
            third_order: false,
            k_vr: c.k_vr,
            k_dv: c.k_dv,
            tau_v: c.tau_v,
        }
    }

    /// τ_f = τ_r / a.
    pub fn tau_f(&self) -> f64 {
        self.tau_r / self.a
    }

    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("tau_r", self.tau_r)?;
        check_finite("k_dr", self.k_dr)?;
        check_positive("a", self.a)?;
        check_non_negative("e_w1", self.e_w1)?;
        check_non_negative("e_w2", self.e_w2)?;
        check_non_negative("e_v", self.e_v)?;
        check_positive("e_w3", self.e_w3)?;
        check_positive("ec_divisor", self.ec_divisor)?;
        check_positive("variance_time_constant", self.variance_time_constant)?;
        check_positive("e_w3_min", self.e_w3_min)?;
        check_positive("e_w3_max", self.e_w3_max)?;
        require(
            self.e_w3_min <= self.e_w3_max,
            "e_w3_min",
            self.e_w3_min,
            "must be <= e_w3_max",
        )?;
        check_finite("k_vr", self.k_vr)?;
        check_finite("k_dv", self.k_dv)?;
        check_positive("tau_v", self.tau_v)?;
        Ok(())
    }
}

type M4 = SMatrix<f64, 4, 4>;
type V4 = SVector<f64, 4>;

/// (A, DQDᵀ, N = DSFᵀ, r = FRFᵀ) of [Klugt1987, App. F] for (τ_r, τ_f, E1, E2, E3, Ev).
fn yaw_matrices(tau_r: f64, tau_f: f64, e1: f64, e2: f64, e3: f64, ev: f64) -> (M4, M4, V4, f64) {
    let mut a = M4::zeros();
    a[(0, 1)] = 1.0;
    a[(1, 1)] = -1.0 / tau_r;
    a[(1, 2)] = 1.0 / tau_r;
    a[(3, 3)] = -1.0 / tau_f;
    let mut qd = M4::zeros();
    qd[(1, 1)] = e1 / (tau_r * tau_r);
    qd[(2, 2)] = e2;
    qd[(3, 3)] = e3 / (tau_f * tau_f);
    let n = V4::new(0.0, 0.0, 0.0, e3 / tau_f);
    (a, qd, n, e3 + ev)
}

/// [Klugt1987, App. F] steady-state yaw-filter gains (k1..k4) and P for τ_r, τ_f and the noise intensities.
pub fn yaw_filter_gains(
    tau_r: f64,
    tau_f: f64,
    e1: f64,
    e2: f64,
    e3: f64,
    ev: f64,
) -> Result<([f64; 4], M4), RiccatiError> {
    let (a, qd, n, r) = yaw_matrices(tau_r, tau_f, e1, e2, e3, ev);
    let dm = |m: &M4| DMatrix::from_column_slice(4, 4, m.as_slice());
    let c = DMatrix::from_row_slice(1, 4, &[1.0, 0.0, 0.0, -1.0]);
    let nn = DMatrix::from_column_slice(4, 1, n.as_slice());
    let (k, p) = riccati::kalman_bucy_correlated(
        &dm(&a),
        &c,
        &dm(&qd),
        &DMatrix::from_element(1, 1, r),
        &nn,
    )?;
    let mut pm = M4::zeros();
    pm.copy_from_slice(p.as_slice());
    Ok(([k[0], k[1], k[2], k[3]], pm))
}

/// The yaw filter. State (ψ̂, ψ̂̇, x̂3, x̂4) plus the optional noise-free x̂1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct YawFilter {
    params: YawFilterParams,
    /// Riccati P of the innovation process and the gains it yields.
    p: M4,
    k: V4,
    x: V4,
    x1: f64,
    innovation: f64,
    /// E*[w3²] in use, low-frequency part of z, and the variance estimates.
    e_w3: f64,
    z_lf: f64,
    var_lf: f64,
    var_hf: f64,
}

impl YawFilter {
    /// Gains and P start at the CARE solution for the start E[w3²].
    pub fn new(params: YawFilterParams) -> Result<Self, String> {
        params.validate()?;
        let (k, p) = yaw_filter_gains(
            params.tau_r,
            params.tau_f(),
            params.e_w1,
            params.e_w2,
            params.e_w3,
            params.e_v,
        )
        .map_err(|e| format!("yaw-filter gains: {e}"))?;
        Ok(YawFilter {
            params,
            p,
            k: V4::from_row_slice(&k),
            x: V4::zeros(),
            x1: 0.0,
            innovation: 0.0,
            e_w3: params.e_w3,
            z_lf: 0.0,
            var_lf: 0.0,
            var_hf: 0.0,
        })
    }

    pub fn params(&self) -> &YawFilterParams {
        &self.params
    }

    /// Replaces the model parameters (e.g. on-line τ_r, k_dr estimates or a new a); the state,
    /// P and the adaptation carry over.
    pub fn set_params(&mut self, params: YawFilterParams) -> Result<(), String> {
        params.validate()?;
        if params.adaptive != self.params.adaptive || !params.adaptive {
            self.e_w3 = params.e_w3;
        }
        self.params = params;
        Ok(())
    }

    /// Gains (k1..k4) in use.
    pub fn gains(&self) -> [f64; 4] {
        [self.k[0], self.k[1], self.k[2], self.k[3]]
    }

    /// (ψ̂, ψ̂̇, x̂3, x̂4).
    pub fn state(&self) -> [f64; 4] {
        [self.x[0], self.x[1], self.x[2], self.x[3]]
    }

    pub fn set_state(&mut self, x: [f64; 4]) {
        self.x = V4::from_row_slice(&x);
    }

    /// Prediction error z = y − (ψ̂ − x̂4) of the last sample.
    pub fn innovation(&self) -> f64 {
        self.innovation
    }

    /// E*[w3²] in use.
    pub fn e_w3(&self) -> f64 {
        self.e_w3
    }

    /// E_c = E[z_hf²]/E[z_lf²] (0 before any data).
    pub fn e_c(&self) -> f64 {
        if self.var_lf > 0.0 {
            self.var_hf / self.var_lf
        } else {
            0.0
        }
    }

    /// Riccati P of the innovation process.
    pub fn covariance(&self) -> &M4 {
        &self.p
    }

    /// One sample: measured heading `y` and course-controller output `delta_psi` of sample k−1.
    /// Order: innovation; state update with the gains of k−1 [Klugt1987, eq. (6.2)]; adaptation of E*[w3²];
    /// one innovation-process step ([Klugt1987, eq. (6.5)] with L = 1/T) giving the gains for the next sample.
    #[inline]
    pub fn sample(&mut self, y: f64, delta_psi: f64, t: f64) {
        let p = self.params;
        let tau_f = p.tau_f();
        let z = y - (self.x[0] - self.x[3]);
        let u = p.k_dr * delta_psi + if p.third_order { p.k_vr * self.x1 } else { 0.0 };
        let (a, qd, n, r) = yaw_matrices(p.tau_r, tau_f, p.e_w1, p.e_w2, self.e_w3, p.e_v);
        let mut b = V4::zeros();
        b[1] = 1.0 / p.tau_r;
        let dx = a * self.x + b * u + self.k * z;
        self.x += dx * t;
        if p.third_order {
            self.x1 += t * (-self.x1 + p.k_dv * delta_psi) / p.tau_v;
        }
        self.innovation = z;
        // [Klugt1987, eq. (5.12)]: complementary first-order split at 1/τ_f, low-pass filtered squares.
        let alpha = (t / tau_f).min(1.0);
        self.z_lf += alpha * (z - self.z_lf);
        let z_hf = z - self.z_lf;
        let beta = (t / p.variance_time_constant).min(1.0);
        self.var_lf += beta * (self.z_lf * self.z_lf - self.var_lf);
        self.var_hf += beta * (z_hf * z_hf - self.var_hf);
        if p.adaptive && self.var_lf > 0.0 {
            self.e_w3 = (self.var_hf / self.var_lf / p.ec_divisor).clamp(p.e_w3_min, p.e_w3_max);
        }
        // Innovation process: Ṗ = AP + PAᵀ + DQDᵀ − K(PCᵀ + N)ᵀ, K = (PCᵀ + N)/r.
        let (a, qd, n, r) = if p.adaptive {
            yaw_matrices(p.tau_r, tau_f, p.e_w1, p.e_w2, self.e_w3, p.e_v)
        } else {
            (a, qd, n, r)
        };
        let pc = V4::new(
            self.p[(0, 0)] - self.p[(0, 3)],
            self.p[(1, 0)] - self.p[(1, 3)],
            self.p[(2, 0)] - self.p[(2, 3)],
            self.p[(3, 0)] - self.p[(3, 3)],
        ) + n;
        let k = pc / r;
        let dp = a * self.p + self.p * a.transpose() + qd - k * pc.transpose();
        let next = self.p + dp * t;
        self.p = (next + next.transpose()) * 0.5;
        let pc = V4::new(
            self.p[(0, 0)] - self.p[(0, 3)],
            self.p[(1, 0)] - self.p[(1, 3)],
            self.p[(2, 0)] - self.p[(2, 3)],
            self.p[(3, 0)] - self.p[(3, 3)],
        ) + n;
        self.k = pc / r;
    }
}

// ---------------------------------------------------------------------------------------------
// Speed filter
// ---------------------------------------------------------------------------------------------

/// Adaptation law of the speed filter [Klugt1987, sec. 5.5.3]: exponent n of τ_f = τ0 (p1/|e_z|)^n.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SpeedAdaptation {
    /// n = 0: C-filter (no adaptation).
    Constant,
    /// n = 1: L-filter (the realised autopilot, [Klugt1987, sec. 6.3.3]).
    Linear,
    /// n = 2: Q-filter (the study's best compromise, c = 3).
    Quadratic,
    /// n = ∞: S-filter, switches between τ0 and τ_f,min.
    Switch,
}

/// Speed-filter parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpeedFilterParams {
    /// τ0 = sqrt(E[v²]/E[w²]) [s] (study: 100 s).
    pub tau0: f64,
    /// τ_f,min [s] (Q_max = Q (τ0/τ_f,min)²; study: 10 s).
    pub tau_min: f64,
    /// Threshold factor c and the a-priori standard deviation σ_z of e_z: p1 = c σ_z.
    pub c: f64,
    pub sigma_z: f64,
    pub adaptation: SpeedAdaptation,
}

impl SpeedFilterParams {
    /// The simulation study of [Klugt1987, sec. 5.5.3] (τ0 = 100 s, τ_min = 10 s, σ_z = 1) with law and c.
    pub fn study(adaptation: SpeedAdaptation, c: f64) -> Self {
        SpeedFilterParams {
            tau0: 100.0,
            tau_min: 10.0,
            c,
            sigma_z: 1.0,
            adaptation,
        }
    }

    /// The realised autopilot [Klugt1987, sec. 6.3.3]: L-filter with p1 = 2 (c = 2, σ_z = 1 speed unit); τ0 and
    /// τ_min are not given, the study's 100 s and 10 s are used.
    pub fn realised() -> Self {
        Self::study(SpeedAdaptation::Linear, 2.0)
    }

    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("speed_tau0", self.tau0)?;
        check_positive("speed_tau_min", self.tau_min)?;
        require(
            self.tau_min <= self.tau0,
            "speed_tau_min",
            self.tau_min,
            "must be <= speed_tau0",
        )?;
        check_non_negative("speed_c", self.c)?;
        check_positive("speed_sigma_z", self.sigma_z)?;
        Ok(())
    }

    /// τ_f for prediction error `e`.
    #[inline]
    pub fn time_constant(&self, e: f64) -> f64 {
        let p1 = self.c * self.sigma_z;
        let ae = e.abs();
        if ae <= p1 {
            return self.tau0;
        }
        let tau = match self.adaptation {
            SpeedAdaptation::Constant => self.tau0,
            SpeedAdaptation::Linear => self.tau0 * (p1 / ae),
            SpeedAdaptation::Quadratic => self.tau0 * (p1 / ae).powi(2),
            SpeedAdaptation::Switch => self.tau_min,
        };
        tau.max(self.tau_min)
    }
}

/// The adaptive first-order speed filter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpeedFilter {
    pub params: SpeedFilterParams,
    u_hat: f64,
    tau_f: f64,
    innovation: f64,
}

impl SpeedFilter {
    pub fn new(params: SpeedFilterParams, u0: f64) -> Result<Self, String> {
        params.validate()?;
        Ok(SpeedFilter {
            tau_f: params.tau0,
            params,
            u_hat: u0,
            innovation: 0.0,
        })
    }

    /// Û.
    pub fn estimate(&self) -> f64 {
        self.u_hat
    }

    pub fn set_estimate(&mut self, u: f64) {
        self.u_hat = u;
    }

    /// τ_f used in the last sample.
    pub fn time_constant(&self) -> f64 {
        self.tau_f
    }

    /// e_z = U_meas − Û of the last sample.
    pub fn innovation(&self) -> f64 {
        self.innovation
    }

    /// One sample: Û(k) = Û(k−1) + T/τ_f (U(k−1) − Û(k−1)) (Euler, [Klugt1987, eq. (6.2)]; the gain T/τ_f is
    /// capped at 1).
    #[inline]
    pub fn sample(&mut self, u_meas: f64, t: f64) {
        let e = u_meas - self.u_hat;
        self.tau_f = self.params.time_constant(e);
        self.u_hat += (t / self.tau_f).min(1.0) * e;
        self.innovation = e;
    }
}

/// [Klugt1987, eqs. (4.100)-(4.101)]: gains (k1, k2) of the second-order speed filter with high-pass coloured
/// measurement noise, for E[w²], E[v²] and the colouring time constant τ.
pub fn second_order_speed_gains(e_w: f64, e_v: f64, tau: f64) -> (f64, f64) {
    let k1 = (e_w / e_v).sqrt();
    let k2 = (k1 * tau + 1.0 - (k1 * k1 * tau * tau + 2.0 * k1 * tau).sqrt()) / tau;
    (k1, k2)
}

// ---------------------------------------------------------------------------------------------
// The three filters together
// ---------------------------------------------------------------------------------------------

/// Roll, yaw and speed filter sampled together at T.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RrsFilter {
    pub roll: RollFilter,
    pub yaw: YawFilter,
    pub speed: SpeedFilter,
    /// Sample time T [s].
    pub sample_time: f64,
}

/// Inputs of one sample (held over a co-simulation step).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RrsFilterInputs {
    /// Measured roll φ [rad], heading ψ [rad] and speed U [m/s].
    pub roll: f64,
    pub heading: f64,
    pub speed: f64,
    /// Roll-controller output δ_φ and course-controller output δ_ψ [rad].
    pub roll_rudder: f64,
    pub course_rudder: f64,
}

impl RrsFilter {
    pub fn new(
        roll: RollFilterParams,
        yaw: YawFilterParams,
        speed: SpeedFilterParams,
        sample_time: f64,
        u0: f64,
    ) -> Result<Self, String> {
        check_positive("sample_time", sample_time)?;
        Ok(RrsFilter {
            roll: RollFilter::new(roll)?,
            yaw: YawFilter::new(yaw)?,
            speed: SpeedFilter::new(speed, u0)?,
            sample_time,
        })
    }

    /// Advances `h` seconds in ⌈h/T⌉ equal samples with the inputs held.
    pub fn step(&mut self, inp: &RrsFilterInputs, h: f64) {
        let n = crate::integrate::substeps(h, self.sample_time);
        if n == 0 {
            return;
        }
        let t = h / n as f64;
        for _ in 0..n {
            self.roll.sample(inp.roll, inp.roll_rudder, t);
            self.yaw.sample(inp.heading, inp.course_rudder, t);
            self.speed.sample(inp.speed, t);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::sin;
    use crate::random::NoiseStream;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// [DERIVED] from [Klugt1987, App. E] (not printed in the thesis): ω_n = 0.63, z_n = 0.1058 ([Klugt1987, Table 2.4] at 11 m/s):
    /// (q1, q2) = (1, 0.01) ⇒ K = (0.42488, 0.13275, 0.10000); (10, 0.001) ⇒ (1.20735, 0.76703,
    /// 0.03162); k3 = sqrt(q2). Tolerance: half a unit in the 5th decimal.
    #[test]
    fn roll_filter_gains_app_e() {
        let k = roll_filter_gains(0.63, 0.1058, 1.0, 0.01).unwrap();
        for (a, b) in k.iter().zip([0.42488, 0.13275, 0.10000]) {
            assert!(close(*a, b, 0.5e-5), "{k:?}");
        }
        let k = roll_filter_gains(0.63, 0.1058, 10.0, 0.001).unwrap();
        for (a, b) in k.iter().zip([1.20735, 0.76703, 0.03162]) {
            assert!(close(*a, b, 0.5e-5), "{k:?}");
        }
        assert!(close(k[2], 0.001f64.sqrt(), 1e-10));
        // [Klugt1987, Table 2.4] at 11 m/s gives the same ω_n, z_n
        let p = RollFilterParams::table_2_4(11.0, 1.0, 0.01);
        assert!(close(p.z_n, 0.1058, 1e-12) && p.omega_n == 0.63);
    }

    /// The element equations [Klugt1987, eqs. (E.8)-(E.16)] (the innovation process, forward-integrated from
    /// P = 0) converge to the CARE gains.
    #[test]
    fn roll_innovation_process_e11_e16() {
        let (wn, zn, q1, q2) = (0.63, 0.1058, 1.0, 0.01);
        let mut p = [0.0f64; 7]; // p[1..=6]
        let dt = 0.001;
        let mut k = [0.0; 3];
        for _ in 0..400_000 {
            let k1 = p[2] + p[1];
            let k2 = p[3] + p[5];
            let k3 = p[1] + p[6];
            let w2 = wn * wn;
            let d = [
                0.0,
                p[5] - k1 * p[1] - k1 * p[6],
                2.0 * p[3] - k1 * p[2] - k1 * p[1],
                p[4] - w2 * p[2] - 2.0 * zn * wn * p[3] - k1 * p[3] - k1 * p[5],
                -2.0 * w2 * p[3] - 4.0 * zn * wn * p[4] - k2 * p[3] - k2 * p[5] + w2 * w2 * q1,
                -w2 * p[1] - 2.0 * zn * wn * p[5] - k2 * p[1] - k2 * p[6],
                -k3 * p[1] - k3 * p[6] + q2,
            ];
            for i in 1..7 {
                p[i] += dt * d[i];
            }
            k = [k1, k2, k3];
        }
        let kc = roll_filter_gains(wn, zn, q1, q2).unwrap();
        for i in 0..3 {
            assert!(close(k[i], kc[i], 1e-6), "{k:?} vs {kc:?}");
        }
    }

    /// The roll filter rejects a constant heel: y = φ_true + 0.1 with φ_true a roll oscillation;
    /// after the transient φ̂ follows φ_true and x̂_v → 0.1 (the zero at s = 0 of φ̂/y, derived here).
    #[test]
    fn roll_filter_rejects_constant_heel() {
        let p = RollFilterParams {
            k_dp: 0.0,
            k_vp: 0.0,
            ..RollFilterParams::table_2_4(11.0, 10.0, 0.001)
        };
        let mut f = RollFilter::new(p).unwrap();
        let t = 0.05;
        let mut worst: f64 = 0.0;
        for k in 0..40_000 {
            let time = k as f64 * t;
            let phi = 0.05 * sin(0.63 * time);
            f.sample(phi + 0.1, 0.0, t);
            if time > 1500.0 {
                let phi_next = 0.05 * sin(0.63 * (time + t));
                worst = worst.max((f.state()[0] - phi_next).abs());
            }
        }
        assert!(close(f.state()[2], 0.1, 2e-3), "{:?}", f.state());
        assert!(worst < 0.01, "{worst}");
    }

    /// [DERIVED] from [Klugt1987, App. F] (not printed in the thesis): τ_r = 1.18 s, τ_f = 5.9 s, E1 = 0.1, E2 = 1e-4, E3 = 1,
    /// Ev = 0.01 ⇒ K = (0.29589, 0.04623, 0.00995, 0.02601); k3 = sqrt(E2/(E3 + Ev)).
    /// Tolerance half a unit in the 5th decimal. τ_f = 5.9 s is a = 0.2 in the τ_f = τ_r/a reading.
    #[test]
    fn yaw_filter_gains_app_f() {
        let (k, _) = yaw_filter_gains(1.18, 5.9, 0.1, 1e-4, 1.0, 0.01).unwrap();
        for (a, b) in k.iter().zip([0.29589, 0.04623, 0.00995, 0.02601]) {
            assert!(close(*a, b, 0.5e-5), "{k:?}");
        }
        assert!(close(k[2], (1e-4f64 / 1.01).sqrt(), 1e-10));
        let p = YawFilterParams {
            tau_r: 1.18,
            a: 0.2,
            e_w3: 1.0,
            adaptive: false,
            ..YawFilterParams::realised(11.0)
        };
        let f = YawFilter::new(p).unwrap();
        for (a, b) in f.gains().iter().zip([0.29589, 0.04623, 0.00995, 0.02601]) {
            assert!(close(*a, b, 0.5e-5));
        }
    }

    /// The on-line innovation process (one Euler step of the Riccati ODE per sample) started from
    /// P = 0 converges to the CARE gains of [Klugt1987, eqs. (F.8)-(F.11)].
    #[test]
    fn yaw_innovation_process_converges() {
        let p = YawFilterParams {
            tau_r: 1.18,
            a: 5.0,
            e_w3: 0.5,
            adaptive: false,
            ..YawFilterParams::realised(11.0)
        };
        let mut f = YawFilter::new(p).unwrap();
        let (k_care, _) = yaw_filter_gains(1.18, 1.18 / 5.0, 0.1, 1e-4, 0.5, 0.01).unwrap();
        f.p = M4::zeros();
        for _ in 0..20_000 {
            f.sample(0.0, 0.0, 0.05);
        }
        for (a, b) in f.gains().iter().zip(k_care) {
            assert!(
                close(*a, b, 1e-6 * b.abs().max(1e-3)),
                "{:?} {k_care:?}",
                f.gains()
            );
        }
    }

    /// Speed-filter gains of [Klugt1987, eqs. (4.100)-(4.101)] agree with the CARE with cross term (reference
    /// values computed from the closed form, not printed in the thesis):
    /// (1e-4, 1, 20) ⇒ (0.01, 0.026834); (1e-2, 1, 5) ⇒ (0.1, 0.076393); (1, 0.5, 3) ⇒
    /// (1.41421, 0.032085).
    #[test]
    // 1.41421 is the rounded reference value, not an approximation of √2 to be replaced
    #[allow(clippy::approx_constant)]
    fn second_order_speed_filter_gains() {
        for (ew, ev, tau, k1, k2) in [
            (1e-4, 1.0, 20.0, 0.01, 0.026834),
            (1e-2, 1.0, 5.0, 0.1, 0.076393),
            (1.0, 0.5, 3.0, 1.41421, 0.032085),
        ] {
            let (a1, a2) = second_order_speed_gains(ew, ev, tau);
            assert!(close(a1, k1, 0.5e-5) && close(a2, k2, 0.5e-6), "{a1} {a2}");
            // CARE: A = [[0,0],[0,−1/τ]], DQDᵀ = diag(E_w, E_v/τ²), C = (1 −1), R = E_v,
            // N = D S = (0, E_v/τ) (w = (w, v), v shared with the measurement)
            let a = DMatrix::from_row_slice(2, 2, &[0.0, 0.0, 0.0, -1.0 / tau]);
            let c = DMatrix::from_row_slice(1, 2, &[1.0, -1.0]);
            let qd = DMatrix::from_row_slice(2, 2, &[ew, 0.0, 0.0, ev / (tau * tau)]);
            let n = DMatrix::from_row_slice(2, 1, &[0.0, ev / tau]);
            let (k, _) =
                riccati::kalman_bucy_correlated(&a, &c, &qd, &DMatrix::from_element(1, 1, ev), &n)
                    .unwrap();
            assert!(close(k[0], a1, 1e-9), "{k}");
            assert!(close(k[1], a2, 1e-9), "{k}");
        }
    }

    /// One 500 s step run of the study [Klugt1987, sec. 5.5.3]: U = 10 + v (v ~ N(0, 1) per sample), Û(0) = 0,
    /// sample time `t`. Returns (mean square of u − Û, t_5% = first time |u − Û| < 0.5).
    fn step_run(params: SpeedFilterParams, t: f64, seed: u64) -> (f64, f64) {
        let mut f = SpeedFilter::new(params, 0.0).unwrap();
        let mut noise = NoiseStream::new(seed, 0x0600);
        let n = (500.0 / t).round() as usize;
        let (mut ms, mut t5) = (0.0, f64::NAN);
        for k in 0..n {
            let e = 10.0 - f.estimate();
            ms += e * e;
            if t5.is_nan() && e.abs() < 0.5 {
                t5 = k as f64 * t;
            }
            f.sample(10.0 + noise.normal(), t);
        }
        (ms / n as f64, if t5.is_nan() { 500.0 } else { t5 })
    }

    const LAWS: [SpeedAdaptation; 4] = [
        SpeedAdaptation::Constant,
        SpeedAdaptation::Linear,
        SpeedAdaptation::Quadratic,
        SpeedAdaptation::Switch,
    ];

    /// [Klugt1987, Table 5.4] (σ_z² over the 500 s step run, step 0 → 10, τ0 = 100 s, τ_min = 10 s, unit noise),
    /// averaged over 200 seeds at T = 0.1 s and T = 0.5 s: C 10.0; L 1.7/3.4/4.9/6.2;
    /// Q 1.1/1.6/2.7/4.2; S 1.0/1.1/1.3/1.7 (c = 1..4).
    /// Ours (T = 0.1 s): C 10.005; L 1.728/3.383/4.888/6.201; Q 1.081/1.621/2.714/4.148;
    /// S 1.014/1.055/1.228/1.609. The S row is not reproduced to its last digit: the literal rule
    /// gives 1.0/1.1/1.2/1.6 (two independent re-computations found the same; the thesis's noise
    /// generation and T are unknown); S is
    /// held to ±0.15, the other rows to ±0.1 (the printed precision plus the seed-average spread).
    /// [Klugt1987, Table 5.3] (t_5%) is reproduced only in trend: ours C 299 (thesis 289, held
    /// within 5 %), L 108/193/239/262 (128/188/245/270), Q 52/139/204/239 (58/159/203/245),
    /// S 32/46/99/163 (37/58/148/182); asserted: for every c the ordering S < Q < L < C, and L and
    /// Q increasing with c.
    #[test]
    fn speed_filter_tables_5_3_and_5_4() {
        let table54 = [
            [10.0, 10.0, 10.0, 10.0],
            [1.7, 3.4, 4.9, 6.2],
            [1.1, 1.6, 2.7, 4.2],
            [1.0, 1.1, 1.3, 1.7],
        ];
        for t in [0.1, 0.5] {
            let mut t5 = [[0.0; 4]; 4];
            for (i, law) in LAWS.iter().enumerate() {
                for ci in 0..4 {
                    let c = (ci + 1) as f64;
                    let seeds = 200;
                    let (mut ms, mut ts) = (0.0, 0.0);
                    for s in 0..seeds {
                        let (m, t5s) = step_run(SpeedFilterParams::study(*law, c), t, s);
                        ms += m;
                        ts += t5s;
                    }
                    ms /= seeds as f64;
                    t5[i][ci] = ts / seeds as f64;
                    let tol = if i == 3 { 0.15 } else { 0.1 };
                    eprintln!(
                        "T={t} law {i} c={c}: sigma_z^2 {ms:.3} (thesis {}), t5 {:.0}",
                        table54[i][ci], t5[i][ci]
                    );
                    assert!(
                        close(ms, table54[i][ci], tol),
                        "T={t} law {law:?} c={c}: {ms} vs {}",
                        table54[i][ci]
                    );
                }
            }
            assert!(close(t5[0][0], 289.0, 0.05 * 289.0), "C t5 {}", t5[0][0]);
            for ci in 0..4 {
                assert!(t5[3][ci] < t5[2][ci] && t5[2][ci] < t5[1][ci] && t5[1][ci] < t5[0][ci]);
            }
            for i in 1..3 {
                for ci in 0..3 {
                    assert!(t5[i][ci] < t5[i][ci + 1]);
                }
            }
        }
    }

    /// The realised speed filter (L, p1 = 2) follows a 5 → 20 kn speed change with much less lag
    /// than the C-filter with the same noise suppression [Klugt1987, Fig. 7.24].
    #[test]
    fn l_filter_tracks_a_speed_change_faster_than_c_filter() {
        let mut l = SpeedFilter::new(SpeedFilterParams::realised(), 5.0).unwrap();
        let mut c = SpeedFilter::new(
            SpeedFilterParams::study(SpeedAdaptation::Constant, 2.0),
            5.0,
        )
        .unwrap();
        let mut noise = NoiseStream::new(3, 0x0600);
        // 60 s after the step: L-filter error ≈ 1/(1/15 + 60/200) = 2.7, C-filter 15 e^-0.6 = 8.2
        for k in 0..800 {
            let time = k as f64 * 0.1;
            let u = if time < 20.0 { 5.0 } else { 20.0 } + 0.3 * noise.normal();
            l.sample(u, 0.1);
            c.sample(u, 0.1);
        }
        assert!((20.0 - l.estimate()).abs() < 3.5, "{}", l.estimate());
        assert!((20.0 - c.estimate()).abs() > 7.0, "{}", c.estimate());
    }
}
