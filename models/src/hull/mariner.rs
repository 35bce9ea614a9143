//! Mariner-class cargo ship: nonlinear 3-DOF (surge, sway, yaw) manoeuvring model.
//!
//! # Source
//! The MSS toolbox (T. I. Fossen, Marine Systems Simulator, `CRAFT/SHIP/models/mariner.m`), after
//! M. S. Chislett and J. Strøm-Tejsen (1965), *Planar motion mechanism tests and full-scale
//! steering and manoeuvring predictions for a Mariner class vessel*, Report Hy-5, Lyngby:
//! * states, inputs and data (L = 160.93 m, U₀ = 7.7175 m/s, rudder 40°, 5°/s);
//! * coefficient table (all ×10⁻⁵ except x′_G) and mass terms;
//! * equations, sign facts and the bias terms Y′₀, N′₀.
//!
//! # Readings taken
//! * Rudder sign: the model negates its input, δ_c = −u_i, so a positive input gives a
//!   starboard turn (r > 0) and the rudder *state* δ has the opposite sign of the input. The output
//!   [`MarinerOutputs::rudder`] is the physical rudder −δ (as MSS plots it; same sign as the input);
//!   [`MarinerOutputs::rudder_state`] is δ.
//! * Because Y′₀, N′₀ ≠ 0, x = 0 is not an equilibrium. [`Mariner::trimmed`] starts on the
//!   trimmed straight course instead, solving X′ = Y′ = N′ = 0 with r = 0 for (Δu, v, δ) by Newton
//!   iteration; the matching input is returned by [`Mariner::trim_input`].
//! * No current input: the source model has none.
//!
//! # Integration
//! RK4 with a fixed sub-step ≤ [`MarinerParams::max_substep`] (default 0.05 s), inputs held over
//! the step; see [`crate::integrate`].

use super::{mss_rudder_rate, wrap_pi, DEG};
use crate::error::{check_finite, check_positive, require, ParamError};
use crate::integrate::rk4_advance;
use crate::math::{atan2, sin_cos};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Length L [m].
pub const L: f64 = 160.93;
/// Default nominal speed U₀ [m/s] = 15 kn.
pub const U0_DEFAULT: f64 = 7.7175;

const S: f64 = 1e-5;
// Coefficients of `mariner.m`.
const MP: f64 = 798.0 * S;
const IZ: f64 = 39.2 * S;
const XG: f64 = -0.023;
const X_UDOT: f64 = -42.0 * S;
const X_U: f64 = -184.0 * S;
const X_UU: f64 = -110.0 * S;
const X_UUU: f64 = -215.0 * S;
const X_VV: f64 = -899.0 * S;
const X_RR: f64 = 18.0 * S;
const X_DD: f64 = -95.0 * S;
const X_UDD: f64 = -190.0 * S;
const X_RV: f64 = 798.0 * S;
const X_VD: f64 = 93.0 * S;
const X_UVD: f64 = 93.0 * S;
const Y_VDOT: f64 = -748.0 * S;
const Y_RDOT: f64 = -9.354 * S;
const N_VDOT: f64 = 4.646 * S;
const N_RDOT: f64 = -43.8 * S;

/// Y′ and N′ coefficients in the order v, r, vvv, vvr, vu, ru, δ, δδδ, uδ, uuδ, vδδ, vvδ,
/// 0, 0u, 0uu (×10⁻⁵).
const YC: [f64; 15] = [
    -1160.0, -499.0, -8078.0, 15356.0, -1160.0, -499.0, 278.0, -90.0, 556.0, 278.0, -4.0, 1190.0,
    -4.0, -8.0, -4.0,
];
const NC: [f64; 15] = [
    -264.0, -166.0, 1636.0, -5483.0, -264.0, -166.0, -139.0, 45.0, -278.0, -139.0, 13.0, -489.0,
    3.0, 6.0, 3.0,
];

const M11: f64 = MP - X_UDOT;
const M22: f64 = MP - Y_VDOT;
const M23: f64 = MP * XG - Y_RDOT;
const M32: f64 = MP * XG - N_VDOT;
const M33: f64 = IZ - N_RDOT;

