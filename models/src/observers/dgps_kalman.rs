//! The DGPS position/velocity Kalman filter of [Artyszuk2003] and its manoeuvre bias.
//!
//! # Source
//! [Artyszuk2003, sec. 1-2, eqs. (1)-(7)], with steady-state reference values computed from
//! these equations ([DERIVED], not printed in the paper):
//! ```text
//! x = [v_NS, v_EW, x, y],  z = [x_DGPS, y_DGPS]
//! Φ = [[1,0,0,0],[0,1,0,0],[Δt,0,1,0],[0,Δt,0,1]],  H = [[0,0,1,0],[0,0,0,1]]
//! R = diag(4, 4) m²,  Q = S_p [[Δt,0,Δt²/2,0],[0,Δt,0,Δt²/2],[Δt²/2,0,Δt³/3,0],[0,Δt²/2,0,Δt³/3]]
//! P⁻ = ΦPΦᵀ + Q,  K = P⁻Hᵀ(HP⁻Hᵀ + R)⁻¹,  P = (I − KH)P⁻;  x = Φx + K(z − HΦx)   [Artyszuk2003, eq. (5)]
//! v_xy = sqrt(v_NS² + v_EW²)   [Artyszuk2003, eq. (6)],   β_A = ψ − atan2(v_EW, v_NS)   [Artyszuk2003, eq. (7)]
//! ```
//! # Readings taken
//! * S_p in m²/s³ (PSD of a white acceleration; the paper gives no unit), Δt = 1 s.
//! * [Artyszuk2003, eq. (7)] is evaluated with atan2 and wrapped to (−π, π]; ψ is the gyro heading (the paper's
//!   "course angle ψ" after [Artyszuk2003, eq. (7)] is the heading).
//! * Current correction [Artyszuk2003, sec. 1]: the body-frame water-related velocity is the
//!   ground-related one minus Dᵀ(ψ)·|v_c|[cos γ_c, sin γ_c], γ_c the direction the current flows
//!   *toward* (0 = a north current moving the ship north, [Artyszuk2003, sec. 1]), and
//!   tan β_A^water = −v_y^water / v_x^water [Artyszuk2003, sec. 1], evaluated with atan2 as [Artyszuk2003, eq. (7)]. The
//!   ground-related body velocity is the filter's [v_NS, v_EW] rotated by Dᵀ(ψ).
//! * The steady-state form ([Artyszuk2003, eq. (5)], the paper's results) is the default; the full time-varying
//!   recursion from P₀ is an option. A co-simulation step h is ⌈h/Δt⌉ filter cycles with the
//!   measurement held.

use crate::error::{check_non_negative, check_positive};
use crate::hull::wrap_pi;
use crate::math::{atan2, hypot, sin_cos};
use nalgebra::{Matrix2, SMatrix, SVector};
use serde::{Deserialize, Serialize};

type M4 = SMatrix<f64, 4, 4>;
type M42 = SMatrix<f64, 4, 2>;
type M24 = SMatrix<f64, 2, 4>;
type V4 = SVector<f64, 4>;

/// Φ, H, Q, R of [Artyszuk2003, eqs. (3)-(4)].
pub fn model(dt: f64, sp: f64, r: f64) -> (M4, M24, M4, Matrix2<f64>) {
    let mut phi = M4::identity();
    phi[(2, 0)] = dt;
    phi[(3, 1)] = dt;
    let mut h = M24::zeros();
    h[(0, 2)] = 1.0;
    h[(1, 3)] = 1.0;
    let mut q = M4::zeros();
    for i in 0..2 {
        q[(i, i)] = sp * dt;
        q[(i, i + 2)] = sp * dt * dt / 2.0;
        q[(i + 2, i)] = sp * dt * dt / 2.0;
        q[(i + 2, i + 2)] = sp * dt * dt * dt / 3.0;
    }
    (phi, h, q, Matrix2::identity() * r)
}

/// One cycle of the covariance recursion: returns (P⁻, K, P⁺) from the previous P⁺.
pub fn riccati_cycle(p: &M4, dt: f64, sp: f64, r: f64) -> (M4, M42, M4) {
    let (phi, h, q, rr) = model(dt, sp, r);
    let pm = phi * p * phi.transpose() + q;
    let s = h * pm * h.transpose() + rr;
    let k = pm * h.transpose() * s.try_inverse().unwrap_or_else(Matrix2::zeros);
    let pp = (M4::identity() - k * h) * pm;
    (pm, k, (pp + pp.transpose()) * 0.5)
}

