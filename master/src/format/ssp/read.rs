//! The SSD (`SystemStructureDescription`, SSP 1.0, sec. 5) read into a flat [`System`].
//!
//! - **Systems** nest: every component becomes an instance named by its path below the root
//!   system, the levels joined with [`SEP`] (`inner/comp`; top-level components keep their
//!   names, as in libcosim). A dot cannot join them: `instance.variable` splits at the first
//!   dot everywhere in shipsim (`--set`, outputs, campaigns).
//! - **Connections** between components, through any number of system connectors, become one
//!   connection each from the source component's connector to the target component's.
//! - **Units**: a Real connection whose ends have different units (the connector's `unit`, a
//!   `Unit` of the SSD's `Units`, or else the FMU variable's declared unit) is converted
//!   ([`crate::units::Conversion::gain_offset`]); different SI exponents are an error unless
//!   `suppressUnitConversion` is set. The conversion is applied before a `LinearTransformation`
//!   (SSP 1.0, `SystemStructureCommon.xsd`, `LinearTransformation@factor`).
//! - **Mappings**: `BooleanMappingTransformation`, `IntegerMappingTransformation` and
//!   `EnumerationMappingTransformation` (item names resolved through the connectors'
//!   `Enumeration` types in the SSD's `Enumerations`) become a [`ValueMapping`].
//! - **Time**: `DefaultExperiment` start and stop; the base step from libcosim's
//!   `com.opensimulationplatform` annotation (`osp:FixedStepAlgorithm@baseStepSize`, and
//!   `osp:StepSizeHint` per component for step multiples) or OMSimulator's `org.openmodelica`
//!   one (`oms:FixedStepMaster@stepSize`). A variable-step master is refused.

