//! The container ship in waves and wind of `systems/container_ship_seaway_autopilot.toml` as a
//! pure-Rust model loop: four instances (ship, waves, wind, autopilot) at h = 0.1 s, Jacobi, no
//! FMI. The ship's yaw and roll moment inputs are the sums of the waves' and the wind's moments
//! (the file's summed inputs). It records the 12 columns of the file's `[output]`, compared with
//! `shipsim run` in the study `container_ship_seaway`.
//!
//! Each instance below is its FMU's wrapper without the export layer, as in [`super::rrs`]: the
//! wrapper's start values and the system file's parameters, its `initialize`,
//! `calculate_outputs` and `do_step` (`fmus/<name>/src/lib.rs`), and the outputs its variable
//! table reads.
//!
//! A summed input is Σ (gain·x + offset) over its connections ([`link`] each); with two terms the
//! order of the addition does not change a bit (IEEE 754 addition is commutative).

pub use super::disturbances::Moments;
use super::disturbances::{bretschneider, WavesInstance, WindInstance};
use super::{link, n_steps, LoopSummary};
use models::controllers::loop_shaped::presets::HeadingPreset;
use models::controllers::loop_shaped::{HeadingAutopilot, HeadingDesign, HeadingReference};
use models::disturbances::wind::WindParams;
use models::hull::container_ship::{
    ContainerShip, ContainerShipInputs, ContainerShipOutputs, ContainerShipParams,
};
use shipsim::run::TimeGrid;
use std::f64::consts::{FRAC_PI_4, PI};
use std::time::Instant;

/// `[simulation]` of the system file.
pub const START_TIME: f64 = 0.0;
pub const STOP_TIME: f64 = 600.0;
pub const STEP_SIZE: f64 = 0.1;
/// Instances: the master's initial exchange has one round per instance.
const INSTANCES: usize = 4;
/// The shaft speed of the file (initial and commanded) [rpm].
const SHAFT_RPM: f64 = 70.0;

/// The system file's main parameters; [`Default`] is `systems/container_ship_seaway_autopilot.toml`.
/// Each names the `--set instance.variable` it stands for.
#[derive(Clone, Debug, PartialEq)]
pub struct SeawayParams {
    /// `ship.initial_heading` and `ap.heading_reference` [rad].
    pub heading: f64,
    /// `waves.seed`.
    pub waves_seed: u64,
    /// `waves.significant_wave_height` [m].
    pub significant_wave_height: f64,
    /// `waves.wave_period` [s].
    pub wave_period: f64,
    /// `waves.wave_direction` [rad].
    pub wave_direction: f64,
    /// `waves.roll_gain`, `waves.yaw_gain` [N.m per m].
    pub wave_gains: (f64, f64),
    /// `wind.seed`.
    pub wind_seed: u64,
    /// `wind.mean_wind_speed` [m/s].
    pub mean_wind_speed: f64,
    /// `wind.wind_direction` [rad].
    pub wind_direction: f64,
    /// `wind.roll_coefficient`, `wind.yaw_coefficient` [N.m/(m/s)²].
    pub wind_coefficients: (f64, f64),
}

impl Default for SeawayParams {
    fn default() -> Self {
        SeawayParams {
            heading: FRAC_PI_4,
            waves_seed: 7,
            significant_wave_height: 3.0,
            wave_period: 8.0,
            wave_direction: PI,
            wave_gains: (1.0e6, 4.0e6),
            wind_seed: 8,
            mean_wind_speed: 15.0,
            wind_direction: PI,
            wind_coefficients: (1.7e4, 3.75e4),
        }
    }
}

/// The values published at a communication point: every output a connection reads or
/// `[output]` records.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SeawayValues {
    pub ship: ContainerShipOutputs,
    pub waves: Moments,
    pub wind: Moments,
    /// `ap.rudder_command`.
    pub rudder_command: f64,
}

/// The recorded columns of the file's `[output]`, in its order.
pub const COLUMNS: [&str; 12] = [
    "ship.x",
    "ship.y",
    "ship.heading",
    "ship.yaw_rate",
    "ship.roll",
    "ship.rudder_angle",
    "ship.speed",
    "ap.rudder_command",
    "waves.yaw_moment",
    "wind.yaw_moment",
    "waves.roll_moment",
    "wind.roll_moment",
];

