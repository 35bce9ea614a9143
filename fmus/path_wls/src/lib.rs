//! `PathWlsEstimator` FMU: the moving-window Weighted Least-Squares parameter estimator of
//! [Parsons1980, sec. 4] in `models::controllers::wls`, estimating
//! f22, f23, f25, f32, f33, f35 of the Tokyo Maru and the window means of N′, Y′ from the
//! measured states, the rudder angle and the control-loop filter's estimate at the window start;
//! its f outputs feed the PathController's estimate inputs. No physics here.

use fmi2_export::FmuModel;
use models::controllers::path::UpdateDecision;
use models::controllers::wls::{WlsEstimator, WlsSchedule, WlsSettings};
use models::error::check_positive;
use models::hull::tokyo_maru::TokyoMaruCoefficients;
use models::observers::path_model::states_prime;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one estimator instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PathWlsFmu {
    schedule: WlsSchedule,
    initial_depth_ratio: f64,
    gamma_depth_ratio: f64,
    /// PSDs r_jj of ψ′, r′, β′, η′ [Parsons1980, Table 9]; W = diag(1/r_jj).
    measurement_psd: [f64; 4],
    max_evaluations: i32,
    ship_length: f64,
    ship_speed: f64,
    /// Measured ψ [rad], r [rad/s], β [rad], η [m]; rudder δ [rad].
    measured: [f64; 4],
    rudder: f64,
    /// Filter estimate ψ̂, r̂, β̂, η̂ (SI).
    filter_estimate: [f64; 4],
    start_time: f64,
    estimator: WlsEstimator,
}

impl PathWlsFmu {
    fn settings(&self) -> WlsSettings {
        let g = TokyoMaruCoefficients::at_depth_ratio(self.gamma_depth_ratio);
        WlsSettings {
            dt: 0.005,
            gamma: [g.g21, g.g22, g.g31, g.g32],
            weight: self.measurement_psd.map(|r| 1.0 / r),
            max_evaluations: self.max_evaluations.max(0) as usize,
        }
    }

    fn prime(&self, v: &[f64; 4]) -> [f64; 4] {
        states_prime(v, self.ship_length, self.ship_speed)
    }
}

/// The [Parsons1980, Table 2] coefficients at H/T = `depth_ratio` with N′ = Y′ = 0.
fn initial_estimate(depth_ratio: f64) -> [f64; 8] {
    let c = TokyoMaruCoefficients::at_depth_ratio(depth_ratio);
    [c.f22, c.f23, c.f25, c.f32, c.f33, c.f35, 0.0, 0.0]
}

impl Default for PathWlsFmu {
    fn default() -> Self {
        let schedule = WlsSchedule {
            window_start: 3.45,
            window_length: 2.5,
            update_cycle: 6.0,
        };
        // WlsSettings::default() is what settings() gives for the parameter defaults below
        // (gammas at H/T = 1.89, weights of [Parsons1980, Table 9], 2000 evaluations); initialize rebuilds it.
        PathWlsFmu {
            schedule,
            initial_depth_ratio: 1.89,
            gamma_depth_ratio: 1.89,
            measurement_psd: [1.2976e-9, 7.7215e-10, 8.2777e-10, 5.0651e-9],
            max_evaluations: 2000,
            ship_length: models::hull::tokyo_maru::L,
            ship_speed: models::hull::tokyo_maru::U,
            measured: [0.0; 4],
            rudder: 0.0,
            filter_estimate: [0.0; 4],
            start_time: 0.0,
            estimator: WlsEstimator::new(WlsSettings::default(), schedule, initial_estimate(1.89))
                .expect("default settings are valid"),
        }
    }
}

