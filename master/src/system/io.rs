//! The system file's `[[io]]` tables: channels that put a running system on the wire
//! (docs/system-files.md, "I/O"). The system only holds them, as written; the run checks them
//! against the FMUs and opens them ([`crate::realtime`]).

use serde::Deserialize;
use std::collections::BTreeMap;

/// What a channel does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IoKind {
    /// NMEA 0183 sentences out (UDP to `to`, or a TCP listener on `listen`).
    NmeaOut,
    /// NMEA 0183 commands in (UDP on `listen`).
    NmeaIn,
    /// Named variables out as little-endian f64 with a header, or JSON (UDP to `to`).
    UdpOut,
    /// Named variables in, the same layouts (UDP on `listen`).
    UdpIn,
}

/// One input of an `nmea-in` or `udp-in` channel: a field onto a variable.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IoInput {
    /// `SENTENCE.field` (nmea-in, e.g. `HTC.heading_to_steer`) or the value's name (udp-in).
    pub field: String,
    /// `instance.variable`: an input or tunable parameter.
    pub variable: String,
    /// udp-in: the unit the value has on the wire (default: the variable's own).
    #[serde(default)]
    pub unit: Option<String>,
    /// A heading or bearing taken as the angle nearest to this variable's value (a heading
    /// that is not wrapped, such as an autopilot's reference for a continuous heading).
    #[serde(default)]
    pub near: Option<String>,
    /// What the input does when its sender is quiet for `after` seconds of wall time:
    /// `hold` the last value (the default), fall back to `fallback`, or `end` the run.
    #[serde(default)]
    pub on_quiet: Option<String>,
    #[serde(default)]
    pub after: Option<f64>,
    #[serde(default)]
    pub fallback: Option<f64>,
}

/// One `[[io]]` table.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IoSpec {
    pub kind: IoKind,
    /// `udp` (the default) or `tcp` (nmea-out only: a listener on `listen`).
    #[serde(default)]
    pub transport: Option<String>,
    /// host:port a UDP output sends to.
    #[serde(default)]
    pub to: Option<String>,
    /// host:port an input (or a TCP output) listens on.
    #[serde(default)]
    pub listen: Option<String>,
    /// nmea-out: the talker ID (default `II`, integrated instrumentation).
    #[serde(default)]
    pub talker: Option<String>,
    /// nmea-out: the datum, [latitude, longitude] in degrees (WGS-84).
    #[serde(default)]
    pub datum: Option<[f64; 2]>,
    /// nmea-out: the UTC of the start time (`2024-06-01T12:00:00Z`).
    #[serde(default)]
    pub start_date: Option<String>,
    /// nmea-out: the magnetic variation [deg, east positive] for HDG, RMC, VTG and VHW.
    #[serde(default)]
    pub variation: Option<f64>,
    /// nmea-out: the sentences sent.
    #[serde(default)]
    pub sentences: Vec<String>,
    /// Sentences (or datagrams) per second of simulated time (default 1).
    #[serde(default)]
    pub rate: Option<f64>,
    /// nmea-out: a rate per sentence, overriding `rate`.
    #[serde(default)]
    pub rates: BTreeMap<String, f64>,
    /// nmea-out: quantities bound to variables (heading, rate_of_turn, rudder_angle, north,
    /// east, course_over_ground, speed_over_ground, speed_through_water, wind_angle,
    /// wind_speed).
    #[serde(default)]
    pub bind: BTreeMap<String, String>,
    /// udp-out: the variables sent, in order.
    #[serde(default)]
    pub variables: Vec<String>,
    /// nmea-in, udp-in: the inputs.
    #[serde(default)]
    pub inputs: Vec<IoInput>,
    /// udp-in, udp-out: `binary` (the default) or `json`.
    #[serde(default)]
    pub format: Option<String>,
    /// Inputs: the longest queue of received commands between two macro steps (default
    /// 1024); more are dropped and counted.
    #[serde(default)]
    pub queue: Option<usize>,
}
