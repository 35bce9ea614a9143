//! `NomotoShip` FMU: the linear manoeuvring models of the DDG-51 thesis
//! (`models::hull::nomoto`): the DDG-51 first-order Nomoto model and the linear sway-yaw model
//! with Esso Osaka coefficients, as an FMI 2.0 co-simulation FMU. No physics here: the variable
//! table maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::error::{check_positive, ParamError};
use models::hull::nomoto::{NomotoInputs, NomotoModel, NomotoOutputs, NomotoShip};
use models::hull::DEG;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NomotoShipFmu {
    /// 1: DDG-51 first-order Nomoto; 2: linear sway-yaw (Esso Osaka coefficients).
    model: i32,
    t_prime: f64,
    k_prime: f64,
    mass: [[f64; 2]; 2],
    damping: [[f64; 2]; 2],
    rudder: [f64; 2],
    /// 0: the preset's value.
    length: f64,
    /// 0: the preset's value.
    speed: f64,
    max_substep: f64,
    inputs: NomotoInputs,
    ship: NomotoShip,
    /// The model's outputs, computed once wherever the model changes (initialize, do_step,
    /// calculate_outputs) instead of in every getter; `None` (after a deserialized restore)
    /// means compute them. Not part of the state.
    #[serde(skip)]
    outputs: Option<NomotoOutputs>,
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
        let (mass, damping, rudder) = match NomotoShip::esso_osaka().model {
            NomotoModel::SwayYaw { m, n, b } => (m, n, b),
            NomotoModel::FirstOrder { .. } => unreachable!("esso_osaka is sway-yaw"),
        };
        NomotoShipFmu {
            model: 1,
            t_prime,
            k_prime,
            mass,
            damping,
            rudder,
            length: 0.0,
            speed: 0.0,
            max_substep: ddg.max_substep,
            inputs: NomotoInputs {
                rudder: DEFAULT_RUDDER_ANGLE,
                ..Default::default()
            },
            ship: ddg,
            outputs: None,
        }
    }
}

/// A model error with the model's parameter name replaced by the FMU variable's name.
fn param_error(e: ParamError) -> String {
    e.renamed(&[("t", "t_prime"), ("k", "k_prime")]).to_string()
}

impl NomotoShipFmu {
    fn model_outputs(&self) -> NomotoOutputs {
        self.ship.outputs()
    }

    fn out(&self) -> NomotoOutputs {
        self.outputs.unwrap_or_else(|| self.model_outputs())
    }

    /// Keeps the outputs of the model as it is now (the getters read them).
    fn keep_outputs(&mut self) {
        self.outputs = Some(self.model_outputs());
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
                    m: self.mass,
                    n: self.damping,
                    b: self.rudder,
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
        check_positive("max_substep", self.max_substep)?;
        ship.max_substep = self.max_substep;
        Ok(ship)
    }
}

