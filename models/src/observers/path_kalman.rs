//! Steady-state Kalman-Bucy filter of the Tokyo Maru path-control loop [Parsons1980, sec. 3].
//!
//! # Source
//! [Parsons1980, sec. 3.2-3.3]: the continuous filter [Parsons1980, eq. (47)]
//! `dx̂′/dt′ = F_e x̂′ + G_e δ′_c + K (z − H_e x̂′)` on the 7-state design model
//! [`PathDesignModel`] (x̂′ = [ψ′, r′, β′, η′, δ′, N′, Y′]) with the steady-state gain
//! K = P∞H_eᵀR⁻¹ of [Parsons1980, eqs. (48)-(52)], stepped with fixed-step forward Euler at the report's step
//! Δt′ = 0.005 [Parsons1980, sec. 2.2 and 4.4].
//!
//! # Readings taken
//! * Random-walk design: −ε (1e-4) on the N′, Y′ diagonal for the gain design only; the running
//!   filter uses F_e(6,6) = F_e(7,7) = 0 (after [Parsons1980, eq. (60)]).
//! * A co-simulation step h (seconds) is covered with n = ⌈h′/Δt′⌉ equal Euler sub-steps
//!   (h′ = hU/L), inputs held; with h = Δt′L/U (≈ 0.2349 s) this is exactly the report's scheme.
//! * The gains are recomputed only when the design changes (gain-update event of the adaptive
//!   loop, [Parsons1980, sec. 1 and 6]); the estimate carries over.
//!
//! # Innovation statistics
//! The innovation ν = z − H_e x̂′ at the start of each sub-step, and its exponentially weighted
//! mean square with forgetting time `innovation_window` (in t′).

use super::path_model::{DisturbanceModel, PathDesignModel, NX, NZ};
use crate::error::{check_positive, check_positive_or_infinite, require, ParamError};
use crate::hull::tokyo_maru::TokyoMaruCoefficients;
use crate::hull::tokyo_maru::{L, U};
use crate::integrate::substeps;
use crate::riccati::RiccatiError;
use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

/// The Kalman gain K (7×3; columns ψ′, r′, η′).
pub type KalmanGain = SMatrix<f64, NX, NZ>;

/// Parameters from which a [`PathDesignModel`] is built (the FMU's parameter set).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathKalmanConfig {
    /// Design (assumed) depth ratio H/T of the [Parsons1980, Table 2] coefficients (∞ allowed).
    pub design_depth_ratio: f64,
    /// When > 0: f23 and f25 are taken at this H/T instead ([Parsons1980, Table 8] partial adaptation).
    pub adapted_depth_ratio: f64,
    /// true: random-walk N′, Y′ [Parsons1980, eqs. (56)-(59)]; false: first-order shaping filters [Parsons1980, eqs. (39)-(41)].
    pub random_walk: bool,
    /// Steering time constant T_r (nondimensional; 0.212874 = 10 s).
    pub t_r: f64,
    /// Shaping-filter time constant T_N = T_Y (ship lengths).
    pub shaping_time_constant: f64,
    /// Random-walk design regulariser ε.
    pub epsilon: f64,
    /// Disturbance intensities [q11, q22]; a value ≤ 0 takes the report's value for the chosen
    /// model ([Parsons1980, eqs. (53)-(54)] or 67-68).
    pub q: [f64; 2],
    /// Measurement noise intensities [r_ψ, r_r, r_η] ([Parsons1980, Table 3] by default).
    pub r: [f64; 3],
}

impl Default for PathKalmanConfig {
    /// The report's adaptive design: random walk at H/T = 1.89 [Parsons1980, Table 5].
    fn default() -> Self {
        PathKalmanConfig {
            design_depth_ratio: 1.89,
            adapted_depth_ratio: 0.0,
            random_walk: true,
            t_r: crate::hull::tokyo_maru::T_R,
            shaping_time_constant: 1.0,
            epsilon: super::path_model::EPSILON,
            q: [0.0; 2],
            r: super::path_model::R_TABLE_3,
        }
    }
}

