//! `Sensors` FMU: sample-and-hold plus Gaussian white measurement noise per channel
//! (`models::sensors`), with the noise levels of 004 Tables 3/9 and 002's DGPS. No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::sensors::{SensorParams, Sensors, CHANNELS};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one sensor block.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SensorsFmu {
    params: SensorParams,
    input: [f64; CHANNELS],
    sensors: Sensors,
}

impl Default for SensorsFmu {
    fn default() -> Self {
        let params = SensorParams::default();
        SensorsFmu {
            sensors: Sensors::new(params.clone(), 0.0, [0.0; CHANNELS])
                .expect("preset parameters are valid"),
            params,
            input: [0.0; CHANNELS],
        }
    }
}

type V = Variable<SensorsFmu>;

macro_rules! table {
    ($( $i:literal, $name:literal, $unit:literal, $what:literal; )*) => {
        [
            V::integer_parameter(
                "seed",
                false,
                "Seed of this instance's ChaCha8 streams (one stream per channel)",
                0,
                i32::MAX,
                |m| m.params.seed as i32,
                |m, v| m.params.seed = v as u64,
            ),
            V::real_parameter(
                "noise_scale",
                None,
                true,
                "Multiplies every sigma (004 uses 1, 0.001 and 0)",
                |m| m.params.noise_scale,
                |m, v| m.params.noise_scale = v,
            )
            .with_range(Some(0.0), None),
            $(
                V::real_parameter(
                    concat!($name, "_sigma"),
                    Some($unit),
                    true,
                    concat!("Per-sample standard deviation of the ", $what, " noise"),
                    |m| m.params.channels[$i].sigma,
                    |m, v| m.params.channels[$i].sigma = v,
                )
                .with_range(Some(0.0), None),
                V::real_parameter(
                    concat!($name, "_interval"),
                    Some("s"),
                    false,
                    concat!("Sampling interval of the ", $what, " (samples at t0 + k interval, held)"),
                    |m| m.params.channels[$i].interval,
                    |m, v| m.params.channels[$i].interval = v,
                )
                .with_range(Some(1e-6), None),
                V::real_input(
                    $name,
                    Some($unit),
                    concat!("True ", $what),
                    |m| m.input[$i],
                    |m, v| m.input[$i] = v,
                ),
                V::real_output(
                    concat!($name, "_measured"),
                    Some($unit),
                    concat!("Measured ", $what, ": sampled true value plus noise, zero-order hold"),
                    |m| m.sensors.measured($i),
                ),
            )*
        ]
    };
}

static VARIABLES: [V; 2 + 4 * CHANNELS] = table! {
    0, "heading", "rad", "heading psi (default: 004 Table 3 compass, sigma' = 1.611e-3 at 0.2349 s)";
    1, "yaw_rate", "rad/s", "yaw rate r (default: 004 Table 3 rate gyro, 7.563e-3 U/L at 0.2349 s)";
    2, "roll", "rad", "roll angle phi (no level in the sources: 0)";
    3, "roll_rate", "rad/s", "roll rate p (no level in the sources: 0)";
    4, "north", "m", "north position (default: 002 DGPS, 2 m at 1 s)";
    5, "east", "m", "east position (default: 002 DGPS, 2 m at 1 s)";
    6, "cross_track", "m", "cross-track offset eta (default: 004 Table 3 DECCA, 9.549e-3 L at 0.2349 s)";
    7, "speed", "m/s", "speed (no level in the sources: 0)";
    8, "sway_velocity", "m/s", "sway velocity v = -U beta (default: 004 Table 3 Doppler, 1.495e-3 U at 0.2349 s)";
};

impl FmuModel for SensorsFmu {
    const MODEL_IDENTIFIER: &'static str = "Sensors";
    const DESCRIPTION: &'static str = "Seeded sensor block: sample-and-hold plus Gaussian white \
        noise for heading, yaw rate, roll, roll rate, position, cross-track, speed and sway \
        velocity (Parsons & Cuong 1980 Tables 3/9, Artyszuk DGPS 2 m at 1 s)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 100.0,
        step_size: 0.1,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.sensors = Sensors::new(self.params.clone(), start_time, self.input)?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.params.validate()?;
        self.sensors.set_noise(
            self.params.channels.map(|c| c.sigma),
            self.params.noise_scale,
        );
        self.sensors.set_inputs(self.input);
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.sensors.set_inputs(self.input);
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.sensors.set_inputs(self.input);
        self.sensors.advance_to(t + h);
        Ok(())
    }
}

export_fmu!(SensorsFmu);
