//! The commands a ship takes: HTC and HTD (heading/track control command and data, IEC
//! 61162-1), ROR (rudder order), APB and RMB (autopilot sentence B and recommended minimum
//! navigation information, as a chart plotter such as OpenCPN sends them when it follows a
//! route). [`parse_sentence`] checks the frame and the checksum and returns the fields the
//! sentence carries as a [`Command`], or a classified [`Reject`]; it never panics.
//!
//! Null fields are normal: a field is taken when it is present, and only the fields that the
//! sentence's mode needs are required (HTC/HTD in heading control need the heading to steer,
//! in track control the track, in rudder control the rudder angle; manual needs none).
//!
//! Layouts (field numbers after the address field):
//!
//! - HTC `A,x.x,a,a,a,x.x,x.x,x.x,x.x,x.x,x.x,x.x,a` (HTD adds `A,A,A,x.x`): 1 override (A in
//!   use, V not), 2 commanded rudder angle [deg], 3 its direction L/R, 4 steering mode (M
//!   manual, S stand-alone, H heading control, T track control, R rudder control), 5 turn
//!   mode (R radius, T rate, N none), 6 rudder limit [deg], 7 off-heading limit [deg], 8 radius
//!   of turn [nmi], 9 rate of turn [deg/min], 10 heading to steer [deg], 11 off-track limit
//!   [nmi], 12 track [deg], 13 heading reference T/M; HTD 14-16 rudder, off-heading and
//!   off-track status, 17 vessel heading [deg].
//! - ROR `x.x,A,x.x,A,a`: 1 starboard (or single) rudder order [deg, negative: bow to port],
//!   2 status, 3 port rudder order, 4 status, 5 command source.
//! - APB `A,A,x.x,a,N,A,A,x.x,a,c--c,x.x,a,x.x,a,a`: 1-2 status (A valid, V warning), 3
//!   cross-track error magnitude, 4 direction to steer L/R, 5 XTE units (N nmi, K km), 6
//!   arrival circle entered, 7 perpendicular passed, 8 bearing origin to destination, 9 M/T,
//!   10 destination waypoint, 11 bearing present position to destination, 12 M/T, 13 heading
//!   to steer to the destination, 14 M/T, 15 mode (NMEA 2.3, optional).
//! - RMB `A,x.x,a,c--c,c--c,llll.ll,a,yyyyy.yy,a,x.x,x.x,x.x,A,a`: 1 status, 2 cross-track
//!   error [nmi], 3 direction to steer L/R, 4 origin and 5 destination waypoint, 6-7
//!   destination latitude, 8-9 longitude, 10 range to destination [nmi], 11 bearing to
//!   destination [deg true], 12 closing velocity [kn], 13 arrival status, 14 mode (optional).
//!
//! The cross-track error is signed: positive when the direction to steer is R (the ship is
//! left of its track). Bearings must be true (T): a magnetic one is rejected, the ship
//! knowing no variation.

use super::{checksum, MAX_SENTENCE};

/// A command's field, with the unit it has on the wire ([`Field::unit`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Field {
    /// 0 manual, 1 stand-alone, 2 heading control, 3 track control, 4 rudder control.
    SteeringMode,
    /// 1 when the override is in use, else 0.
    Override,
    HeadingToSteer,
    /// Signed: positive to starboard.
    RudderOrder,
    PortRudderOrder,
    RudderLimit,
    RateOfTurn,
    RadiusOfTurn,
    Track,
    CrossTrackError,
    BearingOriginToDestination,
    BearingToDestination,
    RangeToDestination,
    DestinationLatitude,
    DestinationLongitude,
    ClosingVelocity,
    /// 1 when the arrival circle is entered, else 0.
    Arrived,
}

