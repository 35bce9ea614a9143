//! `PassiveObserver` FMU: Fossen & Strand's nonlinear passive DP observer with wave filtering and
//! bias estimation (`models::observers::passive_observer`). No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::observers::passive_observer::{Injection, PassiveObserver, PassiveObserverParams};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and observer of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PassiveObserverFmu {
    params: PassiveObserverParams,
    eta0: [f64; 3],
    y: [f64; 3],
    tau: [f64; 3],
    obs: PassiveObserver,
}

impl Default for PassiveObserverFmu {
    fn default() -> Self {
        let params = PassiveObserverParams::northern_clipper();
        PassiveObserverFmu {
            obs: PassiveObserver::new(params.clone(), [0.0; 3]).expect("preset"),
            params,
            eta0: [0.0; 3],
            y: [0.0; 3],
            tau: [0.0; 3],
        }
    }
}

type V = Variable<PassiveObserverFmu>;

static VARIABLES: [V; 58] = [
    V::real_parameter(
        "mass_surge",
        Some("kg"),
        false,
        "M11 of the observer model (Northern Clipper eq. 56; SI)",
        |m| m.params.m[0][0],
        |m, v| m.params.m[0][0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "mass_sway",
        Some("kg"),
        false,
        "M22 of the observer model (Northern Clipper eq. 56; SI)",
        |m| m.params.m[1][1],
        |m, v| m.params.m[1][1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "inertia_yaw",
        None,
        false,
        "M33 of the observer model (Northern Clipper eq. 56; SI)",
        |m| m.params.m[2][2],
        |m, v| m.params.m[2][2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "damping_surge",
        None,
        false,
        "D11 of the observer model (eq. 57; SI)",
        |m| m.params.d[0][0],
        |m, v| m.params.d[0][0] = v,
    ),
    V::real_parameter(
        "damping_sway",
        None,
        false,
        "D22 of the observer model (eq. 57; SI)",
        |m| m.params.d[1][1],
        |m, v| m.params.d[1][1] = v,
    ),
    V::real_parameter(
        "damping_sway_yaw",
        None,
        false,
        "D23 of the observer model (eq. 57; SI)",
        |m| m.params.d[1][2],
        |m, v| m.params.d[1][2] = v,
    ),
    V::real_parameter(
        "damping_yaw_sway",
        None,
        false,
        "D32 of the observer model (eq. 57; SI)",
        |m| m.params.d[2][1],
        |m, v| m.params.d[2][1] = v,
    ),
    V::real_parameter(
        "damping_yaw",
        None,
        false,
        "D33 of the observer model (eq. 57; SI)",
        |m| m.params.d[2][2],
        |m, v| m.params.d[2][2] = v,
    ),
    V::real_parameter(
        "bias_time_constant_surge",
        Some("s"),
        true,
        "Bias time constant T (surge; eq. 58: 1000 s)",
        |m| m.params.t_bias[0],
        |m, v| m.params.t_bias[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "bias_time_constant_sway",
        Some("s"),
        true,
        "Bias time constant T (sway; eq. 58: 1000 s)",
        |m| m.params.t_bias[1],
        |m, v| m.params.t_bias[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "bias_time_constant_yaw",
        Some("s"),
        true,
        "Bias time constant T (yaw; eq. 58: 1000 s)",
        |m| m.params.t_bias[2],
        |m, v| m.params.t_bias[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "wave_frequency_surge",
        Some("rad/s"),
        true,
        "Dominant wave (encounter) frequency omega0 (surge; 0.8976 rad/s = 7 s); tunable for gain scheduling (Remark 2)",
        |m| m.params.omega0[0],
        |m, v| m.params.omega0[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "wave_frequency_sway",
        Some("rad/s"),
        true,
        "Dominant wave (encounter) frequency omega0 (sway; 0.8976 rad/s = 7 s); tunable for gain scheduling (Remark 2)",
        |m| m.params.omega0[1],
        |m, v| m.params.omega0[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "wave_frequency_yaw",
        Some("rad/s"),
        true,
        "Dominant wave (encounter) frequency omega0 (yaw; 0.8976 rad/s = 7 s); tunable for gain scheduling (Remark 2)",
        |m| m.params.omega0[2],
        |m, v| m.params.omega0[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "wave_damping_surge",
        None,
        true,
        "Relative damping zeta of the WF model (surge; 0.1)",
        |m| m.params.zeta[0],
        |m, v| m.params.zeta[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "wave_damping_sway",
        None,
        true,
        "Relative damping zeta of the WF model (sway; 0.1)",
        |m| m.params.zeta[1],
        |m, v| m.params.zeta[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "wave_damping_yaw",
        None,
        true,
        "Relative damping zeta of the WF model (yaw; 0.1)",
        |m| m.params.zeta[2],
        |m, v| m.params.zeta[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "notch_damping_surge",
        None,
        true,
        "Notch damping zeta_n (surge; 1.0)",
        |m| m.params.zeta_n[0],
        |m, v| m.params.zeta_n[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "notch_damping_sway",
        None,
        true,
        "Notch damping zeta_n (sway; 1.0)",
        |m| m.params.zeta_n[1],
        |m, v| m.params.zeta_n[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "notch_damping_yaw",
        None,
        true,
        "Notch damping zeta_n (yaw; 1.0)",
        |m| m.params.zeta_n[2],
        |m, v| m.params.zeta_n[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "cutoff_frequency_surge",
        Some("rad/s"),
        true,
        "Filter cut-off omega_c (surge; 1.1 rad/s); K2 = omega_c",
        |m| m.params.omega_c[0],
        |m, v| m.params.omega_c[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "cutoff_frequency_sway",
        Some("rad/s"),
        true,
        "Filter cut-off omega_c (sway; 1.1 rad/s); K2 = omega_c",
        |m| m.params.omega_c[1],
        |m, v| m.params.omega_c[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "cutoff_frequency_yaw",
        Some("rad/s"),
        true,
        "Filter cut-off omega_c (yaw; 1.1 rad/s); K2 = omega_c",
        |m| m.params.omega_c[2],
        |m, v| m.params.omega_c[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "kappa_surge",
        None,
        true,
        "Velocity injection gain kappa (surge; 0.1, 0.1, 0.01)",
        |m| m.params.kappa[0],
        |m, v| m.params.kappa[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "kappa_sway",
        None,
        true,
        "Velocity injection gain kappa (sway; 0.1, 0.1, 0.01)",
        |m| m.params.kappa[1],
        |m, v| m.params.kappa[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "kappa_yaw",
        None,
        true,
        "Velocity injection gain kappa (yaw; 0.1, 0.1, 0.01)",
        |m| m.params.kappa[2],
        |m, v| m.params.kappa[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "lambda_surge",
        None,
        true,
        "Bias injection gain lambda (surge; Lambda = 0.1 K: 0.01, 0.01, 0.001)",
        |m| m.params.lambda[0],
        |m, v| m.params.lambda[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "lambda_sway",
        None,
        true,
        "Bias injection gain lambda (sway; Lambda = 0.1 K: 0.01, 0.01, 0.001)",
        |m| m.params.lambda[1],
        |m, v| m.params.lambda[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "lambda_yaw",
        None,
        true,
        "Bias injection gain lambda (yaw; Lambda = 0.1 K: 0.01, 0.01, 0.001)",
        |m| m.params.lambda[2],
        |m, v| m.params.lambda[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "gamma",
        None,
        true,
        "Lyapunov scaling gamma (1)",
        |m| m.params.gamma,
        |m, v| m.params.gamma = v,
    )
    .with_range(Some(0.0), None),
    V::integer_parameter(
        "injection",
        true,
        "1: eq. 25 literally with SI M, D (bias in N, N.m; the paper's gains then give almost no velocity/bias injection); 2: injection as an acceleration, bias state in m/s2 (normalised-model reading, default)",
        1,
        2,
        |m| match m.params.injection {
            Injection::Literal => 1,
            Injection::MassNormalised => 2,
        },
        |m, v| {
            m.params.injection = if v == 1 {
                Injection::Literal
            } else {
                Injection::MassNormalised
            }
        },
    ),
    V::real_parameter(
        "max_substep",
        Some("s"),
        false,
        "Largest RK4 sub-step",
        |m| m.params.max_substep,
        |m, v| m.params.max_substep = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "initial_north",
        Some("m"),
        false,
        "Initial LF position/heading estimate",
        |m| m.eta0[0],
        |m, v| m.eta0[0] = v,
    ),
    V::real_parameter(
        "initial_east",
        Some("m"),
        false,
        "Initial LF position/heading estimate",
        |m| m.eta0[1],
        |m, v| m.eta0[1] = v,
    ),
    V::real_parameter(
        "initial_heading",
        Some("rad"),
        false,
        "Initial LF position/heading estimate",
        |m| m.eta0[2],
        |m, v| m.eta0[2] = v,
    ),
    V::real_input(
        "north_measured",
        Some("m"),
        "Measured north position y1 = x + WF motion (DGPS)",
        |m| m.y[0],
        |m, v| m.y[0] = v,
    ),
    V::real_input(
        "east_measured",
        Some("m"),
        "Measured east position y2",
        |m| m.y[1],
        |m, v| m.y[1] = v,
    ),
    V::real_input(
        "heading_measured",
        Some("rad"),
        "Measured heading y3 (gyrocompass)",
        |m| m.y[2],
        |m, v| m.y[2] = v,
    ),
    V::real_input(
        "tau_surge",
        Some("N"),
        "Commanded thrust surge (body frame)",
        |m| m.tau[0],
        |m, v| m.tau[0] = v,
    ),
    V::real_input(
        "tau_sway",
        Some("N"),
        "Commanded thrust sway (body frame)",
        |m| m.tau[1],
        |m, v| m.tau[1] = v,
    ),
    V::real_input(
        "tau_yaw",
        Some("N.m"),
        "Commanded thrust yaw (body frame)",
        |m| m.tau[2],
        |m, v| m.tau[2] = v,
    ),
    V::real_output(
        "north_estimate",
        Some("m"),
        "LF estimate eta_hat (wave-frequency motion removed)",
        |m| m.obs.eta()[0],
    ),
    V::real_output(
        "east_estimate",
        Some("m"),
        "LF estimate eta_hat (wave-frequency motion removed)",
        |m| m.obs.eta()[1],
    ),
    V::real_output(
        "heading_estimate",
        Some("rad"),
        "LF estimate eta_hat (wave-frequency motion removed)",
        |m| m.obs.eta()[2],
    ),
    V::real_output(
        "surge_velocity_estimate",
        Some("m/s"),
        "LF velocity estimate nu_hat (body)",
        |m| m.obs.nu()[0],
    ),
    V::real_output(
        "sway_velocity_estimate",
        Some("m/s"),
        "LF velocity estimate nu_hat (body)",
        |m| m.obs.nu()[1],
    ),
    V::real_output(
        "yaw_rate_estimate",
        Some("rad/s"),
        "LF velocity estimate nu_hat (body)",
        |m| m.obs.nu()[2],
    ),
    V::real_output(
        "north_wf_estimate",
        Some("m"),
        "Wave-frequency motion estimate eta_w_hat = xi2_hat",
        |m| m.obs.eta_w()[0],
    ),
    V::real_output(
        "east_wf_estimate",
        Some("m"),
        "Wave-frequency motion estimate eta_w_hat = xi2_hat",
        |m| m.obs.eta_w()[1],
    ),
    V::real_output(
        "heading_wf_estimate",
        Some("rad"),
        "Wave-frequency motion estimate eta_w_hat = xi2_hat",
        |m| m.obs.eta_w()[2],
    ),
    V::real_output(
        "bias_north_estimate",
        Some("N"),
        "Earth-fixed bias force estimate (J M J^T b_hat when mass-normalised)",
        |m| m.obs.bias_force()[0],
    ),
    V::real_output(
        "bias_east_estimate",
        Some("N"),
        "Earth-fixed bias force estimate (J M J^T b_hat when mass-normalised)",
        |m| m.obs.bias_force()[1],
    ),
    V::real_output(
        "bias_yaw_estimate",
        Some("N.m"),
        "Earth-fixed bias force estimate (J M J^T b_hat when mass-normalised)",
        |m| m.obs.bias_force()[2],
    ),
    V::real_output(
        "innovation_north",
        Some("m"),
        "Innovation y - y_hat",
        |m| m.obs.innovation()[0],
    ),
    V::real_output(
        "innovation_east",
        Some("m"),
        "Innovation y - y_hat",
        |m| m.obs.innovation()[1],
    ),
    V::real_output(
        "innovation_heading",
        Some("rad"),
        "Innovation y - y_hat",
        |m| m.obs.innovation()[2],
    ),
    V::real_output(
        "k1_surge",
        None,
        "Notch gain k1 = -2 (zeta_n - zeta) omega_c / omega0 (eq. 45; -2.2059 for the paper's set)",
        |m| m.obs.gains().0[0],
    ),
    V::real_output(
        "k2_surge",
        Some("rad/s"),
        "Notch gain k2 = 2 omega0 (zeta_n - zeta) (eq. 46; 1.6157)",
        |m| m.obs.gains().1[0],
    ),
];

impl FmuModel for PassiveObserverFmu {
    const MODEL_IDENTIFIER: &'static str = "PassiveObserver";
    const DESCRIPTION: &'static str = "Nonlinear passive observer for dynamic positioning with \
        wave filtering and bias estimation (Fossen & Strand 1999), Northern Clipper preset";
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

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.obs = PassiveObserver::new(self.params.clone(), self.eta0)?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.obs.set_params(self.params.clone())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.obs.step(self.y, self.tau, h);
        Ok(())
    }
}

export_fmu!(PassiveObserverFmu);
