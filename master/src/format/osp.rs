//! OSP `OspSystemStructure.xml` (the libcosim system format, schema version 0.1 as embedded in
//! libcosim): read into a [`System`] and write from one, so the same system runs in libcosim.
//!
//! Mapping: `StartTime`/`EndTime`/`BaseStepSize` -> simulation times; `Simulator@stepSize` ->
//! step multiple (stepSize / BaseStepSize, an integer); `InitialValues` -> parameters/start
//! values; `VariableConnection` -> connection (direction from the variables' causalities);
//! a `LinearTransformation` function between two `SignalConnection`s -> a connection with gain
//! (`factor`) and `offset`. Events and outputs have no place in this file; `export-osp` says so.

use super::{collected, LineIndex};
use crate::error::{Error, Result};
use crate::model_description::{Causality, ModelDescription, ScalarVariable, VarType};
use crate::system::{
    Algorithm, Format, InstanceSpec, OutputSpec, Plan, PlanConnection, System, TypedValue, Value,
    ValueSpec,
};
use serde::Deserialize;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Component, Path, PathBuf};

mod connections;
mod variable_groups;

#[derive(Deserialize)]
struct Root {
    #[serde(rename = "StartTime", default)]
    start_time: Option<f64>,
    #[serde(rename = "EndTime", default)]
    end_time: Option<f64>,
    #[serde(rename = "BaseStepSize", default)]
    base_step_size: Option<f64>,
    #[serde(rename = "Algorithm", default)]
    algorithm: Option<String>,
    #[serde(rename = "Simulators")]
    simulators: Simulators,
    #[serde(rename = "Functions", default)]
    functions: Option<Functions>,
    #[serde(rename = "Connections", default)]
    connections: Option<Connections>,
}

#[derive(Deserialize, Default)]
struct Simulators {
    #[serde(rename = "Simulator", default)]
    list: Vec<Simulator>,
}

#[derive(Deserialize)]
struct Simulator {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@source")]
    source: String,
    #[serde(rename = "@stepSize", default)]
    step_size: Option<f64>,
    #[serde(rename = "InitialValues", default)]
    initial_values: Option<InitialValues>,
}

#[derive(Deserialize, Default)]
struct InitialValues {
    #[serde(rename = "InitialValue", default)]
    list: Vec<InitialValue>,
}

#[derive(Deserialize)]
struct InitialValue {
    #[serde(rename = "@variable")]
    variable: String,
    #[serde(rename = "Real", default)]
    real: Option<ValueAttr<f64>>,
    #[serde(rename = "Integer", default)]
    integer: Option<ValueAttr<i64>>,
    #[serde(rename = "Boolean", default)]
    boolean: Option<ValueAttr<bool>>,
    #[serde(rename = "String", default)]
    string: Option<ValueAttr<String>>,
}

#[derive(Deserialize)]
struct ValueAttr<T> {
    #[serde(rename = "@value")]
    value: T,
}

#[derive(Deserialize, Default)]
struct Functions {
    #[serde(rename = "LinearTransformation", default)]
    linear: Vec<LinearTransformation>,
    #[serde(rename = "Sum", default)]
    sum: Vec<SumFunction>,
    #[serde(rename = "VectorSum", default)]
    vector_sum: Vec<VectorSumFunction>,
}

#[derive(Deserialize)]
struct LinearTransformation {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@factor", default)]
    factor: Option<f64>,
    #[serde(rename = "@offset", default)]
    offset: Option<f64>,
}

/// `<Sum name inputCount>`: out = in[0] + in[1] + ... (OSP-IS; libcosim's `vector_sum_function`
/// of dimension 1).
#[derive(Deserialize)]
struct SumFunction {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@inputCount")]
    input_count: u32,
}

/// `<VectorSum name inputCount dimension>`: the component-wise sum of `inputCount` variable
/// groups of `dimension` variables each.
#[derive(Deserialize)]
struct VectorSumFunction {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@inputCount")]
    input_count: u32,
    #[serde(rename = "@dimension")]
    dimension: u32,
}

#[derive(Deserialize, Default)]
struct Connections {
    #[serde(rename = "$value", default)]
    list: Vec<Connection>,
}

