//! `TokyoMaru` FMU: the Parsons & Cuong (1980) linear path model of the Tokyo Maru in restricted
//! water (`models::hull::tokyo_maru`) as an FMI 2.0 co-simulation FMU. No physics here: the
//! variable table maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::hull::tokyo_maru::{
    TokyoMaru, TokyoMaruInputs, TokyoMaruIntegration, TokyoMaruOutputs, T_R,
};
use models::hull::DEG;
use models::steering_gear::ParamError;
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
        }
    }
}

/// A model error with the model's parameter name replaced by the FMU variable's name.
fn param_error(e: ParamError) -> String {
    let name = match e.name {
        "t_r" => "steering_time_constant_prime",
        "max_substep_prime" => "euler_substep_prime",
        other => other,
    };
    format!("parameter {name} = {} {}", e.value, e.rule)
}

impl TokyoMaruFmu {
    fn out(&self) -> TokyoMaruOutputs {
        self.ship.outputs()
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

type V = Variable<TokyoMaruFmu>;

static VARIABLES: &[V] = &[
    V::real_parameter(
        "depth_ratio",
        None,
        true,
        "Depth ratio H/T (water depth / draft); Table 2 tabulates 1.30, 1.50, 1.89 (design depth, \
         default), 2.50 and infinity; piecewise-linear in H/T between them, linear in T/H above \
         2.50, clamped at 1.30 below",
        |m| m.depth_ratio,
        |m, v| m.depth_ratio = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "deep_water",
        true,
        "true: H/T = infinity (deep water, the U7 case), overriding depth_ratio",
        |m| m.deep_water,
        |m, v| m.deep_water = v,
    ),
    V::boolean_parameter(
        "internal_steering_gear",
        false,
        "false (default): the input rudder_angle is the actual rudder (use SteeringGear); true: the \
         input rudder_command drives the report's first-order gear T_r' delta' = delta_c - delta \
         (eq. 10) inside, the full 5-state model of eq. 11",
        |m| m.internal_steering_gear,
        |m, v| m.internal_steering_gear = v,
    ),
    V::real_parameter(
        "steering_time_constant_prime",
        None,
        true,
        "Nondimensional steering time constant T_r' of the internal gear (0.212874 = 10 s at 12 kn, \
         L = 290 m)",
        |m| m.steering_time_constant_prime,
        |m, v| m.steering_time_constant_prime = v,
    )
    .with_range(Some(0.0), None),
    V::integer_parameter(
        "integration",
        false,
        "1: exact zero-order-hold discretisation over each step (default; independent of the \
         communication step); 2: forward Euler with sub-steps <= euler_substep_prime, as the report",
        1,
        2,
        |m| m.integration,
        |m, v| m.integration = v,
    ),
    V::real_parameter(
        "euler_substep_prime",
        None,
        false,
        "Largest nondimensional Euler sub-step with integration = 2 (report: 0.005)",
        |m| m.euler_substep_prime,
        |m, v| m.euler_substep_prime = v,
    )
    .with_range(Some(0.0), None),
    V::real_input(
        "rudder_angle",
        Some("rad"),
        "Actual rudder angle delta (used when internal_steering_gear = false; positive sense as in \
         the report, see the documentation); start value 5 deg",
        |m| m.rudder_angle,
        |m, v| m.rudder_angle = v,
    ),
    V::real_input(
        "rudder_command",
        Some("rad"),
        "Rudder command delta_c (used when internal_steering_gear = true); start value 5 deg",
        |m| m.rudder_command,
        |m, v| m.rudder_command = v,
    ),
    V::real_input(
        "yaw_moment_prime",
        None,
        "External yaw moment N' = 2N/(rho L^3 U^2) (nondimensional, as the report's disturbance models)",
        |m| m.yaw_moment_prime,
        |m, v| m.yaw_moment_prime = v,
    ),
    V::real_input(
        "sway_force_prime",
        None,
        "External sway force Y' = 2Y/(rho L^2 U^2) (nondimensional)",
        |m| m.sway_force_prime,
        |m, v| m.sway_force_prime = v,
    ),
    V::real_input(
        "current_lateral",
        Some("m/s"),
        "Lateral current v_c toward +y (east, +eta) (section 2.6(b), eqs. 17-20)",
        |m| m.current_lateral,
        |m, v| m.current_lateral = v,
    ),
    V::real_output(
        "heading",
        Some("rad"),
        "Heading psi = psi' relative to the track (north), continuous",
        |m| m.out().heading,
    ),
    V::real_output(
        "heading_wrapped",
        Some("rad"),
        "Heading wrapped to (-pi, pi]",
        |m| m.out().heading_wrapped,
    ),
    V::real_output(
        "yaw_rate",
        Some("rad/s"),
        "Yaw rate r = r' U/L",
        |m| m.out().yaw_rate,
    ),
    V::real_output(
        "yaw_rate_prime",
        None,
        "Nondimensional yaw rate r' = rL/U",
        |m| m.out().yaw_rate_prime,
    ),
    V::real_output(
        "drift_angle",
        Some("rad"),
        "Drift angle beta relative to earth (beta' = beta'_e - v'_c)",
        |m| m.out().drift_angle,
    ),
    V::real_output(
        "sway_velocity",
        Some("m/s"),
        "Sway velocity v = -U beta (eq. 5)",
        |m| m.out().sway_velocity,
    ),
    V::real_output(
        "cross_track",
        Some("m"),
        "Lateral deviation eta from the track (= y)",
        |m| m.out().cross_track,
    ),
    V::real_output(
        "cross_track_prime",
        None,
        "Nondimensional lateral deviation eta' = eta/L",
        |m| m.out().cross_track_prime,
    ),
    V::real_output(
        "x",
        Some("m"),
        "North (along-track) position xi, advancing at U (linearised)",
        |m| m.out().x,
    ),
    V::real_output("y", Some("m"), "East position = eta", |m| m.out().y),
    V::real_output(
        "rudder_angle_actual",
        Some("rad"),
        "Actual rudder angle delta (the internal gear's output, or the input rudder_angle)",
        |m| m.out().rudder,
    ),
    V::real_output(
        "time_prime",
        None,
        "Nondimensional time t' = tU/L since the start",
        |m| m.out().time_prime,
    ),
];

impl FmuModel for TokyoMaruFmu {
    const MODEL_IDENTIFIER: &'static str = "TokyoMaru";
    /// Every output is a function of the state: no direct feedthrough from the inputs.
    const DIRECT_FEEDTHROUGH: bool = false;
    const DESCRIPTION: &'static str = "Tokyo Maru linear path model in restricted water \
        (Parsons & Cuong 1980): yaw rate, drift, heading and lateral deviation with coefficients \
        versus depth ratio H/T, external N', Y' and lateral current";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 600.0,
        step_size: 1.0,
    };

    fn variables() -> &'static [Variable<Self>] {
        VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
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
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        let mut ship = self.ship.clone();
        self.apply_tunables(&mut ship)?;
        self.ship = ship;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        let inputs = self.model_inputs();
        self.ship.step(&inputs, h);
        Ok(())
    }
}

export_fmu!(TokyoMaruFmu);

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
