//! SSP 1.0 export: a [`System`] as a self-contained `.ssp` archive (SSP 1.0, sec. 8: a ZIP with
//! `SystemStructure.ssd` at its root and the files it references), for libcosim
//! (`CosimExecution.from_ssp_file`), FMPy (`fmpy.ssp`) and other SSP tools.
//!
//! The archive holds:
//!
//! - `SystemStructure.ssd`: one `ssd:System` with one `ssd:Component` per instance (SSP 1.0,
//!   sec. 5.3), the connectors that connections use, with their type and unit; the connections,
//!   a gain or offset as `ssc:LinearTransformation`, the value mapping of an Integer or Boolean
//!   connection (read from an SSP) as `ssc:IntegerMappingTransformation` or
//!   `ssc:BooleanMappingTransformation` (sec. 5.4.5); the units of the connectors as
//!   `ssc:Unit` with their SI exponents, factor and offset (sec. 5.4.3, from each FMU's
//!   `UnitDefinitions` or, for a unit the FMU does not define, [`crate::units`]);
//!   `ssd:DefaultExperiment` with the start and stop time (sec. 5.6).
//! - `resources/<fmu>.fmu`: each FMU once, however many instances use it.
//! - `resources/<instance>.ssv`: each instance's parameters and start values as an SSP parameter
//!   set (sec. 6), bound to its component by `ssd:ParameterBinding source=...`; names are the
//!   FMU's variable names, values are in the variables' declared units (the system's `90 deg`
//!   is written as the radians the master would set).
//!
//! SSP 1.0 has no place for a master step size. The base step and each instance's step size
//! (its step multiple times the base step) are written as the OSP annotations that libcosim
//! reads (type `com.opensimulationplatform`: `osp:Algorithm/osp:FixedStepAlgorithm
//! baseStepSize` in the default experiment, `osp:StepSizeHint value` in a component), so that
//! libcosim runs the file as shipsim runs the system; tools that ignore the annotations choose
//! their own step.
//!
//! shipsim applies a connection's gain and offset and never converts units on a connection. A
//! connection between connectors of different units is therefore written with
//! `suppressUnitConversion="true"` (SSP 1.0, sec. 5.3.5): the linear transformation is then the
//! whole transformation, as in shipsim, instead of being applied after a unit conversion.
//!
//! What SSP 1.0 cannot express is refused with an error naming it ([`refusals`]): events (SSP
//! has no scenario), summed inputs (an SSP connector takes one connection), the Gauss-Seidel
//! order, a short last step, and Enumeration variables (not exported: they need an
//! `Enumerations` table, and libcosim aborts on them). What changes nothing in the results but
//! is left out comes back as a warning ([`left_out`]).

use crate::error::{Error, Result};
use crate::fmu::UnpackedFmu;
use crate::model_description::{Causality, ModelDescription, ScalarVariable, VarType};
use crate::system::{Algorithm, LastStep, Plan, PlanConnection, System, TypedValue};
use crate::units::{self, Unit};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// SSP 1.0 namespaces (SSP 1.0, sec. 4).
const NS_SSD: &str = "http://ssp-standard.org/SSP1/SystemStructureDescription";
const NS_SSC: &str = "http://ssp-standard.org/SSP1/SystemStructureCommon";
const NS_SSV: &str = "http://ssp-standard.org/SSP1/SystemStructureParameterValues";
/// The namespace of the OSP annotations libcosim reads (libcosim `test/data/ssp/OSPAnnotations.xsd`).
const NS_OSP: &str = "http://opensimulationplatform.com/SSP/OSPAnnotations";
/// The annotation type libcosim's SSP parser looks for (`src/cosim/ssp/ssp_parser.cpp`).
const OSP_ANNOTATION: &str = "com.opensimulationplatform";

