//! `Mariner` FMU: the Mariner-class 3-DOF nonlinear manoeuvring model of
//! `models::hull::mariner` as an FMI 2.0 co-simulation FMU. No physics here: the variable table
//! maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::error::ParamError;
use models::hull::mariner::{Mariner, MarinerInputs, MarinerOutputs, MarinerParams, U0_DEFAULT};
use models::hull::{check_initial_state, DEG};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Parameters, input and state of one Mariner instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MarinerFmu {
    params: MarinerParams,
    trimmed: bool,
    /// The input that holds the trimmed straight course at `params.u0` (calculated parameter).
    trim: f64,
    inputs: MarinerInputs,
    ship: Mariner,
    /// The model's outputs, computed once wherever the model changes (initialize, do_step,
    /// calculate_outputs) instead of in every getter; `None` (after a deserialized restore)
    /// means compute them. Not part of the state.
    #[serde(skip)]
    outputs: Option<MarinerOutputs>,
    /// The state the run starts from (all 0 by default).
    initial: InitialState,
}

/// The initial state, SI, of the model's state `[Δu, v, r, x, y, ψ, δ]` (MSS `mariner.m`), with
/// the rudder in the sign of the output `rudder_angle` (−δ).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
struct InitialState {
    surge_perturbation: f64,
    sway_velocity: f64,
    yaw_rate: f64,
    x: f64,
    y: f64,
    heading: f64,
    rudder_angle: f64,
}

impl MarinerFmu {
    /// The start state: the trimmed course's Δu, v, δ (with `trimmed`) or the parameters', with
    /// r, x, y, ψ from the parameters in both cases.
    fn initial_state(&self) -> Result<[f64; 7], String> {
        let i = &self.initial;
        check_initial_state(
            &[
                ("initial_surge_perturbation", i.surge_perturbation),
                ("initial_sway_velocity", i.sway_velocity),
                ("initial_yaw_rate", i.yaw_rate),
                ("initial_x", i.x),
                ("initial_y", i.y),
                ("initial_heading", i.heading),
                ("initial_rudder_angle", i.rudder_angle),
            ],
            &[],
        )?;
        let (du, v, delta) = if self.trimmed {
            for (name, value) in [
                ("initial_surge_perturbation", i.surge_perturbation),
                ("initial_sway_velocity", i.sway_velocity),
                ("initial_rudder_angle", i.rudder_angle),
            ] {
                if value != 0.0 {
                    return Err(format!(
                        "parameter {name} = {value} applies with trimmed = false only (the trim \
                         solves it)"
                    ));
                }
            }
            let s = Mariner::trimmed(self.params.u0).map_err(param_error)?;
            let s = s.state();
            (s[0], s[1], s[6])
        } else {
            (i.surge_perturbation, i.sway_velocity, -i.rudder_angle)
        };
        Ok([du, v, i.yaw_rate, i.x, i.y, i.heading, delta])
    }
}

/// Start value of `rudder_command`: a small starboard rudder so that the default experiment turns.
pub const DEFAULT_RUDDER_COMMAND: f64 = 5.0 * DEG;

impl Default for MarinerFmu {
    fn default() -> Self {
        MarinerFmu {
            params: MarinerParams::default(),
            trimmed: true,
            trim: Mariner::trim_input(U0_DEFAULT),
            inputs: MarinerInputs {
                rudder_command: DEFAULT_RUDDER_COMMAND,
            },
            ship: Mariner::trimmed(U0_DEFAULT).expect("valid preset"),
            outputs: None,
            initial: InitialState::default(),
        }
    }
}

/// A model error with the model's parameter name replaced by the FMU variable's name.
fn param_error(e: ParamError) -> String {
    e.renamed(&[
        ("u0", "nominal_speed"),
        ("delta_u", "initial_surge_perturbation"),
    ])
    .to_string()
}