// The variants are the OSP element names.
#[allow(clippy::enum_variant_names)]
#[derive(Deserialize)]
enum Connection {
    VariableConnection {
        #[serde(rename = "Variable", default)]
        variables: Vec<Endpoint>,
    },
    SignalConnection {
        #[serde(rename = "Variable")]
        variable: Endpoint,
        #[serde(rename = "Signal")]
        signal: SignalEndpoint,
    },
    VariableGroupConnection {
        #[serde(rename = "VariableGroup", default)]
        groups: Vec<Endpoint>,
    },
    SignalGroupConnection {
        #[serde(rename = "VariableGroup")]
        group: Endpoint,
        #[serde(rename = "SignalGroup")]
        signal: SignalEndpoint,
    },
}

#[derive(Deserialize, Clone)]
struct Endpoint {
    #[serde(rename = "@simulator")]
    simulator: String,
    #[serde(rename = "@name")]
    name: String,
}

#[derive(Deserialize)]
struct SignalEndpoint {
    #[serde(rename = "@function")]
    function: String,
    #[serde(rename = "@name")]
    name: String,
}

/// One reading of an `OspSystemStructure.xml`.
struct Reader<'t> {
    path: &'t Path,
    text: &'t str,
    lines: LineIndex,
    errors: Vec<Error>,
    /// Simulator name -> its FMU (variable groups are read from beside it).
    fmus: HashMap<String, PathBuf>,
    /// Simulator name -> its variable groups, read when a connection first needs them.
    groups: HashMap<String, Option<variable_groups::Groups>>,
}

/// Reads an `OspSystemStructure.xml`.
pub fn parse(path: &Path, text: &str) -> Result<System> {
    let root: Root = quick_xml::de::from_str(text).map_err(|e| {
        Error::system(
            path,
            None,
            format!("not a valid OspSystemStructure.xml: {e}"),
        )
    })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let h = root.base_step_size.unwrap_or(0.01);
    let mut r = Reader {
        path,
        text,
        lines: LineIndex::new(text),
        errors: Vec::new(),
        fmus: HashMap::new(),
        groups: HashMap::new(),
    };
    let algorithm = r.algorithm(root.algorithm.as_deref());
    let instances: Vec<InstanceSpec> = root
        .simulators
        .list
        .into_iter()
        .map(|s| r.simulator(s, dir, h))
        .collect();
    r.fmus = instances
        .iter()
        .map(|i| (i.name.clone(), i.fmu.clone()))
        .collect();
    let functions = r.functions(root.functions.unwrap_or_default());
    let list = root.connections.map(|c| c.list).unwrap_or_default();
    let connections = r.connections(list, &functions);
    collected(r.errors)?;
    Ok(System {
        source: path.to_path_buf(),
        format: Format::Osp,
        start_time: root.start_time.unwrap_or(0.0),
        stop_time: root.end_time,
        step_size: h,
        algorithm,
        instances,
        connections,
        events: Vec::new(),
        output: OutputSpec {
            file: None,
            variables: None,
            decimation: 1,
        },
        strict_units: false,
        last_step: Default::default(),
        archive: None,
        notes: Vec::new(),
        io: Vec::new(),
    })
}

