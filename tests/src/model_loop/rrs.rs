//! The rudder-roll-stabilization system of `systems/rrs.toml` [Klugt1987] as a pure-Rust model
//! loop: seven instances (ship, gear, waves, wind at h = 0.05 s; sensors, filter, autopilot at
//! step_multiple = 2), Jacobi, no FMI. It records the 14 columns of the file's `[output]` bit for
//! bit as `shipsim run systems/rrs.toml` does (`tests/tests/model_loop.rs`).
//!
//! Each instance below is its FMU's wrapper without the export layer: the wrapper's start
//! values and the system file's parameters, its `initialize`, `calculate_outputs` and `do_step`
//! (`fmus/<name>/src/lib.rs`), and the outputs its variable table reads. [`RrsLoop::macro_step`]
//! is the master's Jacobi step over them; [`RrsLoop::set_inputs`] is the connection list.
//!
//! The waves are used only through `Waves`' public API as the `Waves` FMU uses it (`Waves::new`,
//! `set_inputs`, `advance_to`, `roll_moment`, `yaw_moment`, and the FMU's σ_i from
//! `wf_sigma_for_std`), so a faster wave model changes the FMU system and this loop alike.

pub use super::disturbances::Moments;
use super::disturbances::{bretschneider, WavesInstance, WindInstance};
use super::{link, n_steps, LoopSummary};
use models::controllers::rrs::{RollMode, RrsAutopilot, RrsAutopilotParams, RrsInputs, RrsOutputs};
use models::disturbances::wind::WindParams;
use models::error::check_positive;
use models::hull::rrs_ship::{RrsShip, RrsShipInputs};
use models::observers::rrs_filter::{
    RollFilterParams, RrsFilter, RrsFilterInputs, SpeedFilterParams, YawFilterParams,
};
use models::sensors::{SensorParams, Sensors, CHANNELS};
use models::steering_gear::{SteeringGear, SteeringGearParams};
use shipsim::run::TimeGrid;
use std::f64::consts::FRAC_PI_2;
use std::time::Instant;

/// `[simulation]` of the system file.
pub const START_TIME: f64 = 0.0;
pub const STOP_TIME: f64 = 1200.0;
pub const STEP_SIZE: f64 = 0.05;
/// step_multiple of sensors, filter and autopilot (the others step every base step).
const SLOW: u64 = 2;
/// Instances: the master's initial exchange has one round per instance.
const INSTANCES: usize = 7;

/// Ship speed U of the system file [m/s]: the ship's speed input, the waves' and wind's
/// ship_speed, the filter's design, initial and measured speed, the autopilot's start speed.
const SPEED: f64 = 11.0;
/// The RRS gear of [Klugt1987, Table 7.1] as the system file writes it: 22 deg, 15 deg/s.
const ANGLE_MAX: f64 = 0.3839724354387525;
const RATE_MAX: f64 = 0.2617993877991494;

/// The system file's main parameters; [`Default`] is `systems/rrs.toml`. Each names the
/// `--set instance.variable` it stands for.
#[derive(Clone, Debug, PartialEq)]
pub struct RrsParams {
    /// `waves.seed` (the FMU accepts 0 ..= i32::MAX).
    pub waves_seed: u64,
    /// `waves.wave_direction` [rad] (the ship heads north: π/2 is beam seas).
    pub wave_direction: f64,
    /// `waves.significant_wave_height` [m].
    pub significant_wave_height: f64,
    /// `waves.wave_period` [s] (Bretschneider: mean period).
    pub wave_period: f64,
    /// `waves.roll_gain` [N].
    pub wave_roll_gain: f64,
    /// `wind.seed`.
    pub wind_seed: u64,
    /// `sensors.seed`.
    pub sensors_seed: u64,
    /// `autopilot.roll_mode` (0 Off, 1 On, 2 Forced).
    pub roll_mode: RollMode,
    /// `autopilot.adaptation_enabled`.
    pub adaptation_enabled: bool,
}

impl Default for RrsParams {
    fn default() -> Self {
        RrsParams {
            waves_seed: 1,
            wave_direction: FRAC_PI_2,
            significant_wave_height: 3.0,
            wave_period: 7.7,
            wave_roll_gain: 0.034319,
            wind_seed: 3,
            sensors_seed: 2,
            roll_mode: RollMode::On,
            adaptation_enabled: true,
        }
    }
}

