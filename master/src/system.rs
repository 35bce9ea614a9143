//! System description: the native TOML format, the format-independent [`System`] that the TOML
//! and OSP readers produce, and validation against the FMUs' model descriptions into a [`Plan`]
//! (value references, types, step indices) that the master executes.
//!
//! ```toml
//! [simulation]
//! start_time = 0.0
//! stop_time = 100.0
//! step_size = 0.01          # base step h; t_k = start_time + k*h
//! algorithm = "jacobi"      # or "gauss-seidel"
//!
//! [[instances]]
//! name = "gear"
//! fmu = "SteeringGear.fmu"  # relative to this file
//! step_multiple = 1         # this instance steps every n base steps
//! parameters = { time_constant = 2.0 }
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
//! value = 0.35
//!
//! [output]
//! file = "out.csv"
//! variables = ["gear.rudder_angle", "ship.*"]   # default: every output
//! decimation = 1
//! ```

use crate::error::{did_you_mean, Error, Result};
use crate::fmu::VR;
use crate::model_description::{Causality, ModelDescription, VarType};
use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Master algorithm (DESIGN.md "Master").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Algorithm {
    /// All instances step in parallel from the outputs of the previous communication point.
    #[default]
    Jacobi,
    /// Instances step one after another in connection order, each using the newest outputs.
    GaussSeidel,
}

/// A value given in a system file or on the command line.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
    /// Unparsed text (from `--set`), converted by the variable's type during validation.
    Text(String),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Real(v) => write!(f, "{v}"),
            Value::Integer(v) => write!(f, "{v}"),
            Value::Boolean(v) => write!(f, "{v}"),
            Value::String(v) => write!(f, "\"{v}\""),
            Value::Text(v) => write!(f, "{v}"),
        }
    }
}

/// A value after checking it against the variable type.
#[derive(Debug, Clone, PartialEq)]
pub enum TypedValue {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(String),
}

#[derive(Debug, Clone)]
pub struct ValueSpec {
    pub variable: String,
    pub value: Value,
    pub line: Option<usize>,
}

#[derive(Debug, Clone)]
pub struct InstanceSpec {
    pub name: String,
    /// Path to the .fmu, resolved against the system file's directory.
    pub fmu: PathBuf,
    pub step_multiple: u32,
    pub values: Vec<ValueSpec>,
    pub line: Option<usize>,
}

/// `instance.variable`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct VarRef {
    pub instance: String,
    pub variable: String,
}

impl std::fmt::Display for VarRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.instance, self.variable)
    }
}

impl VarRef {
    /// Splits at the first dot: instance names cannot contain dots, variable names may.
    pub fn parse(s: &str) -> Option<VarRef> {
        let (i, v) = s.trim().split_once('.')?;
        if i.is_empty() || v.is_empty() {
            return None;
        }
        Some(VarRef {
            instance: i.to_string(),
            variable: v.to_string(),
        })
    }
}

#[derive(Debug, Clone)]
pub struct ConnectionSpec {
    pub from: VarRef,
    pub to: VarRef,
    pub gain: f64,
    pub offset: f64,
    pub line: Option<usize>,
    /// OSP VariableConnection: the direction follows the variables' causalities.
    pub either_direction: bool,
    /// The gain converts between physically different quantities (e.g. a wave moment in N.m
    /// into a rudder-equivalent disturbance in rad): the unit check is skipped for it.
    pub convert: bool,
}

#[derive(Debug, Clone)]
pub struct EventSpec {
    pub time: f64,
    pub target: VarRef,
    pub value: Value,
    pub line: Option<usize>,
}

#[derive(Debug, Clone, Default)]
pub struct OutputSpec {
    pub file: Option<PathBuf>,
    /// `inst.var` or `inst.*`; None = every output variable of every instance.
    pub variables: Option<Vec<String>>,
    pub decimation: u32,
}

/// A co-simulation system, whatever file it came from.
#[derive(Debug, Clone)]
pub struct System {
    pub source: PathBuf,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    pub step_size: f64,
    pub algorithm: Algorithm,
    pub instances: Vec<InstanceSpec>,
    pub connections: Vec<ConnectionSpec>,
    pub events: Vec<EventSpec>,
    pub output: OutputSpec,
}

// ---------------------------------------------------------------------------------------------
// TOML

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