impl Reader<'_> {
    fn error(&mut self, line: Option<usize>, message: impl Into<String>) {
        self.errors.push(Error::system(self.path, line, message));
    }

    /// Line of the first occurrence of `needle` (OSP errors point at the element when they
    /// can).
    fn line_of(&self, needle: &str) -> Option<usize> {
        self.text.find(needle).map(|p| self.lines.line(p))
    }

    fn algorithm(&mut self, a: Option<&str>) -> Algorithm {
        match a.map(str::trim) {
            None | Some("fixedStep") => Algorithm::Jacobi,
            Some(other) => {
                let line = self.line_of("<Algorithm");
                self.error(
                    line,
                    format!(
                        "Algorithm '{other}' is not supported; shipsim runs 'fixedStep' (Jacobi)"
                    ),
                );
                Algorithm::Jacobi
            }
        }
    }

    /// A Simulator: its step multiple (stepSize / BaseStepSize) and initial values.
    fn simulator(&mut self, s: Simulator, dir: &Path, h: f64) -> InstanceSpec {
        let line = self.line_of(&format!("name=\"{}\"", s.name));
        let m = match s.step_size {
            None => 1,
            Some(ss) => {
                let r = ss / h;
                let m = r.round();
                if m < 1.0 || (r - m).abs() > 1e-6 * r.max(1.0) {
                    self.error(
                        line,
                        format!(
                            "simulator '{}': stepSize {ss} is not a positive integer multiple of BaseStepSize {h}",
                            s.name
                        ),
                    );
                    1
                } else {
                    m as u32
                }
            }
        };
        let values = s
            .initial_values
            .map(|x| x.list)
            .unwrap_or_default()
            .into_iter()
            .filter_map(|iv| self.initial_value(&s.name, iv))
            .collect();
        let source = s.source.strip_prefix("file://").unwrap_or(&s.source);
        InstanceSpec {
            fmu: dir.join(source),
            name: s.name,
            step_multiple: m,
            values,
            line,
            // OSP has no such attribute: `--isolate=NAMES` isolates instances of an OSP system.
            isolate: false,
        }
    }

    fn initial_value(&mut self, simulator: &str, iv: InitialValue) -> Option<ValueSpec> {
        let line = self.line_of(&format!("variable=\"{}\"", iv.variable));
        let value = if let Some(v) = iv.real {
            Value::Real(v.value)
        } else if let Some(v) = iv.integer {
            Value::Integer(v.value)
        } else if let Some(v) = iv.boolean {
            Value::Boolean(v.value)
        } else if let Some(v) = iv.string {
            Value::String(v.value)
        } else {
            self.error(
                line,
                format!(
                    "simulator '{simulator}', InitialValue '{}': no Real/Integer/Boolean/String value",
                    iv.variable
                ),
            );
            return None;
        };
        Some(ValueSpec {
            line,
            variable: iv.variable,
            value,
        })
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `target` relative to directory `base` (both made absolute), with forward slashes.
fn relative(target: &Path, base: &Path) -> String {
    let abs = |p: &Path| {
        let p = if p.is_absolute() {
            p.to_path_buf()
        } else {
            std::env::current_dir().unwrap_or_default().join(p)
        };
        p.canonicalize().unwrap_or(p)
    };
    let (t, b) = (abs(target), abs(base));
    let target_parts: Vec<Component> = t.components().collect();
    let base_parts: Vec<Component> = b.components().collect();
    let common = target_parts
        .iter()
        .zip(&base_parts)
        .take_while(|(a, b)| a == b)
        .count();
    let mut out = PathBuf::new();
    for _ in common..base_parts.len() {
        out.push("..");
    }
    for c in &target_parts[common..] {
        out.push(c.as_os_str());
    }
    out.to_string_lossy().replace('\\', "/")
}

/// Writes `OspSystemStructure.xml` for a system; returns warnings about what OSP cannot carry.
/// The system is validated first (FMU model descriptions are read, binaries are not loaded), so
/// initial values get the element (`Real`/`Integer`/...) of the variable's FMI type. Events go
/// into a libcosim scenario file `scenario.json` beside it.
pub fn write(sys: &System, out: &Path) -> Result<Vec<String>> {
    let unpacked = sys.unpack_fmus()?;
    let mds: Vec<_> = unpacked.iter().map(|u| &u.model_description).collect();
    let plan = sys.validate(&mds)?;
    let sums = summed_inputs(sys, &plan.connections)?;
    let scenario_path = out.with_file_name("scenario.json");
    let mut warnings = plan.warnings.clone();
    warnings.extend(lost_in_export(sys, &scenario_path));
    warnings.extend(enumerations_left_out(sys, &plan, &mds));
    let base = out.parent().unwrap_or(Path::new("."));
    let base = if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base
    };
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n");
    x.push_str("<!-- written by shipsim export-osp -->\n");
    x.push_str("<OspSystemStructure xmlns=\"http://opensimulationplatform.com/MSMI/OSPSystemStructure\" version=\"0.1\">\n");
    let _ = writeln!(x, "    <StartTime>{:?}</StartTime>", sys.start_time);
    let _ = writeln!(x, "    <EndTime>{:?}</EndTime>", plan.stop_time);
    let _ = writeln!(x, "    <BaseStepSize>{:?}</BaseStepSize>", sys.step_size);
    x.push_str("    <Algorithm>fixedStep</Algorithm>\n");
    write_simulators(&mut x, sys, &plan, &mds, base);
    write_functions(&mut x, &plan.connections, &sums);
    write_connections(&mut x, sys, &plan.connections, &mds, &sums);
    x.push_str("</OspSystemStructure>\n");
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io(format!("creating {}", dir.display()), e))?;
    }
    let out = &crate::output_path::writable(out)?;
    std::fs::write(out, x).map_err(|e| Error::io(format!("writing {}", out.display()), e))?;
    if !plan.events.is_empty() {
        let scenario_path = crate::output_path::writable(&scenario_path)?;
        std::fs::write(&scenario_path, scenario_json(sys, &plan))
            .map_err(|e| Error::io(format!("writing {}", scenario_path.display()), e))?;
    }
    Ok(warnings)
}

