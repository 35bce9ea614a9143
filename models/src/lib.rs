//! Ship-control physics in pure Rust: every model the FMUs expose lives here and is tested here.
//! No FFI: the FMU crates under `fmus/` map these types onto FMI variables.

pub mod controllers;
pub mod disturbances;
pub mod error;
pub mod hull;
pub mod integrate;
pub mod manoeuvre;
pub mod math;
pub mod memo;
pub mod observers;
pub mod random;
pub mod riccati;
pub mod sensors;
pub mod steering_gear;