/// Steady-state gain K∞ and a-priori / a-posteriori P∞ by iterating the recursion from P₀ = 0
/// until K changes by less than 1e-15 (relative).
pub fn steady_state(dt: f64, sp: f64, r: f64) -> (M42, M4, M4) {
    let mut p = M4::zeros();
    let mut last = M42::zeros();
    for _ in 0..100_000 {
        let (pm, k, pp) = riccati_cycle(&p, dt, sp, r);
        p = pp;
        if (k - last).norm() <= 1e-15 * k.norm() {
            return (k, pm, pp);
        }
        last = k;
    }
    let (pm, k, pp) = riccati_cycle(&p, dt, sp, r);
    (k, pm, pp)
}

/// Filter parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DgpsKalmanParams {
    /// Time-update step Δt [s] (1).
    pub dt: f64,
    /// Process-noise level S_p [m²/s³] (0.001 low, 0.01 optimal, 0.1 high).
    pub sp: f64,
    /// Measurement variance per axis [m²] (4: σ = 2 m).
    pub r: f64,
    /// Full time-varying recursion from P₀ (else the steady-state form, [Artyszuk2003, eq. (5)]).
    pub full_recursion: bool,
    /// P₀ = p0 · I for the full recursion.
    pub p0: f64,
}

impl Default for DgpsKalmanParams {
    fn default() -> Self {
        DgpsKalmanParams {
            dt: 1.0,
            sp: 0.01,
            r: 4.0,
            full_recursion: false,
            p0: 100.0,
        }
    }
}

impl DgpsKalmanParams {
    pub fn validate(&self) -> Result<(), String> {
        for (n, v) in [("dt", self.dt), ("sp", self.sp), ("r", self.r)] {
            check_positive(n, v)?;
        }
        check_non_negative("p0", self.p0)?;
        Ok(())
    }
}

/// The filter. State [v_NS, v_EW, x, y].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DgpsKalman {
    params: DgpsKalmanParams,
    phi: M4,
    h: M24,
    k_inf: M42,
    k: M42,
    p: M4,
    x: V4,
    innovation: [f64; 2],
}

impl DgpsKalman {
    /// A filter with estimate [v_NS, v_EW, x, y] = `x0`.
    pub fn new(params: DgpsKalmanParams, x0: [f64; 4]) -> Result<Self, String> {
        params.validate()?;
        let (phi, h, _, _) = model(params.dt, params.sp, params.r);
        let (k_inf, _, _) = steady_state(params.dt, params.sp, params.r);
        Ok(DgpsKalman {
            params,
            phi,
            h,
            k: k_inf,
            k_inf,
            p: M4::identity() * params.p0,
            x: V4::from_row_slice(&x0),
            innovation: [0.0; 2],
        })
    }

    pub fn params(&self) -> &DgpsKalmanParams {
        &self.params
    }

    /// Steady-state gain K∞.
    pub fn steady_gain(&self) -> &M42 {
        &self.k_inf
    }

    /// Gain used in the last cycle.
    pub fn gain(&self) -> &M42 {
        &self.k
    }

    /// [v_NS, v_EW, x, y].
    pub fn estimate(&self) -> [f64; 4] {
        [self.x[0], self.x[1], self.x[2], self.x[3]]
    }

    /// z − HΦx of the last cycle [m].
    pub fn innovation(&self) -> [f64; 2] {
        self.innovation
    }

    /// One filter cycle with the DGPS fix (north, east) [m].
    #[inline]
    pub fn cycle(&mut self, north: f64, east: f64) {
        if self.params.full_recursion {
            let (_, k, p) = riccati_cycle(&self.p, self.params.dt, self.params.sp, self.params.r);
            self.k = k;
            self.p = p;
        }
        let xm = self.phi * self.x;
        let nu = nalgebra::Vector2::new(north, east) - self.h * xm;
        self.x = xm + self.k * nu;
        self.innovation = [nu[0], nu[1]];
    }

