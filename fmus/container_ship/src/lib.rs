//! `ContainerShip` FMU: the Son & Nomoto (1982) nonlinear roll-coupled container ship of
//! `models::hull::container_ship` (and its linearisation as a variant) as an FMI 2.0
//! co-simulation FMU. No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::hull::container_ship::{
    ContainerShip, ContainerShipInputs, ContainerShipOutputs, ContainerShipParams,
    LinearContainerShip, LinearContainerShipInputs, PropellerInflow,
};
use models::hull::DEG;
use models::steering_gear::ParamError;
use serde::{Deserialize, Serialize};

/// The hull in use: the nonlinear model (variant 1) or the linearised model (variant 2).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Hull {
    Nonlinear(ContainerShip),
    Linear(LinearContainerShip),
}

/// Parameters, inputs and state of one container-ship instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ContainerShipFmu {
    /// 1: nonlinear (spec section 2), 2: linearised (section 4).
    variant: i32,
    params: ContainerShipParams,
    /// U0 of the linearised model [m/s].
    nominal_speed: f64,
    mss_speed: bool,
    start_at_equilibrium: bool,
    initial_surge_velocity: f64,
    initial_shaft_speed: f64,
    /// Initial sway velocity v [m/s] (variant 1).
    initial_sway_velocity: f64,
    inputs: ContainerShipInputs,
    hull: Hull,
}

/// Start value of `rudder_command`: a small starboard rudder so that the default experiment turns.
pub const DEFAULT_RUDDER_COMMAND: f64 = 5.0 * DEG;
/// Start value of the shaft speed (initial and commanded) [rpm]: the MSS manoeuvres' 80 rpm.
pub const DEFAULT_SHAFT_SPEED: f64 = 80.0;

impl Default for ContainerShipFmu {
    fn default() -> Self {
        let ship = ContainerShip::at_equilibrium(DEFAULT_SHAFT_SPEED).expect("valid preset");
        ContainerShipFmu {
            variant: 1,
            params: ContainerShipParams::default(),
            nominal_speed: 7.0,
            mss_speed: false,
            start_at_equilibrium: true,
            initial_surge_velocity: 8.0,
            initial_shaft_speed: DEFAULT_SHAFT_SPEED,
            initial_sway_velocity: 0.0,
            inputs: ContainerShipInputs {
                rudder_command: DEFAULT_RUDDER_COMMAND,
                shaft_command_rpm: DEFAULT_SHAFT_SPEED,
                ..Default::default()
            },
            hull: Hull::Nonlinear(ship),
        }
    }
}

/// A model error with the model's parameter name replaced by the FMU variable's name.
fn param_error(e: ParamError) -> String {
    let name = match e.name {
        "u" => "initial_surge_velocity",
        "n_rpm" => "initial_shaft_speed",
        "u0" => "nominal_speed",
        other => other,
    };
    format!("parameter {name} = {} {}", e.value, e.rule)
}

impl ContainerShipFmu {
    fn out(&self) -> ContainerShipOutputs {
        match &self.hull {
            Hull::Nonlinear(s) => s.outputs(),
            Hull::Linear(s) => s.outputs(),
        }
    }

    /// Builds the hull from the parameters (exactly as `ContainerShip::new` /
    /// `LinearContainerShip::new` with the parameter values).
    pub fn build(&self) -> Result<Hull, String> {
        self.params.validate().map_err(param_error)?;
        match self.variant {
            1 => {
                let n = self.initial_shaft_speed;
                if !(n.is_finite() && n > 0.0) {
                    return Err(format!(
                        "parameter initial_shaft_speed = {n} must be finite and > 0"
                    ));
                }
                let u = if self.start_at_equilibrium {
                    ContainerShip::straight_line_speed(n)
                } else {
                    self.initial_surge_velocity
                };
                let v = self.initial_sway_velocity;
                if !v.is_finite() {
                    return Err(format!(
                        "parameter initial_sway_velocity = {v} must be finite"
                    ));
                }
                let ship = ContainerShip::new(
                    self.params.clone(),
                    [u, v, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, n],
                )
                .map_err(param_error)?;
                Ok(Hull::Nonlinear(ship))
            }
            2 => {
                let mut ship = LinearContainerShip::new(self.nominal_speed).map_err(param_error)?;
                ship.mss_speed = self.mss_speed;
                ship.rudder_max = self.params.rudder_max;
                ship.rudder_rate_max = self.params.rudder_rate_max;
                ship.max_substep = self.params.max_substep;
                Ok(Hull::Linear(ship))
            }
            v => Err(format!("parameter variant = {v} must be 1 or 2")),
        }
    }
}

type V = Variable<ContainerShipFmu>;

