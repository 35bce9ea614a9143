//! `ParameterEkf` FMU: the continuous-discrete state-augmented EKF of the DDG-51 thesis
//! (`models::observers::parameter_ekf`), identifying −Y_v, m − Y_r, −N_v, m x_G − N_r.
//! No physics here.

use fmi2_export::{passes, FmuModel};
use models::hull::nomoto::{esso_osaka_assumed_m_b, FOOT};
use models::hull::KNOT;
use models::observers::parameter_ekf::{ParameterEkf, ParameterEkfParams};
use serde::{Deserialize, Serialize};

/// [Taylor2000, Table 2.3] (Esso Osaka) coefficients; the default initial estimates are half of them.
pub const ESSO_OSAKA: [f64; 4] = [0.0244, 0.0138, 1.4578e-3, 8.093e-4];

/// The default parameters: the Esso Osaka preset of `NomotoShip` (L = 1066.3 ft, U = 10 kn,
/// assumed M and b), [Taylor2000, Table 4.1] noise, x̂₀ = 0.5 × [Taylor2000, Table 2.3], n₀ = 80 rpm.
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
    measured: [f64; 4],
    rudder: f64,
    filter: ParameterEkf,
}

impl Default for ParameterEkfFmu {
    fn default() -> Self {
        let params = default_params();
        ParameterEkfFmu {
            filter: ParameterEkf::new(params.clone(), 0.0).expect("preset"),
            params,
            measured: [10.0 * KNOT, 0.0, 0.0, 80.0],
            rudder: 0.0,
        }
    }
}