impl PathKalmanConfig {
    /// Validates and builds the design model.
    pub fn design(&self) -> Result<PathDesignModel, ParamError> {
        check_positive_or_infinite("design_depth_ratio", self.design_depth_ratio)?;
        check_positive("t_r", self.t_r)?;
        require(
            !self.adapted_depth_ratio.is_nan(),
            "adapted_depth_ratio",
            self.adapted_depth_ratio,
            "must be a number (<= 0: not used)",
        )?;
        for (name, v) in [
            ("r_heading", self.r[0]),
            ("r_yaw_rate", self.r[1]),
            ("r_cross_track", self.r[2]),
        ] {
            check_positive(name, v)?;
        }
        let mut m = if self.random_walk {
            check_positive("epsilon", self.epsilon)?;
            PathDesignModel::random_walk(self.design_depth_ratio)
        } else {
            check_positive("shaping_time_constant", self.shaping_time_constant)?;
            PathDesignModel::shaping_filter(self.design_depth_ratio)
        };
        if self.random_walk {
            m.disturbance = DisturbanceModel::RandomWalk {
                epsilon: self.epsilon,
            };
        } else {
            m.disturbance = DisturbanceModel::ShapingFilter {
                t_n: self.shaping_time_constant,
                t_y: self.shaping_time_constant,
            };
        }
        if self.adapted_depth_ratio > 0.0 {
            let a = TokyoMaruCoefficients::at_depth_ratio(self.adapted_depth_ratio);
            m.coefficients.f23 = a.f23;
            m.coefficients.f25 = a.f25;
        }
        m.t_r = self.t_r;
        for i in 0..2 {
            if self.q[i] > 0.0 {
                m.q[i] = self.q[i];
            }
        }
        m.r = self.r;
        Ok(m)
    }
}

/// The filter: design model, gains (computed at construction / gain update) and estimate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathKalmanFilter {
    design: PathDesignModel,
    /// Largest Euler sub-step Δt′ (report: 0.005).
    pub dt_prime: f64,
    /// Forgetting time (t′) of the innovation mean square.
    pub innovation_window: f64,
    f: SMatrix<f64, NX, NX>,
    g: SVector<f64, NX>,
    k: SMatrix<f64, NX, NZ>,
    x: SVector<f64, NX>,
    innovation: SVector<f64, NZ>,
    innovation_ms: SVector<f64, NZ>,
}

impl PathKalmanFilter {
    /// A filter for `design` with estimate `x0` (nondimensional, [ψ′, r′, β′, η′, δ′, N′, Y′]).
    pub fn new(design: PathDesignModel, x0: [f64; NX]) -> Result<Self, RiccatiError> {
        Ok(Self::with_gain(design, x0, design.kalman_gain()?))
    }

    /// [`PathKalmanFilter::new`] with the gain `k = design.kalman_gain()` already solved (e.g.
    /// kept in a [`crate::memo::Memo`] keyed on [`PathDesignModel::key`]).
    pub fn with_gain(design: PathDesignModel, x0: [f64; NX], k: KalmanGain) -> Self {
        PathKalmanFilter {
            f: design.f(false),
            g: design.g(),
            k,
            design,
            dt_prime: super::path_model::DT_PRIME,
            innovation_window: 1.0,
            x: SVector::from_row_slice(&x0),
            innovation: SVector::zeros(),
            innovation_ms: SVector::zeros(),
        }
    }

    /// Gain-update event: new design model (e.g. new coefficient estimates); x̂′ carries over.
    pub fn set_design(&mut self, design: PathDesignModel) -> Result<(), RiccatiError> {
        let k = design.kalman_gain()?;
        self.k = k;
        self.f = design.f(false);
        self.g = design.g();
        self.design = design;
        Ok(())
    }

    /// The design model in use.
    pub fn design(&self) -> &PathDesignModel {
        &self.design
    }