static VARIABLES: &[V] = &[
    V::integer_parameter(
        "variant",
        false,
        "1: nonlinear 4-DOF Son & Nomoto model (container_ship.md section 2); 2: linearised model \
         (section 4, MSS Lcontainer.m; no shaft, u = nominal_speed)",
        1,
        2,
        |m| m.variant,
        |m, v| m.variant = v,
    ),
    V::real_parameter(
        "rudder_max",
        Some("rad"),
        true,
        "Rudder command saturation (section 2.6: 10 deg; exRRD2.m: 20 deg)",
        |m| m.params.rudder_max,
        |m, v| m.params.rudder_max = v,
    )
    .with_range(Some(0.0), Some(std::f64::consts::PI)),
    V::real_parameter(
        "rudder_rate_max",
        Some("rad/s"),
        true,
        "Rudder rate limit of the built-in servo (section 2.6: 5 deg/s; exRRD2.m: 20 deg/s)",
        |m| m.params.rudder_rate_max,
        |m, v| m.params.rudder_rate_max = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "shaft_max_rpm",
        Some("rpm"),
        true,
        "Shaft speed command upper limit (section 2.6: 160 rpm; variant 1)",
        |m| m.params.shaft_max_rpm,
        |m, v| m.params.shaft_max_rpm = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "shaft_min_rpm",
        Some("rpm"),
        true,
        "Shaft speed command lower clamp, a validity guard not in the source (default 1 rpm; variant 1)",
        |m| m.params.shaft_min_rpm,
        |m, v| m.params.shaft_min_rpm = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "gm",
        Some("m"),
        true,
        "Metacentric height GM (section 2.2: 0.3 m; variant 1)",
        |m| m.params.gm,
        |m, v| m.params.gm = v,
    )
    .with_range(Some(0.0), None),
    V::integer_parameter(
        "propeller_inflow",
        false,
        "Propeller inflow u'_P (section 2.7): 1 = u' [(1 - w_p) + tau(...)] (MSS since 2022, \
         default); 2 = cos(v') [...] (pre-2022, exRRD2.m)",
        1,
        2,
        |m| match m.params.propeller_inflow {
            PropellerInflow::Current => 1,
            PropellerInflow::Pre2022Cos => 2,
        },
        |m, v| {
            m.params.propeller_inflow = if v == 2 {
                PropellerInflow::Pre2022Cos
            } else {
                PropellerInflow::Current
            }
        },
    ),
    V::real_parameter(
        "min_speed",
        Some("m/s"),
        false,
        "Speed floor of the nondimensionalisation, a validity guard not in the source (default 0.1 m/s)",
        |m| m.params.min_speed,
        |m, v| m.params.min_speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "max_substep",
        Some("s"),
        false,
        "Largest RK4 sub-step (section 8: <= 0.05 s)",
        |m| m.params.max_substep,
        |m, v| m.params.max_substep = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "start_at_equilibrium",
        false,
        "Variant 1: start on the straight-line equilibrium of initial_shaft_speed (section 2.9, \
         u in closed form); false: start with u = initial_surge_velocity",
        |m| m.start_at_equilibrium,
        |m, v| m.start_at_equilibrium = v,
    ),
    V::real_parameter(
        "initial_surge_velocity",
        Some("m/s"),
        false,
        "Variant 1: initial surge velocity u when start_at_equilibrium = false (MSS exTurnCircle.m: 8 m/s)",
        |m| m.initial_surge_velocity,
        |m, v| m.initial_surge_velocity = v,
    ),
    V::real_parameter(
        "initial_shaft_speed",
        Some("rpm"),
        false,
        "Variant 1: initial shaft speed n (> 0); with start_at_equilibrium also the equilibrium \
         speed (70 rpm: 7.32959 m/s, 80 rpm: 8.37667 m/s)",
        |m| m.initial_shaft_speed,
        |m, v| m.initial_shaft_speed = v,
    ),
    V::real_parameter(
        "initial_sway_velocity",
        Some("m/s"),
        false,
        "Variant 1: initial sway velocity v (to starboard; default 0). The DDG-51 thesis applies its \
         5-kn current to the autopilot runs this way (spec ddg51_ekf_autopilot.md section 2.18)",
        |m| m.initial_sway_velocity,
        |m, v| m.initial_sway_velocity = v,
    ),
    V::real_parameter(
        "nominal_speed",
        Some("m/s"),
        false,
        "Variant 2: speed U0 of the linearised model (section 4.1: 7.0 m/s)",
        |m| m.nominal_speed,
        |m, v| m.nominal_speed = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "mss_speed",
        false,
        "Variant 2: U = sqrt(U0^2 + v^2) as MSS Lcontainer.m (false: strictly linear U = U0)",
        |m| m.mss_speed,
        |m, v| m.mss_speed = v,
    ),
    V::real_input(
        "rudder_command",
        Some("rad"),
        "Commanded rudder angle delta_c (positive: starboard turn), through the built-in servo \
         (saturation rudder_max, rate rudder_rate_max, time constant 1 s); start value 5 deg",
        |m| m.inputs.rudder_command,
        |m, v| m.inputs.rudder_command = v,
    ),
    V::real_input(
        "shaft_speed_command",
        Some("rpm"),
        "Commanded shaft speed n_c (variant 1; clamped to [shaft_min_rpm, shaft_max_rpm])",
        |m| m.inputs.shaft_command_rpm,
        |m, v| m.inputs.shaft_command_rpm = v,
    ),
    V::real_input(
        "sway_force",
        Some("N"),
        "External sway force, body y to starboard (variant 1; added to Y' / (0.5 rho L^2 U^2))",
        |m| m.inputs.sway_force_ext,
        |m, v| m.inputs.sway_force_ext = v,
    ),
    V::real_input(
        "roll_moment",
        Some("N.m"),
        "External roll moment, positive starboard down (variant 1; e.g. Waves.roll_moment)",
        |m| m.inputs.roll_moment_ext,
        |m, v| m.inputs.roll_moment_ext = v,
    ),
    V::real_input(
        "yaw_moment",
        Some("N.m"),
        "External yaw moment, positive to starboard (variant 1; e.g. Waves.yaw_moment)",
        |m| m.inputs.yaw_moment_ext,
        |m, v| m.inputs.yaw_moment_ext = v,
    ),
    V::real_output(
        "surge_velocity",
        Some("m/s"),
        "Surge velocity u (variant 2: U0)",
        |m| m.out().u,
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
        "roll_rate",
        Some("rad/s"),
        "Roll rate p",
        |m| m.out().p,
    ),
    V::real_output(
        "roll",
        Some("rad"),
        "Roll angle phi (positive starboard down; outward heel phi < 0 in a starboard turn)",
        |m| m.out().roll,
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
        "Actual rudder angle delta (servo output)",
        |m| m.out().rudder,
    ),
    V::real_output(
        "shaft_speed",
        Some("rpm"),
        "Actual shaft speed n (variant 2: 0)",
        |m| m.out().shaft_rpm,
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
        "sway_velocity_prime",
        None,
        "Prime-system sway v' = v/U",
        |m| m.out().v_prime,
    ),
    V::real_output(
        "yaw_rate_prime",
        None,
        "Prime-system yaw rate r' = r L/U (L = 175 m)",
        |m| m.out().r_prime,
    ),
    V::real_output(
        "roll_rate_prime",
        None,
        "Prime-system roll rate p' = p L/U",
        |m| m.out().p_prime,
    ),
    V::boolean_output(
        "outside_validity",
        "Variant 1: a validity guard is active (U < min_speed or n < shaft_min_rpm; MSS would stop)",
        |m| match &m.hull {
            Hull::Nonlinear(s) => s.outside_validity(),
            Hull::Linear(_) => false,
        },
    ),
];

