//! `TokyoMaru` FMU: the linear path model of the Tokyo Maru [Parsons1980, sec. 2] in restricted
//! water (`models::hull::tokyo_maru`) as an FMI 2.0 co-simulation FMU. No physics here: the
//! variable table maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::error::ParamError;
use models::hull::tokyo_maru::{
    TokyoMaru, TokyoMaruInputs, TokyoMaruIntegration, TokyoMaruOutputs, L, T_R, U,
};
use models::hull::DEG;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one Tokyo Maru instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TokyoMaruFmu {
    depth_ratio: f64,
    deep_water: bool,
    internal_steering_gear: bool,
    steering_time_constant_prime: f64,
    /// 1: exact ZOH; 2: forward Euler as in the report.
    integration: i32,
    euler_substep_prime: f64,
    rudder_angle: f64,
    rudder_command: f64,
    yaw_moment_prime: f64,
    sway_force_prime: f64,
    current_lateral: f64,
    ship: TokyoMaru,
    /// The model's outputs, computed once wherever the model changes (initialize, do_step,
    /// calculate_outputs) instead of in every getter; `None` (after a deserialized restore)
    /// means compute them. Not part of the state.
    #[serde(skip)]
    outputs: Option<TokyoMaruOutputs>,
}

/// Start value of the rudder inputs: a small rudder so that the default experiment turns.
pub const DEFAULT_RUDDER: f64 = 5.0 * DEG;

impl Default for TokyoMaruFmu {
    fn default() -> Self {
        TokyoMaruFmu {
            depth_ratio: 1.89,
            deep_water: false,
            internal_steering_gear: false,
            steering_time_constant_prime: T_R,
            integration: 1,
            euler_substep_prime: 0.005,
            rudder_angle: DEFAULT_RUDDER,
            rudder_command: DEFAULT_RUDDER,
            yaw_moment_prime: 0.0,
            sway_force_prime: 0.0,
            current_lateral: 0.0,
            ship: TokyoMaru::design_depth(),
            outputs: None,
        }
    }
}

/// A model error with the model's parameter name replaced by the FMU variable's name.
fn param_error(e: ParamError) -> String {
    e.renamed(&[
        ("t_r", "steering_time_constant_prime"),
        ("max_substep_prime", "euler_substep_prime"),
    ])
    .to_string()
}

impl TokyoMaruFmu {
    fn model_outputs(&self) -> TokyoMaruOutputs {
        self.ship.outputs()
    }

    fn out(&self) -> TokyoMaruOutputs {
        self.outputs.unwrap_or_else(|| self.model_outputs())
    }

    /// Keeps the outputs of the model as it is now (the getters read them).
    fn keep_outputs(&mut self) {
        self.outputs = Some(self.model_outputs());
    }

    /// The model's inputs: the rudder input in use depends on `internal_steering_gear`.
    pub fn model_inputs(&self) -> TokyoMaruInputs {
        TokyoMaruInputs {
            rudder: if self.internal_steering_gear {
                self.rudder_command
            } else {
                self.rudder_angle
            },
            yaw_moment_prime: self.yaw_moment_prime,
            sway_force_prime: self.sway_force_prime,
            current_lateral: self.current_lateral,
        }
    }

    /// Copies the tunable parameters into `ship` and validates them.
    fn apply_tunables(&self, ship: &mut TokyoMaru) -> Result<(), String> {
        ship.depth_ratio = if self.deep_water {
            f64::INFINITY
        } else {
            self.depth_ratio
        };
        ship.t_r = self.steering_time_constant_prime;
        ship.validate().map_err(param_error)
    }
}

