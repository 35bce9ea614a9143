//! `NomotoShip` FMU: the linear manoeuvring models of the DDG-51 thesis
//! (`models::hull::nomoto`): the DDG-51 first-order Nomoto model and the linear sway-yaw model
//! with Esso Osaka coefficients, as an FMI 2.0 co-simulation FMU. No physics here: the variable
//! table maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::hull::nomoto::{NomotoInputs, NomotoModel, NomotoOutputs, NomotoShip};
use models::hull::DEG;
use models::steering_gear::ParamError;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NomotoShipFmu {
    /// 1: DDG-51 first-order Nomoto; 2: linear sway-yaw (Esso Osaka coefficients).
    model: i32,
    t_prime: f64,
    k_prime: f64,
    m: [[f64; 2]; 2],
    n: [[f64; 2]; 2],
    b: [f64; 2],
    /// 0: the preset's value.
    length: f64,
    /// 0: the preset's value.
    speed: f64,
    max_substep: f64,
    inputs: NomotoInputs,
    ship: NomotoShip,
}

/// Start value of `rudder_angle`: a small starboard rudder so that the default experiment turns.
pub const DEFAULT_RUDDER_ANGLE: f64 = 5.0 * DEG;

impl Default for NomotoShipFmu {
    fn default() -> Self {
        let ddg = NomotoShip::ddg51();
        let (t_prime, k_prime) = match ddg.model {
            NomotoModel::FirstOrder { t, k } => (t, k),
            NomotoModel::SwayYaw { .. } => unreachable!("ddg51 is first order"),
        };
        let (m, n, b) = match NomotoShip::esso_osaka().model {
            NomotoModel::SwayYaw { m, n, b } => (m, n, b),
            NomotoModel::FirstOrder { .. } => unreachable!("esso_osaka is sway-yaw"),
        };
        NomotoShipFmu {
            model: 1,
            t_prime,
            k_prime,
            m,
            n,
            b,
            length: 0.0,
            speed: 0.0,
            max_substep: ddg.max_substep,
            inputs: NomotoInputs {
                rudder: DEFAULT_RUDDER_ANGLE,
                ..Default::default()
            },
            ship: ddg,
        }
    }
}

/// A model error with the model's parameter name replaced by the FMU variable's name.
fn param_error(e: ParamError) -> String {
    let name = match e.name {
        "t" => "t_prime",
        "k" => "k_prime",
        other => other,
    };
    format!("parameter {name} = {} {}", e.value, e.rule)
}

impl NomotoShipFmu {
    fn out(&self) -> NomotoOutputs {
        self.ship.outputs()
    }

    /// Builds the ship from the parameters (the preset gives length and speed when they are 0).
    pub fn build(&self) -> Result<NomotoShip, String> {
        let (preset, model) = match self.model {
            1 => (
                NomotoShip::ddg51(),
                NomotoModel::FirstOrder {
                    t: self.t_prime,
                    k: self.k_prime,
                },
            ),
            2 => (
                NomotoShip::esso_osaka(),
                NomotoModel::SwayYaw {
                    m: self.m,
                    n: self.n,
                    b: self.b,
                },
            ),
            v => return Err(format!("parameter model = {v} must be 1 or 2")),
        };
        let length = if self.length == 0.0 {
            preset.length
        } else {
            self.length
        };
        let speed = if self.speed == 0.0 {
            preset.speed
        } else {
            self.speed
        };
        let mut ship = NomotoShip::new(model, length, speed).map_err(param_error)?;
        if !(self.max_substep.is_finite() && self.max_substep > 0.0) {
            return Err(format!(
                "parameter max_substep = {} must be finite and > 0",
                self.max_substep
            ));
        }
        ship.max_substep = self.max_substep;
        Ok(ship)
    }
}

type V = Variable<NomotoShipFmu>;

