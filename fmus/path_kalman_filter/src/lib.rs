//! `PathKalmanFilter` FMU: the steady-state Kalman-Bucy filter of [Parsons1980, sec. 3] on the
//! Tokyo Maru 7-state design model (`models::observers::path_kalman`). No physics here.

use fmi2_export::{passes, FmuModel};
use models::error::check_positive;
use models::hull::tokyo_maru::{TokyoMaruCoefficients, L, U};
use models::memo::{Bits, Memo};
use models::observers::path_kalman::{KalmanGain, PathKalmanConfig, PathKalmanFilter};
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
    initial_estimate: [f64; 7],
    /// Inputs: ψ, r, η measured; δ_c.
    measured: [f64; 3],
    command: f64,
    /// Follow the design-coefficient inputs (the gain update of an adaptive loop).
    follow_design_inputs: bool,
    /// Inputs: f22, f23, f25, f32, f33, f35 of the design in use (from the PathController).
    design_inputs: [f64; 6],
    filter: PathKalmanFilter,
    /// The gain of the last design initialized (an importer reads outputs in Initialization
    /// Mode after each input it sets, and each read initializes again: the Riccati solution is
    /// kept while the design does not change; derived, see `models::memo`).
    #[serde(skip)]
    gain: Memo<Bits<22>, KalmanGain>,
}

