//! What the parts of the SSD reader share: one reading's state ([`Reader`], whose methods are
//! split by concern between `read.rs` (systems, components, time), `connect.rs` (connections,
//! units, mappings) and `params.rs` (parameter sets), the connectors and connections as
//! written, and the attribute parsers all three use.

use super::xml::Element;
use crate::error::Error;
use crate::model_description::ModelDescription;
use crate::system::InstanceSpec;
use crate::units::Unit;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Joins the levels of a nested component's instance name.
pub const SEP: char = '/';

/// A connector: on a component (by instance index) or on a system (by its path).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(super) enum Port {
    Component(usize, String),
    System(String, String),
}

/// What a connector declares: its type element, its unit, its enumeration type.
#[derive(Debug, Clone, Default)]
pub(super) struct Connector {
    /// `Real`, `Integer`, `Boolean`, `String`, `Enumeration`; None when the connector gives no type.
    pub var_type: Option<String>,
    pub unit: Option<String>,
    pub enumeration: Option<String>,
}

/// One SSD connection, as written.
pub(super) struct Edge {
    pub from: Port,
    pub to: Port,
    pub line: usize,
    pub linear: Option<(f64, f64)>,
    pub mapping: Option<Element>,
    pub suppress_units: bool,
}

/// One reading of an SSD.
pub(super) struct Reader<'a> {
    /// The SSD as users name it (inside an archive: `archive.ssp/SystemStructure.ssd`).
    pub shown: PathBuf,
    /// The directory relative URIs resolve against.
    pub dir: &'a Path,
    /// The archive it came from (shown in the names of its other files).
    pub archive: Option<&'a Path>,
    pub units: HashMap<String, Unit>,
    pub enums: HashMap<String, Vec<(String, i32)>>,
    pub errors: Vec<Error>,
    pub instances: Vec<InstanceSpec>,
    pub connectors: HashMap<Port, Connector>,
    pub edges: Vec<Edge>,
    /// Model descriptions by FMU file, read when a unit is needed.
    pub mds: HashMap<PathBuf, Option<ModelDescription>>,
    pub step_hints: Vec<Option<f64>>,
    /// System paths ("" is the root).
    pub systems: std::collections::HashSet<String>,
    /// Fixed steps of nested systems' OMSimulator masters (step, line).
    pub nested_steps: Vec<(f64, usize)>,
}

/// A finite number, or None.
pub(super) fn parse_f64(s: &str) -> Option<f64> {
    s.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// `true`/`false`/`1`/`0` (xs:boolean) as 1/0.
pub(super) fn parse_bool(s: &str) -> Option<i32> {
    match s.trim() {
        "true" | "1" => Some(1),
        "false" | "0" => Some(0),
        _ => None,
    }
}

/// A `BaseUnit` element as a [`Unit`].
pub(super) fn base_unit(b: &Element) -> std::result::Result<Unit, String> {
    let mut exponents = [0i32; 8];
    for (k, name) in crate::units::BASE_UNITS.iter().enumerate() {
        if let Some(v) = b.attr(name) {
            let x = v
                .trim()
                .parse::<i32>()
                .ok()
                .filter(|x| x.unsigned_abs() <= 64)
                .ok_or_else(|| {
                    format!(
                        "<BaseUnit {name}=\"{v}\">: not an integer exponent (at most 64 in size)"
                    )
                })?;
            exponents[k] = x;
        }
    }
    let num = |k: &str, default: f64| -> std::result::Result<f64, String> {
        b.attr(k).map_or(Ok(default), |v| {
            parse_f64(v).ok_or_else(|| format!("<BaseUnit {k}=\"{v}\">: not a finite number"))
        })
    };
    let factor = num("factor", 1.0)?;
    if factor == 0.0 {
        return Err("<BaseUnit factor=\"0\">: the factor must not be 0".into());
    }
    Ok(Unit {
        exponents,
        factor,
        offset: num("offset", 0.0)?,
    })
}