/// `ship.*` outputs read by connections or recorded.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShipValues {
    pub roll: f64,
    pub heading: f64,
    pub yaw_rate: f64,
}

/// `gear.*` outputs read by connections or recorded.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GearValues {
    pub rudder_angle: f64,
    pub rudder_rate: f64,
    pub rate_saturated_time: f64,
}

/// `sensors.*` outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorValues {
    pub roll_measured: f64,
    pub heading_measured: f64,
}

/// `filter.*` outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FilterValues {
    pub roll_estimate: f64,
    pub roll_rate_estimate: f64,
    pub rudder_sway_estimate: f64,
    pub heading_estimate: f64,
    pub yaw_rate_estimate: f64,
    pub yaw_bias_estimate: f64,
    pub speed_estimate: f64,
}

/// The values published at a communication point (the master's shared `Values`): every output
/// a connection reads or `[output]` records.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RrsValues {
    pub ship: ShipValues,
    pub gear: GearValues,
    pub waves: Moments,
    pub wind: Moments,
    pub sensors: SensorValues,
    pub filter: FilterValues,
    /// `autopilot.rudder_command`, `roll_rudder`, `course_rudder`, `attenuation`.
    pub autopilot: RrsOutputs,
}

/// The recorded columns of `systems/rrs.toml`'s `[output]`, in its order.
pub const COLUMNS: [&str; 14] = [
    "ship.roll",
    "ship.heading",
    "ship.yaw_rate",
    "gear.rudder_angle",
    "gear.rudder_rate",
    "gear.rate_saturated_time",
    "autopilot.rudder_command",
    "autopilot.roll_rudder",
    "autopilot.course_rudder",
    "autopilot.attenuation",
    "filter.roll_estimate",
    "filter.heading_estimate",
    "waves.roll_moment",
    "wind.roll_moment",
];

impl RrsValues {
    /// The values of [`COLUMNS`].
    pub fn recorded(&self) -> [f64; 14] {
        [
            self.ship.roll,
            self.ship.heading,
            self.ship.yaw_rate,
            self.gear.rudder_angle,
            self.gear.rudder_rate,
            self.gear.rate_saturated_time,
            self.autopilot.rudder_command,
            self.autopilot.roll_rudder,
            self.autopilot.course_rudder,
            self.autopilot.attenuation,
            self.filter.roll_estimate,
            self.filter.heading_estimate,
            self.waves.roll_moment,
            self.wind.roll_moment,
        ]
    }
}

/// `ship` (`fmus/rrs_ship`): the control model (model = 2); the wind's disturbances are added to
/// the waves' in each step.
struct Ship {
    inputs: RrsShipInputs,
    wind_roll: f64,
    wind_yaw: f64,
    ship: RrsShip,
}

impl Ship {
    fn new() -> Ship {
        Ship {
            inputs: RrsShipInputs {
                rudder: 0.0,
                speed: SPEED,
                ..Default::default()
            },
            wind_roll: 0.0,
            wind_yaw: 0.0,
            ship: RrsShip::control_model(),
        }
    }

    /// Model 2 with the FMU's default min_speed and max_substep (those of `RrsShip::new`).
    fn initialize(&mut self) {
        self.ship = RrsShip::control_model();
    }

    fn do_step(&mut self, h: f64) {
        let mut inputs = self.inputs;
        inputs.roll_disturbance += self.wind_roll;
        inputs.yaw_disturbance += self.wind_yaw;
        self.ship.step(&inputs, h);
    }

    fn outputs(&self) -> ShipValues {
        let o = self.ship.outputs();
        ShipValues {
            roll: o.roll,
            heading: o.heading,
            yaw_rate: o.yaw_rate,
        }
    }
}

/// `gear` (`fmus/steering_gear`): the RRS gear with the file's limits, τ = 0.2 s, at 0 rad.
struct Gear {
    params: SteeringGearParams,
    command: f64,
    gear: SteeringGear,
}

impl Gear {
    fn new() -> Result<Gear, String> {
        let params = SteeringGearParams {
            angle_max: ANGLE_MAX,
            rate_max: RATE_MAX,
            time_constant: 0.2,
            ..SteeringGearParams::rrs_klugt1987()
        };
        let gear = SteeringGear::new(params.clone(), 0.0).map_err(|e| e.to_string())?;
        Ok(Gear {
            params,
            command: 0.0,
            gear,
        })
    }

    fn initialize(&mut self) -> Result<(), String> {
        self.gear = SteeringGear::new(self.params.clone(), 0.0).map_err(|e| e.to_string())?;
        self.gear.set_command(self.command);
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.gear.set_command(self.command);
    }

