//! `PathEstimator` FMU: the Minimum-Variance parameter Estimator of [Parsons1980, sec. 5] in
//! `models::controllers::mve`, estimating f22, f23, f25, f32, f33, f35
//! of the Tokyo Maru from the measured states and the rudder angle; its outputs feed the
//! PathController's estimate inputs. No physics here.

use fmi2_export::FmuModel;
use models::controllers::mve::{parameters_of, Mve, MveParams};
use models::error::check_positive;
use models::hull::tokyo_maru::TokyoMaruCoefficients;
use models::observers::path_model::states_prime;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one estimator instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PathEstimatorFmu {
    params: MveParams,
    initial_depth_ratio: f64,
    ship_length: f64,
    ship_speed: f64,
    /// ψ [rad], r [rad/s], β [rad], η [m], δ [rad].
    measured: [f64; 4],
    rudder: f64,
    estimator: Mve,
}

impl PathEstimatorFmu {
    fn initial_estimate(&self) -> [f64; 6] {
        parameters_of(&TokyoMaruCoefficients::at_depth_ratio(
            self.initial_depth_ratio,
        ))
    }

    fn prime(&self) -> [f64; 4] {
        states_prime(&self.measured, self.ship_length, self.ship_speed)
    }
}

impl Default for PathEstimatorFmu {
    fn default() -> Self {
        let params = MveParams::default();
        let initial_depth_ratio = 1e300;
        PathEstimatorFmu {
            initial_depth_ratio,
            ship_length: models::hull::tokyo_maru::L,
            ship_speed: models::hull::tokyo_maru::U,
            measured: [0.0; 4],
            rudder: 0.0,
            estimator: Mve::new(
                params,
                parameters_of(&TokyoMaruCoefficients::at_depth_ratio(initial_depth_ratio)),
            )
            .expect("default settings are valid"),
            params,
        }
    }
}

fmi2_export::fmu! {
    PathEstimatorFmu => "PathEstimator",
    description: "Minimum-Variance parameter Estimator of the Tokyo Maru \\
        path model (Parsons & Cuong 1980, section 5): f22, f23, f25, f32, f33, f35 for the \\
        PathController's partial adaptation",
    experiment: (0.0, 470.0, 0.2349),
    documentation: "documentation.html",
    variables: {
        fixed int(2, 1000) "interval" (params.interval as u32),
            "Estimation interval l in samples (communication steps): 10 (must be > 1)";
        fixed real "initial_depth_ratio" (initial_depth_ratio).min(1.0),
            "H/T whose Table 2 coefficients are the initial estimates (1e300: deep water, as in S14)";
        fixed real "sigma_heading" (params.sigma[0]).min(0.0),
            "Per-sample noise sigma' of psi' (Table 9: 5.0943e-4)";
        fixed real "sigma_yaw_rate" (params.sigma[1]).min(0.0),
            "Per-sample noise sigma' of r' (Table 9: 3.9298e-4)";
        fixed real "sigma_drift_angle" (params.sigma[2]).min(0.0),
            "Per-sample noise sigma' of beta' (Table 9: 4.0688e-4)";
        fixed real "sigma_cross_track" (params.sigma[3]).min(0.0),
            "Per-sample noise sigma' of eta' (Table 9: 1.0065e-3)";
        fixed real "q_n" (params.q[0]).min(0.0), "Disturbance intensity q'_N (eq. 115: 2e-10)";
        fixed real "q_y" (params.q[1]).min(0.0), "Disturbance intensity q'_Y (eq. 116: 1.25e-9)";
        fixed real "p0_f23" (params.p0[1]).min(0.0),
            "Initial variance of f23 (eq. 117: 6.640; the other P0 entries are eq. 117's)";
        fixed real "p0_f25" (params.p0[2]).min(0.0), "Initial variance of f25 (eq. 117: 0.02568)";
        fixed bool "b14_derived" (params.b14_derived),
            "Use B14 = B41 = dt sigma1^2 derived from eq. 88 instead of the printed 0 of eq. 104";
        path_measurements!();
        input real "rudder_angle" ["rad"] (rudder), "Rudder angle delta (known exactly)";
        output real "f22_estimate" (|m| m.estimator.estimate()[0]), "Estimate of f22";
        output real "f23_estimate" (|m| m.estimator.estimate()[1]), "Estimate of f23";
        output real "f25_estimate" (|m| m.estimator.estimate()[2]), "Estimate of f25";
        output real "f32_estimate" (|m| m.estimator.estimate()[3]), "Estimate of f32";
        output real "f33_estimate" (|m| m.estimator.estimate()[4]), "Estimate of f33";
        output real "f35_estimate" (|m| m.estimator.estimate()[5]), "Estimate of f35";
    }
}

impl FmuModel for PathEstimatorFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        check_positive("ship_length", self.ship_length)?;
        check_positive("ship_speed", self.ship_speed)?;
        self.estimator =
            Mve::new(self.params, self.initial_estimate()).map_err(|e| e.to_string())?;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        // one sample per communication step, at its start; Δt′ = h U/L
        let dt = h * self.ship_speed / self.ship_length;
        if (dt - self.estimator.params.dt).abs() > 1e-12 * dt {
            self.estimator.set_dt(dt).map_err(|e| e.to_string())?;
        }
        let z = self.prime();
        self.estimator.sample(z, self.rudder);
        Ok(())
    }
}
