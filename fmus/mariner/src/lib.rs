//! `Mariner` FMU: the Mariner-class 3-DOF nonlinear manoeuvring model of
//! `models::hull::mariner` as an FMI 2.0 co-simulation FMU. No physics here: the variable table
//! maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::error::ParamError;
use models::hull::mariner::{Mariner, MarinerInputs, MarinerOutputs, MarinerParams, U0_DEFAULT};
use models::hull::DEG;
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
        }
    }
}

/// A model error with the model's parameter name replaced by the FMU variable's name.
fn param_error(e: ParamError) -> String {
    e.renamed(&[("u0", "nominal_speed")]).to_string()
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
        fixed real "nominal_speed" ["m/s"] (params.u0).min(0.0),
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
    }
}

impl FmuModel for MarinerFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.outputs = None;
        self.params.validate().map_err(param_error)?;
        let mut ship = if self.trimmed {
            Mariner::trimmed(self.params.u0).map_err(param_error)?
        } else {
            Mariner::new(self.params.clone(), [0.0; 7]).map_err(param_error)?
        };
        ship.params = self.params.clone();
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
