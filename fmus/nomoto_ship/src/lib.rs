//! `NomotoShip` FMU: the linear manoeuvring models of the DDG-51 thesis
//! (`models::hull::nomoto`): the DDG-51 first-order Nomoto model and the linear sway-yaw model
//! with Esso Osaka coefficients, as an FMI 2.0 co-simulation FMU. No physics here: the variable
//! table maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::controllers::loop_shaped::presets::CONTAINER_SHIP_PRESET_SPEED;
use models::error::{check_positive, ParamError};
use models::hull::nomoto::{NomotoInputs, NomotoModel, NomotoOutputs, NomotoShip};
use models::hull::{check_initial_state, preset_value, DEG};
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
    /// The state the run starts from (all 0 by default: heading north at the origin).
    initial: InitialState,
    /// A named ship whose model, coefficients, length and speed replace the parameters (0: none).
    preset: i32,
}

/// The initial state, SI: the motion (v = v'U, r = r'U/L, psi) and the position.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
struct InitialState {
    sway_velocity: f64,
    yaw_rate: f64,
    heading: f64,
    x: f64,
    y: f64,
}

/// The presets: 1 the DDG-51, 2 the Esso Osaka, 3 the container ship at 7 m/s.
const PRESETS: &str = "1, 2 or 3 (0: none)";

impl NomotoShipFmu {
    /// The ship of preset `code` (`None`: no preset).
    fn preset_ship(code: i32) -> Result<Option<NomotoShip>, String> {
        Ok(match code {
            0 => None,
            1 => Some(NomotoShip::ddg51()),
            2 => Some(NomotoShip::esso_osaka()),
            3 => Some(
                NomotoShip::container_ship(CONTAINER_SHIP_PRESET_SPEED)
                    .map_err(|e| e.to_string())?,
            ),
            v => return Err(format!("parameter preset = {v} must be {PRESETS}")),
        })
    }

