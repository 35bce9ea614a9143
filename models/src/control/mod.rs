//! Control and estimation numerics shared by the observers and the controllers.

pub mod riccati;
