//! Linear manoeuvring models of the DDG-51 thesis: the first-order Nomoto model of the DDG-51 and
//! the linear sway-yaw model (Esso Osaka coefficients as a preset).
//!
//! # Source
//! The DDG-51 thesis [Taylor2000]:
//! * sign convention: positive δ → positive r (starboard turn), K = +2.04 (derived from the
//!   rudder model, [Taylor2000, eqs. (3.31)-(3.33)]);
//! * linear identification model [Taylor2000, sec. 4.1, eqs. (4.1)-(4.2)], unknowns −Y_v,
//!   (m − Y_r), −N_v, (m x_G − N_r);
//! * nondimensionalisation [INFERRED]: SNAME prime system, t′ = tU/L (the thesis never defines
//!   it);
//! * Esso Osaka [Taylor2000, sec. 2.3, Tables 2.2-2.3]; kinematics
//!   [Taylor2000, sec. 5.3.1, eqs. (5.35)-(5.37)];
//! * Nomoto model T ψ̈ + ψ̇ = K δ [Taylor2000, sec. 5.2.1, eq. (5.24)] with T′ = 1.9287,
//!   K′ = 2.04 [Taylor2000, eqs. (5.25)-(5.26)], dimensional at 22 kn T = 24.2 s,
//!   K = 0.1626 1/s [DERIVED]; the Nomoto formulas from the sway-yaw matrices (standard, derived
//!   here); DDG-51 data (LBP 466 ft) [Taylor2000, Table 3.1].
//!
//! # Model
//! Sway-yaw (prime system, u′ = 1, time t′ = tU/L): M ν̇′ + N ν′ = b δ with ν′ = [v′, r′],
//! M = [[m − Y_v̇, m x_G − Y_ṙ], [m x_G − N_v̇, I_z − N_ṙ]], N = [[−Y_v, m − Y_r],
//! [−N_v, m x_G − N_r]], b = [Y_δ, N_δ]. Nomoto: T′ ṙ′ + r′ = K′ δ.
//! Kinematics ([Taylor2000, eqs. (5.35)-(5.36)], u = U): ẋ = U cos ψ − v sin ψ + c_N,
//! ẏ = U sin ψ + v cos ψ + c_E, ψ̇ = r, where (c_N, c_E) is the current (the thesis modelled its
//! 5-kn current as an initial sway velocity, [Taylor2000, sec. 5.2.3.1]; here it is an
//! earth-fixed velocity added to the kinematics).
//!
//! # Readings taken, and the Esso Osaka values the source does not give
//! The thesis gives only the four N-matrix coefficients of the Esso Osaka
//! [Taylor2000, Table 2.3] and its principal particulars [Taylor2000, Table 2.2]; the mass
//! matrix, the rudder coefficients and the speed are missing. They are parameters with these
//! documented defaults [ASSUMED]:
//! * m′ = 0.01814 (derived from Δ = 314,410 LT), x′_G = −25/1066.3;
//!   added masses from Clarke's regressions (Clarke, Gedling & Hine 1983) with
//!   T/L = 92.8/1066.3, B/L = 173.9/1066.3, C_B = 0.64 ([Taylor2000, Table 2.2] as printed);
//!   I′_z = m′(0.25)² (radius of gyration L/4);
//! * b = [Y′_δ, N′_δ] from the thesis's own rudder model [Taylor2000, sec. 3.2.2.4, eq. (3.30)]: one rudder of
//!   A_R = 1289.67 ft², ∂C_L/∂α = 2.217 /rad (AR 1.538), inflow speed U, at x′_R = −0.5:
//!   Y′_δ = −(A_R/L²)·2.217, N′_δ = x′_R·Y′_δ (positive δ → starboard turn, as above);
//! * U = 10 kn (any speed gives the same nondimensional results).
//!
//! With [Taylor2000, Table 2.3] the linear Esso Osaka is **course unstable**: det N = (−Y_v)(m x_G − N_r) −
//! (m − Y_r)(−N_v) = −3.71e-7 < 0 (the real ship is known to be directionally unstable). Its
//! "steady turning rate" r′ = K′δ with K′ = (n11 b2 − n21 b1)/det N is therefore an unstable
//! equilibrium, of opposite sign to the rudder (tested). With the assumed M the eigenvalues of
//! −M⁻¹N are −0.638 and +0.0060 per unit t′: the divergence time constant is ≈ 166 L/U (≈ 3 h at
//! 10 kn), so over the minutes of the thesis's 10° turn [Taylor2000, Fig. 2-7] the linear model
//! still looks like a (slowly tightening) turn. The thesis may also have kept the rudder-induced
//! damping of its rudder model [Taylor2000, sec. 3.2.2.4] in N, which is not reproducible from
//! the text.
//!
//! # Integration
//! RK4 with a fixed sub-step ≤ [`NomotoShip::max_substep`] (default 0.1 s, i.e. ≤ 0.008 L/U
//! for the DDG-51 at 22 kn), inputs held over the step; see [`crate::integrate`].

