//! `RrsShip` FMU: van der Klugt's RRS ship (`models::hull::rrs_ship`), the 22-knot simulation
//! model and the speed-dependent fifth-order control model, as an FMI 2.0 co-simulation FMU.
//! No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::hull::rrs_ship::{RrsShip, RrsShipInputs, RrsShipOutputs, U_22KN};
use models::hull::DEG;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one RRS-ship instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RrsShipFmu {
    /// 1: simulation model (Tables 2.1/2.2); 2: control model, Table 2.4; 3: control model,
    /// Table 2.5.
    model: i32,
    min_speed: f64,
    max_substep: f64,
    inputs: RrsShipInputs,
    /// Second disturbance channel (e.g. wind, eqs. 2.19-2.20), added to the first: w_φ and w_ψ
    /// of eq. 3.29 are the sums of all rudder-equivalent disturbances.
    wind_roll: f64,
    wind_yaw: f64,
    ship: RrsShip,
}

/// Start value of `rudder_angle`: a small rudder so that the default experiment turns and rolls.
pub const DEFAULT_RUDDER_ANGLE: f64 = 5.0 * DEG;

impl Default for RrsShipFmu {
    fn default() -> Self {
        let ship = RrsShip::simulation_22kn();
        RrsShipFmu {
            model: 1,
            min_speed: ship.min_speed,
            max_substep: ship.max_substep,
            inputs: RrsShipInputs {
                rudder: DEFAULT_RUDDER_ANGLE,
                speed: U_22KN,
                ..Default::default()
            },
            wind_roll: 0.0,
            wind_yaw: 0.0,
            ship,
        }
    }
}

impl RrsShipFmu {
    fn out(&self) -> RrsShipOutputs {
        self.ship.outputs()
    }

    fn check(&self) -> Result<(), String> {
        for (name, v) in [
            ("min_speed", self.min_speed),
            ("max_substep", self.max_substep),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("parameter {name} = {v} must be finite and > 0"));
            }
        }
        Ok(())
    }
}

type V = Variable<RrsShipFmu>;