use super::params::{self, Binding};
use super::reader::{base_unit, parse_f64, Connector, Edge, Port, Reader, SEP};
use super::xml::{self, Element};
use crate::error::{Error, Result};
use crate::system::{Algorithm, Format, InstanceSpec, OutputSpec, System};
use crate::units::Unit;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Reads `ssd` (shown as `shown`'s name in errors; `in_archive`: `ssd` was unpacked from the
/// archive `shown`).
pub fn read_ssd(ssd: &Path, shown: &Path, in_archive: bool) -> Result<System> {
    let shown_ssd = if in_archive {
        shown.join(super::DEFAULT_SSD)
    } else {
        shown.to_path_buf()
    };
    let text = super::read_bounded(ssd, &shown_ssd)?;
    let root = xml::parse(&shown_ssd, &text)?;
    let dir = ssd.parent().unwrap_or(Path::new("."));
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let mut r = Reader {
        shown: shown_ssd,
        dir,
        archive: in_archive.then_some(shown),
        units: HashMap::new(),
        enums: HashMap::new(),
        errors: Vec::new(),
        instances: Vec::new(),
        connectors: HashMap::new(),
        edges: Vec::new(),
        mds: HashMap::new(),
        step_hints: Vec::new(),
        nested_steps: Vec::new(),
        systems: Default::default(),
    };
    r.document(&root)
}

impl Reader<'_> {
    pub(super) fn error(&mut self, line: Option<usize>, message: impl Into<String>) {
        self.errors
            .push(Error::system(&self.shown, line, message.into()));
    }

    /// The whole document: header, units, enumerations, the systems, the experiment.
    fn document(&mut self, root: &Element) -> Result<System> {
        if root.name != "SystemStructureDescription" {
            return Err(Error::system(
                &self.shown,
                Some(root.line),
                format!(
                    "<{}> is not an SSP 1.0 SystemStructureDescription",
                    root.name
                ),
            ));
        }
        let version = root.attr("version").unwrap_or("");
        if !version.starts_with("1.") {
            return Err(Error::system(
                &self.shown,
                Some(root.line),
                format!("<SystemStructureDescription version=\"{version}\">: shipsim reads SSP 1.0 (version 1.x)"),
            ));
        }
        if let Some(u) = root.child("Units") {
            self.units = self.read_units(u);
        }
        if let Some(e) = root.child("Enumerations") {
            self.enums = self.read_enumerations(e);
        }
        let Some(system) = root.child("System") else {
            return Err(Error::system(
                &self.shown,
                Some(root.line),
                "<SystemStructureDescription> has no <System>",
            ));
        };
        let mut bindings = Vec::new();
        self.system(system, "", &mut bindings);
        let (start, stop) = self.experiment(root);
        let step = self.base_step(root, system);
        for b in bindings {
            params::apply(self, b);
        }
        let connections = self.connections();
        let step_size = step.unwrap_or(f64::NAN);
        self.step_multiples(step_size);
        super::super::collected(std::mem::take(&mut self.errors))?;
        Ok(System {
            source: self.shown.clone(),
            format: Format::Ssp,
            start_time: start,
            stop_time: stop,
            step_size,
            algorithm: Algorithm::Jacobi,
            instances: std::mem::take(&mut self.instances),
            connections,
            events: Vec::new(),
            output: OutputSpec {
                decimation: 1,
                ..OutputSpec::default()
            },
            strict_units: true,
            last_step: Default::default(),
            archive: None,
            notes: Vec::new(),
            io: Vec::new(),
        })
    }

    /// `Units`: name -> unit (SSP 1.0 `ssc:Unit` with `BaseUnit`, as FMI 2.0 sec. 2.2.2).
    fn read_units(&mut self, units: &Element) -> HashMap<String, Unit> {
        let mut out = HashMap::new();
        for u in units.children_named("Unit") {
            let name = u.attr("name").unwrap_or("").to_string();
            let Some(b) = u.child("BaseUnit") else {
                self.error(
                    Some(u.line),
                    format!("<Unit name=\"{name}\"> has no <BaseUnit>"),
                );
                continue;
            };
            match base_unit(b) {
                Ok(unit) => {
                    out.insert(name, unit);
                }
                Err(m) => self.error(Some(b.line), format!("<Unit name=\"{name}\">: {m}")),
            }
        }
        out
    }

    /// `Enumerations`: name -> items (name, value).
    pub(super) fn read_enumerations(
        &mut self,
        el: &Element,
    ) -> HashMap<String, Vec<(String, i32)>> {
        let mut out = HashMap::new();
        for e in el.children_named("Enumeration") {
            let name = e.attr("name").unwrap_or("").to_string();
            let mut items = Vec::new();
            for it in e.children_named("Item") {
                let v = it.attr("value").and_then(|v| v.trim().parse::<i32>().ok());
                match (it.attr("name"), v) {
                    (Some(n), Some(v)) => items.push((n.to_string(), v)),
                    _ => self.error(
                        Some(it.line),
                        format!("<Enumeration name=\"{name}\">: an <Item> needs a name and an integer value"),
                    ),
                }
            }
            out.insert(name, items);
        }
        out
    }

    /// One system at `path` ("" for the root): its connectors, elements, connections and
    /// parameter bindings (collected in `bindings`, applied after every system is read).
    fn system(&mut self, sys: &Element, path: &str, bindings: &mut Vec<Binding>) {
        let sys_name = sys.attr("name").unwrap_or("").to_string();
        self.systems.insert(path.to_string());
        if sys.child("SignalDictionaries").is_some() {
            self.error(
                Some(sys.child("SignalDictionaries").map_or(sys.line, |e| e.line)),
                format!("system '{sys_name}': <SignalDictionaries> are not supported"),
            );
        }
        for c in connectors(sys) {
            let (name, conn) = self.connector(c, &sys_name);
            self.connectors
                .insert(Port::System(path.to_string(), name), conn);
        }
        // element name -> its port (component instance or system path)
        let mut elements: HashMap<String, ElementRef> = HashMap::new();
        for el in sys.children_named("Elements").flat_map(|e| &e.children) {
            let Some(name) = el.attr("name").map(str::to_string) else {
                self.error(Some(el.line), format!("<{}> has no name", el.name));
                continue;
            };
            if elements.contains_key(&name) {
                self.error(
                    Some(el.line),
                    format!("system '{sys_name}': element '{name}' is defined twice"),
                );
                continue;
            }
            let full = join(path, &name);
            match el.name.as_str() {
                "Component" => {
                    if let Some(i) = self.component(el, &full, bindings) {
                        elements.insert(name, ElementRef::Component(i));
                    }
                }
                "System" => {
                    self.system(el, &full, bindings);
                    elements.insert(name, ElementRef::System(full));
                }
                other => self.error(
                    Some(el.line),
                    format!("system '{sys_name}': <{other} name=\"{name}\"> is not supported (signal dictionaries are not)"),
                ),
            }
        }
        for c in sys.children_named("Connections").flat_map(|e| &e.children) {
            if c.name == "Connection" {
                self.edge(c, path, &sys_name, &elements);
            }
        }
        for b in params::bindings(self, sys, params::Target::System(path.to_string())) {
            bindings.push(b);
        }
        self.system_annotations(sys, path);
    }

    /// A connector element: its name and declaration.
    fn connector(&mut self, c: &Element, owner: &str) -> (String, Connector) {
        let name = c.attr("name").unwrap_or("").to_string();
        let kind = c.attr("kind").unwrap_or("").to_string();
        if !matches!(
            kind.as_str(),
            "input" | "output" | "inout" | "parameter" | "calculatedParameter"
        ) {
            self.error(
                Some(c.line),
                format!("'{owner}': connector '{name}' has kind \"{kind}\"; SSP 1.0 kinds are input, output, inout, parameter, calculatedParameter"),
            );
        }
        let mut conn = Connector::default();
        for t in &c.children {
            match t.name.as_str() {
                "Real" => {
                    conn.var_type = Some("Real".into());
                    conn.unit = t.attr("unit").map(str::to_string);
                }
                "Integer" | "Boolean" | "String" => conn.var_type = Some(t.name.clone()),
                "Enumeration" => {
                    conn.var_type = Some("Enumeration".into());
                    conn.enumeration = t.attr("name").map(str::to_string);
                }
                "Binary" => self.error(
                    Some(t.line),
                    format!("'{owner}': connector '{name}' is Binary, which FMI 2.0 has no variable for"),
                ),
                _ => {}
            }
        }
        (name, conn)
    }

    /// A component: an FMU, its connectors, its step-size hint and parameter bindings.
    fn component(
        &mut self,
        el: &Element,
        full: &str,
        bindings: &mut Vec<Binding>,
    ) -> Option<usize> {
        let mime = el.attr("type").unwrap_or("application/x-fmu-sharedlibrary");
        if mime != "application/x-fmu-sharedlibrary" {
            self.error(
                Some(el.line),
                format!("component '{full}': type \"{mime}\" is not supported (only FMUs, application/x-fmu-sharedlibrary)"),
            );
            return None;
        }
        if let Some(imp) = el.attr("implementation").filter(|i| *i == "ModelExchange") {
            self.error(
                Some(el.line),
                format!("component '{full}': implementation \"{imp}\" is not supported (shipsim runs co-simulation FMUs)"),
            );
            return None;
        }
        let Some(source) = el.attr("source") else {
            self.error(Some(el.line), format!("component '{full}' has no source"));
            return None;
        };
        let fmu = self.resolve_uri(source, el.line, &format!("component '{full}'"))?;
        if !fmu.is_file() {
            self.error(
                Some(el.line),
                format!("component '{full}': FMU '{source}' not found"),
            );
            return None;
        }
        let i = self.instances.len();
        self.instances.push(InstanceSpec {
            name: full.to_string(),
            fmu,
            step_multiple: 1,
            values: Vec::new(),
            line: Some(el.line),
            // SSP has no such attribute: `--isolate=NAMES` isolates instances of an SSP system.
            isolate: false,
        });
        self.step_hints.push(step_size_hint(el));
        for c in connectors(el) {
            let (name, conn) = self.connector(c, full);
            self.connectors.insert(Port::Component(i, name), conn);
        }
        bindings.extend(params::bindings(self, el, params::Target::Component(i)));
        Some(i)
    }

    /// A relative URI (SSP 1.0: relative to the SSD; percent-escapes decoded) as a file path.
    /// Absolute URIs, schemes, and `..` inside an archive are refused.
    pub(super) fn resolve_uri(&mut self, uri: &str, line: usize, what: &str) -> Option<PathBuf> {
        let path = percent_decode(uri.strip_prefix("./").unwrap_or(uri));
        let has_scheme = path
            .split_once(':')
            .is_some_and(|(s, _)| !s.is_empty() && !s.contains('/'));
        let up = Path::new(&path)
            .components()
            .any(|c| c == std::path::Component::ParentDir);
        if has_scheme
            || path.starts_with('/')
            || path.contains('#')
            || (up && self.archive.is_some())
        {
            self.error(
                Some(line),
                format!("{what}: source \"{uri}\" is not supported; use a relative path (SSP 1.0: relative to the SSD, inside the archive)"),
            );
            return None;
        }
        Some(self.dir.join(path))
    }

    /// The name users see for a file next to the SSD.
    pub(super) fn shown_file(&self, file: &Path) -> PathBuf {
        let rel = file.strip_prefix(self.dir).unwrap_or(file);
        match self.archive {
            Some(a) => a.join(rel),
            None => file.to_path_buf(),
        }
    }

    /// One `Connection`: both ends resolved to ports, its transformation kept.
    fn edge(
        &mut self,
        c: &Element,
        path: &str,
        sys_name: &str,
        elements: &HashMap<String, ElementRef>,
    ) {
        let mut end = |el: Option<&str>, conn: Option<&str>, which: &str| -> Option<Port> {
            let conn = conn.unwrap_or("");
            let port = match el {
                None | Some("") => Port::System(path.to_string(), conn.to_string()),
                Some(e) => match elements.get(e) {
                    Some(ElementRef::Component(i)) => Port::Component(*i, conn.to_string()),
                    Some(ElementRef::System(p)) => Port::System(p.clone(), conn.to_string()),
                    None => {
                        self.error(
                            Some(c.line),
                            format!("system '{sys_name}': <Connection> {which}Element \"{e}\" is not an element of the system"),
                        );
                        return None;
                    }
                },
            };
            if !self.connectors.contains_key(&port) {
                let owner = el.unwrap_or(sys_name);
                self.error(
                    Some(c.line),
                    format!("system '{sys_name}': <Connection> {which}Connector \"{conn}\": '{owner}' has no such connector"),
                );
                return None;
            }
            Some(port)
        };
        let from = end(c.attr("startElement"), c.attr("startConnector"), "start");
        let to = end(c.attr("endElement"), c.attr("endConnector"), "end");
        let (Some(from), Some(to)) = (from, to) else {
            return;
        };
        let mut linear = None;
        let mut mapping = None;
        for t in &c.children {
            match t.name.as_str() {
                "LinearTransformation" => {
                    let factor = t.attr("factor").map_or(Some(1.0), parse_f64);
                    let offset = t.attr("offset").map_or(Some(0.0), parse_f64);
                    match (factor, offset) {
                        (Some(f), Some(o)) => linear = Some((f, o)),
                        _ => self.error(
                            Some(t.line),
                            "<LinearTransformation>: factor and offset must be finite numbers",
                        ),
                    }
                }
                "BooleanMappingTransformation"
                | "IntegerMappingTransformation"
                | "EnumerationMappingTransformation" => mapping = Some(t.clone()),
                _ => {}
            }
        }
        self.edges.push(Edge {
            from,
            to,
            line: c.line,
            linear,
            mapping,
            suppress_units: c.attr("suppressUnitConversion").map(str::trim) == Some("true"),
        });
    }
}

