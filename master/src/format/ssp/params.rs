//! Parameter bindings (SSP 1.0, sec. 5.3.4, `ParameterBinding`): parameter sets inline
//! (`ParameterValues`) or in `.ssv` files (`ParameterSet`, sec. 6), renamed and transformed by
//! parameter mappings inline or in `.ssm` files (`ParameterMapping`, sec. 7), then applied as
//! start values of the instances.
//!
//! Precedence as the standard says: a later binding of the same element overrides an earlier
//! one, and a system's bindings override those of its elements (they are applied last, the
//! outermost system at the very end). A system's bindings name variables hierarchically
//! (`element.variable`, `subsystem.element.variable`); a `prefix` is prepended to every name.
//! A name that matches no element is an error here (SSP lets tools ignore it), so that a typo
//! does not go unnoticed; a variable the FMU does not have is reported by the validation.

use super::reader::{base_unit, parse_bool, Reader, SEP};
use super::xml::{self, Element};
use crate::system::{Value, ValueSpec};
use crate::units::{RadRule, Unit};
use std::collections::HashMap;
use std::path::PathBuf;

/// What a binding parameterizes.
#[derive(Debug, Clone)]
pub(super) enum Target {
    /// An instance, by index.
    Component(usize),
    /// A system, by path ("" for the root).
    System(String),
}

/// A parameter value as written.
#[derive(Debug, Clone)]
enum PValue {
    Real(f64, Option<Unit>),
    Integer(i64),
    Boolean(bool),
    String(String),
    /// Item name and the items of its `Enumeration` (when the parameter names one).
    Enumeration(String, Option<Vec<(String, i32)>>),
}

#[derive(Debug, Clone)]
struct Param {
    name: String,
    value: PValue,
    /// The line in the SSD (inline parameter sets only).
    line: Option<usize>,
}

/// One binding, read and mapped, waiting to be applied.
pub(super) struct Binding {
    target: Target,
    params: Vec<Param>,
    /// The file the parameters came from (the SSD or an `.ssv`), for messages.
    file: PathBuf,
    line: usize,
}

/// The `ParameterBindings` of a component or system, read (not yet applied).
pub(super) fn bindings(r: &mut Reader, el: &Element, target: Target) -> Vec<Binding> {
    let mut out = Vec::new();
    for b in el
        .children_named("ParameterBindings")
        .flat_map(|p| p.children_named("ParameterBinding"))
    {
        if let Some(binding) = binding(r, b, target.clone()) {
            out.push(binding);
        }
    }
    out
}

/// The root element of an SSP file next to the SSD (an `.ssv` or `.ssm`), and its shown name.
fn referenced(r: &mut Reader, uri: &str, line: usize, what: &str) -> Option<(Element, PathBuf)> {
    let file = r.resolve_uri(uri, line, what)?;
    let shown = r.shown_file(&file);
    if !file.is_file() {
        r.error(Some(line), format!("{what}: file '{uri}' not found"));
        return None;
    }
    let parsed = super::read_bounded(&file, &shown).and_then(|t| xml::parse(&shown, &t));
    match parsed {
        Ok(root) => Some((root, shown)),
        Err(e) => {
            r.errors.push(e);
            None
        }
    }
}

fn binding(r: &mut Reader, b: &Element, target: Target) -> Option<Binding> {
    let mime = b.attr("type").unwrap_or("application/x-ssp-parameter-set");
    if mime != "application/x-ssp-parameter-set" {
        r.error(
            Some(b.line),
            format!("<ParameterBinding type=\"{mime}\"> is not supported (only application/x-ssp-parameter-set)"),
        );
        return None;
    }
    if b.attr("sourceBase") == Some("component") {
        r.error(
            Some(b.line),
            "<ParameterBinding sourceBase=\"component\"> (a parameter set inside the FMU) is not supported",
        );
        return None;
    }
    let (set, file, inline) = match b.attr("source") {
        Some(uri) => {
            let (root, shown) = referenced(r, uri, b.line, "<ParameterBinding>")?;
            (root, shown, false)
        }
        None => {
            let set = b
                .child("ParameterValues")
                .and_then(|v| v.child("ParameterSet"))
                .cloned();
            let Some(set) = set else {
                r.error(
                    Some(b.line),
                    "<ParameterBinding> has neither a source nor <ParameterValues><ssv:ParameterSet>",
                );
                return None;
            };
            (set, r.shown.clone(), true)
        }
    };
    let mut params = parameter_set(r, &set, &file, inline)?;
    // the prefix comes first: mapping entries name the prefixed parameters
    let prefix = b.attr("prefix").unwrap_or("");
    for p in &mut params {
        p.name = format!("{prefix}{}", p.name);
    }
    if let Some(m) = b.child("ParameterMapping") {
        let mapping = match m.attr("source") {
            Some(uri) => referenced(r, uri, m.line, "<ParameterMapping>")?,
            None => (m.child("ParameterMapping")?.clone(), r.shown.clone()),
        };
        params = map_parameters(r, params, &mapping.0, &mapping.1)?;
    }
    Some(Binding {
        target,
        params,
        file,
        line: b.line,
    })
}