    fn do_step(&mut self, h: f64) {
        self.gear.step(self.command, h);
    }

    fn outputs(&self) -> GearValues {
        GearValues {
            rudder_angle: self.gear.angle(),
            rudder_rate: self.gear.rate(),
            rate_saturated_time: self.gear.rate_saturated_time(),
        }
    }
}

/// `waves` (`fmus/waves`): a Bretschneider-ITTC sea from the file, the FMU's other defaults.
fn waves_instance(p: &RrsParams) -> Result<WavesInstance, String> {
    let params = bretschneider(
        p.significant_wave_height,
        p.wave_period,
        (p.wave_roll_gain, 0.002),
        p.waves_seed,
    );
    WavesInstance::new(params, p.wave_direction, SPEED, START_TIME)
}

/// `wind` (`fmus/wind`): 10 m/s beam wind with the default gusts.
fn wind_instance(p: &RrsParams) -> Result<WindInstance, String> {
    let params = WindParams {
        seed: p.wind_seed,
        mean_speed: 10.0,
        direction: FRAC_PI_2,
        roll_coefficient: 2.35e-4,
        yaw_coefficient: 2.3e-5,
        ..WindParams::default()
    };
    WindInstance::new(params, SPEED, START_TIME)
}

/// Channels of `models::sensors` the system uses.
const HEADING: usize = 0;
const ROLL: usize = 2;

/// `sensors` (`fmus/sensors`): heading and roll sampled every 0.1 s with 0.001 rad noise.
struct SensorsInstance {
    params: SensorParams,
    true_values: [f64; CHANNELS],
    sensors: Sensors,
}

impl SensorsInstance {
    fn new(p: &RrsParams) -> Result<SensorsInstance, String> {
        let mut params = SensorParams {
            seed: p.sensors_seed,
            ..SensorParams::default()
        };
        for c in [ROLL, HEADING] {
            params.channels[c].sigma = 0.001;
            params.channels[c].interval = 0.1;
        }
        let true_values = [0.0; CHANNELS];
        Ok(SensorsInstance {
            sensors: Sensors::new(params.clone(), START_TIME, true_values)?,
            params,
            true_values,
        })
    }

    fn initialize(&mut self) -> Result<(), String> {
        self.sensors = Sensors::new(self.params.clone(), START_TIME, self.true_values)?;
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.sensors.set_inputs(self.true_values);
    }

    fn do_step(&mut self, t: f64, h: f64) {
        self.sensors.set_inputs(self.true_values);
        self.sensors.advance_to(t + h);
    }

    fn outputs(&self) -> SensorValues {
        SensorValues {
            roll_measured: self.sensors.measured(ROLL),
            heading_measured: self.sensors.measured(HEADING),
        }
    }
}

/// `filter` (`fmus/rrs_filter`): sample time 0.1 s, designed, started and measured at 11 m/s,
/// the FMU's default q = (10, 0.001) and realised yaw and speed filters.
struct FilterInstance {
    inputs: RrsFilterInputs,
    filter: RrsFilter,
}

impl FilterInstance {
    fn new() -> Result<FilterInstance, String> {
        Ok(FilterInstance {
            inputs: RrsFilterInputs {
                speed: SPEED,
                ..Default::default()
            },
            filter: Self::build()?,
        })
    }

    /// `RrsFilterFmu::build` at design_speed = 11 m/s. Its yaw parameters are the speed-law
    /// fields of `realised(design_speed)` over the FMU's default `realised(11.0)`: all of
    /// `realised(11.0)` here.
    fn build() -> Result<RrsFilter, String> {
        check_positive("design_speed", SPEED)?;
        RrsFilter::new(
            RollFilterParams::table_2_4(SPEED, 10.0, 0.001),
            YawFilterParams::realised(SPEED),
            SpeedFilterParams::realised(),
            0.1,
            SPEED,
        )
    }

    fn initialize(&mut self) -> Result<(), String> {
        self.filter = Self::build()?;
        Ok(())
    }

    fn do_step(&mut self, h: f64) {
        self.filter.step(&self.inputs, h);
    }

