//! SSP 1.0 (Modelica Association, System Structure and Parameterization): [`write`] exports a
//! system as a `.ssp` archive.

pub mod write;
