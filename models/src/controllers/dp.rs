//! A simple dynamic-positioning (DP) controller: nonlinear PID on the observer's low-frequency
//! estimates, in the body frame, for the 3-DOF DP models of [Fossen1999].
//!
//! # Why it exists
//! [Fossen1999] gives an observer but no controller; the DP simulation of issue 8 needs one to
//! close the loop. This is the textbook
//! DP law (Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2011, sec. 12.2.6 and
//! 13.3.3), kept deliberately small. It is fed with η̂ and ν̂ (never the raw measurement), so the
//! first-order wave motion stays out of the feedback loop [Fossen1999, Definition 1].
//!
//! # Control law
//! ```text
//! e   = Jᵀ(ψ̂) (η̂ − η_d),  e₃ wrapped to (−π, π]   body-frame position/heading error
//! ż   = e                                           integral state (body frame)
//! τ   = −K_p e − K_d ν̂ − K_i z + τ_ff(t)            N, N, N·m
//! τ_ff,i = A_i sin(ω_i t)                           open-loop test input [Fossen1999, eq. (61)]
//! ```
//! # Gains from the desired bandwidth (per DOF, diagonal m_i and d_i)
//! The closed loop m ë + (d + K_d) ė + K_p e = 0 is placed at natural frequency ω_n and relative
//! damping ζ; ω_n follows from the requested closed-loop bandwidth ω_b (Fossen 2011 eq. 12.123):
//! ```text
//! ω_n = ω_b / sqrt(1 − 2ζ² + sqrt(4ζ⁴ − 4ζ² + 2))
//! K_p = m ω_n²,   K_d = max(0, 2ζω_n m − d),   K_i = K_p ω_n / r_i   (r_i = 10: Fossen's rule)
//! ```
//! ω_b = 0 switches the feedback of that DOF off (τ = τ_ff only: the paper's open-loop run).
//! The sway-yaw coupling of D (d₂₃ = d₃₂ for Northern Clipper) is ignored in the design.
//!
//! # Integration
//! The inputs are held over a step; the integral state is advanced exactly for the held error
//! (z += e h) and τ at the end of the step uses the held inputs. No thrust allocation or limits:
//! B_u is not given for *Northern Clipper* [Fossen1999, eq. (4)], so τ is the generalized force itself.

use super::ControlError;
use crate::error::{check_finite, check_non_negative, check_positive};
use crate::hull::wrap_pi;
use crate::math::{sin, sin_cos};
use serde::{Deserialize, Serialize};

/// Parameters (per DOF: surge, sway, yaw).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DpParams {
    /// Inertia m_i [kg, kg, kg·m²] used for the gains (diagonal of M).
    pub mass: [f64; 3],
    /// Linear damping d_i [N·s/m, N·s/m, N·m·s] used for the gains (diagonal of D).
    pub damping: [f64; 3],
    /// Desired closed-loop bandwidth ω_b [rad/s]; 0 = no feedback in that DOF.
    pub bandwidth: [f64; 3],
    /// Relative damping ζ of the closed loop.
    pub relative_damping: f64,
    /// r in K_i = K_p ω_n / r; 0 = no integral action.
    pub integral_ratio: f64,
    /// Feed-forward test input amplitudes A_i [N, N, N·m] and frequencies ω_i [rad/s].
    pub test_amplitude: [f64; 3],
    pub test_frequency: [f64; 3],
}

impl DpParams {
    /// Northern Clipper ([Fossen1999, eqs. (56)-(57)] diagonals), ω_b = 0.05 rad/s in every DOF, ζ = 0.9,
    /// r = 10, no test input.
    pub fn northern_clipper() -> Self {
        DpParams {
            mass: [5.3122e6, 8.2831e6, 3.7454e9],
            damping: [5.0242e4, 2.7229e5, 4.1894e8],
            bandwidth: [0.05; 3],
            relative_damping: 0.9,
            integral_ratio: 10.0,
            test_amplitude: [0.0; 3],
            test_frequency: [0.05, 0.1, 0.07],
        }
    }

    pub fn validate(&self) -> Result<(), ControlError> {
        for i in 0..3 {
            check_positive("mass", self.mass[i])?;
            check_non_negative("damping", self.damping[i])?;
            check_non_negative("bandwidth", self.bandwidth[i])?;
            check_finite("test_amplitude", self.test_amplitude[i])?;
            check_finite("test_frequency", self.test_frequency[i])?;
        }
        check_positive("relative_damping", self.relative_damping)?;
        check_non_negative("integral_ratio", self.integral_ratio)?;
        Ok(())
    }