/// What `OspSystemStructure.xml` cannot carry, as warnings.
fn lost_in_export(sys: &System, scenario_path: &Path) -> Vec<String> {
    let mut warnings = Vec::new();
    if sys.algorithm == Algorithm::GaussSeidel {
        warnings.push("libcosim's fixedStep algorithm is Jacobi-type; the Gauss-Seidel setting is not carried over".to_string());
    }
    if !sys.events.is_empty() {
        warnings.push(format!(
            "{} scenario event(s) are not part of OspSystemStructure.xml: written to {} (libcosim \
             scenario: `cosim run --scenario`, libcosimpy `CosimExecution.load_scenario`)",
            sys.events.len(),
            scenario_path.display()
        ));
    }
    if sys.output.file.is_some() || sys.output.variables.is_some() {
        warnings.push("output settings are not part of OspSystemStructure.xml".to_string());
    }
    warnings.extend(super::isolation_left_out(sys, "OspSystemStructure.xml"));
    warnings
}

/// `<Simulators>`: source relative to the output folder, stepSize, typed initial values
/// (Enumeration variables left out, see [`enumerations_left_out`]).
fn write_simulators(
    x: &mut String,
    sys: &System,
    plan: &Plan,
    mds: &[&ModelDescription],
    base: &Path,
) {
    x.push_str("    <Simulators>\n");
    for (i, inst) in sys.instances.iter().enumerate() {
        let _ = write!(
            x,
            "        <Simulator name=\"{}\" source=\"{}\" stepSize=\"{:?}\"",
            esc(&inst.name),
            esc(&relative(&inst.fmu, base)),
            inst.step_multiple as f64 * sys.step_size
        );
        let svs: Vec<_> = plan.instances[i]
            .start_values
            .iter()
            .filter(|sv| !is_enumeration(mds[i], &sv.variable))
            .collect();
        if svs.is_empty() {
            x.push_str("/>\n");
            continue;
        }
        x.push_str(">\n            <InitialValues>\n");
        for sv in svs {
            let (el, v) = match &sv.value {
                TypedValue::Real(v) => ("Real", format!("{v:?}")),
                TypedValue::Integer(v) => ("Integer", v.to_string()),
                TypedValue::Boolean(v) => ("Boolean", v.to_string()),
                TypedValue::String(v) => ("String", esc(v)),
            };
            let _ = writeln!(
                x,
                "                <InitialValue variable=\"{}\"><{el} value=\"{v}\"/></InitialValue>",
                esc(&sv.variable)
            );
        }
        x.push_str("            </InitialValues>\n        </Simulator>\n");
    }
    x.push_str("    </Simulators>\n");
}

/// The variable is an Enumeration (its values travel as Integer in the plan).
fn is_enumeration(md: &ModelDescription, variable: &str) -> bool {
    md.model_variables
        .variables
        .iter()
        .any(|v| v.name == variable && v.var_type() == Some(VarType::Enumeration))
}

/// The variable with this value reference (an input, or not) is an Enumeration.
fn is_enumeration_vr(md: &ModelDescription, vr: u32, t: VarType, input: bool) -> bool {
    connected_variable(md, vr, t, input).is_some_and(|v| v.var_type() == Some(VarType::Enumeration))
}

/// The variable a connection end of type `t` names by value reference `vr`: an input (`input`)
/// or not. Value references are unique only within one family of get/set functions (FMI 2.0,
/// sec. 2.2.7: Real, Integer and Enumeration, Boolean, String), so the type is part of the key.
fn connected_variable(
    md: &ModelDescription,
    vr: u32,
    t: VarType,
    input: bool,
) -> Option<&ScalarVariable> {
    md.model_variables.variables.iter().find(|v| {
        v.value_reference == vr
            && (v.causality == Causality::Input) == input
            && v.var_type().is_some_and(|vt| vt.connectable_with(t))
    })
}

