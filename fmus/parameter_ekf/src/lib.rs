//! `ParameterEkf` FMU: the continuous-discrete state-augmented EKF of the DDG-51 thesis
//! (`models::observers::parameter_ekf`), identifying −Y_v, m − Y_r, −N_v, m x_G − N_r.
//! No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::hull::nomoto::{esso_osaka_assumed_m_b, FOOT};
use models::hull::KNOT;
use models::observers::parameter_ekf::{ParameterEkf, ParameterEkfParams};
use serde::{Deserialize, Serialize};

/// Table 2.3 (Esso Osaka) coefficients; the default initial estimates are half of them.
pub const ESSO_OSAKA: [f64; 4] = [0.0244, 0.0138, 1.4578e-3, 8.093e-4];

/// The default parameters: the Esso Osaka preset of `NomotoShip` (L = 1066.3 ft, U = 10 kn,
/// assumed M and b), Table 4.1 noise, x̂₀ = 0.5 × Table 2.3, n₀ = 80 rpm.
pub fn default_params() -> ParameterEkfParams {
    let (m, b) = esso_osaka_assumed_m_b();
    ParameterEkfParams::table_4_1(
        1066.3 * FOOT,
        10.0 * KNOT,
        80.0,
        m,
        b,
        ESSO_OSAKA.map(|c| 0.5 * c),
    )
}

/// Parameters, inputs and filter of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ParameterEkfFmu {
    params: ParameterEkfParams,
    /// Measured u [m/s], v [m/s], r [rad/s], n [rpm].
    z: [f64; 4],
    rudder: f64,
    filter: ParameterEkf,
}

impl Default for ParameterEkfFmu {
    fn default() -> Self {
        let params = default_params();
        ParameterEkfFmu {
            filter: ParameterEkf::new(params.clone(), 0.0).expect("preset"),
            params,
            z: [10.0 * KNOT, 0.0, 0.0, 80.0],
            rudder: 0.0,
        }
    }
}

type V = Variable<ParameterEkfFmu>;