impl ContainerShipFmu {
    /// The linear-model inputs derived from the FMU inputs (only the rudder command is used).
    fn linear_inputs(&self) -> LinearContainerShipInputs {
        LinearContainerShipInputs {
            rudder_command: self.inputs.rudder_command,
        }
    }
}

impl FmuModel for ContainerShipFmu {
    const MODEL_IDENTIFIER: &'static str = "ContainerShip";
    /// Every output is a function of the state: no direct feedthrough from the inputs.
    const DIRECT_FEEDTHROUGH: bool = false;
    const DESCRIPTION: &'static str = "Son & Nomoto (1982) high-speed container ship: nonlinear \
        roll-coupled surge-sway-yaw-roll manoeuvring model with rudder and shaft servos (MSS \
        container.m), or its linearisation (Lcontainer.m)";
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
        self.hull = self.build()?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.params.validate().map_err(param_error)?;
        match &mut self.hull {
            Hull::Nonlinear(s) => s.params = self.params.clone(),
            Hull::Linear(s) => {
                s.rudder_max = self.params.rudder_max;
                s.rudder_rate_max = self.params.rudder_rate_max;
            }
        }
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        let lin = self.linear_inputs();
        match &mut self.hull {
            Hull::Nonlinear(s) => s.step(&self.inputs, h),
            Hull::Linear(s) => s.step(&lin, h),
        }
        Ok(())
    }
}

export_fmu!(ContainerShipFmu);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_fmu_parameter_and_value() {
        let mut m = ContainerShipFmu {
            initial_shaft_speed: -1.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("initial_shaft_speed = -1"), "{e}");
        m.initial_shaft_speed = 70.0;
        m.start_at_equilibrium = false;
        m.initial_surge_velocity = 0.0;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("initial_surge_velocity = 0"), "{e}");
        m.params.rudder_max = -0.1;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("rudder_max = -0.1"), "{e}");
        let mut m = ContainerShipFmu {
            variant: 2,
            nominal_speed: 0.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("nominal_speed = 0"), "{e}");
    }
}
