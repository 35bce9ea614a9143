//! `PathKalmanFilter` FMU: the steady-state Kalman-Bucy filter of Parsons & Cuong (1980) on the
//! Tokyo Maru 7-state design model (`models::observers::path_kalman`). No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::hull::tokyo_maru::{TokyoMaruCoefficients, L, U};
use models::observers::path_kalman::{PathKalmanConfig, PathKalmanFilter};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and filter of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PathKalmanFilterFmu {
    config: PathKalmanConfig,
    /// Steering time constant [s] (T_r = time_constant·U/L).
    steering_time_constant: f64,
    euler_step_prime: f64,
    innovation_window: f64,
    /// Initial estimate, SI: ψ, r, β, η, δ, N′, Y′.
    x0: [f64; 7],
    /// Inputs: ψ, r, η measured; δ_c.
    z: [f64; 3],
    command: f64,
    /// Follow the design-coefficient inputs (the gain update of an adaptive loop).
    follow_design_inputs: bool,
    /// Inputs: f22, f23, f25, f32, f33, f35 of the design in use (from the PathController).
    design_inputs: [f64; 6],
    filter: PathKalmanFilter,
}

impl Default for PathKalmanFilterFmu {
    fn default() -> Self {
        let config = PathKalmanConfig::default();
        let design_inputs = coefficients_of(&config.design().expect("preset").coefficients);
        PathKalmanFilterFmu {
            filter: PathKalmanFilter::new(config.design().expect("preset"), [0.0; 7])
                .expect("preset design has a stabilising Riccati solution"),
            config,
            steering_time_constant: 10.0,
            euler_step_prime: 0.005,
            innovation_window: 1.0,
            x0: [0.0; 7],
            z: [0.0; 3],
            command: 0.0,
            follow_design_inputs: false,
            design_inputs,
        }
    }
}

/// f22, f23, f25, f32, f33, f35 of a coefficient set.
fn coefficients_of(c: &TokyoMaruCoefficients) -> [f64; 6] {
    [c.f22, c.f23, c.f25, c.f32, c.f33, c.f35]
}

impl PathKalmanFilterFmu {
    fn rebuild_config(&mut self) -> Result<(), String> {
        if !(self.steering_time_constant > 0.0) {
            return Err(format!(
                "steering_time_constant = {} must be > 0",
                self.steering_time_constant
            ));
        }
        if !(self.euler_step_prime > 0.0) {
            return Err(format!(
                "euler_step_prime = {} must be > 0",
                self.euler_step_prime
            ));
        }
        if !(self.innovation_window > 0.0) {
            return Err(format!(
                "innovation_window = {} must be > 0",
                self.innovation_window
            ));
        }
        self.config.t_r = self.steering_time_constant * U / L;
        Ok(())
    }

    fn x(&self, i: usize) -> f64 {
        self.filter.estimate()[i]
    }

    fn nu(&self, i: usize) -> f64 {
        self.filter.innovation()[i]
    }

    fn nu_rms(&self, i: usize) -> f64 {
        self.filter.innovation_mean_square()[i].sqrt()
    }
}

type V = Variable<PathKalmanFilterFmu>;

const UL: f64 = U / L;