/// Parameters of [`Mariner`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MarinerParams {
    /// Nominal speed U₀ [m/s]; 7.7175.
    pub u0: f64,
    /// Rudder command saturation [rad]; 40°.
    pub rudder_max: f64,
    /// Rudder rate limit [rad/s]; 5°/s.
    pub rudder_rate_max: f64,
    /// Largest RK4 sub-step [s]; 0.05.
    pub max_substep: f64,
}

impl Default for MarinerParams {
    fn default() -> Self {
        MarinerParams {
            u0: U0_DEFAULT,
            rudder_max: 40.0 * DEG,
            rudder_rate_max: 5.0 * DEG,
            max_substep: 0.05,
        }
    }
}

impl MarinerParams {
    /// Checks every parameter; the error names the parameter and its value.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("u0", self.u0)?;
        check_positive("rudder_max", self.rudder_max)?;
        check_positive("rudder_rate_max", self.rudder_rate_max)?;
        check_positive("max_substep", self.max_substep)?;
        Ok(())
    }
}

/// Inputs of [`Mariner`], held over a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MarinerInputs {
    /// Rudder input u_i [rad]; positive → starboard turn (δ_c = −u_i inside the model).
    pub rudder_command: f64,
}

/// Outputs of [`Mariner`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MarinerOutputs {
    /// Time [s].
    pub time: f64,
    /// Surge perturbation Δu [m/s].
    pub delta_u: f64,
    /// Surge u = U₀ + Δu [m/s].
    pub u: f64,
    /// Sway v [m/s].
    pub v: f64,
    /// Yaw rate r [rad/s].
    pub r: f64,
    /// North x [m].
    pub x: f64,
    /// East y [m].
    pub y: f64,
    /// Heading ψ [rad], continuous.
    pub heading: f64,
    /// Heading wrapped to (−π, π].
    pub heading_wrapped: f64,
    /// Physical rudder angle −δ [rad] (same sign as the input).
    pub rudder: f64,
    /// Rudder state δ [rad] (MSS sign).
    pub rudder_state: f64,
    /// Total speed U [m/s].
    pub speed: f64,
    /// Drift angle β = atan2(v, U₀ + Δu) [rad].
    pub drift_angle: f64,
    /// u′ = Δu/U.
    pub u_prime: f64,
    /// v′ = v/U.
    pub v_prime: f64,
    /// r′ = rL/U.
    pub r_prime: f64,
}

/// The Mariner-class ship (MSS `mariner.m`). State `[Δu, v, r, x, y, ψ, δ]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Mariner {
    pub params: MarinerParams,
    state: [f64; 7],
    time: f64,
}

impl Mariner {
    /// A ship with the given parameters and initial state `[Δu, v, r, x, y, ψ, δ]`.
    pub fn new(params: MarinerParams, state: [f64; 7]) -> Result<Self, ParamError> {
        params.validate()?;
        const NAMES: [&str; 7] = ["delta_u", "v", "r", "x", "y", "psi", "delta"];
        for (i, &s) in state.iter().enumerate() {
            check_finite(NAMES[i], s)?;
        }
        require(
            params.u0 + state[0] > 0.0,
            "delta_u",
            state[0],
            "u0 + delta_u must be > 0",
        )?;
        Ok(Mariner {
            params,
            state,
            time: 0.0,
        })
    }

    /// MSS's start: x = 0 at U₀ = 7.7175 m/s (not an equilibrium).
    pub fn mss_default() -> Self {
        Self::new(MarinerParams::default(), [0.0; 7]).expect("valid preset")
    }

    /// Ship on the trimmed straight course at `u0` (see module docs), heading north at the origin.
    pub fn trimmed(u0: f64) -> Result<Self, ParamError> {
        let params = MarinerParams {
            u0,
            ..Default::default()
        };
        params.validate()?;
        let (du, v, d) = Self::trim_solve(u0);
        Self::new(params, [du, v, 0.0, 0.0, 0.0, 0.0, d])
    }

    /// The input u_i [rad] that holds the trimmed straight course at `u0` (= −δ_trim).
    pub fn trim_input(u0: f64) -> f64 {
        -Self::trim_solve(u0).2
    }