fmi2_export::fmu! {
    ParameterEkfFmu => "ParameterEkf",
    description: "State-augmented EKF identifying the linear sway-yaw \
        coefficients -Y_v, m-Y_r, -N_v, m x_G-N_r on-line (DDG-51 thesis)",
    experiment: (0.0, 1800.0, 1.0),
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        // ---- ship data ----
        fixed real "length" ["m"] (params.length).min(0.0),
            "Reference length L (default Esso Osaka LBP 1066.3 ft)";
        fixed real "speed" ["m/s"] (params.speed).min(0.0),
            "Nominal speed U: u' = u/U, v' = v/U, r' = r L/U, t' = t U/L (default 10 kn)";
        fixed real "shaft_speed" ["rpm"] (params.shaft_speed).min(0.0),
            "Nominal shaft speed n0: n' = n/n0 (the thesis leaves n' undefined)";
        fixed real "m11" (params.mass[0][0]),
            "Mass matrix m - Y_vdot (prime; default: assumed Esso Osaka value)";
        fixed real "m12" (params.mass[0][1]), "Mass matrix m x_G - Y_rdot (prime)";
        fixed real "m21" (params.mass[1][0]), "Mass matrix m x_G - N_vdot (prime)";
        fixed real "m22" (params.mass[1][1]), "Mass matrix I_z - N_rdot (prime)";
        fixed real "rudder_sway_coefficient" (params.rudder[0]),
            "Y'_delta per rad (prime; known, not identified)";
        fixed real "rudder_yaw_coefficient" (params.rudder[1]),
            "N'_delta per rad (prime; known, not identified)";
        // ---- filter ----
        fixed real "initial_neg_y_v" (params.initial_coefficients[0]),
            "Initial estimate of -Y'_v (default half the Esso Osaka 0.0244)";
        fixed real "initial_m_minus_y_r" (params.initial_coefficients[1]),
            "Initial estimate of m' - Y'_r (default half of 0.0138)";
        fixed real "initial_neg_n_v" (params.initial_coefficients[2]),
            "Initial estimate of -N'_v (default half of 1.4578e-3)";
        fixed real "initial_mxg_minus_n_r" (params.initial_coefficients[3]),
            "Initial estimate of m'x'_G - N'_r (default half of 8.093e-4)";
        fixed real "initial_state_variance" (params.initial_state_variance).min(0.0),
            "P0 diagonal of u', v', r', n'";
        fixed real "initial_coefficient_variance" (params.initial_coefficient_variance).min(0.0),
            "P0 diagonal of the four coefficients";
        fixed real "process_noise" (params.process_noise).min(0.0),
            "Q on u', v', r', n', spectral density per unit t' (Table 4.1: 0.05; Esso Osaka run: 0)";
        fixed real "coefficient_noise" (params.coefficient_noise).min(0.0),
            "FQ, 'fake' noise on the coefficients, spectral density per unit t' (Table 4.1: 0.01)";
        fixed real "measurement_noise" (params.measurement_noise).min(0.0),
            "R, variance of each nondimensional measurement per sample (Table 4.1: 0.01)";
        fixed real "sample_interval" ["s"] (params.sample_interval).min(0.0),
            "Measurement sample interval: an update at the start of each step reaching the next sample time";
        fixed real "averaging_fraction" (params.averaging_fraction).range(0.0, 1.0),
            "Fraction of the estimate history averaged for the *_mean outputs (thesis: 0.67)";
        fixed real "max_substep" ["s"] (params.max_substep).min(0.0),
            "Largest RK4 sub-step of the propagation of the estimate and covariance";
        // ---- inputs ----
        input real "surge_velocity_measured" ["m/s"] (measured[0]), "Measured surge u";
        input real "sway_velocity_measured" ["m/s"] (measured[1]), "Measured sway v";
        input real "yaw_rate_measured" ["rad/s"] (measured[2]), "Measured yaw rate r";
        input real "shaft_speed_measured" ["rpm"] (measured[3]), "Measured shaft speed n";
        input real "rudder_angle" ["rad"] (rudder),
            "Rudder angle applied over the step (positive: starboard turn)";
        // ---- outputs ----
        output real "surge_velocity_estimate" ["m/s"] (|m| m.filter.dimensional_states()[0]),
            "Estimated u (a priori at the end of the step)";
        output real "sway_velocity_estimate" ["m/s"] (|m| m.filter.dimensional_states()[1]),
            "Estimated v";
        output real "yaw_rate_estimate" ["rad/s"] (|m| m.filter.dimensional_states()[2]),
            "Estimated r";
        output real "shaft_speed_estimate" ["rpm"] (|m| m.filter.dimensional_states()[3]),
            "Estimated n";
        output real "neg_y_v_estimate" (|m| m.filter.coefficients()[0]), "Current estimate of -Y'_v";
        output real "m_minus_y_r_estimate" (|m| m.filter.coefficients()[1]),
            "Current estimate of m' - Y'_r";
        output real "neg_n_v_estimate" (|m| m.filter.coefficients()[2]), "Current estimate of -N'_v";
        output real "mxg_minus_n_r_estimate" (|m| m.filter.coefficients()[3]),
            "Current estimate of m'x'_G - N'_r";
        output real "neg_y_v_mean" (|m| m.filter.averaged_coefficients()[0]),
            "-Y'_v: mean of the last averaging_fraction of the updated estimates (the identified value)";
        output real "m_minus_y_r_mean" (|m| m.filter.averaged_coefficients()[1]),
            "m' - Y'_r: running mean of the last averaging_fraction of the estimates";
        output real "neg_n_v_mean" (|m| m.filter.averaged_coefficients()[2]),
            "-N'_v: running mean of the last averaging_fraction of the estimates";
        output real "mxg_minus_n_r_mean" (|m| m.filter.averaged_coefficients()[3]),
            "m'x'_G - N'_r: running mean of the last averaging_fraction of the estimates";
        output real "neg_y_v_std" (|m| m.filter.covariance()[(4, 4)].max(0.0).sqrt()),
            "Filter standard deviation of -Y'_v (sqrt of the P diagonal)";
        output real "neg_n_v_std" (|m| m.filter.covariance()[(6, 6)].max(0.0).sqrt()),
            "Filter standard deviation of -N'_v";
        output real "nomoto_time_constant_prime" (|m| m.filter.identified_nomoto().0),
            "First-order Nomoto T' of the model with the mean coefficients";
        output real "nomoto_gain_prime" (|m| m.filter.identified_nomoto().1),
            "First-order Nomoto K' of the model with the mean coefficients (steady r' = K' delta)";
        output real "innovation_sway" (|m| m.filter.innovation()[1]),
            "Innovation of v' at the last update";
        output real "innovation_yaw_rate" (|m| m.filter.innovation()[2]),
            "Innovation of r' at the last update";
        output real "update_count" (|m| m.filter.updates() as f64),
            "Number of measurement updates so far";
    }
}

impl FmuModel for ParameterEkfFmu {
    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.filter = ParameterEkf::new(self.params.clone(), start_time)?;
        Ok(())
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.filter.step(t, h, self.measured, self.rudder);
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        // RK4 in t' = t U/L ([`ParameterEkf::propagate`]); at most one update per step.
        let p = self.filter.params();
        let scale = p.speed / p.length;
        let n = passes(h * scale, p.max_substep * scale);
        each("max_substep", p.max_substep, n);
    }
}
