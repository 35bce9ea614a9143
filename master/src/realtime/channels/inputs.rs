//! Input channels: `nmea-in` (HTC, HTD, ROR, APB, RMB over UDP) and `udp-in` (named values,
//! binary or JSON, the layouts of [`super::outputs`]). Each listens on its own thread, which
//! parses every datagram as it arrives and queues the bound values, with the arrival instant,
//! in a bounded queue; the step loop drains the queues at each macro-step boundary and applies
//! the values in arrival order through [`Session::set`] (so they are journaled).
//!
//! A flood cannot grow memory: a datagram is read into a fixed 64 KiB buffer, the queue holds
//! at most `queue` updates (default 1024) and drops the rest ("queue full"), and the kernel
//! drops what the thread cannot read. Rejected sentences are counted by kind and logged once
//! per kind; nothing a sender does stops or slows the step loop.

use super::outputs::{HEADER, MAGIC, VERSION};
use super::{address, conversion, value, Linear};
use crate::error::{Error, Result};
use crate::realtime::nmea::{parse_sentence, Field};
use crate::run::Session;
use crate::system::io::{IoKind, IoSpec};
use crate::system::Value;
use std::collections::BTreeMap;
use std::net::UdpSocket;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What an input does when its sender goes quiet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Quiet {
    Hold,
    Fallback { after: f64, value: f64 },
    End { after: f64 },
}

/// One bound input.
struct Binding {
    /// nmea-in: the sentence and field; udp-in: the value's name.
    sentence: &'static str,
    field: Option<Field>,
    name: String,
    variable: String,
    wire: Linear,
    /// The variable whose value a heading is taken nearest to, and a full turn in the
    /// input's unit.
    near: Option<(String, f64)>,
    quiet: Quiet,
    last: Instant,
    fell_back: bool,
}

/// Values received in one datagram: (binding, value in the wire unit), with its arrival.
struct Update {
    arrival: Instant,
    values: Vec<(usize, f64)>,
}

/// Counts of rejected sentences (or datagrams) by kind, shared with the receiving threads.
pub type Rejections = Arc<Mutex<BTreeMap<String, u64>>>;
/// Where a first rejection of a kind is logged.
pub type Log = Arc<dyn Fn(&str) + Send + Sync>;

struct InChannel {
    bindings: Vec<Binding>,
    queue: Receiver<Update>,
    thread: Option<std::thread::JoinHandle<()>>,
}

/// The run's input channels.
pub struct Inputs {
    channels: Vec<InChannel>,
    pub rejected: Rejections,
    /// Values applied, and the arrival instants not yet reflected by an output.
    pub applied: u64,
    pub pending: Vec<Instant>,
    stop: Arc<AtomicBool>,
    log: Log,
}

/// An input from the system file, checked against the session.
fn binding(
    session: &Session,
    spec: &IoSpec,
    n: usize,
    i: &crate::system::io::IoInput,
) -> Result<Binding> {
    let err = |m: String| Error::Other(format!("[[io]] #{n}, input '{}': {m}", i.field));
    session.variable(&i.variable)?;
    let (sentence, field, wire) = match spec.kind {
        IoKind::NmeaIn => {
            let (s, f) = Field::parse_binding(&i.field).ok_or_else(|| {
                err("expected SENTENCE.field, e.g. HTC.heading_to_steer, APB.heading_to_steer, ROR.rudder_order, RMB.cross_track_error".into())
            })?;
            (s, Some(f), f.unit().to_string())
        }
        _ => ("", None, i.unit.clone().unwrap_or_default()),
    };
    let lin = match wire.is_empty() && spec.kind == IoKind::UdpIn {
        true => Linear {
            gain: 1.0,
            offset: 0.0,
        },
        false => conversion(session, &i.variable, &wire, false)?,
    };
    let near = match &i.near {
        Some(v) => {
            session.variable(v)?;
            let turn = conversion(session, &i.variable, "rad", false)?.gain * std::f64::consts::TAU;
            Some((v.clone(), turn))
        }
        None => None,
    };
    let after = i.after.filter(|a| *a > 0.0 && a.is_finite());
    let quiet = match (i.on_quiet.as_deref().unwrap_or("hold"), after, i.fallback) {
        ("hold", _, _) => Quiet::Hold,
        ("fallback", Some(after), Some(value)) => Quiet::Fallback { after, value },
        ("end", Some(after), _) => Quiet::End { after },
        (q, _, _) => {
            return Err(err(format!(
                "on_quiet = \"{q}\": \"hold\", \"fallback\" (with after = SECONDS and fallback = VALUE) or \"end\" (with after = SECONDS)"
            )))
        }
    };
    Ok(Binding {
        sentence,
        field,
        name: i.field.clone(),
        variable: i.variable.clone(),
        wire: lin,
        near,
        quiet,
        last: Instant::now(),
        fell_back: false,
    })
}

