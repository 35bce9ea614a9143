//! Currents and slowly varying force disturbances: the constant/ramped current of [Taylor2000],
//! the design disturbance histories of [Parsons1980] (as nondimensional yaw moment N′ and side
//! force Y′) and the earth-fixed bias of [Fossen1999].
//!
//! # Current velocity [Taylor2000, sec. 5.2.3.1 and 5.3.3]
//! Earth-fixed current of speed `V_c(t)` flowing **towards** the direction β_c (same frame as the
//! heading): `V_c = V0` before `t_start`, then linearly to `V1` over `ramp_duration` (0: a step,
//! "a current gust of 5 knots directly on its port beam"), `V1` after. Outputs: north/east
//! components and the body-frame components `u_c = V_c cos(β_c − ψ)`, `v_c = V_c sin(β_c − ψ)`
//! for the hull kinematics (ẋ = u cos ψ − v sin ψ + V_N, ...). The thesis applies its 5-kn
//! current in the autopilot tests "as an initial condition on the ship's sway velocity"
//! [Taylor2000, sec. 5.2.3.1]; here it is a velocity for the kinematics, the form taken for the
//! track tests too (how the thesis applied it there is not stated). Preset
//! [`CurrentParams::ddg51_beam_current`]: 5 kn, step.
//!
//! # Disturbances of [Parsons1980, sec. 2.3 and 3.2-3.3], in t′ = t U/L
//! All enter the hull as N′, Y′ through Γ_s [Parsons1980, eq. (11)] and are independent of H/T. Superposed:
//! * **Design lateral current [Parsons1980, Fig. 4]**: N′ = 1.0262e-3 s(t′), Y′ = 2.3277e-3 s(t′) (the
//!   "correct values" of [Parsons1980, Tables 12-13]; the text's rounded N′ is 0.00103), s = 1 for t′ ≤ 15,
//!   linear to 0.5 at t′ = 20, 0.5 after ([Parsons1980, sec. 2.3 and 3.3]: "0.00103 and
//!   0.000515"). The end of the constant part is a parameter (t′ = 18 in the WLS runs,
//!   [Parsons1980, sec. 4.2.2]).
//! * **Passing ship [Parsons1980, Fig. 3]**: the figure is lost; a surrogate of our own is used — zero-mean
//!   Ricker pulses centred on the beam-to-beam instant t′_p,
//!   `g(τ; w) = (1 − 2(τ/w)²) exp(−(τ/w)²)`, τ = t′ − t′_p,
//!   `N′ = −20.4e-5 f g(τ; 0.674)`, `Y′ = 48.0e-5 f g(τ; 0.706)`: peaks of [Parsons1980, sec. 4.3.2] at
//!   beam-to-beam, RMS over −2 ≤ τ ≤ 1.4 equal to σ_N = 8.798e-5, σ_Y = 21.178e-5 of [Parsons1980, sec. 3.2],
//!   active for |τ| ≲ 1.9 (the 3.5 L span). f = 1 ([Parsons1980, Figs. 29-37], t′_p = 7) or 4 ([Parsons1980, Figs. 6-7 and
//!   11-12], t′_p = 20). A placeholder until Newton's data (DTMB 1461) are available.
//! * **White sequences**: per-sample σ_N, σ_Y on the internal grid ([Parsons1980, sec. 5.3]: σ_N = 2e-5,
//!   σ_Y = 5e-5 at Δt′ = 0.005, read as per-sample), zero-order hold.
//! * **First-order shaping filters** [Parsons1980, eqs. (39)-(40)]: `T dN′/dt′ = −N′ + w1`, T = 1 ship length,
//!   stationary std σ (q = 2Tσ², [Parsons1980, eqs. (53)-(54)]: σ_N = 8.798e-5, σ_Y = 21.178e-5).
//! * **Random walks** [Parsons1980, eqs. (56)-(57)]: `dN′/dt′ = w_N` with intensity q per unit t′ ([Parsons1980, eqs. (67)-(68)]:
//!   q11 = 2e-8, q22 = 1.25e-7): increments over Δt′ have variance q Δt′.
//!   Dimensional outputs: `N = N′ ½ρL³U²`, `Y = Y′ ½ρL²U²` (ρ = 1025 kg/m³, not given in the report).
//!
//! # Bias [Fossen1999, eq. (7)]
//! `ḃ = −T⁻¹ b + Ψ n`, earth-fixed (surge force N, sway force N, yaw moment N·m), T = 1000 s
//! [Fossen1999, eq. (58)], Ψ not given in the paper (default 0: b decays from its initial value), stationary
//! variance Ψ² T/2. Also rotated into the body frame with the heading input: `Jᵀ(ψ) b`.
//!
//! All random processes run on the fixed internal grid of [`super::shaping`].