static VARIABLES: [V; 45] = [
    // ---- ship data ----
    V::real_parameter(
        "length",
        Some("m"),
        false,
        "Reference length L (default Esso Osaka LBP 1066.3 ft)",
        |m| m.params.length,
        |m, v| m.params.length = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "speed",
        Some("m/s"),
        false,
        "Nominal speed U: u' = u/U, v' = v/U, r' = r L/U, t' = t U/L (default 10 kn)",
        |m| m.params.speed,
        |m, v| m.params.speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "shaft_speed",
        Some("rpm"),
        false,
        "Nominal shaft speed n0: n' = n/n0 (the thesis leaves n' undefined)",
        |m| m.params.shaft_speed,
        |m, v| m.params.shaft_speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "m11",
        None,
        false,
        "Mass matrix m - Y_vdot (prime; default: assumed Esso Osaka value)",
        |m| m.params.mass[0][0],
        |m, v| m.params.mass[0][0] = v,
    ),
    V::real_parameter(
        "m12",
        None,
        false,
        "Mass matrix m x_G - Y_rdot (prime)",
        |m| m.params.mass[0][1],
        |m, v| m.params.mass[0][1] = v,
    ),
    V::real_parameter(
        "m21",
        None,
        false,
        "Mass matrix m x_G - N_vdot (prime)",
        |m| m.params.mass[1][0],
        |m, v| m.params.mass[1][0] = v,
    ),
    V::real_parameter(
        "m22",
        None,
        false,
        "Mass matrix I_z - N_rdot (prime)",
        |m| m.params.mass[1][1],
        |m, v| m.params.mass[1][1] = v,
    ),
    V::real_parameter(
        "rudder_sway_coefficient",
        None,
        false,
        "Y'_delta per rad (prime; known, not identified)",
        |m| m.params.rudder[0],
        |m, v| m.params.rudder[0] = v,
    ),
    V::real_parameter(
        "rudder_yaw_coefficient",
        None,
        false,
        "N'_delta per rad (prime; known, not identified)",
        |m| m.params.rudder[1],
        |m, v| m.params.rudder[1] = v,
    ),
    // ---- filter ----
    V::real_parameter(
        "initial_neg_y_v",
        None,
        false,
        "Initial estimate of -Y'_v (default half the Esso Osaka 0.0244)",
        |m| m.params.initial_coefficients[0],
        |m, v| m.params.initial_coefficients[0] = v,
    ),
    V::real_parameter(
        "initial_m_minus_y_r",
        None,
        false,
        "Initial estimate of m' - Y'_r (default half of 0.0138)",
        |m| m.params.initial_coefficients[1],
        |m, v| m.params.initial_coefficients[1] = v,
    ),
    V::real_parameter(
        "initial_neg_n_v",
        None,
        false,
        "Initial estimate of -N'_v (default half of 1.4578e-3)",
        |m| m.params.initial_coefficients[2],
        |m, v| m.params.initial_coefficients[2] = v,
    ),
    V::real_parameter(
        "initial_mxg_minus_n_r",
        None,
        false,
        "Initial estimate of m'x'_G - N'_r (default half of 8.093e-4)",
        |m| m.params.initial_coefficients[3],
        |m, v| m.params.initial_coefficients[3] = v,
    ),
    V::real_parameter(
        "initial_state_variance",
        None,
        false,
        "P0 diagonal of u', v', r', n'",
        |m| m.params.initial_state_variance,
        |m, v| m.params.initial_state_variance = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "initial_coefficient_variance",
        None,
        false,
        "P0 diagonal of the four coefficients",
        |m| m.params.initial_coefficient_variance,
        |m, v| m.params.initial_coefficient_variance = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "process_noise",
        None,
        false,
        "Q on u', v', r', n', spectral density per unit t' (Table 4.1: 0.05; Esso Osaka run: 0)",
        |m| m.params.process_noise,
        |m, v| m.params.process_noise = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "coefficient_noise",
        None,
        false,
        "FQ, 'fake' noise on the coefficients, spectral density per unit t' (Table 4.1: 0.01)",
        |m| m.params.coefficient_noise,
        |m, v| m.params.coefficient_noise = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "measurement_noise",
        None,
        false,
        "R, variance of each nondimensional measurement per sample (Table 4.1: 0.01)",
        |m| m.params.measurement_noise,
        |m, v| m.params.measurement_noise = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "sample_interval",
        Some("s"),
        false,
        "Measurement sample interval: an update at the start of each step reaching the next sample time",
        |m| m.params.sample_interval,
        |m, v| m.params.sample_interval = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "averaging_fraction",
        None,
        false,
        "Fraction of the estimate history averaged for the *_mean outputs (thesis: 0.67)",
        |m| m.params.averaging_fraction,
        |m, v| m.params.averaging_fraction = v,
    )
    .with_range(Some(0.0), Some(1.0)),
    V::real_parameter(
        "max_substep",
        Some("s"),
        false,
        "Largest RK4 sub-step of the propagation of the estimate and covariance",
        |m| m.params.max_substep,
        |m, v| m.params.max_substep = v,
    )
    .with_range(Some(0.0), None),
    // ---- inputs ----
    V::real_input(
        "surge_velocity_measured",
        Some("m/s"),
        "Measured surge u",
        |m| m.z[0],
        |m, v| m.z[0] = v,
    ),
    V::real_input(
        "sway_velocity_measured",
        Some("m/s"),
        "Measured sway v",
        |m| m.z[1],
        |m, v| m.z[1] = v,
    ),
    V::real_input(
        "yaw_rate_measured",
        Some("rad/s"),
        "Measured yaw rate r",
        |m| m.z[2],
        |m, v| m.z[2] = v,
    ),
    V::real_input(
        "shaft_speed_measured",
        Some("rpm"),
        "Measured shaft speed n",
        |m| m.z[3],
        |m, v| m.z[3] = v,
    ),
    V::real_input(
        "rudder_angle",
        Some("rad"),
        "Rudder angle applied over the step (positive: starboard turn)",
        |m| m.rudder,
        |m, v| m.rudder = v,
    ),
    // ---- outputs ----
    V::real_output(
        "surge_velocity_estimate",
        Some("m/s"),
        "Estimated u (a priori at the end of the step)",
        |m| m.filter.dimensional_states()[0],
    ),
    V::real_output(
        "sway_velocity_estimate",
        Some("m/s"),
        "Estimated v",
        |m| m.filter.dimensional_states()[1],
    ),
    V::real_output(
        "yaw_rate_estimate",
        Some("rad/s"),
        "Estimated r",
        |m| m.filter.dimensional_states()[2],
    ),
    V::real_output(
        "shaft_speed_estimate",
        Some("rpm"),
        "Estimated n",
        |m| m.filter.dimensional_states()[3],
    ),
    V::real_output(
        "neg_y_v_estimate",
        None,
        "Current estimate of -Y'_v",
        |m| m.filter.coefficients()[0],
    ),
    V::real_output(
        "m_minus_y_r_estimate",
        None,
        "Current estimate of m' - Y'_r",
        |m| m.filter.coefficients()[1],
    ),
    V::real_output(
        "neg_n_v_estimate",
        None,
        "Current estimate of -N'_v",
        |m| m.filter.coefficients()[2],
    ),
    V::real_output(
        "mxg_minus_n_r_estimate",
        None,
        "Current estimate of m'x'_G - N'_r",
        |m| m.filter.coefficients()[3],
    ),
    V::real_output(
        "neg_y_v_mean",
        None,
        "-Y'_v: mean of the last averaging_fraction of the updated estimates (the identified value)",
        |m| m.filter.averaged_coefficients()[0],
    ),
    V::real_output(
        "m_minus_y_r_mean",
        None,
        "m' - Y'_r: running mean of the last averaging_fraction of the estimates",
        |m| m.filter.averaged_coefficients()[1],
    ),
    V::real_output(
        "neg_n_v_mean",
        None,
        "-N'_v: running mean of the last averaging_fraction of the estimates",
        |m| m.filter.averaged_coefficients()[2],
    ),
    V::real_output(
        "mxg_minus_n_r_mean",
        None,
        "m'x'_G - N'_r: running mean of the last averaging_fraction of the estimates",
        |m| m.filter.averaged_coefficients()[3],
    ),
    V::real_output(
        "neg_y_v_std",
        None,
        "Filter standard deviation of -Y'_v (sqrt of the P diagonal)",
        |m| m.filter.covariance()[(4, 4)].max(0.0).sqrt(),
    ),
    V::real_output(
        "neg_n_v_std",
        None,
        "Filter standard deviation of -N'_v",
        |m| m.filter.covariance()[(6, 6)].max(0.0).sqrt(),
    ),
    V::real_output(
        "nomoto_time_constant_prime",
        None,
        "First-order Nomoto T' of the model with the mean coefficients",
        |m| m.filter.identified_nomoto().0,
    ),
    V::real_output(
        "nomoto_gain_prime",
        None,
        "First-order Nomoto K' of the model with the mean coefficients (steady r' = K' delta)",
        |m| m.filter.identified_nomoto().1,
    ),
    V::real_output(
        "innovation_sway",
        None,
        "Innovation of v' at the last update",
        |m| m.filter.innovation()[1],
    ),
    V::real_output(
        "innovation_yaw_rate",
        None,
        "Innovation of r' at the last update",
        |m| m.filter.innovation()[2],
    ),
    V::real_output(
        "update_count",
        None,
        "Number of measurement updates so far",
        |m| m.filter.updates() as f64,
    ),
];

impl FmuModel for ParameterEkfFmu {
    const MODEL_IDENTIFIER: &'static str = "ParameterEkf";
    const DESCRIPTION: &'static str = "State-augmented EKF identifying the linear sway-yaw \
        coefficients -Y_v, m-Y_r, -N_v, m x_G-N_r on-line (DDG-51 thesis)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 1800.0,
        step_size: 1.0,
    };
    const DIRECT_FEEDTHROUGH: bool = false;

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.filter = ParameterEkf::new(self.params.clone(), start_time)?;
        Ok(())
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.filter.step(t, h, self.z, self.rudder);
        Ok(())
    }
}

export_fmu!(ParameterEkfFmu);