impl Field {
    /// Every field, for the names a system file may bind.
    pub const ALL: [Field; 17] = [
        Field::SteeringMode,
        Field::Override,
        Field::HeadingToSteer,
        Field::RudderOrder,
        Field::PortRudderOrder,
        Field::RudderLimit,
        Field::RateOfTurn,
        Field::RadiusOfTurn,
        Field::Track,
        Field::CrossTrackError,
        Field::BearingOriginToDestination,
        Field::BearingToDestination,
        Field::RangeToDestination,
        Field::DestinationLatitude,
        Field::DestinationLongitude,
        Field::ClosingVelocity,
        Field::Arrived,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Field::SteeringMode => "steering_mode",
            Field::Override => "override",
            Field::HeadingToSteer => "heading_to_steer",
            Field::RudderOrder => "rudder_order",
            Field::PortRudderOrder => "port_rudder_order",
            Field::RudderLimit => "rudder_limit",
            Field::RateOfTurn => "rate_of_turn",
            Field::RadiusOfTurn => "radius_of_turn",
            Field::Track => "track",
            Field::CrossTrackError => "cross_track_error",
            Field::BearingOriginToDestination => "bearing_origin_to_destination",
            Field::BearingToDestination => "bearing_to_destination",
            Field::RangeToDestination => "range_to_destination",
            Field::DestinationLatitude => "destination_latitude",
            Field::DestinationLongitude => "destination_longitude",
            Field::ClosingVelocity => "closing_velocity",
            Field::Arrived => "arrived",
        }
    }

    /// The field's unit on the wire (a unit of [`crate::units`]; "" for a code or flag).
    pub fn unit(self) -> &'static str {
        match self {
            Field::SteeringMode | Field::Override | Field::Arrived => "",
            Field::RateOfTurn => "deg/min",
            Field::RadiusOfTurn | Field::CrossTrackError | Field::RangeToDestination => "nmi",
            Field::ClosingVelocity => "kn",
            _ => "deg",
        }
    }

    /// The sentences that carry the field.
    pub fn sentences(self) -> &'static [&'static str] {
        match self {
            Field::SteeringMode
            | Field::Override
            | Field::RudderLimit
            | Field::RateOfTurn
            | Field::RadiusOfTurn
            | Field::Track => &["HTC", "HTD"],
            Field::HeadingToSteer => &["HTC", "HTD", "APB"],
            Field::RudderOrder => &["HTC", "HTD", "ROR"],
            Field::PortRudderOrder => &["ROR"],
            Field::CrossTrackError | Field::BearingToDestination | Field::Arrived => {
                &["APB", "RMB"]
            }
            Field::BearingOriginToDestination => &["APB"],
            Field::RangeToDestination
            | Field::DestinationLatitude
            | Field::DestinationLongitude
            | Field::ClosingVelocity => &["RMB"],
        }
    }

    /// `SENTENCE.field` (as a system file binds it) parsed: the sentence and the field.
    pub fn parse_binding(text: &str) -> Option<(&'static str, Field)> {
        let (s, f) = text.split_once('.')?;
        let field = Field::ALL.into_iter().find(|x| x.name() == f)?;
        let sentence = field.sentences().iter().find(|x| **x == s)?;
        Some((sentence, field))
    }
}

/// A command taken from one sentence: its type (HTC, HTD, ROR, APB, RMB) and the fields it
/// carried, in the field's wire unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Command {
    pub sentence: &'static str,
    pub fields: Vec<(Field, f64)>,
}

impl Command {
    pub fn get(&self, f: Field) -> Option<f64> {
        self.fields.iter().find(|(g, _)| *g == f).map(|(_, x)| *x)
    }
}

