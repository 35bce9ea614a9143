//! The nonlinear passive observer of [Fossen1999] for dynamic positioning, with wave filtering and
//! bias estimation.
//!
//! # Source
//! [Fossen1999, sec. 4-5, eqs. (22)-(26), (40)-(48)] and the Northern Clipper settings of
//! [Fossen1999, sec. 6, eqs. (56)-(60)]:
//! ```text
//! ỹ = y − η̂ − ξ̂₂                      ([Fossen1999, eq. (26)], Γ = [0 I]; ỹ₃ wrapped to (−π, π])
//! ξ̂₁' = ξ̂₂ + k1 ỹ,  ξ̂₂' = −ω₀² ξ̂₁ − 2ζω₀ ξ̂₂ + k2 ỹ     ([Fossen1999, eq. (22)], per DOF)
//! η̂' = J(y₃) ν̂ + K₂ ỹ                   [Fossen1999, eq. (23)]
//! b̂' = −T⁻¹ b̂ + (1/γ) Λ ỹ               [Fossen1999, eq. (24)]
//! M ν̂' = −D ν̂ + Jᵀ(y₃) b̂ + τ + (1/γ) Jᵀ(y₃) 𝒦 ỹ      [Fossen1999, eq. (25)]
//! k1 = −2(ζ_n − ζ) ω_c/ω₀,  k2 = 2ω₀(ζ_n − ζ),  k3 = ω_c   [Fossen1999, eqs. (45)-(47)]
//! ```
//!
//! # Readings taken
//! * [Fossen1999, eq. (45)]: the OCR text prints `k1 = −2ω_c(ζ_n − ζ)/ω_c` (−1.8 with the paper's numbers); the
//!   coefficient-matching form −2(ζ_n − ζ)ω_c/ω₀ reproduces the paper's [Fossen1999, eq. (59)] value −2.2059 and
//!   is used.
//! * Scaling of the velocity and bias injection: 𝒦 = diag(0.1, 0.1, 0.01) and
//!   Λ = 0.1𝒦 are negligible against the SI M (10⁶-10⁹) if [Fossen1999, eq. (25)] is taken literally (the bias
//!   error then decays only at 1/T = 1000 s). [`Injection::MassNormalised`] (default) applies the
//!   injection as an acceleration, `ν̂' = M⁻¹(−Dν̂ + τ) + Jᵀb̂ + (1/γ)Jᵀ𝒦ỹ`, with b̂ in m/s² and
//!   rad/s² (the normalised-model reading); [`Injection::Literal`] is [Fossen1999, eq. (25)] with b̂ in N, N·m. The
//!   bias output is always given as an earth-fixed force: J M Jᵀ b̂ in the normalised form.
//! * Integration: RK4 with sub-steps ≤ `max_substep` (default 0.1 s), measurements and τ held over
//!   the step (the paper samples at 1 Hz).

use crate::error::{check_finite, check_non_negative, check_positive, require, ParamError};
use crate::hull::wrap_pi;
use crate::integrate::rk4_advance;
use crate::math::sin_cos;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// How the velocity and bias injections enter (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Injection {
    /// [Fossen1999, eq. (25)] literally with SI M and D; b̂ in N, N, N·m.
    Literal,
    /// Injection as an acceleration; b̂ in m/s², m/s², rad/s².
    MassNormalised,
}

/// Notch-filter gains of [Fossen1999, eqs. (45)-(47)] for one DOF: (k1, k2, k3).
pub fn notch_gains(zeta: f64, omega0: f64, zeta_n: f64, omega_c: f64) -> (f64, f64, f64) {
    (
        -2.0 * (zeta_n - zeta) * omega_c / omega0,
        2.0 * omega0 * (zeta_n - zeta),
        omega_c,
    )
}

/// Observer parameters (all per DOF: surge/north, sway/east, yaw).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PassiveObserverParams {
    pub m: [[f64; 3]; 3],
    pub d: [[f64; 3]; 3],
    /// Bias time constants T [s] ([Fossen1999, eq. (58)]: 1000).
    pub t_bias: [f64; 3],
    /// WF model: relative damping ζ and dominant frequency ω₀ [rad/s] (0.1, 0.8976).
    pub zeta: [f64; 3],
    pub omega0: [f64; 3],
    /// Notch damping ζ_n (1.0) and cut-off ω_c [rad/s] (1.1).
    pub zeta_n: [f64; 3],
    pub omega_c: [f64; 3],
    /// Velocity injection 𝒦 = diag(κ) (0.1, 0.1, 0.01) and bias injection Λ = diag(λ) (0.1 𝒦).
    pub kappa: [f64; 3],
    pub lambda: [f64; 3],
    pub gamma: f64,
    pub injection: Injection,
    pub max_substep: f64,
}

