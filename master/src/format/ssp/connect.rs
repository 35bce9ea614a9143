//! SSD connections flattened: each path from a component's connector, through any number of
//! system connectors, to another component's connector becomes one [`ConnectionSpec`], with the
//! unit conversions and transformations along it composed.

use super::reader::{parse_bool, Connector, Edge, Port, Reader};
use super::xml::Element;
use crate::model_description::ModelDescription;
use crate::system::{ConnectionSpec, ValueMapping, VarRef};
use crate::units::{RadRule, Unit};
use std::collections::HashMap;

/// A connection's transformation so far: `to = gain * from + offset`, and a value mapping.
#[derive(Clone)]
struct Transform {
    gain: f64,
    offset: f64,
    mapping: Option<ValueMapping>,
    /// The reader checked the units (or they were suppressed, or transformed on purpose).
    units_checked: bool,
}

const IDENTITY: Transform = Transform {
    gain: 1.0,
    offset: 0.0,
    mapping: None,
    units_checked: false,
};

/// `second` after `first`; identities are skipped so that one transformation keeps its bits.
fn compose(first: &Transform, second: Transform) -> Result<Transform, String> {
    let (gain, offset) = match ((first.gain, first.offset), (second.gain, second.offset)) {
        ((1.0, 0.0), g) | (g, (1.0, 0.0)) => g,
        ((g1, o1), (g2, o2)) => (g2 * g1, g2 * o1 + o2),
    };
    let mapping = match (&first.mapping, second.mapping) {
        (Some(_), Some(_)) => {
            return Err(
                "two value mappings on one path through system connectors are not supported".into(),
            )
        }
        (m, None) => m.clone(),
        (None, m) => m,
    };
    Ok(Transform {
        gain,
        offset,
        mapping,
        units_checked: first.units_checked || second.units_checked,
    })
}

/// The unit of a Real connector, and whether it came from the FMU (which may omit `rad`).
type PortUnit = Option<(Unit, bool)>;

