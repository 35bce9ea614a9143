//! `shipsim`: an FMI 2.0 co-simulation master (see DESIGN.md, "Master").
//!
//! - [`fmu`]: FMU import (unzip, modelDescription, libloading, all symbols resolved once).
//! - [`instance`]: a safe slave instance whose lifecycle is enforced by types.
//! - [`model_description`]: typed `modelDescription.xml`.
//! - [`inspect`]: human-readable FMU summary.

pub mod error;
pub mod fmu;
pub mod inspect;
pub mod instance;
pub mod master;
pub mod model_description;
pub mod osp;
pub mod system;

pub use error::{Error, Result};
pub use fmu::Fmu;
