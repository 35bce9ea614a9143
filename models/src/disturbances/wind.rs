//! Wind: mean wind plus gusts, relative wind on board and the roll and yaw moments of
//! [Klugt1987, eqs. (2.19)-(2.20)].
//!
//! # Moments [Klugt1987, sec. 2.4.2]
//! `K_wφ = c_wφ V_w² sin γ` [Klugt1987, eq. (2.19)], `N_wψ = c_wR V_w² sin 2γ` [Klugt1987, eq. (2.20)], V_w the relative wind speed
//! (as measured on board), γ the relative wind angle in (−180°, 180°]. The thesis gives no values for
//! c_wφ, c_wR (they depend on superstructure area, air density; see Schelling 1977):
//! parameters, default 0.
//!
//! # Angle convention (reading taken: [Klugt1987, Fig. 2.9] is lost)
//! Directions are those the air moves **towards** (as for the waves and currents of this
//! project), in the earth frame of the heading. The relative wind angle is
//! `γ = atan2` of the relative air velocity `W − U_ship` expressed in the body frame: γ = 0 wind
//! from astern, ±90° beam wind (+90°: blowing towards starboard), 180° head wind — the same
//! sense as the wave encounter angle (0 following, 180 head). A ship under way in calm air
//! sees a head wind of its own speed (γ = 180°, no moment).
//!
//! # Gusts (the spectrum documented here; the thesis specifies none)
//! [Klugt1987, sec. 2.4.2]: V_w = "a constant component and a component representing the stochastic variations of
//! the speed and the relative wind angle". Both variations are first-order Gauss-Markov
//! processes on the fixed internal grid ([`super::shaping`], exact discretisation, linear
//! interpolation): true wind speed `V(t) = V̄ + v_g(t)`, `T_g v̇_g = −v_g + …` with stationary
//! std σ_g, i.e. the one-sided gust spectrum `S(ω) = (2 σ_g² T_g/π)/(1 + ω² T_g²)` [m²/s² per
//! rad/s]; direction `β(t) = β̄ + β_g(t)` likewise (σ_β, T_β). Defaults (assumptions): V̄ =
//! 10 m/s, σ_g = 1.5 m/s (15 % turbulence intensity), T_g = 20 s, σ_β = 5°, T_β = 60 s.
//! V is clipped at 0.

use super::shaping::{quantise_time, FirstOrderProcess, Start};
use crate::error::{check_non_negative, check_positive};
use crate::math::{atan2, sin, sin_cos};
use crate::random::{channel, NoiseStream};
use serde::{Deserialize, Serialize};

/// Parameters of [`Wind`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WindParams {
    pub mean_speed: f64,
    /// Direction the wind blows towards [rad].
    pub direction: f64,
    pub gust_std: f64,
    pub gust_time_constant: f64,
    pub direction_std: f64,
    pub direction_time_constant: f64,
    /// c_wφ [N·m/(m/s)²].
    pub roll_coefficient: f64,
    /// c_wR [N·m/(m/s)²].
    pub yaw_coefficient: f64,
    pub internal_step: f64,
    pub seed: u64,
}

impl Default for WindParams {
    fn default() -> Self {
        WindParams {
            mean_speed: 10.0,
            direction: 0.0,
            gust_std: 1.5,
            gust_time_constant: 20.0,
            direction_std: 5f64.to_radians(),
            direction_time_constant: 60.0,
            roll_coefficient: 0.0,
            yaw_coefficient: 0.0,
            internal_step: 0.1,
            seed: 1,
        }
    }
}

impl WindParams {
    pub fn validate(&self) -> Result<(), String> {
        for (n, v) in [
            ("mean_wind_speed", self.mean_speed),
            ("gust_std", self.gust_std),
            ("direction_std", self.direction_std),
        ] {
            check_non_negative(n, v)?;
        }
        for (n, v) in [
            ("gust_time_constant", self.gust_time_constant),
            ("direction_time_constant", self.direction_time_constant),
            ("internal_step", self.internal_step),
        ] {
            check_positive(n, v)?;
        }
        Ok(())
    }
}

/// Relative wind (speed, angle γ) from the true wind (speed, towards-direction) and the ship's
/// speed and heading.
pub fn relative_wind(
    wind_speed: f64,
    wind_direction: f64,
    ship_speed: f64,
    heading: f64,
) -> (f64, f64) {
    // body frame: x forward, y starboard; earth direction β → body angle β − ψ
    let (s, c) = sin_cos(wind_direction - heading);
    let (x, y) = (wind_speed * c - ship_speed, wind_speed * s);
    ((x * x + y * y).sqrt(), atan2(y, x))
}