    /// Kalman gain K (7×3; columns ψ′, r′, η′).
    pub fn gain(&self) -> &SMatrix<f64, NX, NZ> {
        &self.k
    }

    /// Estimate x̂′ = [ψ′, r′, β′, η′, δ′, N′, Y′].
    pub fn estimate(&self) -> &SVector<f64, NX> {
        &self.x
    }

    /// Overwrites the estimate.
    pub fn set_estimate(&mut self, x: [f64; NX]) {
        self.x = SVector::from_row_slice(&x);
    }

    /// Innovation z − H_e x̂′ of the last sub-step, [ψ′, r′, η′].
    pub fn innovation(&self) -> &SVector<f64, NZ> {
        &self.innovation
    }

    /// Exponentially weighted innovation mean square, [ψ′, r′, η′].
    pub fn innovation_mean_square(&self) -> &SVector<f64, NZ> {
        &self.innovation_ms
    }

    /// One Euler step of length `dt` (t′) with measurement `z` = [ψ′, r′, η′] and command δ′_c.
    #[inline]
    pub fn euler_step_prime(&mut self, z: &SVector<f64, NZ>, u: f64, dt: f64) {
        let nu = z - SVector::<f64, NZ>::new(self.x[0], self.x[1], self.x[3]);
        let dx = self.f * self.x + self.g * u + self.k * nu;
        self.x += dx * dt;
        self.innovation = nu;
        let a = (dt / self.innovation_window.max(dt)).min(1.0);
        self.innovation_ms += (nu.component_mul(&nu) - self.innovation_ms) * a;
    }

    /// Advances `h_prime` (t′) with inputs held, in ⌈h′/Δt′⌉ equal Euler sub-steps.
    pub fn step_prime(&mut self, z: [f64; NZ], u: f64, h_prime: f64) {
        let n = substeps(h_prime, self.dt_prime);
        if n == 0 {
            return;
        }
        let dt = h_prime / n as f64;
        let z = SVector::from_row_slice(&z);
        for _ in 0..n {
            self.euler_step_prime(&z, u, dt);
        }
    }