    fn outputs(&self) -> FilterValues {
        let f = &self.filter;
        let (roll, yaw) = (f.roll.state(), f.yaw.state());
        FilterValues {
            roll_estimate: roll[0],
            roll_rate_estimate: roll[1],
            rudder_sway_estimate: roll[3],
            heading_estimate: yaw[0],
            yaw_rate_estimate: yaw[1],
            yaw_bias_estimate: yaw[2],
            speed_estimate: f.speed.estimate(),
        }
    }
}

/// `autopilot` (`fmus/rrs_autopilot`): the file's roll mode, adaptation and rudder limits.
struct AutopilotInstance {
    params: RrsAutopilotParams,
    inputs: RrsInputs,
    autopilot: RrsAutopilot,
}

impl AutopilotInstance {
    fn new(p: &RrsParams) -> Result<AutopilotInstance, String> {
        let mut params = RrsAutopilotParams {
            roll_mode: p.roll_mode,
            angle_max: ANGLE_MAX,
            rate_max: RATE_MAX,
            ..RrsAutopilotParams::default()
        };
        params.adaptation.enabled = p.adaptation_enabled;
        Ok(AutopilotInstance {
            params,
            inputs: RrsInputs {
                speed: SPEED,
                ..RrsInputs::default()
            },
            autopilot: RrsAutopilot::new(params).map_err(|e| e.to_string())?,
        })
    }

    fn initialize(&mut self) -> Result<(), String> {
        self.autopilot = RrsAutopilot::new(self.params).map_err(|e| e.to_string())?;
        Ok(())
    }

    fn do_step(&mut self, h: f64) {
        self.autopilot.step(&self.inputs, h);
    }

    /// The FMU evaluates `outputs(&inputs)` for each variable read; once here.
    fn outputs(&self) -> RrsOutputs {
        self.autopilot.outputs(&self.inputs)
    }
}

/// The RRS system at communication point t_k.
pub struct RrsLoop {
    grid: TimeGrid,
    k: u64,
    values: RrsValues,
    ship: Ship,
    gear: Gear,
    waves: WavesInstance,
    wind: WindInstance,
    sensors: SensorsInstance,
    filter: FilterInstance,
    autopilot: AutopilotInstance,
}

impl RrsLoop {
    /// The system with `params`, initialized at t_0 with its outputs published, to run until
    /// `stop_time` (on the grid as the master puts it, [`n_steps`]).
    pub fn new(params: &RrsParams, stop_time: f64) -> Result<RrsLoop, String> {
        let n = n_steps(START_TIME, stop_time, STEP_SIZE)?;
        let mut s = RrsLoop {
            grid: TimeGrid::new(START_TIME, STEP_SIZE, n),
            k: 0,
            values: RrsValues::default(),
            ship: Ship::new(),
            gear: Gear::new()?,
            waves: waves_instance(params)?,
            wind: wind_instance(params)?,
            sensors: SensorsInstance::new(params)?,
            filter: FilterInstance::new()?,
            autopilot: AutopilotInstance::new(params)?,
        };
        s.initialize()?;
        Ok(s)
    }

    /// `master/src/run/initialize.rs` with Jacobi's initial exchange: one round per instance
    /// of reading every output (in Initialization Mode after a set, each FMU first rebuilds its
    /// model: `initialize`, then `calculate_outputs`) and setting every input; then
    /// `fmi2ExitInitializationMode` (`initialize`) and the outputs at t_0.
    fn initialize(&mut self) -> Result<(), String> {
        for _ in 0..INSTANCES {
            self.initialize_models()?;
            self.gear.calculate_outputs();
            self.waves.calculate_outputs();
            self.wind.calculate_outputs();
            self.sensors.calculate_outputs();
            self.publish(true);
            self.set_inputs(true);
        }
        self.initialize_models()?;
        self.publish(true);
        Ok(())
    }

    /// Every instance's `FmuModel::initialize` at the start time.
    fn initialize_models(&mut self) -> Result<(), String> {
        self.ship.initialize();
        self.gear.initialize()?;
        self.waves.initialize(START_TIME)?;
        self.wind.initialize(START_TIME)?;
        self.sensors.initialize()?;
        self.filter.initialize()?;
        self.autopilot.initialize()
    }