fmi2_export::fmu! {
    PathWlsFmu => "PathWlsEstimator",
    description: "Moving-window Weighted Least-Squares estimator of the \
        Tokyo Maru path model (Parsons & Cuong 1980, section 4): f22, f23, f25, f32, f33, f35 \
        and the window means of N', Y' for the PathController's partial adaptation",
    experiment: (0.0, 940.0, 0.2349),
    // The outputs change only in a step (at the end of a window).
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        // ---- parameters (0..12)
        fixed real "window_start" (schedule.window_start),
            "Start of the first data window in ship lengths t' = (t - t0) U/L (S11: 3.45, a window \
            of 2.5 L ending 0.05 L before the update at t' = 6)";
        fixed real "window_length" (schedule.window_length).min(0.0),
            "Data window LW in ship lengths (2.5; one sample per communication step)";
        fixed real "update_cycle" (schedule.update_cycle).min(0.0),
            "Update cycle LU in ship lengths: a window every LU from window_start (5, 6 or 6.25)";
        fixed real "initial_depth_ratio" (initial_depth_ratio).min(1.0),
            "H/T whose Table 2 coefficients start the first search (1.89; 1e300: deep water); N', Y' start at 0";
        fixed real "gamma_depth_ratio" (gamma_depth_ratio).min(1.0),
            "H/T of the fixed gamma~_ij of the model eq. 75 (1.89)";
        fixed real "r_heading" (measurement_psd[0]).min(0.0),
            "PSD r_jj of psi' for the weight W = R^-1 of eq. 77 (Table 9: 1.2976e-9)";
        fixed real "r_yaw_rate" (measurement_psd[1]).min(0.0), "PSD r_jj of r' (Table 9: 7.7215e-10)";
        fixed real "r_drift_angle" (measurement_psd[2]).min(0.0), "PSD r_jj of beta' (Table 9: 8.2777e-10)";
        fixed real "r_cross_track" (measurement_psd[3]).min(0.0), "PSD r_jj of eta' (Table 9: 5.0651e-9)";
        fixed int(10, 1_000_000) "max_evaluations" (max_evaluations),
            "Largest number of cost evaluations per fit (Levenberg-Marquardt with a forward-difference Jacobian)";
        // ship_length, ship_speed, then the inputs (12..21)
        path_measurements!();
        input real "rudder_angle" ["rad"] (rudder),
            "Rudder angle delta (known exactly), sampled with the states";
        input real "heading_estimate" ["rad"] (filter_estimate[0]),
            "Control-loop filter estimate of psi (its value at the window start is the model's initial state)";
        input real "yaw_rate_estimate" ["rad/s"] (filter_estimate[1]), "Filter estimate of r";
        input real "drift_angle_estimate" ["rad"] (filter_estimate[2]), "Filter estimate of beta";
        input real "cross_track_estimate" ["m"] (filter_estimate[3]), "Filter estimate of eta";
        // ---- outputs (21..35)
        output real "f22_estimate" (|m| m.estimator.estimate()[0]), "Estimate of f22 (last fit)";
        output real "f23_estimate" (|m| m.estimator.estimate()[1]), "Estimate of f23 (last fit)";
        output real "f25_estimate" (|m| m.estimator.estimate()[2]), "Estimate of f25 (last fit)";
        output real "f32_estimate" (|m| m.estimator.estimate()[3]), "Estimate of f32 (last fit)";
        output real "f33_estimate" (|m| m.estimator.estimate()[4]), "Estimate of f33 (last fit)";
        output real "f35_estimate" (|m| m.estimator.estimate()[5]), "Estimate of f35 (last fit)";
        output real "yaw_moment_prime_estimate" (|m| m.estimator.estimate()[6]),
            "p7: window mean of N' = 2N/(rho L^3 U^2) seen through the fixed gamma~ (a by-product)";
        output real "sway_force_prime_estimate" (|m| m.estimator.estimate()[7]),
            "p8: window mean of Y' = 2Y/(rho L^2 U^2) seen through the fixed gamma~ (a by-product)";
        output bool "estimate_valid" (|m| m.estimator.decision() != UpdateDecision::None),
            "f23 and f25 estimates within their Table 10 ranges (the controller would update)";
        output real "validity" (|m| match m.estimator.decision() {
            UpdateDecision::None => 0.0, UpdateDecision::F23F25 => 1.0, UpdateDecision::All => 2.0 }),
            "Table 10 branch of the estimate: 0 no update (f23 or f25 out of range), 1 f23/f25 only, 2 all";
        output real "evaluations" (|m| m.estimator.evaluations() as f64),
            "Cost evaluations of the last fit (Levenberg-Marquardt; the report's DUD counts differ)";
        output real "final_cost" (|m| m.estimator.cost()),
            "Cost J of eq. 77 at the last fit's minimum, W = R^-1 (dimensionless)";
        output real "residual_sum_of_squares" (|m| m.estimator.sum_of_squares()),
            "Sum over the window of |z'_k - x_m,k|^2 at the last fit's minimum (W = I, no 1/2: the scale of the report's printed J)";
        output real "updates" (|m| m.estimator.updates() as f64), "Number of fits since the start";
        output bool "loading" (|m| m.estimator.loading()), "A data window is being loaded";
    }
}

impl FmuModel for PathWlsFmu {
    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        check_positive("ship_length", self.ship_length)?;
        check_positive("ship_speed", self.ship_speed)?;
        let names = ["r_heading", "r_yaw_rate", "r_drift_angle", "r_cross_track"];
        for (n, r) in names.iter().zip(self.measurement_psd) {
            check_positive(n, r)?;
        }
        self.start_time = start_time;
        let x0 = initial_estimate(self.initial_depth_ratio);
        self.estimator =
            WlsEstimator::new(self.settings(), self.schedule, x0).map_err(|e| e.to_string())?;
        Ok(())
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        // one sample per communication step, at its start
        let ul = self.ship_speed / self.ship_length;
        let (tp, dt) = ((t - self.start_time) * ul, h * ul);
        let (z, xhat) = (
            self.prime(&self.measured),
            self.prime(&self.filter_estimate),
        );
        self.estimator
            .sample(tp, dt, z, self.rudder, xhat)
            .map(|_| ())
            .map_err(|e| format!("WLS fit at t = {t} s: {e}"))
    }
}