    /// Advances `h` seconds: ⌈h/Δt⌉ cycles with the fix held.
    pub fn step(&mut self, north: f64, east: f64, h: f64) {
        for _ in 0..crate::integrate::substeps(h, self.params.dt) {
            self.cycle(north, east);
        }
    }

    /// Speed over ground v_xy [Artyszuk2003, eq. (6)] [m/s].
    pub fn speed_over_ground(&self) -> f64 {
        hypot(self.x[0], self.x[1])
    }

    /// Course over ground atan2(v_EW, v_NS) [rad].
    pub fn course_over_ground(&self) -> f64 {
        atan2(self.x[1], self.x[0])
    }

    /// Drift angle β_A = ψ − χ [Artyszuk2003, eq. (7)], wrapped to (−π, π].
    pub fn drift_angle(&self, heading: f64) -> f64 {
        drift_angle(heading, self.x[0], self.x[1])
    }
}

impl DgpsKalman {
    /// Ground-related body velocity [v_x, v_y] = Dᵀ(ψ)[v_NS, v_EW] [m/s] (surge, sway to
    /// starboard) at gyro heading `heading`.
    pub fn body_velocity_over_ground(&self, heading: f64) -> [f64; 2] {
        rotate_to_body(heading, self.x[0], self.x[1])
    }

    /// Water-related body velocity [Artyszuk2003, sec. 1] for a current of `current_speed` [m/s] flowing toward
    /// `current_direction` [rad from north, clockwise].
    pub fn body_velocity_through_water(
        &self,
        heading: f64,
        current_speed: f64,
        current_direction: f64,
    ) -> [f64; 2] {
        let g = self.body_velocity_over_ground(heading);
        water_velocity(heading, g, current_speed, current_direction)
    }

    /// Water-related drift angle β_A^water = atan2(−v_y^water, v_x^water) [Artyszuk2003, sec. 1].
    pub fn drift_angle_through_water(
        &self,
        heading: f64,
        current_speed: f64,
        current_direction: f64,
    ) -> f64 {
        let w = self.body_velocity_through_water(heading, current_speed, current_direction);
        atan2(-w[1], w[0])
    }
}

/// Dᵀ(ψ)[a_N, a_E] = [cos ψ a_N + sin ψ a_E, −sin ψ a_N + cos ψ a_E] [Artyszuk2003, sec. 1].
pub fn rotate_to_body(heading: f64, north: f64, east: f64) -> [f64; 2] {
    let (s, c) = sin_cos(heading);
    [c * north + s * east, -s * north + c * east]
}

/// [Artyszuk2003, sec. 1]: water-related body velocity = ground-related body velocity `ground` minus
/// Dᵀ(ψ)·|v_c|[cos γ_c, sin γ_c].
pub fn water_velocity(
    heading: f64,
    ground: [f64; 2],
    current_speed: f64,
    current_direction: f64,
) -> [f64; 2] {
    let (s, c) = sin_cos(current_direction);
    let cb = rotate_to_body(heading, current_speed * c, current_speed * s);
    [ground[0] - cb[0], ground[1] - cb[1]]
}