use super::{wrap_pi, KNOT};
use crate::error::{check_finite, check_mass_matrix_2x2, check_positive, ParamError};
use crate::integrate::rk4_advance;
use crate::math::sin_cos;
use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

/// One foot in metres.
pub const FOOT: f64 = 0.3048;

/// Which model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum NomotoModel {
    /// First-order Nomoto T′ ṙ′ + r′ = K′ δ (nondimensional T′, K′).
    FirstOrder { t: f64, k: f64 },
    /// Linear sway-yaw M ν̇′ + N ν′ = b δ (prime system, row-major 2×2 matrices).
    SwayYaw {
        m: [[f64; 2]; 2],
        n: [[f64; 2]; 2],
        b: [f64; 2],
    },
}

/// Inputs, held over a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NomotoInputs {
    /// Actual rudder δ [rad] (positive → starboard turn).
    pub rudder: f64,
    /// Current speed [m/s] and the direction it flows *toward* [rad from north, clockwise].
    pub current_speed: f64,
    pub current_direction: f64,
    /// Rudder-equivalent environmental disturbance δ_w [rad], added to δ in the dynamics:
    /// T′ ṙ′ + r′ = K′(δ + δ_w), or b(δ + δ_w) for the sway-yaw model. The thesis's sea-state-4
    /// disturbance is "a random disturbance filtered to preserve only the low-frequency
    /// components" ([Taylor2000, sec. 5.3.3.2]) whose entry point into the hull is not given; the
    /// rudder-equivalent form is the usual one for a Nomoto plant (as [Klugt1987, eq. (3.29)] for
    /// the RRS ship).
    pub yaw_disturbance: f64,
}

/// Outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NomotoOutputs {
    pub time: f64,
    /// t′ = tU/L.
    pub time_prime: f64,
    /// Sway v [m/s] (0 for the Nomoto model) and v′ = v/U.
    pub sway_velocity: f64,
    pub v_prime: f64,
    /// Yaw rate r [rad/s] and r′ = rL/U.
    pub yaw_rate: f64,
    pub r_prime: f64,
    /// Heading ψ [rad] (continuous) and wrapped.
    pub heading: f64,
    pub heading_wrapped: f64,
    /// North x, east y [m].
    pub x: f64,
    pub y: f64,
    /// Speed over ground [m/s].
    pub speed_over_ground: f64,
}

/// The ship. State `[v′, r′, ψ, x, y]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NomotoShip {
    pub model: NomotoModel,
    /// Reference length L [m].
    pub length: f64,
    /// Speed U [m/s].
    pub speed: f64,
    /// Largest RK4 sub-step [s].
    pub max_substep: f64,
    state: [f64; 5],
    time: f64,
}

impl NomotoShip {
    /// A ship with `model`, length `length` [m] and speed `speed` [m/s], on a straight course
    /// north at the origin.
    pub fn new(model: NomotoModel, length: f64, speed: f64) -> Result<Self, ParamError> {
        check_positive("length", length)?;
        check_positive("speed", speed)?;
        match &model {
            NomotoModel::FirstOrder { t, k } => {
                check_positive("t", *t)?;
                check_finite("k", *k)?;
            }
            NomotoModel::SwayYaw { m, n, b } => {
                check_mass_matrix_2x2(m)?;
                for (name, v) in [
                    ("n11", n[0][0]),
                    ("n12", n[0][1]),
                    ("n21", n[1][0]),
                    ("n22", n[1][1]),
                    ("b1", b[0]),
                    ("b2", b[1]),
                ] {
                    check_finite(name, v)?;
                }
            }
        }
        Ok(NomotoShip {
            model,
            length,
            speed,
            max_substep: 0.1,
            state: [0.0; 5],
            time: 0.0,
        })
    }

