//! The variable table: the single source of truth from which the C API dispatches get/set and
//! from which `modelDescription.xml` and the HTML documentation are generated.
//!
//! A variable's value reference is its index in the table, so value references cannot drift
//! between the XML and the code. The `initial` attribute and the start values are derived:
//! parameters are `initial="exact"` with the start taken from `M::default()` through the getter,
//! inputs carry a start value and no `initial`, outputs and locals are `initial="calculated"`
//! without a start (FMI 2.0 standard, section 2.2.7, table of legal combinations).

use std::fmt;

pub use fmi2::{Causality, Initial, Variability};

/// Typed accessors of a variable into the model `M`.
pub enum Access<M> {
    Real {
        get: fn(&M) -> f64,
        set: Option<fn(&mut M, f64)>,
        unit: Option<&'static str>,
        min: Option<f64>,
        max: Option<f64>,
    },
    Integer {
        get: fn(&M) -> i32,
        set: Option<fn(&mut M, i32)>,
        min: Option<i32>,
        max: Option<i32>,
    },
    Boolean {
        get: fn(&M) -> bool,
        set: Option<fn(&mut M, bool)>,
    },
}

/// The FMI base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BaseType {
    Real,
    Integer,
    Boolean,
}

impl fmt::Display for BaseType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            BaseType::Real => "Real",
            BaseType::Integer => "Integer",
            BaseType::Boolean => "Boolean",
        })
    }
}

/// One scalar variable.
pub struct Variable<M> {
    pub name: &'static str,
    pub causality: Causality,
    pub variability: Variability,
    pub description: &'static str,
    pub access: Access<M>,
    /// For outputs: the inputs this output depends on directly (ModelStructure `dependencies`).
    /// `None`: not declared (all inputs, unless the model says `DIRECT_FEEDTHROUGH = false`).
    pub dependencies: Option<&'static [&'static str]>,
    /// For outputs: the parameter that scales this output (0 makes it 0), written as a
    /// `shipsim` vendor annotation so that a master can warn about a connection that carries
    /// only zeros.
    pub gate: Option<&'static str>,
}

impl<M> Variable<M> {
    /// Declares the parameter that scales this output (see [`Variable::gate`]).
    pub const fn gated_by(mut self, parameter: &'static str) -> Self {
        self.gate = Some(parameter);
        self
    }

    /// Declares the inputs an output depends on directly (`&[]`: the state only).
    pub const fn depends_on(mut self, inputs: &'static [&'static str]) -> Self {
        self.dependencies = Some(inputs);
        self
    }

    /// An inclusive range `[lo, hi]` of a Real variable (declared in the XML, enforced on set).
    pub const fn range(self, lo: f64, hi: f64) -> Self {
        self.min(lo).max(hi)
    }

    /// A lower bound of a Real variable (declared in the XML, enforced on set).
    pub const fn min(mut self, lo: f64) -> Self {
        if let Access::Real { ref mut min, .. } = self.access {
            *min = Some(lo);
        }
        self
    }

    /// An upper bound of a Real variable (declared in the XML, enforced on set).
    pub const fn max(mut self, hi: f64) -> Self {
        if let Access::Real { ref mut max, .. } = self.access {
            *max = Some(hi);
        }
        self
    }

    #[inline]
    pub fn base_type(&self) -> BaseType {
        match self.access {
            Access::Real { .. } => BaseType::Real,
            Access::Integer { .. } => BaseType::Integer,
            Access::Boolean { .. } => BaseType::Boolean,
        }
    }

    /// The derived `initial` attribute (None: not written).
    pub fn initial(&self) -> Option<Initial> {
        match self.causality {
            Causality::Parameter => Some(Initial::Exact),
            Causality::Input | Causality::Independent => None,
            Causality::Output | Causality::Local | Causality::CalculatedParameter => {
                Some(Initial::Calculated)
            }
        }
    }

    /// Whether the variable carries a start value in the XML.
    pub fn has_start(&self) -> bool {
        matches!(self.causality, Causality::Parameter | Causality::Input)
    }

    /// Whether fmi2SetXXX may write it at all.
    #[inline]
    pub fn settable(&self) -> bool {
        matches!(self.causality, Causality::Parameter | Causality::Input)
    }

    pub fn unit(&self) -> Option<&'static str> {
        match self.access {
            Access::Real { unit, .. } => unit,
            _ => None,
        }
    }
}