impl SeawayValues {
    /// The values of [`COLUMNS`].
    pub fn recorded(&self) -> [f64; 12] {
        let s = &self.ship;
        [
            s.x,
            s.y,
            s.heading,
            s.r,
            s.roll,
            s.rudder,
            s.speed,
            self.rudder_command,
            self.waves.yaw_moment,
            self.wind.yaw_moment,
            self.waves.roll_moment,
            self.wind.roll_moment,
        ]
    }
}

/// `ship` (`fmus/container_ship`): variant 1, preset 1 (the default servo), started on the
/// 70 rpm equilibrium at the file's heading.
struct Ship {
    heading: f64,
    inputs: ContainerShipInputs,
    ship: ContainerShip,
}

impl Ship {
    fn new(p: &SeawayParams) -> Result<Ship, String> {
        let mut s = Ship {
            heading: p.heading,
            inputs: ContainerShipInputs {
                rudder_command: 0.0,
                shaft_command_rpm: SHAFT_RPM,
                ..Default::default()
            },
            ship: ContainerShip::at_equilibrium(SHAFT_RPM).map_err(|e| e.to_string())?,
        };
        s.initialize()?;
        Ok(s)
    }

    /// `ContainerShipFmu::build`, variant 1: [u_eq, 0, 0, 0, 0, ψ0, 0, 0, 0, n].
    fn initialize(&mut self) -> Result<(), String> {
        let u = ContainerShip::straight_line_speed(SHAFT_RPM);
        let state = [
            u,
            0.0,
            0.0,
            0.0,
            0.0,
            self.heading,
            0.0,
            0.0,
            0.0,
            SHAFT_RPM,
        ];
        self.ship =
            ContainerShip::new(ContainerShipParams::default(), state).map_err(|e| e.to_string())?;
        Ok(())
    }

    fn do_step(&mut self, h: f64) {
        self.ship.step(&self.inputs, h);
    }
}

/// `waves`: the file's Bretschneider sea, gains and seed, the FMU's other defaults.
fn waves_instance(p: &SeawayParams) -> Result<WavesInstance, String> {
    let params = bretschneider(
        p.significant_wave_height,
        p.wave_period,
        p.wave_gains,
        p.waves_seed,
    );
    WavesInstance::new(params, p.wave_direction, 0.0, START_TIME)
}

/// `wind`: the file's mean wind and coefficients, the default gusts.
fn wind_instance(p: &SeawayParams) -> Result<WindInstance, String> {
    let params = WindParams {
        seed: p.wind_seed,
        mean_speed: p.mean_wind_speed,
        direction: p.wind_direction,
        roll_coefficient: p.wind_coefficients.0,
        yaw_coefficient: p.wind_coefficients.1,
        ..WindParams::default()
    };
    WindInstance::new(params, 0.0, START_TIME)
}

/// `ap` (`fmus/heading_autopilot`): preset 2, the external reference.
struct AutopilotInstance {
    design: HeadingDesign,
    reference: f64,
    heading: f64,
    autopilot: HeadingAutopilot,
}

impl AutopilotInstance {
    fn new(p: &SeawayParams) -> Result<AutopilotInstance, String> {
        let design = HeadingPreset::ContainerShip
            .design()
            .ok_or("the container-ship preset has a design")?;
        let mut a = AutopilotInstance {
            design,
            reference: p.heading,
            heading: 0.0,
            autopilot: HeadingAutopilot::new(design).map_err(|e| e.to_string())?,
        };
        a.initialize()?;
        Ok(a)
    }

    /// `HeadingAutopilotFmu::initialize`.
    fn initialize(&mut self) -> Result<(), String> {
        let mut autopilot = HeadingAutopilot::new(self.design).map_err(|e| e.to_string())?;
        autopilot.reference = HeadingReference::External;
        autopilot.start(self.heading, self.reference);
        self.autopilot = autopilot;
        Ok(())
    }

    fn do_step(&mut self, h: f64) {
        self.autopilot.step(self.heading, self.reference, h);
    }
}

/// The system at communication point t_k.
pub struct SeawayLoop {
    grid: TimeGrid,
    k: u64,
    values: SeawayValues,
    ship: Ship,
    waves: WavesInstance,
    wind: WindInstance,
    autopilot: AutopilotInstance,
}