/// Why a sentence was not taken. [`Reject::kind`] is the class counted in a run's summary.
#[derive(Debug, Clone, PartialEq)]
pub enum Reject {
    /// Not a sentence: no `$`, no `*HH`, not printable ASCII, longer than 82 characters, too
    /// few fields, a character where a number or flag must be.
    Malformed(String),
    /// The checksum does not match (`got`, `computed`).
    Checksum { got: u8, computed: u8 },
    /// A well-formed sentence of a type we do not take.
    Unknown(String),
    /// A numeric field reads NaN or infinity.
    NotANumber(&'static str),
    /// A field outside its range.
    OutOfRange(&'static str, f64),
    /// A field the sentence's mode needs is null.
    Missing(&'static str),
    /// The sentence says its data are not valid (status V, mode N).
    NotValid(&'static str),
    /// A bearing referenced to magnetic north.
    Magnetic(&'static str),
}

impl Reject {
    /// The class counted in the summary.
    pub fn kind(&self) -> &'static str {
        match self {
            Reject::Malformed(_) => "malformed",
            Reject::Checksum { .. } => "bad checksum",
            Reject::Unknown(_) => "unknown sentence",
            Reject::NotANumber(_) => "not a number",
            Reject::OutOfRange(..) => "out of range",
            Reject::Missing(_) => "missing required field",
            Reject::NotValid(_) => "not valid (status V)",
            Reject::Magnetic(_) => "magnetic bearing",
        }
    }
}

impl std::fmt::Display for Reject {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Reject::Malformed(m) => write!(f, "malformed: {m}"),
            Reject::Checksum { got, computed } => {
                write!(f, "checksum {got:02X}, computed {computed:02X}")
            }
            Reject::Unknown(s) => write!(f, "sentence {s} is not one we take"),
            Reject::NotANumber(n) => write!(f, "{n} is not a number"),
            Reject::OutOfRange(n, x) => write!(f, "{n} = {x} is out of range"),
            Reject::Missing(n) => write!(f, "{n} is required and null"),
            Reject::NotValid(n) => write!(f, "{n} says the data are not valid"),
            Reject::Magnetic(n) => write!(f, "{n} is magnetic (only true bearings are taken)"),
        }
    }
}

type Fields<'a> = Vec<&'a str>;

/// Checks the frame and checksum of one sentence (CR/LF and surrounding blanks trimmed) and
/// returns its address (`TTSSS`) and fields.
fn unframe(raw: &[u8]) -> Result<(&str, Fields<'_>), Reject> {
    let malformed = |m: &str| Reject::Malformed(m.to_string());
    let text = std::str::from_utf8(raw).map_err(|_| malformed("not ASCII"))?;
    let text = text.trim_matches(|c: char| c == '\r' || c == '\n' || c == ' ' || c == '\0');
    if text.len() + 2 > MAX_SENTENCE {
        return Err(malformed("longer than 82 characters"));
    }
    if !text.bytes().all(|b| (0x20..0x7f).contains(&b)) {
        return Err(malformed("not printable ASCII"));
    }
    let body = text
        .strip_prefix('$')
        .ok_or_else(|| malformed("no leading $"))?;
    let (body, sum) = body
        .rsplit_once('*')
        .ok_or_else(|| malformed("no *checksum"))?;
    let got = match sum.len() {
        2 => u8::from_str_radix(sum, 16).map_err(|_| malformed("checksum is not hex"))?,
        _ => return Err(malformed("checksum is not two hex digits")),
    };
    let computed = checksum(body.as_bytes());
    if got != computed {
        return Err(Reject::Checksum { got, computed });
    }
    let mut parts = body.split(',');
    let address = parts.next().unwrap_or_default();
    if address.len() != 5 || !address.bytes().all(|b| b.is_ascii_alphanumeric()) {
        return Err(Reject::Unknown(address.to_string()));
    }
    Ok((address, parts.collect()))
}

/// Parses one sentence (see the module documentation).
pub fn parse_sentence(raw: &[u8]) -> Result<Command, Reject> {
    let (address, f) = unframe(raw)?;
    match &address[2..] {
        "HTC" => htc(&f, "HTC"),
        "HTD" => htc(&f, "HTD"),
        "ROR" => ror(&f),
        "APB" => apb(&f),
        "RMB" => rmb(&f),
        _ => Err(Reject::Unknown(address.to_string())),
    }
}

/// Field `i` (null when absent).
fn at<'a>(f: &[&'a str], i: usize) -> &'a str {
    f.get(i).copied().unwrap_or("")
}

/// A numeric field: None when null; NaN/inf and non-numbers are rejected; checked in
/// `range`.
fn number(
    f: &[&str],
    i: usize,
    name: &'static str,
    range: std::ops::RangeInclusive<f64>,
) -> Result<Option<f64>, Reject> {
    let s = at(f, i);
    if s.is_empty() {
        return Ok(None);
    }
    let lower = s.to_ascii_lowercase();
    if lower.contains("nan") || lower.contains("inf") {
        return Err(Reject::NotANumber(name));
    }
    if !s.bytes().all(|b| b.is_ascii_digit() || b"+-.".contains(&b)) {
        return Err(Reject::Malformed(format!("{name} '{s}' is not a number")));
    }
    let x: f64 = s
        .parse()
        .map_err(|_| Reject::Malformed(format!("{name} '{s}' is not a number")))?;
    match range.contains(&x) {
        true => Ok(Some(x)),
        false => Err(Reject::OutOfRange(name, x)),
    }
}

fn required(x: Option<f64>, name: &'static str) -> Result<f64, Reject> {
    x.ok_or(Reject::Missing(name))
}

/// A one-letter field among `allowed` (null allowed).
fn letter(f: &[&str], i: usize, name: &str, allowed: &str) -> Result<Option<char>, Reject> {
    let s = at(f, i);
    let mut c = s.chars();
    match (c.next(), c.next()) {
        (None, _) => Ok(None),
        (Some(x), None) if allowed.contains(x) => Ok(Some(x)),
        _ => Err(Reject::Malformed(format!(
            "{name} '{s}' is not one of {allowed}"
        ))),
    }
}

