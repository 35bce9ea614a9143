//! State observers of the sources: Kalman filters, the state-augmented EKF and the passive
//! nonlinear observer. Each takes the measured signals and the command actually applied as
//! inputs and produces estimates plus innovation statistics.
//!
//! | module | source |
//! | --- | --- |
//! | [`path_kalman::PathKalmanFilter`] | seed 004, spec `adaptive_path_control.md` §2.8-2.9, §5.5: steady-state Kalman-Bucy filter, Euler at Δt′ = 0.005 |
//! | [`rrs_filter::RrsFilter`] | seed 003, spec `rrs_models_filters.md` §4.4-4.7, `rrs_controller_results.md` §2.7-2.8: roll (App. E), yaw (App. F, adaptive E[w3²]) and adaptive speed filters, Euler Eqs. 6.2-6.4 |
//! | [`passive_observer::PassiveObserver`] | seed 001, spec `passive_observer_dp.md` §2.8-2.10, §3.2-3.3: nonlinear passive DP observer with wave filtering and bias estimation |
//! | [`dgps_kalman::DgpsKalman`] | seed 002, spec `dgps_kalman.md` §2.2-2.4, §3.4: 4-state DGPS position/velocity filter, speed over ground and drift angle |
//! | [`parameter_ekf::ParameterEkf`] | seed 000, spec `ddg51_ekf_autopilot.md` §2.10, §3.4: continuous-discrete state-augmented EKF identifying −Y_v, m − Y_r, −N_v, m x_G − N_r, running mean of the last 67 % |
//! | [`path_model`] | seed 004, spec `adaptive_path_control.md` §2.7-2.9: Tokyo Maru 7-state design model (shared with the path controller) |
//!
//! Gains are computed at initialization (DMatrix Riccati solvers of [`crate::riccati`]);
//! the per-step updates use fixed-size nalgebra types and allocate nothing. Every filter is
//! `Clone + Serialize + Deserialize` so an FMU state snapshot is a clone.

pub mod dgps_kalman;
pub mod parameter_ekf;
pub mod passive_observer;
pub mod path_kalman;
pub mod path_model;
pub mod rrs_filter;