    /// The connections of `systems/rrs.toml`: the inputs from the values published at the last
    /// communication point. The inputs of the slow instances are set only when they step
    /// (`slow`), as the master sets an instance's inputs only at its own steps.
    fn set_inputs(&mut self, slow: bool) {
        let v = &self.values;
        let ship = &mut self.ship;
        ship.inputs.roll_disturbance = link(v.waves.roll_moment);
        ship.inputs.yaw_disturbance = link(v.waves.yaw_moment);
        ship.wind_roll = link(v.wind.roll_moment);
        ship.wind_yaw = link(v.wind.yaw_moment);
        self.wind.heading = link(v.ship.heading);
        self.waves.heading = link(v.ship.heading);
        ship.inputs.rudder = link(v.gear.rudder_angle);
        if slow {
            let sensors = &mut self.sensors.true_values;
            sensors[ROLL] = link(v.ship.roll);
            sensors[HEADING] = link(v.ship.heading);
            let filter = &mut self.filter.inputs;
            filter.roll = link(v.sensors.roll_measured);
            filter.heading = link(v.sensors.heading_measured);
            filter.roll_rudder = link(v.autopilot.roll_rudder);
            filter.course_rudder = link(v.autopilot.course_rudder);
            let autopilot = &mut self.autopilot.inputs;
            autopilot.roll = link(v.filter.roll_estimate);
            autopilot.roll_rate = link(v.filter.roll_rate_estimate);
            autopilot.sway_rudder = link(v.filter.rudder_sway_estimate);
            autopilot.heading_error = link(v.filter.heading_estimate);
            autopilot.yaw_rate = link(v.filter.yaw_rate_estimate);
            autopilot.yaw_offset = link(v.filter.yaw_bias_estimate);
            autopilot.speed = link(v.filter.speed_estimate);
            autopilot.rudder = link(v.gear.rudder_angle);
        }
        self.gear.command = link(v.autopilot.rudder_command);
    }

    /// Publishes the outputs of the fast instances, and of the slow ones when `slow`.
    fn publish(&mut self, slow: bool) {
        let v = &mut self.values;
        v.ship = self.ship.outputs();
        v.gear = self.gear.outputs();
        v.waves = self.waves.outputs();
        v.wind = self.wind.outputs();
        if slow {
            v.sensors = self.sensors.outputs();
            v.filter = self.filter.outputs();
            v.autopilot = self.autopilot.outputs();
        }
    }

    /// One Jacobi macro step t_k → t_(k+1) (`Jacobi::step`): the inputs of the instances due
    /// at k from the values published at t_k, then each due instance steps (from t_k over
    /// t_(k+m) − t_k, the last step shortened to t_n), then the instances whose step ends at
    /// t_(k+1), and every instance at t_n, publish their outputs.
    pub fn macro_step(&mut self) {
        let (grid, k) = (self.grid, self.k);
        let n = grid.n_steps();
        assert!(k < n, "the run ended at t = {}", grid.at(n));
        let t = grid.at(k);
        let slow_steps = k % SLOW == 0;
        self.set_inputs(slow_steps);
        let h = grid
            .step_size(k, 1, n, true)
            .expect("variable steps allowed");
        self.ship.do_step(h);
        self.gear.do_step(h);
        self.waves.do_step(t, h);
        self.wind.do_step(t, h);
        if slow_steps {
            let h = grid
                .step_size(k, SLOW, n, true)
                .expect("variable steps allowed");
            self.sensors.do_step(t, h);
            self.filter.do_step(h);
            self.autopilot.do_step(h);
        }
        self.k = k + 1;
        self.publish(self.k % SLOW == 0 || self.k == n);
    }

    /// The current communication point t_k.
    pub fn time(&self) -> f64 {
        self.grid.at(self.k)
    }

    /// k: the macro steps taken.
    pub fn step_index(&self) -> u64 {
        self.k
    }

    /// The number of macro steps of the run.
    pub fn n_steps(&self) -> u64 {
        self.grid.n_steps()
    }

    /// The values published at t_k.
    pub fn values(&self) -> &RrsValues {
        &self.values
    }
}

/// Runs the system with `params` from t_0 to `stop_time`, handing `record` the published
/// values at t_0 and after every macro step, as the master hands its recorder a row (decimation
/// 1). The wall time covers the macro steps and `record` after t_0.
pub fn run(
    stop_time: f64,
    params: &RrsParams,
    mut record: impl FnMut(f64, &RrsValues),
) -> Result<LoopSummary, String> {
    let mut system = RrsLoop::new(params, stop_time)?;
    record(system.time(), system.values());
    let n = system.n_steps();
    let start = Instant::now();
    while system.step_index() < n {
        system.macro_step();
        record(system.time(), system.values());
    }
    Ok(LoopSummary {
        stop_time: system.time(),
        macro_steps: n,
        wall: start.elapsed(),
    })
}
