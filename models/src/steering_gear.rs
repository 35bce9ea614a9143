//! Steering machine (rudder servo) with rudder-angle and rudder-rate limits.
//!
//! # Source and the reading taken
//! [Klugt1987, sec. 2.3 and Fig. 2.8, sec. 5.2.1-5.2.2] and
//! [Klugt1987, sec. 6.5.2, eqs. (6.35)-(6.49)].
//! Fig. 2.8 itself is lost in the OCR; the text says only that it holds "two limiters, one
//! describing the limitation of the rudder angle and the other describing the limitation of the
//! rudder speed", the angle limit being "the rudder-angle constraints of the autopilot, or ... the
//! mechanical constraints". The text admits two places for the angle limiter (on the set point,
//! or as clamping of the integrator). This model applies **both**, with the same limit δ_max:
//!
//! ```text
//! δ_c  = sat(δ_g, ±δ_max)                         set-point (autopilot) limit
//! e_δ  = δ_c − δ_w                                servo error ([Klugt1987, eq. (6.38)], read as e_δ = τ_δ δ̇_w)
//! δ̇_w = sat(e_δ / τ_δ, ±δ̇_max)                   gain 1/τ_δ, then the rate limiter
//! δ_w  = sat(∫ δ̇_w dt, ±δ_max)                    mechanical stop
//! ```
//!
//! For the first-order servo the two readings give identical δ_w (a first-order lag of a signal
//! bounded by δ_max stays within δ_max); the stop only matters for the second-order servo.
//! Small-signal transfer: δ_w/δ_g = 1/(τ_δ s + 1) [Klugt1987, eq. (6.35)].
//!
//! Second-order servo [Klugt1987, sec. 6.5.2, eqs. (6.41)-(6.42)]: the gain 1/τ_δ is replaced by the main-servo
//! dynamics K/(τ s + 1), giving H = ω0²/(s² + 2 z0 ω0 s + ω0²) with ω0² = K/τ, 2 z0 ω0 = 1/τ.
//! The rate limiter acts on the main-servo output (the rudder speed).
//!
//! The other sources use special cases of the first-order servo:
//! * DDG-51 [Taylor2000, eq. (5.28)]: δ/δ_c = 6/(s + 6) in nondimensional time t' = tU/L, with a
//!   ±30° command limit and no rate limit: τ_δ = L/(6U) s (≈ 2.09 s at 22 kn).
//! * Tokyo Maru [Parsons1980, eq. (10)]: dδ'/dt' = (δ'_c − δ')/T_r with T_r = 10 s full scale,
//!   T_r = 0.212874 nondimensional (derived here, not printed in the source), no rate limit.
//!
//! # Integration
//! The command is held constant over a step (zero-order hold, as every FMI master delivers it).
//! The first-order servo is piecewise linear/exponential and is integrated **exactly**: a
//! rate-limited ramp until |e_δ| = δ̇_max τ_δ, then the exponential approach. Results therefore do
//! not depend on the step size. The second-order servo uses classical RK4 on a fixed sub-step of at
//! most [`SteeringGearParams::max_substep`].

use crate::error::{check_positive, ParamError};
use crate::math::exp;
use crate::memo::{bits, Bits, Memo};
use serde::{Deserialize, Serialize};

/// Order of the servo loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ServoOrder {
    /// Gain 1/τ_δ followed by the rate limiter [Klugt1987, Fig. 2.8, eq. (6.35)].
    First,
    /// Main servo K/(τ s + 1) followed by the rate limiter [Klugt1987, eqs. (6.41)-(6.42)].
    Second,
}

/// Parameters of the steering machine. Angles in rad, rates in rad/s, times in s.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SteeringGearParams {
    /// Rudder-angle limit δ_max [rad], applied to the set point and as the mechanical stop.
    pub angle_max: f64,
    /// Rudder-rate limit δ̇_max [rad/s].
    pub rate_max: f64,
    /// Whether the rate limiter is present (false for the gears of [Taylor2000] and [Parsons1980]).
    pub rate_limited: bool,
    /// Servo time constant τ_δ [s] of the first-order servo.
    pub time_constant: f64,
    /// First- or second-order servo.
    pub order: ServoOrder,
    /// Natural frequency ω0 [rad/s] of the second-order servo [Klugt1987, eq. (6.42)].
    pub omega0: f64,
    /// Relative damping z0 [-] of the second-order servo ([Klugt1987, eq. (6.44)] requires z0 ≥ 1).
    pub zeta0: f64,
    /// Largest RK4 sub-step [s] for the second-order servo.
    pub max_substep: f64,
}

