//! `PathController` FMU: the LQ path controller of [Parsons1980, sec. 3] in
//! `models::controllers::path` (gain design from the design depth and disturbance model, gain
//! scheduling over depth, partial adaptation from a parameter estimator, dither) as an FMI 2.0
//! co-simulation FMU. No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::FmuModel;
use models::controllers::path::{
    path_gains, Adaptation, DisturbanceModel, PathController, PathControllerParams, PathGains,
    PathInputs, EPSILON,
};
use models::memo::{Bits, Memo};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one path-controller instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PathControllerFmu {
    params: PathControllerParams,
    /// Steering time constant [s] (T_r = 10 s full scale); T_r′ = T·U/L.
    steering_time_constant: f64,
    /// 1: first-order shaping filter [Parsons1980, Table 4]; 2: random walk [Parsons1980, Tables 5, 6, 8].
    disturbance_model: i32,
    epsilon: f64,
    /// Shaping-filter time constant T_N = T_Y [ship lengths].
    shaping_time_constant: f64,
    inputs: PathInputs,
    controller: PathController,
    /// The gains of the last initial design (an importer reads outputs in Initialization Mode
    /// after each input it sets, and each read initializes again: the two Riccati solutions are
    /// kept while the design does not change; derived, see `models::memo`).
    #[serde(skip)]
    gains: Memo<Bits<22>, PathGains>,
}

impl PathControllerFmu {
    /// A controller for `params`, its initial gains from `memo` when the design is unchanged.
    fn build(
        params: PathControllerParams,
        memo: &mut Memo<Bits<22>, PathGains>,
    ) -> Result<PathController, String> {
        PathController::new_with(params, |d| memo.try_get(d.key(), || path_gains(d)).copied())
            .map_err(|e| e.to_string())
    }
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
        let mut gains = Memo::default();
        PathControllerFmu {
            steering_time_constant: params.design.t_r * params.length / params.speed,
            disturbance_model: 2,
            epsilon: EPSILON,
            shaping_time_constant: 1.0,
            inputs: PathInputs {
                depth_ratio: params.design_depth_ratio,
                ..PathInputs::default()
            },
            controller: Self::build(params, &mut gains).expect("default design solves"),
            gains,
            params,
        }
    }
}