impl Inputs {
    /// Opens the input channels of `specs` and starts their threads.
    pub fn open(session: &Session, specs: &[IoSpec], log: Log) -> Result<Inputs> {
        let mut inputs = Inputs {
            channels: Vec::new(),
            rejected: Arc::new(Mutex::new(BTreeMap::new())),
            applied: 0,
            pending: Vec::new(),
            stop: Arc::new(AtomicBool::new(false)),
            log,
        };
        for (k, spec) in specs.iter().enumerate() {
            let n = k + 1;
            if !matches!(spec.kind, IoKind::NmeaIn | IoKind::UdpIn) {
                continue;
            }
            let bindings = spec
                .inputs
                .iter()
                .map(|i| binding(session, spec, n, i))
                .collect::<Result<Vec<_>>>()?;
            if bindings.is_empty() {
                return Err(Error::Other(format!("[[io]] #{n}: no inputs")));
            }
            let at = address(spec.listen.as_deref(), "listen", n)?;
            let socket = UdpSocket::bind(at)
                .map_err(|e| Error::io(format!("[[io]] #{n}: listening on {at}"), e))?;
            socket
                .set_read_timeout(Some(Duration::from_millis(20)))
                .map_err(|e| Error::io("a UDP socket", e))?;
            let (tx, rx) = sync_channel(spec.queue.unwrap_or(1024).clamp(1, 1 << 20));
            let json = spec.format.as_deref() == Some("json");
            let keys: Vec<Key> = bindings
                .iter()
                .map(|b| (b.sentence, b.field, b.name.clone()))
                .collect();
            let receiver = Receiver_ {
                socket,
                tx,
                keys,
                nmea: spec.kind == IoKind::NmeaIn,
                json,
                rejected: inputs.rejected.clone(),
                stop: inputs.stop.clone(),
                log: inputs.log.clone(),
            };
            inputs.channels.push(InChannel {
                bindings,
                queue: rx,
                thread: Some(std::thread::spawn(move || receiver.run())),
            });
        }
        Ok(inputs)
    }

    /// The local address of each input channel (for tests with port 0).
    pub fn is_empty(&self) -> bool {
        self.channels.is_empty()
    }

    /// Applies every queued value, in arrival order across channels, at the session's
    /// boundary; then the quiet rules. Returns the reason to end the run, if one fired.
    pub fn apply(&mut self, session: &mut Session) -> Result<Option<String>> {
        let mut updates: Vec<(Instant, usize, usize, f64)> = Vec::new();
        for (c, ch) in self.channels.iter().enumerate() {
            while let Ok(u) = ch.queue.try_recv() {
                updates.extend(u.values.iter().map(|&(b, x)| (u.arrival, c, b, x)));
            }
        }
        updates.sort_by_key(|u| u.0);
        // Of the values for one variable at one boundary only the last one counts (the events
        // of a step are applied in order, so the last wins): only it is set and journaled,
        // so the history grows by at most one set per variable and step, whatever a sender
        // floods.
        let last_of = |c: usize, b: usize| self.channels[c].bindings[b].variable.clone();
        let mut last: BTreeMap<String, usize> = BTreeMap::new();
        for (j, u) in updates.iter().enumerate() {
            last.insert(last_of(u.1, u.2), j);
        }
        for (j, (arrival, c, b, x)) in updates.into_iter().enumerate() {
            let binding = &mut self.channels[c].bindings[b];
            binding.last = arrival.max(binding.last);
            binding.fell_back = false;
            if last.get(&binding.variable) != Some(&j) {
                self.pending.push(arrival);
                continue;
            }
            let mut v = binding.wire.apply(x);
            if let Some((near, turn)) = &binding.near {
                let reference = value(session, near)?;
                v = reference + (v - reference - turn * ((v - reference) / turn).round());
            }
            let var = binding.variable.clone();
            match session.set(&var, Value::Real(v)) {
                Ok(()) => {
                    self.applied += 1;
                    self.pending.push(arrival);
                }
                Err(e) => count(
                    &self.rejected,
                    &self.log,
                    "refused by the variable",
                    &e.to_string(),
                ),
            }
        }
        self.quiet(session)
    }

    fn quiet(&mut self, session: &mut Session) -> Result<Option<String>> {
        let now = Instant::now();
        for b in self.channels.iter_mut().flat_map(|c| c.bindings.iter_mut()) {
            let silent = now.duration_since(b.last).as_secs_f64();
            match b.quiet {
                Quiet::Hold => {}
                Quiet::Fallback { after, value } if silent > after && !b.fell_back => {
                    b.fell_back = true;
                    (self.log)(&format!(
                        "input {} ({}) quiet for {after} s: {} falls back to {value}",
                        b.name, b.variable, b.variable
                    ));
                    session.set(&b.variable, Value::Real(value))?;
                }
                Quiet::End { after } if silent > after => {
                    return Ok(Some(format!(
                        "input {} ({}) was quiet for {after} s",
                        b.name, b.variable
                    )));
                }
                _ => {}
            }
        }
        Ok(None)
    }

    /// The rejection counts so far.
    pub fn rejections(&self) -> BTreeMap<String, u64> {
        self.rejected
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }
}

impl Drop for Inputs {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        for c in &mut self.channels {
            if let Some(t) = c.thread.take() {
                let _ = t.join();
            }
        }
    }
}

