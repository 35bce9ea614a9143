//! Generation of `modelDescription.xml` (FMI 2.0 section 2.2) and `documentation/index.html`
//! from a model's variable table.

use crate::variables::{base_unit_names, unit_def, Access, Causality, Initial};
use crate::{FmuModel, LOG_CATEGORIES};
use std::fmt::Write;

/// Escapes text for XML/HTML attribute and element content.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

/// Formats a Real so that it round-trips exactly and is a valid `xs:double`.
pub fn real(v: f64) -> String {
    format!("{v:?}")
}

const GUID_PLACEHOLDER: &str = "@GUID@";

/// `<VendorAnnotations>` (FMI 2.0, sec. 2.2.6) with the tool "shipsim"'s couplings: each output
/// declared `.gated_by(parameter)` as `<Coupling output=".." gain=".."/>`. Nothing when no output
/// declares one (the model description is then as before).
fn vendor_annotations<M>(x: &mut String, vars: &[crate::Variable<M>]) {
    let gated: Vec<_> = vars
        .iter()
        .filter_map(|v| v.gate.map(|g| (v.name, g)))
        .collect();
    if gated.is_empty() {
        return;
    }
    x.push_str("  <VendorAnnotations>\n    <Tool name=\"shipsim\">\n      <Couplings>\n");
    for (output, gain) in gated {
        let _ = writeln!(
            x,
            r#"        <Coupling output="{}" gain="{}"/>"#,
            escape(output),
            escape(gain)
        );
    }
    x.push_str("      </Couplings>\n    </Tool>\n  </VendorAnnotations>\n");
}

/// The model description with the GUID placeholder (the GUID is a hash of this text).
fn description_template<M: FmuModel>() -> String {
    description_template_of(&M::default())
}