impl MarinerFmu {
    fn model_outputs(&self) -> MarinerOutputs {
        self.ship.outputs()
    }

    fn out(&self) -> MarinerOutputs {
        self.outputs.unwrap_or_else(|| self.model_outputs())
    }

    /// Keeps the outputs of the model as it is now (the getters read them).
    fn keep_outputs(&mut self) {
        self.outputs = Some(self.model_outputs());
    }
}

fmi2_export::fmu! {
    MarinerFmu => "Mariner",
    description: "Mariner-class cargo ship: nonlinear 3-DOF surge-sway-yaw \
        manoeuvring model with rudder servo (Chislett & Strom-Tejsen 1965; MSS mariner.m)",
    experiment: (0.0, 600.0, 0.1),
    // Every output is a function of the state: no direct feedthrough from the inputs.
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        // Declared minimum 0.1 m/s (was 0): the model is a perturbation about U0, and at
        // U0 = 1e-100 its nondimensional states fall into denormal numbers, which made a step of
        // 1e6 RK4 sub-steps (the work bound) take 1.2 s instead of 0.18 s (fuzz run seed 2027,
        // replay param Mariner 2228 135).
        fixed real "nominal_speed" ["m/s"] (params.u0).min(0.1),
            "Nominal speed U0 of the model (section 3.1: 7.7175 m/s = 15 kn); surge u = U0 + delta_u";
        tunable real "rudder_max" ["rad"] (params.rudder_max).range(0.0, PI),
            "Rudder command saturation (section 3.1: 40 deg)";
        tunable real "rudder_rate_max" ["rad/s"] (params.rudder_rate_max).min(0.0),
            "Rudder rate limit of the built-in servo (section 3.1: 5 deg/s)";
        fixed real "max_substep" ["s"] (params.max_substep).min(0.0),
            "Largest RK4 sub-step (default 0.05 s)";
        fixed bool "trimmed" (trimmed),
            "true: start on the trimmed straight course at nominal_speed (X' = Y' = N' = 0 with r = 0, \
             solved for delta_u, v, delta); false: MSS's start, all states 0 (not an equilibrium, section 3.3)";
        calculated real "trim_rudder_command" ["rad"] (trim),
            "The rudder_command that holds the trimmed straight course at nominal_speed \
             (about -1.108 deg at 15 kn; the Y'0, N'0 bias terms of section 3.3)";
        input real "rudder_command" ["rad"] (inputs.rudder_command),
            "Rudder input u_i (positive: starboard turn), through the built-in servo (saturation \
             rudder_max, rate rudder_rate_max, time constant 1 s); start value 5 deg";
        output real "surge_velocity" ["m/s"] (|m| m.out().u), "Surge velocity u = U0 + delta_u";
        output real "surge_perturbation" ["m/s"] (|m| m.out().delta_u),
            "Surge perturbation delta_u (the model's state)";
        output real "sway_velocity" ["m/s"] (|m| m.out().v), "Sway velocity v";
        output real "yaw_rate" ["rad/s"] (|m| m.out().r), "Yaw rate r";
        pose!(out());
        output real "rudder_angle" ["rad"] (|m| m.out().rudder),
            "Physical rudder angle -delta (same sign as rudder_command; positive: starboard turn)";
        output real "speed" ["m/s"] (|m| m.out().speed), "Total speed U = sqrt(u^2 + v^2)";
        output real "drift_angle" ["rad"] (|m| m.out().drift_angle), "Drift angle beta = atan2(v, u)";
        output real "surge_perturbation_prime" (|m| m.out().u_prime),
            "Prime-system surge perturbation u' = delta_u/U";
        output real "sway_velocity_prime" (|m| m.out().v_prime), "Prime-system sway v' = v/U";
        output real "yaw_rate_prime" (|m| m.out().r_prime),
            "Prime-system yaw rate r' = r L/U (L = 160.93 m)";
        // The initial state (issue 17), appended after the released variables: the state
        // [delta_u, v, r, x, y, psi, delta] of MSS mariner.m.
        fixed real "initial_surge_perturbation" ["m/s"] (initial.surge_perturbation),
            "Surge perturbation delta_u at the start time, u = U0 + delta_u > 0 (trimmed = false only; \
             default 0)";
        fixed real "initial_sway_velocity" ["m/s"] (initial.sway_velocity),
            "Sway velocity v at the start time (trimmed = false only; default 0)";
        fixed real "initial_yaw_rate" ["rad/s"] (initial.yaw_rate),
            "Yaw rate r at the start time (default 0; with trimmed the course is then no longer \
             straight)";
        fixed real "initial_x" ["m"] (initial.x), "North position at the start time (default 0)";
        fixed real "initial_y" ["m"] (initial.y), "East position at the start time (default 0)";
        fixed real "initial_heading" ["rad"] (initial.heading),
            "Heading psi from north, clockwise, at the start time (default 0)";
        fixed real "initial_rudder_angle" ["rad"] (initial.rudder_angle),
            "Physical rudder angle at the start time, sign of rudder_angle (the servo state is its \
             negative, MSS delta; trimmed = false only; default 0)";
    }
}