impl Default for PathKalmanFilterFmu {
    fn default() -> Self {
        let config = PathKalmanConfig::default();
        let design = config.design().expect("preset");
        let design_inputs = coefficients_of(&design.coefficients);
        let mut gain = Memo::default();
        let k = *gain
            .try_get(design.key(), || design.kalman_gain())
            .expect("preset design has a stabilising Riccati solution");
        PathKalmanFilterFmu {
            filter: PathKalmanFilter::with_gain(design, [0.0; 7], k),
            gain,
            config,
            steering_time_constant: 10.0,
            euler_step_prime: 0.005,
            innovation_window: 1.0,
            initial_estimate: [0.0; 7],
            measured: [0.0; 3],
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
        for (name, v) in [
            ("steering_time_constant", self.steering_time_constant),
            ("euler_step_prime", self.euler_step_prime),
            ("innovation_window", self.innovation_window),
        ] {
            check_positive(name, v)?;
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

const UL: f64 = U / L;

fmi2_export::fmu! {
    PathKalmanFilterFmu => "PathKalmanFilter",
    description: "Steady-state Kalman-Bucy filter with N', Y' bias states \
        (shaping filter or random walk) on the Tokyo Maru 7-state path model, Euler at dt' = 0.005 \
        (Parsons & Cuong 1980)",
    experiment: (0.0, 940.0, 0.005 * L / U),
    documentation: "documentation.html",
    variables: {
        tunable real "design_depth_ratio" (config.design_depth_ratio).min(0.0),
            "Design (assumed) water depth / draft H/T of the Table 2 coefficients in the filter model ([Parsons1980, Table 2]; 1.89 = [Parsons1980, Table 5] design; a very large value gives deep water); changing it in step mode is a gain-update event";
        tunable real "adapted_depth_ratio" (config.adapted_depth_ratio),
            "If > 0: f23 and f25 are taken at this H/T ([Parsons1980, Table 8] partial adaptation); 0: not used";
        tunable int "disturbance_model" (config.random_walk => { 1: false, 2: true }),
            "N', Y' model in the filter: 1 first-order shaping filter ([Parsons1980, eqs. (39)-(41), Table 4]); 2 random walk ([Parsons1980, eqs. (56)-(59), Tables 5, 6, 8])";
        tunable real "steering_time_constant" ["s"] (steering_time_constant).min(0.0),
            "Steering-gear time constant of eq. 10 (T_r' = T U/L; 10 s = 0.212874 is the value derived in the spec, the report does not print it)";
        tunable real "shaping_time_constant" (config.shaping_time_constant).min(0.0),
            "Shaping-filter time constant T_N = T_Y in ship lengths (t' units) ([Parsons1980, eqs. (39)-(40)])";
        tunable real "epsilon" (config.epsilon).min(0.0),
            "Random-walk design regulariser: -epsilon on the N', Y' diagonal for the gain design only ([Parsons1980, sec. 3.3])";
        tunable real "q_yaw_moment" (config.q[0]),
            "Intensity q11 of the N' driving noise (nondimensional); <= 0: the report's value (1.548e-8 shaping filter, eq. 53; 2e-8 random walk, eq. 67)";
        tunable real "q_sway_force" (config.q[1]),
            "Intensity q22 of the Y' driving noise (nondimensional); <= 0: the report's value (8.970e-8, eq. 54; 1.25e-7, eq. 68)";
        tunable real "r_heading" (config.r[0]).min(0.0),
            "Heading measurement noise intensity r11 (nondimensional PSD, [Parsons1980, Table 3]: 1.298e-8)";
        tunable real "r_yaw_rate" (config.r[1]).min(0.0),
            "Yaw-rate measurement noise intensity r22 (nondimensional PSD, [Parsons1980, Table 3]: 2.860e-7)";
        tunable real "r_cross_track" (config.r[2]).min(0.0),
            "Cross-track measurement noise intensity r33 (nondimensional PSD, [Parsons1980, Table 3]: 4.559e-7)";
        fixed real "euler_step_prime" (euler_step_prime).min(0.0),
            "Largest forward-Euler sub-step dt' of the filter ([Parsons1980]: 0.005 = 0.2349 s); a communication step is covered by ceil(h'/dt') equal sub-steps";
        tunable real "innovation_window" (innovation_window).min(0.0),
            "Forgetting time (ship lengths) of the innovation mean square";
        fixed real "initial_heading" ["rad"] (initial_estimate[0]), "Initial heading estimate";
        fixed real "initial_yaw_rate" ["rad/s"] (initial_estimate[1]), "Initial yaw-rate estimate";
        fixed real "initial_drift_angle" ["rad"] (initial_estimate[2]),
            "Initial drift-angle estimate beta (v = -U beta)";
        fixed real "initial_cross_track" ["m"] (initial_estimate[3]), "Initial cross-track estimate eta";
        fixed real "initial_rudder" ["rad"] (initial_estimate[4]), "Initial rudder-angle estimate";
        fixed real "initial_yaw_moment_prime" (initial_estimate[5]),
            "Initial N' estimate (nondimensional, 2N/(rho L^3 U^2))";
        fixed real "initial_sway_force_prime" (initial_estimate[6]),
            "Initial Y' estimate (nondimensional, 2Y/(rho L^2 U^2))";
        input real "heading_measured" ["rad"] (measured[0]),
            "Measured heading psi (compass), deviation from the track direction";
        input real "yaw_rate_measured" ["rad/s"] (measured[1]), "Measured yaw rate r (rate gyro)";
        input real "cross_track_measured" ["m"] (measured[2]),
            "Measured lateral deviation eta from the track (DECCA Hi-Fix / radar)";
        input real "rudder_command" ["rad"] (command),
            "Rudder command delta_c actually applied (controller output or dither)";
        output real "heading_estimate" ["rad"] (|m| m.x(0)), "Estimated heading psi";
        output real "yaw_rate_estimate" ["rad/s"] (|m| m.x(1) * UL), "Estimated yaw rate r = r' U/L";
        output real "drift_angle_estimate" ["rad"] (|m| m.x(2)), "Estimated drift angle beta";
        output real "sway_velocity_estimate" ["m/s"] (|m| -U * m.x(2)),
            "Estimated sway velocity v = -U beta ([Parsons1980, eq. (5)])";
        output real "cross_track_estimate" ["m"] (|m| m.x(3) * L),
            "Estimated lateral deviation eta = eta' L";
        output real "rudder_estimate" ["rad"] (|m| m.x(4)),
            "Estimated rudder angle delta (known exactly from the command history, K row = 0)";
        output real "yaw_moment_prime_estimate" (|m| m.x(5)),
            "Estimated external yaw moment N' (nondimensional)";
        output real "sway_force_prime_estimate" (|m| m.x(6)),
            "Estimated external sway force Y' (nondimensional)";
        output real "yaw_rate_prime_estimate" (|m| m.x(1)), "Estimated yaw rate r' = r L/U";
        output real "cross_track_prime_estimate" (|m| m.x(3)), "Estimated eta' = eta/L";
        output real "innovation_heading" ["rad"] (|m| m.nu(0)),
            "Innovation psi - psi_hat of the last filter sub-step";
        output real "innovation_yaw_rate" ["rad/s"] (|m| m.nu(1) * UL),
            "Innovation r - r_hat of the last filter sub-step";
        output real "innovation_cross_track" ["m"] (|m| m.nu(2) * L),
            "Innovation eta - eta_hat of the last filter sub-step";
        output real "innovation_rms_heading" ["rad"] (|m| m.nu_rms(0)),
            "Exponentially weighted RMS of the heading innovation (window innovation_window)";
        output real "innovation_rms_yaw_rate" ["rad/s"] (|m| m.nu_rms(1) * UL),
            "Exponentially weighted RMS of the yaw-rate innovation";
        output real "innovation_rms_cross_track" ["m"] (|m| m.nu_rms(2) * L),
            "Exponentially weighted RMS of the cross-track innovation";
        output real "gain_heading_heading" (|m| m.filter.gain()[(0, 0)]),
            "Kalman gain K(psi', psi') in use ([Parsons1980, Tables 4-6, 8])";
        output real "gain_cross_track_cross_track" (|m| m.filter.gain()[(3, 2)]),
            "Kalman gain K(eta', eta') in use";
        output real "gain_yaw_moment_cross_track" (|m| m.filter.gain()[(5, 2)]),
            "Kalman gain K(N', eta') in use";
        output real "gain_sway_force_cross_track" (|m| m.filter.gain()[(6, 2)]),
            "Kalman gain K(Y', eta') in use";
        output real "design_steering_time_constant_prime" (|m| m.filter.design().t_r),
            "T_r' = T U/L in use";
        output real "time_scale" ["1/s"] (|_m| UL), "U/L of Tokyo Maru at 12 kn (t' = t U/L)";
        // ---- gain update from an adaptive controller (appended: earlier value references unchanged)
        fixed bool "follow_design_inputs" (follow_design_inputs),
            "Re-design the filter model F_e and gain K whenever the f*_design inputs change ([Parsons1980, Fig. 1]: the gain \
             calculation updates C, K and the filter model together; connect all six from the PathController's design_f* \
             outputs); the gammas stay those of the design depth";
        input real "f22_design" (design_inputs[0]), "f22 of the design to follow (follow_design_inputs)";
        input real "f23_design" (design_inputs[1]), "f23 of the design to follow (follow_design_inputs)";
        input real "f25_design" (design_inputs[2]), "f25 of the design to follow (follow_design_inputs)";
        input real "f32_design" (design_inputs[3]), "f32 of the design to follow (follow_design_inputs)";
        input real "f33_design" (design_inputs[4]), "f33 of the design to follow (follow_design_inputs)";
        input real "f35_design" (design_inputs[5]), "f35 of the design to follow (follow_design_inputs)";
    }
}

impl FmuModel for PathKalmanFilterFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.rebuild_config()?;
        let design = self.config.design().map_err(|e| e.to_string())?;
        let x0 = self.initial_estimate;
        let xp = [x0[0], x0[1] / UL, x0[2], x0[3] / L, x0[4], x0[5], x0[6]];
        let k = *self
            .gain
            .try_get(design.key(), || design.kalman_gain())
            .map_err(|e| format!("Kalman gain design failed: {e}"))?;
        self.filter = PathKalmanFilter::with_gain(design, xp, k);
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
        self.filter.step(
            self.measured[0],
            self.measured[1],
            self.measured[2],
            self.command,
            h,
        );
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        // Euler sub-steps of t' = t U/L ([`PathKalmanFilter::step`]).
        let dt_prime = self.filter.dt_prime;
        each("euler_step_prime", dt_prime / UL, passes(h * UL, dt_prime));
    }
}