    fn trim_solve(u0: f64) -> (f64, f64, f64) {
        let f = |z: &Vector3<f64>| {
            let s = [z[0], z[1], 0.0, 0.0, 0.0, 0.0, z[2]];
            let (x, y, n, _) = Self::forces(u0, &s);
            Vector3::new(x, y, n)
        };
        let mut z = Vector3::new(0.0, 0.0, 0.0);
        for _ in 0..50 {
            let f0 = f(&z);
            let mut jac = Matrix3::zeros();
            for j in 0..3 {
                let mut zp = z;
                zp[j] += 1e-7;
                let col = (f(&zp) - f0) / 1e-7;
                jac.set_column(j, &col);
            }
            let dz = jac.lu().solve(&(-f0)).unwrap_or_else(Vector3::zeros);
            z += dz;
            if dz.norm() < 1e-15 {
                break;
            }
        }
        (z[0], z[1], z[2])
    }

    /// State `[Δu, v, r, x, y, ψ, δ]`.
    pub fn state(&self) -> &[f64; 7] {
        &self.state
    }

    /// Time [s] advanced.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Nondimensional X′, Y′, N′ and the total speed U.
    pub fn forces(u0: f64, s: &[f64; 7]) -> (f64, f64, f64, f64) {
        let (du, v, r, d) = (s[0], s[1], s[2], s[6]);
        let speed = ((u0 + du).powi(2) + v * v).sqrt();
        let (up, vp, rp) = (du / speed, v / speed, r * L / speed);
        let x = X_U * up
            + X_UU * up * up
            + X_UUU * up.powi(3)
            + X_VV * vp * vp
            + X_RR * rp * rp
            + X_RV * rp * vp
            + X_DD * d * d
            + X_UDD * up * d * d
            + X_VD * vp * d
            + X_UVD * up * vp * d;
        let t = [
            vp,
            rp,
            vp.powi(3),
            vp * vp * rp,
            vp * up,
            rp * up,
            d,
            d.powi(3),
            up * d,
            up * up * d,
            vp * d * d,
            vp * vp * d,
            1.0,
            up,
            up * up,
        ];
        let mut y = 0.0;
        let mut n = 0.0;
        for i in 0..15 {
            y += YC[i] * S * t[i];
            n += NC[i] * S * t[i];
        }
        (x, y, n, speed)
    }

    /// State derivative.
    pub fn derivative(params: &MarinerParams, s: &[f64; 7], inp: &MarinerInputs) -> [f64; 7] {
        let (x, y, n, sp) = Self::forces(params.u0, s);
        let (du, v, r, psi, d) = (s[0], s[1], s[2], s[5], s[6]);
        let det = M22 * M33 - M23 * M32;
        let (spsi, cpsi) = sin_cos(psi);
        [
            x * sp * sp / L / M11,
            (M33 * y - M23 * n) / det * sp * sp / L,
            (-M32 * y + M22 * n) / det * sp * sp / (L * L),
            (params.u0 + du) * cpsi - v * spsi,
            (params.u0 + du) * spsi + v * cpsi,
            r,
            mss_rudder_rate(
                -inp.rudder_command,
                d,
                params.rudder_max,
                params.rudder_rate_max,
            ),
        ]
    }

    /// Advances exactly `h` seconds (RK4, sub-step ≤ `max_substep`), inputs held.
    pub fn step(&mut self, inputs: &MarinerInputs, h: f64) {
        let params = &self.params;
        rk4_advance(&mut self.state, h, params.max_substep, |s| {
            Self::derivative(params, s, inputs)
        });
        if h > 0.0 && h.is_finite() {
            self.time += h;
        }
    }

