//! `ContainerShip` FMU: the Son & Nomoto (1982) nonlinear roll-coupled container ship of
//! `models::hull::container_ship` (and its linearisation as a variant) as an FMI 2.0
//! co-simulation FMU. No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::error::{check_positive, ParamError};
use models::hull::container_ship::{
    ContainerShip, ContainerShipInputs, ContainerShipOutputs, ContainerShipParams,
    LinearContainerShip, LinearContainerShipInputs, PropellerInflow,
};
use models::hull::{check_initial_state, preset_value, DEG};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// The hull in use: the nonlinear model (variant 1) or the linearised model (variant 2).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Hull {
    Nonlinear(ContainerShip),
    Linear(LinearContainerShip),
}

/// Parameters, inputs and state of one container-ship instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ContainerShipFmu {
    /// 1: nonlinear (MSS `container.m`), 2: linearised (MSS `Lcontainer.m`).
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
    /// The model's outputs, computed once wherever the model changes (initialize, do_step,
    /// calculate_outputs) instead of in every getter; `None` (after a deserialized restore)
    /// means compute them. Not part of the state.
    #[serde(skip)]
    outputs: Option<ContainerShipOutputs>,
    /// The rest of the state the run starts from (all 0 by default: upright on a straight
    /// course north at the origin, rudder amidships).
    initial: InitialState,
    /// 0: none; 1: the source's own servo; 2: driven by an external steering gear.
    preset: i32,
}

/// The initial state beyond u, v and n (which have their own parameters), in the order of the
/// model's state `[u, v, r, x, y, ψ, p, φ, δ, n]` (MSS `container.m`).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
struct InitialState {
    yaw_rate: f64,
    x: f64,
    y: f64,
    heading: f64,
    roll_rate: f64,
    roll: f64,
    rudder_angle: f64,
}

/// The built-in servo of preset 2, opened up for an external steering gear: a command limit
/// above any gear's angle limit, and a rate limit that does not bind for commands within
/// 1 rad of the rudder; the servo's 1 s lag stays.
pub const OPEN_SERVO: (f64, f64) = (FRAC_PI_2, 1.0);
/// The source's own servo of preset 1 (MSS `container.m`): 10 deg, 5 deg/s.
pub const OWN_SERVO: (f64, f64) = (10.0 * DEG, 5.0 * DEG);

impl ContainerShipFmu {
    /// Selects the named preset `code`; preset 2 also makes the start value of `rudder_command`
    /// 0 unless it was set to something other than the default 5 deg.
    fn select_preset(&mut self, code: i32) {
        self.preset = code;
        if code == 2 && self.inputs.rudder_command == DEFAULT_RUDDER_COMMAND {
            self.inputs.rudder_command = 0.0;
        }
    }

    /// The parameters with the preset's servo in place of `rudder_max` and `rudder_rate_max`;
    /// a value set to neither the default nor the preset's is refused.
    fn resolved_params(&self) -> Result<ContainerShipParams, String> {
        let servo = match self.preset {
            0 => return Ok(self.params.clone()),
            1 => OWN_SERVO,
            2 => OPEN_SERVO,
            v => return Err(format!("parameter preset = {v} must be 0, 1 or 2")),
        };
        let d = ContainerShipParams::default();
        let mut p = self.params.clone();
        p.rudder_max = preset_value(
            self.preset,
            "rudder_max",
            p.rudder_max,
            d.rudder_max,
            servo.0,
        )?;
        p.rudder_rate_max = preset_value(
            self.preset,
            "rudder_rate_max",
            p.rudder_rate_max,
            d.rudder_rate_max,
            servo.1,
        )?;
        Ok(p)
    }

    /// The initial state `[v, r, x, y, ψ, p, φ, δ]` (v from `initial_sway_velocity`), checked.
    fn initial_motion(&self) -> Result<[f64; 8], String> {
        let i = &self.initial;
        let v = self.initial_sway_velocity;
        check_initial_state(
            &[
                ("initial_sway_velocity", v),
                ("initial_yaw_rate", i.yaw_rate),
                ("initial_x", i.x),
                ("initial_y", i.y),
                ("initial_heading", i.heading),
                ("initial_roll_rate", i.roll_rate),
                ("initial_roll", i.roll),
                ("initial_rudder_angle", i.rudder_angle),
            ],
            &["initial_roll"],
        )?;
        Ok([
            v,
            i.yaw_rate,
            i.x,
            i.y,
            i.heading,
            i.roll_rate,
            i.roll,
            i.rudder_angle,
        ])
    }
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
            outputs: None,
            initial: InitialState::default(),
            preset: 0,
        }
    }
}