    /// DDG-51 first-order Nomoto model, T′ = 1.9287, K′ = 2.04 [Taylor2000, eqs. (5.25)-(5.26)], L = 466 ft,
    /// U = 22 kn (L/U = 12.55 s).
    pub fn ddg51() -> Self {
        Self::new(
            NomotoModel::FirstOrder { t: 1.9287, k: 2.04 },
            466.0 * FOOT,
            22.0 * KNOT,
        )
        .expect("valid preset")
    }

    /// Esso Osaka linear sway-yaw model: N from [Taylor2000, Table 2.3]; M, b and U are the [ASSUMED] defaults
    /// of the module documentation.
    pub fn esso_osaka() -> Self {
        let (m, b) = esso_osaka_assumed_m_b();
        let n = [[0.0244, 0.0138], [1.4578e-3, 8.093e-4]];
        Self::new(NomotoModel::SwayYaw { m, n, b }, 1066.3 * FOOT, 10.0 * KNOT)
            .expect("valid preset")
    }

    /// The first-order Nomoto model of the Son & Nomoto container ship at `speed` [m/s]: K′ and
    /// T′ of its linearised model (MSS `Lcontainer.m`, roll coupling included) by the low-frequency
    /// match of [`crate::controllers::loop_shaped::presets`] (K′ = 2.920998, T′ = 4.359567, the
    /// same in t′ at every speed), L = 175 m. The plant the heading autopilot's container-ship
    /// preset is designed on.
    pub fn container_ship(speed: f64) -> Result<Self, ParamError> {
        use crate::controllers::loop_shaped::presets::{
            container_ship_yaw_rate, nomoto_first_order,
        };
        check_positive("speed", speed)?;
        let (k, t) = container_ship_yaw_rate(speed)
            .and_then(|g| nomoto_first_order(&g))
            .map_err(|_| ParamError::new("speed", speed, "gives no Nomoto model"))?;
        Self::new(
            NomotoModel::FirstOrder { t, k },
            super::container_ship::L,
            speed,
        )
    }

    /// State `[v′, r′, ψ, x, y]`.
    pub fn state(&self) -> &[f64; 5] {
        &self.state
    }

    /// Sets the nondimensional motion state (v′, r′) and heading ψ.
    pub fn set_motion(&mut self, v_prime: f64, r_prime: f64, heading: f64) {
        self.state[0] = v_prime;
        self.state[1] = r_prime;
        self.state[2] = heading;
    }

    /// Sets the motion (v′, r′, ψ) and the position (x, y) [m].
    pub fn set_state(&mut self, state: [f64; 5]) {
        self.state = state;
    }

    pub fn time(&self) -> f64 {
        self.time
    }

    /// Nondimensional derivatives d(v′, r′)/dt′ at (v′, r′, δ).
    pub fn derivative_prime(&self, v: f64, r: f64, delta: f64) -> (f64, f64) {
        match &self.model {
            NomotoModel::FirstOrder { t, k } => (0.0, (k * delta - r) / t),
            NomotoModel::SwayYaw { m, n, b } => {
                let mm = Matrix2::new(m[0][0], m[0][1], m[1][0], m[1][1]);
                let nn = Matrix2::new(n[0][0], n[0][1], n[1][0], n[1][1]);
                let rhs = Vector2::new(b[0], b[1]) * delta - nn * Vector2::new(v, r);
                let a = mm.lu().solve(&rhs).unwrap_or_else(Vector2::zeros);
                (a[0], a[1])
            }
        }
    }

