//! `SteeringGear` FMU: the steering machine of `models::steering_gear` as an FMI 2.0
//! co-simulation FMU. No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::steering_gear::{ServoOrder, SteeringGear, SteeringGearParams};
use serde::{Deserialize, Serialize};

/// Parameters, input and state of one steering-gear instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SteeringGearFmu {
    params: SteeringGearParams,
    initial_angle: f64,
    command: f64,
    gear: SteeringGear,
}

impl Default for SteeringGearFmu {
    fn default() -> Self {
        let params = SteeringGearParams::rrs_003();
        SteeringGearFmu {
            gear: SteeringGear::new(params.clone(), 0.0).expect("preset parameters are valid"),
            params,
            initial_angle: 0.0,
            command: 0.0,
        }
    }
}

type V = Variable<SteeringGearFmu>;

static VARIABLES: [V; 16] = [
    V::real_parameter(
        "angle_max",
        Some("rad"),
        true,
        "Rudder-angle limit delta_max on the set point and the actual angle (003 Fig. 2.8)",
        |m| m.params.angle_max,
        |m, v| m.params.angle_max = v,
    )
    .with_range(Some(0.0), Some(std::f64::consts::PI)),
    V::real_parameter(
        "rate_max",
        Some("rad/s"),
        true,
        "Rudder-rate limit (max rudder speed), used when rate_limited (003 Fig. 2.8, eq. 6.33)",
        |m| m.params.rate_max,
        |m, v| m.params.rate_max = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "rate_limited",
        true,
        "Rate limiter present (true: 003 RRS gear; false: the 000 and 004 first-order gears)",
        |m| m.params.rate_limited,
        |m, v| m.params.rate_limited = v,
    ),
    V::real_parameter(
        "time_constant",
        Some("s"),
        true,
        "Servo time constant tau_delta of the first-order servo (003 eq. 6.35; 000: L/(6U); 004: T_r = 10 s)",
        |m| m.params.time_constant,
        |m, v| m.params.time_constant = v,
    )
    .with_range(Some(0.0), None),
    V::integer_parameter(
        "servo_order",
        false,
        "1: first-order servo (003 Fig. 2.8, eq. 6.35); 2: second-order main servo (003 eqs. 6.41-6.42)",
        1,
        2,
        |m| match m.params.order {
            ServoOrder::First => 1,
            ServoOrder::Second => 2,
        },
        |m, v| {
            m.params.order = if v == 2 {
                ServoOrder::Second
            } else {
                ServoOrder::First
            }
        },
    ),
    V::real_parameter(
        "omega0",
        Some("rad/s"),
        true,
        "Natural frequency omega0 of the second-order servo (003 eq. 6.42; >= 10 omega_n, eq. 6.43)",
        |m| m.params.omega0,
        |m, v| m.params.omega0 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "zeta0",
        None,
        true,
        "Relative damping z0 of the second-order servo (003 eq. 6.44: z0 >= 1)",
        |m| m.params.zeta0,
        |m, v| m.params.zeta0 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "max_substep",
        Some("s"),
        false,
        "Largest RK4 sub-step of the second-order servo (the first-order servo is integrated exactly)",
        |m| m.params.max_substep,
        |m, v| m.params.max_substep = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "initial_angle",
        Some("rad"),
        false,
        "Rudder angle at the start time",
        |m| m.initial_angle,
        |m, v| m.initial_angle = v,
    ),
    V::real_input(
        "rudder_command",
        Some("rad"),
        "Set-point rudder angle delta_g from the autopilot (positive: starboard turn)",
        |m| m.command,
        |m, v| m.command = v,
    ),
    V::real_output(
        "rudder_angle",
        Some("rad"),
        "Actual rudder angle delta_w",
        |m| m.gear.angle(),
    ),
    V::real_output(
        "rudder_rate",
        Some("rad/s"),
        "Actual rudder speed d(delta_w)/dt",
        |m| m.gear.rate(),
    )
    .depends_on(&["rudder_command"]),
    V::real_output(
        "limited_command",
        Some("rad"),
        "Set point after the angle limiter, sat(delta_g, +-angle_max)",
        |m| m.gear.limited_command(),
    )
    .depends_on(&["rudder_command"]),
    V::boolean_output(
        "command_saturated",
        "The set point exceeds angle_max (angle limiter active)",
        |m| SteeringGear::command_saturated(m.command, &m.gear.params),
    )
    .depends_on(&["rudder_command"]),
    V::boolean_output(
        "rate_saturated",
        "The rate limiter is active",
        |m| m.gear.rate_saturated(),
    )
    .depends_on(&["rudder_command"]),
    V::real_output(
        "rate_saturated_time",
        Some("s"),
        "Total time the rate limiter has been active since the start (exact, for the RRS statistics of 003)",
        |m| m.gear.rate_saturated_time(),
    ),
];

impl FmuModel for SteeringGearFmu {
    const MODEL_IDENTIFIER: &'static str = "SteeringGear";
    /// rudder_angle and rate_saturated_time are state; the others declare rudder_command.
    const DIRECT_FEEDTHROUGH: bool = false;
    const DESCRIPTION: &'static str = "Steering machine with rudder-angle and rudder-rate limits \
        and first- or second-order servo (van der Klugt 1987 Fig. 2.8 and section 6.5.2; \
        DDG-51 6/(s+6) gear; Parsons-Cuong T_r gear)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 30.0,
        step_size: 0.01,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.gear = SteeringGear::new(self.params.clone(), self.initial_angle)
            .map_err(|e| e.to_string())?;
        self.gear.set_command(self.command);
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.params.validate().map_err(|e| e.to_string())?;
        self.gear.params = self.params.clone();
        self.gear.set_command(self.command);
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.gear.set_command(self.command);
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.gear.step(self.command, h);
        Ok(())
    }
}

export_fmu!(SteeringGearFmu);