/// A connection with an Enumeration at either end.
fn touches_enumeration(c: &PlanConnection, mds: &[&ModelDescription]) -> bool {
    is_enumeration_vr(mds[c.from_instance], c.from_vr, c.var_type, false)
        || is_enumeration_vr(mds[c.to_instance], c.to_vr, c.var_type, true)
}

/// libcosim ignores FMI 2.0 Enumeration variables: its FMU import leaves them out of the model
/// description with the log warning "FMI 2.0 Enumeration variable type not supported"
/// (libcosim `src/cosim/fmi/v2/fmu.cpp`), so an initial value or a connection that names one
/// makes the whole file fail ("No such variable"), whichever element carries the value (its
/// schema has no `<Enumeration>` initial value either). Such values and connections are left
/// out of the file, with this warning: in libcosim those variables keep the FMU's start values.
fn enumerations_left_out(sys: &System, plan: &Plan, mds: &[&ModelDescription]) -> Vec<String> {
    let mut left: Vec<String> = Vec::new();
    for (i, inst) in plan.instances.iter().enumerate() {
        for sv in &inst.start_values {
            if is_enumeration(mds[i], &sv.variable) {
                left.push(format!("the value of {}.{}", inst.name, sv.variable));
            }
        }
    }
    for c in &plan.connections {
        if touches_enumeration(c, mds) {
            left.push(format!("the connection {}", c.name));
        }
    }
    if left.is_empty() {
        return left;
    }
    vec![format!(
        "{}: libcosim ignores Enumeration variables (\"FMI 2.0 Enumeration variable type not \
         supported\"), so OspSystemStructure.xml leaves out {}; in libcosim they keep the FMU's \
         start values",
        sys.source.display(),
        left.join(", ")
    )]
}

fn is_transformed(c: &PlanConnection) -> bool {
    c.gain != 1.0 || c.offset != 0.0
}

/// A summed input, exported as a `Sum` function `sum<k>` (k: its first term's connection).
struct SummedInput {
    /// Its terms, as indices into the plan's connections, in order (`in[0]`, `in[1]`, ...).
    terms: Vec<usize>,
}

/// The summed inputs of a plan (in the order of their first terms). A term with a gain or
/// offset cannot be exported: OSP's `Sum` adds its inputs as they are, and libcosim connects a
/// function's output to a simulator's input only, never to another function, so there is no
/// LinearTransformation in front of a Sum input. That is an error naming the connection.
fn summed_inputs(sys: &System, connections: &[PlanConnection]) -> Result<Vec<SummedInput>> {
    let mut sums: Vec<SummedInput> = Vec::new();
    let mut index: HashMap<(usize, u32), usize> = HashMap::new();
    let mut scaled = Vec::new();
    for (k, c) in connections.iter().enumerate().filter(|(_, c)| c.sum) {
        if is_transformed(c) {
            scaled.push(format!("{} (gain {}, offset {})", c.name, c.gain, c.offset));
        }
        let s = *index.entry((c.to_instance, c.to_vr)).or_insert_with(|| {
            sums.push(SummedInput { terms: Vec::new() });
            sums.len() - 1
        });
        sums[s].terms.push(k);
    }
    if !scaled.is_empty() {
        return Err(Error::system(
            &sys.source,
            None,
            format!(
                "cannot export to OSP: the summed connection(s) {} have a gain or offset, but OSP's Sum function adds its inputs as they are and libcosim cannot put a LinearTransformation in front of a Sum input (a function feeds simulators only)",
                scaled.join(", ")
            ),
        ));
    }
    Ok(sums)
}

/// `<Functions>`: one LinearTransformation `lt<k>` per connection k with a gain or offset, then
/// one Sum `sum<k>` per summed input (the OSP schema's order).
fn write_functions(x: &mut String, connections: &[PlanConnection], sums: &[SummedInput]) {
    let transformed: Vec<_> = connections
        .iter()
        .enumerate()
        .filter(|(_, c)| is_transformed(c) && !c.sum)
        .collect();
    if transformed.is_empty() && sums.is_empty() {
        return;
    }
    x.push_str("    <Functions>\n");
    for (k, c) in &transformed {
        let _ = writeln!(
            x,
            "        <LinearTransformation name=\"lt{k}\" factor=\"{:?}\" offset=\"{:?}\"/>",
            c.gain, c.offset
        );
    }
    for s in sums {
        let _ = writeln!(
            x,
            "        <Sum name=\"sum{}\" inputCount=\"{}\"/>",
            s.terms[0],
            s.terms.len()
        );
    }
    x.push_str("    </Functions>\n");
}