    /// First-order Nomoto (T′, K′) of the model: identity for the Nomoto model; for the sway-yaw
    /// model T′ = T1 + T2 − T3, K′ = (n11 b2 − n21 b1)/det N (the standard Nomoto formulas).
    pub fn nomoto_constants(&self) -> (f64, f64) {
        match &self.model {
            NomotoModel::FirstOrder { t, k } => (*t, *k),
            NomotoModel::SwayYaw { m, n, b } => {
                let det_n = n[0][0] * n[1][1] - n[0][1] * n[1][0];
                let t1t2_sum =
                    (m[0][0] * n[1][1] + m[1][1] * n[0][0] - m[0][1] * n[1][0] - m[1][0] * n[0][1])
                        / det_n;
                let k = (n[0][0] * b[1] - n[1][0] * b[0]) / det_n;
                let kt3 = (m[0][0] * b[1] - m[1][0] * b[0]) / det_n;
                (t1t2_sum - kt3 / k, k)
            }
        }
    }

    /// Advances exactly `h` seconds (RK4, sub-step ≤ `max_substep`), inputs held.
    pub fn step(&mut self, inputs: &NomotoInputs, h: f64) {
        let (l, u) = (self.length, self.speed);
        let s_scale = u / l; // dt′/dt
        let (cs, cc) = sin_cos(inputs.current_direction);
        let (cn, ce) = (inputs.current_speed * cc, inputs.current_speed * cs);
        let delta = inputs.rudder + inputs.yaw_disturbance;
        let me = &*self;
        let mut st = self.state;
        rk4_advance(&mut st, h, self.max_substep, |s| {
            let (dv, dr) = me.derivative_prime(s[0], s[1], delta);
            let v = s[0] * u;
            let (sp, cp) = sin_cos(s[2]);
            [
                dv * s_scale,
                dr * s_scale,
                s[1] * s_scale,
                u * cp - v * sp + cn,
                u * sp + v * cp + ce,
            ]
        });
        self.state = st;
        if h > 0.0 && h.is_finite() {
            self.time += h;
        }
    }

    /// Current outputs (the ground speed uses zero current; the current is an input).
    pub fn outputs(&self) -> NomotoOutputs {
        let s = &self.state;
        let (l, u) = (self.length, self.speed);
        NomotoOutputs {
            time: self.time,
            time_prime: self.time * u / l,
            sway_velocity: s[0] * u,
            v_prime: s[0],
            yaw_rate: s[1] * u / l,
            r_prime: s[1],
            heading: s[2],
            heading_wrapped: wrap_pi(s[2]),
            x: s[3],
            y: s[4],
            speed_over_ground: (u * u + (s[0] * u).powi(2)).sqrt(),
        }
    }
}