    /// ω_n from ω_b and ζ (Fossen 2011 eq. 12.123).
    pub fn natural_frequency(&self, i: usize) -> f64 {
        let z = self.relative_damping;
        let f = (1.0 - 2.0 * z * z + (4.0 * z.powi(4) - 4.0 * z * z + 2.0).sqrt()).sqrt();
        self.bandwidth[i] / f
    }

    /// (K_p, K_d, K_i) per DOF.
    pub fn gains(&self) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let (mut kp, mut kd, mut ki) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        for i in 0..3 {
            let wn = self.natural_frequency(i);
            if wn == 0.0 {
                continue;
            }
            kp[i] = self.mass[i] * wn * wn;
            kd[i] = (2.0 * self.relative_damping * wn * self.mass[i] - self.damping[i]).max(0.0);
            ki[i] = if self.integral_ratio > 0.0 {
                kp[i] * wn / self.integral_ratio
            } else {
                0.0
            };
        }
        (kp, kd, ki)
    }
}

/// Inputs, held over a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DpInputs {
    /// Estimated LF position/heading η̂ = [north m, east m, ψ rad].
    pub eta: [f64; 3],
    /// Estimated LF body velocity ν̂ = [u m/s, v m/s, r rad/s].
    pub nu: [f64; 3],
    /// Set point η_d = [north m, east m, ψ rad].
    pub setpoint: [f64; 3],
}

/// The controller. State: integral z and time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DpController {
    params: DpParams,
    kp: [f64; 3],
    kd: [f64; 3],
    ki: [f64; 3],
    /// ∫ error dt per axis (the integral action's state).
    integral: [f64; 3],
    time: f64,
}

/// Body-frame error Jᵀ(ψ̂)(η̂ − η_d), heading error wrapped.
pub fn body_error(eta: [f64; 3], setpoint: [f64; 3]) -> [f64; 3] {
    let (s, c) = sin_cos(eta[2]);
    let (dn, de) = (eta[0] - setpoint[0], eta[1] - setpoint[1]);
    [
        c * dn + s * de,
        -s * dn + c * de,
        wrap_pi(eta[2] - setpoint[2]),
    ]
}

impl DpController {
    pub fn new(params: DpParams, start_time: f64) -> Result<Self, ControlError> {
        params.validate()?;
        let (kp, kd, ki) = params.gains();
        Ok(DpController {
            params,
            kp,
            kd,
            ki,
            integral: [0.0; 3],
            time: start_time,
        })
    }

    /// Replaces the parameters (gains recomputed); integral state and time carry over.
    pub fn set_params(&mut self, params: DpParams) -> Result<(), ControlError> {
        params.validate()?;
        (self.kp, self.kd, self.ki) = params.gains();
        self.params = params;
        Ok(())
    }

    pub fn params(&self) -> &DpParams {
        &self.params
    }

    pub fn gains(&self) -> ([f64; 3], [f64; 3], [f64; 3]) {
        (self.kp, self.kd, self.ki)
    }

    pub fn integral(&self) -> [f64; 3] {
        self.integral
    }

    pub fn time(&self) -> f64 {
        self.time
    }

    /// Sets the controller's clock (the FMU passes the communication point, rounded to 1 ns,
    /// so that τ_ff is bit-identical whichever master computes the time grid).
    pub fn set_time(&mut self, t: f64) {
        self.time = t;
    }

    /// τ = −K_p e − K_d ν̂ − K_i z + τ_ff(t) at the controller's time [N, N, N·m].
    pub fn tau(&self, u: &DpInputs) -> [f64; 3] {
        let e = body_error(u.eta, u.setpoint);
        std::array::from_fn(|i| {
            -self.kp[i] * e[i] - self.kd[i] * u.nu[i] - self.ki[i] * self.integral[i]
                + self.params.test_amplitude[i] * sin(self.params.test_frequency[i] * self.time)
        })
    }