impl FmuModel for MarinerFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.outputs = None;
        self.params.validate().map_err(param_error)?;
        let state = self.initial_state()?;
        let ship = Mariner::new(self.params.clone(), state).map_err(param_error)?;
        self.trim = Mariner::trim_input(self.params.u0);
        self.ship = ship;
        self.keep_outputs();
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.outputs = None;
        self.params.validate().map_err(param_error)?;
        self.ship.params = self.params.clone();
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.keep_outputs();
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.ship.step(&self.inputs, h);
        self.keep_outputs();
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let max_substep = self.ship.params.max_substep;
        each("max_substep", max_substep, passes(h, max_substep));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// trimmed (default): the trim's delta_u, v, delta with r, x, y, psi from the parameters,
    /// and the defaults give today's start; trimmed = false: every state from the parameters,
    /// the rudder with the output's sign (state delta = -rudder_angle).
    #[test]
    fn the_initial_state_is_the_start() {
        let mut m = MarinerFmu::default();
        m.initialize(0.0).unwrap();
        assert_eq!(m.ship, Mariner::trimmed(U0_DEFAULT).unwrap());
        m.initial.heading = 0.5;
        m.initial.x = 100.0;
        m.initialize(0.0).unwrap();
        let trim = *Mariner::trimmed(U0_DEFAULT).unwrap().state();
        let s = m.ship.state();
        assert_eq!((s[0], s[1], s[6]), (trim[0], trim[1], trim[6]));
        assert_eq!((s[2], s[3], s[4], s[5]), (0.0, 100.0, 0.0, 0.5));
        m.initial.sway_velocity = 0.1;
        let e = m.initialize(0.0).unwrap_err();
        assert!(
            e.contains("initial_sway_velocity = 0.1 applies with trimmed = false"),
            "{e}"
        );
        m.trimmed = false;
        m.initial.rudder_angle = 0.2;
        m.initial.surge_perturbation = -0.5;
        m.initialize(0.0).unwrap();
        assert_eq!(m.ship.state(), &[-0.5, 0.1, 0.0, 100.0, 0.0, 0.5, -0.2]);
        assert_eq!(m.out().rudder, 0.2);
        m.initial.surge_perturbation = -8.0;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("initial_surge_perturbation = -8"), "{e}");
    }

    #[test]
    fn errors_name_the_fmu_parameter_and_value() {
        let mut m = MarinerFmu::default();
        m.params.u0 = -1.0;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("nominal_speed = -1"), "{e}");
        let mut m = MarinerFmu::default();
        m.params.rudder_rate_max = 0.0;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("rudder_rate_max = 0"), "{e}");
    }
}