/// Writes the system as an SSP 1.0 archive at `out`; returns warnings about what was left out.
/// The system is validated first (FMU model descriptions are read, binaries are not loaded);
/// what SSP 1.0 cannot express is an error naming it, and nothing is written.
pub fn write(sys: &System, out: &Path) -> Result<Vec<String>> {
    let unpacked = sys.unpack_fmus()?;
    let mds: Vec<&ModelDescription> = unpacked.iter().map(|u| &u.model_description).collect();
    let plan = sys.validate(&mds)?;
    super::super::collected(refusals(sys, &plan, &mds))?;
    let mut warnings = plan.warnings.clone();
    warnings.extend(left_out(sys, &plan));
    let archive = Archive::build(sys, &plan, &unpacked, &mut warnings);
    archive.write_zip(out)?;
    Ok(warnings)
}

/// Everything SSP 1.0 cannot express, each as an error naming it.
fn refusals(sys: &System, plan: &Plan, mds: &[&ModelDescription]) -> Vec<Error> {
    let mut errors = Vec::new();
    let mut refuse =
        |line: Option<usize>, m: String| errors.push(Error::system(&sys.source, line, m));
    for e in &sys.events {
        refuse(
            e.line,
            format!(
                "event at t = {} s setting {} = {}: SSP 1.0 has no scenario form, so the event \
                 cannot be exported (remove it to export the rest; `shipsim export-osp` writes \
                 events as a libcosim scenario)",
                e.time, e.target, e.value
            ),
        );
    }
    if sys.algorithm == Algorithm::GaussSeidel {
        refuse(
            None,
            "algorithm \"gauss-seidel\": SSP 1.0 has no master algorithm, and libcosim's \
             fixed-step algorithm is Jacobi-type; export the system with algorithm = \"jacobi\""
                .into(),
        );
    }
    if let Some(og) = plan.off_grid.filter(|o| o.last_step == LastStep::Short) {
        refuse(
            None,
            format!(
                "stop time {} s is off the base-step grid and last_step = \"short\": SSP 1.0 \
                 (and libcosim) cannot take a shorter last step",
                og.stop_time
            ),
        );
    }
    for (to, terms) in summed_inputs(&plan.connections) {
        let names: Vec<&str> = terms.iter().map(|c| c.name.as_str()).collect();
        refuse(
            None,
            format!(
                "summed input {to}: SSP 1.0 gives an input connector one connection, it has no \
                 sum of several ({}); `shipsim export-osp` writes it as an OSP Sum function",
                names.join(", ")
            ),
        );
    }
    for what in enumerations(plan, mds) {
        refuse(
            None,
            format!(
                "{what} is an Enumeration variable: not exported to SSP (it needs an SSP \
                 Enumerations table, and libcosim aborts on Enumeration connectors and parameters)"
            ),
        );
    }
    errors
}

/// Inputs driven by more than one connection (summed inputs), with their connections, in
/// plan order.
fn summed_inputs(connections: &[PlanConnection]) -> Vec<(String, Vec<&PlanConnection>)> {
    // a value reference is unique per type only (FMI 2.0, sec. 2.2.7)
    type Input = (usize, u32, VarType);
    let mut by_input: Vec<(Input, Vec<&PlanConnection>)> = Vec::new();
    for c in connections {
        let key = (c.to_instance, c.to_vr, vr_space(c.var_type));
        match by_input.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(c),
            None => by_input.push((key, vec![c])),
        }
    }
    by_input
        .into_iter()
        .filter(|(_, v)| v.len() > 1)
        .map(|(_, v)| {
            let to = v[0].name.rsplit("->").next().unwrap_or(&v[0].name).trim();
            (to.to_string(), v)
        })
        .collect()
}

/// The values and connection ends that are Enumeration variables, as `instance.variable`.
fn enumerations(plan: &Plan, mds: &[&ModelDescription]) -> Vec<String> {
    let mut found = Vec::new();
    for (i, inst) in plan.instances.iter().enumerate() {
        for sv in &inst.start_values {
            if variable(mds[i], &sv.variable).and_then(|v| v.var_type())
                == Some(VarType::Enumeration)
            {
                found.push(format!("{}.{}", inst.name, sv.variable));
            }
        }
    }
    for c in &plan.connections {
        for (i, vr, input) in [
            (c.from_instance, c.from_vr, false),
            (c.to_instance, c.to_vr, true),
        ] {
            if let Some(v) = by_vr(mds[i], vr, c.var_type, input) {
                if v.var_type() == Some(VarType::Enumeration) {
                    found.push(format!("{}.{}", plan.instances[i].name, v.name));
                }
            }
        }
    }
    found
}

