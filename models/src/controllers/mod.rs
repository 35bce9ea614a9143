//! Controllers: LQ designs and the autopilots the controller FMUs expose.
//!
//! * [`lq`]: continuous LQ state feedback in the sources' sign convention (u = C x), shared by
//!   every LQ design here; the Riccati numerics themselves are [`crate::riccati`].
//! * [`path`]: the optimal steady-state path controller of [Parsons1980] for the
//!   *Tokyo Maru* in restricted water, with gain scheduling over depth, the partial adaptation
//!   of f23/f25 from a parameter estimator (validity logic of [Parsons1980, Table 10]) and the
//!   open-loop dither.
//!
//! Design computations (Riccati equations) run at initialization, on a parameter change or on
//! an adaptation clock and may allocate; the per-step control laws use fixed-size nalgebra types
//! and allocate nothing. Every controller state is `Clone + Serialize + Deserialize` so an FMU
//! state is a clone and a serialized state its bincode bytes.

use std::fmt;

pub mod dp;
pub mod loop_shaped;
pub mod lq;
pub mod mve;
pub mod path;
pub mod rrs;
pub mod wls;

/// Why a controller could not be designed or configured: names the parameter or the design step.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlError(pub String);

impl fmt::Display for ControlError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ControlError {}

impl From<crate::riccati::RiccatiError> for ControlError {
    fn from(e: crate::riccati::RiccatiError) -> Self {
        ControlError(format!("Riccati equation: {e}"))
    }
}

impl From<crate::error::ParamError> for ControlError {
    fn from(e: crate::error::ParamError) -> Self {
        ControlError(e.to_string())
    }
}