/// The [ASSUMED] Esso Osaka mass matrix and rudder vector (module documentation).
pub fn esso_osaka_assumed_m_b() -> ([[f64; 2]; 2], [f64; 2]) {
    let l: f64 = 1066.3;
    let (b_beam, t_draft): (f64, f64) = (173.9, 92.8);
    let m = 0.01814;
    let xg = -25.0 / l;
    let cb = 0.64;
    let tl2 = std::f64::consts::PI * (t_draft / l).powi(2);
    let (bl, bt) = (b_beam / l, b_beam / t_draft);
    // Clarke, Gedling & Hine (1983) regressions (prime system).
    let y_vdot = -tl2 * (1.0 + 0.16 * cb * bt - 5.1 * bl * bl);
    let y_rdot = -tl2 * (0.67 * bl - 0.0033 * bt * bt);
    let n_vdot = -tl2 * (1.1 * bl - 0.041 * bt);
    let n_rdot = -tl2 * (1.0 / 12.0 + 0.017 * cb * bt - 0.33 * bl);
    let iz = m * 0.25 * 0.25;
    let mm = [
        [m - y_vdot, m * xg - y_rdot],
        [m * xg - n_vdot, iz - n_rdot],
    ];
    let ar_l2 = 1289.67 / (l * l);
    let y_delta = -ar_l2 * 2.217;
    let n_delta = -0.5 * y_delta;
    (mm, [y_delta, n_delta])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{cos, exp, sin};

    /// [DERIVED] from [Taylor2000, eqs. (5.25)-(5.26)]: DDG-51 at 22 kn has L/U = 12.55 s,
    /// T = 24.2 s, K = 0.1626 1/s.
    #[test]
    fn ddg51_scales() {
        let s = NomotoShip::ddg51();
        let lu = s.length / s.speed;
        assert!((lu - 12.55).abs() < 0.005, "{lu}");
        assert!((1.9287 * lu - 24.2).abs() < 0.05);
        assert!((2.04 / lu - 0.1626).abs() < 5e-5);
    }

    /// The yaw disturbance is rudder-equivalent: rudder δ with disturbance δ_w gives the same
    /// motion as rudder δ + δ_w alone (both models), and a disturbance that cancels the rudder
    /// leaves the ship on its straight course.
    #[test]
    fn yaw_disturbance_is_rudder_equivalent() {
        for proto in [NomotoShip::ddg51(), NomotoShip::esso_osaka()] {
            let (mut a, mut b, mut c) = (proto.clone(), proto.clone(), proto.clone());
            for k in 0..200 {
                let d = 0.05 * sin(0.01 * k as f64);
                let w = 0.03 * cos(0.07 * k as f64);
                a.step(
                    &NomotoInputs {
                        rudder: d,
                        yaw_disturbance: w,
                        ..Default::default()
                    },
                    0.5,
                );
                b.step(
                    &NomotoInputs {
                        rudder: d + w,
                        ..Default::default()
                    },
                    0.5,
                );
                c.step(
                    &NomotoInputs {
                        rudder: d,
                        yaw_disturbance: -d,
                        ..Default::default()
                    },
                    0.5,
                );
            }
            assert_eq!(a.state(), b.state());
            assert!(a.state()[2].abs() > 1e-3, "the disturbance turns the ship");
            assert_eq!(c.state()[2], 0.0);
        }
    }

    /// Step response of the Nomoto model [Taylor2000, eq. (5.24)]: for a rudder step δ at t = 0,
    /// r(t) = (K/(L/U)) δ (1 − e^{−t/T}), ψ(t) = K δ (t′ − T′(1 − e^{−t′/T′})) with
    /// T = T′ L/U, written out here; the simulation must agree to 1e-9 (RK4, 0.1 s sub-step),
    /// independently of the communication step (0.1, 1 and 5 s).
    #[test]
    fn ddg51_step_response() {
        let d = 5.0 * std::f64::consts::PI / 180.0;
        for h in [0.1, 1.0, 5.0] {
            let mut s = NomotoShip::ddg51();
            let lu = s.length / s.speed;
            let inp = NomotoInputs {
                rudder: d,
                ..Default::default()
            };
            let n = (100.0 / h) as usize;
            for _ in 0..n {
                s.step(&inp, h);
            }
            let o = s.outputs();
            let tp = 100.0 / lu;
            let (tt, kk) = (1.9287, 2.04);
            let r_exp = kk * d * (1.0 - exp(-tp / tt)) / lu;
            let psi_exp = kk * d * (tp - tt * (1.0 - exp(-tp / tt)));
            assert!(
                (o.yaw_rate - r_exp).abs() < 1e-9 * r_exp,
                "h {h}: {} vs {r_exp}",
                o.yaw_rate
            );
            assert!((o.heading - psi_exp).abs() < 1e-9 * psi_exp);
            assert!(
                o.yaw_rate > 0.0,
                "positive rudder → starboard turn (sign convention)"
            );
        }
        // Steady turning rate K δ: after 10 T.
        let mut s = NomotoShip::ddg51();
        s.step(
            &NomotoInputs {
                rudder: d,
                ..Default::default()
            },
            250.0,
        );
        assert!((s.outputs().r_prime - 2.04 * d).abs() < 1e-4 * 2.04 * d);
    }

    /// Esso Osaka [Taylor2000, Table 2.3]: det N = (−Y_v)(m x_G − N_r) − (m − Y_r)(−N_v) = −3.7072e-7
    /// (written out here), so the linear model is course unstable: exactly one positive
    /// eigenvalue of −M⁻¹N. The steady turning rate from the coefficients,
    /// r′ = (n11 b2 − n21 b1)/det N · δ and v′ = (n22 b1 − n12 b2)/det N · δ (Cramer's rule on
    /// N ν = b δ, written out here), is an equilibrium of the model (started there, it stays
    /// within 1e-6 relative for 60 s) — an unstable one, with r′ of opposite sign to δ.
    #[test]
    fn esso_osaka_steady_turn_and_stability() {
        let (n11, n12, n21, n22): (f64, f64, f64, f64) = (0.0244, 0.0138, 1.4578e-3, 8.093e-4);
        let det_n = n11 * n22 - n12 * n21;
        assert!((det_n + 3.7072e-7).abs() < 1e-10, "{det_n}");
        let s0 = NomotoShip::esso_osaka();
        let NomotoModel::SwayYaw { m, b, .. } = s0.model else {
            panic!()
        };
        let mm = Matrix2::new(m[0][0], m[0][1], m[1][0], m[1][1]);
        let nn = Matrix2::new(n11, n12, n21, n22);
        let a = -mm.try_inverse().unwrap() * nn;
        let e = a.complex_eigenvalues();
        let positive = e.iter().filter(|z| z.re > 0.0).count();
        println!("Esso Osaka eigenvalues (1/t'): {e:?}, M = {m:?}, b = {b:?}");
        assert_eq!(positive, 1);

        let d = 10.0 * std::f64::consts::PI / 180.0;
        let r_ss = (n11 * b[1] - n21 * b[0]) / det_n * d;
        let v_ss = (n22 * b[0] - n12 * b[1]) / det_n * d;
        println!("Esso Osaka 10 deg: steady r' = {r_ss:.4}, v' = {v_ss:.4} (unstable equilibrium)");
        assert!(r_ss < 0.0);
        let (t_n, k_n) = s0.nomoto_constants();
        assert!((k_n * d - r_ss).abs() < 1e-12 * r_ss.abs());
        println!("Esso Osaka first-order Nomoto: T' = {t_n:.3}, K' = {k_n:.3}");
        let mut s = s0.clone();
        s.set_motion(v_ss, r_ss, 0.0);
        let inp = NomotoInputs {
            rudder: d,
            ..Default::default()
        };
        for _ in 0..60 {
            s.step(&inp, 1.0);
        }
        let o = s.outputs();
        assert!((o.r_prime - r_ss).abs() < 1e-6 * r_ss.abs());
        assert!((o.v_prime - v_ss).abs() < 1e-6 * v_ss.abs());
    }

    /// The sway-yaw model reduces to the first-order Nomoto one for consistent data: with
    /// M = diag(m1, T), N = diag(n1, 1), b = [0, K] the yaw rate follows T ṙ′ + r′ = K δ.
    #[test]
    fn sway_yaw_consistent_with_nomoto() {
        let model = NomotoModel::SwayYaw {
            m: [[0.02, 0.0], [0.0, 1.9287]],
            n: [[0.03, 0.0], [0.0, 1.0]],
            b: [0.0, 2.04],
        };
        let mut a = NomotoShip::new(model, 466.0 * FOOT, 22.0 * KNOT).unwrap();
        let mut b = NomotoShip::ddg51();
        let inp = NomotoInputs {
            rudder: 0.1,
            current_speed: 1.0,
            current_direction: 0.5,
            yaw_disturbance: 0.0,
        };
        for _ in 0..100 {
            a.step(&inp, 1.0);
            b.step(&inp, 1.0);
        }
        for i in 0..5 {
            assert!((a.state()[i] - b.state()[i]).abs() < 1e-12 * (1.0 + b.state()[i].abs()));
        }
        let (t, k) = a.nomoto_constants();
        assert!((t - 1.9287).abs() < 1e-12 && (k - 2.04).abs() < 1e-12);
    }

    #[test]
    fn rejects_bad_parameters() {
        let e =
            NomotoShip::new(NomotoModel::FirstOrder { t: -1.0, k: 1.0 }, 100.0, 5.0).unwrap_err();
        assert_eq!(e.name, "t");
        let e =
            NomotoShip::new(NomotoModel::FirstOrder { t: 1.0, k: 1.0 }, 100.0, 0.0).unwrap_err();
        assert_eq!(e.name, "speed");
    }
}