use super::shaping::{quantise_time, FirstOrderProcess, Start, WhiteSequence};
use crate::error::{check_non_negative, check_positive};
use crate::math::{exp, sin_cos};
use crate::random::{channel, NoiseStream};
use serde::{Deserialize, Serialize};

/// Knot in m/s.
pub const KNOT: f64 = 1852.0 / 3600.0;

/// Ricker ("Mexican hat") pulse `(1 − 2x²) e^(−x²)`, x = τ/w.
pub fn ricker(tau: f64, w: f64) -> f64 {
    let x2 = (tau / w).powi(2);
    (1.0 - 2.0 * x2) * exp(-x2)
}

/// Passing-ship surrogate (for [Parsons1980, Fig. 3]) at τ = t′ − t′_p for magnitude factor f: (N′, Y′).
pub fn passing_ship(tau: f64, factor: f64) -> (f64, f64) {
    (
        -20.4e-5 * factor * ricker(tau, 0.674),
        48.0e-5 * factor * ricker(tau, 0.706),
    )
}

/// [Parsons1980, Fig. 4] profile s(t′): 1 until `t_end_constant`, linear to `final_fraction` at
/// `t_end_ramp`, constant after.
pub fn design_current_profile(
    tp: f64,
    t_end_constant: f64,
    t_end_ramp: f64,
    final_fraction: f64,
) -> f64 {
    if tp <= t_end_constant {
        1.0
    } else if tp >= t_end_ramp {
        final_fraction
    } else {
        1.0 + (final_fraction - 1.0) * (tp - t_end_constant) / (t_end_ramp - t_end_constant)
    }
}

/// Parameters of [`Current`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CurrentParams {
    // current velocity
    pub speed_initial: f64,
    pub speed_final: f64,
    pub direction: f64,
    pub t_start: f64,
    pub ramp_duration: f64,
    // [Parsons1980] scaling
    pub ship_speed: f64,
    pub ship_length: f64,
    pub density: f64,
    // design lateral current [Parsons1980, Fig. 4]
    pub design_current: bool,
    pub design_n: f64,
    pub design_y: f64,
    pub design_t_constant: f64,
    pub design_t_ramp: f64,
    pub design_final_fraction: f64,
    // passing ship [Parsons1980, Fig. 3]
    pub passing_factor: f64,
    pub passing_time: f64,
    // random disturbances of [Parsons1980, sec. 3.2-3.3 and 5.3]
    pub white_sigma: [f64; 2],
    pub shaping_sigma: [f64; 2],
    pub shaping_time_constant: f64,
    pub walk_q: [f64; 2],
    // bias [Fossen1999, eq. (7)]
    pub bias_time_constant: f64,
    pub bias_psi: [f64; 3],
    pub bias_initial: [f64; 3],
    /// Internal grid of the random processes [s].
    pub internal_step: f64,
    pub seed: u64,
}

impl Default for CurrentParams {
    /// No current, no disturbances; Tokyo Maru scaling (12 kn, 290 m), Δt′ = 0.005 grid,
    /// Bias time constant 1000 s [Fossen1999, eq. (58)].
    fn default() -> Self {
        let u = 12.0 * KNOT;
        CurrentParams {
            speed_initial: 0.0,
            speed_final: 0.0,
            direction: 0.0,
            t_start: 0.0,
            ramp_duration: 0.0,
            ship_speed: u,
            ship_length: 290.0,
            density: 1025.0,
            design_current: false,
            design_n: 1.0262e-3,
            design_y: 2.3277e-3,
            design_t_constant: 15.0,
            design_t_ramp: 20.0,
            design_final_fraction: 0.5,
            passing_factor: 0.0,
            passing_time: 7.0,
            white_sigma: [0.0; 2],
            shaping_sigma: [0.0; 2],
            shaping_time_constant: 1.0,
            walk_q: [0.0; 2],
            bias_time_constant: 1000.0,
            bias_psi: [0.0; 3],
            bias_initial: [0.0; 3],
            internal_step: 0.005 * 290.0 / u,
            seed: 1,
        }
    }
}

