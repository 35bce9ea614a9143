//! `PathController` FMU: the Parsons & Cuong (1980, source 004) LQ path controller of
//! `models::controllers::path` (gain design from the design depth and disturbance model, gain
//! scheduling over depth, partial adaptation from a parameter estimator, dither) as an FMI 2.0
//! co-simulation FMU. No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::controllers::path::{
    Adaptation, DisturbanceModel, PathController, PathControllerParams, PathInputs, EPSILON,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one path-controller instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PathControllerFmu {
    params: PathControllerParams,
    /// Steering time constant [s] (T_r = 10 s full scale); T_r′ = T·U/L.
    steering_time_constant: f64,
    /// 1: first-order shaping filter (Table 4); 2: random walk (Tables 5, 6, 8).
    disturbance_model: i32,
    epsilon: f64,
    /// Shaping-filter time constant T_N = T_Y [ship lengths].
    shaping_time_constant: f64,
    inputs: PathInputs,
    ctl: PathController,
}

impl PathControllerFmu {
    /// The model parameters with the FMU's SI / selector parameters folded in.
    fn model_params(&self) -> PathControllerParams {
        let mut p = self.params;
        p.design.t_r = self.steering_time_constant * p.speed / p.length;
        p.design.disturbance = if self.disturbance_model == 1 {
            DisturbanceModel::ShapingFilter {
                t_n: self.shaping_time_constant,
                t_y: self.shaping_time_constant,
            }
        } else {
            DisturbanceModel::RandomWalk {
                epsilon: self.epsilon,
            }
        };
        p
    }
}

impl Default for PathControllerFmu {
    fn default() -> Self {
        let params = PathControllerParams::default();
        PathControllerFmu {
            steering_time_constant: params.design.t_r * params.length / params.speed,
            disturbance_model: 2,
            epsilon: EPSILON,
            shaping_time_constant: 1.0,
            inputs: PathInputs {
                depth_ratio: params.design_depth_ratio,
                ..PathInputs::default()
            },
            ctl: PathController::new(params).expect("default design solves"),
            params,
        }
    }
}

type V = Variable<PathControllerFmu>;

fn adaptation_code(a: Adaptation) -> i32 {
    match a {
        Adaptation::Fixed => 0,
        Adaptation::Scheduled => 1,
        Adaptation::Estimated => 2,
    }
}

