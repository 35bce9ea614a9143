//! The native TOML system file, read into a [`System`].
//!
//! An example with every key (gain, offset, convert, step_multiple and decimation show their
//! defaults):
//!
//! ```toml
//! [simulation]
//! start_time = 0.0
//! stop_time = 100.0
//! step_size = 0.01          # base step h; t_k = start_time + k*h
//! algorithm = "jacobi"      # or "gauss-seidel" (any case; also gauss_seidel, gaussseidel,
//!                           # seidel: the names of `Algorithm`'s `FromStr`)
//! last_step = "drop"        # stop_time off the grid: "drop" stops at the grid point before
//!                           # it, "short" takes a shorter last step to it
//!
//! [[instances]]
//! name = "gear"
//! fmu = "SteeringGear.fmu"  # relative to this file
//! step_multiple = 1         # this instance steps every n base steps
//! isolate = false           # true: always run out of process (docs/isolation.md)
//! parameters = { time_constant = 2.0, rate_max = "10 deg/s" }
//!
//! [[connections]]            # or a list, see below
//! from = "autopilot.rudder_command"
//! to = "gear.rudder_command"
//! gain = 1.0                # to = gain*from + offset (unit conversion)
//! offset = 0.0
//! convert = false           # true: the gain maps one quantity onto another (no unit check)
//! sum = false               # true: a term of a summed input (see below)
//!
//! [[events]]
//! time = 10.0
//! set = "autopilot.heading_setpoint"
//! value = 0.35              # or "20 deg", "pi/9"
//!
//! [output]
//! file = "out.csv"
//! variables = ["gear.rudder_angle", "ship.*"]   # default: every output
//! decimation = 1
//! ```
//!
//! Connections may instead be one list, which must come before the first table (TOML puts a
//! key into the last table header above it) and cannot be combined with `[[connections]]`
//! tables (a TOML key holds one value). Its entries are strings `"from -> to"` with the table
//! form's keys after commas, or inline tables, mixed freely:
//!
//! ```toml
//! connections = [
//!     "autopilot.rudder_command -> gear.rudder_command",
//!     "gear.rudder_angle -> ship.rudder_angle, gain = 1.0, offset = 0.0",
//!     "ship.r -> log.yaw_rate_deg, gain = 57.29577951308232, convert",
//!     { from = "ship.psi", to = "autopilot.heading", gain = 1.0 },
//! ]
//! ```
//!
//! Several connections into one input are added only when each of them says `sum = true` (in
//! the string form `, sum`): the input gets t0 + t1 + ..., each term `gain*from + offset`,
//! added left to right in file order, as libcosim's `Sum` function adds its inputs. A second
//! connection into an input without it stays an error ("driven twice"), so a copied line is not
//! silently added:
//!
//! ```toml
//! connections = [
//!     "wind.yaw_moment -> ship.yaw_moment, sum",
//!     "waves.yaw_moment -> ship.yaw_moment, sum",
//!     "current.yaw_moment -> ship.yaw_moment, sum, gain = 0.5",
//! ]
//! ```
//!
//! A value is a number, a boolean or a string. For a Real variable a string is a number or a
//! `pi` expression with an optional unit (`"90 deg"`, `"15 kn"`, `"pi/2"`), converted to the
//! variable's declared unit when the system is validated ([`crate::units`], `docs/units.md`);
//! a plain number is used as written.
//!
//! Errors name the file and line; all errors of a file are reported together.