/// What the archive leaves out without changing the results, and the step sizes written as
/// OSP annotations only, as warnings.
fn left_out(sys: &System, plan: &Plan) -> Vec<String> {
    let mut warnings = Vec::new();
    if sys.output.file.is_some() || sys.output.variables.is_some() || sys.output.decimation > 1 {
        warnings.push(
            "the [output] settings (file, variables, decimation) are not part of SSP 1.0 and \
             are left out"
                .to_string(),
        );
    }
    warnings.extend(crate::format::isolation_left_out(sys, "SSP 1.0"));
    let mapped: Vec<&str> = plan
        .connections
        .iter()
        .filter(|c| c.mapping.is_some())
        .map(|c| c.name.as_str())
        .collect();
    if !mapped.is_empty() {
        warnings.push(format!(
            "libcosim applies no mapping transformation (it passes the values of {} unchanged); \
             shipsim and other SSP tools apply them",
            mapped.join(", ")
        ));
    }
    let multiples: Vec<String> = plan
        .instances
        .iter()
        .filter(|i| i.step_multiple > 1)
        .map(|i| format!("{} (x{})", i.name, i.step_multiple))
        .collect();
    if !multiples.is_empty() {
        warnings.push(format!(
            "SSP 1.0 has no per-component step size: the step multiples of {} are written as the \
             OSP annotation osp:StepSizeHint, which libcosim reads; other SSP tools step these \
             instances at their own step",
            multiples.join(", ")
        ));
    }
    warnings
}

/// The variable named `name`.
fn variable<'m>(md: &'m ModelDescription, name: &str) -> Option<&'m ScalarVariable> {
    md.model_variables.variables.iter().find(|v| v.name == name)
}

/// The variable of a connection end: value reference `vr` of type `t`, an input (or not). A
/// value reference is unique per base type only (FMI 2.0, sec. 2.2.7); Enumerations share
/// Integer's.
fn by_vr(md: &ModelDescription, vr: u32, t: VarType, input: bool) -> Option<&ScalarVariable> {
    md.model_variables.variables.iter().find(|v| {
        v.value_reference == vr
            && (v.causality == Causality::Input) == input
            && v.var_type().map(vr_space) == Some(vr_space(t))
    })
}

/// The value-reference space of a type: Enumerations share Integer's.
fn vr_space(t: VarType) -> VarType {
    match t {
        VarType::Enumeration => VarType::Integer,
        t => t,
    }
}

/// An XML attribute value.
fn esc(s: &str) -> std::borrow::Cow<'_, str> {
    quick_xml::escape::escape(s)
}

/// An `xs:double`: the shortest text that reads back to the same bits (Rust's `{:?}`), with
/// XML Schema's spelling of the infinities.
fn xs_double(v: f64) -> String {
    match v {
        f64::INFINITY => "INF".into(),
        f64::NEG_INFINITY => "-INF".into(),
        _ => format!("{v:?}"),
    }
}

/// The SSD's unit table: one `ssc:Unit` per name. Two FMUs that define the same name
/// differently get the second under `name (2)`, so that every connector keeps its own
/// definition.
#[derive(Default)]
struct Units {
    list: Vec<(String, Unit)>,
}

impl Units {
    /// The SSD name of unit `name` defined as `unit`.
    fn name_for(&mut self, name: &str, unit: Unit) -> String {
        let mut candidate = name.to_string();
        for k in 2.. {
            match self.list.iter().find(|(n, _)| *n == candidate) {
                Some((_, u)) if *u == unit => return candidate,
                Some(_) => candidate = format!("{name} ({k})"),
                None => break,
            }
        }
        self.list.push((candidate.clone(), unit));
        candidate
    }