impl CurrentParams {
    /// [Taylor2000, sec. 5.2.3.1]: a 5-kn current on the port beam of a ship heading north (flowing east), applied
    /// as a step at `t_start`.
    pub fn ddg51_beam_current(t_start: f64) -> Self {
        CurrentParams {
            speed_initial: 0.0,
            speed_final: 5.0 * KNOT,
            direction: std::f64::consts::FRAC_PI_2,
            t_start,
            ramp_duration: 0.0,
            ..Self::default()
        }
    }

    /// [Parsons1980, Figs. 8-10 and 13-15]: design lateral current of [Parsons1980, Fig. 4].
    pub fn parsons_design_current() -> Self {
        CurrentParams {
            design_current: true,
            ..Self::default()
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        check_positive("ship_speed", self.ship_speed)?;
        check_positive("ship_length", self.ship_length)?;
        check_positive("density", self.density)?;
        check_positive("internal_step", self.internal_step)?;
        check_positive("shaping_time_constant", self.shaping_time_constant)?;
        check_positive("bias_time_constant", self.bias_time_constant)?;
        check_non_negative("ramp_duration", self.ramp_duration)?;
        if !(self.design_t_ramp > self.design_t_constant) {
            return Err(format!(
                "design_t_ramp = {} must exceed design_t_constant = {}",
                self.design_t_ramp, self.design_t_constant
            ));
        }
        for (n, v) in [
            ("white_sigma_n", self.white_sigma[0]),
            ("white_sigma_y", self.white_sigma[1]),
            ("shaping_sigma_n", self.shaping_sigma[0]),
            ("shaping_sigma_y", self.shaping_sigma[1]),
            ("walk_q_n", self.walk_q[0]),
            ("walk_q_y", self.walk_q[1]),
            ("bias_psi_x", self.bias_psi[0]),
            ("bias_psi_y", self.bias_psi[1]),
            ("bias_psi_n", self.bias_psi[2]),
        ] {
            check_non_negative(n, v)?;
        }
        Ok(())
    }

    /// Seconds per unit of t′ (L/U).
    pub fn time_scale(&self) -> f64 {
        self.ship_length / self.ship_speed
    }
}

/// The current and disturbance model (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Current {
    params: CurrentParams,
    t0: f64,
    time: f64,
    heading: f64,
    white: [WhiteSequence; 2],
    shaping: [FirstOrderProcess; 2],
    walk: [FirstOrderProcess; 2],
    bias: [FirstOrderProcess; 3],
}

impl Current {
    pub fn new(params: CurrentParams, t0: f64) -> Result<Self, String> {
        let t0 = quantise_time(t0);
        params.validate()?;
        let ts = params.time_scale();
        let dt = params.internal_step;
        let seed = params.seed;
        let white = std::array::from_fn(|i| {
            WhiteSequence::new(
                params.white_sigma[i],
                dt,
                t0,
                NoiseStream::new(seed, channel::CURRENT_WHITE + i as u64),
            )
        });
        let (shaping_t, shaping_g) = Self::shaping_params(&params);
        let shaping = std::array::from_fn(|i| {
            FirstOrderProcess::new(
                shaping_t,
                shaping_g[i],
                dt,
                t0,
                Start::Stationary,
                NoiseStream::new(seed, channel::CURRENT_SHAPING + i as u64),
            )
        });
        // random walk: intensity q per unit t′ → q/ts per second
        let walk = std::array::from_fn(|i| {
            FirstOrderProcess::new(
                f64::INFINITY,
                (params.walk_q[i] / ts).sqrt(),
                dt,
                t0,
                Start::Value(0.0),
                NoiseStream::new(seed, channel::CURRENT_WALK + i as u64),
            )
        });
        let bias = std::array::from_fn(|i| {
            FirstOrderProcess::new(
                params.bias_time_constant,
                params.bias_psi[i],
                dt,
                t0,
                Start::Value(params.bias_initial[i]),
                NoiseStream::new(seed, channel::CURRENT_BIAS + i as u64),
            )
        });
        Ok(Current {
            params,
            t0,
            time: t0,
            heading: 0.0,
            white,
            shaping,
            walk,
            bias,
        })
    }

