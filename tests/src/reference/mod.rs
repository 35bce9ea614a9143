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

pub mod container_ship;
pub mod current;
pub mod dgps_kalman;
pub mod dp_controller;
pub mod loop_shaped;
pub mod manoeuvre;
pub mod mariner;
pub mod nomoto_ship;
pub mod parameter_ekf;
pub mod passive_observer;
pub mod path_controller;
pub mod path_estimator;
pub mod path_kalman_filter;
pub mod path_wls;
pub mod rrs_autopilot;
pub mod rrs_filter;
pub mod rrs_ship;
pub mod sensors;
pub mod steering_gear;
pub mod supply_vessel;
pub mod tokyo_maru;
pub mod waves;
pub mod wind;

/// A reference case: name, description, generator.
pub type Case = (
    &'static str,
    &'static str,
    fn(&mut dyn Write) -> std::io::Result<()>,
);

pub const CASES: &[Case] = &[
    (
        "heading_autopilot_track_change",
        "HeadingAutopilot with the track-change generator (-90 deg at 0.05 rad/s from 10 s, 60 s leg); \
         heading input a lagging pseudo-response; h = 0.05 s, 200 s",
        loop_shaped::heading_track_change,
    ),
    (
        "track_controller_offset",
        "TrackController with external reference (20 m step at 5 s), cross_track input \
         15(1 - exp(-t/30)) + 0.5 sin(0.9 t) m; h = 0.05 s, 200 s",
        loop_shaped::track_offset,
    ),
    (
        "dp_controller",
        "DpController with default gains (Northern Clipper, bandwidth 0.05 rad/s, zeta 0.9, r 10) and the eq. 61 test input scaled to 1e5/1e5/1e7; sinusoidal estimates, ramped set points; h = 1 s, 600 s",
        dp_controller::case,
    ),
    (
        "path_controller_adaptive",
        "PathController, adaptation 2 (estimates), dither windows of 1 L every 3 L from t' = 1; \
         sinusoidal state-estimate inputs, f23/f25 estimates at deep-water values; h = 0.5 s, 300 s",
        path_controller::adaptive,
    ),
    (
        "path_estimator_dither",
        "PathEstimator (MVE) on the noise-free Tokyo Maru at H/T = 1.89 under a +-0.5 rad dither; \
         h = 0.25 s, 600 steps",
        path_estimator::dither,
    ),
    (
        "path_wls_windows",
        "PathWlsEstimator (WLS) on the Tokyo Maru in deep water under the constant disturbance and a \
         +-0.5 rad dither, perturbed measurements; windows of 1 L every 1.5 L from t' = 0.5; \
         h = 0.25 s, 870 steps",
        path_wls::windows,
    ),
    (
        "rrs_autopilot_adaptive",
        "RrsAutopilot with criterion adaptation (q_phi(0) = 40, rate_max 0.12 rad/s); roll at 0.63 rad/s growing from 2 to 12 deg, \
         speed 11 -> 8 m/s, slow heading error; h = 0.1 s, 300 s",
        rrs_autopilot::adaptive,
    ),
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
    (
        "sensors_default",
        "Sensors with default noise levels (004 Table 3, 002 DGPS), seed 8, roll_sigma 0.3; \
         true channel i = (i+1) sin(0.1 t + 0.05 i); h = 0.1 s, 60 s",
        sensors::default_noise,
    ),
    (
        "container_ship_nonlinear",
        "ContainerShip with default parameters (80 rpm equilibrium), rudder_command = 0.3 \
         sin(0.05 t) rad, shaft_speed_command = 80 - 10 sin(0.01 t) rpm, sway_force = 1e5 \
         sin(0.1 t) N, roll_moment = 2e6 sin(0.5 t) N.m, yaw_moment = -1e6 cos(0.02 t) N.m; h \
         = 0.1 s, 300 s: rudder limits engage",
        container_ship::nonlinear,
    ),
    (
        "container_ship_linear",
        "ContainerShip variant 2 (linearised, U0 = 7 m/s), rudder_command = 0.2 sin(0.03 t) \
         rad; h = 0.25 s, 300 s",
        container_ship::linear,
    ),
    (
        "path_kalman_filter",
        "PathKalmanFilter with default parameters (random walk, H/T 1.89, Table 5 gains); heading = 0.02 sin(0.03 t), yaw_rate = 6e-4 cos(0.03 t), cross_track = 5 + 0.02 t, rudder_command = +-0.05 square wave of period 120 s; h = 0.25 s, 300 s",
        path_kalman_filter::case,
    ),
    (
        "mariner_trimmed",
        "Mariner from the trimmed straight course at 15 kn, rudder_command = trim + 0.3 \
         sin(0.04 t) rad; h = 0.1 s, 300 s: rudder rate limit engages",
        mariner::trimmed,
    ),
    (
        "rrs_ship_simulation",
        "RrsShip model 1 (22 kn simulation model, Tables 2.1/2.2), rudder_angle = 0.1 sin(0.3 \
         t) rad, speed 11.32 m/s, wave_elevation = 0.5 sin(0.64 t) + 0.3 sin(0.9 t) m, \
         roll/yaw disturbances 0.01 sin(0.2 t), 0.005 cos(0.1 t); h = 0.05 s, 200 s",
        rrs_ship::simulation,
    ),
    (
        "rrs_ship_control",
        "RrsShip model 2 (control model, Table 2.4 speed laws), rudder_angle = 0.1 sin(0.3 t) \
         rad, speed = 8 + 0.02 t m/s, roll/yaw disturbances as rrs_ship_simulation; h = 0.05 \
         s, 200 s",
        rrs_ship::control,
    ),
    (
        "current_parsons1980",
        "Current: 5-kn beam current stepped in at 30 s, 004 design current, 4x passing ship at \
         t' = 20, white N', shaping Y', random-walk Y', 001 bias; seed 6; heading 0.2 sin(0.01 t); \
         h = 0.5 s, 1200 s",
        current::disturbances_parsons1980,
    ),
    (
        "rrs_filter",
        "RrsFilter with default parameters (T 0.1 s, Table 2.4 at 11 m/s, roll q (10, 0.001), adaptive yaw filter, L speed filter); roll = 0.1 sin(0.63 t) + 0.02, heading = 0.05 sin(0.02 t) + 0.01 sin(0.9 t), speed = 11 + 4 sin(0.01 t) + 0.5 sin(1.7 t), roll_rudder = 0.01 cos(0.63 t), course_rudder = 0.02 cos(0.01 t); h = 0.25 s, 300 s",
        rrs_filter::case,
    ),
    (
        "wind_gusts",
        "Wind with default gusts (10 m/s, 1.5 m/s, 20 s; 5 deg, 60 s), seed 4, roll_coefficient \
         2e3, yaw_coefficient 5e3, wind_direction 1.0 rad; ship_speed = 5 + 0.01 t, heading = \
         0.5 sin(0.02 t); h = 0.1 s, 300 s",
        wind::gusts,
    ),
    (
        "tokyo_maru_design_depth",
        "TokyoMaru at H/T = 1.89, rudder_angle = 0.1 sin(0.02 t) rad, yaw_moment_prime = 1e-4 \
         sin(0.01 t), sway_force_prime = 2e-3 cos(0.015 t), current_lateral = 0.3 m/s; h = 1 \
         s, 600 s",
        tokyo_maru::design_depth,
    ),
    (
        "tokyo_maru_gear_deep",
        "TokyoMaru deep water (deep_water = true) with the internal steering gear, \
         rudder_command = 0.1 sign(sin(0.02 t)); h = 0.5 s, 600 s",
        tokyo_maru::gear_deep,
    ),
    (
        "nomoto_ship_ddg51",
        "NomotoShip model 1 (DDG-51 Nomoto, 22 kn), rudder_angle = 0.1 sin(0.05 t) rad, \
         current 0.5 m/s toward 1 rad; h = 0.1 s, 300 s",
        nomoto_ship::ddg51,
    ),
    (
        "nomoto_ship_esso_osaka",
        "NomotoShip model 2 (Esso Osaka sway-yaw), rudder_angle = 0.1 sin(0.02 t) rad; h = \
         0.5 s, 600 s",
        nomoto_ship::esso_osaka,
    ),
    (
        "supply_vessel_thrust",
        "SupplyVessel (Northern Clipper), thrust 1e5 sin(0.01 t) N / 5e4 cos(0.02 t) N / 1e6 \
         sin(0.015 t) N.m, bias 2e4, -1e4 N, 5e5 N.m, wave motion 0.5 sin(0.8 t) m, 0.3 \
         cos(0.7 t) m, 0.02 sin(0.9 t) rad; h = 0.2 s, 600 s",
        supply_vessel::thrust,
    ),
    (
        "manoeuvre_zigzag",
        "Manoeuvre kind 2 (zig-zag 10/10, execute at 10 s) driven by heading = 0.3 sin(0.05 \
         (t - 10)) for t > 10, yaw_rate = its derivative; h = 0.1 s, 300 s",
        manoeuvre::zigzag,
    ),
    (
        "manoeuvre_pull_out",
        "Manoeuvre kind 3 (pull-out, 20 deg for 60 s from 10 s) with heading = 0.01 t; h = \
         0.5 s, 200 s",
        manoeuvre::pull_out,
    ),
    (
        "passive_observer",
        "PassiveObserver with default parameters (Northern Clipper, eq. 59 gains, mass-normalised injection); north = 0.02 t + 3 sin(0.9 t), east = 5 sin(0.01 t) - 2 cos(0.85 t), heading = 0.1 + 0.01 sin(0.9 t), tau = 1e5 (sin 0.05 t, sin 0.1 t, sin 0.07 t); h = 1 s, 600 s",
        passive_observer::case,
    ),
    (
        "dgps_kalman_steady",
        "DgpsKalman with default parameters (steady-state form, S_p 0.01, R 4 m2) and \
         initial_velocity_north = 7 m/s; 7 m/s ship \
         turning at 0.03 rad/s from 60 s, fixes with ~2 m deterministic noise, heading = course \
         + 0.1 sin(0.02 t), current 0.3 + 0.1 sin(0.01 t) m/s toward 1 + 0.2 cos(0.015 t) rad; \
         h = 1 s, 600 s",
        dgps_kalman::steady,
    ),
    (
        "dgps_kalman_full_recursion",
        "DgpsKalman as dgps_kalman_steady with full_recursion = true, process_noise_level = \
         0.1; h = 2 s (two filter cycles per step), 600 s",
        dgps_kalman::full_recursion,
    ),
    (
        "parameter_ekf",
        "ParameterEkf with default parameters (Esso Osaka preset, Table 4.1 noise); inputs from \
         the Esso Osaka linear model in a 10/10 zig-zag (u = U, v, r, n = 80 + 0.5 sin(0.1 t) \
         rpm, rudder stepped); h = 0.5 s, 900 s",
        parameter_ekf::case,
    ),
];