impl SeawayLoop {
    /// The system with `params`, initialized at t_0 with its outputs published, to run until
    /// `stop_time` (on the master's grid, [`n_steps`]).
    pub fn new(params: &SeawayParams, stop_time: f64) -> Result<SeawayLoop, String> {
        let n = n_steps(START_TIME, stop_time, STEP_SIZE)?;
        let mut s = SeawayLoop {
            grid: TimeGrid::new(START_TIME, STEP_SIZE, n),
            k: 0,
            values: SeawayValues::default(),
            ship: Ship::new(params)?,
            waves: waves_instance(params)?,
            wind: wind_instance(params)?,
            autopilot: AutopilotInstance::new(params)?,
        };
        s.initialize()?;
        Ok(s)
    }

    /// The master's initialization with Jacobi's initial exchange (see [`super::rrs`]): one
    /// round per instance of rebuilding every model and reading every output, then setting
    /// every input; then `fmi2ExitInitializationMode` and the outputs at t_0.
    fn initialize(&mut self) -> Result<(), String> {
        for _ in 0..INSTANCES {
            self.initialize_models()?;
            self.waves.apply_inputs();
            self.wind.calculate_outputs();
            self.publish();
            self.set_inputs();
        }
        self.initialize_models()?;
        self.publish();
        Ok(())
    }

    fn initialize_models(&mut self) -> Result<(), String> {
        self.ship.initialize()?;
        self.waves.initialize(START_TIME)?;
        self.wind.initialize(START_TIME)?;
        self.autopilot.initialize()
    }

    /// The connections of the system file, from the values published at t_k; the two summed
    /// inputs add their connections.
    fn set_inputs(&mut self) {
        let v = &self.values;
        let ship = &mut self.ship.inputs;
        ship.rudder_command = link(v.rudder_command);
        ship.yaw_moment_ext = link(v.waves.yaw_moment) + link(v.wind.yaw_moment);
        ship.roll_moment_ext = link(v.waves.roll_moment) + link(v.wind.roll_moment);
        self.autopilot.heading = link(v.ship.heading);
        self.waves.heading = link(v.ship.heading);
        self.waves.speed = link(v.ship.speed);
        self.wind.heading = link(v.ship.heading);
        self.wind.speed = link(v.ship.speed);
    }

    fn publish(&mut self) {
        let v = &mut self.values;
        v.ship = self.ship.ship.outputs();
        v.waves = self.waves.outputs();
        v.wind = self.wind.outputs();
        v.rudder_command = self.autopilot.autopilot.command();
    }

    /// One Jacobi macro step t_k → t_(k+1): every input from the values published at t_k, every
    /// instance steps, every instance publishes.
    pub fn macro_step(&mut self) {
        let (grid, k) = (self.grid, self.k);
        let n = grid.n_steps();
        assert!(k < n, "the run ended at t = {}", grid.at(n));
        let t = grid.at(k);
        self.set_inputs();
        let h = grid
            .step_size(k, 1, n, true)
            .expect("variable steps allowed");
        self.ship.do_step(h);
        self.waves.do_step(t, h);
        self.wind.do_step(t, h);
        self.autopilot.do_step(h);
        self.k = k + 1;
        self.publish();
    }

    /// The current communication point t_k.
    pub fn time(&self) -> f64 {
        self.grid.at(self.k)
    }

    /// The values published at t_k.
    pub fn values(&self) -> &SeawayValues {
        &self.values
    }
}

/// Runs the system with `params` from t_0 to `stop_time`, handing `record` the published
/// values at t_0 and after every macro step (decimation 1).
pub fn run(
    stop_time: f64,
    params: &SeawayParams,
    mut record: impl FnMut(f64, &SeawayValues),
) -> Result<LoopSummary, String> {
    let mut system = SeawayLoop::new(params, stop_time)?;
    record(system.time(), system.values());
    let n = system.grid.n_steps();
    let start = Instant::now();
    while system.k < n {
        system.macro_step();
        record(system.time(), system.values());
    }
    Ok(LoopSummary {
        stop_time: system.time(),
        macro_steps: n,
        wall: start.elapsed(),
    })
}