    /// Time constant [s] and gains of the shaping filters of [Parsons1980, sec. 3.2]: stationary std σ ⇔ g = σ √(2/T).
    fn shaping_params(p: &CurrentParams) -> (f64, [f64; 2]) {
        let t = p.shaping_time_constant * p.time_scale();
        (t, p.shaping_sigma.map(|s| s * (2.0 / t).sqrt()))
    }

    pub fn params(&self) -> &CurrentParams {
        &self.params
    }

    /// Changes the current-velocity profile (tunable; the random processes are untouched).
    pub fn set_current_profile(
        &mut self,
        speed_initial: f64,
        speed_final: f64,
        direction: f64,
        t_start: f64,
        ramp_duration: f64,
    ) -> Result<(), String> {
        check_non_negative("ramp_duration", ramp_duration)?;
        let p = &mut self.params;
        p.speed_initial = speed_initial;
        p.speed_final = speed_final;
        p.direction = direction;
        p.t_start = t_start;
        p.ramp_duration = ramp_duration;
        Ok(())
    }

    pub fn set_heading(&mut self, heading: f64) {
        self.heading = heading;
    }

    /// `t` is rounded to a whole nanosecond ([`quantise_time`]).
    pub fn advance_to(&mut self, t: f64) {
        let t = quantise_time(t);
        self.time = t;
        for p in &mut self.white {
            p.advance_to(t);
        }
        for p in self
            .shaping
            .iter_mut()
            .chain(&mut self.walk)
            .chain(&mut self.bias)
        {
            p.advance_to(t);
        }
    }

    /// The noise grids' work of [`advance_to`](Self::advance_to)`(t)`: `each("internal_step",
    /// grid step, passes)` per process (for the bound on the work of one FMU step).
    pub fn internal_steps(&self, t: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let t = quantise_time(t);
        let grids = self.white.iter().map(|p| p.grid_passes(t));
        let processes = self.shaping.iter().chain(&self.walk).chain(&self.bias);
        for (dt, passes) in grids.chain(processes.map(|p| p.grid_passes(t))) {
            each("internal_step", dt, passes);
        }
    }

    /// Nondimensional time t′ = (t − t0) U/L.
    pub fn nondimensional_time(&self) -> f64 {
        (self.time - self.t0) / self.params.time_scale()
    }

    /// Current speed V_c(t) [m/s].
    pub fn current_speed(&self) -> f64 {
        let p = &self.params;
        let t = self.time;
        if t < p.t_start {
            p.speed_initial
        } else if p.ramp_duration <= 0.0 || t >= p.t_start + p.ramp_duration {
            p.speed_final
        } else {
            p.speed_initial + (p.speed_final - p.speed_initial) * (t - p.t_start) / p.ramp_duration
        }
    }

    /// Earth-fixed current velocity (north, east) [m/s].
    pub fn current_velocity(&self) -> [f64; 2] {
        let v = self.current_speed();
        let (s, c) = sin_cos(self.params.direction);
        [v * c, v * s]
    }

    /// Current velocity in the body frame (u_c, v_c) [m/s].
    pub fn current_body(&self) -> [f64; 2] {
        let v = self.current_speed();
        let (s, c) = sin_cos(self.params.direction - self.heading);
        [v * c, v * s]
    }

    /// Components of (N′, Y′): design current, passing ship, white, shaping, walk.
    pub fn disturbance_parts(&self) -> [[f64; 2]; 5] {
        let p = &self.params;
        let tp = self.nondimensional_time();
        let design = if p.design_current {
            let s = design_current_profile(
                tp,
                p.design_t_constant,
                p.design_t_ramp,
                p.design_final_fraction,
            );
            [p.design_n * s, p.design_y * s]
        } else {
            [0.0; 2]
        };
        let passing = if p.passing_factor != 0.0 {
            let (n, y) = passing_ship(tp - p.passing_time, p.passing_factor);
            [n, y]
        } else {
            [0.0; 2]
        };
        let t = self.time;
        [
            design,
            passing,
            [self.white[0].value(), self.white[1].value()],
            [self.shaping[0].value(t), self.shaping[1].value(t)],
            [self.walk[0].value(t), self.walk[1].value(t)],
        ]
    }