    /// Advances `h` seconds. SI inputs: heading ψ [rad], yaw rate r [rad/s], cross-track η [m],
    /// rudder command δ_c [rad]. (Tokyo Maru: L = 290 m, U = 12 kn.)
    pub fn step(&mut self, heading: f64, yaw_rate: f64, cross_track: f64, command: f64, h: f64) {
        self.step_prime(
            [heading, yaw_rate * L / U, cross_track / L],
            command,
            h * U / L,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::tokyo_maru::{TokyoMaru, TokyoMaruInputs, TokyoMaruIntegration};

    /// Constant-disturbance equilibrium [Parsons1980, sec. 4.2.2]: truth at H/T = ∞ under the constant design current
    /// forces N′ = 0.0010262, Y′ = 0.0023277, [Parsons1980, Table 5] controller and filter (design 1.89), Euler at
    /// Δt′ = 0.005. Steady state: N̂′ = 0.001992, Ŷ′ = 0.003437 (±1 in the last digit);
    /// ψ′ = β′ = −0.1428, δ′ = 0.1310 (printed; re-computation 0.13093, so ±1e-4), r′ = 0, η′ ≈ 0
    /// (an independent re-computation found 3.9e-5 too: the Euler-discretised loop is not exactly offset-free).
    #[test]
    fn u9_steady_state_under_design_current() {
        let design = PathDesignModel::random_walk(1.89);
        let c = design.control_gain().unwrap();
        let mut filter = PathKalmanFilter::new(design, [0.0; NX]).unwrap();
        let mut ship = TokyoMaru::deep_water();
        ship.internal_steering_gear = true;
        ship.integration = TokyoMaruIntegration::Euler {
            max_substep_prime: 0.005,
        };
        let h = 0.005 * L / U;
        let w = TokyoMaruInputs {
            rudder: 0.0,
            yaw_moment_prime: 0.0010262,
            sway_force_prime: 0.0023277,
            current_lateral: 0.0,
        };
        for _ in 0..40_000 {
            let u = (c * filter.estimate())[0];
            let s = *ship.state();
            filter.step_prime([s[0], s[1], s[3]], u, 0.005);
            ship.step(&TokyoMaruInputs { rudder: u, ..w }, h);
        }
        let x = filter.estimate();
        let s = ship.state();
        eprintln!("xhat {x:?}\nship {s:?}");
        assert!((x[5] - 0.001992).abs() <= 1e-6, "N' {}", x[5]);
        assert!((x[6] - 0.003437).abs() <= 1e-6, "Y' {}", x[6]);
        assert!((s[0] + 0.1428).abs() <= 1e-4 && (s[2] + 0.1428).abs() <= 1e-4);
        assert!((s[4] - 0.1310).abs() <= 1e-4 && s[1].abs() < 1e-9);
        assert!(s[3].abs() < 1e-4, "eta' {}", s[3]);
    }

    /// Noise-free, disturbance-free, x̂(0) = x(0): the filter reproduces the plant exactly (the
    /// Euler plant and the Euler filter share F_s), innovations stay at rounding level.
    #[test]
    fn exact_model_gives_zero_innovation() {
        let design = PathDesignModel::random_walk(1.89);
        let mut f = PathKalmanFilter::new(design, [0.0; NX]).unwrap();
        let mut ship = TokyoMaru::new(1.89).unwrap();
        ship.internal_steering_gear = true;
        ship.integration = TokyoMaruIntegration::Euler {
            max_substep_prime: 0.005,
        };
        let h = 0.005 * L / U;
        for k in 0..2000 {
            let u = if (k / 100) % 2 == 0 { 0.1 } else { -0.1 };
            let s = *ship.state();
            f.step_prime([s[0], s[1], s[3]], u, 0.005);
            ship.step(
                &TokyoMaruInputs {
                    rudder: u,
                    ..Default::default()
                },
                h,
            );
        }
        let s = ship.state();
        for i in 0..5 {
            assert!((f.estimate()[i] - s[i]).abs() < 1e-12, "state {i}");
        }
        assert!(f.innovation().norm() < 1e-12);
    }

    /// The default config is the [Parsons1980, Table 5] design; q ≤ 0 takes the report's value per model.
    #[test]
    fn config_builds_the_report_designs() {
        let c = PathKalmanConfig::default();
        assert_eq!(c.design().unwrap(), PathDesignModel::random_walk(1.89));
        let s = PathKalmanConfig {
            random_walk: false,
            ..c
        };
        assert_eq!(s.design().unwrap(), PathDesignModel::shaping_filter(1.89));
        let p = PathKalmanConfig {
            design_depth_ratio: 1.89,
            adapted_depth_ratio: f64::INFINITY,
            ..c
        };
        assert_eq!(
            p.design().unwrap(),
            PathDesignModel::partially_adapted(1.89, f64::INFINITY)
        );
        assert!(PathKalmanConfig { t_r: 0.0, ..c }.design().is_err());
        assert!(PathKalmanConfig {
            r: [1e-8, -1.0, 1e-7],
            ..c
        }
        .design()
        .is_err());
    }

    /// The SI step equals the prime step, and a long step is ⌈h′/Δt′⌉ Euler sub-steps.
    #[test]
    fn si_interface_and_substeps() {
        let design = PathDesignModel::shaping_filter(1.89);
        let mut a = PathKalmanFilter::new(design, [0.0; NX]).unwrap();
        let mut b = a.clone();
        a.step(0.01, 0.001, 5.0, 0.05, 4.0 * 0.005 * L / U);
        let z = [0.01, 0.001 * L / U, 5.0 / L];
        for _ in 0..4 {
            b.step_prime(z, 0.05, 0.005);
        }
        assert!((a.estimate() - b.estimate()).norm() < 1e-15);
    }
}