    fn write(&self, x: &mut String) {
        if self.list.is_empty() {
            return;
        }
        x.push_str("  <ssd:Units>\n");
        for (name, u) in &self.list {
            let _ = write!(
                x,
                "    <ssc:Unit name=\"{}\">\n      <ssc:BaseUnit",
                esc(name)
            );
            for (base, e) in units::BASE_UNITS.iter().zip(u.exponents) {
                if e != 0 {
                    let _ = write!(x, " {base}=\"{e}\"");
                }
            }
            if u.factor != 1.0 {
                let _ = write!(x, " factor=\"{}\"", xs_double(u.factor));
            }
            if u.offset != 0.0 {
                let _ = write!(x, " offset=\"{}\"", xs_double(u.offset));
            }
            x.push_str("/>\n    </ssc:Unit>\n");
        }
        x.push_str("  </ssd:Units>\n");
    }
}

/// A connector of a component: an FMU variable that a connection uses.
struct Connector {
    name: String,
    kind: &'static str,
    var_type: VarType,
    /// The SSD unit name (Real variables with a unit that has a definition).
    unit: Option<String>,
}

/// The archive's contents before they are zipped.
struct Archive {
    ssd: String,
    /// (name in the archive, file on disk) of each FMU.
    fmus: Vec<(String, PathBuf)>,
    /// (name in the archive, text) of each parameter set.
    ssvs: Vec<(String, String)>,
}

impl Archive {
    fn build(
        sys: &System,
        plan: &Plan,
        unpacked: &[UnpackedFmu],
        warnings: &mut Vec<String>,
    ) -> Archive {
        let mds: Vec<&ModelDescription> = unpacked.iter().map(|u| &u.model_description).collect();
        let sources = fmu_sources(sys);
        let mut units = Units::default();
        let connectors = connectors(plan, &mds, &mut units, warnings);
        let ssvs: Vec<Option<(String, String)>> = plan
            .instances
            .iter()
            .enumerate()
            .map(|(i, inst)| {
                (!inst.start_values.is_empty()).then(|| (ssv_name(&inst.name, i, plan), ssv(inst)))
            })
            .collect();
        let name = sys
            .source
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "system".into());
        let mut x = String::new();
        x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        x.push_str("<!-- written by shipsim export-ssp -->\n");
        let _ = writeln!(
            x,
            "<ssd:SystemStructureDescription xmlns:ssd=\"{NS_SSD}\" xmlns:ssc=\"{NS_SSC}\" \
             xmlns:ssv=\"{NS_SSV}\" xmlns:osp=\"{NS_OSP}\" version=\"1.0\" name=\"{}\" \
             generationTool=\"shipsim {}\">",
            esc(&name),
            env!("CARGO_PKG_VERSION")
        );
        let _ = writeln!(
            x,
            "  <ssd:System name=\"{}\">\n    <ssd:Elements>",
            esc(&name)
        );
        for (i, inst) in plan.instances.iter().enumerate() {
            let ssv = ssvs[i].as_ref().map(|(n, _)| n.as_str());
            let step =
                (inst.step_multiple > 1).then_some(inst.step_multiple as f64 * plan.step_size);
            component(
                &mut x,
                &inst.name,
                &sources.names[i],
                &connectors[i],
                ssv,
                step,
            );
        }
        x.push_str("    </ssd:Elements>\n");
        connections(&mut x, plan, &mds, &connectors);
        x.push_str("  </ssd:System>\n");
        units.write(&mut x);
        default_experiment(&mut x, plan);
        x.push_str("</ssd:SystemStructureDescription>\n");
        Archive {
            ssd: x,
            fmus: sources.files,
            ssvs: ssvs.into_iter().flatten().collect(),
        }
    }

    /// Zips the archive into `out` (through a temporary file beside it, renamed at the end).
    fn write_zip(&self, out: &Path) -> Result<()> {
        let out = &crate::output_path::writable(out)?;
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| Error::io(format!("creating {}", dir.display()), e))?;
        }
        let tmp = out.with_extension("ssp.partial");
        let result = self.zip_into(&tmp).and_then(|()| {
            std::fs::rename(&tmp, out)
                .map_err(|e| Error::io(format!("writing {}", out.display()), e))
        });
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result
    }

    fn zip_into(&self, path: &Path) -> Result<()> {
        use zip::write::SimpleFileOptions;
        use zip::CompressionMethod;
        let io = |e: std::io::Error| Error::io(format!("writing {}", path.display()), e);
        let zip_err = |e: zip::result::ZipError| io(std::io::Error::other(e));
        let file = std::fs::File::create(path).map_err(io)?;
        let mut z = zip::ZipWriter::new(file);
        let text = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
        // an FMU is a ZIP already: stored as it is
        let stored = SimpleFileOptions::default().compression_method(CompressionMethod::Stored);
        z.start_file(super::DEFAULT_SSD, text).map_err(zip_err)?;
        z.write_all(self.ssd.as_bytes()).map_err(io)?;
        for (name, body) in &self.ssvs {
            z.start_file(name.as_str(), text).map_err(zip_err)?;
            z.write_all(body.as_bytes()).map_err(io)?;
        }
        for (name, src) in &self.fmus {
            let bytes = std::fs::read(src)
                .map_err(|e| Error::io(format!("reading {}", src.display()), e))?;
            z.start_file(name.as_str(), stored).map_err(zip_err)?;
            z.write_all(&bytes).map_err(io)?;
        }
        z.finish().map_err(zip_err)?;
        Ok(())
    }
}