    /// Current outputs.
    pub fn outputs(&self) -> MarinerOutputs {
        let s = &self.state;
        let u = self.params.u0 + s[0];
        let sp = (u * u + s[1] * s[1]).sqrt();
        MarinerOutputs {
            time: self.time,
            delta_u: s[0],
            u,
            v: s[1],
            r: s[2],
            x: s[3],
            y: s[4],
            heading: s[5],
            heading_wrapped: wrap_pi(s[5]),
            rudder: -s[6],
            rudder_state: s[6],
            speed: sp,
            drift_angle: atan2(s[1], u),
            u_prime: s[0] / sp,
            v_prime: s[1] / sp,
            r_prime: s[2] * L / sp,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mass terms.
    #[test]
    fn mass_terms() {
        assert!((M11 - 840e-5).abs() < 1e-15);
        assert!((M22 - 1546e-5).abs() < 1e-15);
        assert!((M23 + 9.0e-5).abs() < 1e-12);
        assert!((M32 + 23.0e-5).abs() < 1e-12);
        assert!((M33 - 83.0e-5).abs() < 1e-15);
    }

    /// Trim: holding a straight line needs u_i ≈ −1.108° (state δ ≈ +1.108°),
    /// v ≈ 0.0091 m/s. Independent check: the linear part of Y′ = N′ = 0 at Δu = 0 is
    /// [Y_v Y_δ; N_v N_δ][v′; δ] = −[Y_0; N_0], solved here by Cramer's rule.
    #[test]
    fn trimmed_straight_course() {
        let ui = Mariner::trim_input(U0_DEFAULT);
        let ship = Mariner::trimmed(U0_DEFAULT).unwrap();
        let o = ship.outputs();
        println!(
            "trim: u_i = {:.4} deg, v = {:.5} m/s, du = {:.6}",
            ui / DEG,
            o.v,
            o.delta_u
        );
        assert!((ui / DEG + 1.108).abs() < 1e-3, "{}", ui / DEG);
        assert!((o.v - 0.0091).abs() < 5e-5, "{}", o.v);
        let (yv, yd, y0, nv, nd, n0) = (-1160.0, 278.0, -4.0, -264.0, -139.0, 3.0);
        let det = yv * nd - yd * nv;
        let d_lin = (yv * (-n0) - nv * (-y0)) / det;
        assert!((ship.state()[6] - d_lin).abs() < 1e-4);
        // It is an equilibrium: derivatives vanish (except ẋ = U₀ + Δu and ẏ = v).
        let der = Mariner::derivative(
            &ship.params,
            ship.state(),
            &MarinerInputs { rudder_command: ui },
        );
        for (i, d) in der.iter().enumerate() {
            if i != 3 && i != 4 {
                assert!(d.abs() < 1e-12, "der[{i}] = {d}");
            }
        }
    }

    /// Bias: with zero rudder from x = 0 the Mariner drifts to starboard,
    /// ψ ≈ 0.18° after 10 s and ≈ 8° after 100 s (MSS values; tolerance 5 %, since MSS used its
    /// own integrator and the values are rounded).
    #[test]
    fn zero_rudder_drift() {
        let mut s = Mariner::mss_default();
        let inp = MarinerInputs::default();
        for _ in 0..100 {
            s.step(&inp, 0.1);
        }
        let psi10 = s.outputs().heading / DEG;
        for _ in 0..900 {
            s.step(&inp, 0.1);
        }
        let psi100 = s.outputs().heading / DEG;
        println!("Mariner zero-rudder drift: psi(10) = {psi10:.4} deg, psi(100) = {psi100:.3} deg");
        assert!((psi10 - 0.18).abs() < 0.05 * 0.18 + 0.005);
        assert!((psi100 - 8.0).abs() < 0.05 * 8.0);
    }

    /// Positive input → starboard turn; the rudder state has the opposite sign.
    #[test]
    fn sign_convention() {
        let mut s = Mariner::trimmed(U0_DEFAULT).unwrap();
        let inp = MarinerInputs {
            rudder_command: 15.0 * DEG,
        };
        for _ in 0..300 {
            s.step(&inp, 0.1);
        }
        let o = s.outputs();
        assert!(o.r > 0.0 && o.heading > 0.0 && o.y > 0.0);
        assert!(o.rudder > 0.0 && o.rudder_state < 0.0);
        assert!((o.rudder - 15.0 * DEG).abs() < 1e-9);
    }

    #[test]
    fn rejects_bad_parameters() {
        let p = MarinerParams {
            u0: f64::NAN,
            ..Default::default()
        };
        assert_eq!(Mariner::new(p, [0.0; 7]).unwrap_err().name, "u0");
    }
}