/// A true/magnetic reference: T or null is fine, M is rejected.
fn true_ref(f: &[&str], i: usize, name: &'static str) -> Result<(), Reject> {
    match letter(f, i, name, "TM")? {
        Some('M') => Err(Reject::Magnetic(name)),
        _ => Ok(()),
    }
}

/// A direction to steer L/R as a sign (null: +).
fn side(f: &[&str], i: usize, name: &str) -> Result<f64, Reject> {
    Ok(match letter(f, i, name, "LR")? {
        Some('L') => -1.0,
        _ => 1.0,
    })
}

const BEARING: std::ops::RangeInclusive<f64> = 0.0..=360.0;

/// HTC and HTD.
fn htc(f: &[&str], sentence: &'static str) -> Result<Command, Reject> {
    if f.len() < 13 {
        return Err(Reject::Malformed(format!(
            "{sentence} has {} fields, at least 13 expected",
            f.len()
        )));
    }
    let mut out = Vec::with_capacity(8);
    if let Some(o) = letter(f, 0, "override", "AV")? {
        out.push((Field::Override, f64::from(u8::from(o == 'A'))));
    }
    let mode = letter(f, 3, "steering mode", "MSHTR")?.ok_or(Reject::Missing("steering mode"))?;
    let code = "MSHTR".find(mode).unwrap_or(0) as f64;
    out.push((Field::SteeringMode, code));
    letter(f, 4, "turn mode", "RTN")?;
    let sign = side(f, 2, "rudder direction")?;
    let rudder = number(f, 1, "commanded rudder angle", -90.0..=90.0)?.map(|r| r * sign);
    let heading = number(f, 9, "heading to steer", BEARING)?;
    let track = number(f, 11, "commanded track", BEARING)?;
    if heading.is_some() || track.is_some() {
        true_ref(f, 12, "heading reference")?;
    }
    match mode {
        'S' | 'H' => out.push((
            Field::HeadingToSteer,
            required(heading, "heading to steer")?,
        )),
        'T' => out.push((Field::Track, required(track, "commanded track")?)),
        'R' => out.push((
            Field::RudderOrder,
            required(rudder, "commanded rudder angle")?,
        )),
        _ => {}
    }
    let optional = [
        (
            Field::RudderLimit,
            number(f, 5, "rudder limit", 0.0..=90.0)?,
        ),
        (
            Field::RadiusOfTurn,
            number(f, 7, "radius of turn", 0.0..=100.0)?,
        ),
        (
            Field::RateOfTurn,
            number(f, 8, "rate of turn", -3600.0..=3600.0)?,
        ),
    ];
    out.extend(optional.into_iter().filter_map(|(k, v)| v.map(|x| (k, x))));
    if mode != 'S' && mode != 'H' {
        out.extend(heading.map(|h| (Field::HeadingToSteer, h)));
    }
    if mode != 'T' {
        out.extend(track.map(|t| (Field::Track, t)));
    }
    if mode != 'R' {
        out.extend(rudder.map(|r| (Field::RudderOrder, r)));
    }
    if sentence == "HTD" {
        number(f, 16, "vessel heading", BEARING)?;
    }
    Ok(Command {
        sentence,
        fields: out,
    })
}

/// ROR.
fn ror(f: &[&str]) -> Result<Command, Reject> {
    if f.len() < 2 {
        return Err(Reject::Malformed("ROR has fewer than 2 fields".into()));
    }
    let mut out = Vec::with_capacity(2);
    let stbd = number(f, 0, "rudder order", -90.0..=90.0)?;
    match letter(f, 1, "rudder order status", "AV")? {
        Some('A') => out.push((Field::RudderOrder, required(stbd, "rudder order")?)),
        Some(_) => return Err(Reject::NotValid("rudder order status")),
        None => return Err(Reject::Missing("rudder order status")),
    }
    let port = number(f, 2, "port rudder order", -90.0..=90.0)?;
    if let (Some(p), Some('A')) = (port, letter(f, 3, "port rudder order status", "AV")?) {
        out.push((Field::PortRudderOrder, p));
    }
    Ok(Command {
        sentence: "ROR",
        fields: out,
    })
}

/// A status field that must be A (null counts as valid in the optional mode fields only).
fn valid(f: &[&str], i: usize, name: &'static str) -> Result<(), Reject> {
    match letter(f, i, name, "AV")? {
        Some('A') => Ok(()),
        Some(_) => Err(Reject::NotValid(name)),
        None => Err(Reject::Missing(name)),
    }
}