/// Each instance's FMU as a name in the archive (`resources/<file>.fmu`; one copy per FMU
/// file, a second file of the same name gets a number).
struct Sources {
    names: Vec<String>,
    files: Vec<(String, PathBuf)>,
}

fn fmu_sources(sys: &System) -> Sources {
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    let mut names = Vec::new();
    for inst in &sys.instances {
        let path = inst.fmu.canonicalize().unwrap_or_else(|_| inst.fmu.clone());
        if let Some((n, _)) = files.iter().find(|(_, p)| *p == path) {
            names.push(n.clone());
            continue;
        }
        let stem = path
            .file_stem()
            .map(|s| safe_file_name(&s.to_string_lossy()))
            .unwrap_or_else(|| "model".into());
        let mut name = format!("resources/{stem}.fmu");
        for k in 2.. {
            if !files.iter().any(|(n, _)| *n == name) {
                break;
            }
            name = format!("resources/{stem}_{k}.fmu");
        }
        names.push(name.clone());
        files.push((name, path));
    }
    Sources { names, files }
}

/// A file name made of letters, digits, `_`, `-` and `.` only.
fn safe_file_name(s: &str) -> String {
    s.chars()
        .map(
            |c| match c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.' {
                true => c,
                false => '_',
            },
        )
        .collect()
}

/// The archive name of instance `i`'s parameter set: `resources/<instance>.ssv` (the instance
/// index is added when two instance names give the same file name).
fn ssv_name(instance: &str, i: usize, plan: &Plan) -> String {
    let safe = safe_file_name(instance);
    let clash = plan
        .instances
        .iter()
        .enumerate()
        .any(|(j, o)| j != i && safe_file_name(&o.name) == safe);
    match clash {
        true => format!("resources/{safe}_{i}.ssv"),
        false => format!("resources/{safe}.ssv"),
    }
}

/// An instance's start values as an SSP parameter set (SSP 1.0, sec. 6).
fn ssv(inst: &crate::system::PlanInstance) -> String {
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str("<!-- written by shipsim export-ssp -->\n");
    let _ = writeln!(
        x,
        "<ssv:ParameterSet xmlns:ssv=\"{NS_SSV}\" version=\"1.0\" name=\"{}\">\n  <ssv:Parameters>",
        esc(&inst.name)
    );
    for sv in &inst.start_values {
        let (el, v) = match &sv.value {
            TypedValue::Real(v) => ("Real", xs_double(*v)),
            TypedValue::Integer(v) => ("Integer", v.to_string()),
            TypedValue::Boolean(v) => ("Boolean", v.to_string()),
            TypedValue::String(v) => ("String", esc(v).into_owned()),
        };
        let _ = writeln!(
            x,
            "    <ssv:Parameter name=\"{}\">\n      <ssv:{el} value=\"{v}\"/>\n    </ssv:Parameter>",
            esc(&sv.variable)
        );
    }
    x.push_str("  </ssv:Parameters>\n</ssv:ParameterSet>\n");
    x
}

