//! Output channels: `nmea-out` (sentences over UDP, or to the clients of a TCP listener) and
//! `udp-out` (named variables as a binary datagram or JSON), each at its own rate of
//! simulated time, sent at the communication points where they fall due.
//!
//! The binary datagram of `udp-out` (and `udp-in`), little-endian: the magic `SHIP` (4
//! bytes), the layout's version (u16, 1), the number n of values (u16), the sequence number
//! (u64, from 0), the simulated time (f64), then n f64 values in the channel's order: 24 + 8n
//! bytes. The JSON datagram: `{"seq":k,"time":t,"values":{"inst.var":x,...}}`.

use super::{address, conversion, value, Linear};
use crate::error::{Error, Result};
use crate::realtime::nmea::{datum::Datum, encode, utc::Utc};
use crate::run::Session;
use crate::system::io::{IoKind, IoSpec};
use std::io::Write;
use std::net::{SocketAddr, TcpListener, TcpStream, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// The binary layout's magic and version.
pub const MAGIC: &[u8; 4] = b"SHIP";
pub const VERSION: u16 = 1;
pub const HEADER: usize = 24;

/// Where a channel's datagrams go.
enum Sink {
    Udp(UdpSocket, SocketAddr),
    /// The connected clients of a listener (a thread accepts them).
    Tcp(Arc<Mutex<Vec<TcpStream>>>),
}

impl Sink {
    /// Sends; a TCP client that cannot take the bytes at once is dropped (a slow client never
    /// slows the step loop). Errors of UDP (no listener yet) are ignored.
    fn send(&self, bytes: &[u8]) -> bool {
        match self {
            Sink::Udp(s, to) => s.send_to(bytes, to).is_ok(),
            Sink::Tcp(clients) => {
                let mut c = clients.lock().unwrap_or_else(|e| e.into_inner());
                c.retain_mut(|s| s.write_all(bytes).is_ok());
                !c.is_empty()
            }
        }
    }
}

/// A quantity a sentence needs, its wire unit, and the variable bound to it.
const QUANTITIES: [(&str, &str); 10] = [
    ("heading", "deg"),
    ("rate_of_turn", "deg/min"),
    ("rudder_angle", "deg"),
    ("north", "m"),
    ("east", "m"),
    ("course_over_ground", "deg"),
    ("speed_over_ground", "kn"),
    ("speed_through_water", "kn"),
    ("wind_angle", "deg"),
    ("wind_speed", "m/s"),
];
const HEADING: usize = 0;
const ROT: usize = 1;
const RUDDER: usize = 2;
const NORTH: usize = 3;
const EAST: usize = 4;
const COG: usize = 5;
const SOG: usize = 6;
const STW: usize = 7;
const WIND_ANGLE: usize = 8;
const WIND_SPEED: usize = 9;

/// The sentences we send and the quantities each needs (COG and SOG may be derived from
/// north and east).
const SENTENCES: [(&str, &[usize]); 10] = [
    ("HDT", &[HEADING]),
    ("THS", &[HEADING]),
    ("ROT", &[ROT]),
    ("RSA", &[RUDDER]),
    ("HDG", &[HEADING]),
    ("GGA", &[NORTH, EAST]),
    ("RMC", &[NORTH, EAST, COG, SOG]),
    ("VTG", &[COG, SOG]),
    ("VHW", &[HEADING, STW]),
    ("MWV", &[WIND_ANGLE, WIND_SPEED]),
];

/// A sentence or datagram due every `period` s of simulated time from the start.
struct Due {
    period: f64,
    next: f64,
}

impl Due {
    fn new(rate: f64, t0: f64, what: &str, channel: usize) -> Result<Due> {
        if !(rate > 0.0 && rate.is_finite()) {
            return Err(Error::Other(format!(
                "[[io]] #{channel}: the rate of {what} must be positive ({rate})"
            )));
        }
        Ok(Due {
            period: 1.0 / rate,
            next: t0,
        })
    }

    /// True at the first point at or after the next due time (within 1e-9 s); the next one is
    /// then one period later on the channel's own grid.
    fn due(&mut self, t: f64) -> bool {
        if t + 1e-9 < self.next {
            return false;
        }
        while self.next <= t + 1e-9 {
            self.next += self.period;
        }
        true
    }
}

struct NmeaOut {
    sink: Sink,
    talker: String,
    datum: Datum,
    start: Utc,
    variation: f64,
    sentences: Vec<(usize, Due)>,
    /// Per quantity: the variable and the map to the wire unit.
    bound: Vec<Option<(String, Linear)>>,
    /// The previous (time, north, east) for derived COG and SOG.
    previous: Option<(f64, f64, f64)>,
    derived: (f64, f64),
}

struct UdpOut {
    sink: Sink,
    json: bool,
    variables: Vec<String>,
    due: Due,
    seq: u64,
    buffer: Vec<u8>,
}

enum Channel {
    Nmea(Box<NmeaOut>),
    Udp(UdpOut),
}

/// The run's output channels.
pub struct Outputs {
    channels: Vec<Channel>,
    /// Datagrams sent (for the summary).
    pub sent: u64,
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl Outputs {
    /// Opens the output channels of `specs` (the others are skipped); `channel` numbers
    /// count every `[[io]]` table from 1.
    pub fn open(session: &Session, specs: &[IoSpec]) -> Result<Outputs> {
        let mut out = Outputs {
            channels: Vec::new(),
            sent: 0,
            stop: Arc::new(AtomicBool::new(false)),
            threads: Vec::new(),
        };
        let t0 = session.plan().start_time;
        for (i, spec) in specs.iter().enumerate() {
            let n = i + 1;
            let sink = match spec.kind {
                IoKind::NmeaOut | IoKind::UdpOut => out.sink(spec, n)?,
                _ => continue,
            };
            out.channels.push(match spec.kind {
                IoKind::NmeaOut => Channel::Nmea(Box::new(nmea_out(session, spec, n, sink, t0)?)),
                _ => Channel::Udp(udp_out(session, spec, n, sink, t0)?),
            });
        }
        Ok(out)
    }

    fn sink(&mut self, spec: &IoSpec, n: usize) -> Result<Sink> {
        match spec.transport.as_deref().unwrap_or("udp") {
            "udp" => {
                let to = address(spec.to.as_deref(), "to", n)?;
                let bind = if to.is_ipv4() { "0.0.0.0:0" } else { "[::]:0" };
                let s = UdpSocket::bind(bind)
                    .map_err(|e| Error::io(format!("[[io]] #{n}: a UDP socket"), e))?;
                Ok(Sink::Udp(s, to))
            }
            "tcp" if spec.kind == IoKind::NmeaOut => {
                let at = address(spec.listen.as_deref(), "listen", n)?;
                let l = TcpListener::bind(at)
                    .map_err(|e| Error::io(format!("[[io]] #{n}: listening on {at}"), e))?;
                let clients = Arc::new(Mutex::new(Vec::new()));
                self.threads
                    .push(accept(l, clients.clone(), self.stop.clone())?);
                Ok(Sink::Tcp(clients))
            }
            t => Err(Error::Other(format!(
                "[[io]] #{n}: transport = \"{t}\": expected \"udp\" (or \"tcp\" for nmea-out)"
            ))),
        }
    }

    /// Sends what is due at the session's time. True when something was sent.
    pub fn publish(&mut self, session: &mut Session) -> Result<bool> {
        let t = session.time();
        let mut any = false;
        for c in &mut self.channels {
            let n = match c {
                Channel::Nmea(c) => c.publish(session, t)?,
                Channel::Udp(c) => c.publish(session, t)?,
            };
            self.sent += n;
            any |= n > 0;
        }
        Ok(any)
    }
}

impl Drop for Outputs {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// A thread that accepts TCP clients until `stop`.
fn accept(
    l: TcpListener,
    clients: Arc<Mutex<Vec<TcpStream>>>,
    stop: Arc<AtomicBool>,
) -> Result<std::thread::JoinHandle<()>> {
    l.set_nonblocking(true)
        .map_err(|e| Error::io("a TCP listener", e))?;
    Ok(std::thread::spawn(move || {
        while !stop.load(Ordering::SeqCst) {
            match l.accept() {
                Ok((s, _)) if s.set_nonblocking(true).is_ok() => {
                    let _ = s.set_nodelay(true);
                    clients.lock().unwrap_or_else(|e| e.into_inner()).push(s);
                }
                _ => std::thread::sleep(std::time::Duration::from_millis(20)),
            }
        }
    }))
}

fn nmea_out(session: &Session, spec: &IoSpec, n: usize, sink: Sink, t0: f64) -> Result<NmeaOut> {
    let err = |m: String| Error::Other(format!("[[io]] #{n} (nmea-out): {m}"));
    let talker = spec.talker.clone().unwrap_or_else(|| "II".into());
    if talker.len() != 2 || !talker.bytes().all(|b| b.is_ascii_uppercase()) {
        return Err(err(format!("talker = \"{talker}\": two capital letters")));
    }
    let [lat, lon] = spec
        .datum
        .ok_or_else(|| err("datum = [latitude, longitude] is required".into()))?;
    let datum = Datum::new(lat, lon).map_err(err)?;
    let start =
        Utc::parse(spec.start_date.as_deref().unwrap_or("2024-06-01T12:00:00Z")).map_err(err)?;
    let mut bound = vec![None; QUANTITIES.len()];
    for (q, var) in &spec.bind {
        let Some(i) = QUANTITIES.iter().position(|(name, _)| name == q) else {
            let names: Vec<&str> = QUANTITIES.iter().map(|(q, _)| *q).collect();
            return Err(err(format!(
                "bind: unknown quantity '{q}' (one of {})",
                names.join(", ")
            )));
        };
        bound[i] = Some((
            var.clone(),
            conversion(session, var, QUANTITIES[i].1, true)?,
        ));
    }
    let mut sentences = Vec::new();
    for s in &spec.sentences {
        let Some(i) = SENTENCES.iter().position(|(name, _)| name == s) else {
            let names: Vec<&str> = SENTENCES.iter().map(|(s, _)| *s).collect();
            return Err(err(format!("sentence '{s}' (one of {})", names.join(", "))));
        };
        for &q in SENTENCES[i].1 {
            let derivable =
                (q == COG || q == SOG) && bound[NORTH].is_some() && bound[EAST].is_some();
            if bound[q].is_none() && !derivable {
                return Err(err(format!("{s} needs bind.{}", QUANTITIES[q].0)));
            }
        }
        let rate = spec.rates.get(s).copied().or(spec.rate).unwrap_or(1.0);
        sentences.push((i, Due::new(rate, t0, s, n)?));
    }
    if let Some(k) = spec.rates.keys().find(|k| !spec.sentences.contains(k)) {
        return Err(err(format!("rates.{k}: not among the sentences")));
    }
    Ok(NmeaOut {
        sink,
        talker,
        datum,
        start,
        variation: spec.variation.unwrap_or(0.0),
        sentences,
        bound,
        previous: None,
        derived: (f64::NAN, f64::NAN),
    })
}

impl NmeaOut {
    fn quantity(&self, session: &mut Session, q: usize) -> Result<f64> {
        match &self.bound[q] {
            Some((var, lin)) => Ok(lin.apply(value(session, var)?)),
            None if q == COG => Ok(self.derived.0),
            None if q == SOG => Ok(self.derived.1),
            None => Ok(f64::NAN),
        }
    }

    /// Course [deg] and speed [kn] over ground from the displacement since the last point.
    fn derive(&mut self, session: &mut Session, t: f64) -> Result<()> {
        if self.bound[NORTH].is_none() || self.bound[EAST].is_none() {
            return Ok(());
        }
        let (n, e) = (
            self.quantity(session, NORTH)?,
            self.quantity(session, EAST)?,
        );
        if let Some((t1, n1, e1)) = self.previous {
            let dt = t - t1;
            if dt > 0.0 {
                let (dn, de) = (n - n1, e - e1);
                self.derived = (
                    de.atan2(dn).to_degrees(),
                    dn.hypot(de) / dt * 3600.0 / 1852.0,
                );
            }
        }
        self.previous = Some((t, n, e));
        Ok(())
    }

    fn publish(&mut self, session: &mut Session, t: f64) -> Result<u64> {
        self.derive(session, t)?;
        let mut text = String::new();
        for k in 0..self.sentences.len() {
            if self.sentences[k].1.due(t) {
                self.sentence(session, self.sentences[k].0, t, &mut text)?;
            }
        }
        if text.is_empty() {
            return Ok(0);
        }
        // One datagram per communication point, at most ~1400 bytes each (an Ethernet MTU).
        let mut sent = 0;
        let mut start = 0;
        let bytes = text.as_bytes();
        while start < bytes.len() {
            let mut end = start;
            for line in text[start..].split_inclusive('\n') {
                if end > start && end + line.len() - start > 1400 {
                    break;
                }
                end += line.len();
            }
            sent += u64::from(self.sink.send(&bytes[start..end]));
            start = end;
        }
        Ok(sent)
    }

    fn sentence(&self, session: &mut Session, i: usize, t: f64, out: &mut String) -> Result<()> {
        let tk = self.talker.as_str();
        let var = self.variation;
        let mut q = |k: usize| self.quantity(session, k);
        match SENTENCES[i].0 {
            "HDT" => encode::hdt(out, tk, q(HEADING)?),
            "THS" => encode::ths(out, tk, q(HEADING)?, 'A'),
            "ROT" => encode::rot(out, tk, q(ROT)?),
            "RSA" => encode::rsa(out, tk, q(RUDDER)?),
            "HDG" => encode::hdg(out, tk, q(HEADING)?, var),
            "VTG" => encode::vtg(out, tk, q(COG)?, q(SOG)?, var),
            "VHW" => encode::vhw(out, tk, q(HEADING)?, q(STW)?, var),
            "MWV" => encode::mwv(out, tk, q(WIND_ANGLE)?, q(WIND_SPEED)?),
            fix_sentence => {
                let (lat, lon) = self.datum.to_geodetic(q(NORTH)?, q(EAST)?);
                let fix = encode::Fix {
                    utc: self.start.plus(t - session.plan().start_time),
                    latitude: lat,
                    longitude: lon,
                    speed_kn: self.quantity(session, SOG)?,
                    course: self.quantity(session, COG)?,
                };
                match fix_sentence {
                    "GGA" => encode::gga(out, tk, &fix),
                    _ => encode::rmc(out, tk, &fix, var),
                }
            }
        }
        Ok(())
    }
}

fn udp_out(session: &Session, spec: &IoSpec, n: usize, sink: Sink, t0: f64) -> Result<UdpOut> {
    let json = match spec.format.as_deref().unwrap_or("binary") {
        "binary" => false,
        "json" => true,
        f => {
            return Err(Error::Other(format!(
                "[[io]] #{n}: format = \"{f}\": binary or json"
            )))
        }
    };
    if spec.variables.is_empty() || spec.variables.len() > 1000 {
        return Err(Error::Other(format!(
            "[[io]] #{n} (udp-out): variables: 1 to 1000 names"
        )));
    }
    for v in &spec.variables {
        session.variable(v)?;
    }
    Ok(UdpOut {
        sink,
        json,
        variables: spec.variables.clone(),
        due: Due::new(spec.rate.unwrap_or(1.0), t0, "the channel", n)?,
        seq: 0,
        buffer: Vec::with_capacity(HEADER + 8 * spec.variables.len()),
    })
}

impl UdpOut {
    fn publish(&mut self, session: &mut Session, t: f64) -> Result<u64> {
        if !self.due.due(t) {
            return Ok(0);
        }
        let b = &mut self.buffer;
        b.clear();
        if self.json {
            let mut values = serde_json::Map::new();
            for v in &self.variables {
                values.insert(v.clone(), serde_json::json!(value(session, v)?));
            }
            let doc = serde_json::json!({"seq": self.seq, "time": t, "values": values});
            b.extend_from_slice(doc.to_string().as_bytes());
        } else {
            b.extend_from_slice(MAGIC);
            b.extend_from_slice(&VERSION.to_le_bytes());
            b.extend_from_slice(&(self.variables.len() as u16).to_le_bytes());
            b.extend_from_slice(&self.seq.to_le_bytes());
            b.extend_from_slice(&t.to_le_bytes());
            for v in &self.variables {
                let x = value(session, v)?;
                self.buffer.extend_from_slice(&x.to_le_bytes());
            }
        }
        self.seq += 1;
        Ok(u64::from(self.sink.send(&self.buffer)))
    }
}