use super::{collected, LineIndex};
use crate::error::{Error, Result};
use crate::system::{
    Algorithm, ConnectionSpec, EventSpec, Format, InstanceSpec, LastStep, OutputSpec, System,
    UnknownAlgorithm, Value, ValueSpec, VarRef,
};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSystem {
    simulation: RawSimulation,
    #[serde(default)]
    instances: Vec<Spanned<RawInstance>>,
    #[serde(default)]
    connections: Vec<Spanned<RawConnection>>,
    #[serde(default)]
    events: Vec<Spanned<RawEvent>>,
    #[serde(default)]
    output: Option<RawOutput>,
    /// `[[io]]`: channels on the wire for a paced or I/O run ([`crate::system::io`]).
    #[serde(default)]
    io: Vec<crate::system::io::IoSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSimulation {
    #[serde(default)]
    start_time: f64,
    stop_time: Option<f64>,
    step_size: f64,
    #[serde(default)]
    algorithm: Option<Spanned<String>>,
    /// `"drop"` (default) or `"short"`: a stop time off the base-step grid ([`LastStep`]).
    #[serde(default)]
    last_step: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInstance {
    name: String,
    fmu: String,
    #[serde(default)]
    step_multiple: Option<i64>,
    #[serde(default)]
    isolate: bool,
    #[serde(default)]
    parameters: BTreeMap<String, Spanned<toml::Value>>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RawConnection {
    Short(String),
    Full(RawConnectionFull),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConnectionFull {
    from: String,
    to: String,
    #[serde(default)]
    gain: Option<f64>,
    #[serde(default)]
    offset: Option<f64>,
    /// `convert = true`: the gain converts between different physical quantities; no unit check.
    #[serde(default)]
    convert: bool,
    /// `sum = true`: a term of a summed input ([`ConnectionSpec::sum`]).
    #[serde(default)]
    sum: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEvent {
    time: f64,
    set: String,
    value: toml::Value,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOutput {
    #[serde(default)]
    file: Option<String>,
    #[serde(default)]
    variables: Option<Vec<String>>,
    #[serde(default)]
    decimation: Option<i64>,
}

fn toml_value(v: &toml::Value) -> Option<Value> {
    Some(match v {
        toml::Value::Float(f) => Value::Real(*f),
        toml::Value::Integer(i) => Value::Integer(*i),
        toml::Value::Boolean(b) => Value::Boolean(*b),
        toml::Value::String(s) => Value::String(s.clone()),
        _ => return None,
    })
}

/// One reading of a TOML system file: where it is, its lines, and the errors found so far.
struct Reader<'t> {
    path: &'t Path,
    lines: LineIndex,
    dir: &'t Path,
    errors: Vec<Error>,
}

/// Parses the native TOML format.
pub fn parse(path: &Path, text: &str) -> Result<System> {
    let raw: RawSystem = toml::from_str(text).map_err(|e| parse_error(path, text, &e))?;
    let mut r = Reader {
        path,
        lines: LineIndex::new(text),
        dir: path.parent().unwrap_or(Path::new(".")),
        errors: Vec::new(),
    };
    let sim = raw.simulation;
    let algorithm = r.algorithm(sim.algorithm.as_ref());
    let last_step = r.last_step(sim.last_step.as_ref());
    let instances = raw.instances.into_iter().map(|i| r.instance(i)).collect();
    let connections = raw
        .connections
        .into_iter()
        .filter_map(|c| r.connection(c))
        .collect();
    let events = raw.events.into_iter().filter_map(|e| r.event(e)).collect();
    let output = r.output(raw.output);
    collected(r.errors)?;
    Ok(System {
        source: path.to_path_buf(),
        format: Format::Toml,
        start_time: sim.start_time,
        stop_time: sim.stop_time,
        step_size: sim.step_size,
        algorithm,
        instances,
        connections,
        events,
        output,
        strict_units: true,
        last_step,
        archive: None,
        notes: Vec::new(),
        io: raw.io,
    })
}

impl Reader<'_> {
    /// `[simulation] last_step`: "drop" (the default) or "short".
    fn last_step(&mut self, s: Option<&Spanned<String>>) -> LastStep {
        let Some(s) = s else {
            return LastStep::default();
        };
        LastStep::parse(s.get_ref()).unwrap_or_else(|| {
            let e = Error::system(
                self.path,
                self.line(s.span()),
                format!(
                    "last_step = \"{}\": expected \"drop\" (stop at the last base-step point before an off-grid stop_time) or \"short\" (a shorter last step to it)",
                    s.get_ref()
                ),
            );
            self.errors.push(e);
            LastStep::default()
        })
    }

    fn line(&self, span: std::ops::Range<usize>) -> Option<usize> {
        Some(self.lines.line(span.start))
    }

    fn error(&mut self, line: Option<usize>, message: String) {
        self.errors.push(Error::system(self.path, line, message));
    }

    fn algorithm(&mut self, a: Option<&Spanned<String>>) -> Algorithm {
        let Some(a) = a else {
            return Algorithm::Jacobi;
        };
        a.get_ref().parse().unwrap_or_else(|e: UnknownAlgorithm| {
            let line = self.line(a.span());
            self.error(line, e.to_string());
            Algorithm::Jacobi
        })
    }

    fn instance(&mut self, inst: Spanned<RawInstance>) -> InstanceSpec {
        let line = self.line(inst.span());
        let inst = inst.into_inner();
        let mut values = Vec::new();
        for (name, v) in inst.parameters {
            let vline = self.line(v.span());
            match toml_value(v.get_ref()) {
                Some(value) => values.push(ValueSpec {
                    variable: name,
                    value,
                    line: vline,
                }),
                None => self.error(
                    vline,
                    format!(
                        "instance '{}': parameter '{name}' must be a number, boolean or string",
                        inst.name
                    ),
                ),
            }
        }
        let step_multiple = match inst.step_multiple {
            None => 1,
            Some(m) if m >= 1 && m <= u32::MAX as i64 => m as u32,
            Some(m) => {
                self.error(
                    line,
                    format!(
                        "instance '{}': step_multiple = {m}; it must be a positive integer",
                        inst.name
                    ),
                );
                1
            }
        };
        InstanceSpec {
            name: inst.name,
            fmu: self.dir.join(inst.fmu),
            step_multiple,
            values,
            line,
            isolate: inst.isolate,
        }
    }

    fn connection(&mut self, c: Spanned<RawConnection>) -> Option<ConnectionSpec> {
        let line = self.line(c.span());
        let (from, to, gain, offset, flags) = match c.into_inner() {
            RawConnection::Short(s) => match short_connection(&s) {
                Ok(c) => c,
                Err(m) => {
                    self.error(line, format!("connection \"{s}\": {m}"));
                    return None;
                }
            },
            RawConnection::Full(f) => {
                let flags = Flags {
                    convert: f.convert,
                    sum: f.sum,
                };
                (f.from, f.to, f.gain, f.offset, flags)
            }
        };
        let (Some(f), Some(t)) = (VarRef::parse(&from), VarRef::parse(&to)) else {
            self.error(
                line,
                format!(
                    "connection \"{from} -> {to}\": both ends must be written instance.variable"
                ),
            );
            return None;
        };
        Some(ConnectionSpec {
            from: f,
            to: t,
            gain: gain.unwrap_or(1.0),
            offset: offset.unwrap_or(0.0),
            line,
            either_direction: false,
            convert: flags.convert,
            sum: flags.sum,
            mapping: None,
        })
    }

    fn event(&mut self, e: Spanned<RawEvent>) -> Option<EventSpec> {
        let line = self.line(e.span());
        let e = e.into_inner();
        let Some(target) = VarRef::parse(&e.set) else {
            self.error(
                line,
                format!(
                    "event: set = \"{}\" must be written instance.variable",
                    e.set
                ),
            );
            return None;
        };
        let Some(value) = toml_value(&e.value) else {
            self.error(
                line,
                format!(
                    "event at t = {}: value must be a number, boolean or string",
                    e.time
                ),
            );
            return None;
        };
        Some(EventSpec {
            time: e.time,
            target,
            value,
            line,
        })
    }

    fn output(&mut self, o: Option<RawOutput>) -> OutputSpec {
        let Some(o) = o else {
            return OutputSpec {
                file: None,
                variables: None,
                decimation: 1,
            };
        };
        let decimation = match o.decimation {
            None => 1,
            Some(d) if d >= 1 && d <= u32::MAX as i64 => d as u32,
            Some(d) => {
                self.error(
                    None,
                    format!("output.decimation = {d}; it must be a positive integer"),
                );
                1
            }
        };
        OutputSpec {
            file: o.file.map(|f| self.dir.join(f)),
            variables: o.variables,
            decimation,
        }
    }
}

/// A connection's boolean keys.
#[derive(Default)]
struct Flags {
    convert: bool,
    sum: bool,
}

/// A connection's (from, to, gain, offset, flags).
type Link = (String, String, Option<f64>, Option<f64>, Flags);

/// A boolean key of the string form: `key` alone or `key = true` is true, `key = false` false.
fn flag(key: &str, value: Option<&str>, part: &str) -> std::result::Result<bool, String> {
    match value {
        None | Some("true") => Ok(true),
        Some("false") => Ok(false),
        Some(_) => Err(format!("'{}': {key} is true or false", part.trim())),
    }
}

/// The string form of a connection: `"from -> to"`, then optionally, comma-separated, the keys
/// of the table form: `gain = G`, `offset = O`, `convert` (or `convert = true`) and `sum` (or
/// `sum = true`), e.g. `"ap.rudder_command -> gear.rudder_command, gain = 2.5, offset = 0.1"`.
fn short_connection(s: &str) -> std::result::Result<Link, String> {
    const FORM: &str = "it must read \"instance.output -> instance.input\", optionally followed by \", gain = G\", \", offset = O\", \", convert\" and \", sum\"";
    let mut parts = s.split(',');
    let ends = parts.next().unwrap_or_default();
    let Some((from, to)) = ends.split_once("->") else {
        return Err(FORM.into());
    };
    let (mut gain, mut offset, mut convert, mut sum) = (None, None, None, None);
    for part in parts {
        let (key, value) = match part.split_once('=') {
            Some((k, v)) => (k.trim(), Some(v.trim())),
            None => (part.trim(), None),
        };
        let number = |v: Option<&str>| {
            v.and_then(|v| v.parse::<f64>().ok().filter(|x| x.is_finite()))
                .ok_or(format!(
                    "'{}': {key} must be a number ({key} = 2.5)",
                    part.trim()
                ))
        };
        let slot_taken = match key {
            "gain" => gain.replace(number(value)?).is_some(),
            "offset" => offset.replace(number(value)?).is_some(),
            "convert" => convert.replace(flag(key, value, part)?).is_some(),
            "sum" => sum.replace(flag(key, value, part)?).is_some(),
            _ => {
                return Err(format!(
                    "unknown key '{key}' (expected gain, offset, convert or sum); {FORM}"
                ))
            }
        };
        if slot_taken {
            return Err(format!("{key} is given twice"));
        }
    }
    Ok((
        from.trim().to_string(),
        to.trim().to_string(),
        gain,
        offset,
        Flags {
            convert: convert.unwrap_or(false),
            sum: sum.unwrap_or(false),
        },
    ))
}

/// A TOML parse error, explained where the cause is TOML's own rule on top-level keys: a key
/// belongs to the last table header above it, so `connections = [...]` must come before the
/// first table, and a key holds one value, so `connections = [...]` and `[[connections]]`
/// tables cannot both be in one file.
fn parse_error(path: &Path, text: &str, e: &toml::de::Error) -> Error {
    let line = e.span().map(|s| LineIndex::new(text).line(s.start));
    let msg = e.message().trim();
    const LIST: &str = "connections = [\"a.y -> b.u\", \"c.y -> d.u, gain = 2.5, convert\", { from = \"e.y\", to = \"f.u\", offset = 1.0 }]";
    let explained = if msg.contains("duplicate key `connections`") {
        Some(format!("[[connections]] tables and a connections = [...] list in one file: TOML allows only one of the two for a key. Write every connection in the list (strings and inline tables mix there: {LIST}), or every one as a [[connections]] table"))
    } else if msg.contains("unknown field `connections`") {
        let header = line.and_then(|l| {
            text.lines()
                .take(l)
                .map(str::trim)
                .filter(|h| h.starts_with('['))
                .last()
        });
        Some(format!("connections = [...] is read as a key of the table {} above it: in TOML a key belongs to the last table header before it, so top-level keys must come before the first table. Move the connections list to the top of the file (before [simulation]), or write [[connections]] tables", header.unwrap_or("header")))
    } else {
        None
    };
    Error::system(path, line, explained.unwrap_or_else(|| msg.to_string()))
}
