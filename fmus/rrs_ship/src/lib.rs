//! `RrsShip` FMU: the RRS ship of [Klugt1987] (`models::hull::rrs_ship`), the 22-knot simulation
//! model and the speed-dependent fifth-order control model, as an FMI 2.0 co-simulation FMU.
//! No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::error::check_positive;
use models::hull::rrs_ship::{RrsShip, RrsShipInputs, RrsShipOutputs, NX, U_22KN};
use models::hull::{check_initial_state, DEG};
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;

/// Parameters, inputs and state of one RRS-ship instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RrsShipFmu {
    /// 1: simulation model [Klugt1987, Tables 2.1, 2.2]; 2: control model, [Klugt1987, Table 2.4];
    /// 3: control model, [Klugt1987, Table 2.5].
    model: i32,
    min_speed: f64,
    max_substep: f64,
    inputs: RrsShipInputs,
    /// Second disturbance channel (e.g. wind, [Klugt1987, eqs. (2.19)-(2.20)]), added to the first:
    /// w_φ and w_ψ of [Klugt1987, eq. (3.29)] are the sums of all rudder-equivalent disturbances.
    wind_roll: f64,
    wind_yaw: f64,
    ship: RrsShip,
    /// The state the run starts from (all 0 by default: upright on a straight course north at
    /// the origin).
    initial: InitialState,
}

/// The initial motion state and position of the hull, `[φ, p, v, r, ψ]` and `(x, y)` of the
/// model's state (the wave-filter states start at 0).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
struct InitialState {
    roll: f64,
    roll_rate: f64,
    sway: f64,
    yaw_rate: f64,
    heading: f64,
    x: f64,
    y: f64,
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
            initial: InitialState::default(),
        }
    }
}

impl RrsShipFmu {
    /// State variable `i` of the model, `[φ, p, v, r, ψ, a1, a2, b1, b2, c1, c2, x, y]`: the
    /// outputs that are states are read straight from it, the value `RrsShip::outputs` copies
    /// (a step loop reads roll, heading and yaw rate, and no output needs computing after a step).
    fn state(&self, i: usize) -> f64 {
        self.ship.state()[i]
    }

    /// The outputs that are not states (wrapped heading, wave contributions), computed when read.
    fn out(&self) -> RrsShipOutputs {
        self.ship.outputs()
    }

    fn check(&self) -> Result<(), String> {
        for (name, v) in [
            ("min_speed", self.min_speed),
            ("max_substep", self.max_substep),
        ] {
            check_positive(name, v)?;
        }
        let i = &self.initial;
        check_initial_state(
            &[
                ("initial_roll", i.roll),
                ("initial_roll_rate", i.roll_rate),
                ("initial_sway", i.sway),
                ("initial_yaw_rate", i.yaw_rate),
                ("initial_heading", i.heading),
                ("initial_x", i.x),
                ("initial_y", i.y),
            ],
            &["initial_roll"],
        )?;
        Ok(())
    }
}

