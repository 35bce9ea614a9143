//! OSP `OspSystemStructure.xml` (the libcosim system format, schema version 0.1 as embedded in
//! libcosim): read into a [`System`] and write from one, so the same system runs in libcosim.
//!
//! Mapping: `StartTime`/`EndTime`/`BaseStepSize` -> simulation times; `Simulator@stepSize` ->
//! step multiple (stepSize / BaseStepSize, an integer); `InitialValues` -> parameters/start
//! values; `VariableConnection` -> connection (direction from the variables' causalities);
//! a `LinearTransformation` function between two `SignalConnection`s -> a connection with gain
//! (`factor`) and `offset`. Events and outputs have no place in this file; `export-osp` says so.

use crate::error::{Error, Result};
use crate::fmu::UnpackedFmu;
use crate::system::{
    Algorithm, ConnectionSpec, InstanceSpec, OutputSpec, System, TypedValue, Value, ValueSpec,
    VarRef,
};
use serde::Deserialize;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Component, Path, PathBuf};

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
    sum: Vec<Named>,
    #[serde(rename = "VectorSum", default)]
    vector_sum: Vec<Named>,
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

#[derive(Deserialize)]
struct Named {
    #[serde(rename = "@name")]
    name: String,
}

#[derive(Deserialize, Default)]
struct Connections {
    #[serde(rename = "$value", default)]
    list: Vec<Connection>,
}

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
    VariableGroupConnection {},
    SignalGroupConnection {},
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

