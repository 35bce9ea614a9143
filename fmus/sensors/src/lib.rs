//! `Sensors` FMU: sample-and-hold plus Gaussian white measurement noise per channel
//! (`models::sensors`), with the noise levels of [Parsons1980, Tables 3, 9] and the DGPS of
//! [Artyszuk2003, sec. 2]. No physics here.

use fmi2_export::FmuModel;
use models::sensors::{SensorParams, Sensors, CHANNELS};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one sensor block.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SensorsFmu {
    params: SensorParams,
    true_values: [f64; CHANNELS],
    sensors: Sensors,
}

impl Default for SensorsFmu {
    fn default() -> Self {
        let params = SensorParams::default();
        SensorsFmu {
            sensors: Sensors::new(params.clone(), 0.0, [0.0; CHANNELS])
                .expect("preset parameters are valid"),
            params,
            true_values: [0.0; CHANNELS],
        }
    }
}

fmi2_export::fmu! {
    SensorsFmu => "Sensors",
    description: "Seeded sensor block: sample-and-hold plus Gaussian white \
        noise for heading, yaw rate, roll, roll rate, position, cross-track, speed and sway \
        velocity (Parsons & Cuong 1980 Tables 3/9, Artyszuk DGPS 2 m at 1 s)",
    experiment: (0.0, 100.0, 0.1),
    documentation: "documentation.html",
    variables: {
        fixed int(0, i32::MAX) "seed" (params.seed as u64),
            "Seed of this instance's ChaCha8 streams (one stream per channel)";
        tunable real "noise_scale" (params.noise_scale).min(0.0),
            "Multiplies every sigma ([Parsons1980] uses 1, 0.001 and 0)";
        // Four entries per channel of models::sensors::CHANNEL_NAMES, in its order.
        tunable real "heading_sigma" ["rad"] (params.channels[0].sigma).min(0.0),
            "Per-sample standard deviation of the heading psi (default: [Parsons1980, Table 3] compass, sigma' = 1.611e-3 at 0.2349 s) noise";
        fixed real "heading_interval" ["s"] (params.channels[0].interval).min(1e-6),
            "Sampling interval of the heading psi (default: [Parsons1980, Table 3] compass, sigma' = 1.611e-3 at 0.2349 s) (samples at t0 + k interval, held)";
        input real "heading" ["rad"] (true_values[0]),
            "True heading psi (default: [Parsons1980, Table 3] compass, sigma' = 1.611e-3 at 0.2349 s)";
        output real "heading_measured" ["rad"] (|m| m.sensors.measured(0)),
            "Measured heading psi (default: [Parsons1980, Table 3] compass, sigma' = 1.611e-3 at 0.2349 s): sampled true value plus noise, zero-order hold";
        tunable real "yaw_rate_sigma" ["rad/s"] (params.channels[1].sigma).min(0.0),
            "Per-sample standard deviation of the yaw rate r (default: [Parsons1980, Table 3] rate gyro, 7.563e-3 U/L at 0.2349 s) noise";
        fixed real "yaw_rate_interval" ["s"] (params.channels[1].interval).min(1e-6),
            "Sampling interval of the yaw rate r (default: [Parsons1980, Table 3] rate gyro, 7.563e-3 U/L at 0.2349 s) (samples at t0 + k interval, held)";
        input real "yaw_rate" ["rad/s"] (true_values[1]),
            "True yaw rate r (default: [Parsons1980, Table 3] rate gyro, 7.563e-3 U/L at 0.2349 s)";
        output real "yaw_rate_measured" ["rad/s"] (|m| m.sensors.measured(1)),
            "Measured yaw rate r (default: [Parsons1980, Table 3] rate gyro, 7.563e-3 U/L at 0.2349 s): sampled true value plus noise, zero-order hold";
        tunable real "roll_sigma" ["rad"] (params.channels[2].sigma).min(0.0),
            "Per-sample standard deviation of the roll angle phi (no level in the sources: 0) noise";
        fixed real "roll_interval" ["s"] (params.channels[2].interval).min(1e-6),
            "Sampling interval of the roll angle phi (no level in the sources: 0) (samples at t0 + k interval, held)";
        input real "roll" ["rad"] (true_values[2]), "True roll angle phi (no level in the sources: 0)";
        output real "roll_measured" ["rad"] (|m| m.sensors.measured(2)),
            "Measured roll angle phi (no level in the sources: 0): sampled true value plus noise, zero-order hold";
        tunable real "roll_rate_sigma" ["rad/s"] (params.channels[3].sigma).min(0.0),
            "Per-sample standard deviation of the roll rate p (no level in the sources: 0) noise";
        fixed real "roll_rate_interval" ["s"] (params.channels[3].interval).min(1e-6),
            "Sampling interval of the roll rate p (no level in the sources: 0) (samples at t0 + k interval, held)";
        input real "roll_rate" ["rad/s"] (true_values[3]),
            "True roll rate p (no level in the sources: 0)";
        output real "roll_rate_measured" ["rad/s"] (|m| m.sensors.measured(3)),
            "Measured roll rate p (no level in the sources: 0): sampled true value plus noise, zero-order hold";
        tunable real "north_sigma" ["m"] (params.channels[4].sigma).min(0.0),
            "Per-sample standard deviation of the north position (default: [Artyszuk2003] DGPS, 2 m at 1 s) noise";
        fixed real "north_interval" ["s"] (params.channels[4].interval).min(1e-6),
            "Sampling interval of the north position (default: [Artyszuk2003] DGPS, 2 m at 1 s) (samples at t0 + k interval, held)";
        input real "north" ["m"] (true_values[4]), "True north position (default: [Artyszuk2003] DGPS, 2 m at 1 s)";
        output real "north_measured" ["m"] (|m| m.sensors.measured(4)),
            "Measured north position (default: [Artyszuk2003] DGPS, 2 m at 1 s): sampled true value plus noise, zero-order hold";
        tunable real "east_sigma" ["m"] (params.channels[5].sigma).min(0.0),
            "Per-sample standard deviation of the east position (default: [Artyszuk2003] DGPS, 2 m at 1 s) noise";
        fixed real "east_interval" ["s"] (params.channels[5].interval).min(1e-6),
            "Sampling interval of the east position (default: [Artyszuk2003] DGPS, 2 m at 1 s) (samples at t0 + k interval, held)";
        input real "east" ["m"] (true_values[5]), "True east position (default: [Artyszuk2003] DGPS, 2 m at 1 s)";
        output real "east_measured" ["m"] (|m| m.sensors.measured(5)),
            "Measured east position (default: [Artyszuk2003] DGPS, 2 m at 1 s): sampled true value plus noise, zero-order hold";
        tunable real "cross_track_sigma" ["m"] (params.channels[6].sigma).min(0.0),
            "Per-sample standard deviation of the cross-track offset eta (default: [Parsons1980, Table 3] DECCA, 9.549e-3 L at 0.2349 s) noise";
        fixed real "cross_track_interval" ["s"] (params.channels[6].interval).min(1e-6),
            "Sampling interval of the cross-track offset eta (default: [Parsons1980, Table 3] DECCA, 9.549e-3 L at 0.2349 s) (samples at t0 + k interval, held)";
        input real "cross_track" ["m"] (true_values[6]),
            "True cross-track offset eta (default: [Parsons1980, Table 3] DECCA, 9.549e-3 L at 0.2349 s)";
        output real "cross_track_measured" ["m"] (|m| m.sensors.measured(6)),
            "Measured cross-track offset eta (default: [Parsons1980, Table 3] DECCA, 9.549e-3 L at 0.2349 s): sampled true value plus noise, zero-order hold";
        tunable real "speed_sigma" ["m/s"] (params.channels[7].sigma).min(0.0),
            "Per-sample standard deviation of the speed (no level in the sources: 0) noise";
        fixed real "speed_interval" ["s"] (params.channels[7].interval).min(1e-6),
            "Sampling interval of the speed (no level in the sources: 0) (samples at t0 + k interval, held)";
        input real "speed" ["m/s"] (true_values[7]), "True speed (no level in the sources: 0)";
        output real "speed_measured" ["m/s"] (|m| m.sensors.measured(7)),
            "Measured speed (no level in the sources: 0): sampled true value plus noise, zero-order hold";
        tunable real "sway_velocity_sigma" ["m/s"] (params.channels[8].sigma).min(0.0),
            "Per-sample standard deviation of the sway velocity v = -U beta (default: [Parsons1980, Table 3] Doppler, 1.495e-3 U at 0.2349 s) noise";
        fixed real "sway_velocity_interval" ["s"] (params.channels[8].interval).min(1e-6),
            "Sampling interval of the sway velocity v = -U beta (default: [Parsons1980, Table 3] Doppler, 1.495e-3 U at 0.2349 s) (samples at t0 + k interval, held)";
        input real "sway_velocity" ["m/s"] (true_values[8]),
            "True sway velocity v = -U beta (default: [Parsons1980, Table 3] Doppler, 1.495e-3 U at 0.2349 s)";
        output real "sway_velocity_measured" ["m/s"] (|m| m.sensors.measured(8)),
            "Measured sway velocity v = -U beta (default: [Parsons1980, Table 3] Doppler, 1.495e-3 U at 0.2349 s): sampled true value plus noise, zero-order hold";
    }
}

impl FmuModel for SensorsFmu {
    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.sensors = Sensors::new(self.params.clone(), start_time, self.true_values)?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.params.validate()?;
        self.sensors.set_noise(
            self.params.channels.map(|c| c.sigma),
            self.params.noise_scale,
        );
        self.sensors.set_inputs(self.true_values);
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.sensors.set_inputs(self.true_values);
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.sensors.set_inputs(self.true_values);
        self.sensors.advance_to(t + h);
        Ok(())
    }

    fn internal_steps(&self, t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        self.sensors.internal_steps(t + h, each);
    }

    /// The model's own copy of the parameters (sample intervals, σ), which a restored state
    /// carries besides the variables': valid as `Sensors::new` requires (an infinite interval
    /// made the sampling loop endless).
    fn check_restored(&self, _time: f64) -> Result<(), String> {
        self.sensors.params().validate()
    }
}