/// 1-based line of a byte offset.
pub fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
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

impl System {
    /// Reads a system file: `.xml` is OSP `OspSystemStructure.xml`, anything else TOML.
    pub fn load(path: &Path) -> Result<System> {
        let is_xml = path
            .extension()
            .map(|e| e.eq_ignore_ascii_case("xml"))
            .unwrap_or(false);
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::system(path, None, format!("cannot read: {e}")))?;
        if is_xml {
            crate::osp::parse(path, &text)
        } else {
            System::from_toml(path, &text)
        }
    }

    /// Parses the native TOML format.
    pub fn from_toml(path: &Path, text: &str) -> Result<System> {
        let raw: RawSystem = toml::from_str(text).map_err(|e| {
            let line = e.span().map(|s| line_of(text, s.start));
            Error::system(path, line, e.message().trim().to_string())
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let mut errors = Vec::new();
        let sim = raw.simulation;
        let algorithm = match &sim.algorithm {
            None => Algorithm::Jacobi,
            Some(a) => match a.get_ref().to_lowercase().replace(['_', ' '], "-").as_str() {
                "jacobi" => Algorithm::Jacobi,
                "gauss-seidel" | "gaussseidel" | "seidel" => Algorithm::GaussSeidel,
                other => {
                    errors.push(Error::system(
                        path,
                        Some(line_of(text, a.span().start)),
                        format!(
                            "unknown algorithm \"{other}\"; use \"jacobi\" or \"gauss-seidel\""
                        ),
                    ));
                    Algorithm::Jacobi
                }
            },
        };
        let mut instances = Vec::new();
        for inst in raw.instances {
            let line = Some(line_of(text, inst.span().start));
            let inst = inst.into_inner();
            let mut values = Vec::new();
            for (name, v) in inst.parameters {
                let vline = Some(line_of(text, v.span().start));
                match toml_value(v.get_ref()) {
                    Some(value) => values.push(ValueSpec {
                        variable: name,
                        value,
                        line: vline,
                    }),
                    None => errors.push(Error::system(
                        path,
                        vline,
                        format!(
                            "instance '{}': parameter '{name}' must be a number, boolean or string",
                            inst.name
                        ),
                    )),
                }
            }
            let step_multiple = match inst.step_multiple {
                None => 1,
                Some(m) if m >= 1 && m <= u32::MAX as i64 => m as u32,
                Some(m) => {
                    errors.push(Error::system(
                        path,
                        line,
                        format!(
                            "instance '{}': step_multiple = {m}; it must be a positive integer",
                            inst.name
                        ),
                    ));
                    1
                }
            };
            instances.push(InstanceSpec {
                name: inst.name,
                fmu: dir.join(inst.fmu),
                step_multiple,
                values,
                line,
            });
        }
        let mut connections = Vec::new();
        for c in raw.connections {
            let line = Some(line_of(text, c.span().start));
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
                        errors.push(Error::system(
                            path,
                            line,
                            format!("connection \"{s}\" must read \"instance.output -> instance.input\""),
                        ));
                        continue;
                    }
                },
                RawConnection::Full(f) => (f.from, f.to, f.gain, f.offset, f.convert),
            };
            let (Some(f), Some(t)) = (VarRef::parse(&from), VarRef::parse(&to)) else {
                errors.push(Error::system(
                    path,
                    line,
                    format!("connection \"{from} -> {to}\": both ends must be written instance.variable"),
                ));
                continue;
            };
            connections.push(ConnectionSpec {
                from: f,
                to: t,
                gain: gain.unwrap_or(1.0),
                offset: offset.unwrap_or(0.0),
                line,
                either_direction: false,
                convert,
            });
        }
        let mut events = Vec::new();
        for e in raw.events {
            let line = Some(line_of(text, e.span().start));
            let e = e.into_inner();
            let Some(target) = VarRef::parse(&e.set) else {
                errors.push(Error::system(
                    path,
                    line,
                    format!(
                        "event: set = \"{}\" must be written instance.variable",
                        e.set
                    ),
                ));
                continue;
            };
            let Some(value) = toml_value(&e.value) else {
                errors.push(Error::system(
                    path,
                    line,
                    format!(
                        "event at t = {}: value must be a number, boolean or string",
                        e.time
                    ),
                ));
                continue;
            };
            events.push(EventSpec {
                time: e.time,
                target,
                value,
                line,
            });
        }
        let output = match raw.output {
            None => OutputSpec {
                file: None,
                variables: None,
                decimation: 1,
            },
            Some(o) => OutputSpec {
                file: o.file.map(|f| dir.join(f)),
                variables: o.variables,
                decimation: match o.decimation {
                    None => 1,
                    Some(d) if d >= 1 && d <= u32::MAX as i64 => d as u32,
                    Some(d) => {
                        errors.push(Error::system(
                            path,
                            None,
                            format!("output.decimation = {d}; it must be a positive integer"),
                        ));
                        1
                    }
                },
            },
        };
        if !errors.is_empty() {
            return Err(if errors.len() == 1 {
                errors.pop().unwrap()
            } else {
                Error::Many(errors)
            });
        }
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
        })
    }

    /// Applies `--set inst.var=value` overrides (they replace values from the file).
    pub fn apply_overrides(&mut self, sets: &[String]) -> Result<()> {
        for s in sets {
            let Some((lhs, rhs)) = s.split_once('=') else {
                return Err(Error::Other(format!(
                    "--set {s}: expected instance.variable=value"
                )));
            };
            let Some(r) = VarRef::parse(lhs) else {
                return Err(Error::Other(format!(
                    "--set {s}: expected instance.variable=value"
                )));
            };
            let names: Vec<String> = self.instances.iter().map(|i| i.name.clone()).collect();
            let Some(inst) = self.instances.iter_mut().find(|i| i.name == r.instance) else {
                return Err(Error::Other(format!(
                    "--set {s}: no instance '{}'{}",
                    r.instance,
                    did_you_mean(&r.instance, names.iter().map(|s| s.as_str()))
                )));
            };
            inst.values.retain(|v| v.variable != r.variable);
            inst.values.push(ValueSpec {
                variable: r.variable,
                value: Value::Text(rhs.trim().to_string()),
                line: None,
            });
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// Validation

/// A start/parameter value to apply before or during initialization.
#[derive(Debug, Clone)]
pub struct StartValue {
    pub vr: VR,
    pub value: TypedValue,
    /// Settable in "Instantiated" (else in "InitializationMode"), FMI 2.0 section 4.2.4.
    pub before_init: bool,
    pub variable: String,
}

#[derive(Debug, Clone)]
pub struct PlanInstance {
    pub name: String,
    pub step_multiple: u32,
    pub start_values: Vec<StartValue>,
}

/// A checked connection, by instance index and value reference.
#[derive(Debug, Clone)]
pub struct PlanConnection {
    pub from_instance: usize,
    pub from_vr: VR,
    pub to_instance: usize,
    pub to_vr: VR,
    pub var_type: VarType,
    pub gain: f64,
    pub offset: f64,
    pub name: String,
}

#[derive(Debug, Clone)]
pub struct PlanEvent {
    /// Applied before the step that starts at t_k = t0 + k*h.
    pub step: u64,
    pub instance: usize,
    pub vr: VR,
    pub value: TypedValue,
    pub name: String,
}

#[derive(Debug, Clone)]
pub struct PlanOutput {
    pub instance: usize,
    pub vr: VR,
    pub var_type: VarType,
    pub header: String,
}

/// Everything the master needs, resolved to indices and value references before the first step.
#[derive(Debug, Clone)]
pub struct Plan {
    pub start_time: f64,
    pub step_size: f64,
    /// Number of base steps: the run ends at t0 + n_steps*h.
    pub n_steps: u64,
    pub stop_time: f64,
    pub algorithm: Algorithm,
    pub instances: Vec<PlanInstance>,
    /// Stepping order (Gauss-Seidel: connection order; Jacobi: file order).
    pub order: Vec<usize>,
    pub connections: Vec<PlanConnection>,
    pub events: Vec<PlanEvent>,
    pub outputs: Vec<PlanOutput>,
    pub output_file: Option<PathBuf>,
    pub decimation: u32,
    pub warnings: Vec<String>,
}

fn convert(value: &Value, t: VarType) -> std::result::Result<TypedValue, String> {
    let bad = || format!("value {value} does not fit a {t} variable");
    Ok(match (t, value) {
        (VarType::Real, Value::Real(v)) => TypedValue::Real(*v),
        (VarType::Real, Value::Integer(v)) => TypedValue::Real(*v as f64),
        (VarType::Real, Value::Text(s)) => TypedValue::Real(s.parse::<f64>().map_err(|_| bad())?),
        (VarType::Integer | VarType::Enumeration, Value::Integer(v)) => {
            TypedValue::Integer(i32::try_from(*v).map_err(|_| bad())?)
        }
        (VarType::Integer | VarType::Enumeration, Value::Text(s)) => {
            TypedValue::Integer(s.parse::<i32>().map_err(|_| bad())?)
        }
        (VarType::Boolean, Value::Boolean(b)) => TypedValue::Boolean(*b),
        (VarType::Boolean, Value::Integer(i)) if *i == 0 || *i == 1 => TypedValue::Boolean(*i == 1),
        (VarType::Boolean, Value::Text(s)) => TypedValue::Boolean(match s.as_str() {
            "true" | "1" => true,
            "false" | "0" => false,
            _ => return Err(bad()),
        }),
        (VarType::String, Value::String(s)) | (VarType::String, Value::Text(s)) => {
            TypedValue::String(s.clone())
        }
        _ => return Err(bad()),
    })
}

/// Converts a Real unit to SI: (exponents, factor, offset) if the unit is defined.
fn unit_si(md: &ModelDescription, unit: &str) -> Option<([i32; 8], f64, f64)> {
    md.unit(unit)
        .and_then(|u| u.base_unit)
        .map(|b| (b.exponents(), b.factor, b.offset))
}

impl System {
    fn err(&self, line: Option<usize>, msg: String) -> Error {
        Error::system(&self.source, line, msg)
    }

    /// Checks the system against the FMUs' model descriptions (`mds[i]` belongs to
    /// `instances[i]`) and resolves it into a [`Plan`]. All errors are collected and returned
    /// together; each names the file, line, instance and variable, with close-name suggestions.
    pub fn validate(&self, mds: &[&ModelDescription]) -> Result<Plan> {
        assert_eq!(mds.len(), self.instances.len());
        let mut errors: Vec<Error> = Vec::new();
        let mut warnings: Vec<String> = Vec::new();
        let src = self.source.display().to_string();
        let loc = |line: Option<usize>| match line {
            Some(l) => format!("{src}:{l}"),
            None => src.clone(),
        };

        // Time grid.
        if !(self.step_size > 0.0 && self.step_size.is_finite()) {
            errors.push(self.err(
                None,
                format!(
                    "step_size = {}; it must be a positive number",
                    self.step_size
                ),
            ));
        }
        let stop = self.stop_time.unwrap_or(self.start_time + 1.0);
        if !(stop > self.start_time) {
            errors.push(self.err(
                None,
                format!(
                    "stop_time = {stop} must be greater than start_time = {}",
                    self.start_time
                ),
            ));
        }
        let ratio = (stop - self.start_time) / self.step_size;
        let mut n_steps = if ratio.is_finite() && ratio > 0.0 {
            (ratio + 1e-9 * ratio.max(1.0)).floor() as u64
        } else {
            0
        };
        if n_steps == 0 && errors.is_empty() {
            errors.push(self.err(
                None,
                format!(
                    "the run from {} to {stop} is shorter than one step of {}",
                    self.start_time, self.step_size
                ),
            ));
            n_steps = 1;
        }
        let stop_on_grid = self.start_time + n_steps as f64 * self.step_size;
        if errors.is_empty() && (stop_on_grid - stop).abs() > 1e-9 * stop.abs().max(1.0) {
            warnings.push(format!(
                "{}: stop_time {stop} is not on the base-step grid; the run ends at t = {stop_on_grid}",
                loc(None)
            ));
        }

        // Instances.
        let inst_names: Vec<&str> = self.instances.iter().map(|i| i.name.as_str()).collect();
        let mut index: HashMap<&str, usize> = HashMap::new();
        for (i, inst) in self.instances.iter().enumerate() {
            if inst.name.is_empty()
                || inst.name.contains('.')
                || inst.name.contains(char::is_whitespace)
            {
                errors.push(self.err(
                    inst.line,
                    format!(
                        "instance name '{}' must be non-empty, without dots or spaces",
                        inst.name
                    ),
                ));
            }
            if index.insert(inst.name.as_str(), i).is_some() {
                errors.push(self.err(
                    inst.line,
                    format!("instance '{}' is defined twice", inst.name),
                ));
            }
        }
        if self.instances.is_empty() {
            errors.push(self.err(None, "the system has no instances".into()));
        }
        let var_names = |i: usize| {
            mds[i]
                .model_variables
                .variables
                .iter()
                .map(|v| v.name.as_str())
        };

        // Resolves inst.var -> (instance index, variable index) with suggestions.
        let resolve = |r: &VarRef,
                       line: Option<usize>,
                       what: &str|
         -> std::result::Result<(usize, usize), Error> {
            let Some(&i) = index.get(r.instance.as_str()) else {
                return Err(self.err(
                    line,
                    format!(
                        "{what} '{r}': no instance named '{}'{}",
                        r.instance,
                        did_you_mean(&r.instance, inst_names.iter().copied())
                    ),
                ));
            };
            match mds[i]
                .model_variables
                .variables
                .iter()
                .position(|v| v.name == r.variable)
            {
                Some(v) => Ok((i, v)),
                None => Err(self.err(
                    line,
                    format!(
                        "{what} '{r}': instance '{}' (FMU {}) has no variable '{}'{}",
                        r.instance,
                        self.instances[i]
                            .fmu
                            .file_name()
                            .map(|f| f.to_string_lossy().into_owned())
                            .unwrap_or_default(),
                        r.variable,
                        did_you_mean(&r.variable, var_names(i))
                    ),
                )),
            }
        };

        let mut plan_instances = Vec::new();
        for (i, inst) in self.instances.iter().enumerate() {
            let md = mds[i];
            let mut svs = Vec::new();
            for v in &inst.values {
                let Some(vi) = md
                    .model_variables
                    .variables
                    .iter()
                    .position(|x| x.name == v.variable)
                else {
                    errors.push(self.err(
                        v.line,
                        format!(
                            "instance '{}': no variable '{}' to set to {}{}",
                            inst.name,
                            v.variable,
                            v.value,
                            did_you_mean(&v.variable, var_names(i))
                        ),
                    ));
                    continue;
                };
                let sv = &md.model_variables.variables[vi];
                let t = sv.var_type().expect("checked at load");
                let tv = match convert(&v.value, t) {
                    Ok(tv) => tv,
                    Err(m) => {
                        errors.push(self.err(
                            v.line,
                            format!("instance '{}', variable '{}': {m}", inst.name, v.variable),
                        ));
                        continue;
                    }
                };
                let before = sv.settable_in_instantiated();
                if !before && !sv.settable_in_initialization_mode() {
                    errors.push(self.err(v.line, format!(
                        "instance '{}', variable '{}' ({}, {}, initial={}) cannot be set (value {}): only parameters, inputs and variables with initial exact/approx can",
                        inst.name, v.variable, sv.causality, sv.variability,
                        sv.effective_initial().map(|x| format!("{x:?}").to_lowercase()).unwrap_or_else(|| "none".into()),
                        v.value
                    )));
                    continue;
                }
                svs.push(StartValue {
                    vr: sv.value_reference,
                    value: tv,
                    before_init: before,
                    variable: v.variable.clone(),
                });
            }
            plan_instances.push(PlanInstance {
                name: inst.name.clone(),
                step_multiple: inst.step_multiple,
                start_values: svs,
            });
        }

        // Connections.
        let mut connections = Vec::new();
        let mut driven: HashMap<(usize, usize), (String, Option<usize>)> = HashMap::new();
        for c in &self.connections {
            let (fi, fv) = match resolve(&c.from, c.line, "connection source") {
                Ok(x) => x,
                Err(e) => {
                    errors.push(e);
                    continue;
                }
            };
            let (ti, tv) = match resolve(&c.to, c.line, "connection target") {
                Ok(x) => x,
                Err(e) => {
                    errors.push(e);
                    continue;
                }
            };
            let swapped;
            let (c, fi, fv, ti, tv) = if c.either_direction
                && mds[fi].model_variables.variables[fv].causality == Causality::Input
                && mds[ti].model_variables.variables[tv].causality == Causality::Output
            {
                swapped = ConnectionSpec {
                    from: c.to.clone(),
                    to: c.from.clone(),
                    ..c.clone()
                };
                (&swapped, ti, tv, fi, fv)
            } else {
                (c, fi, fv, ti, tv)
            };
            let name = format!("{} -> {}", c.from, c.to);
            let fsv = &mds[fi].model_variables.variables[fv];
            let tsv = &mds[ti].model_variables.variables[tv];
            let mut ok = true;
            if !matches!(
                fsv.causality,
                Causality::Output | Causality::CalculatedParameter
            ) {
                errors.push(self.err(c.line, format!(
                    "connection {name}: causality mismatch: source '{}' is {}, it must be an output", c.from, fsv.causality)));
                ok = false;
            }
            if tsv.causality != Causality::Input {
                errors.push(self.err(c.line, format!(
                    "connection {name}: causality mismatch: target '{}' is {}, it must be an input", c.to, tsv.causality)));
                ok = false;
            }
            let (ft, tt) = (fsv.var_type().unwrap(), tsv.var_type().unwrap());
            if !ft.connectable_with(tt) {
                errors.push(self.err(
                    c.line,
                    format!(
                        "connection {name}: type mismatch: '{}' is {ft} but '{}' is {tt}",
                        c.from, c.to
                    ),
                ));
                ok = false;
            } else if ft == VarType::String {
                errors.push(self.err(
                    c.line,
                    format!("connection {name}: String connections are not supported"),
                ));
                ok = false;
            }
            if ft != VarType::Real && (c.gain != 1.0 || c.offset != 0.0) {
                errors.push(self.err(c.line, format!("connection {name}: gain/offset apply only to Real variables ('{}' is {ft})", c.from)));
                ok = false;
            }
            if ti == fi {
                warnings.push(format!(
                    "{}: connection {name} feeds an instance back to itself",
                    loc(c.line)
                ));
            }
            // Units (FMI 2.0 section 2.2.2: BaseUnit exponents must agree).
            if ft == VarType::Real && tt == VarType::Real && !c.convert {
                if let (Some(fu), Some(tu)) = (mds[fi].real_unit(fsv), mds[ti].real_unit(tsv)) {
                    if fu != tu {
                        match (unit_si(mds[fi], fu), unit_si(mds[ti], tu)) {
                            (Some((fe, ff, fo)), Some((te, tf, to))) => {
                                if fe != te {
                                    errors.push(self.err(c.line, format!(
                                        "connection {name}: incompatible units: '{}' is in {fu} but '{}' is in {tu}", c.from, c.to)));
                                    ok = false;
                                } else if (ff != tf || fo != to) && c.gain == 1.0 && c.offset == 0.0 {
                                    let g = ff / tf;
                                    let o = (fo - to) / tf;
                                    warnings.push(format!(
                                        "{}: connection {name} goes from {fu} to {tu} without conversion; set gain = {g} and offset = {o}",
                                        loc(c.line)));
                                }
                            }
                            _ => warnings.push(format!(
                                "{}: connection {name} connects unit '{fu}' to unit '{tu}' (not comparable: no BaseUnit)", loc(c.line))),
                        }
                    }
                }
            }
            if let Some((prev, pline)) = driven.get(&(ti, tv)) {
                errors.push(self.err(
                    c.line,
                    format!(
                        "input '{}' is driven twice: by {name} and by {prev}{}",
                        c.to,
                        pline.map(|l| format!(" (line {l})")).unwrap_or_default()
                    ),
                ));
                ok = false;
            } else {
                driven.insert((ti, tv), (name.clone(), c.line));
            }
            if ok {
                connections.push(PlanConnection {
                    from_instance: fi,
                    from_vr: fsv.value_reference,
                    to_instance: ti,
                    to_vr: tsv.value_reference,
                    var_type: if ft == VarType::Enumeration {
                        VarType::Integer
                    } else {
                        ft
                    },
                    gain: c.gain,
                    offset: c.offset,
                    name,
                });
            }
        }

        // Unconnected inputs.
        for (i, inst) in self.instances.iter().enumerate() {
            for (vi, v) in mds[i].model_variables.variables.iter().enumerate() {
                if v.causality == Causality::Input && !driven.contains_key(&(i, vi)) {
                    let set = inst.values.iter().any(|x| x.variable == v.name);
                    if !set && !v.has_start() {
                        warnings.push(format!(
                            "{}: input '{}.{}' is not connected and has no start value",
                            loc(inst.line),
                            inst.name,
                            v.name
                        ));
                    }
                }
            }
        }

        // Events.
        let mut events = Vec::new();
        for e in &self.events {
            let (i, vi) = match resolve(&e.target, e.line, "event") {
                Ok(x) => x,
                Err(err) => {
                    errors.push(err);
                    continue;
                }
            };
            let sv = &mds[i].model_variables.variables[vi];
            if !sv.settable_in_step_mode() {
                errors.push(self.err(e.line, format!(
                    "event at t = {}: '{}' is {} {}; only inputs and tunable parameters can change during a run",
                    e.time, e.target, sv.variability, sv.causality)));
                continue;
            }
            let tv = match convert(&e.value, sv.var_type().unwrap()) {
                Ok(v) => v,
                Err(m) => {
                    errors.push(self.err(
                        e.line,
                        format!("event at t = {}, '{}': {m}", e.time, e.target),
                    ));
                    continue;
                }
            };
            let kf = (e.time - self.start_time) / self.step_size;
            let k = kf.round();
            if !(k >= 0.0) || (kf - k).abs() > 1e-6 || k as u64 >= n_steps {
                errors.push(self.err(e.line, format!(
                    "event at t = {} for '{}': the time must be a base-step point t0 + k*h in [{}, {})",
                    e.time, e.target, self.start_time, stop_on_grid)));
                continue;
            }
            if driven.contains_key(&(i, vi)) {
                warnings.push(format!("{}: event sets '{}', which a connection also drives; the connection overrides it at the next exchange", loc(e.line), e.target));
            }
            events.push(PlanEvent {
                step: k as u64,
                instance: i,
                vr: sv.value_reference,
                value: tv,
                name: e.target.to_string(),
            });
        }
        events.sort_by_key(|e| e.step);

        // Outputs.
        let mut outputs = Vec::new();
        let push_var = |outputs: &mut Vec<PlanOutput>, i: usize, vi: usize| {
            let sv = &mds[i].model_variables.variables[vi];
            let t = sv.var_type().unwrap();
            if t != VarType::String {
                outputs.push(PlanOutput {
                    instance: i,
                    vr: sv.value_reference,
                    var_type: if t == VarType::Enumeration {
                        VarType::Integer
                    } else {
                        t
                    },
                    header: format!("{}.{}", self.instances[i].name, sv.name),
                });
            }
        };
        match &self.output.variables {
            None => {
                for i in 0..self.instances.len() {
                    for (vi, v) in mds[i].model_variables.variables.iter().enumerate() {
                        if v.causality == Causality::Output {
                            push_var(&mut outputs, i, vi);
                        }
                    }
                }
            }
            Some(list) => {
                for s in list {
                    if let Some(inst) = s.strip_suffix(".*") {
                        match index.get(inst) {
                            Some(&i) => {
                                for (vi, v) in mds[i].model_variables.variables.iter().enumerate() {
                                    if v.causality == Causality::Output {
                                        push_var(&mut outputs, i, vi);
                                    }
                                }
                            }
                            None => errors.push(self.err(
                                None,
                                format!(
                                    "output '{s}': no instance named '{inst}'{}",
                                    did_you_mean(inst, inst_names.iter().copied())
                                ),
                            )),
                        }
                        continue;
                    }
                    let Some(r) = VarRef::parse(s) else {
                        errors.push(self.err(
                            None,
                            format!("output '{s}' must be written instance.variable or instance.*"),
                        ));
                        continue;
                    };
                    match resolve(&r, None, "output") {
                        Ok((i, vi)) => {
                            if mds[i].model_variables.variables[vi].var_type()
                                == Some(VarType::String)
                            {
                                errors.push(self.err(
                                    None,
                                    format!("output '{s}': String variables cannot be recorded"),
                                ));
                            } else {
                                push_var(&mut outputs, i, vi)
                            }
                        }
                        Err(e) => errors.push(e),
                    }
                }
            }
        }

        // Stepping order and algebraic loops.
        let order: Vec<usize> = match self.algorithm {
            Algorithm::Jacobi => (0..self.instances.len()).collect(),
            Algorithm::GaussSeidel => {
                let mut order = Vec::new();
                let mut seen = vec![false; self.instances.len()];
                for c in &connections {
                    for i in [c.from_instance, c.to_instance] {
                        if !seen[i] {
                            seen[i] = true;
                            order.push(i);
                        }
                    }
                }
                order.extend((0..self.instances.len()).filter(|&i| !seen[i]));
                order
            }
        };
        if self.algorithm == Algorithm::GaussSeidel {
            if let Some(cycle) = find_algebraic_loop(&connections, mds, &self.instances) {
                warnings.push(format!(
                    "{}: algebraic loop under Gauss-Seidel: {cycle}; the loop is not iterated, the first instance in stepping order uses the previous step's value",
                    loc(None)));
            }
        }
        for (i, inst) in self.instances.iter().enumerate() {
            let m = inst.step_multiple;
            if m > 1 && n_steps % m as u64 != 0 {
                let cs = mds[i].co_simulation.as_ref();
                if !cs
                    .map(|c| c.can_handle_variable_communication_step_size)
                    .unwrap_or(false)
                {
                    warnings.push(format!("{}: instance '{}' steps every {m} base steps but the run has {n_steps}; its last step is dropped (it cannot handle variable communication steps)", loc(inst.line), inst.name));
                }
            }
        }

        if !errors.is_empty() {
            return Err(if errors.len() == 1 {
                errors.pop().unwrap()
            } else {
                Error::Many(errors)
            });
        }
        Ok(Plan {
            start_time: self.start_time,
            step_size: self.step_size,
            n_steps,
            stop_time: stop_on_grid,
            algorithm: self.algorithm,
            instances: plan_instances,
            order,
            connections,
            events,
            outputs,
            output_file: self.output.file.clone(),
            decimation: self.output.decimation.max(1),
            warnings,
        })
    }
}

/// Finds a cycle of direct feed-through: connection a.y -> b.u, and within b an output that
/// depends on u (ModelStructure), and so on back to a. Returns it as text.
fn find_algebraic_loop(
    conns: &[PlanConnection],
    mds: &[&ModelDescription],
    instances: &[InstanceSpec],
) -> Option<String> {
    // Graph over connections: edge c1 -> c2 if c2 leaves the instance c1 enters, and c2's source
    // output depends on c1's target input.
    let vr_index = |i: usize, vr: VR, input: bool| -> Option<usize> {
        mds[i].model_variables.variables.iter().position(|v| {
            v.value_reference == vr
                && if input {
                    v.causality == Causality::Input
                } else {
                    v.causality != Causality::Input
                }
        })
    };
    let n = conns.len();
    let mut adj = vec![Vec::new(); n];
    for (a, ca) in conns.iter().enumerate() {
        for (b, cb) in conns.iter().enumerate() {
            if cb.from_instance == ca.to_instance {
                let inp = vr_index(ca.to_instance, ca.to_vr, true);
                let out = vr_index(cb.from_instance, cb.from_vr, false);
                if let (Some(inp), Some(out)) = (inp, out) {
                    if mds[ca.to_instance].output_depends_on(out, inp) {
                        adj[a].push(b);
                    }
                }
            }
        }
    }
    // DFS cycle detection.
    let mut state = vec![0u8; n];
    let mut stack = Vec::new();
    fn dfs(
        u: usize,
        adj: &[Vec<usize>],
        state: &mut [u8],
        stack: &mut Vec<usize>,
    ) -> Option<Vec<usize>> {
        state[u] = 1;
        stack.push(u);
        for &v in &adj[u] {
            if state[v] == 1 {
                let pos = stack.iter().position(|&x| x == v).unwrap();
                return Some(stack[pos..].to_vec());
            }
            if state[v] == 0 {
                if let Some(c) = dfs(v, adj, state, stack) {
                    return Some(c);
                }
            }
        }
        stack.pop();
        state[u] = 2;
        None
    }
    let _ = instances;
    for s in 0..n {
        if state[s] == 0 {
            if let Some(c) = dfs(s, &adj, &mut state, &mut stack) {
                return Some(
                    c.iter()
                        .map(|&i| conns[i].name.clone())
                        .collect::<Vec<_>>()
                        .join(", "),
                );
            }
        }
    }
    None
}