static VARIABLES: &[V] = &[
    V::integer_parameter(
        "model",
        false,
        "1: 22-knot simulation model of Fig. 2.5 (Tables 2.1 and 2.2, wave-height-driven filters); \
         2: speed-dependent fifth-order control model of Fig. 2.6 with the Table 2.3 laws and the \
         Table 2.4 constants; 3: the control model with the Table 2.5 (+-20 deg rudder) constants",
        1,
        3,
        |m| m.model,
        |m, v| m.model = v,
    ),
    V::real_parameter(
        "min_speed",
        Some("m/s"),
        true,
        "Speed floor for the control-model speed laws (default 1 m/s; the thesis extrapolates to 2 m/s)",
        |m| m.min_speed,
        |m, v| m.min_speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "max_substep",
        Some("s"),
        false,
        "Largest RK4 sub-step (default 0.05 s; the fastest pole is about 1.2 rad/s)",
        |m| m.max_substep,
        |m, v| m.max_substep = v,
    )
    .with_range(Some(0.0), None),
    V::real_input(
        "rudder_angle",
        Some("rad"),
        "Actual rudder angle delta_w (from SteeringGear.rudder_angle); sign convention of 003: \
         r/delta < 0 at DC; start value 5 deg",
        |m| m.inputs.rudder,
        |m, v| m.inputs.rudder = v,
    ),
    V::real_input(
        "speed",
        Some("m/s"),
        "Ship speed U: evaluates the control-model speed laws (held over the step) and drives the \
         position kinematics; the simulation model is valid at 22 kn only (start value 11.32 m/s)",
        |m| m.inputs.speed,
        |m, v| m.inputs.speed = v,
    ),
    V::real_input(
        "roll_disturbance",
        Some("rad"),
        "Rudder-equivalent roll disturbance w_phi (eq. 3.29), entering as omega_n^2 w_phi",
        |m| m.inputs.roll_disturbance,
        |m, v| m.inputs.roll_disturbance = v,
    ),
    V::real_input(
        "yaw_disturbance",
        Some("rad"),
        "Rudder-equivalent yaw disturbance w_psi (eq. 3.29), entering as w_psi/tau_r",
        |m| m.inputs.yaw_disturbance,
        |m, v| m.inputs.yaw_disturbance = v,
    ),
    V::real_input(
        "wave_elevation",
        Some("m"),
        "Wave height w driving the Table 2.2 filters (model 1 only; e.g. Waves.wave_elevation)",
        |m| m.inputs.wave_elevation,
        |m, v| m.inputs.wave_elevation = v,
    ),
    V::real_output("roll", Some("rad"), "Roll angle phi", |m| m.out().roll),
    V::real_output(
        "roll_rate",
        Some("rad/s"),
        "Roll rate p",
        |m| m.out().roll_rate,
    ),
    V::real_output(
        "sway",
        None,
        "Sway state v (model 1) or v' (models 2, 3: the sway due to the rudder, x3 of eq. 3.29), in \
         the model's own scale, not m/s (Table 2.4 fixes K_dv0 = 0.01)",
        |m| m.out().sway,
    ),
    V::real_output("yaw_rate", Some("rad/s"), "Yaw rate r", |m| m.out().yaw_rate),
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
    V::real_output(
        "x",
        Some("m"),
        "North position, x' = U cos(psi) (sway neglected: the thesis has no position)",
        |m| m.out().x,
    ),
    V::real_output(
        "y",
        Some("m"),
        "East position, y' = U sin(psi)",
        |m| m.out().y,
    ),
    V::real_output(
        "wave_sway",
        None,
        "Wave-induced sway contribution y_wv (model 1; model units)",
        |m| m.out().wave_sway,
    ),
    V::real_output(
        "wave_yaw",
        None,
        "Wave-induced yaw contribution y_wr (model 1; model units)",
        |m| m.out().wave_yaw,
    ),
    V::real_output(
        "wave_roll",
        None,
        "Wave-induced roll contribution y_wp (model 1; rudder-equivalent, model units)",
        |m| m.out().wave_roll,
    ),
    V::real_input(
        "wind_roll_disturbance",
        Some("rad"),
        "Second rudder-equivalent roll disturbance (e.g. the wind moment of eq. 2.19), added to \
         roll_disturbance",
        |m| m.wind_roll,
        |m, v| m.wind_roll = v,
    ),
    V::real_input(
        "wind_yaw_disturbance",
        Some("rad"),
        "Second rudder-equivalent yaw disturbance (e.g. the wind moment of eq. 2.20), added to \
         yaw_disturbance",
        |m| m.wind_yaw,
        |m, v| m.wind_yaw = v,
    ),
];

impl FmuModel for RrsShipFmu {
    const MODEL_IDENTIFIER: &'static str = "RrsShip";
    /// Every output is a function of the state: no direct feedthrough from the inputs.
    const DIRECT_FEEDTHROUGH: bool = false;
    const DESCRIPTION: &'static str = "Van der Klugt (1987) rudder-roll-stabilisation ship: the \
        22-knot simulation model with wave-height-driven filters (Tables 2.1, 2.2) and the \
        speed-dependent fifth-order control model (Tables 2.3-2.5)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 300.0,
        step_size: 0.05,
    };

    fn variables() -> &'static [Variable<Self>] {
        VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.check()?;
        let mut ship = match self.model {
            1 => RrsShip::simulation_22kn(),
            2 => RrsShip::control_model(),
            3 => RrsShip::control_model_table_2_5(),
            v => return Err(format!("parameter model = {v} must be 1, 2 or 3")),
        };
        ship.min_speed = self.min_speed;
        ship.max_substep = self.max_substep;
        self.ship = ship;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.check()?;
        self.ship.min_speed = self.min_speed;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        let mut inputs = self.inputs;
        inputs.roll_disturbance += self.wind_roll;
        inputs.yaw_disturbance += self.wind_yaw;
        self.ship.step(&inputs, h);
        Ok(())
    }
}

export_fmu!(RrsShipFmu);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_fmu_parameter_and_value() {
        let mut m = RrsShipFmu {
            max_substep: 0.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("max_substep = 0"), "{e}");
        let mut m = RrsShipFmu {
            model: 4,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("model = 4"), "{e}");
    }
}
