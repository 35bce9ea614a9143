//! `DpController` FMU: the dynamic-positioning PID of `models::controllers::dp` as an FMI 2.0
//! co-simulation FMU. No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::FmuModel;
use models::controllers::dp::{body_error, DpController, DpInputs, DpParams};
use models::disturbances::shaping::quantise_time;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one controller instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DpControllerFmu {
    params: DpParams,
    inputs: DpInputs,
    controller: DpController,
}

impl Default for DpControllerFmu {
    fn default() -> Self {
        let params = DpParams::northern_clipper();
        DpControllerFmu {
            controller: DpController::new(params.clone(), 0.0)
                .expect("preset parameters are valid"),
            params,
            inputs: DpInputs::default(),
        }
    }
}

impl DpControllerFmu {
    fn tau(&self, i: usize) -> f64 {
        self.controller.tau(&self.inputs)[i]
    }
    fn error(&self, i: usize) -> f64 {
        body_error(self.inputs.eta, self.inputs.setpoint)[i]
    }
}

/// The inputs the commanded forces depend on directly: every input, in the order eta, nu,
/// setpoint.
pub const TAU_DEPS: &[&str] = &[
    "north_estimate",
    "east_estimate",
    "heading_estimate",
    "surge_velocity_estimate",
    "sway_velocity_estimate",
    "yaw_rate_estimate",
    "north_setpoint",
    "east_setpoint",
    "heading_setpoint",
];
/// The inputs the position errors depend on directly.
const ERR_DEPS: &[&str] = &[
    "north_estimate",
    "east_estimate",
    "heading_estimate",
    "north_setpoint",
    "east_setpoint",
    "heading_setpoint",
];