/// [`description_template`] with the start values read from `default` (= `M::default()`).
fn description_template_of<M: FmuModel>(default: &M) -> String {
    let vars = M::variables();
    let mut x = String::new();
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        x,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{id}" guid="{GUID_PLACEHOLDER}" description="{d}" version="{ver}" generationTool="ship-control fmi2-export {ver}" variableNamingConvention="structured" numberOfEventIndicators="0">"#,
        id = M::MODEL_IDENTIFIER,
        d = escape(M::DESCRIPTION),
        ver = env!("CARGO_PKG_VERSION"),
    );
    let _ = writeln!(
        x,
        r#"  <CoSimulation modelIdentifier="{}" needsExecutionTool="false" canHandleVariableCommunicationStepSize="true" canInterpolateInputs="false" maxOutputDerivativeOrder="0" canRunAsynchronuously="false" canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="true" canSerializeFMUstate="true" providesDirectionalDerivative="false"/>"#,
        M::MODEL_IDENTIFIER
    );
    // Units actually used, in registry order.
    let mut used: Vec<&str> = vars.iter().filter_map(|v| v.unit()).collect();
    used.sort();
    used.dedup();
    if !used.is_empty() {
        x.push_str("  <UnitDefinitions>\n");
        for u in crate::variables::UNITS
            .iter()
            .filter(|u| used.contains(&u.name))
        {
            let _ = write!(x, r#"    <Unit name="{}">"#, escape(u.name));
            x.push_str("\n      <BaseUnit");
            for (name, e) in base_unit_names().iter().zip(u.exponents) {
                if e != 0 {
                    let _ = write!(x, r#" {name}="{e}""#);
                }
            }
            if u.factor != 1.0 {
                let _ = write!(x, r#" factor="{}""#, real(u.factor));
            }
            x.push_str("/>\n");
            for (dname, f) in u.display {
                let _ = writeln!(
                    x,
                    r#"      <DisplayUnit name="{}" factor="{}"/>"#,
                    escape(dname),
                    real(*f)
                );
            }
            x.push_str("    </Unit>\n");
        }
        x.push_str("  </UnitDefinitions>\n");
    }
    x.push_str("  <LogCategories>\n");
    for (name, desc) in LOG_CATEGORIES {
        let _ = writeln!(
            x,
            r#"    <Category name="{name}" description="{}"/>"#,
            escape(desc)
        );
    }
    x.push_str("  </LogCategories>\n");
    let de = M::DEFAULT_EXPERIMENT;
    let _ = writeln!(
        x,
        r#"  <DefaultExperiment startTime="{}" stopTime="{}" stepSize="{}"/>"#,
        real(de.start_time),
        real(de.stop_time),
        real(de.step_size)
    );
    vendor_annotations(&mut x, vars);
    x.push_str("  <ModelVariables>\n");
    for (vr, v) in vars.iter().enumerate() {
        let _ = write!(
            x,
            r#"    <ScalarVariable name="{}" valueReference="{vr}" description="{}" causality="{}" variability="{}""#,
            escape(v.name),
            escape(v.description),
            v.causality.xml_name(),
            v.variability.xml_name()
        );
        if let Some(init) = v.initial() {
            let _ = write!(x, r#" initial="{}""#, init.xml_name());
        }
        x.push_str(">\n      ");
        match &v.access {
            Access::Real {
                get,
                unit,
                min,
                max,
                ..
            } => {
                x.push_str("<Real");
                if let Some(u) = unit {
                    let _ = write!(x, r#" unit="{}""#, escape(u));
                    if let Some(d) = unit_def(u).and_then(|d| d.display.first()) {
                        let _ = write!(x, r#" displayUnit="{}""#, escape(d.0));
                    }
                }
                if let Some(m) = min {
                    let _ = write!(x, r#" min="{}""#, real(*m));
                }
                if let Some(m) = max {
                    let _ = write!(x, r#" max="{}""#, real(*m));
                }
                if v.has_start() {
                    let _ = write!(x, r#" start="{}""#, real(get(default)));
                }
            }
            Access::Integer { get, min, max, .. } => {
                x.push_str("<Integer");
                if let Some(m) = min {
                    let _ = write!(x, r#" min="{m}""#);
                }
                if let Some(m) = max {
                    let _ = write!(x, r#" max="{m}""#);
                }
                if v.has_start() {
                    let _ = write!(x, r#" start="{}""#, get(default));
                }
            }
            Access::Boolean { get, .. } => {
                x.push_str("<Boolean");
                if v.has_start() {
                    let _ = write!(x, r#" start="{}""#, get(default));
                }
            }
        }
        x.push_str("/>\n    </ScalarVariable>\n");
    }
    x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    // FMI indices are 1-based positions in ModelVariables.
    let outputs: Vec<usize> = vars
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .map(|(i, _)| i + 1)
        .collect();
    let initial_unknowns: Vec<usize> = vars
        .iter()
        .enumerate()
        .filter(|(_, v)| {
            (v.causality == Causality::Output && v.initial() == Some(Initial::Calculated))
                || v.causality == Causality::CalculatedParameter
        })
        .map(|(i, _)| i + 1)
        .collect();
    if !outputs.is_empty() {
        x.push_str("    <Outputs>\n");
        for i in &outputs {
            let v = &vars[i - 1];
            let deps = v.dependencies.or(if M::DIRECT_FEEDTHROUGH {
                None
            } else {
                Some(&[])
            });
            match deps {
                None => {
                    let _ = writeln!(x, r#"      <Unknown index="{i}"/>"#);
                }
                Some(names) => {
                    let idx: Vec<String> = names
                        .iter()
                        .filter_map(|n| vars.iter().position(|w| w.name == *n))
                        .map(|k| (k + 1).to_string())
                        .collect();
                    let _ = writeln!(
                        x,
                        r#"      <Unknown index="{i}" dependencies="{}"/>"#,
                        idx.join(" ")
                    );
                }
            }
        }
        x.push_str("    </Outputs>\n");
    }
    if !initial_unknowns.is_empty() {
        x.push_str("    <InitialUnknowns>\n");
        for i in &initial_unknowns {
            let _ = writeln!(x, r#"      <Unknown index="{i}"/>"#);
        }
        x.push_str("    </InitialUnknowns>\n");
    }
    x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    x
}

/// The GUID: a name-based (v5) UUID of the description text, so that any change to the variable
/// table, units, capabilities or version gives a new GUID and an unchanged FMU keeps its GUID.
pub fn guid<M: FmuModel>() -> String {
    guid_str::<M>().to_string()
}

/// [`guid`], computed once per process (it is a constant of the binary; `fmi2Instantiate` checks
/// it, and building the description runs `M::default()` and formats every variable).
pub fn guid_str<M: FmuModel>() -> &'static str {
    M::guid_cell().get_or_init(|| guid_of(&description_template::<M>()))
}

/// [`guid_str`], reading the start values from `default` (= `M::default()`, which the first
/// `fmi2Instantiate` builds for its instance anyway) if it has not been computed yet.
pub(crate) fn guid_str_with<M: FmuModel>(default: &M) -> &'static str {
    M::guid_cell().get_or_init(|| guid_of(&description_template_of(default)))
}

fn guid_of(template: &str) -> String {
    let id = uuid::Uuid::new_v5(&uuid::Uuid::NAMESPACE_URL, template.as_bytes());
    format!("{{{id}}}")
}

/// The complete `modelDescription.xml`.
pub fn model_description<M: FmuModel>() -> String {
    let text = description_template::<M>();
    let id = uuid::Uuid::new_v5(&uuid::Uuid::NAMESPACE_URL, text.as_bytes());
    text.replacen(GUID_PLACEHOLDER, &format!("{{{id}}}"), 1)
}

/// `documentation/index.html`: the model's own text (equations, sources, readings taken) and a
/// table of every variable generated from the same table as the XML.
pub fn documentation_html<M: FmuModel>() -> String {
    let default = M::default();
    let mut h = String::new();
    let id = M::MODEL_IDENTIFIER;
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{id}</title>\n\
         <style>body{{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.4}}\
         table{{border-collapse:collapse}}td,th{{border:1px solid #bbb;padding:2px 6px;text-align:left}}\
         pre{{background:#f4f4f4;padding:0.5em}}</style></head><body>\n<h1>{id}</h1>\n<p>{}</p>\n",
        escape(M::DESCRIPTION)
    );
    h.push_str(M::documentation_html());
    h.push_str("\n<h2>Variables</h2>\n<table><tr><th>name</th><th>value reference</th><th>causality</th><th>variability</th><th>type</th><th>unit</th><th>start</th><th>description</th></tr>\n");
    for (vr, v) in M::variables().iter().enumerate() {
        let start = if v.has_start() {
            match &v.access {
                Access::Real { get, .. } => real(get(&default)),
                Access::Integer { get, .. } => get(&default).to_string(),
                Access::Boolean { get, .. } => get(&default).to_string(),
            }
        } else {
            String::new()
        };
        let _ = writeln!(
            h,
            "<tr><td><code>{}</code></td><td>{vr}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(v.name),
            v.causality.xml_name(),
            v.variability.xml_name(),
            v.base_type(),
            escape(v.unit().unwrap_or("")),
            escape(&start),
            escape(v.description)
        );
    }
    let de = M::DEFAULT_EXPERIMENT;
    let _ = write!(
        h,
        "</table>\n<h2>Capabilities</h2>\n<p>FMI 2.0 co-simulation; variable communication step size; \
         get/set and serialize FMU state (rollback restores every internal state bit-for-bit); \
         many instances per process. Default experiment: {} s to {} s, step {} s. GUID <code>{}</code>.</p>\n\
         <p>Log categories: {}.</p>\n</body></html>\n",
        real(de.start_time),
        real(de.stop_time),
        real(de.step_size),
        guid::<M>(),
        LOG_CATEGORIES
            .iter()
            .map(|(n, _)| format!("<code>{n}</code>"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    h
}