/// A unit of the registry: its SI base-unit exponents (kg, m, s, A, K, mol, cd, rad), factor and
/// display units (name, factor) for `<UnitDefinitions>`.
pub struct UnitDef {
    pub name: &'static str,
    pub exponents: [i8; 8],
    pub factor: f64,
    pub display: &'static [(&'static str, f64)],
}

const BASE_NAMES: [&str; 8] = ["kg", "m", "s", "A", "K", "mol", "cd", "rad"];
const DEG_PER_RAD: f64 = 180.0 / std::f64::consts::PI;

/// Units the FMUs may use. SI on every interface; degrees and knots only as display units.
pub const UNITS: &[UnitDef] = &[
    UnitDef {
        name: "rad",
        exponents: [0, 0, 0, 0, 0, 0, 0, 1],
        factor: 1.0,
        display: &[("deg", DEG_PER_RAD)],
    },
    UnitDef {
        name: "rad/s",
        exponents: [0, 0, -1, 0, 0, 0, 0, 1],
        factor: 1.0,
        display: &[("deg/s", DEG_PER_RAD)],
    },
    UnitDef {
        name: "rad/s2",
        exponents: [0, 0, -2, 0, 0, 0, 0, 1],
        factor: 1.0,
        display: &[("deg/s2", DEG_PER_RAD)],
    },
    UnitDef {
        name: "s",
        exponents: [0, 0, 1, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[],
    },
    UnitDef {
        name: "1/s",
        exponents: [0, 0, -1, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[],
    },
    UnitDef {
        name: "m",
        exponents: [0, 1, 0, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[],
    },
    UnitDef {
        name: "m/s",
        exponents: [0, 1, -1, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[("kn", 3600.0 / 1852.0)],
    },
    UnitDef {
        name: "m/s2",
        exponents: [0, 1, -2, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[],
    },
    UnitDef {
        name: "m2",
        exponents: [0, 2, 0, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[],
    },
    UnitDef {
        name: "kg",
        exponents: [1, 0, 0, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[],
    },
    UnitDef {
        name: "kg/m3",
        exponents: [1, -3, 0, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[],
    },
    UnitDef {
        // wind moment coefficient: moment per dynamic pressure-like term ([Klugt1987, eqs. (2.19)-(2.20)])
        name: "N.m.s2/m2",
        exponents: [1, 0, 0, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[],
    },
    UnitDef {
        name: "N",
        exponents: [1, 1, -2, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[("kN", 1e-3)],
    },
    UnitDef {
        name: "N.m",
        exponents: [1, 2, -2, 0, 0, 0, 0, 0],
        factor: 1.0,
        display: &[("kN.m", 1e-3)],
    },
    UnitDef {
        name: "rpm",
        exponents: [0, 0, -1, 0, 0, 0, 0, 0],
        factor: 1.0 / 60.0,
        display: &[],
    },
];

/// Looks a unit up in [`UNITS`].
pub fn unit_def(name: &str) -> Option<&'static UnitDef> {
    UNITS.iter().find(|u| u.name == name)
}

/// Names of the SI base units in the order of [`UnitDef::exponents`].
pub fn base_unit_names() -> &'static [&'static str; 8] {
    &BASE_NAMES
}

/// Largest Integer range whose every value [`check_table`] writes and reads back.
const ENUMERABLE: i64 = 64;

/// For a settable Integer with a small declared range (an enumeration or a code): the first value
/// of the range that, written into a default model, does not read back. `fmi2SetInteger` accepts
/// every value of the range, so such a value would be accepted and silently lost.
fn unwritable_code<M: Clone>(default: &M, access: &Access<M>) -> Option<i32> {
    let Access::Integer {
        get,
        set: Some(set),
        min: Some(lo),
        max: Some(hi),
    } = access
    else {
        return None;
    };
    if i64::from(*hi) - i64::from(*lo) >= ENUMERABLE {
        return None;
    }
    (*lo..=*hi).find(|&code| {
        let mut m = default.clone();
        set(&mut m, code);
        get(&m) != code
    })
}

/// Checks a variable table for the rules the XML and the C API rely on: unique legal names,
/// settable causalities have setters, units are in the registry, legal
/// causality/variability combinations, start values finite and in range, every code of a small
/// Integer range writable. Returns every problem found.
pub fn check_table<M: Default + Clone>(vars: &[Variable<M>]) -> Result<(), Vec<String>> {
    let mut problems = Vec::new();
    let default = M::default();
    for (i, v) in vars.iter().enumerate() {
        let legal_name = !v.name.is_empty()
            && v.name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.')
            && !v.name.starts_with(|c: char| c.is_ascii_digit());
        if !legal_name {
            problems.push(format!("variable {i}: illegal name {:?}", v.name));
        }
        if vars[..i].iter().any(|w| w.name == v.name) {
            problems.push(format!("variable {}: duplicate name", v.name));
        }
        let has_setter = match &v.access {
            Access::Real { set, .. } => set.is_some(),
            Access::Integer { set, .. } => set.is_some(),
            Access::Boolean { set, .. } => set.is_some(),
        };
        if v.settable() != has_setter {
            problems.push(format!(
                "variable {}: causality {:?} {} a setter",
                v.name,
                v.causality,
                if has_setter { "must not have" } else { "needs" }
            ));
        }
        if let Some(u) = v.unit() {
            if unit_def(u).is_none() {
                problems.push(format!("variable {}: unit {u:?} is not in UNITS", v.name));
            }
        }
        let legal = match v.causality {
            Causality::Parameter | Causality::CalculatedParameter => {
                matches!(v.variability, Variability::Fixed | Variability::Tunable)
            }
            // The export layer has no independent variable (co-simulation time is the master's).
            Causality::Independent => false,
            Causality::Input | Causality::Output | Causality::Local => {
                matches!(
                    v.variability,
                    Variability::Discrete | Variability::Continuous
                )
            }
        };
        if !legal {
            problems.push(format!(
                "variable {}: causality {:?} with variability {:?} is illegal",
                v.name, v.causality, v.variability
            ));
        }
        if let Some(deps) = v.dependencies {
            if v.causality != Causality::Output {
                problems.push(format!(
                    "variable {}: only outputs declare dependencies",
                    v.name
                ));
            }
            for d in deps {
                if !vars
                    .iter()
                    .any(|w| w.name == *d && w.causality == Causality::Input)
                {
                    problems.push(format!(
                        "variable {}: dependency {d:?} is not an input of this model",
                        v.name
                    ));
                }
            }
        }
        if v.variability == Variability::Continuous && v.base_type() != BaseType::Real {
            problems.push(format!(
                "variable {}: only Real variables may be continuous",
                v.name
            ));
        }
        if v.has_start() {
            if let Access::Real { get, min, max, .. } = &v.access {
                let s = get(&default);
                if !s.is_finite() {
                    problems.push(format!(
                        "variable {}: start value {s} is not finite",
                        v.name
                    ));
                }
                if min.is_some_and(|m| s < m) || max.is_some_and(|m| s > m) {
                    problems.push(format!(
                        "variable {}: start value {s} outside range",
                        v.name
                    ));
                }
            }
        }
        if let Some(code) = unwritable_code(&default, &v.access) {
            problems.push(format!(
                "variable {}: {code} lies in the declared range but does not read back \
                 (an enumeration with a gap, or a setter that drops it)",
                v.name
            ));
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems)
    }
}