static VARIABLES: &[V] = &[
    V::integer_parameter(
        "model",
        false,
        "1: DDG-51 first-order Nomoto model T' r'' + r' = K' delta (eq. 5.24), L = 466 ft, 22 kn; \
         2: linear sway-yaw model M nu'' + N nu' = b delta with the Esso Osaka coefficients (Table 2.3 \
         and the documented assumptions), L = 1066.3 ft, 10 kn",
        1,
        2,
        |m| m.model,
        |m, v| m.model = v,
    ),
    V::real_parameter(
        "t_prime",
        None,
        false,
        "Model 1: nondimensional Nomoto time constant T' (eq. 5.25: 1.9287)",
        |m| m.t_prime,
        |m, v| m.t_prime = v,
    ),
    V::real_parameter(
        "k_prime",
        None,
        false,
        "Model 1: nondimensional Nomoto gain K' (eq. 5.26: 2.04)",
        |m| m.k_prime,
        |m, v| m.k_prime = v,
    ),
    V::real_parameter(
        "m11",
        None,
        false,
        "Model 2: mass matrix M, entry m11 = m' - Y'_vdot (prime system)",
        |m| m.m[0][0],
        |m, v| m.m[0][0] = v,
    ),
    V::real_parameter(
        "m12",
        None,
        false,
        "Model 2: mass matrix M, entry m12 = m'x'_G - Y'_rdot (prime system)",
        |m| m.m[0][1],
        |m, v| m.m[0][1] = v,
    ),
    V::real_parameter(
        "m21",
        None,
        false,
        "Model 2: mass matrix M, entry m21 = m'x'_G - N'_vdot (prime system)",
        |m| m.m[1][0],
        |m, v| m.m[1][0] = v,
    ),
    V::real_parameter(
        "m22",
        None,
        false,
        "Model 2: mass matrix M, entry m22 = I'_z - N'_rdot (prime system)",
        |m| m.m[1][1],
        |m, v| m.m[1][1] = v,
    ),
    V::real_parameter(
        "n11",
        None,
        false,
        "Model 2: damping matrix N (one of the four hull coefficients of Table 2.3), entry n11 = -Y'_v (prime system)",
        |m| m.n[0][0],
        |m, v| m.n[0][0] = v,
    ),
    V::real_parameter(
        "n12",
        None,
        false,
        "Model 2: damping matrix N (one of the four hull coefficients of Table 2.3), entry n12 = m' - Y'_r (prime system)",
        |m| m.n[0][1],
        |m, v| m.n[0][1] = v,
    ),
    V::real_parameter(
        "n21",
        None,
        false,
        "Model 2: damping matrix N (one of the four hull coefficients of Table 2.3), entry n21 = -N'_v (prime system)",
        |m| m.n[1][0],
        |m, v| m.n[1][0] = v,
    ),
    V::real_parameter(
        "n22",
        None,
        false,
        "Model 2: damping matrix N (one of the four hull coefficients of Table 2.3), entry n22 = m'x'_G - N'_r (prime system)",
        |m| m.n[1][1],
        |m, v| m.n[1][1] = v,
    ),
    V::real_parameter(
        "b1",
        None,
        false,
        "Model 2: rudder vector entry b1 = Y'_delta (prime system, per rad)",
        |m| m.b[0],
        |m, v| m.b[0] = v,
    ),
    V::real_parameter(
        "b2",
        None,
        false,
        "Model 2: rudder vector entry b2 = N'_delta (prime system, per rad)",
        |m| m.b[1],
        |m, v| m.b[1] = v,
    ),
    V::real_parameter(
        "length",
        Some("m"),
        false,
        "Reference length L; 0 (default): the preset's (model 1: 466 ft = 142.04 m; model 2: \
         1066.3 ft = 325.01 m)",
        |m| m.length,
        |m, v| m.length = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "speed",
        Some("m/s"),
        false,
        "Ship speed U (time scale L/U and kinematics); 0 (default): the preset's (model 1: 22 kn = \
         11.32 m/s; model 2: 10 kn = 5.14 m/s)",
        |m| m.speed,
        |m, v| m.speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "max_substep",
        Some("s"),
        false,
        "Largest RK4 sub-step (default 0.1 s)",
        |m| m.max_substep,
        |m, v| m.max_substep = v,
    )
    .with_range(Some(0.0), None),
    V::real_input(
        "rudder_angle",
        Some("rad"),
        "Actual rudder angle delta (positive: starboard turn, K' > 0); start value 5 deg",
        |m| m.inputs.rudder,
        |m, v| m.inputs.rudder = v,
    ),
    V::real_input(
        "current_speed",
        Some("m/s"),
        "Current speed, an earth-fixed velocity added to the kinematics",
        |m| m.inputs.current_speed,
        |m, v| m.inputs.current_speed = v,
    ),
    V::real_input(
        "current_direction",
        Some("rad"),
        "Direction the current flows toward, from north, clockwise",
        |m| m.inputs.current_direction,
        |m, v| m.inputs.current_direction = v,
    ),
    V::real_input(
        "yaw_disturbance",
        Some("rad"),
        "Rudder-equivalent environmental disturbance delta_w added to the rudder in the \
         dynamics (T' r'' + r' = K'(delta + delta_w)); e.g. Waves.yaw_moment through a \
         converting connection gain. The thesis does not say how its sea-state-4 disturbance \
         enters the hull (spec section 2.18)",
        |m| m.inputs.yaw_disturbance,
        |m, v| m.inputs.yaw_disturbance = v,
    ),
    V::real_output(
        "sway_velocity",
        Some("m/s"),
        "Sway velocity v = v' U (0 for model 1)",
        |m| m.out().sway_velocity,
    ),
    V::real_output(
        "sway_velocity_prime",
        None,
        "Prime-system sway v' = v/U",
        |m| m.out().v_prime,
    ),
    V::real_output("yaw_rate", Some("rad/s"), "Yaw rate r", |m| m.out().yaw_rate),
    V::real_output(
        "yaw_rate_prime",
        None,
        "Prime-system yaw rate r' = rL/U",
        |m| m.out().r_prime,
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
        "speed_over_ground",
        Some("m/s"),
        "sqrt(U^2 + v^2) (through the water; the current is not included)",
        |m| m.out().speed_over_ground,
    ),
    V::real_output(
        "time_prime",
        None,
        "Nondimensional time t' = tU/L since the start",
        |m| m.out().time_prime,
    ),
];

