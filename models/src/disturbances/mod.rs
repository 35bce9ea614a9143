//! Environmental disturbances: waves, wind, currents and bias processes, with the noise-process
//! and spectral machinery they share. Every random source is seeded per instance
//! ([`crate::random`]).

pub mod current;
pub mod shaping;
pub mod sinusoids;
pub mod spectral;
pub mod waves;
pub mod wind;
