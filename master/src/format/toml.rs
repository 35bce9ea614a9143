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
//! algorithm = "jacobi"      # or "gauss-seidel"
//! last_step = "drop"        # stop_time off the grid: "drop" stops at the grid point before
//!                           # it, "short" takes a shorter last step to it
//!
//! [[instances]]
//! name = "gear"
//! fmu = "SteeringGear.fmu"  # relative to this file
//! step_multiple = 1         # this instance steps every n base steps
//! parameters = { time_constant = 2.0, rate_max = "10 deg/s" }
//!
//! [[connections]]            # or: connections = ["a.y -> b.u", ...]
//! from = "autopilot.rudder_command"
//! to = "gear.rudder_command"
//! gain = 1.0                # to = gain*from + offset (unit conversion)
//! offset = 0.0
//! convert = false           # true: the gain maps one quantity onto another (no unit check)
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
//! A value is a number, a boolean or a string. For a Real variable a string is a number or a
//! `pi` expression with an optional unit (`"90 deg"`, `"15 kn"`, `"pi/2"`), converted to the
//! variable's declared unit when the system is validated ([`crate::units`], `docs/units.md`);
//! a plain number is used as written.
//!
//! Errors name the file and line; all errors of a file are reported together.

use super::{collected, line_of};
use crate::error::{Error, Result};
use crate::run::LastStep;
use crate::system::{
    Algorithm, ConnectionSpec, EventSpec, InstanceSpec, OutputSpec, System, Value, ValueSpec,
    VarRef,
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

/// One reading of a TOML system file: where it is, its text, and the errors found so far.
struct Reader<'t> {
    path: &'t Path,
    text: &'t str,
    dir: &'t Path,
    errors: Vec<Error>,
}

/// Parses the native TOML format.
pub fn parse(path: &Path, text: &str) -> Result<System> {
    let raw: RawSystem = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| line_of(text, s.start));
        Error::system(path, line, e.message().trim().to_string())
    })?;
    let mut r = Reader {
        path,
        text,
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
        Some(line_of(self.text, span.start))
    }

    fn error(&mut self, line: Option<usize>, message: String) {
        self.errors.push(Error::system(self.path, line, message));
    }

    fn algorithm(&mut self, a: Option<&Spanned<String>>) -> Algorithm {
        let Some(a) = a else {
            return Algorithm::Jacobi;
        };
        match a.get_ref().to_lowercase().replace(['_', ' '], "-").as_str() {
            "jacobi" => Algorithm::Jacobi,
            "gauss-seidel" | "gaussseidel" | "seidel" => Algorithm::GaussSeidel,
            other => {
                let line = self.line(a.span());
                self.error(
                    line,
                    format!("unknown algorithm \"{other}\"; use \"jacobi\" or \"gauss-seidel\""),
                );
                Algorithm::Jacobi
            }
        }
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
        }
    }

    fn connection(&mut self, c: Spanned<RawConnection>) -> Option<ConnectionSpec> {
        let line = self.line(c.span());
        let (from, to, gain, offset, convert) = match c.into_inner() {
            RawConnection::Short(s) => match s.split_once("->") {
                Some((a, b)) => (
                    a.trim().to_string(),
                    b.trim().to_string(),
                    None,
                    None,
                    false,
                ),
                None => {
                    self.error(
                        line,
                        format!(
                            "connection \"{s}\" must read \"instance.output -> instance.input\""
                        ),
                    );
                    return None;
                }
            },
            RawConnection::Full(f) => (f.from, f.to, f.gain, f.offset, f.convert),
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
            convert,
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