/// A model error with the model's parameter name replaced by the FMU variable's name.
fn param_error(e: ParamError) -> String {
    e.renamed(&[
        ("u", "initial_surge_velocity"),
        ("n_rpm", "initial_shaft_speed"),
        ("u0", "nominal_speed"),
    ])
    .to_string()
}

impl ContainerShipFmu {
    fn model_outputs(&self) -> ContainerShipOutputs {
        match &self.hull {
            Hull::Nonlinear(s) => s.outputs(),
            Hull::Linear(s) => s.outputs(),
        }
    }

    fn out(&self) -> ContainerShipOutputs {
        self.outputs.unwrap_or_else(|| self.model_outputs())
    }

    /// Keeps the outputs of the model as it is now (the getters read them).
    fn keep_outputs(&mut self) {
        self.outputs = Some(self.model_outputs());
    }

    /// Builds the hull from the parameters (exactly as `ContainerShip::new` /
    /// `LinearContainerShip::new` with the parameter values).
    pub fn build(&self) -> Result<Hull, String> {
        let params = self.resolved_params()?;
        params.validate().map_err(param_error)?;
        let motion = self.initial_motion()?;
        match self.variant {
            1 => {
                let n = self.initial_shaft_speed;
                check_positive("initial_shaft_speed", n)?;
                let u = if self.start_at_equilibrium {
                    ContainerShip::straight_line_speed(n)
                } else {
                    self.initial_surge_velocity
                };
                let mut state = [0.0; 10];
                state[0] = u;
                state[1..9].copy_from_slice(&motion);
                state[9] = n;
                let ship = ContainerShip::new(params, state).map_err(param_error)?;
                Ok(Hull::Nonlinear(ship))
            }
            2 => {
                let mut ship = LinearContainerShip::new(self.nominal_speed).map_err(param_error)?;
                ship.mss_speed = self.mss_speed;
                ship.rudder_max = params.rudder_max;
                ship.rudder_rate_max = params.rudder_rate_max;
                ship.max_substep = params.max_substep;
                ship.set_motion(motion);
                Ok(Hull::Linear(ship))
            }
            v => Err(format!("parameter variant = {v} must be 1 or 2")),
        }
    }
}

