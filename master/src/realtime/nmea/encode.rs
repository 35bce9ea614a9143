//! The sentences a ship sends, each appended to a `String` as one framed sentence
//! ([`super::frame`]). A value that is not finite leaves its field empty (null) and, where the
//! sentence has one, sets its status to V (invalid).
//!
//! Layouts (field numbers after the address field; "NMEA Revealed" for the GPS sentences,
//! IEC 61162-1 as the manuals cited in [`super`] reproduce it for the others):
//!
//! - HDT `x.x,T`: heading [deg true], T.
//! - THS `x.x,a`: heading [deg true], mode (A autonomous, E estimated, M manual, S simulator,
//!   V invalid).
//! - ROT `x.x,A`: rate of turn [deg/min, negative: bow turns to port], status A/V.
//! - RSA `x.x,A,x.x,A`: starboard (or single) rudder sensor [deg, negative: bow turns to port],
//!   status; port rudder sensor, status (null, V: one rudder).
//! - HDG `x.x,x.x,a,x.x,a`: magnetic sensor heading [deg], deviation [deg] E/W (null),
//!   variation [deg] E/W.
//! - GGA `hhmmss.ss,llll.ll,a,yyyyy.yy,a,x,xx,x.x,x.x,M,x.x,M,x.x,xxxx`: UTC, latitude N/S,
//!   longitude E/W, quality (1: GPS fix), satellites, HDOP, antenna altitude [m] M, geoidal
//!   separation [m] M, age of differential data (null), station (null).
//! - RMC `hhmmss.ss,A,llll.ll,a,yyyyy.yy,a,x.x,x.x,ddmmyy,x.x,a,m`: UTC, status, latitude,
//!   longitude, speed over ground [kn], course over ground [deg true], date, magnetic
//!   variation [deg] E/W, mode (A autonomous, N not valid).
//! - VTG `x.x,T,x.x,M,x.x,N,x.x,K,m`: course over ground true and magnetic [deg], speed over
//!   ground [kn] and [km/h], mode.
//! - VHW `x.x,T,x.x,M,x.x,N,x.x,K`: heading true and magnetic [deg], speed through water [kn]
//!   and [km/h].
//! - MWV `x.x,a,x.x,a,A`: wind angle [deg, 0 to 359.9], reference (R relative, T true), wind
//!   speed, unit (M: m/s), status.
//!
//! Precision: headings, courses and angles 0.01 deg; rate of turn 0.01 deg/min; speeds 0.01
//! kn; positions 0.00001 minute of arc (2 cm); time 0.01 s.

use super::frame;
use super::utc::Utc;
use std::fmt::Write;

/// A position fix: UTC, latitude and longitude [deg], speed [kn] and course [deg true] over
/// ground.
#[derive(Debug, Clone, Copy)]
pub struct Fix {
    pub utc: Utc,
    pub latitude: f64,
    pub longitude: f64,
    pub speed_kn: f64,
    pub course: f64,
}

/// `x` with `decimals` digits, or nothing when it is not finite.
fn num(x: f64, decimals: usize) -> String {
    match x.is_finite() {
        true => format!("{x:.decimals$}"),
        false => String::new(),
    }
}

/// A bearing [deg] wrapped to [0, 360) after rounding to 0.01 (so 359.996 is written 0.00).
fn bearing(x: f64) -> String {
    if !x.is_finite() {
        return String::new();
    }
    let r = ((x.rem_euclid(360.0)) * 100.0).round() / 100.0;
    num(if r >= 360.0 { r - 360.0 } else { r }, 2)
}

fn status(ok: bool) -> char {
    if ok {
        'A'
    } else {
        'V'
    }
}

/// A variation [deg, east positive] as `x.x,E` or `x.x,W`.
fn variation(v: f64) -> String {
    match v.is_finite() {
        true => format!("{:.1},{}", v.abs(), if v < 0.0 { 'W' } else { 'E' }),
        false => ",".to_string(),
    }
}

