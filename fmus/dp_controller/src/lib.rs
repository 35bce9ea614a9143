//! `DpController` FMU: the dynamic-positioning PID of `models::controllers::dp` as an FMI 2.0
//! co-simulation FMU. No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::controllers::dp::{body_error, DpController, DpInputs, DpParams};
use models::disturbances::shaping::quantise_time;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one controller instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DpControllerFmu {
    params: DpParams,
    inputs: DpInputs,
    ctrl: DpController,
}

impl Default for DpControllerFmu {
    fn default() -> Self {
        let params = DpParams::northern_clipper();
        DpControllerFmu {
            ctrl: DpController::new(params.clone(), 0.0).expect("preset parameters are valid"),
            params,
            inputs: DpInputs::default(),
        }
    }
}

impl DpControllerFmu {
    fn tau(&self, i: usize) -> f64 {
        self.ctrl.tau(&self.inputs)[i]
    }
    fn error(&self, i: usize) -> f64 {
        body_error(self.inputs.eta, self.inputs.setpoint)[i]
    }
}

type V = Variable<DpControllerFmu>;

const TAU_DEPS: &[&str] = &[
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
const ERR_DEPS: &[&str] = &[
    "north_estimate",
    "east_estimate",
    "heading_estimate",
    "north_setpoint",
    "east_setpoint",
    "heading_setpoint",
];

macro_rules! fixed {
    ($name:literal, $unit:expr, $desc:literal, $field:ident, $i:literal) => {
        V::real_parameter(
            $name,
            $unit,
            false,
            $desc,
            |m| m.params.$field[$i],
            |m, v| m.params.$field[$i] = v,
        )
        .with_range(Some(0.0), None)
    };
}

macro_rules! input {
    ($name:literal, $unit:expr, $desc:literal, $field:ident, $i:literal) => {
        V::real_input(
            $name,
            $unit,
            $desc,
            |m| m.inputs.$field[$i],
            |m, v| m.inputs.$field[$i] = v,
        )
    };
}

static VARIABLES: [V; 41] = [
    fixed!(
        "mass_surge",
        Some("kg"),
        "m11 = m - X_udot used for the surge gains (001 Eq. 56: 5.3122e6)",
        mass,
        0
    ),
    fixed!(
        "mass_sway",
        Some("kg"),
        "m22 = m - Y_vdot used for the sway gains (001 Eq. 56: 8.2831e6)",
        mass,
        1
    ),
    fixed!(
        "inertia_yaw",
        None,
        "m33 = I_z - N_rdot [kg m2] used for the yaw gains (001 Eq. 56: 3.7454e9)",
        mass,
        2
    ),
    fixed!(
        "damping_surge",
        None,
        "d11 = -X_u [N s/m] used for the surge gains (001 Eq. 57: 5.0242e4)",
        damping,
        0
    ),
    fixed!(
        "damping_sway",
        None,
        "d22 = -Y_v [N s/m] used for the sway gains (001 Eq. 57: 2.7229e5)",
        damping,
        1
    ),
    fixed!(
        "damping_yaw",
        None,
        "d33 = -N_r [N m s] used for the yaw gains (001 Eq. 57: 4.1894e8)",
        damping,
        2
    ),
    fixed!(
        "bandwidth_surge",
        Some("rad/s"),
        "Desired closed-loop bandwidth omega_b in surge; 0: no feedback",
        bandwidth,
        0
    ),
    fixed!(
        "bandwidth_sway",
        Some("rad/s"),
        "Desired closed-loop bandwidth omega_b in sway; 0: no feedback",
        bandwidth,
        1
    ),
    fixed!(
        "bandwidth_yaw",
        Some("rad/s"),
        "Desired closed-loop bandwidth omega_b in yaw; 0: no feedback",
        bandwidth,
        2
    ),
    V::real_parameter(
        "relative_damping",
        None,
        false,
        "Relative damping zeta of the closed loop (gains: Kp = m wn^2, Kd = 2 zeta wn m - d)",
        |m| m.params.relative_damping,
        |m, v| m.params.relative_damping = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "integral_ratio",
        None,
        false,
        "r in Ki = Kp wn / r (Fossen's rule r = 10); 0: no integral action",
        |m| m.params.integral_ratio,
        |m, v| m.params.integral_ratio = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "test_amplitude_surge",
        Some("N"),
        true,
        "Amplitude A of the feed-forward test input A sin(w t) in surge (001 Eq. 61: 1000)",
        |m| m.params.test_amplitude[0],
        |m, v| m.params.test_amplitude[0] = v,
    ),
    V::real_parameter(
        "test_amplitude_sway",
        Some("N"),
        true,
        "Amplitude of the feed-forward test input in sway (001 Eq. 61: 1000)",
        |m| m.params.test_amplitude[1],
        |m, v| m.params.test_amplitude[1] = v,
    ),
    V::real_parameter(
        "test_amplitude_yaw",
        Some("N.m"),
        true,
        "Amplitude of the feed-forward test input in yaw (001 Eq. 61: 1000)",
        |m| m.params.test_amplitude[2],
        |m, v| m.params.test_amplitude[2] = v,
    ),
    V::real_parameter(
        "test_frequency_surge",
        Some("rad/s"),
        true,
        "Frequency w of the surge test input (001 Eq. 61: 0.05)",
        |m| m.params.test_frequency[0],
        |m, v| m.params.test_frequency[0] = v,
    ),
    V::real_parameter(
        "test_frequency_sway",
        Some("rad/s"),
        true,
        "Frequency of the sway test input (001 Eq. 61: 0.1)",
        |m| m.params.test_frequency[1],
        |m, v| m.params.test_frequency[1] = v,
    ),
    V::real_parameter(
        "test_frequency_yaw",
        Some("rad/s"),
        true,
        "Frequency of the yaw test input (001 Eq. 61: 0.07)",
        |m| m.params.test_frequency[2],
        |m, v| m.params.test_frequency[2] = v,
    ),
    input!(
        "north_estimate",
        Some("m"),
        "LF north position estimate (observer eta_hat, not the measurement)",
        eta,
        0
    ),
    input!(
        "east_estimate",
        Some("m"),
        "LF east position estimate",
        eta,
        1
    ),
    input!(
        "heading_estimate",
        Some("rad"),
        "LF heading estimate (rotation J(psi_hat) of the error)",
        eta,
        2
    ),
    input!(
        "surge_velocity_estimate",
        Some("m/s"),
        "LF surge velocity estimate (body)",
        nu,
        0
    ),
    input!(
        "sway_velocity_estimate",
        Some("m/s"),
        "LF sway velocity estimate (body)",
        nu,
        1
    ),
    input!(
        "yaw_rate_estimate",
        Some("rad/s"),
        "LF yaw-rate estimate",
        nu,
        2
    ),
    input!(
        "north_setpoint",
        Some("m"),
        "Desired north position",
        setpoint,
        0
    ),
    input!(
        "east_setpoint",
        Some("m"),
        "Desired east position",
        setpoint,
        1
    ),
    input!(
        "heading_setpoint",
        Some("rad"),
        "Desired heading",
        setpoint,
        2
    ),
    V::real_output(
        "tau_surge",
        Some("N"),
        "Commanded surge force (body)",
        |m| m.tau(0),
    )
    .depends_on(TAU_DEPS),
    V::real_output("tau_sway", Some("N"), "Commanded sway force (body)", |m| {
        m.tau(1)
    })
    .depends_on(TAU_DEPS),
    V::real_output("tau_yaw", Some("N.m"), "Commanded yaw moment", |m| m.tau(2))
        .depends_on(TAU_DEPS),
    V::real_output(
        "error_surge",
        Some("m"),
        "Body-frame position error J^T(psi_hat)(eta_hat - eta_d), surge",
        |m| m.error(0),
    )
    .depends_on(ERR_DEPS),
    V::real_output(
        "error_sway",
        Some("m"),
        "Body-frame position error, sway",
        |m| m.error(1),
    )
    .depends_on(ERR_DEPS),
    V::real_output(
        "error_yaw",
        Some("rad"),
        "Heading error, wrapped to (-pi, pi]",
        |m| m.error(2),
    )
    .depends_on(ERR_DEPS),
    V::real_calculated_parameter("kp_surge", None, "Kp surge [N/m]", |m| m.ctrl.gains().0[0]),
    V::real_calculated_parameter("kp_sway", None, "Kp sway [N/m]", |m| m.ctrl.gains().0[1]),
    V::real_calculated_parameter("kp_yaw", None, "Kp yaw [N m/rad]", |m| m.ctrl.gains().0[2]),
    V::real_calculated_parameter("kd_surge", None, "Kd surge [N s/m]", |m| {
        m.ctrl.gains().1[0]
    }),
    V::real_calculated_parameter("kd_sway", None, "Kd sway [N s/m]", |m| m.ctrl.gains().1[1]),
    V::real_calculated_parameter("kd_yaw", None, "Kd yaw [N m s/rad]", |m| {
        m.ctrl.gains().1[2]
    }),
    V::real_calculated_parameter("ki_surge", None, "Ki surge [N/(m s)]", |m| {
        m.ctrl.gains().2[0]
    }),
    V::real_calculated_parameter("ki_sway", None, "Ki sway [N/(m s)]", |m| {
        m.ctrl.gains().2[1]
    }),
    V::real_calculated_parameter("ki_yaw", None, "Ki yaw [N m/(rad s)]", |m| {
        m.ctrl.gains().2[2]
    }),
];

impl FmuModel for DpControllerFmu {
    const MODEL_IDENTIFIER: &'static str = "DpController";
    const DESCRIPTION: &'static str =
        "Dynamic-positioning PID on the observer's LF estimates in the \
        body frame, gains from the desired bandwidth, with the open-loop test input of Fossen & \
        Strand (1999) Eq. 61";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 1000.0,
        step_size: 1.0,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.ctrl = DpController::new(self.params.clone(), quantise_time(start_time))
            .map_err(|e| e.to_string())?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.ctrl
            .set_params(self.params.clone())
            .map_err(|e| e.to_string())
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.ctrl.step(&self.inputs, h);
        self.ctrl.set_time(quantise_time(t + h));
        Ok(())
    }
}

export_fmu!(DpControllerFmu);