impl Reader<'_> {
    /// Every SSD connection path from a component to a component.
    pub(super) fn connections(&mut self) -> Vec<ConnectionSpec> {
        let edges = std::mem::take(&mut self.edges);
        let mut from_system: HashMap<&Port, Vec<usize>> = HashMap::new();
        for (k, e) in edges.iter().enumerate() {
            if matches!(e.from, Port::System(..)) {
                from_system.entry(&e.from).or_default().push(k);
            }
        }
        let mut out = Vec::new();
        for (k, e) in edges.iter().enumerate() {
            if let Port::Component(i, c) = &e.from {
                let from = VarRef {
                    instance: self.instances[*i].name.clone(),
                    variable: c.clone(),
                };
                let mut stack = vec![(k, IDENTITY, 0usize)];
                while let Some((k, acc, depth)) = stack.pop() {
                    let edge = &edges[k];
                    let Some(t) = self.hop(edge).and_then(|hop| {
                        compose(&acc, hop)
                            .map_err(|m| self.error(Some(edge.line), m))
                            .ok()
                    }) else {
                        continue;
                    };
                    match &edge.to {
                        Port::Component(j, c) => out.push(self.spec(&from, *j, c, t, e.line)),
                        to @ Port::System(..) if depth < edges.len() => {
                            for &k2 in from_system.get(to).into_iter().flatten() {
                                stack.push((k2, t.clone(), depth + 1));
                            }
                        }
                        Port::System(..) => self.error(
                            Some(edge.line),
                            "the connections through system connectors form a cycle",
                        ),
                    }
                }
            }
        }
        out
    }

    fn spec(&self, from: &VarRef, j: usize, c: &str, t: Transform, line: usize) -> ConnectionSpec {
        let plain = t.gain == 1.0 && t.offset == 0.0 && t.mapping.is_none();
        ConnectionSpec {
            from: from.clone(),
            to: VarRef {
                instance: self.instances[j].name.clone(),
                variable: c.to_string(),
            },
            gain: t.gain,
            offset: t.offset,
            line: Some(line),
            either_direction: plain,
            convert: t.units_checked,
            // SSP 1.0 has no sum: a second connection into one input is an error
            sum: false,
            mapping: t.mapping,
        }
    }

    /// One connection's own transformation: the unit conversion between its ends, then its
    /// `LinearTransformation`; or its value mapping.
    fn hop(&mut self, e: &Edge) -> Option<Transform> {
        let fc = self.connectors[&e.from].clone();
        let tc = self.connectors[&e.to].clone();
        let mut t = IDENTITY;
        let real = |c: &Connector| matches!(c.var_type.as_deref(), None | Some("Real"));
        if e.suppress_units {
            t.units_checked = true;
        } else if real(&fc) && real(&tc) && e.mapping.is_none() {
            let fu = self.port_unit(&e.from, &fc, e.line);
            let tu = self.port_unit(&e.to, &tc, e.line);
            if let (Some((fu, f_fmu)), Some((tu, t_fmu))) = (fu, tu) {
                t.units_checked = true;
                let rule = RadRule::Omittable {
                    from: f_fmu,
                    to: t_fmu,
                };
                let Some(c) = fu.conversion_to(&tu, rule) else {
                    let names = (self.port_name(&e.from), self.port_name(&e.to));
                    self.error(
                        Some(e.line),
                        format!(
                            "<Connection> {} -> {}: unit mismatch without conversion: {} is in {} but {} is in {} (set suppressUnitConversion=\"true\" with a LinearTransformation to connect them anyway)",
                            names.0, names.1, names.0, describe(&fc, &fu), names.1, describe(&tc, &tu)
                        ),
                    );
                    return None;
                };
                if fu.factor != tu.factor || fu.offset != tu.offset {
                    (t.gain, t.offset) = c.gain_offset();
                }
            }
        }
        if let Some((f, o)) = e.linear {
            t.units_checked = true;
            (t.gain, t.offset) = match (t.gain, t.offset) {
                (1.0, 0.0) => (f, o),
                (g, off) => (f * g, f * off + o),
            };
        }
        if let Some(m) = &e.mapping {
            t.mapping = Some(self.mapping(m, &fc, &tc)?);
        }
        Some(t)
    }

    /// `instance.connector` or `system/path.connector` for messages.
    fn port_name(&self, p: &Port) -> String {
        match p {
            Port::Component(i, c) => format!("{}.{c}", self.instances[*i].name),
            Port::System(s, c) if s.is_empty() => format!("(root system).{c}"),
            Port::System(s, c) => format!("{s}.{c}"),
        }
    }

    /// A Real connector's unit: its own `unit` (a `Unit` of the SSD, or a built-in name), or
    /// for a component's connector without one the FMU variable's declared unit.
    fn port_unit(&mut self, p: &Port, c: &Connector, line: usize) -> PortUnit {
        if let Some(name) = &c.unit {
            if let Some(u) = self.units.get(name) {
                return Some((*u, false));
            }
            return match Unit::parse(name) {
                Ok(u) => Some((u, false)),
                Err(_) => {
                    self.error(
                        Some(line),
                        format!(
                            "connector {}: unit \"{name}\" is not defined in the SSD's <Units>",
                            self.port_name(p)
                        ),
                    );
                    None
                }
            };
        }
        let Port::Component(i, var) = p else {
            return None;
        };
        let md = self.model_description(*i)?;
        let sv = md
            .model_variables
            .variables
            .iter()
            .find(|v| &v.name == var)?;
        let name = md.real_unit(sv)?;
        crate::units::declared(md, name).ok()
    }

    /// The model description of instance `i` (each FMU read once, when a unit is needed).
    pub(super) fn model_description(&mut self, i: usize) -> Option<&ModelDescription> {
        let fmu = &self.instances[i].fmu;
        self.mds
            .entry(fmu.clone())
            .or_insert_with(|| {
                crate::fmu::UnpackedFmu::open(fmu)
                    .ok()
                    .map(|u| u.model_description)
            })
            .as_ref()
    }

    /// A mapping transformation as a [`ValueMapping`] (enumeration items resolved by name
    /// through the connectors' `Enumeration` types).
    fn mapping(&mut self, m: &Element, fc: &Connector, tc: &Connector) -> Option<ValueMapping> {
        let boolean = m.name == "BooleanMappingTransformation";
        let mut entries = Vec::new();
        for entry in m.children_named("MapEntry") {
            let (s, t) = (entry.attr("source"), entry.attr("target"));
            let pair = match (m.name.as_str(), s, t) {
                (_, Some(s), Some(t)) if boolean => parse_bool(s).zip(parse_bool(t)),
                ("IntegerMappingTransformation", Some(s), Some(t)) => s
                    .trim()
                    .parse::<i32>()
                    .ok()
                    .zip(t.trim().parse::<i32>().ok()),
                (_, Some(s), Some(t)) => {
                    let s = self.item(fc, s, entry.line)?;
                    let t = self.item(tc, t, entry.line)?;
                    Some((s, t))
                }
                _ => None,
            };
            match pair {
                Some(p) => entries.push(p),
                None => {
                    self.error(
                        Some(entry.line),
                        format!(
                            "<{}>: a <MapEntry> needs a source and a target of its type",
                            m.name
                        ),
                    );
                    return None;
                }
            }
        }
        ValueMapping::new(boolean, entries)
            .map_err(|msg| self.error(Some(m.line), format!("<{}>: {msg}", m.name)))
            .ok()
    }

    /// The value of an enumeration item of the connector's `Enumeration` type.
    fn item(&mut self, c: &Connector, item: &str, line: usize) -> Option<i32> {
        let Some(ty) = &c.enumeration else {
            self.error(
                Some(line),
                format!("<MapEntry> \"{item}\": an EnumerationMappingTransformation needs connectors typed <ssc:Enumeration name=\"...\"> naming an <Enumeration> of the SSD"),
            );
            return None;
        };
        let value = self
            .enums
            .get(ty)
            .and_then(|items| items.iter().find(|(n, _)| n == item))
            .map(|(_, v)| *v);
        if value.is_none() {
            self.error(
                Some(line),
                format!("<MapEntry> \"{item}\": no such item in enumeration '{ty}'"),
            );
        }
        value
    }
}

/// `km/h (m.s-1)`: a unit's name where known and its SI exponents.
fn describe(c: &Connector, u: &Unit) -> String {
    match &c.unit {
        Some(n) => format!("{n} ({})", u.dimension()),
        None => format!("the FMU's unit ({})", u.dimension()),
    }
}