    /// Advances `h` seconds with the inputs held.
    pub fn step(&mut self, u: &DpInputs, h: f64) {
        let e = body_error(u.eta, u.setpoint);
        for i in 0..3 {
            if self.ki[i] != 0.0 {
                self.integral[i] += e[i] * h;
            }
        }
        self.time += h;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::supply_vessel::{SupplyVessel, SupplyVesselInputs};

    /// ζ = 1/√2 gives ω_n = ω_b·1.0 (the −3 dB point of the 2nd-order loop is then ω_n).
    #[test]
    fn bandwidth_to_natural_frequency() {
        let mut p = DpParams::northern_clipper();
        p.relative_damping = std::f64::consts::FRAC_1_SQRT_2;
        assert!((p.natural_frequency(0) - 0.05).abs() < 1e-15);
        p.relative_damping = 0.9;
        // 1 − 2·0.81 + sqrt(4·0.6561 − 3.24 + 2) = −0.62 + sqrt(1.3844) = 0.556595...
        let f = (-0.62f64 + 1.3844f64.sqrt()).sqrt();
        assert!((p.natural_frequency(1) - 0.05 / f).abs() < 1e-15);
        let (kp, kd, ki) = p.gains();
        let wn = 0.05 / f;
        assert!((kp[0] - 5.3122e6 * wn * wn).abs() < 1e-6);
        assert!((kd[0] - (1.8 * wn * 5.3122e6 - 5.0242e4)).abs() < 1e-6);
        assert!((ki[0] - kp[0] * wn / 10.0).abs() < 1e-9);
        p.bandwidth = [0.0; 3];
        assert_eq!(p.gains(), ([0.0; 3], [0.0; 3], [0.0; 3]));
    }

    #[test]
    fn rotation_and_wrap() {
        let e = body_error([10.0, 0.0, std::f64::consts::FRAC_PI_2], [0.0; 3]);
        assert!((e[0]).abs() < 1e-12 && (e[1] + 10.0).abs() < 1e-12);
        let e = body_error([0.0, 0.0, 3.1], [0.0, 0.0, -3.1]);
        assert!((e[2] - (6.2 - 2.0 * std::f64::consts::PI)).abs() < 1e-12);
        assert!(DpController::new(
            DpParams {
                relative_damping: -1.0,
                ..DpParams::northern_clipper()
            },
            0.0
        )
        .is_err());
    }

    /// On the true state of Northern Clipper with a constant earth-fixed bias: the integral
    /// action removes the offset (η → η_d), and τ → −Jᵀ b.
    #[test]
    fn holds_position_against_a_constant_bias() {
        let mut ship = SupplyVessel::northern_clipper();
        let mut c = DpController::new(DpParams::northern_clipper(), 0.0).unwrap();
        let bias = [8e4, -6e4, 2e6];
        let setpoint = [5.0, -3.0, 0.1];
        for _ in 0..20_000 {
            let o = ship.outputs();
            let u = DpInputs {
                eta: o.eta,
                nu: o.nu,
                setpoint,
            };
            let tau = c.tau(&u);
            c.step(&u, 0.1);
            ship.step(
                &SupplyVesselInputs {
                    tau,
                    bias,
                    wave_motion: [0.0; 3],
                },
                0.1,
            );
        }
        let o = ship.outputs();
        for i in 0..3 {
            assert!((o.eta[i] - setpoint[i]).abs() < 1e-6, "{:?}", o.eta);
        }
        let u = DpInputs {
            eta: o.eta,
            nu: o.nu,
            setpoint,
        };
        let tau = c.tau(&u);
        let (s, co) = sin_cos(0.1f64);
        let jtb = [
            co * bias[0] + s * bias[1],
            -s * bias[0] + co * bias[1],
            bias[2],
        ];
        for i in 0..3 {
            assert!(
                (tau[i] + jtb[i]).abs() < 1e-3 * jtb[i].abs(),
                "{tau:?} {jtb:?}"
            );
        }
    }

    #[test]
    fn feed_forward_is_eq_61() {
        let mut p = DpParams::northern_clipper();
        p.bandwidth = [0.0; 3];
        p.test_amplitude = [1000.0; 3];
        let mut c = DpController::new(p, 0.0).unwrap();
        let u = DpInputs::default();
        for _ in 0..37 {
            c.step(&u, 1.0);
        }
        let tau = c.tau(&u);
        assert_eq!(tau[0], 1000.0 * sin(0.05f64 * 37.0));
        assert_eq!(tau[2], 1000.0 * sin(0.07f64 * 37.0));
    }
}