    /// The parameters with the preset's values in place of the ones it sets; a parameter set to
    /// a value that is neither its default nor the preset's is refused.
    fn with_preset(&self) -> Result<Self, String> {
        let Some(ship) = Self::preset_ship(self.preset)? else {
            return Ok(self.clone());
        };
        let (d, code) = (Self::default(), self.preset);
        let mut p = self.clone();
        let set = |name: &str, value: f64, default: f64, ours: f64| {
            preset_value(code, name, value, default, ours)
        };
        match ship.model {
            NomotoModel::FirstOrder { t, k } => {
                p.model = set("model", self.model.into(), d.model.into(), 1.0)? as i32;
                p.t_prime = set("t_prime", self.t_prime, d.t_prime, t)?;
                p.k_prime = set("k_prime", self.k_prime, d.k_prime, k)?;
            }
            NomotoModel::SwayYaw { m, n, b } => {
                p.model = set("model", self.model.into(), d.model.into(), 2.0)? as i32;
                for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                    let ij = format!("{}{}", i + 1, j + 1);
                    p.mass[i][j] = set(&format!("m{ij}"), self.mass[i][j], d.mass[i][j], m[i][j])?;
                    p.damping[i][j] = set(
                        &format!("n{ij}"),
                        self.damping[i][j],
                        d.damping[i][j],
                        n[i][j],
                    )?;
                }
                for (i, ours) in b.into_iter().enumerate() {
                    p.rudder[i] = set(&format!("b{}", i + 1), self.rudder[i], d.rudder[i], ours)?;
                }
            }
        }
        p.length = set("length", self.length, d.length, ship.length)?;
        p.speed = set("speed", self.speed, d.speed, ship.speed)?;
        Ok(p)
    }
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
            initial: InitialState::default(),
            preset: 0,
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

    /// Builds the ship from the parameters (the preset gives length and speed when they are 0;
    /// the named `preset`, when set, gives the model, its coefficients, length and speed), in
    /// its initial state.
    pub fn build(&self) -> Result<NomotoShip, String> {
        let p = self.with_preset()?;
        let mut ship = p.build_model()?;
        let i = &self.initial;
        check_initial_state(
            &[
                ("initial_sway_velocity", i.sway_velocity),
                ("initial_yaw_rate", i.yaw_rate),
                ("initial_heading", i.heading),
                ("initial_x", i.x),
                ("initial_y", i.y),
            ],
            &[],
        )?;
        let (l, u) = (ship.length, ship.speed);
        ship.set_state([i.sway_velocity / u, i.yaw_rate * l / u, i.heading, i.x, i.y]);
        Ok(ship)
    }

    /// The ship of the model parameters, at rest at the origin.
    fn build_model(&self) -> Result<NomotoShip, String> {
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
        // The initial state and the named presets (issues 17, 18), appended after the released
        // variables.
        fixed real "initial_sway_velocity" ["m/s"] (initial.sway_velocity),
            "Sway velocity v = v' U at the start time (state v' of eqs. 4.1-4.2; default 0). Model 1 \
             has no sway dynamics: v stays constant, a drift as the thesis's 5-kn current \
             (section 5.2.3.1)";
        fixed real "initial_yaw_rate" ["rad/s"] (initial.yaw_rate),
            "Yaw rate r = r' U/L at the start time (state r' of eqs. 4.1-4.2 and 5.24; default 0)";
        fixed real "initial_heading" ["rad"] (initial.heading),
            "Heading psi from north, clockwise, at the start time (eq. 5.37; default 0)";
        fixed real "initial_x" ["m"] (initial.x),
            "North position at the start time (eq. 5.35; default 0)";
        fixed real "initial_y" ["m"] (initial.y),
            "East position at the start time (eq. 5.36; default 0)";
        fixed int(0, 3) "preset" (preset),
            "Named ship, replacing model, t_prime, k_prime, m11..b2, length and speed (a parameter set \
             to a third value is refused): 0 none (those parameters); 1 DDG-51, model 1, T' = 1.9287, \
             K' = 2.04 (eqs. 5.25-5.26), L = 466 ft, 22 kn (= the defaults); 2 Esso Osaka, model 2 \
             (Table 2.3 and the documented assumptions), L = 1066.3 ft, 10 kn; 3 container ship \
             (ContainerShip, MSS Lcontainer.m), model 1 with K' = 2.9210, T' = 4.3596 from its \
             linearised model (derived here), L = 175 m, 7 m/s: the plant of HeadingAutopilot's \
             preset 2";
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

    /// Each preset sets the values its source gives (written out here from the sources, not
    /// read from the code): [Taylor2000, eqs. (5.25)-(5.26), Table 3.1] for the DDG-51, its
    /// Table 2.3 for the Esso Osaka's N, and the container ship's K', T' from its linearised
    /// model (numpy on MSS Lcontainer.m's matrices, models::controllers::loop_shaped::presets).
    #[test]
    fn presets_set_the_documented_values() {
        let mut m = NomotoShipFmu {
            preset: 1,
            ..Default::default()
        };
        m.initialize(0.0).unwrap();
        assert_eq!(m.ship.model, NomotoModel::FirstOrder { t: 1.9287, k: 2.04 });
        assert_eq!(m.ship.length, 466.0 * 0.3048);
        assert_eq!(m.ship.speed, 22.0 * 1852.0 / 3600.0);

        m.preset = 2;
        m.initialize(0.0).unwrap();
        match m.ship.model {
            NomotoModel::SwayYaw { n, .. } => {
                assert_eq!(n, [[0.0244, 0.0138], [1.4578e-3, 8.093e-4]])
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(m.ship.length, 1066.3 * 0.3048);
        assert_eq!(m.ship.speed, 10.0 * 1852.0 / 3600.0);

        m.preset = 3;
        m.initialize(0.0).unwrap();
        match m.ship.model {
            NomotoModel::FirstOrder { t, k } => {
                assert!((k - 2.920998).abs() < 1e-5, "K' = {k}");
                assert!((t - 4.359567).abs() < 1e-5, "T' = {t}");
            }
            other => panic!("{other:?}"),
        }
        assert_eq!((m.ship.length, m.ship.speed), (175.0, 7.0));
    }

    #[test]
    fn a_parameter_set_against_the_preset_is_refused() {
        let mut m = NomotoShipFmu {
            preset: 3,
            k_prime: 1.5,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("preset = 3 sets k_prime = 2.92"), "{e}");
        assert!(e.contains("k_prime was set to 1.5"), "{e}");
        // the preset's own value and the default are accepted
        let mut m = NomotoShipFmu {
            preset: 3,
            speed: 7.0,
            ..Default::default()
        };
        m.initialize(0.0).unwrap();
        let mut m = NomotoShipFmu {
            preset: 2,
            model: 1,
            ..Default::default()
        };
        m.initialize(0.0).unwrap();
        assert!(matches!(m.ship.model, NomotoModel::SwayYaw { .. }));
        let mut m = NomotoShipFmu {
            preset: 1,
            model: 2,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("model was set to 2"), "{e}");
    }

    /// The initial state in SI is the model's prime state: v' = v/U, r' = rL/U (DDG-51: L/U =
    /// 142.0368/11.317778 s), and it is what the outputs show before the first step.
    #[test]
    fn the_initial_state_is_the_start() {
        let mut m = NomotoShipFmu::default();
        m.initial = InitialState {
            sway_velocity: -2.5,
            yaw_rate: 0.01,
            heading: 1.0,
            x: 100.0,
            y: -50.0,
        };
        m.initialize(0.0).unwrap();
        let o = m.out();
        let (l, u) = (142.0368, 22.0 * 1852.0 / 3600.0);
        assert!((o.v_prime - (-2.5 / u)).abs() < 1e-15);
        assert!((o.r_prime - 0.01 * l / u).abs() < 1e-15);
        assert!((o.sway_velocity + 2.5).abs() < 1e-14);
        assert!((o.yaw_rate - 0.01).abs() < 1e-16);
        assert_eq!((o.heading, o.x, o.y), (1.0, 100.0, -50.0));
        m.initial.heading = f64::INFINITY;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("initial_heading = inf"), "{e}");
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