fmi2_export::fmu! {
    ContainerShipFmu => "ContainerShip",
    description: "Son & Nomoto (1982) high-speed container ship: nonlinear \
        roll-coupled surge-sway-yaw-roll manoeuvring model with rudder and shaft servos (MSS \
        container.m), or its linearisation (Lcontainer.m). Its own rudder servo (10 deg, 5 deg/s, \
        1 s) acts on rudder_command (start value 5 deg): open it up (rudder_max, rudder_rate_max) \
        when a SteeringGear drives it",
    experiment: (0.0, 600.0, 0.1),
    // Every output is a function of the state: no direct feedthrough from the inputs.
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        fixed int(1, 2) "variant" (variant),
            "1: nonlinear 4-DOF Son & Nomoto model (container_ship.md section 2); 2: linearised model \
             (section 4, MSS Lcontainer.m; no shaft, u = nominal_speed)";
        tunable real "rudder_max" ["rad"] (params.rudder_max).range(0.0, PI),
            "Rudder command saturation of the built-in servo (section 2.6: 10 deg; exRRD2.m: 20 deg). \
            It also limits a SteeringGear's rudder_angle connected to rudder_command: raise it to \
            at least the gear's angle limit";
        // Declared minimum 1e-3 rad/s (was 0): at 1e-300 the rate-limited rudder ran on
        // denormal numbers and a 1 s step of 1e6 RK4 sub-steps (the work bound) took 3.0 s
        // instead of 0.38 s (fuzz run seed 2027, replay param ContainerShip 2368 273).
        tunable real "rudder_rate_max" ["rad/s"] (params.rudder_rate_max).min(1e-3),
            "Rudder rate limit of the built-in servo (section 2.6: 5 deg/s; exRRD2.m: 20 deg/s). \
            When a SteeringGear drives rudder_command, open the servo up: rudder_rate_max well above \
            the gear's rate (e.g. 1 rad/s, as systems/autopilot_*_nonlinear.toml do); the servo's \
            1 s time constant stays";
        tunable real "shaft_max_rpm" ["rpm"] (params.shaft_max_rpm).min(0.0),
            "Shaft speed command upper limit (section 2.6: 160 rpm; variant 1)";
        tunable real "shaft_min_rpm" ["rpm"] (params.shaft_min_rpm).min(0.0),
            "Shaft speed command lower clamp, a validity guard not in the source (default 1 rpm; variant 1)";
        tunable real "gm" ["m"] (params.gm).min(0.0),
            "Metacentric height GM (section 2.2: 0.3 m; variant 1)";
        fixed int "propeller_inflow" (params.propeller_inflow => {
                1: PropellerInflow::Current, 2: PropellerInflow::Pre2022Cos }),
            "Propeller inflow u'_P (section 2.7): 1 = u' [(1 - w_p) + tau(...)] (MSS since 2022, \
             default); 2 = cos(v') [...] (pre-2022, exRRD2.m)";
        fixed real "min_speed" ["m/s"] (params.min_speed).min(0.0),
            "Speed floor of the nondimensionalisation, a validity guard not in the source (default 0.1 m/s)";
        fixed real "max_substep" ["s"] (params.max_substep).min(0.0),
            "Largest RK4 sub-step (section 8: <= 0.05 s)";
        fixed bool "start_at_equilibrium" (start_at_equilibrium),
            "Variant 1: start on the straight-line equilibrium of initial_shaft_speed (section 2.9, \
             u in closed form); false: start with u = initial_surge_velocity";
        fixed real "initial_surge_velocity" ["m/s"] (initial_surge_velocity),
            "Variant 1: initial surge velocity u when start_at_equilibrium = false (MSS exTurnCircle.m: 8 m/s)";
        fixed real "initial_shaft_speed" ["rpm"] (initial_shaft_speed),
            "Variant 1: initial shaft speed n (> 0); with start_at_equilibrium also the equilibrium \
             speed (70 rpm: 7.32959 m/s, 80 rpm: 8.37667 m/s)";
        fixed real "initial_sway_velocity" ["m/s"] (initial_sway_velocity),
            "Variant 1: initial sway velocity v (to starboard; default 0). The DDG-51 thesis applies its \
             5-kn current to the autopilot runs this way (spec ddg51_ekf_autopilot.md section 2.18)";
        fixed real "nominal_speed" ["m/s"] (nominal_speed).min(0.0),
            "Variant 2: speed U0 of the linearised model (section 4.1: 7.0 m/s)";
        fixed bool "mss_speed" (mss_speed),
            "Variant 2: U = sqrt(U0^2 + v^2) as MSS Lcontainer.m (false: strictly linear U = U0)";
        input real "rudder_command" ["rad"] (inputs.rudder_command),
            "Commanded rudder angle delta_c (positive: starboard turn), through the built-in servo \
             (saturation rudder_max 10 deg, rate rudder_rate_max 5 deg/s, time constant 1 s). Start \
             value 5 deg, not 0: unconnected, the ship turns; set 0 for a straight course";
        input real "shaft_speed_command" ["rpm"] (inputs.shaft_command_rpm),
            "Commanded shaft speed n_c (variant 1; clamped to [shaft_min_rpm, shaft_max_rpm])";
        input real "sway_force" ["N"] (inputs.sway_force_ext),
            "External sway force, body y to starboard (variant 1; added to Y' / (0.5 rho L^2 U^2))";
        input real "roll_moment" ["N.m"] (inputs.roll_moment_ext),
            "External roll moment, positive starboard down (variant 1; e.g. Waves.roll_moment)";
        input real "yaw_moment" ["N.m"] (inputs.yaw_moment_ext),
            "External yaw moment, positive to starboard (variant 1; e.g. Waves.yaw_moment)";
        output real "surge_velocity" ["m/s"] (|m| m.out().u), "Surge velocity u (variant 2: U0)";
        output real "sway_velocity" ["m/s"] (|m| m.out().v), "Sway velocity v";
        output real "yaw_rate" ["rad/s"] (|m| m.out().r), "Yaw rate r";
        output real "roll_rate" ["rad/s"] (|m| m.out().p), "Roll rate p";
        output real "roll" ["rad"] (|m| m.out().roll),
            "Roll angle phi (positive starboard down; outward heel phi < 0 in a starboard turn)";
        pose!(out());
        output real "rudder_angle" ["rad"] (|m| m.out().rudder),
            "Actual rudder angle delta (servo output)";
        output real "shaft_speed" ["rpm"] (|m| m.out().shaft_rpm),
            "Actual shaft speed n (variant 2: 0)";
        output real "speed" ["m/s"] (|m| m.out().speed), "Total speed U = sqrt(u^2 + v^2)";
        output real "drift_angle" ["rad"] (|m| m.out().drift_angle), "Drift angle beta = atan2(v, u)";
        output real "sway_velocity_prime" (|m| m.out().v_prime), "Prime-system sway v' = v/U";
        output real "yaw_rate_prime" (|m| m.out().r_prime),
            "Prime-system yaw rate r' = r L/U (L = 175 m)";
        output real "roll_rate_prime" (|m| m.out().p_prime), "Prime-system roll rate p' = p L/U";
        output bool "outside_validity"
            (|m| matches!(&m.hull, Hull::Nonlinear(s) if s.outside_validity())),
            "Variant 1: a validity guard is active (U < min_speed or n < shaft_min_rpm; MSS would stop)";
        // The initial state and the named presets (issues 17, 18), appended after the released
        // variables. The state is x = [u, v, r, x, y, psi, p, phi, delta, n] of container.m; u, v
        // and n have their own parameters above (initial_sway_velocity applies to both variants).
        fixed real "initial_yaw_rate" ["rad/s"] (initial.yaw_rate),
            "Yaw rate r at the start time (state x3; variants 1 and 2; default 0)";
        fixed real "initial_x" ["m"] (initial.x),
            "North position at the start time (state x4; variants 1 and 2; default 0)";
        fixed real "initial_y" ["m"] (initial.y),
            "East position at the start time (state x5; variants 1 and 2; default 0)";
        fixed real "initial_heading" ["rad"] (initial.heading),
            "Heading psi from north, clockwise, at the start time (state x6; variants 1 and 2; \
             default 0)";
        fixed real "initial_roll_rate" ["rad/s"] (initial.roll_rate),
            "Roll rate p at the start time (state x7; variants 1 and 2; default 0)";
        fixed real "initial_roll" ["rad"] (initial.roll).range(-FRAC_PI_2, FRAC_PI_2),
            "Roll angle phi at the start time, positive starboard down (state x8; variants 1 and 2; \
             default 0; within (-pi/2, pi/2))";
        fixed real "initial_rudder_angle" ["rad"] (initial.rudder_angle),
            "Actual rudder angle delta of the built-in servo at the start time (state x9; variants 1 \
             and 2; default 0)";
        fixed int(0, 2) "preset" (|m| m.preset, |m, v| m.select_preset(v)),
            "Named rudder servo, replacing rudder_max and rudder_rate_max (a value set to neither \
             the default nor the preset's is refused): 0 none (those parameters; defaults = 1); 1 the \
             source's own servo (section 2.6, MSS container.m: 10 deg, 5 deg/s; rudder_command start \
             5 deg); 2 driven by an external SteeringGear: the servo opened up (rudder_max 90 deg, \
             rudder_rate_max 1 rad/s; its 1 s lag stays) and the start value of rudder_command 0 \
             (unless it was set)";
    }
}

