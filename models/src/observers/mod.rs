//! State observers of the sources: Kalman filters, the state-augmented EKF and the passive
//! nonlinear observer. Each takes the measured signals and the command actually applied as
//! inputs and produces estimates plus innovation statistics.
//!
//! | module | source |
//! | --- | --- |
//! | [`path_kalman::PathKalmanFilter`] | [Parsons1980, sec. 3.2-3.3, eqs. (47)-(52)]: steady-state Kalman-Bucy filter, Euler at Δt′ = 0.005 |
//! | [`rrs_filter::RrsFilter`] | [Klugt1987, sec. 4.4-4.5, 5.5 and 6.3, App. E-F]: roll, yaw (adaptive E[w3²]) and adaptive speed filters, Euler [Klugt1987, eqs. (6.2)-(6.4)] |
//! | [`passive_observer::PassiveObserver`] | [Fossen1999, sec. 4-6, eqs. (45)-(46), (59)-(60)]: nonlinear passive DP observer with wave filtering and bias estimation |
//! | [`dgps_kalman::DgpsKalman`] | [Artyszuk2003, sec. 2, eqs. (2)-(7)]: 4-state DGPS position/velocity filter, speed over ground and drift angle |
//! | [`parameter_ekf::ParameterEkf`] | [Taylor2000, sec. 2.2 and 4.3, Table 4.1]: continuous-discrete state-augmented EKF identifying −Y_v, m − Y_r, −N_v, m x_G − N_r, running mean of the last 67 % |
//! | [`path_model`] | [Parsons1980, sec. 3.1-3.3]: Tokyo Maru 7-state design model (shared with the path controller) |
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