/// Each instance's connectors: the variables its connections use, in the order they are first
/// used.
fn connectors(
    plan: &Plan,
    mds: &[&ModelDescription],
    units: &mut Units,
    warnings: &mut Vec<String>,
) -> Vec<Vec<Connector>> {
    let mut out: Vec<Vec<Connector>> = plan.instances.iter().map(|_| Vec::new()).collect();
    for c in &plan.connections {
        for (i, vr, input) in [
            (c.from_instance, c.from_vr, false),
            (c.to_instance, c.to_vr, true),
        ] {
            let Some(v) = by_vr(mds[i], vr, c.var_type, input) else {
                continue;
            };
            if out[i].iter().any(|k| k.name == v.name) {
                continue;
            }
            let unit = connector_unit(mds[i], v, units).unwrap_or_else(|w| {
                warnings.push(format!(
                    "{}.{}: {w}; its connector carries no unit",
                    plan.instances[i].name, v.name
                ));
                None
            });
            out[i].push(Connector {
                name: v.name.clone(),
                kind: match input {
                    true => "input",
                    false if v.causality == Causality::CalculatedParameter => "calculatedParameter",
                    false => "output",
                },
                var_type: v.var_type().unwrap_or(VarType::Real),
                unit,
            });
        }
    }
    out
}

/// The SSD unit of a Real variable: its declared unit with the FMU's definition (or the
/// built-in one, [`units::declared`]); `None` without a unit, an error when the unit has no
/// definition.
fn connector_unit(
    md: &ModelDescription,
    v: &ScalarVariable,
    units: &mut Units,
) -> std::result::Result<Option<String>, String> {
    if v.var_type() != Some(VarType::Real) {
        return Ok(None);
    }
    let Some(name) = md.real_unit(v) else {
        return Ok(None);
    };
    let (unit, _) = units::declared(md, name).map_err(|e| e.to_string())?;
    Ok(Some(units.name_for(name, unit)))
}

/// One `ssd:Component`: connectors, the parameter binding, the step size hint.
fn component(
    x: &mut String,
    name: &str,
    source: &str,
    connectors: &[Connector],
    ssv: Option<&str>,
    step: Option<f64>,
) {
    let _ = write!(
        x,
        "      <ssd:Component name=\"{}\" type=\"application/x-fmu-sharedlibrary\" source=\"{}\"",
        esc(name),
        esc(source)
    );
    if connectors.is_empty() && ssv.is_none() && step.is_none() {
        x.push_str("/>\n");
        return;
    }
    x.push_str(">\n");
    if !connectors.is_empty() {
        x.push_str("        <ssd:Connectors>\n");
        for k in connectors {
            let _ = write!(
                x,
                "          <ssd:Connector name=\"{}\" kind=\"{}\">\n            <ssc:{}",
                esc(&k.name),
                k.kind,
                k.var_type.name()
            );
            if let Some(u) = &k.unit {
                let _ = write!(x, " unit=\"{}\"", esc(u));
            }
            x.push_str("/>\n          </ssd:Connector>\n");
        }
        x.push_str("        </ssd:Connectors>\n");
    }
    if let Some(s) = ssv {
        let _ = writeln!(
            x,
            "        <ssd:ParameterBindings>\n          <ssd:ParameterBinding type=\"application/x-ssp-parameter-set\" source=\"{}\"/>\n        </ssd:ParameterBindings>",
            esc(s)
        );
    }
    if let Some(h) = step {
        let _ = writeln!(
            x,
            "        <ssd:Annotations>\n          <ssc:Annotation type=\"{OSP_ANNOTATION}\">\n            <osp:StepSizeHint value=\"{}\"/>\n          </ssc:Annotation>\n        </ssd:Annotations>",
            xs_double(h)
        );
    }
    x.push_str("      </ssd:Component>\n");
}