static VARIABLES: [V; 53] = [
    V::real_parameter(
        "design_depth_ratio",
        None,
        true,
        "Design (assumed) water depth / draft H/T of the Table 2 coefficients in the filter model (004 Table 2; 1.89 = Table 5 design; a very large value gives deep water); changing it in step mode is a gain-update event",
        |m| m.config.design_depth_ratio,
        |m, v| m.config.design_depth_ratio = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "adapted_depth_ratio",
        None,
        true,
        "If > 0: f23 and f25 are taken at this H/T (004 Table 8 partial adaptation); 0: not used",
        |m| m.config.adapted_depth_ratio,
        |m, v| m.config.adapted_depth_ratio = v,
    ),
    V::integer_parameter(
        "disturbance_model",
        true,
        "N', Y' model in the filter: 1 first-order shaping filter (004 eqs. 39-41, Table 4); 2 random walk (eqs. 56-59, Tables 5, 6, 8)",
        1,
        2,
        |m| if m.config.random_walk { 2 } else { 1 },
        |m, v| m.config.random_walk = v == 2,
    ),
    V::real_parameter(
        "steering_time_constant",
        Some("s"),
        true,
        "Steering-gear time constant of eq. 10 (T_r' = T U/L; 10 s = 0.212874 is the value derived in the spec, the report does not print it)",
        |m| m.steering_time_constant,
        |m, v| m.steering_time_constant = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "shaping_time_constant",
        None,
        true,
        "Shaping-filter time constant T_N = T_Y in ship lengths (t' units) (004 eqs. 39-40)",
        |m| m.config.shaping_time_constant,
        |m, v| m.config.shaping_time_constant = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "epsilon",
        None,
        true,
        "Random-walk design regulariser: -epsilon on the N', Y' diagonal for the gain design only (004 line 768)",
        |m| m.config.epsilon,
        |m, v| m.config.epsilon = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "q_yaw_moment",
        None,
        true,
        "Intensity q11 of the N' driving noise (nondimensional); <= 0: the report's value (1.548e-8 shaping filter, eq. 53; 2e-8 random walk, eq. 67)",
        |m| m.config.q[0],
        |m, v| m.config.q[0] = v,
    ),
    V::real_parameter(
        "q_sway_force",
        None,
        true,
        "Intensity q22 of the Y' driving noise (nondimensional); <= 0: the report's value (8.970e-8, eq. 54; 1.25e-7, eq. 68)",
        |m| m.config.q[1],
        |m, v| m.config.q[1] = v,
    ),
    V::real_parameter(
        "r_heading",
        None,
        true,
        "Heading measurement noise intensity r11 (nondimensional PSD, 004 Table 3: 1.298e-8)",
        |m| m.config.r[0],
        |m, v| m.config.r[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "r_yaw_rate",
        None,
        true,
        "Yaw-rate measurement noise intensity r22 (nondimensional PSD, 004 Table 3: 2.860e-7)",
        |m| m.config.r[1],
        |m, v| m.config.r[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "r_cross_track",
        None,
        true,
        "Cross-track measurement noise intensity r33 (nondimensional PSD, 004 Table 3: 4.559e-7)",
        |m| m.config.r[2],
        |m, v| m.config.r[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "euler_step_prime",
        None,
        false,
        "Largest forward-Euler sub-step dt' of the filter (004: 0.005 = 0.2349 s); a communication step is covered by ceil(h'/dt') equal sub-steps",
        |m| m.euler_step_prime,
        |m, v| m.euler_step_prime = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "innovation_window",
        None,
        true,
        "Forgetting time (ship lengths) of the innovation mean square",
        |m| m.innovation_window,
        |m, v| m.innovation_window = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "initial_heading",
        Some("rad"),
        false,
        "Initial heading estimate",
        |m| m.x0[0],
        |m, v| m.x0[0] = v,
    ),
    V::real_parameter(
        "initial_yaw_rate",
        Some("rad/s"),
        false,
        "Initial yaw-rate estimate",
        |m| m.x0[1],
        |m, v| m.x0[1] = v,
    ),
    V::real_parameter(
        "initial_drift_angle",
        Some("rad"),
        false,
        "Initial drift-angle estimate beta (v = -U beta)",
        |m| m.x0[2],
        |m, v| m.x0[2] = v,
    ),
    V::real_parameter(
        "initial_cross_track",
        Some("m"),
        false,
        "Initial cross-track estimate eta",
        |m| m.x0[3],
        |m, v| m.x0[3] = v,
    ),
    V::real_parameter(
        "initial_rudder",
        Some("rad"),
        false,
        "Initial rudder-angle estimate",
        |m| m.x0[4],
        |m, v| m.x0[4] = v,
    ),
    V::real_parameter(
        "initial_yaw_moment_prime",
        None,
        false,
        "Initial N' estimate (nondimensional, 2N/(rho L^3 U^2))",
        |m| m.x0[5],
        |m, v| m.x0[5] = v,
    ),
    V::real_parameter(
        "initial_sway_force_prime",
        None,
        false,
        "Initial Y' estimate (nondimensional, 2Y/(rho L^2 U^2))",
        |m| m.x0[6],
        |m, v| m.x0[6] = v,
    ),
    V::real_input(
        "heading_measured",
        Some("rad"),
        "Measured heading psi (compass), deviation from the track direction",
        |m| m.z[0],
        |m, v| m.z[0] = v,
    ),
    V::real_input(
        "yaw_rate_measured",
        Some("rad/s"),
        "Measured yaw rate r (rate gyro)",
        |m| m.z[1],
        |m, v| m.z[1] = v,
    ),
    V::real_input(
        "cross_track_measured",
        Some("m"),
        "Measured lateral deviation eta from the track (DECCA Hi-Fix / radar)",
        |m| m.z[2],
        |m, v| m.z[2] = v,
    ),
    V::real_input(
        "rudder_command",
        Some("rad"),
        "Rudder command delta_c actually applied (controller output or dither)",
        |m| m.command,
        |m, v| m.command = v,
    ),
    V::real_output(
        "heading_estimate",
        Some("rad"),
        "Estimated heading psi",
        |m| m.x(0),
    ),
    V::real_output(
        "yaw_rate_estimate",
        Some("rad/s"),
        "Estimated yaw rate r = r' U/L",
        |m| m.x(1) * UL,
    ),
    V::real_output(
        "drift_angle_estimate",
        Some("rad"),
        "Estimated drift angle beta",
        |m| m.x(2),
    ),
    V::real_output(
        "sway_velocity_estimate",
        Some("m/s"),
        "Estimated sway velocity v = -U beta (004 eq. 5)",
        |m| -U * m.x(2),
    ),
    V::real_output(
        "cross_track_estimate",
        Some("m"),
        "Estimated lateral deviation eta = eta' L",
        |m| m.x(3) * L,
    ),
    V::real_output(
        "rudder_estimate",
        Some("rad"),
        "Estimated rudder angle delta (known exactly from the command history, K row = 0)",
        |m| m.x(4),
    ),
    V::real_output(
        "yaw_moment_prime_estimate",
        None,
        "Estimated external yaw moment N' (nondimensional)",
        |m| m.x(5),
    ),
    V::real_output(
        "sway_force_prime_estimate",
        None,
        "Estimated external sway force Y' (nondimensional)",
        |m| m.x(6),
    ),
    V::real_output(
        "yaw_rate_prime_estimate",
        None,
        "Estimated yaw rate r' = r L/U",
        |m| m.x(1),
    ),
    V::real_output(
        "cross_track_prime_estimate",
        None,
        "Estimated eta' = eta/L",
        |m| m.x(3),
    ),
    V::real_output(
        "innovation_heading",
        Some("rad"),
        "Innovation psi - psi_hat of the last filter sub-step",
        |m| m.nu(0),
    ),
    V::real_output(
        "innovation_yaw_rate",
        Some("rad/s"),
        "Innovation r - r_hat of the last filter sub-step",
        |m| m.nu(1) * UL,
    ),
    V::real_output(
        "innovation_cross_track",
        Some("m"),
        "Innovation eta - eta_hat of the last filter sub-step",
        |m| m.nu(2) * L,
    ),
    V::real_output(
        "innovation_rms_heading",
        Some("rad"),
        "Exponentially weighted RMS of the heading innovation (window innovation_window)",
        |m| m.nu_rms(0),
    ),
    V::real_output(
        "innovation_rms_yaw_rate",
        Some("rad/s"),
        "Exponentially weighted RMS of the yaw-rate innovation",
        |m| m.nu_rms(1) * UL,
    ),
    V::real_output(
        "innovation_rms_cross_track",
        Some("m"),
        "Exponentially weighted RMS of the cross-track innovation",
        |m| m.nu_rms(2) * L,
    ),
    V::real_output(
        "gain_heading_heading",
        None,
        "Kalman gain K(psi', psi') in use (004 Tables 4-6, 8)",
        |m| m.filter.gain()[(0, 0)],
    ),
    V::real_output(
        "gain_cross_track_cross_track",
        None,
        "Kalman gain K(eta', eta') in use",
        |m| m.filter.gain()[(3, 2)],
    ),
    V::real_output(
        "gain_yaw_moment_cross_track",
        None,
        "Kalman gain K(N', eta') in use",
        |m| m.filter.gain()[(5, 2)],
    ),
    V::real_output(
        "gain_sway_force_cross_track",
        None,
        "Kalman gain K(Y', eta') in use",
        |m| m.filter.gain()[(6, 2)],
    ),
    V::real_output(
        "design_steering_time_constant_prime",
        None,
        "T_r' = T U/L in use",
        |m| m.filter.design().t_r,
    ),
    V::real_output(
        "time_scale",
        Some("1/s"),
        "U/L of Tokyo Maru at 12 kn (t' = t U/L)",
        |_| UL,
    ),
    // ---- gain update from an adaptive controller (appended: earlier value references unchanged)
    V::boolean_parameter(
        "follow_design_inputs",
        false,
        "Re-design the filter model F_e and gain K whenever the f*_design inputs change (004 Fig. 1: the gain \
         calculation updates C, K and the filter model together; connect all six from the PathController's design_f* \
         outputs); the gammas stay those of the design depth",
        |m| m.follow_design_inputs,
        |m, v| m.follow_design_inputs = v,
    ),
    V::real_input(
        "f22_design",
        None,
        "f22 of the design to follow (follow_design_inputs)",
        |m| m.design_inputs[0],
        |m, v| m.design_inputs[0] = v,
    ),
    V::real_input(
        "f23_design",
        None,
        "f23 of the design to follow (follow_design_inputs)",
        |m| m.design_inputs[1],
        |m, v| m.design_inputs[1] = v,
    ),
    V::real_input(
        "f25_design",
        None,
        "f25 of the design to follow (follow_design_inputs)",
        |m| m.design_inputs[2],
        |m, v| m.design_inputs[2] = v,
    ),
    V::real_input(
        "f32_design",
        None,
        "f32 of the design to follow (follow_design_inputs)",
        |m| m.design_inputs[3],
        |m, v| m.design_inputs[3] = v,
    ),
    V::real_input(
        "f33_design",
        None,
        "f33 of the design to follow (follow_design_inputs)",
        |m| m.design_inputs[4],
        |m, v| m.design_inputs[4] = v,
    ),
    V::real_input(
        "f35_design",
        None,
        "f35 of the design to follow (follow_design_inputs)",
        |m| m.design_inputs[5],
        |m, v| m.design_inputs[5] = v,
    ),
];

impl FmuModel for PathKalmanFilterFmu {
    const MODEL_IDENTIFIER: &'static str = "PathKalmanFilter";
    const DESCRIPTION: &'static str = "Steady-state Kalman-Bucy filter with N', Y' bias states \
        (shaping filter or random walk) on the Tokyo Maru 7-state path model, Euler at dt' = 0.005 \
        (Parsons & Cuong 1980)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 940.0,
        step_size: 0.005 * L / U,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.rebuild_config()?;
        let design = self.config.design().map_err(|e| e.to_string())?;
        let x0 = self.x0;
        let xp = [x0[0], x0[1] / UL, x0[2], x0[3] / L, x0[4], x0[5], x0[6]];
        self.filter = PathKalmanFilter::new(design, xp)
            .map_err(|e| format!("Kalman gain design failed: {e}"))?;
        self.filter.dt_prime = self.euler_step_prime;
        self.filter.innovation_window = self.innovation_window;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.rebuild_config()?;
        let design = self.config.design().map_err(|e| e.to_string())?;
        if design != *self.filter.design() {
            self.filter
                .set_design(design)
                .map_err(|e| format!("Kalman gain design failed: {e}"))?;
        }
        self.filter.innovation_window = self.innovation_window;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        if self.follow_design_inputs {
            let mut design = *self.filter.design();
            // (the export layer refuses non-finite inputs at fmi2SetReal)
            if coefficients_of(&design.coefficients) != self.design_inputs {
                let [f22, f23, f25, f32, f33, f35] = self.design_inputs;
                let c = &mut design.coefficients;
                (c.f22, c.f23, c.f25, c.f32, c.f33, c.f35) = (f22, f23, f25, f32, f33, f35);
                self.filter.set_design(design).map_err(|e| {
                    format!("Kalman gain design for the f*_design inputs failed: {e}")
                })?;
            }
        }
        self.filter
            .step(self.z[0], self.z[1], self.z[2], self.command, h);
        Ok(())
    }
}

export_fmu!(PathKalmanFilterFmu);
