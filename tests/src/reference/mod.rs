//! Reference outputs of the Rust models for named input cases, printed as CSV with round-trip
//! float formatting. tests/python drives each FMU with the same inputs in FMPy and libcosim and
//! requires agreement to 1e-12, which proves the FMU wrapper adds nothing to the model.
//!
//! Conventions for a case: the time grid and step sizes are computed as FMPy computes them
//! (t_k = t0 + k*h; step = t_(k+1) - t_k); each row holds `time`, the inputs set at `time` (held
//! until the next row), and the outputs at `time` as an importer samples them before setting that
//! row's inputs. Row 0 holds the outputs after initialization.
//!
//! To add a case: a module here with `pub fn case(out: &mut dyn Write) -> std::io::Result<()>`
//! and one entry in [`CASES`].

use std::io::Write;

pub mod steering_gear;
pub mod waves;

/// A reference case: name, description, generator.
pub type Case = (
    &'static str,
    &'static str,
    fn(&mut dyn Write) -> std::io::Result<()>,
);

pub const CASES: &[Case] = &[
    (
        "steering_gear_sine",
        "SteeringGear with default (003 RRS) parameters, rudder_command = 0.5 sin(0.8 t) rad, \
         h = 0.01 s, 30 s: both the angle limit (22 deg) and the rate limit (15 deg/s) engage",
        steering_gear::sine,
    ),
    (
        "waves_sum_of_sinusoids",
        "Waves, default sea (SS4 PM, 400 sinusoids), seed 5, roll_gain 1e6, yaw_gain 3e5, \
         wave_direction 0.4 rad; ship_speed = 6 + 0.01 t, heading = 0.3 sin(0.05 t); h = 0.1 s, 300 s",
        waves::sum_of_sinusoids,
    ),
    (
        "waves_shaping_filter",
        "Waves as waves_sum_of_sinusoids with realisation 2 (shaping filter), shaping_form 1 \
         (003 low-pass)",
        waves::shaping_filter,
    ),
];