/// Line of the first occurrence of `needle` (OSP errors point at the element when they can).
fn line_of_needle(text: &str, needle: &str) -> Option<usize> {
    text.find(needle).map(|p| crate::system::line_of(text, p))
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
    let mut errors = Vec::new();
    let algorithm = match root.algorithm.as_deref().map(str::trim) {
        None | Some("fixedStep") => Algorithm::Jacobi,
        Some(other) => {
            errors.push(Error::system(
                path,
                line_of_needle(text, "<Algorithm"),
                format!("Algorithm '{other}' is not supported; shipsim runs 'fixedStep' (Jacobi)"),
            ));
            Algorithm::Jacobi
        }
    };
    let mut instances = Vec::new();
    for s in root.simulators.list {
        let line = line_of_needle(text, &format!("name=\"{}\"", s.name));
        let m = match s.step_size {
            None => 1,
            Some(ss) => {
                let r = ss / h;
                let m = r.round();
                if m < 1.0 || (r - m).abs() > 1e-6 * r.max(1.0) {
                    errors.push(Error::system(
                        path,
                        line,
                        format!(
                            "simulator '{}': stepSize {ss} is not a positive integer multiple of BaseStepSize {h}",
                            s.name
                        ),
                    ));
                    1
                } else {
                    m as u32
                }
            }
        };
        let mut values = Vec::new();
        for iv in s.initial_values.map(|x| x.list).unwrap_or_default() {
            let value = if let Some(v) = iv.real {
                Value::Real(v.value)
            } else if let Some(v) = iv.integer {
                Value::Integer(v.value)
            } else if let Some(v) = iv.boolean {
                Value::Boolean(v.value)
            } else if let Some(v) = iv.string {
                Value::String(v.value)
            } else {
                errors.push(Error::system(
                    path,
                    line_of_needle(text, &format!("variable=\"{}\"", iv.variable)),
                    format!(
                        "simulator '{}', InitialValue '{}': no Real/Integer/Boolean/String value",
                        s.name, iv.variable
                    ),
                ));
                continue;
            };
            values.push(ValueSpec {
                line: line_of_needle(text, &format!("variable=\"{}\"", iv.variable)),
                variable: iv.variable,
                value,
            });
        }
        let source = s.source.strip_prefix("file://").unwrap_or(&s.source);
        instances.push(InstanceSpec {
            name: s.name,
            fmu: dir.join(source),
            step_multiple: m,
            values,
            line,
        });
    }
    let functions = root.functions.unwrap_or_default();
    let linear: HashMap<String, (f64, f64)> = functions
        .linear
        .iter()
        .map(|f| {
            (
                f.name.clone(),
                (f.factor.unwrap_or(1.0), f.offset.unwrap_or(0.0)),
            )
        })
        .collect();
    for f in functions.sum.iter().chain(functions.vector_sum.iter()) {
        errors.push(Error::system(
            path,
            line_of_needle(text, &format!("name=\"{}\"", f.name)),
            format!(
                "function '{}': Sum/VectorSum functions are not supported",
                f.name
            ),
        ));
    }
    let mut connections = Vec::new();
    // function name -> (input endpoint, output endpoint)
    let mut signal_in: HashMap<String, Endpoint> = HashMap::new();
    let mut signal_out: HashMap<String, Vec<Endpoint>> = HashMap::new();
    for c in root.connections.map(|c| c.list).unwrap_or_default() {
        match c {
            Connection::VariableConnection { variables } => {
                if variables.len() != 2 {
                    errors.push(Error::system(
                        path,
                        None,
                        "VariableConnection must have exactly two Variable elements",
                    ));
                    continue;
                }
                let line = line_of_needle(
                    text,
                    &format!("name=\"{}\"", variables[1].name.replace('"', "&quot;")),
                );
                connections.push(ConnectionSpec {
                    from: VarRef {
                        instance: variables[0].simulator.clone(),
                        variable: variables[0].name.clone(),
                    },
                    to: VarRef {
                        instance: variables[1].simulator.clone(),
                        variable: variables[1].name.clone(),
                    },
                    gain: 1.0,
                    offset: 0.0,
                    line,
                    either_direction: true,
                    convert: false,
                });
            }
            Connection::SignalConnection { variable, signal } => {
                if !linear.contains_key(&signal.function) {
                    errors.push(Error::system(
                        path,
                        line_of_needle(text, &format!("function=\"{}\"", signal.function)),
                        format!(
                            "SignalConnection refers to unknown function '{}'",
                            signal.function
                        ),
                    ));
                    continue;
                }
                match signal.name.as_str() {
                    "in" => {
                        signal_in.insert(signal.function, variable);
                    }
                    "out" => signal_out.entry(signal.function).or_default().push(variable),
                    other => errors.push(Error::system(
                        path,
                        None,
                        format!(
                            "function '{}': unknown signal '{other}' (LinearTransformation has 'in' and 'out')",
                            signal.function
                        ),
                    )),
                }
            }
            Connection::VariableGroupConnection {} | Connection::SignalGroupConnection {} => {
                errors.push(Error::system(
                    path,
                    None,
                    "VariableGroupConnection/SignalGroupConnection (OSP-IS variable groups) are not supported",
                ));
            }
        }
    }
    let mut fnames: Vec<&String> = linear.keys().collect();
    fnames.sort();
    for f in fnames {
        let (gain, offset) = linear[f];
        match (signal_in.get(f), signal_out.get(f)) {
            (Some(src), Some(dsts)) => {
                for d in dsts {
                    connections.push(ConnectionSpec {
                        from: VarRef {
                            instance: src.simulator.clone(),
                            variable: src.name.clone(),
                        },
                        to: VarRef {
                            instance: d.simulator.clone(),
                            variable: d.name.clone(),
                        },
                        gain,
                        offset,
                        line: line_of_needle(text, &format!("function=\"{f}\"")),
                        either_direction: false,
                        // a LinearTransformation may map one quantity onto another
                        convert: gain != 1.0 || offset != 0.0,
                    });
                }
            }
            _ => errors.push(Error::system(
                path,
                line_of_needle(text, &format!("name=\"{f}\"")),
                format!("LinearTransformation '{f}' needs one 'in' and at least one 'out' SignalConnection"),
            )),
        }
    }
    if !errors.is_empty() {
        return Err(if errors.len() == 1 {
            errors.pop().unwrap()
        } else {
            Error::Many(errors)
        });
    }
    Ok(System {
        source: path.to_path_buf(),
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
    })
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
    let tc: Vec<Component> = t.components().collect();
    let bc: Vec<Component> = b.components().collect();
    let common = tc.iter().zip(&bc).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..bc.len() {
        out.push("..");
    }
    for c in &tc[common..] {
        out.push(c.as_os_str());
    }
    out.to_string_lossy().replace('\\', "/")
}