    /// Total nondimensional (N′, Y′).
    pub fn disturbance(&self) -> [f64; 2] {
        let parts = self.disturbance_parts();
        let mut s = [0.0; 2];
        for p in parts {
            s[0] += p[0];
            s[1] += p[1];
        }
        s
    }

    /// Dimensional yaw moment N [N·m] and side force Y [N]: N′ ½ρL³U², Y′ ½ρL²U².
    pub fn disturbance_dimensional(&self) -> [f64; 2] {
        self.dimensional(self.disturbance())
    }

    /// [`Current::disturbance_dimensional`] of a [`Current::disturbance`] `[n, y]`.
    pub fn dimensional(&self, [n, y]: [f64; 2]) -> [f64; 2] {
        let p = &self.params;
        let q = 0.5 * p.density * p.ship_length * p.ship_length * p.ship_speed * p.ship_speed;
        [n * q * p.ship_length, y * q]
    }

    /// Bias [Fossen1999, eq. (7)], earth-fixed (X [N], Y [N], N [N·m]).
    pub fn bias(&self) -> [f64; 3] {
        std::array::from_fn(|i| self.bias[i].value(self.time))
    }

    /// Bias [Fossen1999, eq. (7)] in the body frame, Jᵀ(ψ) b.
    pub fn bias_body(&self) -> [f64; 3] {
        self.body(self.bias())
    }