/// An `ssv:ParameterSet`: its parameters, Real units and enumeration items resolved.
fn parameter_set(
    r: &mut Reader,
    set: &Element,
    file: &PathBuf,
    inline: bool,
) -> Option<Vec<Param>> {
    let err = |r: &mut Reader, line: usize, m: String| {
        r.errors
            .push(crate::error::Error::system(file, Some(line), m))
    };
    if set.name != "ParameterSet" {
        err(
            r,
            set.line,
            format!("<{}> is not an ssv:ParameterSet", set.name),
        );
        return None;
    }
    let mut units: HashMap<String, Unit> = r.units.clone();
    for u in set
        .children_named("Units")
        .flat_map(|u| u.children_named("Unit"))
    {
        match u.child("BaseUnit").map(base_unit) {
            Some(Ok(unit)) => {
                units.insert(u.attr("name").unwrap_or("").to_string(), unit);
            }
            _ => err(r, u.line, "<Unit>: needs a valid <BaseUnit>".into()),
        }
    }
    let mut enums = r.enums.clone();
    if let Some(e) = set.child("Enumerations") {
        enums.extend(r.read_enumerations(e));
    }
    let mut out = Vec::new();
    for p in set
        .children_named("Parameters")
        .flat_map(|p| p.children_named("Parameter"))
    {
        let name = p.attr("name").unwrap_or("").to_string();
        match parameter_value(p, &units, &enums) {
            Ok(value) => out.push(Param {
                name,
                value,
                line: inline.then_some(p.line),
            }),
            Err(m) => err(r, p.line, format!("<Parameter name=\"{name}\">: {m}")),
        }
    }
    Some(out)
}

/// The value element of a `Parameter`.
fn parameter_value(
    p: &Element,
    units: &HashMap<String, Unit>,
    enums: &HashMap<String, Vec<(String, i32)>>,
) -> Result<PValue, String> {
    let v = p
        .children
        .iter()
        .find(|c| c.name != "Annotations")
        .ok_or("no value element")?;
    let text = v
        .attr("value")
        .ok_or_else(|| format!("<{}> has no value", v.name))?;
    let bad = || format!("<{} value=\"{text}\">: not a valid {}", v.name, v.name);
    Ok(match v.name.as_str() {
        "Real" => {
            let x = text.trim().parse::<f64>().map_err(|_| bad())?;
            let unit = match v.attr("unit") {
                None => None,
                Some(u) => Some(
                    units
                        .get(u)
                        .copied()
                        .or_else(|| Unit::parse(u).ok())
                        .ok_or_else(|| format!("unit \"{u}\" is not defined in <Units>"))?,
                ),
            };
            PValue::Real(x, unit)
        }
        "Integer" => PValue::Integer(text.trim().parse::<i32>().map_err(|_| bad())? as i64),
        "Boolean" => PValue::Boolean(parse_bool(text).ok_or_else(bad)? == 1),
        "String" => PValue::String(text.to_string()),
        "Enumeration" => PValue::Enumeration(
            text.to_string(),
            v.attr("name").and_then(|e| enums.get(e)).cloned(),
        ),
        other => return Err(format!("<{other}> values are not supported")),
    })
}

/// Applies an `ssm:ParameterMapping`: a parameter named by a `MappingEntry@source` is renamed
/// to its `target` and its value transformed; the others keep their names.
fn map_parameters(
    r: &mut Reader,
    params: Vec<Param>,
    m: &Element,
    file: &PathBuf,
) -> Option<Vec<Param>> {
    if m.name != "ParameterMapping" {
        r.errors.push(crate::error::Error::system(
            file,
            Some(m.line),
            format!("<{}> is not an ssm:ParameterMapping", m.name),
        ));
        return None;
    }
    let entries: Vec<&Element> = m.children_named("MappingEntry").collect();
    let mut out = Vec::with_capacity(params.len());
    for mut p in params {
        if let Some(e) = entries
            .iter()
            .find(|e| e.attr("source") == Some(p.name.as_str()))
        {
            p.name = e.attr("target").unwrap_or("").to_string();
            if let Some(t) = e.children.iter().find(|c| c.name != "Annotations") {
                match transform(&p.value, t) {
                    Ok(v) => p.value = v,
                    Err(msg) => {
                        r.errors.push(crate::error::Error::system(
                            file,
                            Some(t.line),
                            format!(
                                "<MappingEntry source=\"{}\">: {msg}",
                                e.attr("source").unwrap_or("")
                            ),
                        ));
                        continue;
                    }
                }
            }
        }
        out.push(p);
    }
    Some(out)
}

