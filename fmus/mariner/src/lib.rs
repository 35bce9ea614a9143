//! `Mariner` FMU: the Mariner-class 3-DOF nonlinear manoeuvring model of
//! `models::hull::mariner` as an FMI 2.0 co-simulation FMU. No physics here: the variable table
//! maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::hull::mariner::{Mariner, MarinerInputs, MarinerOutputs, MarinerParams, U0_DEFAULT};
use models::hull::DEG;
use models::steering_gear::ParamError;
use serde::{Deserialize, Serialize};

/// Parameters, input and state of one Mariner instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MarinerFmu {
    params: MarinerParams,
    trimmed: bool,
    /// The input that holds the trimmed straight course at `params.u0` (calculated parameter).
    trim: f64,
    inputs: MarinerInputs,
    ship: Mariner,
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
        }
    }
}

/// A model error with the model's parameter name replaced by the FMU variable's name.
fn param_error(e: ParamError) -> String {
    let name = match e.name {
        "u0" => "nominal_speed",
        other => other,
    };
    format!("parameter {name} = {} {}", e.value, e.rule)
}

impl MarinerFmu {
    fn out(&self) -> MarinerOutputs {
        self.ship.outputs()
    }
}

type V = Variable<MarinerFmu>;

static VARIABLES: &[V] = &[
    V::real_parameter(
        "nominal_speed",
        Some("m/s"),
        false,
        "Nominal speed U0 of the model (section 3.1: 7.7175 m/s = 15 kn); surge u = U0 + delta_u",
        |m| m.params.u0,
        |m, v| m.params.u0 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "rudder_max",
        Some("rad"),
        true,
        "Rudder command saturation (section 3.1: 40 deg)",
        |m| m.params.rudder_max,
        |m, v| m.params.rudder_max = v,
    )
    .with_range(Some(0.0), Some(std::f64::consts::PI)),
    V::real_parameter(
        "rudder_rate_max",
        Some("rad/s"),
        true,
        "Rudder rate limit of the built-in servo (section 3.1: 5 deg/s)",
        |m| m.params.rudder_rate_max,
        |m, v| m.params.rudder_rate_max = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "max_substep",
        Some("s"),
        false,
        "Largest RK4 sub-step (default 0.05 s)",
        |m| m.params.max_substep,
        |m, v| m.params.max_substep = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "trimmed",
        false,
        "true: start on the trimmed straight course at nominal_speed (X' = Y' = N' = 0 with r = 0, \
         solved for delta_u, v, delta); false: MSS's start, all states 0 (not an equilibrium, section 3.3)",
        |m| m.trimmed,
        |m, v| m.trimmed = v,
    ),
    V::real_calculated_parameter(
        "trim_rudder_command",
        Some("rad"),
        "The rudder_command that holds the trimmed straight course at nominal_speed \
         (about -1.108 deg at 15 kn; the Y'0, N'0 bias terms of section 3.3)",
        |m| m.trim,
    ),
    V::real_input(
        "rudder_command",
        Some("rad"),
        "Rudder input u_i (positive: starboard turn), through the built-in servo (saturation \
         rudder_max, rate rudder_rate_max, time constant 1 s); start value 5 deg",
        |m| m.inputs.rudder_command,
        |m, v| m.inputs.rudder_command = v,
    ),
    V::real_output(
        "surge_velocity",
        Some("m/s"),
        "Surge velocity u = U0 + delta_u",
        |m| m.out().u,
    ),
    V::real_output(
        "surge_perturbation",
        Some("m/s"),
        "Surge perturbation delta_u (the model's state)",
        |m| m.out().delta_u,
    ),
    V::real_output(
        "sway_velocity",
        Some("m/s"),
        "Sway velocity v",
        |m| m.out().v,
    ),
    V::real_output(
        "yaw_rate",
        Some("rad/s"),
        "Yaw rate r",
        |m| m.out().r,
    ),
    V::real_output(
        "heading",
        Some("rad"),
        "Heading psi from north, clockwise, continuous (not wrapped)",
        |m| m.out().heading,
    ),
    V::real_output(
        "heading_wrapped",
        Some("rad"),
        "Heading wrapped to (-pi, pi]",
        |m| m.out().heading_wrapped,
    ),
    V::real_output("x", Some("m"), "North position", |m| m.out().x),
    V::real_output("y", Some("m"), "East position", |m| m.out().y),
    V::real_output(
        "rudder_angle",
        Some("rad"),
        "Physical rudder angle -delta (same sign as rudder_command; positive: starboard turn)",
        |m| m.out().rudder,
    ),
    V::real_output(
        "speed",
        Some("m/s"),
        "Total speed U = sqrt(u^2 + v^2)",
        |m| m.out().speed,
    ),
    V::real_output(
        "drift_angle",
        Some("rad"),
        "Drift angle beta = atan2(v, u)",
        |m| m.out().drift_angle,
    ),
    V::real_output(
        "surge_perturbation_prime",
        None,
        "Prime-system surge perturbation u' = delta_u/U",
        |m| m.out().u_prime,
    ),
    V::real_output(
        "sway_velocity_prime",
        None,
        "Prime-system sway v' = v/U",
        |m| m.out().v_prime,
    ),
    V::real_output(
        "yaw_rate_prime",
        None,
        "Prime-system yaw rate r' = r L/U (L = 160.93 m)",
        |m| m.out().r_prime,
    ),
];

impl FmuModel for MarinerFmu {
    const MODEL_IDENTIFIER: &'static str = "Mariner";
    /// Every output is a function of the state: no direct feedthrough from the inputs.
    const DIRECT_FEEDTHROUGH: bool = false;
    const DESCRIPTION: &'static str = "Mariner-class cargo ship: nonlinear 3-DOF surge-sway-yaw \
        manoeuvring model with rudder servo (Chislett & Strom-Tejsen 1965; MSS mariner.m)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 600.0,
        step_size: 0.1,
    };

    fn variables() -> &'static [Variable<Self>] {
        VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.params.validate().map_err(param_error)?;
        let mut ship = if self.trimmed {
            Mariner::trimmed(self.params.u0).map_err(param_error)?
        } else {
            Mariner::new(self.params.clone(), [0.0; 7]).map_err(param_error)?
        };
        ship.params = self.params.clone();
        self.trim = Mariner::trim_input(self.params.u0);
        self.ship = ship;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.params.validate().map_err(param_error)?;
        self.ship.params = self.params.clone();
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.ship.step(&self.inputs, h);
        Ok(())
    }
}

export_fmu!(MarinerFmu);

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