/// A `<SignalConnection>` between variable `name` of simulator `sim` and signal `signal` of
/// `function`: into the function when `into`, else out of it.
fn signal_connection(
    x: &mut String,
    (sim, name): (&str, &str),
    function: &str,
    signal: &str,
    into: bool,
) {
    let variable = format!("<Variable simulator=\"{sim}\" name=\"{name}\"/>");
    let signal = format!("<Signal function=\"{function}\" name=\"{signal}\"/>");
    let (first, second) = if into {
        (variable, signal)
    } else {
        (signal, variable)
    };
    let _ = writeln!(x, "        <SignalConnection>\n            {first}\n            {second}\n        </SignalConnection>");
}

/// `<Connections>`: a VariableConnection, or two SignalConnections through `lt<k>`; then the
/// SignalConnections of each summed input's `sum<k>` (`in[0]`, `in[1]`, ..., `out`).
fn write_connections(
    x: &mut String,
    sys: &System,
    connections: &[PlanConnection],
    mds: &[&ModelDescription],
    sums: &[SummedInput],
) {
    if connections.is_empty() {
        return;
    }
    x.push_str("    <Connections>\n");
    let var_name = |inst: usize, vr: u32, t: VarType, input: bool| -> String {
        connected_variable(mds[inst], vr, t, input)
            .map(|v| v.name.clone())
            .unwrap_or_default()
    };
    let from = |c: &PlanConnection| {
        let name = esc(&var_name(c.from_instance, c.from_vr, c.var_type, false));
        (esc(&sys.instances[c.from_instance].name), name)
    };
    let to = |c: &PlanConnection| {
        let name = esc(&var_name(c.to_instance, c.to_vr, c.var_type, true));
        (esc(&sys.instances[c.to_instance].name), name)
    };
    for (k, c) in connections.iter().enumerate() {
        if touches_enumeration(c, mds) || c.sum {
            continue;
        }
        let ((fi, fname), (ti, tname)) = (from(c), to(c));
        if is_transformed(c) {
            let f = format!("lt{k}");
            signal_connection(x, (&fi, &fname), &f, "in", true);
            signal_connection(x, (&ti, &tname), &f, "out", false);
        } else {
            let _ = writeln!(x, "        <VariableConnection>\n            <Variable simulator=\"{fi}\" name=\"{fname}\" causality=\"output\"/>\n            <Variable simulator=\"{ti}\" name=\"{tname}\" causality=\"input\"/>\n        </VariableConnection>");
        }
    }
    for s in sums {
        let f = format!("sum{}", s.terms[0]);
        for (i, &k) in s.terms.iter().enumerate() {
            let (fi, fname) = from(&connections[k]);
            signal_connection(x, (&fi, &fname), &f, &format!("in[{i}]"), true);
        }
        let (ti, tname) = to(&connections[s.terms[0]]);
        signal_connection(x, (&ti, &tname), &f, "out", false);
    }
    x.push_str("    </Connections>\n");
}

/// The system's events as a libcosim scenario (JSON): each event an "override" of the variable at
/// its time relative to the start, and "end" = the run's end. Without "end" libcosim ends the
/// scenario after its last event and resets the overridden variables (a variable with an initial
/// value falls back to it), unlike shipsim, where a set value stays.
fn scenario_json(sys: &System, plan: &Plan) -> String {
    use serde_json::{json, Value};
    let events: Vec<Value> = plan
        .events
        .iter()
        .map(|e| {
            let (inst, var) = e.name.split_once('.').unwrap_or(("", e.name.as_str()));
            let value = match &e.value {
                TypedValue::Real(v) => json!(v),
                TypedValue::Integer(v) => json!(v),
                TypedValue::Boolean(v) => json!(v),
                TypedValue::String(v) => json!(v),
            };
            json!({
                "time": e.step as f64 * plan.step_size,
                "model": inst,
                "variable": var,
                "action": "override",
                "value": value,
            })
        })
        .collect();
    let scenario = json!({
        "description": format!("events of {}, written by shipsim export-osp", sys.source.display()),
        "events": events,
        "end": plan.stop_time - plan.start_time,
    });
    let mut text = serde_json::to_string_pretty(&scenario).unwrap_or_default();
    text.push('\n');
    text
}