/// The wind model (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Wind {
    params: WindParams,
    time: f64,
    ship_speed: f64,
    heading: f64,
    gust: FirstOrderProcess,
    turn: FirstOrderProcess,
}

impl Wind {
    pub fn new(params: WindParams, t0: f64) -> Result<Self, String> {
        let t0 = quantise_time(t0);
        params.validate()?;
        let gain = |std: f64, t: f64| std * (2.0 / t).sqrt();
        let gust = FirstOrderProcess::new(
            params.gust_time_constant,
            gain(params.gust_std, params.gust_time_constant),
            params.internal_step,
            t0,
            Start::Stationary,
            NoiseStream::new(params.seed, channel::WIND_GUST),
        );
        let turn = FirstOrderProcess::new(
            params.direction_time_constant,
            gain(params.direction_std, params.direction_time_constant),
            params.internal_step,
            t0,
            Start::Stationary,
            NoiseStream::new(params.seed, channel::WIND_GUST + 1),
        );
        Ok(Wind {
            params,
            time: t0,
            ship_speed: 0.0,
            heading: 0.0,
            gust,
            turn,
        })
    }

    pub fn params(&self) -> &WindParams {
        &self.params
    }

    /// Tunable: mean speed, mean direction and the two coefficients.
    pub fn set_mean_and_coefficients(
        &mut self,
        mean_speed: f64,
        direction: f64,
        roll: f64,
        yaw: f64,
    ) {
        self.params.mean_speed = mean_speed;
        self.params.direction = direction;
        self.params.roll_coefficient = roll;
        self.params.yaw_coefficient = yaw;
    }

    pub fn set_inputs(&mut self, ship_speed: f64, heading: f64) {
        self.ship_speed = ship_speed;
        self.heading = heading;
    }

    /// `t` is rounded to a whole nanosecond ([`quantise_time`]).
    pub fn advance_to(&mut self, t: f64) {
        let t = quantise_time(t);
        self.time = t;
        self.gust.advance_to(t);
        self.turn.advance_to(t);
    }

    /// The noise grids' work of [`advance_to`](Self::advance_to)`(t)`: `each("internal_step",
    /// grid step, passes)` per process (for the bound on the work of one FMU step).
    pub fn internal_steps(&self, t: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let t = quantise_time(t);
        for (dt, passes) in [self.gust.grid_passes(t), self.turn.grid_passes(t)] {
            each("internal_step", dt, passes);
        }
    }

    /// True wind speed V̄ + v_g (≥ 0) [m/s].
    pub fn true_speed(&self) -> f64 {
        (self.params.mean_speed + self.gust.value(self.time)).max(0.0)
    }

    /// True wind direction (towards) β̄ + β_g [rad].
    pub fn true_direction(&self) -> f64 {
        self.params.direction + self.turn.value(self.time)
    }

    /// (V_w, γ): relative wind speed [m/s] and angle [rad].
    pub fn relative(&self) -> (f64, f64) {
        relative_wind(
            self.true_speed(),
            self.true_direction(),
            self.ship_speed,
            self.heading,
        )
    }

    /// [Klugt1987, eq. (2.19)]: c_wφ V_w² sin γ [N·m].
    pub fn roll_moment(&self) -> f64 {
        self.roll_moment_at(self.relative())
    }

    /// [`Wind::roll_moment`] for the relative wind `(V_w, γ)` of [`Wind::relative`].
    pub fn roll_moment_at(&self, (v, g): (f64, f64)) -> f64 {
        self.params.roll_coefficient * v * v * sin(g)
    }

    /// [Klugt1987, eq. (2.20)]: c_wR V_w² sin 2γ [N·m].
    pub fn yaw_moment(&self) -> f64 {
        self.yaw_moment_at(self.relative())
    }