/// `ssd:Connections`: one per plan connection, a gain or offset as a LinearTransformation,
/// unit conversion suppressed between connectors of different units.
fn connections(
    x: &mut String,
    plan: &Plan,
    mds: &[&ModelDescription],
    connectors: &[Vec<Connector>],
) {
    if plan.connections.is_empty() {
        return;
    }
    let unit_of = |i: usize, name: &str| {
        connectors[i]
            .iter()
            .find(|k| k.name == name)
            .and_then(|k| k.unit.clone())
    };
    x.push_str("    <ssd:Connections>\n");
    for c in &plan.connections {
        let (Some(f), Some(t)) = (
            by_vr(mds[c.from_instance], c.from_vr, c.var_type, false),
            by_vr(mds[c.to_instance], c.to_vr, c.var_type, true),
        ) else {
            continue;
        };
        let _ = write!(
            x,
            "      <ssd:Connection startElement=\"{}\" startConnector=\"{}\" endElement=\"{}\" endConnector=\"{}\"",
            esc(&plan.instances[c.from_instance].name),
            esc(&f.name),
            esc(&plan.instances[c.to_instance].name),
            esc(&t.name)
        );
        let (fu, tu) = (
            unit_of(c.from_instance, &f.name),
            unit_of(c.to_instance, &t.name),
        );
        if fu.is_some() && tu.is_some() && fu != tu {
            x.push_str(" suppressUnitConversion=\"true\"");
        }
        match transformation(c) {
            None => x.push_str("/>\n"),
            Some(t) => {
                let _ = writeln!(x, ">\n        {t}\n      </ssd:Connection>");
            }
        }
    }
    x.push_str("    </ssd:Connections>\n");
}

/// A connection's transformation (SSP 1.0, `GTransformationChoice`): its value mapping as an
/// Integer or Boolean mapping transformation, or its gain and offset as a linear one.
fn transformation(c: &PlanConnection) -> Option<String> {
    if let Some(m) = &c.mapping {
        let (el, value): (&str, fn(i32) -> String) = match m.boolean {
            true => ("BooleanMappingTransformation", |v| (v != 0).to_string()),
            false => ("IntegerMappingTransformation", |v| v.to_string()),
        };
        let mut t = format!("<ssc:{el}>");
        for (source, target) in m.entries() {
            let _ = write!(
                t,
                "\n          <ssc:MapEntry source=\"{}\" target=\"{}\"/>",
                value(*source),
                value(*target)
            );
        }
        let _ = write!(t, "\n        </ssc:{el}>");
        return Some(t);
    }
    (c.gain != 1.0 || c.offset != 0.0).then(|| {
        format!(
            "<ssc:LinearTransformation factor=\"{}\" offset=\"{}\"/>",
            xs_double(c.gain),
            xs_double(c.offset)
        )
    })
}

/// `ssd:DefaultExperiment` with the base step as libcosim's fixed-step algorithm annotation.
fn default_experiment(x: &mut String, plan: &Plan) {
    let _ = writeln!(
        x,
        "  <ssd:DefaultExperiment startTime=\"{}\" stopTime=\"{}\">\n    <ssd:Annotations>\n      \
         <ssc:Annotation type=\"{OSP_ANNOTATION}\">\n        <osp:Algorithm>\n          \
         <osp:FixedStepAlgorithm baseStepSize=\"{}\"/>\n        </osp:Algorithm>\n      \
         </ssc:Annotation>\n    </ssd:Annotations>\n  </ssd:DefaultExperiment>",
        xs_double(plan.start_time),
        xs_double(plan.stop_time),
        xs_double(plan.step_size)
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_keep_each_definition() {
        let mut u = Units::default();
        let m = Unit::parse("m").unwrap();
        let km = Unit::parse("km").unwrap();
        assert_eq!(u.name_for("m", m), "m");
        assert_eq!(u.name_for("m", m), "m");
        assert_eq!(u.name_for("m", km), "m (2)");
        assert_eq!(u.name_for("m", km), "m (2)");
        let mut x = String::new();
        u.write(&mut x);
        assert!(
            x.contains(
                "<ssc:Unit name=\"m (2)\">\n      <ssc:BaseUnit m=\"1\" factor=\"1000.0\"/>"
            ),
            "{x}"
        );
    }

    #[test]
    fn doubles_read_back_to_the_same_bits() {
        for v in [
            0.05,
            1e-7,
            0.1 + 0.2,
            std::f64::consts::PI / 180.0,
            -2.5e300,
        ] {
            assert_eq!(xs_double(v).parse::<f64>().unwrap().to_bits(), v.to_bits());
        }
        assert_eq!(xs_double(f64::INFINITY), "INF");
    }
}