/// [Artyszuk2003, eq. (7)]: β_A = ψ − atan2(v_EW, v_NS), wrapped.
pub fn drift_angle(heading: f64, v_ns: f64, v_ew: f64) -> f64 {
    wrap_pi(heading - atan2(v_ew, v_ns))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{cos, sin};

    /// Steady-state gains ([DERIVED] from [Artyszuk2003, eqs. (3)-(5)]): K∞ = (k_v, k_p) per axis: S_p 0.001 → (0.014466, 0.162914); 0.01 →
    /// (0.042688, 0.271106); 0.1 → (0.11936, 0.430124); a-priori P∞ (P_vv, P_vp, P_pp) and the
    /// a-posteriori one; tolerance 1e-5 (the reference values' precision), 1e-4 for the 5-significant-digit 0.11936.
    #[test]
    fn steady_gains_t1() {
        let cases = [
            (
                0.001,
                0.014466,
                0.162914,
                [0.011762, 0.069127, 0.778479],
                [0.010762, 0.057865, 0.651654],
            ),
            (
                0.01,
                0.042688,
                0.271106,
                [0.068509, 0.23426, 1.487769],
                [0.058509, 0.170751, 1.084426],
            ),
            (
                0.1,
                0.11936,
                0.430124,
                [0.410357, 0.837799, 3.019069],
                [0.310357, 0.477442, 1.720495],
            ),
        ];
        for (sp, kv, kp, pm, pp) in cases {
            let (k, pmin, pplus) = steady_state(1.0, sp, 4.0);
            assert!(
                (k[(0, 0)] - kv).abs() < 1e-5 && (k[(1, 1)] - kv).abs() < 1e-5,
                "{k}"
            );
            assert!((k[(2, 0)] - kp).abs() < 1e-5 && (k[(3, 1)] - kp).abs() < 1e-5);
            assert!(k[(0, 1)].abs() < 1e-15 && k[(2, 1)].abs() < 1e-15);
            for (i, j, n) in [(0, 0, 0), (0, 2, 1), (2, 2, 2)] {
                assert!((pmin[(i, j)] - pm[n]).abs() < 1e-5, "P- {sp} {pmin}");
                assert!((pplus[(i, j)] - pp[n]).abs() < 1e-5, "P+ {sp} {pplus}");
            }
        }
    }

    /// The gain reaches 1 % of K∞ within ~30 cycles for S_p ≥ 0.01 whatever P₀ (reference re-computation: 20, 16,
    /// 18, 19 cycles at 0.01 for P₀ = 0, I, diag(100, 100, 4, 4), 1e4 I).
    #[test]
    fn gain_convergence_cycles() {
        let (kinf, _, _) = steady_state(1.0, 0.01, 4.0);
        let mut p0d = M4::identity() * 4.0;
        p0d[(0, 0)] = 100.0;
        p0d[(1, 1)] = 100.0;
        for (p0, want) in [
            (M4::zeros(), 20),
            (M4::identity(), 16),
            (p0d, 18),
            (M4::identity() * 1e4, 19),
        ] {
            let mut p = p0;
            let mut n = 0;
            for c in 1..200 {
                let (_, k, pp) = riccati_cycle(&p, 1.0, 0.01, 4.0);
                p = pp;
                if (k - kinf).abs().max() <= 0.01 * kinf.abs().max() && n == 0 {
                    n = c;
                }
            }
            eprintln!("cycles {n} (spec {want})");
            assert!(n <= 30 && (n as i32 - want).abs() <= 3, "{n} vs {want}");
        }
    }

    /// T4: noise-free constant deceleration a at S_p = 0.01: steady velocity bias 5.85·a (the
    /// estimate is *higher*) and position bias 17.1·a (the estimate runs ahead along the track);
    /// ours 5.851·a and 17.08·a, tolerance 1 %. T3: constant velocity, zero bias.
    #[test]
    fn deceleration_and_constant_velocity_bias() {
        let mut f = DgpsKalman::new(DgpsKalmanParams::default(), [7.0, 0.0, 0.0, 0.0]).unwrap();
        let a = 0.1;
        let (mut v, mut x) = (7.0, 0.0);
        for _ in 0..60 {
            v -= a; // truth at the next fix (exact kinematics of a constant deceleration)
            x += v + 0.5 * a;
            f.cycle(x, 0.0);
        }
        let e = f.estimate();
        eprintln!("velocity bias {} position bias {}", e[0] - v, e[2] - x);
        assert!(((e[0] - v) - 5.85 * a).abs() < 0.01 * 5.85 * a);
        assert!(((e[2] - x) - 17.1 * a).abs() < 0.01 * 17.1 * a);
        let mut f = DgpsKalman::new(DgpsKalmanParams::default(), [0.0; 4]).unwrap();
        for k in 1..400 {
            f.cycle(3.0 * k as f64, -2.0 * k as f64);
        }
        let e = f.estimate();
        assert!((e[0] - 3.0).abs() < 1e-9 && (e[1] + 2.0).abs() < 1e-9);
        assert!((e[2] - 1197.0).abs() < 1e-7);
    }

    /// T5: noise-free steady turn at r = 0.03 rad/s, 7 m/s, S_p = 0.01: the estimated course lags
    /// by ≈ 5.85 s × r = 10.1° (so β̂ − β ≈ +10°, the paper's "always higher, by even 10°"), and
    /// the speed is right within 0.1 %. Tolerances: 0.3° and 0.1 %.
    #[test]
    fn steady_turn_course_lag() {
        let (u, r) = (7.0, 0.03);
        let mut f = DgpsKalman::new(DgpsKalmanParams::default(), [u, 0.0, 0.0, 0.0]).unwrap();
        let pos = |t: f64| (u / r * sin(r * t), u / r * (1.0 - cos(r * t)));
        let mut t = 0.0;
        for _ in 0..300 {
            t += 1.0;
            let (n, e) = pos(t);
            f.cycle(n, e);
        }
        let chi = r * t;
        let lag = wrap_pi(chi - f.course_over_ground());
        eprintln!(
            "course lag {} deg, speed {}",
            lag.to_degrees(),
            f.speed_over_ground()
        );
        assert!((lag.to_degrees() - 10.1).abs() < 0.3);
        assert!((f.speed_over_ground() / u - 1.0).abs() < 1e-3);
        // drift angle: heading = course (no true drift) -> β̂ ≈ +10°
        assert!((f.drift_angle(chi).to_degrees() - lag.to_degrees()).abs() < 1e-9);
    }

    /// Worked example of [Artyszuk2003, eq. (7)]: ψ = 30°, 5 m/s at course 20° ⇒ β_A = +10.00°.
    #[test]
    fn drift_angle_example() {
        let (vn, ve) = (5.0 * cos(20f64.to_radians()), 5.0 * sin(20f64.to_radians()));
        assert!((vn - 4.6985).abs() < 1e-4 && (ve - 1.7101).abs() < 1e-4);
        assert!((drift_angle(30f64.to_radians(), vn, ve).to_degrees() - 10.0).abs() < 1e-9);
    }

    /// Worked example of the current correction [Artyszuk2003, sec. 1]: ψ = 90°, ground body velocity [7, 0] m/s, a 0.25 m/s north
    /// current (γ_c = 0) ⇒ Dᵀ·[0.25, 0] = [0, −0.25], water velocity [7.0, 0.25] m/s and
    /// β_A^water = atan(−0.25/7) = −2.045° while β_A^ground = 0. Also through the filter: a
    /// filter holding v = [0, 7] (course east) at heading 90° gives the same numbers.
    #[test]
    fn current_correction_t8() {
        let psi = 90f64.to_radians();
        let w = water_velocity(psi, [7.0, 0.0], 0.25, 0.0);
        assert!(
            (w[0] - 7.0).abs() < 1e-12 && (w[1] - 0.25).abs() < 1e-12,
            "{w:?}"
        );
        let mut f = DgpsKalman::new(DgpsKalmanParams::default(), [0.0, 7.0, 0.0, 0.0]).unwrap();
        let g = f.body_velocity_over_ground(psi);
        assert!((g[0] - 7.0).abs() < 1e-12 && g[1].abs() < 1e-12);
        let wf = f.body_velocity_through_water(psi, 0.25, 0.0);
        assert!((wf[0] - 7.0).abs() < 1e-12 && (wf[1] - 0.25).abs() < 1e-12);
        let beta = f.drift_angle_through_water(psi, 0.25, 0.0).to_degrees();
        assert!((beta + 2.045).abs() < 5e-4, "{beta}");
        assert!(f.drift_angle(psi).abs() < 1e-12);
        // Without current the water and ground drift angles agree ([Artyszuk2003, eq. (7)] vs the water-related form of [Artyszuk2003, sec. 1]).
        for k in 1..100 {
            f.cycle(k as f64 * 0.5, k as f64 * 6.9);
        }
        for psi in [0.3, 1.4, -2.0] {
            let d = wrap_pi(f.drift_angle_through_water(psi, 0.0, 1.0) - f.drift_angle(psi));
            assert!(d.abs() < 1e-12);
        }
    }

    /// T2: the full recursion from any P₀ becomes the steady-state form.
    #[test]
    fn full_recursion_converges_to_steady_form() {
        let p = DgpsKalmanParams {
            full_recursion: true,
            ..Default::default()
        };
        let mut f = DgpsKalman::new(p, [0.0; 4]).unwrap();
        for k in 0..200 {
            f.cycle(k as f64, 0.5 * k as f64);
        }
        assert!((f.gain() - f.steady_gain()).norm() < 1e-9);
    }
}