/// The optional NMEA 2.3 mode field: N (not valid) is rejected.
fn mode_valid(f: &[&str], i: usize) -> Result<(), Reject> {
    match letter(f, i, "mode", "ADEMSNFRPV")? {
        Some('N' | 'V') => Err(Reject::NotValid("mode")),
        _ => Ok(()),
    }
}

/// APB.
fn apb(f: &[&str]) -> Result<Command, Reject> {
    if f.len() < 14 {
        return Err(Reject::Malformed(format!(
            "APB has {} fields, at least 14 expected",
            f.len()
        )));
    }
    valid(f, 0, "status (general warning)")?;
    valid(f, 1, "status (cycle lock)")?;
    mode_valid(f, 14)?;
    let mut out = Vec::with_capacity(5);
    let heading = number(f, 12, "heading to steer", BEARING)?;
    true_ref(f, 13, "heading to steer reference")?;
    out.push((
        Field::HeadingToSteer,
        required(heading, "heading to steer")?,
    ));
    if let Some(x) = number(f, 2, "cross-track error", 0.0..=1000.0)? {
        let km = match letter(f, 4, "cross-track error units", "NK")? {
            Some('K') => 1.0 / 1.852,
            _ => 1.0,
        };
        out.push((
            Field::CrossTrackError,
            x * km * side(f, 3, "direction to steer")?,
        ));
    }
    if let Some(b) = number(f, 7, "bearing origin to destination", BEARING)? {
        true_ref(f, 8, "bearing origin to destination reference")?;
        out.push((Field::BearingOriginToDestination, b));
    }
    if let Some(b) = number(f, 10, "bearing to destination", BEARING)? {
        true_ref(f, 11, "bearing to destination reference")?;
        out.push((Field::BearingToDestination, b));
    }
    if let Some(a) = letter(f, 5, "arrival status", "AV")? {
        out.push((Field::Arrived, f64::from(u8::from(a == 'A'))));
    }
    Ok(Command {
        sentence: "APB",
        fields: out,
    })
}

/// A latitude `ddmm.mm` or longitude `dddmm.mm` with its hemisphere, in degrees.
fn position(f: &[&str], i: usize, lon: bool) -> Result<Option<f64>, Reject> {
    let name = if lon { "longitude" } else { "latitude" };
    let max = if lon { 18000.0 } else { 9000.0 };
    let Some(x) = number(f, i, name, 0.0..=max)? else {
        return Ok(None);
    };
    let (deg, min) = ((x / 100.0).floor(), x - 100.0 * (x / 100.0).floor());
    if min >= 60.0 {
        return Err(Reject::OutOfRange(name, x));
    }
    let hemi = if lon { "EW" } else { "NS" };
    let sign = match letter(f, i + 1, name, hemi)? {
        Some('S' | 'W') => -1.0,
        Some(_) => 1.0,
        None => return Err(Reject::Missing(name)),
    };
    Ok(Some(sign * (deg + min / 60.0)))
}

/// RMB.
fn rmb(f: &[&str]) -> Result<Command, Reject> {
    if f.len() < 13 {
        return Err(Reject::Malformed(format!(
            "RMB has {} fields, at least 13 expected",
            f.len()
        )));
    }
    valid(f, 0, "status")?;
    mode_valid(f, 13)?;
    let mut out = Vec::with_capacity(7);
    let xte = required(
        number(f, 1, "cross-track error", 0.0..=1000.0)?,
        "cross-track error",
    )?;
    out.push((
        Field::CrossTrackError,
        xte * side(f, 2, "direction to steer")?,
    ));
    let bearing = number(f, 10, "bearing to destination", BEARING)?;
    out.push((
        Field::BearingToDestination,
        required(bearing, "bearing to destination")?,
    ));
    let rest = [
        (Field::DestinationLatitude, position(f, 5, false)?),
        (Field::DestinationLongitude, position(f, 7, true)?),
        (
            Field::RangeToDestination,
            number(f, 9, "range", 0.0..=25_000.0)?,
        ),
        (
            Field::ClosingVelocity,
            number(f, 11, "closing velocity", -1000.0..=1000.0)?,
        ),
    ];
    out.extend(rest.into_iter().filter_map(|(k, v)| v.map(|x| (k, x))));
    if let Some(a) = letter(f, 12, "arrival status", "AV")? {
        out.push((Field::Arrived, f64::from(u8::from(a == 'A'))));
    }
    Ok(Command {
        sentence: "RMB",
        fields: out,
    })
}

#[cfg(test)]
mod tests;
