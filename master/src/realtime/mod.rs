//! Real time: a system paced to the wall clock and on the wire.
pub mod nmea;