/// Counts a rejection; logs the first of its kind.
fn count(rejected: &Rejections, log: &Log, kind: &str, detail: &str) {
    let mut m = rejected.lock().unwrap_or_else(|e| e.into_inner());
    let n = m.entry(kind.to_string()).or_insert(0);
    *n += 1;
    if *n == 1 {
        drop(m);
        log(&format!(
            "rejected input ({kind}): {detail}; further ones of this kind are counted"
        ));
    }
}

/// (sentence, field, name) of a binding, for the receiving thread.
type Key = (&'static str, Option<Field>, String);

/// The receiving side of a channel, moved into its thread.
#[allow(non_camel_case_types)]
struct Receiver_ {
    socket: UdpSocket,
    tx: SyncSender<Update>,
    keys: Vec<Key>,
    nmea: bool,
    json: bool,
    rejected: Rejections,
    stop: Arc<AtomicBool>,
    log: Log,
}

impl Receiver_ {
    fn run(self) {
        let mut buf = vec![0u8; 65_536];
        while !self.stop.load(Ordering::SeqCst) {
            let Ok(len) = self.socket.recv(&mut buf) else {
                continue;
            };
            let arrival = Instant::now();
            let values = match (self.nmea, self.json) {
                (true, _) => self.nmea_values(&buf[..len]),
                (false, false) => self.binary_values(&buf[..len]),
                (false, true) => self.json_values(&buf[..len]),
            };
            if values.is_empty() {
                continue;
            }
            match self.tx.try_send(Update { arrival, values }) {
                Ok(()) => {}
                Err(TrySendError::Full(_)) => count(
                    &self.rejected,
                    &self.log,
                    "queue full",
                    "the step loop had not taken the queued inputs yet",
                ),
                Err(TrySendError::Disconnected(_)) => return,
            }
        }
    }

    fn reject(&self, kind: &str, detail: &str) {
        count(&self.rejected, &self.log, kind, detail);
    }

    /// The bound values of every sentence in a datagram (one or more lines).
    fn nmea_values(&self, data: &[u8]) -> Vec<(usize, f64)> {
        let mut out = Vec::new();
        for line in data
            .split(|b| *b == b'\n')
            .filter(|l| !l.iter().all(|b| b.is_ascii_whitespace()))
        {
            match parse_sentence(line) {
                Ok(cmd) => {
                    let before = out.len();
                    for (i, (s, f, _)) in self.keys.iter().enumerate() {
                        if *s == cmd.sentence {
                            out.extend(f.and_then(|f| cmd.get(f)).map(|x| (i, x)));
                        }
                    }
                    if out.len() == before {
                        self.reject(
                            "no bound field",
                            &format!("{} carries no field bound to an input", cmd.sentence),
                        );
                    }
                }
                Err(e) => {
                    let text = String::from_utf8_lossy(&line[..line.len().min(90)]);
                    self.reject(e.kind(), &format!("{e}: {}", text.trim_end()));
                }
            }
        }
        out
    }

    /// The binary layout: the header, then one f64 per input in order.
    fn binary_values(&self, d: &[u8]) -> Vec<(usize, f64)> {
        let n = self.keys.len();
        if d.len() != HEADER + 8 * n
            || &d[..4] != MAGIC
            || u16::from_le_bytes([d[4], d[5]]) != VERSION
            || usize::from(u16::from_le_bytes([d[6], d[7]])) != n
        {
            self.reject(
                "malformed",
                &format!(
                    "a datagram of {} bytes is not SHIP v1 with {n} values ({} bytes)",
                    d.len(),
                    HEADER + 8 * n
                ),
            );
            return Vec::new();
        }
        let mut out = Vec::with_capacity(n);
        for i in 0..n {
            let o = HEADER + 8 * i;
            let x = f64::from_le_bytes(d[o..o + 8].try_into().unwrap_or([0; 8]));
            match x.is_finite() {
                true => out.push((i, x)),
                false => self.reject(
                    "not a number",
                    &format!("value {i} ({}) is {x}", self.keys[i].2),
                ),
            }
        }
        out
    }

    /// JSON: `{"values": {"name": x, ...}}`, names among the inputs.
    fn json_values(&self, d: &[u8]) -> Vec<(usize, f64)> {
        let doc: serde_json::Value = match serde_json::from_slice(d) {
            Ok(v) => v,
            Err(e) => {
                self.reject("malformed", &format!("not JSON: {e}"));
                return Vec::new();
            }
        };
        let Some(values) = doc.get("values").and_then(|v| v.as_object()) else {
            self.reject("malformed", "no \"values\" object");
            return Vec::new();
        };
        let mut out = Vec::new();
        for (name, v) in values {
            match (self.keys.iter().position(|k| &k.2 == name), v.as_f64()) {
                (Some(i), Some(x)) if x.is_finite() => out.push((i, x)),
                (Some(_), _) => self.reject("not a number", &format!("{name} = {v}")),
                (None, _) => self.reject("unknown name", &format!("{name} is not an input")),
            }
        }
        out
    }
}