impl FmuModel for NomotoShipFmu {
    const MODEL_IDENTIFIER: &'static str = "NomotoShip";
    /// Every output is a function of the state: no direct feedthrough from the inputs.
    const DIRECT_FEEDTHROUGH: bool = false;
    const DESCRIPTION: &'static str = "Linear manoeuvring models of the DDG-51 EKF thesis (2000): \
        the DDG-51 first-order Nomoto model and the linear sway-yaw model with Esso Osaka \
        coefficients, with position kinematics and current";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 300.0,
        step_size: 0.1,
    };

    fn variables() -> &'static [Variable<Self>] {
        VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.ship = self.build()?;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.ship.step(&self.inputs, h);
        Ok(())
    }
}

export_fmu!(NomotoShipFmu);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_fmu_parameter_and_value() {
        let mut m = NomotoShipFmu {
            t_prime: -1.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("t_prime = -1"), "{e}");
        let mut m = NomotoShipFmu {
            model: 2,
            m: [[0.0; 2]; 2],
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("m (determinant) = 0"), "{e}");
        let mut m = NomotoShipFmu {
            length: -3.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("length = -3"), "{e}");
    }

    #[test]
    fn presets_are_the_models_presets() {
        let mut m = NomotoShipFmu::default();
        m.initialize(0.0).unwrap();
        assert_eq!(m.ship, NomotoShip::ddg51());
        m.model = 2;
        m.initialize(0.0).unwrap();
        assert_eq!(m.ship, NomotoShip::esso_osaka());
    }
}