fmi2_export::fmu! {
    NomotoShipFmu => "NomotoShip",
    description: "Linear manoeuvring models of the DDG-51 EKF thesis (2000): \
        the DDG-51 first-order Nomoto model and the linear sway-yaw model with Esso Osaka \
        coefficients, with position kinematics and current",
    experiment: (0.0, 300.0, 0.1),
    // Every output is a function of the state: no direct feedthrough from the inputs.
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        fixed int(1, 2) "model" (model),
            "1: DDG-51 first-order Nomoto model T' r'' + r' = K' delta (eq. 5.24), L = 466 ft, 22 kn; \
             2: linear sway-yaw model M nu'' + N nu' = b delta with the Esso Osaka coefficients (Table 2.3 \
             and the documented assumptions), L = 1066.3 ft, 10 kn";
        fixed real "t_prime" (t_prime),
            "Model 1: nondimensional Nomoto time constant T' (eq. 5.25: 1.9287)";
        fixed real "k_prime" (k_prime), "Model 1: nondimensional Nomoto gain K' (eq. 5.26: 2.04)";
        fixed real "m11" (mass[0][0]),
            "Model 2: mass matrix M, entry m11 = m' - Y'_vdot (prime system)";
        fixed real "m12" (mass[0][1]),
            "Model 2: mass matrix M, entry m12 = m'x'_G - Y'_rdot (prime system)";
        fixed real "m21" (mass[1][0]),
            "Model 2: mass matrix M, entry m21 = m'x'_G - N'_vdot (prime system)";
        fixed real "m22" (mass[1][1]),
            "Model 2: mass matrix M, entry m22 = I'_z - N'_rdot (prime system)";
        fixed real "n11" (damping[0][0]),
            "Model 2: damping matrix N (one of the four hull coefficients of Table 2.3), entry n11 = -Y'_v (prime system)";
        fixed real "n12" (damping[0][1]),
            "Model 2: damping matrix N (one of the four hull coefficients of Table 2.3), entry n12 = m' - Y'_r (prime system)";
        fixed real "n21" (damping[1][0]),
            "Model 2: damping matrix N (one of the four hull coefficients of Table 2.3), entry n21 = -N'_v (prime system)";
        fixed real "n22" (damping[1][1]),
            "Model 2: damping matrix N (one of the four hull coefficients of Table 2.3), entry n22 = m'x'_G - N'_r (prime system)";
        fixed real "b1" (rudder[0]), "Model 2: rudder vector entry b1 = Y'_delta (prime system, per rad)";
        fixed real "b2" (rudder[1]), "Model 2: rudder vector entry b2 = N'_delta (prime system, per rad)";
        fixed real "length" ["m"] (length).min(0.0),
            "Reference length L; 0 (default): the preset's (model 1: 466 ft = 142.04 m; model 2: \
             1066.3 ft = 325.01 m)";
        fixed real "speed" ["m/s"] (speed).min(0.0),
            "Ship speed U (time scale L/U and kinematics); 0 (default): the preset's (model 1: 22 kn = \
             11.32 m/s; model 2: 10 kn = 5.14 m/s)";
        fixed real "max_substep" ["s"] (max_substep).min(0.0), "Largest RK4 sub-step (default 0.1 s)";
        input real "rudder_angle" ["rad"] (inputs.rudder),
            "Actual rudder angle delta (positive: starboard turn, K' > 0); start value 5 deg";
        input real "current_speed" ["m/s"] (inputs.current_speed),
            "Current speed, an earth-fixed velocity added to the kinematics";
        input real "current_direction" ["rad"] (inputs.current_direction),
            "Direction the current flows toward, from north, clockwise";
        input real "yaw_disturbance" ["rad"] (inputs.yaw_disturbance),
            "Rudder-equivalent environmental disturbance delta_w added to the rudder in the \
             dynamics (T' r'' + r' = K'(delta + delta_w)); e.g. Waves.yaw_moment through a \
             converting connection gain. The thesis does not say how its sea-state-4 disturbance \
             enters the hull (spec section 2.18)";
        output real "sway_velocity" ["m/s"] (|m| m.out().sway_velocity),
            "Sway velocity v = v' U (0 for model 1)";
        output real "sway_velocity_prime" (|m| m.out().v_prime), "Prime-system sway v' = v/U";
        output real "yaw_rate" ["rad/s"] (|m| m.out().yaw_rate), "Yaw rate r";
        output real "yaw_rate_prime" (|m| m.out().r_prime), "Prime-system yaw rate r' = rL/U";
        pose!(out());
        output real "speed_over_ground" ["m/s"] (|m| m.out().speed_over_ground),
            "sqrt(U^2 + v^2) (through the water; the current is not included)";
        output real "time_prime" (|m| m.out().time_prime),
            "Nondimensional time t' = tU/L since the start";
    }
}

impl FmuModel for NomotoShipFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.outputs = None;
        self.ship = self.build()?;
        self.keep_outputs();
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
        let max_substep = self.ship.max_substep;
        each("max_substep", max_substep, passes(h, max_substep));
    }
}

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
            mass: [[0.0; 2]; 2],
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