fmi2_export::fmu! {
    PathControllerFmu => "PathController",
    description: "LQ path controller of the Tokyo Maru in restricted water \
        (Parsons & Cuong 1980): steady-state LQ gains from the design depth and disturbance \
        model, gain scheduling over depth, partial adaptation of f23/f25, open-loop dither",
    experiment: (0.0, 940.0, 0.2349),
    documentation: "documentation.html",
    variables: {
        // ---- design (0..13)
        tunable real "design_depth_ratio" (params.design_depth_ratio).min(1.0),
            "Depth ratio H/T of the initial design (Table 2 interpolated; 1.89 in the report; 1e300 for deep water)";
        tunable int(1, 2) "disturbance_model" (disturbance_model),
            "Design model of N', Y': 1 first-order shaping filter (eqs. 39-41, Table 4), 2 random walk (eqs. 56-59, Tables 5/6/8)";
        tunable real "epsilon" (epsilon).min(0.0),
            "Random-walk regulariser epsilon on F_e(6,6), F_e(7,7) ([Parsons1980, sec. 3.3]: 1e-4)";
        tunable real "shaping_time_constant" (shaping_time_constant).min(0.0),
            "Shaping-filter time constant T_N = T_Y in ship lengths (eqs. 39-40: 1)";
        tunable real "steering_time_constant" ["s"] (steering_time_constant).min(0.0),
            "Steering-gear time constant of the design model ([Parsons1980, eq. (10)]; not printed there, 10 s derived from [Parsons1980, Table 4])";
        tunable real "a44" (params.design.a44).min(0.0),
            "Weight on eta'^2 = (eta'_0)^-2 (eq. 31: 772.463, eta_0 = 10.43 m)";
        tunable real "a55" (params.design.a55).min(0.0),
            "Weight on delta'^2 = (delta'_0)^-2 (eq. 32: 131.332, 5 deg)";
        tunable real "b11" (params.design.b11).min(0.0),
            "Weight on delta'_c^2 (eq. 33: 131.332, 5 deg)";
        tunable real "q_n" (params.design.q[0]).min(0.0),
            "Process-noise PSD of N' (random walk eq. 67: 2e-8; shaping filter eq. 53: 1.548e-8)";
        tunable real "q_y" (params.design.q[1]).min(0.0),
            "Process-noise PSD of Y' (random walk eq. 68: 1.25e-7; shaping filter eq. 54: 8.970e-8)";
        tunable real "r_heading" (params.design.r[0]).min(0.0),
            "Measurement-noise PSD r_jj of psi' for the Kalman gain output (Table 3: 1.298e-8)";
        tunable real "r_yaw_rate" (params.design.r[1]).min(0.0),
            "Measurement-noise PSD r_jj of r' (Table 3: 2.860e-7)";
        tunable real "r_cross_track" (params.design.r[2]).min(0.0),
            "Measurement-noise PSD r_jj of eta' (Table 3: 4.559e-7)";
        fixed real "ship_length" ["m"] (params.length).min(0.0),
            "Ship length L of the prime system (Tokyo Maru 290 m)";
        // ---- adaptation and dither (14..23)
        fixed real "ship_speed" ["m/s"] (params.speed).min(0.0),
            "Ship speed U of the prime system (12 kn = 6.1733 m/s)";
        fixed int "adaptation" (params.adaptation => { 0: Adaptation::Fixed, 1: Adaptation::Scheduled, 2: Adaptation::Estimated }),
            "0 fixed design; 1 gain scheduling on the measured depth_ratio input; 2 partial adaptation from the estimator inputs at the end of each dither window (Table 10 rule)";
        tunable real "update_interval" (params.update_interval).min(0.0),
            "Gain-scheduling clock in ship lengths (t' = tU/L)";
        tunable real "schedule_tolerance" (params.schedule_tolerance).min(0.0),
            "Re-design when the measured T/H moved by more than this since the current design";
        fixed bool "dither_enabled" (params.dither.enabled),
            "Open-loop dither windows with the control loop off ([Parsons1980, secs. 4-5])";
        fixed real "dither_amplitude" ["rad"] (params.dither.amplitude),
            "Square-wave rudder command amplitude (0.5 rad)";
        fixed real "dither_period" (params.dither.period).min(0.0),
            "Square-wave period in ship lengths (0.5; 1.0, 2.5, 5.0 also used)";
        fixed real "dither_window" (params.dither.window).min(0.0),
            "Dither window length LW in ship lengths (2.5)";
        fixed real "dither_cycle" (params.dither.cycle).min(0.0),
            "Cycle length in ship lengths: a window at the start of each cycle (MVE schedule 6.25)";
        fixed real "dither_start" (params.dither.start),
            "Start of the first window in ship lengths after the start time";
        // ---- inputs (24..38)
        input real "heading" ["rad"] (inputs.heading),
            "Estimated heading psi relative to the track direction";
        input real "yaw_rate" ["rad/s"] (inputs.yaw_rate), "Estimated yaw rate r";
        input real "drift_angle" ["rad"] (inputs.drift_angle),
            "Estimated drift angle beta (v = -U beta)";
        input real "cross_track" ["m"] (inputs.cross_track),
            "Estimated lateral offset eta from the track";
        input real "rudder_angle" ["rad"] (inputs.rudder),
            "Actual rudder angle delta (known exactly in [Parsons1980])";
        input real "yaw_moment_prime" (inputs.yaw_moment_prime),
            "Estimated external yaw moment N' = 2N/(rho L^3 U^2)";
        input real "sway_force_prime" (inputs.sway_force_prime),
            "Estimated external sway force Y' = 2Y/(rho L^2 U^2)";
        input real "depth_ratio" (inputs.depth_ratio),
            "Measured depth ratio H/T for gain scheduling (adaptation = 1)";
        input real "f22_estimate" (inputs.estimates[0]), "Estimator output f22 (adaptation = 2)";
        input real "f23_estimate" (inputs.estimates[1]),
            "Estimator output f23 (adaptation = 2; no update unless in [2.10, 12.00], Table 10)";
        input real "f25_estimate" (inputs.estimates[2]),
            "Estimator output f25 (adaptation = 2; no update unless in [-1.30, -0.30], Table 10)";
        input real "f32_estimate" (inputs.estimates[3]), "Estimator output f32 (adaptation = 2)";
        input real "f33_estimate" (inputs.estimates[4]), "Estimator output f33 (adaptation = 2)";
        input real "f35_estimate" (inputs.estimates[5]), "Estimator output f35 (adaptation = 2)";
        // ---- outputs (38..49)
        output real "rudder_command" ["rad"] (|m| m.controller.command(&m.inputs)),
            "Rudder command delta_c = C x' (control loop) or the dither square wave";
        output bool "dithering" (|m| m.controller.dithering()),
            "Inside a dither window (control loop off)";
        output real "gain_heading" (|m| m.controller.gains().c[0]), "c11: gain on psi' [rad/rad]";
        output real "gain_yaw_rate" (|m| m.controller.gains().c[1]), "c12: gain on r' = rL/U";
        output real "gain_drift_angle" (|m| m.controller.gains().c[2]), "c13: gain on beta'";
        output real "gain_cross_track" (|m| m.controller.gains().c[3]),
            "c14: gain on eta' = eta/L (sqrt(a44/b11) = 2.4252)";
        output real "gain_rudder" (|m| m.controller.gains().c[4]), "c15: gain on delta'";
        output real "gain_yaw_moment" (|m| m.controller.gains().c[5]), "c16: feedforward gain on N'";
        output real "gain_sway_force" (|m| m.controller.gains().c[6]), "c17: feedforward gain on Y'";
        output real "design_f23" (|m| m.controller.coefficients().f23), "f23 of the current design";
        output real "design_f25" (|m| m.controller.coefficients().f25), "f25 of the current design";
        output real "gain_updates" (|m| m.controller.updates() as f64),
            "Number of gain re-designs since the start";
        // ---- the rest of the current design (appended: earlier value references unchanged), for
        // the PathKalmanFilter's f*_design inputs ([Parsons1980, Fig. 1]: C, K and the filter model together)
        output real "design_f22" (|m| m.controller.coefficients().f22), "f22 of the current design";
        output real "design_f32" (|m| m.controller.coefficients().f32), "f32 of the current design";
        output real "design_f33" (|m| m.controller.coefficients().f33), "f33 of the current design";
        output real "design_f35" (|m| m.controller.coefficients().f35), "f35 of the current design";
    }
}

impl FmuModel for PathControllerFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.controller = Self::build(self.model_params(), &mut self.gains)?;
        self.controller.start(&self.inputs);
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.controller
            .set_params(self.model_params())
            .map_err(|e| e.to_string())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.controller
            .step(&self.inputs, h)
            .map_err(|e| e.to_string())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        self.controller.internal_steps(h, each);
    }
}