fmi2_export::fmu! {
    TokyoMaruFmu => "TokyoMaru",
    description: "Tokyo Maru linear path model in restricted water \
        (Parsons & Cuong 1980): yaw rate, drift, heading and lateral deviation with coefficients \
        versus depth ratio H/T, external N', Y' and lateral current",
    experiment: (0.0, 600.0, 1.0),
    // Every output is a function of the state: no direct feedthrough from the inputs.
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        tunable real "depth_ratio" (depth_ratio).min(0.0),
            "Depth ratio H/T (water depth / draft); Table 2 tabulates 1.30, 1.50, 1.89 (design depth, \
             default), 2.50 and infinity; piecewise-linear in H/T between them, linear in T/H above \
             2.50, clamped at 1.30 below";
        tunable bool "deep_water" (deep_water),
            "true: H/T = infinity (deep water, the U7 case), overriding depth_ratio";
        fixed bool "internal_steering_gear" (internal_steering_gear),
            "false (default): the input rudder_angle is the actual rudder (use SteeringGear); true: the \
             input rudder_command drives the report's first-order gear T_r' delta' = delta_c - delta \
             (eq. 10) inside, the full 5-state model of eq. 11";
        tunable real "steering_time_constant_prime" (steering_time_constant_prime).min(0.0),
            "Nondimensional steering time constant T_r' of the internal gear (0.212874 = 10 s at 12 kn, \
             L = 290 m)";
        fixed int(1, 2) "integration" (integration),
            "1: exact zero-order-hold discretisation over each step (default; independent of the \
             communication step); 2: forward Euler with sub-steps <= euler_substep_prime, as the report";
        fixed real "euler_substep_prime" (euler_substep_prime).min(0.0),
            "Largest nondimensional Euler sub-step with integration = 2 (report: 0.005)";
        input real "rudder_angle" ["rad"] (rudder_angle),
            "Actual rudder angle delta (used when internal_steering_gear = false; positive sense as in \
             the report, see the documentation); start value 5 deg";
        input real "rudder_command" ["rad"] (rudder_command),
            "Rudder command delta_c (used when internal_steering_gear = true); start value 5 deg";
        input real "yaw_moment_prime" (yaw_moment_prime),
            "External yaw moment N' = 2N/(rho L^3 U^2) (nondimensional, as the report's disturbance models)";
        input real "sway_force_prime" (sway_force_prime),
            "External sway force Y' = 2Y/(rho L^2 U^2) (nondimensional)";
        input real "current_lateral" ["m/s"] (current_lateral),
            "Lateral current v_c toward +y (east, +eta) (section 2.6(b), eqs. 17-20)";
        output real "heading" ["rad"] (|m| m.out().heading),
            "Heading psi = psi' relative to the track (north), continuous";
        output real "heading_wrapped" ["rad"] (|m| m.out().heading_wrapped),
            "Heading wrapped to (-pi, pi]";
        output real "yaw_rate" ["rad/s"] (|m| m.out().yaw_rate), "Yaw rate r = r' U/L";
        output real "yaw_rate_prime" (|m| m.out().yaw_rate_prime),
            "Nondimensional yaw rate r' = rL/U";
        output real "drift_angle" ["rad"] (|m| m.out().drift_angle),
            "Drift angle beta relative to earth (beta' = beta'_e - v'_c)";
        output real "sway_velocity" ["m/s"] (|m| m.out().sway_velocity),
            "Sway velocity v = -U beta (eq. 5)";
        output real "cross_track" ["m"] (|m| m.out().cross_track),
            "Lateral deviation eta from the track (= y)";
        output real "cross_track_prime" (|m| m.out().cross_track_prime),
            "Nondimensional lateral deviation eta' = eta/L";
        output real "x" ["m"] (|m| m.out().x),
            "North (along-track) position xi, advancing at U (linearised)";
        output real "y" ["m"] (|m| m.out().y), "East position = eta";
        output real "rudder_angle_actual" ["rad"] (|m| m.out().rudder),
            "Actual rudder angle delta (the internal gear's output, or the input rudder_angle)";
        output real "time_prime" (|m| m.out().time_prime),
            "Nondimensional time t' = tU/L since the start";
    }
}

impl FmuModel for TokyoMaruFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.outputs = None;
        let mut ship = TokyoMaru::new(1.89).map_err(param_error)?;
        self.apply_tunables(&mut ship)?;
        ship.internal_steering_gear = self.internal_steering_gear;
        ship.integration = match self.integration {
            1 => TokyoMaruIntegration::Exact,
            2 => TokyoMaruIntegration::Euler {
                max_substep_prime: self.euler_substep_prime,
            },
            v => return Err(format!("parameter integration = {v} must be 1 or 2")),
        };
        ship.validate().map_err(param_error)?;
        self.ship = ship;
        self.keep_outputs();
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.outputs = None;
        let mut ship = self.ship.clone();
        self.apply_tunables(&mut ship)?;
        self.ship = ship;
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.keep_outputs();
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        let inputs = self.model_inputs();
        self.ship.step(&inputs, h);
        self.keep_outputs();
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        // Euler sub-steps of t' = t U/L ([`TokyoMaru::step`]); the exact ZOH has no loop.
        if let TokyoMaruIntegration::Euler { max_substep_prime } = self.ship.integration {
            let length = max_substep_prime * L / U;
            each(
                "euler_substep_prime",
                length,
                passes(h * U / L, max_substep_prime),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_fmu_parameter_and_value() {
        let mut m = TokyoMaruFmu {
            depth_ratio: 0.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("depth_ratio = 0"), "{e}");
        let mut m = TokyoMaruFmu {
            steering_time_constant_prime: 0.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("steering_time_constant_prime = 0"), "{e}");
        let mut m = TokyoMaruFmu {
            integration: 2,
            euler_substep_prime: 0.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("euler_substep_prime = 0"), "{e}");
    }
}