/// Latitude as `ddmm.mmmmm,N` (or a longitude as `dddmm.mmmmm,E` with `lon`), rounded in
/// whole 1e-5 minutes so that a minute never reads 60.
fn angle(x: f64, lon: bool) -> String {
    if !x.is_finite() {
        return ",".to_string();
    }
    let hemi = match (lon, x < 0.0) {
        (false, false) => 'N',
        (false, true) => 'S',
        (true, false) => 'E',
        (true, true) => 'W',
    };
    let total = (x.abs() * 60.0 * 1e5).round() as u64;
    let (deg, rem) = (total / 6_000_000, total % 6_000_000);
    let (min, frac) = (rem / 100_000, rem % 100_000);
    match lon {
        false => format!("{deg:02}{min:02}.{frac:05},{hemi}"),
        true => format!("{deg:03}{min:02}.{frac:05},{hemi}"),
    }
}

/// Appends `body` (after the talker) as a sentence.
fn push(out: &mut String, talker: &str, body: std::fmt::Arguments<'_>) {
    let mut s = String::with_capacity(80);
    let _ = write!(s, "{talker}{body}");
    frame(out, &s);
}

pub fn hdt(out: &mut String, talker: &str, heading: f64) {
    push(out, talker, format_args!("HDT,{},T", bearing(heading)));
}

pub fn ths(out: &mut String, talker: &str, heading: f64, mode: char) {
    let mode = if heading.is_finite() { mode } else { 'V' };
    push(out, talker, format_args!("THS,{},{mode}", bearing(heading)));
}

/// `rate` [deg/min].
pub fn rot(out: &mut String, talker: &str, rate: f64) {
    let s = status(rate.is_finite());
    push(out, talker, format_args!("ROT,{},{s}", num(rate, 2)));
}

/// `rudder` [deg, positive: bow turns to starboard].
pub fn rsa(out: &mut String, talker: &str, rudder: f64) {
    let s = status(rudder.is_finite());
    push(out, talker, format_args!("RSA,{},{s},,V", num(rudder, 2)));
}

/// `heading` [deg true], `var` the magnetic variation [deg, east positive]: the sensor
/// heading is the magnetic one, true - variation, with no deviation.
pub fn hdg(out: &mut String, talker: &str, heading: f64, var: f64) {
    let magnetic = bearing(heading - if var.is_finite() { var } else { 0.0 });
    let v = variation(var);
    push(out, talker, format_args!("HDG,{magnetic},,,{v}"));
}

pub fn gga(out: &mut String, talker: &str, fix: &Fix) {
    let ok = fix.latitude.is_finite() && fix.longitude.is_finite();
    let (lat, lon) = (angle(fix.latitude, false), angle(fix.longitude, true));
    let q = if ok { 1 } else { 0 };
    let t = fix.utc.hhmmss();
    push(
        out,
        talker,
        format_args!("GGA,{t},{lat},{lon},{q},08,1.0,0.0,M,0.0,M,,"),
    );
}

pub fn rmc(out: &mut String, talker: &str, fix: &Fix, var: f64) {
    let ok = fix.latitude.is_finite() && fix.longitude.is_finite();
    let (lat, lon) = (angle(fix.latitude, false), angle(fix.longitude, true));
    let (t, d) = (fix.utc.hhmmss(), fix.utc.ddmmyy());
    let (sog, cog, v) = (num(fix.speed_kn, 2), bearing(fix.course), variation(var));
    let (s, mode) = if ok { ('A', 'A') } else { ('V', 'N') };
    push(
        out,
        talker,
        format_args!("RMC,{t},{s},{lat},{lon},{sog},{cog},{d},{v},{mode}"),
    );
}

pub fn vtg(out: &mut String, talker: &str, course: f64, speed_kn: f64, var: f64) {
    let magnetic = bearing(course - if var.is_finite() { var } else { 0.0 });
    let (cog, kn, kmh) = (bearing(course), num(speed_kn, 2), num(speed_kn * 1.852, 2));
    let mode = if speed_kn.is_finite() { 'A' } else { 'N' };
    push(
        out,
        talker,
        format_args!("VTG,{cog},T,{magnetic},M,{kn},N,{kmh},K,{mode}"),
    );
}