fmi2_export::fmu! {
    RrsShipFmu => "RrsShip",
    description: "Van der Klugt (1987) rudder-roll-stabilisation ship: the \
        22-knot simulation model with wave-height-driven filters (Tables 2.1, 2.2) and the \
        speed-dependent fifth-order control model (Tables 2.3-2.5)",
    experiment: (0.0, 300.0, 0.05),
    // Every output is a function of the state: no direct feedthrough from the inputs.
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        fixed int(1, 3) "model" (model),
            "1: 22-knot simulation model of Fig. 2.5 (Tables 2.1 and 2.2, wave-height-driven filters); \
             2: speed-dependent fifth-order control model of Fig. 2.6 with the Table 2.3 laws and the \
             Table 2.4 constants; 3: the control model with the Table 2.5 (+-20 deg rudder) constants";
        tunable real "min_speed" ["m/s"] (min_speed).min(0.0),
            "Speed floor for the control-model speed laws (default 1 m/s; the thesis extrapolates to 2 m/s)";
        fixed real "max_substep" ["s"] (max_substep).min(0.0),
            "Largest RK4 sub-step (default 0.05 s; the fastest pole is about 1.2 rad/s)";
        input real "rudder_angle" ["rad"] (inputs.rudder),
            "Actual rudder angle delta_w (from SteeringGear.rudder_angle); sign convention of [Klugt1987]: \
             r/delta < 0 at DC; start value 5 deg";
        input real "speed" ["m/s"] (inputs.speed),
            "Ship speed U: evaluates the control-model speed laws (held over the step) and drives the \
             position kinematics; the simulation model is valid at 22 kn only (start value 11.32 m/s)";
        input real "roll_disturbance" ["rad"] (inputs.roll_disturbance),
            "Rudder-equivalent roll disturbance w_phi (eq. 3.29), entering as omega_n^2 w_phi";
        input real "yaw_disturbance" ["rad"] (inputs.yaw_disturbance),
            "Rudder-equivalent yaw disturbance w_psi (eq. 3.29), entering as w_psi/tau_r";
        input real "wave_elevation" ["m"] (inputs.wave_elevation),
            "Wave height w driving the Table 2.2 filters (model 1 only; e.g. Waves.wave_elevation)";
        output real "roll" ["rad"] (|m| m.state(0)), "Roll angle phi";
        output real "roll_rate" ["rad/s"] (|m| m.state(1)), "Roll rate p";
        output real "sway" (|m| m.state(2)),
            "Sway state v (model 1) or v' (models 2, 3: the sway due to the rudder, x3 of eq. 3.29), in \
             the model's own scale, not m/s (Table 2.4 fixes K_dv0 = 0.01)";
        output real "yaw_rate" ["rad/s"] (|m| m.state(3)), "Yaw rate r";
        output real "heading" ["rad"] (|m| m.state(4)),
            "Heading psi from north, clockwise, continuous (not wrapped)";
        output real "heading_wrapped" ["rad"] (|m| m.out().heading_wrapped),
            "Heading wrapped to (-pi, pi]";
        output real "x" ["m"] (|m| m.state(NX)),
            "North position, x' = U cos(psi) (sway neglected: the thesis has no position)";
        output real "y" ["m"] (|m| m.state(NX + 1)), "East position, y' = U sin(psi)";
        output real "wave_sway" (|m| m.out().wave_sway),
            "Wave-induced sway contribution y_wv (model 1; model units)";
        output real "wave_yaw" (|m| m.out().wave_yaw),
            "Wave-induced yaw contribution y_wr (model 1; model units)";
        output real "wave_roll" (|m| m.out().wave_roll),
            "Wave-induced roll contribution y_wp (model 1; rudder-equivalent, model units)";
        input real "wind_roll_disturbance" ["rad"] (wind_roll),
            "Second rudder-equivalent roll disturbance (e.g. the wind moment of eq. 2.19), added to \
             roll_disturbance";
        input real "wind_yaw_disturbance" ["rad"] (wind_yaw),
            "Second rudder-equivalent yaw disturbance (e.g. the wind moment of eq. 2.20), added to \
             yaw_disturbance";
        // The initial state (issue 17), appended after the released variables.
        fixed real "initial_roll" ["rad"] (initial.roll).range(-FRAC_PI_2, FRAC_PI_2),
            "Roll angle phi at the start time (positive starboard down; default 0; within \
             (-pi/2, pi/2)). The states are those of eqs. 2.16-2.18 (model 1) and of eq. 3.29 \
             (models 2, 3: x = [phi, p, v', r, psi]); the wave-filter states start at 0";
        fixed real "initial_roll_rate" ["rad/s"] (initial.roll_rate),
            "Roll rate p at the start time (default 0)";
        fixed real "initial_sway" (initial.sway),
            "Sway state v (model 1) or v' (models 2, 3, x3 of eq. 3.29) at the start time, in the \
             model's own scale as the output sway (default 0)";
        fixed real "initial_yaw_rate" ["rad/s"] (initial.yaw_rate),
            "Yaw rate r at the start time (default 0)";
        fixed real "initial_heading" ["rad"] (initial.heading),
            "Heading psi from north, clockwise, at the start time (default 0)";
        fixed real "initial_x" ["m"] (initial.x), "North position at the start time (default 0)";
        fixed real "initial_y" ["m"] (initial.y), "East position at the start time (default 0)";
    }
}

impl FmuModel for RrsShipFmu {
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
        let i = &self.initial;
        ship.set_motion(
            [i.roll, i.roll_rate, i.sway, i.yaw_rate, i.heading],
            [i.x, i.y],
        );
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

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let max_substep = self.ship.max_substep;
        each("max_substep", max_substep, passes(h, max_substep));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The initial state is the start of the state vector [phi, p, v, r, psi, .., x, y] in
    /// every model, the defaults are today's start (all 0), and a roll outside (-pi/2, pi/2)
    /// or a non-finite value is refused.
    #[test]
    fn the_initial_state_is_the_start() {
        let mut m = RrsShipFmu::default();
        m.initialize(0.0).unwrap();
        assert_eq!(m.ship.state(), &[0.0; NX + 2]);
        m.initial = InitialState {
            roll: 0.1,
            roll_rate: -0.01,
            sway: 0.2,
            yaw_rate: 0.003,
            heading: 1.5,
            x: 10.0,
            y: -20.0,
        };
        for model in [1, 2, 3] {
            m.model = model;
            m.initialize(0.0).unwrap();
            let s = m.ship.state();
            assert_eq!(&s[..5], &[0.1, -0.01, 0.2, 0.003, 1.5]);
            assert_eq!(&s[5..NX], &[0.0; 6]);
            assert_eq!(&s[NX..], &[10.0, -20.0]);
        }
        m.initial.roll = -1.6;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("initial_roll = -1.6"), "{e}");
        m.initial.roll = 0.0;
        m.initial.y = f64::NEG_INFINITY;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("initial_y = -inf"), "{e}");
    }

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