    /// [`Wind::yaw_moment`] for the relative wind `(V_w, γ)` of [`Wind::relative`].
    pub fn yaw_moment_at(&self, (v, g): (f64, f64)) -> f64 {
        self.params.yaw_coefficient * v * v * sin(2.0 * g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::exp;
    use crate::random::{correlation, mean_variance};
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    #[test]
    fn relative_wind_geometry_and_moments_of_eqs_2_19_2_20() {
        // calm air, ship at 10 m/s: head wind of 10 m/s
        let (v, g) = relative_wind(0.0, 0.0, 10.0, 0.3);
        assert!((v - 10.0).abs() < 1e-12 && (g.abs() - PI).abs() < 1e-12);
        // beam wind towards starboard of a ship at rest heading north
        let (v, g) = relative_wind(10.0, FRAC_PI_2, 0.0, 0.0);
        assert!((v - 10.0).abs() < 1e-12 && (g - FRAC_PI_2).abs() < 1e-12);
        // following wind faster than the ship
        let (v, g) = relative_wind(15.0, 1.0, 5.0, 1.0);
        assert!((v - 10.0).abs() < 1e-12 && g.abs() < 1e-12);
        // moments without gusts
        let p = WindParams {
            mean_speed: 10.0,
            direction: FRAC_PI_4,
            gust_std: 0.0,
            direction_std: 0.0,
            roll_coefficient: 2.0e3,
            yaw_coefficient: 5.0e3,
            ..WindParams::default()
        };
        let mut w = Wind::new(p, 0.0).unwrap();
        w.set_inputs(0.0, 0.0);
        w.advance_to(1.0);
        assert!((w.roll_moment() - 2.0e3 * 100.0 * sin(FRAC_PI_4)).abs() < 1e-9);
        assert!((w.yaw_moment() - 5.0e3 * 100.0).abs() < 1e-9); // sin 2γ = 1 at 45°
                                                                // beam wind: no yaw moment, full roll moment
        w.set_inputs(0.0, -FRAC_PI_4);
        assert!((w.roll_moment() - 2.0e3 * 100.0).abs() < 1e-9);
        assert!(w.yaw_moment().abs() < 1e-9);
        // head wind: none
        w.set_inputs(0.0, FRAC_PI_4 + PI);
        assert!(w.roll_moment().abs() < 1e-9 && w.yaw_moment().abs() < 1e-9);
    }

    #[test]
    fn gust_statistics_seeds_and_step_independence() {
        let p = WindParams {
            internal_step: 1.0,
            seed: 9,
            ..WindParams::default()
        };
        let mut w = Wind::new(p.clone(), 0.0).unwrap();
        let n = 400_000;
        let (mut v, mut d) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for k in 0..n {
            w.advance_to(k as f64);
            v.push(w.true_speed());
            d.push(w.true_direction());
        }
        let (m, var) = mean_variance(&v);
        assert!((m - 10.0).abs() < 0.05, "{m}");
        assert!((var.sqrt() / 1.5 - 1.0).abs() < 0.03, "{}", var.sqrt());
        let (_, vd) = mean_variance(&d);
        assert!((vd.sqrt() / 5f64.to_radians() - 1.0).abs() < 0.03);
        let r = correlation(&v[..n - 20], &v[20..]);
        assert!((r - exp(-1.0f64)).abs() < 0.02, "lag T_g: {r}");
        assert!(correlation(&v, &d).abs() < 0.05);
        // another seed: uncorrelated
        let mut w2 = Wind::new(
            WindParams {
                seed: 10,
                ..p.clone()
            },
            0.0,
        )
        .unwrap();
        let v2: Vec<f64> = (0..n)
            .map(|k| {
                w2.advance_to(k as f64);
                w2.true_speed()
            })
            .collect();
        assert!(correlation(&v, &v2).abs() < 0.05);
        // step independence: the same values at 1 s whether stepped by 0.1 or 1
        let (mut a, mut b) = (
            Wind::new(p.clone(), 0.0).unwrap(),
            Wind::new(p, 0.0).unwrap(),
        );
        for k in 1..=300 {
            for j in 1..=10 {
                a.advance_to((10 * (k - 1) + j) as f64 * 0.1);
            }
            b.advance_to(k as f64);
            assert!((a.true_speed() - b.true_speed()).abs() < 1e-12);
        }
        let snap = a.clone();
        let go = |w: &mut Wind| -> Vec<u64> {
            (1..50)
                .map(|k| {
                    w.advance_to(300.0 + k as f64 * 0.7);
                    w.true_speed().to_bits()
                })
                .collect()
        };
        let first = go(&mut a);
        let mut again = snap;
        assert_eq!(first, go(&mut again));
    }
}