const DEG: f64 = std::f64::consts::PI / 180.0;

impl SteeringGearParams {
    /// The RRS steering machine of [Klugt1987]: δ_max = 22°, δ̇_max = 15 deg/s (the settings of the
    /// trials of [Klugt1987, Table 7.1]), τ_δ = 0.2 s (within the rule τ_δ ≤ 0.2/ω_n of
    /// [Klugt1987, eq. (6.37)] for ω_n = 0.63-0.75 rad/s; the thesis prints no single value),
    /// first-order servo.
    pub fn rrs_klugt1987() -> Self {
        SteeringGearParams {
            angle_max: 22.0 * DEG,
            rate_max: 15.0 * DEG,
            rate_limited: true,
            time_constant: 0.2,
            order: ServoOrder::First,
            omega0: 7.5,
            zeta0: 1.0,
            max_substep: 1e-3,
        }
    }

    /// The DDG-51 gear [Taylor2000, eq. (5.28)]: 6/(s+6) in nondimensional time, i.e.
    /// τ = L/(6U) seconds, ±30° command limit, no rate limit.
    pub fn ddg51_taylor2000(length_m: f64, speed_m_s: f64) -> Self {
        SteeringGearParams {
            angle_max: 30.0 * DEG,
            rate_limited: false,
            time_constant: length_m / (6.0 * speed_m_s),
            ..Self::rrs_klugt1987()
        }
    }

    /// The Tokyo Maru gear [Parsons1980, eq. (10)]: first-order lag T_r = 10 s full scale
    /// (T_r' = 0.212874, derived here), no rate limit; δ_max is not given there and is left at 35°.
    pub fn tokyo_maru_parsons1980() -> Self {
        SteeringGearParams {
            angle_max: 35.0 * DEG,
            rate_limited: false,
            time_constant: 10.0,
            ..Self::rrs_klugt1987()
        }
    }

    /// Checks every parameter; the message names the parameter and its value.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("angle_max", self.angle_max)?;
        check_positive("rate_max", self.rate_max)?;
        check_positive("time_constant", self.time_constant)?;
        check_positive("omega0", self.omega0)?;
        check_positive("zeta0", self.zeta0)?;
        check_positive("max_substep", self.max_substep)?;
        Ok(())
    }
}

impl Default for SteeringGearParams {
    fn default() -> Self {
        Self::rrs_klugt1987()
    }
}

/// The steering machine's state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SteeringGear {
    pub params: SteeringGearParams,
    /// Actual rudder angle δ_w [rad].
    angle: f64,
    /// Main-servo output (commanded rudder speed before the rate limiter) [rad/s]; second order only.
    servo: f64,
    /// Rudder speed δ̇_w [rad/s] at the current time.
    rate: f64,
    /// Set point after the angle limiter [rad].
    command: f64,
    /// Time [s] spent with the rate limiter active since the start.
    rate_saturated_time: f64,
    /// e^(−t/τ) of the first-order servo for the last two durations t (the communication step,
    /// unless the rate limiter was active; derived, see [`crate::memo`]).
    #[serde(skip)]
    decay: Memo<Bits<2>, f64, 2>,
}

impl SteeringGear {
    /// A gear at rest at `angle0` (clamped to ±δ_max) with zero command error.
    pub fn new(params: SteeringGearParams, angle0: f64) -> Result<Self, ParamError> {
        params.validate()?;
        let angle = angle0.clamp(-params.angle_max, params.angle_max);
        Ok(SteeringGear {
            params,
            angle,
            servo: 0.0,
            rate: 0.0,
            command: angle,
            rate_saturated_time: 0.0,
            decay: Memo::default(),
        })
    }

    /// Actual rudder angle δ_w [rad].
    pub fn angle(&self) -> f64 {
        self.angle
    }

    /// Rudder speed δ̇_w [rad/s].
    pub fn rate(&self) -> f64 {
        self.rate
    }

    /// Set point after the angle limiter [rad].
    pub fn limited_command(&self) -> f64 {
        self.command
    }