impl PassiveObserverParams {
    /// Northern Clipper with the paper's gains [Fossen1999, sec. 6, eqs. (56)-(60)], mass-normalised injection.
    pub fn northern_clipper() -> Self {
        let v = crate::hull::supply_vessel::SupplyVessel::northern_clipper();
        PassiveObserverParams {
            m: v.m,
            d: v.d,
            t_bias: [1000.0; 3],
            zeta: [0.1; 3],
            omega0: [0.8976; 3],
            zeta_n: [1.0; 3],
            omega_c: [1.1; 3],
            kappa: [0.1, 0.1, 0.01],
            lambda: [0.01, 0.01, 0.001],
            gamma: 1.0,
            injection: Injection::MassNormalised,
            max_substep: 0.1,
        }
    }

    pub fn validate(&self) -> Result<(), ParamError> {
        for i in 0..3 {
            check_positive("t_bias", self.t_bias[i])?;
            check_positive("zeta", self.zeta[i])?;
            check_positive("omega0", self.omega0[i])?;
            check_positive("zeta_n", self.zeta_n[i])?;
            check_positive("omega_c", self.omega_c[i])?;
            for j in 0..3 {
                check_finite("m", self.m[i][j])?;
                check_finite("d", self.d[i][j])?;
            }
            check_non_negative("kappa", self.kappa[i])?;
            check_non_negative("lambda", self.lambda[i])?;
        }
        check_positive("gamma", self.gamma)?;
        check_positive("max_substep", self.max_substep)?;
        let m = Matrix3::from_fn(|i, j| self.m[i][j]);
        require(
            m.try_inverse().is_some(),
            "m (determinant)",
            m.determinant(),
            "must be invertible",
        )
    }

    /// [Fossen1999, eq. (48)] tuning rule 1/T ≪ λ/κ < ω₀ < ω_c per DOF ("≪" taken as a factor 10). The paper's own
    /// numbers pass the rule, but the exact SPR phase condition is violated marginally (derived
    /// here: −94.85°); this is a check to warn on, not a reason to reject.
    pub fn tuning_rule_holds(&self) -> bool {
        (0..3).all(|i| {
            let r = self.lambda[i] / self.kappa[i];
            10.0 / self.t_bias[i] <= r && r < self.omega0[i] && self.omega0[i] < self.omega_c[i]
        })
    }
}

/// The observer. State [ξ̂₁ (3), ξ̂₂ (3), η̂ (3), b̂ (3), ν̂ (3)].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PassiveObserver {
    params: PassiveObserverParams,
    k1: [f64; 3],
    k2: [f64; 3],
    k3: [f64; 3],
    minv: Matrix3<f64>,
    state: [f64; 15],
    /// Last measurement (for ỹ and the outputs).
    y: [f64; 3],
}