pub fn vhw(out: &mut String, talker: &str, heading: f64, speed_kn: f64, var: f64) {
    let magnetic = bearing(heading - if var.is_finite() { var } else { 0.0 });
    let (h, kn, kmh) = (bearing(heading), num(speed_kn, 2), num(speed_kn * 1.852, 2));
    push(
        out,
        talker,
        format_args!("VHW,{h},T,{magnetic},M,{kn},N,{kmh},K"),
    );
}

/// `angle` [deg, relative to the bow, clockwise], `speed` [m/s].
pub fn mwv(out: &mut String, talker: &str, angle: f64, speed: f64) {
    let s = status(angle.is_finite() && speed.is_finite());
    let (a, v) = (bearing(angle), num(speed, 2));
    push(out, talker, format_args!("MWV,{a},R,{v},M,{s}"));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(f: impl FnOnce(&mut String)) -> String {
        let mut s = String::new();
        f(&mut s);
        s
    }

    /// Every sentence against its layout, the checksums computed by hand with Python's
    /// `functools.reduce(operator.xor, body.encode())`.
    #[test]
    fn each_sentence_field_by_field() {
        assert_eq!(one(|s| hdt(s, "HE", 359.996)), "$HEHDT,0.00,T*1F\r\n");
        assert_eq!(one(|s| hdt(s, "HE", -90.0)), "$HEHDT,270.00,T*1A\r\n");
        assert_eq!(one(|s| ths(s, "HE", 12.345, 'A')), "$HETHS,12.35,A*28\r\n");
        assert_eq!(one(|s| ths(s, "HE", f64::NAN, 'A')), "$HETHS,,V*14\r\n");
        assert_eq!(one(|s| rot(s, "TI", -35.5)), "$TIROT,-35.50,A*15\r\n");
        assert_eq!(one(|s| rsa(s, "II", 3.0)), "$IIRSA,3.00,A,,V*4A\r\n");
        assert_eq!(
            one(|s| hdg(s, "HC", 10.0, -2.5)),
            "$HCHDG,12.50,,,2.5,W*3A\r\n"
        );
        assert_eq!(
            one(|s| vtg(s, "GP", 54.7, 5.5, 0.0)),
            "$GPVTG,54.70,T,54.70,M,5.50,N,10.19,K,A*1A\r\n"
        );
        assert_eq!(
            one(|s| vhw(s, "VW", 90.0, 10.0, 0.0)),
            "$VWVHW,90.00,T,90.00,M,10.00,N,18.52,K*5B\r\n"
        );
        assert_eq!(
            one(|s| mwv(s, "WI", 45.0, 7.5)),
            "$WIMWV,45.00,R,7.50,M,A*13\r\n"
        );
    }

    #[test]
    fn positions_and_time() {
        let fix = Fix {
            utc: Utc::parse("1994-03-23T12:35:19Z").unwrap(),
            latitude: 48.0 + 7.038 / 60.0,
            longitude: -(11.0 + 31.0 / 60.0),
            speed_kn: 22.4,
            course: 84.4,
        };
        assert_eq!(
            one(|s| gga(s, "GP", &fix)),
            "$GPGGA,123519.00,4807.03800,N,01131.00000,W,1,08,1.0,0.0,M,0.0,M,,*48\r\n"
        );
        assert_eq!(
            one(|s| rmc(s, "GP", &fix, 3.1)),
            "$GPRMC,123519.00,A,4807.03800,N,01131.00000,W,22.40,84.40,230394,3.1,E,A*29\r\n"
        );
        // A minute that rounds to 60 carries into the degrees.
        assert_eq!(angle(59.999_999_99, false), "6000.00000,N");
        assert_eq!(angle(-0.5, true), "00030.00000,W");
    }
}