impl FmuModel for ContainerShipFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.outputs = None;
        self.hull = self.build()?;
        self.keep_outputs();
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.outputs = None;
        let params = self.resolved_params()?;
        params.validate().map_err(param_error)?;
        match &mut self.hull {
            Hull::Nonlinear(s) => s.params = params,
            Hull::Linear(s) => {
                s.rudder_max = params.rudder_max;
                s.rudder_rate_max = params.rudder_rate_max;
            }
        }
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.keep_outputs();
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        match &mut self.hull {
            Hull::Nonlinear(s) => s.step(&self.inputs, h),
            Hull::Linear(s) => {
                // The linear model uses only the rudder command.
                let rudder_command = self.inputs.rudder_command;
                s.step(&LinearContainerShipInputs { rudder_command }, h)
            }
        }
        self.keep_outputs();
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let max_substep = match &self.hull {
            Hull::Nonlinear(s) => s.params.max_substep,
            Hull::Linear(s) => s.max_substep,
        };
        each("max_substep", max_substep, passes(h, max_substep));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The presets' values, written out from the sources: MSS container.m's servo, 10 deg =
    /// 0.17453292519943295 rad and 5 deg/s = 0.08726646259971647 rad/s, rudder_command start
    /// 5 deg; the opened-up servo of preset 2: 90 deg = 1.5707963267948966 rad, 1 rad/s, start 0.
    #[test]
    fn presets_set_the_documented_values() {
        let mut m = ContainerShipFmu::default();
        m.select_preset(1);
        m.initialize(0.0).unwrap();
        let Hull::Nonlinear(s) = &m.hull else {
            panic!("variant 1")
        };
        assert_eq!(s.params.rudder_max, 0.17453292519943295);
        assert_eq!(s.params.rudder_rate_max, 0.08726646259971647);
        assert_eq!(m.inputs.rudder_command, 0.08726646259971647);

        let mut m = ContainerShipFmu::default();
        m.select_preset(2);
        m.initialize(0.0).unwrap();
        let Hull::Nonlinear(s) = &m.hull else {
            panic!("variant 1")
        };
        assert_eq!(s.params.rudder_max, 1.5707963267948966);
        assert_eq!(s.params.rudder_rate_max, 1.0);
        assert_eq!(m.inputs.rudder_command, 0.0);
        // the linear variant takes the same servo
        let mut m = ContainerShipFmu {
            variant: 2,
            ..Default::default()
        };
        m.select_preset(2);
        m.initialize(0.0).unwrap();
        let Hull::Linear(s) = &m.hull else {
            panic!("variant 2")
        };
        assert_eq!((s.rudder_max, s.rudder_rate_max), (1.5707963267948966, 1.0));
        // a rudder_command set before the preset is kept
        let mut m = ContainerShipFmu::default();
        m.inputs.rudder_command = 0.01;
        m.select_preset(2);
        assert_eq!(m.inputs.rudder_command, 0.01);
    }

    #[test]
    fn a_servo_set_against_the_preset_is_refused() {
        let mut m = ContainerShipFmu::default();
        m.params.rudder_max = 0.5;
        m.select_preset(2);
        let e = m.initialize(0.0).unwrap_err();
        assert!(
            e.contains(
                "preset = 2 sets rudder_max = 1.5707963267948966, but rudder_max was set to 0.5"
            ),
            "{e}"
        );
        // the preset's own value is accepted, also when set in step mode
        let mut m = ContainerShipFmu::default();
        m.params.rudder_rate_max = 1.0;
        m.select_preset(2);
        m.initialize(0.0).unwrap();
        m.params.rudder_rate_max = 0.2;
        assert!(m.parameters_changed().is_err());
        m.preset = 3;
        assert!(m.initialize(0.0).unwrap_err().contains("preset = 3"));
    }

    /// Every initial-state parameter is the state at the start (variant 1 and 2), the defaults
    /// are today's start, and a roll outside (-pi/2, pi/2) or a non-finite value is refused.
    #[test]
    fn the_initial_state_is_the_start() {
        let mut m = ContainerShipFmu::default();
        m.initialize(0.0).unwrap();
        let today = ContainerShip::at_equilibrium(DEFAULT_SHAFT_SPEED).unwrap();
        let Hull::Nonlinear(s) = &m.hull else {
            panic!("variant 1")
        };
        assert_eq!(s.state(), today.state());

        m.initial_sway_velocity = 0.5;
        m.initial = InitialState {
            yaw_rate: 0.01,
            x: 10.0,
            y: -20.0,
            heading: 0.3,
            roll_rate: -0.02,
            roll: 0.1,
            rudder_angle: -0.05,
        };
        m.initialize(0.0).unwrap();
        let Hull::Nonlinear(s) = &m.hull else {
            panic!("variant 1")
        };
        let u = ContainerShip::straight_line_speed(80.0);
        assert_eq!(
            s.state(),
            &[u, 0.5, 0.01, 10.0, -20.0, 0.3, -0.02, 0.1, -0.05, 80.0]
        );
        m.variant = 2;
        m.initialize(0.0).unwrap();
        let Hull::Linear(s) = &m.hull else {
            panic!("variant 2")
        };
        assert_eq!(
            s.state(),
            &[7.0, 0.5, 0.01, 10.0, -20.0, 0.3, -0.02, 0.1, -0.05]
        );
        m.initial.roll = 1.6;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("initial_roll = 1.6"), "{e}");
        m.initial.roll = 0.0;
        m.initial.x = f64::NAN;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("initial_x = NaN"), "{e}");
    }

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