/// Writes `OspSystemStructure.xml` for a system; returns warnings about what OSP cannot carry.
/// The system is validated first (FMU model descriptions are read, binaries are not loaded), so
/// initial values get the element (`Real`/`Integer`/...) of the variable's FMI type.
pub fn write(sys: &System, out: &Path) -> Result<Vec<String>> {
    let mut unpacked = Vec::new();
    for inst in &sys.instances {
        if !inst.fmu.exists() {
            return Err(Error::system(
                &sys.source,
                inst.line,
                format!(
                    "instance '{}': FMU file '{}' not found",
                    inst.name,
                    inst.fmu.display()
                ),
            ));
        }
        unpacked.push(UnpackedFmu::open(&inst.fmu)?);
    }
    let mds: Vec<_> = unpacked.iter().map(|u| &u.model_description).collect();
    let plan = sys.validate(&mds)?;
    let mut warnings = Vec::new();
    if sys.algorithm == Algorithm::GaussSeidel {
        warnings.push("libcosim's fixedStep algorithm is Jacobi-type; the Gauss-Seidel setting is not carried over".to_string());
    }
    let scenario_path = out.with_file_name("scenario.json");
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
    x.push_str("    <Algorithm>fixedStep</Algorithm>\n    <Simulators>\n");
    for (i, inst) in sys.instances.iter().enumerate() {
        let _ = write!(
            x,
            "        <Simulator name=\"{}\" source=\"{}\" stepSize=\"{:?}\"",
            esc(&inst.name),
            esc(&relative(&inst.fmu, base)),
            inst.step_multiple as f64 * sys.step_size
        );
        let svs = &plan.instances[i].start_values;
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
    let transformed: Vec<_> = plan
        .connections
        .iter()
        .enumerate()
        .filter(|(_, c)| c.gain != 1.0 || c.offset != 0.0)
        .collect();
    if !transformed.is_empty() {
        x.push_str("    <Functions>\n");
        for (k, c) in &transformed {
            let _ = writeln!(
                x,
                "        <LinearTransformation name=\"lt{k}\" factor=\"{:?}\" offset=\"{:?}\"/>",
                c.gain, c.offset
            );
        }
        x.push_str("    </Functions>\n");
    }
    if !plan.connections.is_empty() {
        x.push_str("    <Connections>\n");
        let var_name = |inst: usize, vr: u32, input: bool| -> String {
            mds[inst]
                .model_variables
                .variables
                .iter()
                .find(|v| {
                    v.value_reference == vr
                        && (v.causality == crate::model_description::Causality::Input) == input
                })
                .map(|v| v.name.clone())
                .unwrap_or_default()
        };
        for (k, c) in plan.connections.iter().enumerate() {
            let fname = esc(&var_name(c.from_instance, c.from_vr, false));
            let tname = esc(&var_name(c.to_instance, c.to_vr, true));
            let fi = esc(&sys.instances[c.from_instance].name);
            let ti = esc(&sys.instances[c.to_instance].name);
            if c.gain != 1.0 || c.offset != 0.0 {
                let _ = writeln!(x, "        <SignalConnection>\n            <Variable simulator=\"{fi}\" name=\"{fname}\"/>\n            <Signal function=\"lt{k}\" name=\"in\"/>\n        </SignalConnection>");
                let _ = writeln!(x, "        <SignalConnection>\n            <Signal function=\"lt{k}\" name=\"out\"/>\n            <Variable simulator=\"{ti}\" name=\"{tname}\"/>\n        </SignalConnection>");
            } else {
                let _ = writeln!(x, "        <VariableConnection>\n            <Variable simulator=\"{fi}\" name=\"{fname}\" causality=\"output\"/>\n            <Variable simulator=\"{ti}\" name=\"{tname}\" causality=\"input\"/>\n        </VariableConnection>");
            }
        }
        x.push_str("    </Connections>\n");
    }
    x.push_str("</OspSystemStructure>\n");
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io(format!("creating {}", dir.display()), e))?;
    }
    std::fs::write(out, x).map_err(|e| Error::io(format!("writing {}", out.display()), e))?;
    if !plan.events.is_empty() {
        std::fs::write(&scenario_path, scenario_json(sys, &plan))
            .map_err(|e| Error::io(format!("writing {}", scenario_path.display()), e))?;
    }
    Ok(warnings)
}

/// The system's events as a libcosim scenario (JSON): each event an "override" of the variable at
/// its time relative to the start, and "end" = the run's end. Without "end" libcosim ends the
/// scenario after its last event and resets the overridden variables (a variable with an initial
/// value falls back to it), unlike shipsim, where a set value stays.
fn scenario_json(sys: &System, plan: &crate::system::Plan) -> String {
    use crate::system::TypedValue;
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