/// What an element name of a system refers to.
enum ElementRef {
    Component(usize),
    System(String),
}

/// The `Connector`s of a component or system.
fn connectors(el: &Element) -> impl Iterator<Item = &Element> {
    el.children_named("Connectors")
        .flat_map(|c| c.children_named("Connector"))
}

/// `path/name`, or `name` at the root.
fn join(path: &str, name: &str) -> String {
    if path.is_empty() {
        name.to_string()
    } else {
        format!("{path}{SEP}{name}")
    }
}

/// `%XX` escapes of a URI decoded (invalid ones kept as written).
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// `osp:StepSizeHint@value` of a component's `com.opensimulationplatform` annotation.
fn step_size_hint(el: &Element) -> Option<f64> {
    annotations(el, "com.opensimulationplatform")
        .filter_map(|a| a.child("StepSizeHint"))
        .find_map(|h| h.attr("value").and_then(parse_f64))
}

/// The `Annotation`s of this type under the element's `Annotations`.
fn annotations<'e>(el: &'e Element, kind: &'e str) -> impl Iterator<Item = &'e Element> {
    el.children_named("Annotations")
        .flat_map(|a| a.children_named("Annotation"))
        .filter(move |a| a.attr("type") == Some(kind))
}

/// Every element below `el` (depth first).
fn descendants(el: &Element) -> Vec<&Element> {
    let mut out = Vec::new();
    let mut stack: Vec<&Element> = el.children.iter().rev().collect();
    while let Some(e) = stack.pop() {
        out.push(e);
        stack.extend(e.children.iter().rev());
    }
    out
}