static VARIABLES: [V; 54] = [
    // ---- design (0..13)
    V::real_parameter(
        "design_depth_ratio",
        None,
        true,
        "Depth ratio H/T of the initial design (Table 2 interpolated; 1.89 in the report; 1e300 for deep water)",
        |m| m.params.design_depth_ratio,
        |m, v| m.params.design_depth_ratio = v,
    )
    .with_range(Some(1.0), None),
    V::integer_parameter(
        "disturbance_model",
        true,
        "Design model of N', Y': 1 first-order shaping filter (eqs. 39-41, Table 4), 2 random walk (eqs. 56-59, Tables 5/6/8)",
        1,
        2,
        |m| m.disturbance_model,
        |m, v| m.disturbance_model = v,
    ),
    V::real_parameter(
        "epsilon",
        None,
        true,
        "Random-walk regulariser epsilon on F_e(6,6), F_e(7,7) (line 768: 1e-4)",
        |m| m.epsilon,
        |m, v| m.epsilon = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "shaping_time_constant",
        None,
        true,
        "Shaping-filter time constant T_N = T_Y in ship lengths (eqs. 39-40: 1)",
        |m| m.shaping_time_constant,
        |m, v| m.shaping_time_constant = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "steering_time_constant",
        Some("s"),
        true,
        "Steering-gear time constant of the design model (eq. 10; not printed in 004, 10 s derived from Table 4)",
        |m| m.steering_time_constant,
        |m, v| m.steering_time_constant = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "a44",
        None,
        true,
        "Weight on eta'^2 = (eta'_0)^-2 (eq. 31: 772.463, eta_0 = 10.43 m)",
        |m| m.params.design.a44,
        |m, v| m.params.design.a44 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "a55",
        None,
        true,
        "Weight on delta'^2 = (delta'_0)^-2 (eq. 32: 131.332, 5 deg)",
        |m| m.params.design.a55,
        |m, v| m.params.design.a55 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "b11",
        None,
        true,
        "Weight on delta'_c^2 (eq. 33: 131.332, 5 deg)",
        |m| m.params.design.b11,
        |m, v| m.params.design.b11 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "q_n",
        None,
        true,
        "Process-noise PSD of N' (random walk eq. 67: 2e-8; shaping filter eq. 53: 1.548e-8)",
        |m| m.params.design.q[0],
        |m, v| m.params.design.q[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "q_y",
        None,
        true,
        "Process-noise PSD of Y' (random walk eq. 68: 1.25e-7; shaping filter eq. 54: 8.970e-8)",
        |m| m.params.design.q[1],
        |m, v| m.params.design.q[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "r_heading",
        None,
        true,
        "Measurement-noise PSD r_jj of psi' for the Kalman gain output (Table 3: 1.298e-8)",
        |m| m.params.design.r[0],
        |m, v| m.params.design.r[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "r_yaw_rate",
        None,
        true,
        "Measurement-noise PSD r_jj of r' (Table 3: 2.860e-7)",
        |m| m.params.design.r[1],
        |m, v| m.params.design.r[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "r_cross_track",
        None,
        true,
        "Measurement-noise PSD r_jj of eta' (Table 3: 4.559e-7)",
        |m| m.params.design.r[2],
        |m, v| m.params.design.r[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "ship_length",
        Some("m"),
        false,
        "Ship length L of the prime system (Tokyo Maru 290 m)",
        |m| m.params.length,
        |m, v| m.params.length = v,
    )
    .with_range(Some(0.0), None),
    // ---- adaptation and dither (14..23)
    V::real_parameter(
        "ship_speed",
        Some("m/s"),
        false,
        "Ship speed U of the prime system (12 kn = 6.1733 m/s)",
        |m| m.params.speed,
        |m, v| m.params.speed = v,
    )
    .with_range(Some(0.0), None),
    V::integer_parameter(
        "adaptation",
        false,
        "0 fixed design; 1 gain scheduling on the measured depth_ratio input; 2 partial adaptation from the estimator inputs at the end of each dither window (Table 10 rule)",
        0,
        2,
        |m| adaptation_code(m.params.adaptation),
        |m, v| {
            m.params.adaptation = match v {
                1 => Adaptation::Scheduled,
                2 => Adaptation::Estimated,
                _ => Adaptation::Fixed,
            }
        },
    ),
    V::real_parameter(
        "update_interval",
        None,
        true,
        "Gain-scheduling clock in ship lengths (t' = tU/L)",
        |m| m.params.update_interval,
        |m, v| m.params.update_interval = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "schedule_tolerance",
        None,
        true,
        "Re-design when the measured T/H moved by more than this since the current design",
        |m| m.params.schedule_tolerance,
        |m, v| m.params.schedule_tolerance = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "dither_enabled",
        false,
        "Open-loop dither windows with the control loop off (section 4-5 of 004)",
        |m| m.params.dither.enabled,
        |m, v| m.params.dither.enabled = v,
    ),
    V::real_parameter(
        "dither_amplitude",
        Some("rad"),
        false,
        "Square-wave rudder command amplitude (0.5 rad)",
        |m| m.params.dither.amplitude,
        |m, v| m.params.dither.amplitude = v,
    ),
    V::real_parameter(
        "dither_period",
        None,
        false,
        "Square-wave period in ship lengths (0.5; 1.0, 2.5, 5.0 also used)",
        |m| m.params.dither.period,
        |m, v| m.params.dither.period = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "dither_window",
        None,
        false,
        "Dither window length LW in ship lengths (2.5)",
        |m| m.params.dither.window,
        |m, v| m.params.dither.window = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "dither_cycle",
        None,
        false,
        "Cycle length in ship lengths: a window at the start of each cycle (MVE schedule 6.25)",
        |m| m.params.dither.cycle,
        |m, v| m.params.dither.cycle = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "dither_start",
        None,
        false,
        "Start of the first window in ship lengths after the start time",
        |m| m.params.dither.start,
        |m, v| m.params.dither.start = v,
    ),
    // ---- inputs (24..38)
    V::real_input(
        "heading",
        Some("rad"),
        "Estimated heading psi relative to the track direction",
        |m| m.inputs.heading,
        |m, v| m.inputs.heading = v,
    ),
    V::real_input(
        "yaw_rate",
        Some("rad/s"),
        "Estimated yaw rate r",
        |m| m.inputs.yaw_rate,
        |m, v| m.inputs.yaw_rate = v,
    ),
    V::real_input(
        "drift_angle",
        Some("rad"),
        "Estimated drift angle beta (v = -U beta)",
        |m| m.inputs.drift_angle,
        |m, v| m.inputs.drift_angle = v,
    ),
    V::real_input(
        "cross_track",
        Some("m"),
        "Estimated lateral offset eta from the track",
        |m| m.inputs.cross_track,
        |m, v| m.inputs.cross_track = v,
    ),
    V::real_input(
        "rudder_angle",
        Some("rad"),
        "Actual rudder angle delta (known exactly in 004)",
        |m| m.inputs.rudder,
        |m, v| m.inputs.rudder = v,
    ),
    V::real_input(
        "yaw_moment_prime",
        None,
        "Estimated external yaw moment N' = 2N/(rho L^3 U^2)",
        |m| m.inputs.yaw_moment_prime,
        |m, v| m.inputs.yaw_moment_prime = v,
    ),
    V::real_input(
        "sway_force_prime",
        None,
        "Estimated external sway force Y' = 2Y/(rho L^2 U^2)",
        |m| m.inputs.sway_force_prime,
        |m, v| m.inputs.sway_force_prime = v,
    ),
    V::real_input(
        "depth_ratio",
        None,
        "Measured depth ratio H/T for gain scheduling (adaptation = 1)",
        |m| m.inputs.depth_ratio,
        |m, v| m.inputs.depth_ratio = v,
    ),
    V::real_input(
        "f22_estimate",
        None,
        "Estimator output f22 (adaptation = 2)",
        |m| m.inputs.estimates[0],
        |m, v| m.inputs.estimates[0] = v,
    ),
    V::real_input(
        "f23_estimate",
        None,
        "Estimator output f23 (adaptation = 2; no update unless in [2.10, 12.00], Table 10)",
        |m| m.inputs.estimates[1],
        |m, v| m.inputs.estimates[1] = v,
    ),
    V::real_input(
        "f25_estimate",
        None,
        "Estimator output f25 (adaptation = 2; no update unless in [-1.30, -0.30], Table 10)",
        |m| m.inputs.estimates[2],
        |m, v| m.inputs.estimates[2] = v,
    ),
    V::real_input(
        "f32_estimate",
        None,
        "Estimator output f32 (adaptation = 2)",
        |m| m.inputs.estimates[3],
        |m, v| m.inputs.estimates[3] = v,
    ),
    V::real_input(
        "f33_estimate",
        None,
        "Estimator output f33 (adaptation = 2)",
        |m| m.inputs.estimates[4],
        |m, v| m.inputs.estimates[4] = v,
    ),
    V::real_input(
        "f35_estimate",
        None,
        "Estimator output f35 (adaptation = 2)",
        |m| m.inputs.estimates[5],
        |m, v| m.inputs.estimates[5] = v,
    ),
    // ---- outputs (38..49)
    V::real_output(
        "rudder_command",
        Some("rad"),
        "Rudder command delta_c = C x' (control loop) or the dither square wave",
        |m| m.ctl.command(&m.inputs),
    ),
    V::boolean_output(
        "dithering",
        "Inside a dither window (control loop off)",
        |m| m.ctl.dithering(),
    ),
    V::real_output(
        "gain_heading",
        None,
        "c11: gain on psi' [rad/rad]",
        |m| m.ctl.gains().c[0],
    ),
    V::real_output(
        "gain_yaw_rate",
        None,
        "c12: gain on r' = rL/U",
        |m| m.ctl.gains().c[1],
    ),
    V::real_output(
        "gain_drift_angle",
        None,
        "c13: gain on beta'",
        |m| m.ctl.gains().c[2],
    ),
    V::real_output(
        "gain_cross_track",
        None,
        "c14: gain on eta' = eta/L (sqrt(a44/b11) = 2.4252)",
        |m| m.ctl.gains().c[3],
    ),
    V::real_output(
        "gain_rudder",
        None,
        "c15: gain on delta'",
        |m| m.ctl.gains().c[4],
    ),
    V::real_output(
        "gain_yaw_moment",
        None,
        "c16: feedforward gain on N'",
        |m| m.ctl.gains().c[5],
    ),
    V::real_output(
        "gain_sway_force",
        None,
        "c17: feedforward gain on Y'",
        |m| m.ctl.gains().c[6],
    ),
    V::real_output(
        "design_f23",
        None,
        "f23 of the current design",
        |m| m.ctl.coefficients().f23,
    ),
    V::real_output(
        "design_f25",
        None,
        "f25 of the current design",
        |m| m.ctl.coefficients().f25,
    ),
    V::real_output(
        "gain_updates",
        None,
        "Number of gain re-designs since the start",
        |m| m.ctl.updates() as f64,
    ),
    // ---- the rest of the current design (appended: earlier value references unchanged), for
    // the PathKalmanFilter's f*_design inputs (004 Fig. 1: C, K and the filter model together)
    V::real_output(
        "design_f22",
        None,
        "f22 of the current design",
        |m| m.ctl.coefficients().f22,
    ),
    V::real_output(
        "design_f32",
        None,
        "f32 of the current design",
        |m| m.ctl.coefficients().f32,
    ),
    V::real_output(
        "design_f33",
        None,
        "f33 of the current design",
        |m| m.ctl.coefficients().f33,
    ),
    V::real_output(
        "design_f35",
        None,
        "f35 of the current design",
        |m| m.ctl.coefficients().f35,
    ),
];

impl FmuModel for PathControllerFmu {
    const MODEL_IDENTIFIER: &'static str = "PathController";
    const DESCRIPTION: &'static str = "LQ path controller of the Tokyo Maru in restricted water \
        (Parsons & Cuong 1980): steady-state LQ gains from the design depth and disturbance \
        model, gain scheduling over depth, partial adaptation of f23/f25, open-loop dither";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 940.0,
        step_size: 0.2349,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.ctl = PathController::new(self.model_params()).map_err(|e| e.to_string())?;
        self.ctl.start(&self.inputs);
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.ctl
            .set_params(self.model_params())
            .map_err(|e| e.to_string())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.ctl.step(&self.inputs, h).map_err(|e| e.to_string())
    }
}

export_fmu!(PathControllerFmu);