fmi2_export::fmu! {
    DpControllerFmu => "DpController",
    description: "Dynamic-positioning PID on the observer's LF estimates in the \
        body frame, gains from the desired bandwidth, with the open-loop test input of Fossen & \
        Strand (1999) Eq. 61",
    experiment: (0.0, 1000.0, 1.0),
    documentation: "documentation.html",
    variables: {
        fixed real "mass_surge" ["kg"] (params.mass[0]).min(0.0),
            "m11 = m - X_udot used for the surge gains ([Fossen1999, eq. (56)]: 5.3122e6)";
        fixed real "mass_sway" ["kg"] (params.mass[1]).min(0.0),
            "m22 = m - Y_vdot used for the sway gains ([Fossen1999, eq. (56)]: 8.2831e6)";
        fixed real "inertia_yaw" (params.mass[2]).min(0.0),
            "m33 = I_z - N_rdot [kg m2] used for the yaw gains ([Fossen1999, eq. (56)]: 3.7454e9)";
        fixed real "damping_surge" (params.damping[0]).min(0.0),
            "d11 = -X_u [N s/m] used for the surge gains ([Fossen1999, eq. (57)]: 5.0242e4)";
        fixed real "damping_sway" (params.damping[1]).min(0.0),
            "d22 = -Y_v [N s/m] used for the sway gains ([Fossen1999, eq. (57)]: 2.7229e5)";
        fixed real "damping_yaw" (params.damping[2]).min(0.0),
            "d33 = -N_r [N m s] used for the yaw gains ([Fossen1999, eq. (57)]: 4.1894e8)";
        fixed real "bandwidth_surge" ["rad/s"] (params.bandwidth[0]).min(0.0),
            "Desired closed-loop bandwidth omega_b in surge; 0: no feedback";
        fixed real "bandwidth_sway" ["rad/s"] (params.bandwidth[1]).min(0.0),
            "Desired closed-loop bandwidth omega_b in sway; 0: no feedback";
        fixed real "bandwidth_yaw" ["rad/s"] (params.bandwidth[2]).min(0.0),
            "Desired closed-loop bandwidth omega_b in yaw; 0: no feedback";
        fixed real "relative_damping" (params.relative_damping).min(0.0),
            "Relative damping zeta of the closed loop (gains: Kp = m wn^2, Kd = 2 zeta wn m - d)";
        fixed real "integral_ratio" (params.integral_ratio).min(0.0),
            "r in Ki = Kp wn / r (Fossen's rule r = 10); 0: no integral action";
        tunable real "test_amplitude_surge" ["N"] (params.test_amplitude[0]),
            "Amplitude A of the feed-forward test input A sin(w t) in surge ([Fossen1999, eq. (61)]: 1000)";
        tunable real "test_amplitude_sway" ["N"] (params.test_amplitude[1]),
            "Amplitude of the feed-forward test input in sway ([Fossen1999, eq. (61)]: 1000)";
        tunable real "test_amplitude_yaw" ["N.m"] (params.test_amplitude[2]),
            "Amplitude of the feed-forward test input in yaw ([Fossen1999, eq. (61)]: 1000)";
        tunable real "test_frequency_surge" ["rad/s"] (params.test_frequency[0]),
            "Frequency w of the surge test input ([Fossen1999, eq. (61)]: 0.05)";
        tunable real "test_frequency_sway" ["rad/s"] (params.test_frequency[1]),
            "Frequency of the sway test input ([Fossen1999, eq. (61)]: 0.1)";
        tunable real "test_frequency_yaw" ["rad/s"] (params.test_frequency[2]),
            "Frequency of the yaw test input ([Fossen1999, eq. (61)]: 0.07)";
        input real "north_estimate" ["m"] (inputs.eta[0]),
            "LF north position estimate (observer eta_hat, not the measurement)";
        input real "east_estimate" ["m"] (inputs.eta[1]), "LF east position estimate";
        input real "heading_estimate" ["rad"] (inputs.eta[2]),
            "LF heading estimate (rotation J(psi_hat) of the error)";
        input real "surge_velocity_estimate" ["m/s"] (inputs.nu[0]),
            "LF surge velocity estimate (body)";
        input real "sway_velocity_estimate" ["m/s"] (inputs.nu[1]),
            "LF sway velocity estimate (body)";
        input real "yaw_rate_estimate" ["rad/s"] (inputs.nu[2]), "LF yaw-rate estimate";
        input real "north_setpoint" ["m"] (inputs.setpoint[0]), "Desired north position";
        input real "east_setpoint" ["m"] (inputs.setpoint[1]), "Desired east position";
        input real "heading_setpoint" ["rad"] (inputs.setpoint[2]), "Desired heading";
        output real "tau_surge" ["N"] (|m| m.tau(0)).depends_on(TAU_DEPS),
            "Commanded surge force (body)";
        output real "tau_sway" ["N"] (|m| m.tau(1)).depends_on(TAU_DEPS),
            "Commanded sway force (body)";
        output real "tau_yaw" ["N.m"] (|m| m.tau(2)).depends_on(TAU_DEPS), "Commanded yaw moment";
        output real "error_surge" ["m"] (|m| m.error(0)).depends_on(ERR_DEPS),
            "Body-frame position error J^T(psi_hat)(eta_hat - eta_d), surge";
        output real "error_sway" ["m"] (|m| m.error(1)).depends_on(ERR_DEPS),
            "Body-frame position error, sway";
        output real "error_yaw" ["rad"] (|m| m.error(2)).depends_on(ERR_DEPS),
            "Heading error, wrapped to (-pi, pi]";
        calculated real "kp_surge" (|m| m.controller.gains().0[0]), "Kp surge [N/m]";
        calculated real "kp_sway" (|m| m.controller.gains().0[1]), "Kp sway [N/m]";
        calculated real "kp_yaw" (|m| m.controller.gains().0[2]), "Kp yaw [N m/rad]";
        calculated real "kd_surge" (|m| m.controller.gains().1[0]), "Kd surge [N s/m]";
        calculated real "kd_sway" (|m| m.controller.gains().1[1]), "Kd sway [N s/m]";
        calculated real "kd_yaw" (|m| m.controller.gains().1[2]), "Kd yaw [N m s/rad]";
        calculated real "ki_surge" (|m| m.controller.gains().2[0]), "Ki surge [N/(m s)]";
        calculated real "ki_sway" (|m| m.controller.gains().2[1]), "Ki sway [N/(m s)]";
        calculated real "ki_yaw" (|m| m.controller.gains().2[2]), "Ki yaw [N m/(rad s)]";
    }
}

impl FmuModel for DpControllerFmu {
    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.controller = DpController::new(self.params.clone(), quantise_time(start_time))
            .map_err(|e| e.to_string())?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.controller
            .set_params(self.params.clone())
            .map_err(|e| e.to_string())
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.controller.step(&self.inputs, h);
        self.controller.set_time(quantise_time(t + h));
        Ok(())
    }
}