fn rot(psi: f64) -> Matrix3<f64> {
    let (s, c) = sin_cos(psi);
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

impl PassiveObserver {
    /// An observer with η̂(0) = `eta0`, the other states 0.
    pub fn new(params: PassiveObserverParams, eta0: [f64; 3]) -> Result<Self, String> {
        params.validate()?;
        let mut o = PassiveObserver {
            k1: [0.0; 3],
            k2: [0.0; 3],
            k3: [0.0; 3],
            minv: Matrix3::identity(),
            params: params.clone(),
            state: [0.0; 15],
            y: eta0,
        };
        o.set_params(params)?;
        o.state[6..9].copy_from_slice(&eta0);
        Ok(o)
    }

    /// Replaces the parameters (gain scheduling on ω₀, Remark 2); the state carries over.
    pub fn set_params(&mut self, params: PassiveObserverParams) -> Result<(), String> {
        params.validate()?;
        for i in 0..3 {
            let (a, b, c) = notch_gains(
                params.zeta[i],
                params.omega0[i],
                params.zeta_n[i],
                params.omega_c[i],
            );
            self.k1[i] = a;
            self.k2[i] = b;
            self.k3[i] = c;
        }
        self.minv = Matrix3::from_fn(|i, j| params.m[i][j])
            .try_inverse()
            .ok_or("M is singular")?;
        self.params = params;
        Ok(())
    }

    pub fn params(&self) -> &PassiveObserverParams {
        &self.params
    }

    /// K₁ = [diag(k1); diag(k2)] and K₂ = diag(k3) per DOF.
    pub fn gains(&self) -> ([f64; 3], [f64; 3], [f64; 3]) {
        (self.k1, self.k2, self.k3)
    }

    fn innovation_of(&self, s: &[f64; 15], y: &[f64; 3]) -> [f64; 3] {
        let mut e = [0.0; 3];
        for i in 0..3 {
            e[i] = y[i] - s[6 + i] - s[3 + i];
        }
        e[2] = wrap_pi(e[2]);
        e
    }

    /// Advances `h` seconds with measurement y = [x, y, ψ] (position + WF motion) and thrust τ
    /// (body frame) held.
    pub fn step(&mut self, y: [f64; 3], tau: [f64; 3], h: f64) {
        self.y = y;
        let p = &self.params;
        let j = rot(y[2]);
        let jt = j.transpose();
        let mm = Matrix3::from_fn(|i, k| p.m[i][k]);
        let dd = Matrix3::from_fn(|i, k| p.d[i][k]);
        let minv = self.minv;
        let tau = Vector3::from(tau);
        let (k1, k2, k3) = (self.k1, self.k2, self.k3);
        let this = &*self;
        let f = |s: &[f64; 15]| {
            let e = this.innovation_of(s, &y);
            let ev = Vector3::from(e);
            let nu = Vector3::new(s[12], s[13], s[14]);
            let b = Vector3::new(s[9], s[10], s[11]);
            let kap = Vector3::from(p.kappa).component_mul(&ev) / p.gamma;
            let dnu = match p.injection {
                Injection::Literal => minv * (-dd * nu + jt * b + tau + jt * kap),
                Injection::MassNormalised => minv * (-dd * nu + tau) + jt * b + jt * kap,
            };
            let deta = j * nu;
            let mut d = [0.0; 15];
            for i in 0..3 {
                d[i] = s[3 + i] + k1[i] * e[i];
                d[3 + i] = -p.omega0[i] * p.omega0[i] * s[i]
                    - 2.0 * p.zeta[i] * p.omega0[i] * s[3 + i]
                    + k2[i] * e[i];
                d[6 + i] = deta[i] + k3[i] * e[i];
                d[9 + i] = -s[9 + i] / p.t_bias[i] + p.lambda[i] / p.gamma * e[i];
                d[12 + i] = dnu[i];
            }
            let _ = &mm;
            d
        };
        let mut s = self.state;
        rk4_advance(&mut s, h, p.max_substep, f);
        self.state = s;
    }

    /// LF position/heading estimate η̂.
    pub fn eta(&self) -> [f64; 3] {
        [self.state[6], self.state[7], self.state[8]]
    }

    /// LF velocity estimate ν̂ (body).
    pub fn nu(&self) -> [f64; 3] {
        [self.state[12], self.state[13], self.state[14]]
    }

    /// WF motion estimate η̂_w = ξ̂₂.
    pub fn eta_w(&self) -> [f64; 3] {
        [self.state[3], self.state[4], self.state[5]]
    }

    /// The bias state b̂ as integrated (N, N·m, or m/s², rad/s² when mass-normalised).
    pub fn bias_state(&self) -> [f64; 3] {
        [self.state[9], self.state[10], self.state[11]]
    }

    /// Earth-fixed bias force estimate [N, N, N·m]: b̂, or J M Jᵀ b̂ when mass-normalised
    /// (with J at the last measured heading).
    pub fn bias_force(&self) -> [f64; 3] {
        let b = Vector3::from(self.bias_state());
        match self.params.injection {
            Injection::Literal => self.bias_state(),
            Injection::MassNormalised => {
                let j = rot(self.y[2]);
                let mm = Matrix3::from_fn(|i, k| self.params.m[i][k]);
                let f = j * mm * j.transpose() * b;
                [f[0], f[1], f[2]]
            }
        }
    }

    /// ŷ = η̂ + η̂_w.
    pub fn y_hat(&self) -> [f64; 3] {
        let (e, w) = (self.eta(), self.eta_w());
        [e[0] + w[0], e[1] + w[1], e[2] + w[2]]
    }

    /// Innovation ỹ = y − ŷ for the last measurement (yaw wrapped).
    pub fn innovation(&self) -> [f64; 3] {
        self.innovation_of(&self.state, &self.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::disturbances::waves::{WaveParams, Waves};
    use crate::hull::supply_vessel::{SupplyVessel, SupplyVesselInputs};
    use crate::math::sin;

    /// [Fossen1999, eq. (59)]: K₁ = [−2.2059; 1.6157], K₂ = 1.1 to 4 decimals; exact −2.2058824.
    /// T2/T3: the tuning rule holds for the paper's set and fails for λ/κ ≥ ω₀ or ω_c ≤ ω₀.
    #[test]
    fn gains_eq_59() {
        let o = PassiveObserver::new(PassiveObserverParams::northern_clipper(), [0.0; 3]).unwrap();
        let (k1, k2, k3) = o.gains();
        for i in 0..3 {
            assert!((k1[i] - -2.2059).abs() < 0.5e-4, "{k1:?}");
            assert!((k1[i] - -2.2058824).abs() < 1e-7);
            assert!((k2[i] - 1.6157).abs() < 0.5e-4);
            assert!((k3[i] - 1.1).abs() < 1e-15);
        }
        let p = PassiveObserverParams::northern_clipper();
        assert!(p.tuning_rule_holds());
        assert_eq!(p.lambda, [0.01, 0.01, 0.001]);
        let mut bad = p.clone();
        bad.lambda = [0.1, 0.1, 0.01];
        bad.kappa = [0.1, 0.1, 0.01];
        assert!(!bad.tuning_rule_holds());
        let mut bad = p;
        bad.omega_c = [0.8; 3];
        assert!(!bad.tuning_rule_holds());
    }

    /// T9 (Theorem 1): noise-free, matched model, no waves, nonzero initial errors: all estimation
    /// errors → 0 (mass-normalised injection; the vessel under a slowly varying τ). Sampled at
    /// 10 Hz so that the sample-and-hold of y adds little.
    #[test]
    fn ges_noise_free() {
        let mut ship = SupplyVessel::northern_clipper();
        ship.set_state([5.0, -3.0, 0.3], [0.2, 0.0, 0.001]);
        let mut obs =
            PassiveObserver::new(PassiveObserverParams::northern_clipper(), [0.0, 0.0, 0.0])
                .unwrap();
        for k in 0..30_000 {
            let t = k as f64 * 0.1;
            let tau = [1e5 * sin(0.05 * t), 1e5 * sin(0.1 * t), 1e7 * sin(0.07 * t)];
            let y = ship.outputs().measured;
            obs.step(y, tau, 0.1);
            ship.step(
                &SupplyVesselInputs {
                    tau,
                    ..Default::default()
                },
                0.1,
            );
        }
        let (s, e) = (ship.outputs(), obs.eta());
        for i in 0..3 {
            // the hull moves up to ~2 m/s under this τ: the 0.1 s sample-and-hold of y leaves
            // errors of order 1e-2 m; the converged errors are that, not the initial 5 m / 0.3 rad
            let scale = if i == 2 { 2e-3 } else { 0.05 };
            assert!(
                (s.eta[i] - e[i]).abs() < scale,
                "eta {i}: {:?} {e:?}",
                s.eta
            );
            assert!((s.nu[i] - obs.nu()[i]).abs() < scale, "nu {i}");
        }
    }

    /// Closed loop SupplyVessel + Waves (WF model of [Fossen1999, sec. 2.4], 5 m / 5 m / 0.5° std at ω₀ = 0.8976) +
    /// this observer at 1 Hz + a slow PD station-keeping law on (η̂, ν̂), constant earth-fixed
    /// bias b = (8e4 N, −6e4 N, 2e6 N·m). Acceptance (issue 6): WF power in the estimate < 5 % of
    /// that in the measurement (power in the wave band 0.45-1.8 rad/s of η̂ against that of y, over
    /// the last 4096 s), and the bias estimate converges to the applied force.
    ///
    /// The bias cannot converge exactly: [Fossen1999, eq. (24)]'s leak −b̂/T leaves, at equilibrium, a relative
    /// error (κ + M⁻¹D K₂)/(Tλ + κ + M⁻¹D K₂) per DOF ≈ 1 % in surge and sway but ≈ 12 % in yaw
    /// (Tλ = 1 there). The instantaneous b̂ carries the wave-frequency residual of ỹ integrated by
    /// λ, so its mean over the last 4096 s is compared. Ours (seed 11): WF band-power ratios
    /// 3.5 %, 3.9 %, 3.2 %; mean bias 7.75e4 N, −5.72e4 N, 1.76e6 N·m (−3.1 %, −4.7 %, −12 %).
    /// Asserted: surge and sway within 6 %, yaw within 15 %.
    #[test]
    fn closed_loop_wave_filtering_and_bias() {
        let mut ship = SupplyVessel::northern_clipper();
        let mut waves = Waves::new(
            WaveParams {
                seed: 11,
                ..WaveParams::default()
            },
            0.0,
        )
        .unwrap();
        let mut obs =
            PassiveObserver::new(PassiveObserverParams::northern_clipper(), [0.0; 3]).unwrap();
        let bias = [8e4, -6e4, 2e6];
        let m = [5.3122e6, 8.2831e6, 3.7454e9];
        let w = 0.03;
        let (mut rec_est, mut rec_y) = (Vec::new(), Vec::new());
        let mut b_mean = [0.0; 3];
        let n = 8000;
        for k in 0..n {
            let t = k as f64;
            let (eh, nh) = (obs.eta(), obs.nu());
            // PD on the estimates, in the body frame
            let j = rot(eh[2]);
            let err = j.transpose() * Vector3::new(eh[0], eh[1], wrap_pi(eh[2]));
            let mut tau = [0.0; 3];
            for i in 0..3 {
                tau[i] = -m[i] * (w * w * err[i] + 2.0 * 0.8 * w * nh[i]);
            }
            waves.advance_to(t);
            let wf = waves.wf_motion();
            ship.step(
                &SupplyVesselInputs {
                    tau: [0.0; 3],
                    bias,
                    wave_motion: wf,
                },
                0.0,
            );
            let y = ship.outputs().measured;
            obs.step(y, tau, 1.0);
            ship.step(
                &SupplyVesselInputs {
                    tau,
                    bias,
                    wave_motion: wf,
                },
                1.0,
            );
            if k >= n - 4096 {
                rec_est.push(obs.eta());
                rec_y.push(y);
                let bf = obs.bias_force();
                for i in 0..3 {
                    b_mean[i] += bf[i] / 4096.0;
                }
            }
        }
        // power in the wave band 0.45-1.8 rad/s (periodogram by direct DFT, 1 Hz samples)
        let band = |x: &[[f64; 3]], i: usize| {
            let len = x.len();
            let mean = x.iter().map(|v| v[i]).sum::<f64>() / len as f64;
            let mut p = 0.0;
            for kf in 1..len / 2 {
                let wk = 2.0 * std::f64::consts::PI * kf as f64 / len as f64;
                if !(0.45..=1.8).contains(&wk) {
                    continue;
                }
                let (mut re, mut im) = (0.0, 0.0);
                for (q, v) in x.iter().enumerate() {
                    let (sn, cs) = sin_cos(wk * q as f64);
                    re += (v[i] - mean) * cs;
                    im -= (v[i] - mean) * sn;
                }
                p += re * re + im * im;
            }
            p
        };
        let p_est: Vec<f64> = (0..3).map(|i| band(&rec_est, i)).collect();
        let p_wf: Vec<f64> = (0..3).map(|i| band(&rec_y, i)).collect();
        for i in 0..3 {
            let ratio = p_est[i] / p_wf[i];
            eprintln!("DOF {i}: WF power ratio {ratio:.4}");
            assert!(ratio < 0.05, "DOF {i}: {ratio}");
        }
        let b = b_mean;
        eprintln!("mean bias estimate {b:?} vs {bias:?}");
        for (i, tol) in [(0, 0.06), (1, 0.06), (2, 0.15)] {
            assert!(
                ((b[i] - bias[i]) / bias[i]).abs() < tol,
                "DOF {i}: {} vs {}",
                b[i],
                bias[i]
            );
        }
    }
}