impl Reader<'_> {
    /// `DefaultExperiment` start (default 0) and stop times.
    fn experiment(&mut self, root: &Element) -> (f64, Option<f64>) {
        let Some(de) = root.child("DefaultExperiment") else {
            return (0.0, None);
        };
        let mut time = |k: &str| -> Option<f64> {
            let v = de.attr(k)?;
            let t = parse_f64(v);
            if t.is_none() {
                self.error(
                    Some(de.line),
                    format!("<DefaultExperiment {k}=\"{v}\">: not a finite number"),
                );
            }
            t
        };
        (time("startTime").unwrap_or(0.0), time("stopTime"))
    }

    /// The base step: libcosim's annotation on the `DefaultExperiment` or OMSimulator's on the
    /// root system (both, if present, must agree). None is an error naming the file.
    fn base_step(&mut self, root: &Element, system: &Element) -> Option<f64> {
        let mut steps: Vec<(f64, usize, &str)> = Vec::new();
        if let Some(de) = root.child("DefaultExperiment") {
            for a in annotations(de, "com.opensimulationplatform") {
                for e in descendants(a) {
                    match e.name.as_str() {
                        "FixedStepAlgorithm" => match e.attr("baseStepSize").and_then(parse_f64) {
                            Some(h) if h > 0.0 => steps.push((h, e.line, "osp:FixedStepAlgorithm")),
                            _ => self.error(
                                Some(e.line),
                                "<osp:FixedStepAlgorithm>: baseStepSize must be a positive number",
                            ),
                        },
                        "Algorithm" | "SimulationInformation" => {}
                        other => self.error(
                            Some(e.line),
                            format!("<osp:{other}>: only the fixed-step master (osp:FixedStepAlgorithm) is supported"),
                        ),
                    }
                }
            }
        }
        if let Some((h, line)) = self.oms_step(system) {
            steps.push((h, line, "oms:FixedStepMaster"));
        }
        for (h, line) in std::mem::take(&mut self.nested_steps) {
            steps.push((h, line, "oms:FixedStepMaster of a nested system"));
        }
        match steps.as_slice() {
            // SSP 1.0 defines no step size: the run's caller gives one
            // (System::apply_step_size), unless a component's rate needs the base step now.
            [] => {
                if let Some(i) = self.step_hints.iter().position(Option::is_some) {
                    let (name, line) = (self.instances[i].name.clone(), self.instances[i].line);
                    self.error(
                        line,
                        format!("component '{name}' has an osp:StepSizeHint, but no <osp:FixedStepAlgorithm baseStepSize=\"...\"> gives the base step it is a multiple of"),
                    );
                }
                None
            }
            [(h, ..)] => Some(*h),
            [(h, _, a), rest @ ..] => {
                for (h2, line, b) in rest {
                    if h2 != h {
                        self.error(
                            Some(*line),
                            format!("<{b}> gives step size {h2} but <{a}> gives {h}"),
                        );
                    }
                }
                Some(*h)
            }
        }
    }

    /// OMSimulator's `oms:FixedStepMaster@stepSize` of a system (refusing a variable-step master).
    fn oms_step(&mut self, system: &Element) -> Option<(f64, usize)> {
        let mut found = None;
        for a in annotations(system, "org.openmodelica") {
            for e in descendants(a) {
                match e.name.as_str() {
                    "FixedStepMaster" => match e.attr("stepSize").and_then(parse_f64) {
                        Some(h) if h > 0.0 => found = Some((h, e.line)),
                        _ => self.error(
                            Some(e.line),
                            "<oms:FixedStepMaster>: stepSize must be a positive number",
                        ),
                    },
                    n if n.starts_with("VariableStep") => self.error(
                        Some(e.line),
                        format!("<oms:{n}>: variable-step masters are not supported; shipsim runs a fixed-step master"),
                    ),
                    _ => {}
                }
            }
        }
        found
    }

    /// A nested system's own OMSimulator master (compared with the root's in
    /// [`Reader::base_step`]; a variable-step one is refused in [`Reader::oms_step`]).
    fn system_annotations(&mut self, sys: &Element, path: &str) {
        if !path.is_empty() {
            if let Some(s) = self.oms_step(sys) {
                self.nested_steps.push(s);
            }
        }
    }

    /// Step multiples from the components' `osp:StepSizeHint` (an integer multiple of the base step).
    fn step_multiples(&mut self, h: f64) {
        if !(h > 0.0) {
            return;
        }
        for i in 0..self.instances.len() {
            let Some(hint) = self.step_hints[i] else {
                continue;
            };
            let r = hint / h;
            let m = r.round();
            if m < 1.0 || (r - m).abs() > 1e-6 * r.max(1.0) || m > u32::MAX as f64 {
                let (name, line) = (self.instances[i].name.clone(), self.instances[i].line);
                self.error(
                    line,
                    format!("component '{name}': osp:StepSizeHint {hint} is not a positive integer multiple of the base step {h}"),
                );
            } else {
                self.instances[i].step_multiple = m as u32;
            }
        }
    }
}