    /// [`Current::bias_body`] of a [`Current::bias`] `b`.
    pub fn body(&self, b: [f64; 3]) -> [f64; 3] {
        let (s, c) = sin_cos(self.heading);
        [c * b[0] + s * b[1], -s * b[0] + c * b[1], b[2]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{correlation, mean_variance};

    fn at(c: &mut Current, tp: f64) -> [f64; 2] {
        let t = tp * c.params().time_scale();
        c.advance_to(t);
        c.disturbance()
    }

    #[test]
    fn passing_ship_peaks_rms_and_span_of_parsons1980() {
        for (factor, tpass) in [(1.0, 7.0), (4.0, 20.0)] {
            let p = CurrentParams {
                passing_factor: factor,
                passing_time: tpass,
                ..CurrentParams::default()
            };
            let mut c = Current::new(p, 0.0).unwrap();
            let [n, y] = at(&mut c, tpass);
            assert!((n - -20.4e-5 * factor).abs() < 1e-15 * factor, "{n}");
            assert!((y - 48.0e-5 * factor).abs() < 1e-15 * factor, "{y}");
            // extremes are at beam-to-beam
            for k in 0..2000 {
                let tp = tpass - 5.0 + k as f64 * 0.005;
                let [n2, y2] = at(&mut c, tp);
                assert!(n2 >= n - 1e-18 && y2 <= y + 1e-18);
            }
        }
        // RMS over -2 <= τ <= 1.4 equals σ_N = 8.798e-5, σ_Y = 21.178e-5 [Parsons1980, sec. 3.2] within 0.5 %
        let m = 34_000;
        let (mut sn, mut sy) = (0.0, 0.0);
        for k in 0..=m {
            let tau = -2.0 + 3.4 * k as f64 / m as f64;
            let (n, y) = passing_ship(tau, 1.0);
            sn += n * n;
            sy += y * y;
        }
        let (rn, ry) = ((sn / (m + 1) as f64).sqrt(), (sy / (m + 1) as f64).sqrt());
        assert!((rn / 8.798e-5 - 1.0).abs() < 5e-3, "{rn}");
        assert!((ry / 21.178e-5 - 1.0).abs() < 5e-3, "{ry}");
        // active span: below 1 % of the peak for |τ| >= 1.9 (the 3.5 L span of [Parsons1980, sec. 4.3.2])
        for tau in [-1.95f64, 1.95, 2.5, -3.0] {
            let (n, y) = passing_ship(tau, 1.0);
            assert!(
                n.abs() < 0.01 * 20.4e-5 && y.abs() < 0.01 * 48.0e-5,
                "{tau}"
            );
        }
        // q11 = 2 T σ_N² = 1.548e-8, q22 = 8.970e-8 [Parsons1980, eqs. (53)-(54)]
        assert!((2.0 * 8.798e-5f64.powi(2) / 1.548e-8 - 1.0).abs() < 1e-3);
        assert!((2.0 * 21.178e-5f64.powi(2) / 8.970e-8 - 1.0).abs() < 1e-3);
    }

    #[test]
    fn design_lateral_current_profile_of_fig_4() {
        let mut c = Current::new(CurrentParams::parsons_design_current(), 0.0).unwrap();
        for (tp, s) in [
            (0.0, 1.0),
            (10.0, 1.0),
            (15.0, 1.0),
            (17.5, 0.75),
            (20.0, 0.5),
            (40.0, 0.5),
        ] {
            let [n, y] = at(&mut c, tp);
            assert!((n - 1.0262e-3 * s).abs() < 1e-12, "t' = {tp}: {n}");
            assert!((y - 2.3277e-3 * s).abs() < 1e-12, "t' = {tp}: {y}");
        }
        // "constant disturbance levels of 0.00103 and 0.000515" [Parsons1980, sec. 3.3]
        assert!((1.0262e-3f64 - 0.00103).abs() < 5e-6);
        // [DERIVED] [Parsons1980, eqs. (24)-(25)] with the stability derivatives N′β = 0.0123,
        // Y′β = 0.0279 obtained by inverting [Parsons1980, Table 2] at H/T = 1.89, and v′c = 1/12:
        // N′ = N′β v′c, Y′ = Y′β v′c within 0.2 % of the printed values
        assert!((0.0123f64 / 12.0 / 1.0262e-3 - 1.0).abs() < 2e-3);
        assert!((0.0279f64 / 12.0 / 2.3277e-3 - 1.0).abs() < 2e-3);
        // time scale: one ship length = 46.98 s
        assert!((c.params().time_scale() - 46.98).abs() < 0.01);
    }

    #[test]
    fn bias_of_fossen1999_decays_with_t_1000_and_has_the_stationary_variance() {
        // deterministic decay from b0 with Ψ = 0
        let p = CurrentParams {
            bias_initial: [1.0e4, -2.0e4, 5.0e5],
            internal_step: 1.0,
            ..CurrentParams::default()
        };
        let mut c = Current::new(p, 0.0).unwrap();
        c.advance_to(1000.0);
        let b = c.bias();
        assert!((b[0] - 1.0e4 * exp(-1.0f64)).abs() < 1e-8);
        assert!((b[2] - 5.0e5 * exp(-1.0f64)).abs() < 1e-6);
        // body frame at heading 90 deg: x_body = b_y... J^T b
        c.set_heading(std::f64::consts::FRAC_PI_2);
        let bb = c.bias_body();
        assert!((bb[0] - b[1]).abs() < 1e-9 && (bb[1] + b[0]).abs() < 1e-9);
        // stochastic: Ψ = 10 → var = Ψ² T/2 = 5e4; 1e6 steps of 10 s
        let p = CurrentParams {
            bias_psi: [10.0, 10.0, 0.0],
            internal_step: 10.0,
            seed: 4,
            ..CurrentParams::default()
        };
        let mut c = Current::new(p, 0.0).unwrap();
        let n = 1_000_000;
        let (mut x, mut y) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for k in 1..=n {
            c.advance_to(k as f64 * 10.0);
            let b = c.bias();
            x.push(b[0]);
            y.push(b[1]);
        }
        let (_, v) = mean_variance(&x[1000..]);
        assert!((v / 5.0e4 - 1.0).abs() < 0.03, "{v}");
        let r = correlation(&x[..n - 100], &x[100..]);
        assert!((r - exp(-1.0f64)).abs() < 0.02, "lag 1000 s: {r}");
        assert!(correlation(&x, &y).abs() < 0.05);
    }

    #[test]
    fn random_disturbances_of_parsons1980() {
        let p = CurrentParams {
            white_sigma: [2e-5, 5e-5],
            shaping_sigma: [8.798e-5, 21.178e-5],
            walk_q: [2e-8, 1.25e-7],
            seed: 12,
            ..CurrentParams::default()
        };
        let dt = p.internal_step;
        let ts = p.time_scale();
        let mut c = Current::new(p, 0.0).unwrap();
        let n = 400_000;
        let mut parts = vec![[[0.0; 2]; 5]; n];
        for k in 0..n {
            c.advance_to(k as f64 * dt);
            parts[k] = c.disturbance_parts();
        }
        let col = |j: usize, i: usize| -> Vec<f64> { parts.iter().map(|p| p[j][i]).collect() };
        let (_, vw) = mean_variance(&col(2, 1));
        assert!((vw.sqrt() / 5e-5 - 1.0).abs() < 0.01);
        // shaping: T = 1 ship length; 400k · 0.005 = 2000 ship lengths
        let (_, vs) = mean_variance(&col(3, 0));
        assert!((vs.sqrt() / 8.798e-5 - 1.0).abs() < 0.03, "{}", vs.sqrt());
        // random walk: increments over one ship length (200 grid steps) have variance q·1
        let w = col(4, 1);
        let inc: Vec<f64> = (1..n / 200)
            .map(|k| w[200 * k] - w[200 * (k - 1)])
            .collect();
        let (_, vi) = mean_variance(&inc);
        assert!((vi / 1.25e-7 - 1.0).abs() < 0.05, "{vi}");
        assert!((dt / ts - 0.005).abs() < 1e-12);
    }

    #[test]
    fn ddg51_current_step_and_ramp() {
        let mut c = Current::new(CurrentParams::ddg51_beam_current(30.0), 0.0).unwrap();
        c.advance_to(29.9);
        assert_eq!(c.current_speed(), 0.0);
        c.advance_to(30.0);
        assert!((c.current_speed() - 2.572_222).abs() < 1e-6);
        let [vn, ve] = c.current_velocity();
        assert!(vn.abs() < 1e-12 && (ve - 5.0 * KNOT).abs() < 1e-12);
        // on the port beam of a ship heading north: pushes to starboard (+v)
        c.set_heading(0.0);
        let [u, v] = c.current_body();
        assert!(u.abs() < 1e-12 && (v - 5.0 * KNOT).abs() < 1e-12);
        let p = CurrentParams {
            speed_initial: 1.0,
            speed_final: 3.0,
            t_start: 10.0,
            ramp_duration: 20.0,
            ..CurrentParams::default()
        };
        let mut c = Current::new(p, 0.0).unwrap();
        c.advance_to(20.0);
        assert!((c.current_speed() - 2.0).abs() < 1e-15);
        c.advance_to(50.0);
        assert_eq!(c.current_speed(), 3.0);
    }

    #[test]
    fn step_independence_and_snapshots() {
        let p = CurrentParams {
            white_sigma: [2e-5, 5e-5],
            shaping_sigma: [8.798e-5, 21.178e-5],
            walk_q: [2e-8, 1.25e-7],
            bias_psi: [10.0, 10.0, 100.0],
            passing_factor: 1.0,
            seed: 3,
            ..CurrentParams::default()
        };
        let (mut a, mut b) = (
            Current::new(p.clone(), 0.0).unwrap(),
            Current::new(p, 0.0).unwrap(),
        );
        for k in 1..=500 {
            for j in 1..=10 {
                a.advance_to((10 * (k - 1) + j) as f64 * 0.07);
            }
            b.advance_to(k as f64 * 0.7);
            let (da, db) = (a.disturbance(), b.disturbance());
            assert!((da[0] - db[0]).abs() < 1e-15 && (da[1] - db[1]).abs() < 1e-15);
            assert!((a.bias()[2] - b.bias()[2]).abs() < 1e-9);
        }
        let snap = a.clone();
        let go = |c: &mut Current| -> Vec<u64> {
            (1..100)
                .map(|k| {
                    c.advance_to(350.0 + k as f64 * 0.3);
                    c.disturbance()[1].to_bits() ^ c.bias()[0].to_bits()
                })
                .collect()
        };
        let first = go(&mut a);
        let mut again = snap;
        assert_eq!(first, go(&mut again));
    }
}