    /// Total time [s] the rate limiter has been active.
    pub fn rate_saturated_time(&self) -> f64 {
        self.rate_saturated_time
    }

    /// Whether the rate limiter is active at the current time.
    pub fn rate_saturated(&self) -> bool {
        self.params.rate_limited && self.rate.abs() >= self.params.rate_max * (1.0 - 1e-12)
    }

    /// Sets the set point δ_g and updates the instantaneous rate (no time passes).
    pub fn set_command(&mut self, command: f64) {
        let p = &self.params;
        self.command = command.clamp(-p.angle_max, p.angle_max);
        self.rate = match p.order {
            ServoOrder::First => self.limit_rate((self.command - self.angle) / p.time_constant),
            ServoOrder::Second => self.limit_rate(self.servo),
        };
    }

    /// Whether the set point is being clipped by the angle limiter.
    pub fn command_saturated(command: f64, params: &SteeringGearParams) -> bool {
        command.abs() > params.angle_max
    }

    fn limit_rate(&self, r: f64) -> f64 {
        if self.params.rate_limited {
            r.clamp(-self.params.rate_max, self.params.rate_max)
        } else {
            r
        }
    }

    /// Advances the gear by `h` seconds with the set point `command` held constant.
    pub fn step(&mut self, command: f64, h: f64) {
        self.set_command(command);
        if h <= 0.0 {
            return;
        }
        match self.params.order {
            ServoOrder::First => self.step_first_order(h),
            ServoOrder::Second => self.step_second_order(h),
        }
        self.set_command(command);
    }

    /// Exact solution of δ̇ = sat((δ_c − δ)/τ, ±R) over `h` with δ_c constant.
    fn step_first_order(&mut self, h: f64) {
        let p = &self.params;
        let tau = p.time_constant;
        let c = self.command;
        let e = c - self.angle;
        let mut remaining = h;
        let mut angle = self.angle;
        let mut saturated = 0.0;
        if p.rate_limited {
            let band = p.rate_max * tau; // |e| above which the rate limiter is active
            if e.abs() > band {
                let t_ramp = (e.abs() - band) / p.rate_max;
                let t = t_ramp.min(remaining);
                angle += e.signum() * p.rate_max * t;
                saturated = t;
                remaining -= t;
                if remaining > 0.0 {
                    // leave the ramp exactly on the band edge (avoids rounding drift)
                    angle = c - e.signum() * band;
                }
            }
        }
        if remaining > 0.0 {
            let decay = *self
                .decay
                .get(bits([remaining, tau]), || exp(-remaining / tau));
            angle = c - (c - angle) * decay;
        }
        let p = &self.params;
        self.angle = angle.clamp(-p.angle_max, p.angle_max);
        self.rate_saturated_time += saturated;
    }