/// A mapping entry's transformation applied to a parameter value.
fn transform(v: &PValue, t: &Element) -> Result<PValue, String> {
    let entries = || {
        t.children_named("MapEntry")
            .map(|e| (e.attr("source"), e.attr("target")))
    };
    match (t.name.as_str(), v) {
        ("LinearTransformation", PValue::Real(x, u)) => {
            let num = |k: &str, d: f64| t.attr(k).map_or(Some(d), |s| s.trim().parse().ok());
            let (Some(f), Some(o)) = (num("factor", 1.0), num("offset", 0.0)) else {
                return Err("<LinearTransformation>: factor and offset must be numbers".into());
            };
            Ok(PValue::Real(f * x + o, *u))
        }
        ("IntegerMappingTransformation", PValue::Integer(x)) => Ok(PValue::Integer(
            entries()
                .find(|(s, _)| s.and_then(|s| s.trim().parse::<i64>().ok()) == Some(*x))
                .and_then(|(_, t)| t?.trim().parse::<i64>().ok())
                .unwrap_or(*x),
        )),
        ("BooleanMappingTransformation", PValue::Boolean(x)) => Ok(PValue::Boolean(
            entries()
                .find(|(s, _)| s.and_then(parse_bool) == Some(*x as i32))
                .and_then(|(_, t)| parse_bool(t?))
                .map_or(*x, |t| t == 1),
        )),
        ("EnumerationMappingTransformation", PValue::Enumeration(x, items)) => {
            match entries().find(|(s, _)| *s == Some(x.as_str())) {
                Some((_, Some(t))) => Ok(PValue::Enumeration(t.to_string(), items.clone())),
                _ => Ok(v.clone()),
            }
        }
        (name, _) => Err(format!("<{name}> does not apply to this parameter's type")),
    }
}

/// Applies a binding's parameters as start values of the instances they name.
pub(super) fn apply(r: &mut Reader, b: Binding) {
    for p in b.params {
        let resolved = match &b.target {
            Target::Component(i) => Some((*i, p.name.clone())),
            Target::System(path) => resolve(r, path, &p.name),
        };
        let Some((i, variable)) = resolved else {
            r.errors.push(crate::error::Error::system(
                &b.file,
                p.line.or(Some(b.line)),
                format!(
                    "parameter '{}': no component of system '{}' has this hierarchical name (parameters of system connectors are not supported)",
                    p.name,
                    match &b.target { Target::System(s) if !s.is_empty() => s.as_str(), _ => "(root)" }
                ),
            ));
            continue;
        };
        let Some(value) = value(r, i, &variable, &p, &b.file) else {
            continue;
        };
        let inst = &mut r.instances[i];
        inst.values.retain(|v| v.variable != variable);
        inst.values.push(ValueSpec {
            variable,
            value,
            line: p.line,
        });
    }
}

/// `element.variable` or `subsystem.element.variable` below the system at `path`: the instance
/// and the variable name.
fn resolve(r: &Reader, path: &str, name: &str) -> Option<(usize, String)> {
    let (first, rest) = name.split_once('.')?;
    let full = if path.is_empty() {
        first.to_string()
    } else {
        format!("{path}{SEP}{first}")
    };
    if let Some(i) = r.instances.iter().position(|inst| inst.name == full) {
        return Some((i, rest.to_string()));
    }
    if r.systems.contains(&full) {
        return resolve(r, &full, rest);
    }
    None
}

/// The start value of a parameter: a Real with a unit converted to the FMU variable's unit
/// (exactly when the units are equal), an enumeration item as its value.
fn value(r: &mut Reader, i: usize, variable: &str, p: &Param, file: &PathBuf) -> Option<Value> {
    let fail = |r: &mut Reader, m: String| {
        r.errors.push(crate::error::Error::system(
            file,
            p.line,
            format!(
                "parameter '{}' ({}.{variable}): {m}",
                p.name, r.instances[i].name
            ),
        ));
        None
    };
    Some(match &p.value {
        PValue::Real(x, None) => Value::Real(*x),
        PValue::Real(x, Some(u)) => {
            let declared = r.model_description(i).and_then(|md| {
                let sv = md.model_variables.variables.iter().find(|v| v.name == variable)?;
                crate::units::declared(md, md.real_unit(sv)?).ok()
            });
            match declared {
                None => Value::Real(u.to_si(*x)),
                Some((to, fmu)) => {
                    let rule = RadRule::Omittable { from: false, to: fmu };
                    match u.conversion_to(&to, rule) {
                        Some(c) => Value::Real(c.apply(*x)),
                        None => {
                            return fail(
                                r,
                                format!(
                                    "its unit ({}) does not convert to the variable's ({})",
                                    u.dimension(),
                                    to.dimension()
                                ),
                            )
                        }
                    }
                }
            }
        }
        PValue::Integer(x) => Value::Integer(*x),
        PValue::Boolean(x) => Value::Boolean(*x),
        PValue::String(s) => Value::String(s.clone()),
        PValue::Enumeration(item, items) => match items
            .iter()
            .flatten()
            .find(|(n, _)| n == item)
        {
            Some((_, v)) => Value::Integer(i64::from(*v)),
            None => return fail(
                r,
                format!("enumeration item \"{item}\" is not an item of an <Enumeration> of the SSV or SSD (give its name attribute)"),
            ),
        },
    })
}
