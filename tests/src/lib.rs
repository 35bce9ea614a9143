//! Shared code of the system tests:
//! - [`model_loop`]: coupled systems run directly on the `models` crate with the master's
//!   exchange order and no FMI, bit for bit as the master runs their FMUs (the limit the FMU
//!   system is measured against);
//! - [`reference`]: the Rust-model reference outputs the Python cross-checks compare FMPy and
//!   libcosim against;
//! - [`fuzz`]: the FMI fuzzer of issue 19 (`fuzz` binary, docs/fuzzing.md);
//! - [`study`] and [`studies`]: coupled-system studies run through the shipsim master and
//!   compared with the sources' published values (system tests and `cargo xtask report`).

pub mod fuzz;
pub mod model_loop;
pub mod reference;
pub mod studies;
pub mod study;
