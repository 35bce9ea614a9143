//! `PathEstimator` FMU: the Minimum-Variance parameter Estimator of Parsons & Cuong (1980,
//! source 004, section 5) in `models::controllers::mve`, estimating f22, f23, f25, f32, f33, f35
//! of the Tokyo Maru from the measured states and the rudder angle; its outputs feed the
//! PathController's estimate inputs. No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::controllers::mve::{parameters_of, Mve, MveParams};
use models::hull::tokyo_maru::TokyoMaruCoefficients;
use models::observers::path_model::states_prime;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one estimator instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PathEstimatorFmu {
    p: MveParams,
    interval: i32,
    initial_depth_ratio: f64,
    ship_length: f64,
    ship_speed: f64,
    /// ψ [rad], r [rad/s], β [rad], η [m], δ [rad].
    z: [f64; 4],
    rudder: f64,
    mve: Mve,
}

impl PathEstimatorFmu {
    fn initial_estimate(&self) -> [f64; 6] {
        parameters_of(&TokyoMaruCoefficients::at_depth_ratio(
            self.initial_depth_ratio,
        ))
    }

    fn prime(&self) -> [f64; 4] {
        states_prime(&self.z, self.ship_length, self.ship_speed)
    }
}

impl Default for PathEstimatorFmu {
    fn default() -> Self {
        let p = MveParams::default();
        let initial_depth_ratio = 1e300;
        PathEstimatorFmu {
            interval: p.interval as i32,
            initial_depth_ratio,
            ship_length: models::hull::tokyo_maru::L,
            ship_speed: models::hull::tokyo_maru::U,
            z: [0.0; 4],
            rudder: 0.0,
            mve: Mve::new(
                p,
                parameters_of(&TokyoMaruCoefficients::at_depth_ratio(initial_depth_ratio)),
            )
            .expect("default settings are valid"),
            p,
        }
    }
}

type V = Variable<PathEstimatorFmu>;

static VARIABLES: [V; 24] = [
    V::integer_parameter(
        "interval",
        false,
        "Estimation interval l in samples (communication steps): 10 (must be > 1)",
        2,
        1000,
        |m| m.interval,
        |m, v| m.interval = v,
    ),
    V::real_parameter(
        "initial_depth_ratio",
        None,
        false,
        "H/T whose Table 2 coefficients are the initial estimates (1e300: deep water, as in S14)",
        |m| m.initial_depth_ratio,
        |m, v| m.initial_depth_ratio = v,
    )
    .with_range(Some(1.0), None),
    V::real_parameter(
        "sigma_heading",
        None,
        false,
        "Per-sample noise sigma' of psi' (Table 9: 5.0943e-4)",
        |m| m.p.sigma[0],
        |m, v| m.p.sigma[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "sigma_yaw_rate",
        None,
        false,
        "Per-sample noise sigma' of r' (Table 9: 3.9298e-4)",
        |m| m.p.sigma[1],
        |m, v| m.p.sigma[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "sigma_drift_angle",
        None,
        false,
        "Per-sample noise sigma' of beta' (Table 9: 4.0688e-4)",
        |m| m.p.sigma[2],
        |m, v| m.p.sigma[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "sigma_cross_track",
        None,
        false,
        "Per-sample noise sigma' of eta' (Table 9: 1.0065e-3)",
        |m| m.p.sigma[3],
        |m, v| m.p.sigma[3] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "q_n",
        None,
        false,
        "Disturbance intensity q'_N (eq. 115: 2e-10)",
        |m| m.p.q[0],
        |m, v| m.p.q[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "q_y",
        None,
        false,
        "Disturbance intensity q'_Y (eq. 116: 1.25e-9)",
        |m| m.p.q[1],
        |m, v| m.p.q[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "p0_f23",
        None,
        false,
        "Initial variance of f23 (eq. 117: 6.640; the other P0 entries are eq. 117's)",
        |m| m.p.p0[1],
        |m, v| m.p.p0[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "p0_f25",
        None,
        false,
        "Initial variance of f25 (eq. 117: 0.02568)",
        |m| m.p.p0[2],
        |m, v| m.p.p0[2] = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "b14_derived",
        false,
        "Use B14 = B41 = dt sigma1^2 derived from eq. 88 instead of the printed 0 of eq. 104",
        |m| m.p.b14_derived,
        |m, v| m.p.b14_derived = v,
    ),
    V::real_parameter(
        "ship_length",
        Some("m"),
        false,
        "Ship length L of the prime system (290 m)",
        |m| m.ship_length,
        |m, v| m.ship_length = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "ship_speed",
        Some("m/s"),
        false,
        "Ship speed U of the prime system (12 kn)",
        |m| m.ship_speed,
        |m, v| m.ship_speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_input(
        "heading",
        Some("rad"),
        "Measured heading psi relative to the track direction",
        |m| m.z[0],
        |m, v| m.z[0] = v,
    ),
    V::real_input(
        "yaw_rate",
        Some("rad/s"),
        "Measured yaw rate r",
        |m| m.z[1],
        |m, v| m.z[1] = v,
    ),
    V::real_input(
        "drift_angle",
        Some("rad"),
        "Measured drift angle beta (Doppler sonar, v = -U beta)",
        |m| m.z[2],
        |m, v| m.z[2] = v,
    ),
    V::real_input(
        "cross_track",
        Some("m"),
        "Measured lateral offset eta",
        |m| m.z[3],
        |m, v| m.z[3] = v,
    ),
    V::real_input(
        "rudder_angle",
        Some("rad"),
        "Rudder angle delta (known exactly)",
        |m| m.rudder,
        |m, v| m.rudder = v,
    ),
    V::real_output("f22_estimate", None, "Estimate of f22", |m| {
        m.mve.estimate()[0]
    }),
    V::real_output("f23_estimate", None, "Estimate of f23", |m| {
        m.mve.estimate()[1]
    }),
    V::real_output("f25_estimate", None, "Estimate of f25", |m| {
        m.mve.estimate()[2]
    }),
    V::real_output("f32_estimate", None, "Estimate of f32", |m| {
        m.mve.estimate()[3]
    }),
    V::real_output("f33_estimate", None, "Estimate of f33", |m| {
        m.mve.estimate()[4]
    }),
    V::real_output("f35_estimate", None, "Estimate of f35", |m| {
        m.mve.estimate()[5]
    }),
];

impl FmuModel for PathEstimatorFmu {
    const MODEL_IDENTIFIER: &'static str = "PathEstimator";
    const DESCRIPTION: &'static str = "Minimum-Variance parameter Estimator of the Tokyo Maru \\
        path model (Parsons & Cuong 1980, section 5): f22, f23, f25, f32, f33, f35 for the \\
        PathController's partial adaptation";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 470.0,
        step_size: 0.2349,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        if !(self.ship_length > 0.0 && self.ship_speed > 0.0) {
            return Err("ship_length and ship_speed must be > 0".into());
        }
        self.p.interval = self.interval.max(2) as u32;
        self.mve = Mve::new(self.p, self.initial_estimate()).map_err(|e| e.to_string())?;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        // one sample per communication step, at its start; Δt′ = h U/L
        let dt = h * self.ship_speed / self.ship_length;
        if (dt - self.mve.params.dt).abs() > 1e-12 * dt {
            self.mve.set_dt(dt).map_err(|e| e.to_string())?;
        }
        let z = self.prime();
        self.mve.sample(z, self.rudder);
        Ok(())
    }
}

export_fmu!(PathEstimatorFmu);
