//! Shared code of the system tests:
//! - [`reference`]: the Rust-model reference outputs the Python cross-checks compare FMPy and
//!   libcosim against;
//! - [`study`] and [`studies`]: coupled-system studies run through the shipsim master and
//!   compared with the sources' published values (system tests and `cargo xtask report`).

pub mod reference;
pub mod studies;
pub mod study;