    /// RK4 on (δ, u): u̇ = (K e − u)/τ_m, δ̇ = sat(u), with τ_m = 1/(2 z0 ω0), K = ω0² τ_m.
    fn step_second_order(&mut self, h: f64) {
        let p = self.params.clone();
        let tau_m = 1.0 / (2.0 * p.zeta0 * p.omega0);
        let gain = p.omega0 * p.omega0 * tau_m;
        let n = (h / p.max_substep).ceil().max(1.0);
        let dt = h / n;
        let c = self.command;
        let f = |d: f64, u: f64| -> (f64, f64) {
            let rate = if p.rate_limited {
                u.clamp(-p.rate_max, p.rate_max)
            } else {
                u
            };
            (rate, (gain * (c - d) - u) / tau_m)
        };
        for _ in 0..n as usize {
            let (d, u) = (self.angle, self.servo);
            let (k1d, k1u) = f(d, u);
            let (k2d, k2u) = f(d + 0.5 * dt * k1d, u + 0.5 * dt * k1u);
            let (k3d, k3u) = f(d + 0.5 * dt * k2d, u + 0.5 * dt * k2u);
            let (k4d, k4u) = f(d + dt * k3d, u + dt * k3u);
            let mut d_new = d + dt / 6.0 * (k1d + 2.0 * k2d + 2.0 * k3d + k4d);
            let u_new = u + dt / 6.0 * (k1u + 2.0 * k2u + 2.0 * k3u + k4u);
            if d_new.abs() > p.angle_max {
                // mechanical stop: the rudder stands, the servo output cannot drive it further
                d_new = d_new.clamp(-p.angle_max, p.angle_max);
            }
            if p.rate_limited && u.abs() >= p.rate_max {
                self.rate_saturated_time += dt;
            }
            self.angle = d_new;
            self.servo = u_new;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{asin, atan2, cos, ln, sin};
    use std::f64::consts::PI;

    fn gear(params: SteeringGearParams) -> SteeringGear {
        SteeringGear::new(params, 0.0).unwrap()
    }

    /// Least-squares first harmonic (a cos + b sin) of samples over whole periods of `omega`.
    fn first_harmonic(t: &[f64], y: &[f64], omega: f64) -> (f64, f64) {
        let n = t.len() as f64;
        let a = 2.0 / n
            * t.iter()
                .zip(y)
                .map(|(t, y)| y * cos(omega * t))
                .sum::<f64>();
        let b = 2.0 / n
            * t.iter()
                .zip(y)
                .map(|(t, y)| y * sin(omega * t))
                .sum::<f64>();
        ((a * a + b * b).sqrt(), atan2(a, b)) // amplitude, phase relative to sin(omega t)
    }

    #[test]
    fn invalid_parameters_are_named() {
        let p = SteeringGearParams {
            time_constant: -1.0,
            ..Default::default()
        };
        let err = SteeringGear::new(p, 0.0).unwrap_err();
        assert_eq!(err.name, "time_constant");
        assert!(err.to_string().contains("time_constant = -1"));
        let p = SteeringGearParams {
            rate_max: f64::NAN,
            ..Default::default()
        };
        assert_eq!(SteeringGear::new(p, 0.0).unwrap_err().name, "rate_max");
    }

    /// Angle limit [Klugt1987, sec. 5.2.1]: with a negligible servo time constant and
    /// an unlimited rate, the angle limit clips the amplitude with no phase shift, and has no
    /// effect for u_δ ≤ δ_max.
    #[test]
    fn t1_angle_limit_clips_without_phase_shift() {
        let dmax = 20.0 * DEG;
        let params = SteeringGearParams {
            angle_max: dmax,
            rate_limited: false,
            time_constant: 1e-4,
            ..Default::default()
        };
        let omega = 0.6;
        let period = 2.0 * PI / omega;
        let h = period / 2000.0;
        for (u, clipped) in [(dmax, false), (2.0 * dmax, true)] {
            let mut g = gear(params.clone());
            let (mut ts, mut ys) = (vec![], vec![]);
            let mut max_dev: f64 = 0.0;
            for k in 0..4000 {
                let t = k as f64 * h;
                let cmd = u * sin(omega * t);
                g.step(cmd, h);
                let t1 = t + h;
                // ideal limiter output at t1 (input held over the step, so compare with cmd at t)
                let ideal = cmd.clamp(-dmax, dmax);
                max_dev = max_dev.max((g.angle() - ideal).abs());
                if k >= 2000 {
                    // the held command was sampled at t: pair the output with that instant
                    ts.push(t);
                    ys.push(g.angle());
                }
                assert!(g.angle().abs() <= dmax + 1e-15 && t1 > t);
            }
            // the only deviation is the 1e-4 s servo lag: |e| ≤ τ·max|δ̇_g|
            assert!(
                max_dev < 1e-4 * u * omega * 1.01 + 1e-12,
                "u={u}: {max_dev}"
            );
            let (amp, phase) = first_harmonic(&ts, &ys, omega);
            // what remains is the 1e-4 s servo lag: ωτ = 0.003°
            assert!(phase.abs() < 0.01 * DEG, "phase {}", phase / DEG);
            if clipped {
                // first harmonic of a sine clipped at half its amplitude:
                // (2/π)(asin(r) + r√(1−r²)) with r = 1/2  →  0.6090·u
                let r: f64 = 0.5;
                let expected = u * 2.0 / PI * (asin(r) + r * (1.0 - r * r).sqrt());
                assert!(
                    (amp - expected).abs() / expected < 1e-3,
                    "{amp} vs {expected}"
                );
            } else {
                assert!((amp - u).abs() / u < 1e-3);
            }
        }
    }

    /// Rate limit [Klugt1987, sec. 5.2.2, eq. (5.2)]: δ_g = a sin(bt) with ab = 3 δ̇_max. The rate limiter causes a
    /// considerable phase lag and a low-frequency component that decays asymptotically.
    ///
    /// Expected values derived here from the limiter alone (τ_δ → 0): the settled output is a
    /// triangle of slope ±δ̇_max and amplitude δ̇_max·π/(2b) = πa/6; it turns where it meets the
    /// falling input, sin(bt) = π/6, i.e. a lag of π/2 − asin(π/6) = 58.4°, and its fundamental has
    /// amplitude (8/π²)(πa/6) = 0.4244a.
    #[test]
    fn t2_rate_limit_phase_lag_and_decaying_offset() {
        let rate = 15.0 * DEG;
        let b = 0.63;
        let a = 3.0 * rate / b;
        let params = SteeringGearParams {
            angle_max: 2.0 * a,
            rate_max: rate,
            time_constant: 1e-3,
            ..Default::default()
        };
        let mut g = gear(params);
        let period = 2.0 * PI / b;
        let per = 1000;
        let h = period / per as f64;
        let mut means = vec![];
        let (mut ts, mut ys) = (vec![], vec![]);
        for p in 0..12 {
            let mut sum = 0.0;
            for k in 0..per {
                let t = (p * per + k) as f64 * h;
                g.step(a * sin(b * t), h);
                sum += g.angle();
                assert!(g.rate().abs() <= rate * (1.0 + 1e-12));
                if p >= 10 {
                    ts.push(t + h);
                    ys.push(g.angle());
                }
            }
            means.push(sum / per as f64);
        }
        // the first period carries a clear positive low-frequency component ...
        assert!(means[0] > 0.1 * a, "first-period mean {}", means[0] / a);
        // ... that decays (monotonically in magnitude) ...
        for w in means.windows(2) {
            assert!(w[1].abs() <= w[0].abs() + 1e-9 * a, "{means:?}");
        }
        // ... asymptotically towards zero
        assert!(means[11].abs() < 0.02 * a, "last mean {}", means[11] / a);
        let (amp, phase) = first_harmonic(&ts, &ys, b);
        let lag = -phase;
        let expected_lag = PI / 2.0 - asin(PI / 6.0);
        assert!(
            (lag - expected_lag).abs() < 0.5 * DEG,
            "lag {} deg",
            lag / DEG
        );
        assert!(
            (amp / a - 8.0 / (PI * PI) * PI / 6.0).abs() < 0.01,
            "amp {}",
            amp / a
        );
    }

    /// Classification rule [Klugt1987, sec. 2.3]: 35° port to 35° starboard within 30 s needs 2.5 deg/s.
    /// Expected time to come within ε of the target, from the piecewise solution:
    /// (70° − δ̇τ)/δ̇ + τ ln(δ̇τ/ε).
    #[test]
    fn classification_rule_35_to_35_in_30_s() {
        let rate = 2.5 * DEG;
        let tau = 0.2;
        let params = SteeringGearParams {
            angle_max: 35.0 * DEG,
            rate_max: rate,
            time_constant: tau,
            ..Default::default()
        };
        let mut g = SteeringGear::new(params, -35.0 * DEG).unwrap();
        let h = 0.001;
        let eps = 0.01 * DEG;
        let mut t = 0.0;
        let mut k = 0u64;
        while g.angle() < 35.0 * DEG - eps {
            g.step(35.0 * DEG, h);
            k += 1;
            t = k as f64 * h;
            assert!(t < 60.0);
        }
        let expected = (70.0 * DEG - rate * tau) / rate + tau * ln(rate * tau / eps);
        assert!((t - expected).abs() <= h, "{t} vs {expected}");
        assert!(t < 30.0);
        assert!((g.rate_saturated_time() - (70.0 * DEG - rate * tau) / rate).abs() < 1e-9);
    }

    /// DDG-51 gear [Taylor2000, eq. (5.28)]: 6/(s+6) in t' = tU/L with a ±30° command limit. A 40° command
    /// is clipped to 30°, and the response is 30°(1 − e^(−t/τ)), τ = L/(6U).
    #[test]
    fn ddg51_gear_step_response() {
        let (l, u) = (142.0, 22.0 * 1852.0 / 3600.0);
        let p = SteeringGearParams::ddg51_taylor2000(l, u);
        let tau = l / (6.0 * u);
        assert!((tau - 2.0913).abs() < 1e-3); // ≈ 2.09 s at 22 kn (derived: L/(6U))
        let mut g = gear(p);
        for k in 1..=2000 {
            g.step(40.0 * DEG, 0.01);
            let t = k as f64 * 0.01;
            let expected = 30.0 * DEG * (1.0 - exp(-t / tau));
            assert!((g.angle() - expected).abs() < 1e-12, "t={t}");
        }
    }

    /// Tokyo Maru gear [Parsons1980, eq. (10)]: first-order lag T_r = 10 s full scale; 63.2 % at t = T_r, and the
    /// same answer whatever the step size (exact integration).
    #[test]
    fn tokyo_maru_gear_step_response_is_step_size_independent() {
        let p = SteeringGearParams::tokyo_maru_parsons1980();
        for h in [0.01f64, 0.1, 1.0, 2.5, 10.0] {
            let mut g = gear(p.clone());
            let n = (10.0 / h).round() as usize;
            for _ in 0..n {
                g.step(0.1, h);
            }
            let expected = 0.1 * (1.0 - exp(-1.0f64));
            assert!((g.angle() - expected).abs() < 1e-14, "h={h}: {}", g.angle());
        }
    }

    /// Exactness of the rate-limited first-order servo: one big step equals many small ones.
    #[test]
    fn first_order_rate_limited_is_step_size_independent() {
        let p = SteeringGearParams::rrs_klugt1987();
        let mut one = gear(p.clone());
        let mut many = gear(p);
        one.step(0.3, 3.0);
        for _ in 0..3000 {
            many.step(0.3, 0.001);
        }
        assert!((one.angle() - many.angle()).abs() < 1e-13);
        assert!((one.rate_saturated_time() - many.rate_saturated_time()).abs() < 1e-12);
    }

    /// Second-order servo [Klugt1987, eq. (6.42)] with z0 = 1 and no rate limit: the step response is
    /// 1 − (1 + ω0 t) e^(−ω0 t), and its −3 dB bandwidth is ω0·√(√2 − 1) = 0.6436 ω0 [Klugt1987, App. H].
    #[test]
    fn second_order_servo_matches_critically_damped_response() {
        let p = SteeringGearParams {
            order: ServoOrder::Second,
            rate_limited: false,
            omega0: 7.5,
            zeta0: 1.0,
            ..Default::default()
        };
        let step_amp = 0.1;
        let mut g = gear(p.clone());
        for k in 1..=300 {
            g.step(step_amp, 0.01);
            let t = k as f64 * 0.01;
            let w = 7.5 * t;
            let expected = step_amp * (1.0 - (1.0 + w) * exp(-w));
            assert!((g.angle() - expected).abs() < 1e-10, "t={t}");
        }
        // frequency response at B = 0.6436 ω0: gain 1/√2 (small amplitude, steady state)
        let bw = 7.5 * (2f64.sqrt() - 1.0).sqrt();
        let mut g = gear(p);
        let period = 2.0 * PI / bw;
        let h = period / 1000.0;
        let (mut ts, mut ys) = (vec![], vec![]);
        for k in 0..10_000 {
            let t = k as f64 * h;
            g.step(0.01 * sin(bw * (t + 0.5 * h)), h);
            if k >= 5000 {
                ts.push(t + h);
                ys.push(g.angle());
            }
        }
        let (amp, phase) = first_harmonic(&ts, &ys, bw);
        assert!(
            (amp / 0.01 - 0.5f64.sqrt()).abs() < 1e-3,
            "gain {}",
            amp / 0.01
        );
        // [Klugt1987, eq. (6.49)]: phase −2 atan(B/ω0) = −65.5°
        assert!((phase / DEG + 65.5).abs() < 0.2, "phase {}", phase / DEG);
    }

    #[test]
    fn second_order_with_rate_limit_never_exceeds_limits() {
        let p = SteeringGearParams {
            order: ServoOrder::Second,
            ..Default::default()
        };
        let mut g = gear(p.clone());
        for k in 0..20_000 {
            let cmd = if (k / 700) % 2 == 0 { 1.0 } else { -1.0 };
            g.step(cmd, 0.005);
            assert!(g.angle().abs() <= p.angle_max);
            assert!(g.rate().abs() <= p.rate_max * (1.0 + 1e-12));
        }
        assert!(g.rate_saturated_time() > 10.0);
    }
}
