//! Connections: both ends exist, an output drives an input, the types agree, gain and offset
//! only on Real, the units are compatible (FMI 2.0 section 2.2.2), no input is driven twice
//! unless every connection into it is a term of a sum (`sum = true`, Real only); and the
//! inputs no connection drives.

use super::Checker;
use crate::error::Error;
use crate::model_description::{Causality, ModelDescription, ScalarVariable, VarType};
use crate::system::{ConnectionSpec, Format, PlanConnection};
use crate::units::{RadRule, Unit, RAD};
use std::borrow::Cow;
use std::collections::{HashMap, HashSet};

/// Inputs driven by a connection: (instance, variable index) -> (connection name, line).
pub(super) type Driven = HashMap<(usize, usize), (String, Option<usize>)>;

/// Inputs whose first connection is a term of a sum (`sum = true`).
type Summed = HashSet<(usize, usize)>;

/// A connection with both ends resolved, in output -> input direction.
struct Ends<'c> {
    /// As written, or turned around (an owned copy) for an input-first OSP VariableConnection.
    spec: Cow<'c, ConnectionSpec>,
    /// "from -> to" as written (after an OSP VariableConnection is turned around).
    name: String,
    from: (usize, usize),
    to: (usize, usize),
}

/// A Real unit of a model description as the unit module has it, if it is defined with a
/// `BaseUnit`.
fn defined_unit(md: &ModelDescription, unit: &str) -> Option<Unit> {
    md.unit(unit).and_then(Unit::from_definition)
}

impl<'a> Checker<'a> {
    fn variable(&self, (i, v): (usize, usize)) -> &'a ScalarVariable {
        &self.mds[i].model_variables.variables[v]
    }

    /// Every connection checked and resolved, and the inputs they drive.
    pub(super) fn connections(&mut self) -> (Vec<PlanConnection>, Driven) {
        let mut connections = Vec::new();
        let mut driven = Driven::new();
        let mut summed = Summed::new();
        for spec in &self.sys.connections {
            let Some(ends) = self.resolve_ends(spec) else {
                continue;
            };
            let mut ok = self.check_causality(&ends);
            ok &= self.check_types(&ends);
            ok &= self.check_units(&ends);
            ok &= self.check_driven_once(&ends, &mut driven, &mut summed);
            if ok {
                connections.push(self.plan_connection(ends));
            }
        }
        (connections, driven)
    }

    /// Resolves both ends; an OSP VariableConnection written input-first is turned around.
    fn resolve_ends<'c>(&mut self, c: &'c ConnectionSpec) -> Option<Ends<'c>> {
        let from = self.resolve(&c.from, c.line, "connection source");
        let from = from.map_err(|e| self.errors.push(e)).ok()?;
        let to = self.resolve(&c.to, c.line, "connection target");
        let to = to.map_err(|e| self.errors.push(e)).ok()?;
        let turn = c.either_direction
            && self.variable(from).causality == Causality::Input
            && self.variable(to).causality == Causality::Output;
        let (spec, from, to) = if turn {
            let swapped = ConnectionSpec {
                from: c.to.clone(),
                to: c.from.clone(),
                ..c.clone()
            };
            (Cow::Owned(swapped), to, from)
        } else {
            (Cow::Borrowed(c), from, to)
        };
        Some(Ends {
            name: format!("{} -> {}", spec.from, spec.to),
            spec,
            from,
            to,
        })
    }

    /// The source is an output (or calculated parameter), the target an input.
    fn check_causality(&mut self, c: &Ends) -> bool {
        let (fsv, tsv) = (self.variable(c.from), self.variable(c.to));
        let (name, line) = (&c.name, c.spec.line);
        let mut ok = true;
        if !matches!(
            fsv.causality,
            Causality::Output | Causality::CalculatedParameter
        ) {
            let e = self.err(line, format!(
                "connection {name}: causality mismatch: source '{}' is {}, it must be an output", c.spec.from, fsv.causality));
            self.errors.push(e);
            ok = false;
        }
        if tsv.causality != Causality::Input {
            let e = self.err(
                line,
                format!(
                    "connection {name}: causality mismatch: target '{}' is {}, it must be an input",
                    c.spec.to, tsv.causality
                ),
            );
            self.errors.push(e);
            ok = false;
        }
        ok
    }

    /// Connectable types, no String connections, gain/offset only on Real; a connection back
    /// into the same instance is a warning.
    fn check_types(&mut self, c: &Ends) -> bool {
        let (ft, tt) = self.types(c);
        let (name, line, spec) = (&c.name, c.spec.line, &c.spec);
        let mut errors: Vec<Error> = Vec::new();
        if !ft.connectable_with(tt) {
            errors.push(self.err(
                line,
                format!(
                    "connection {name}: type mismatch: '{}' is {ft} but '{}' is {tt}",
                    spec.from, spec.to
                ),
            ));
        } else if ft == VarType::String {
            errors.push(self.err(
                line,
                format!("connection {name}: String connections are not supported"),
            ));
        }
        if ft != VarType::Real && spec.sum {
            errors.push(self.err(
                line,
                format!(
                    "connection {name}: sum = true adds Real inputs only ('{}' is {ft})",
                    spec.to
                ),
            ));
        }
        if ft != VarType::Real && (spec.gain != 1.0 || spec.offset != 0.0) {
            errors.push(self.err(
                line,
                format!(
                    "connection {name}: gain/offset apply only to Real variables ('{}' is {ft})",
                    spec.from
                ),
            ));
        }
        if let Some(m) = &spec.mapping {
            let boolean = matches!(ft, VarType::Boolean);
            if m.boolean != boolean
                || !matches!(
                    ft,
                    VarType::Integer | VarType::Enumeration | VarType::Boolean
                )
            {
                errors.push(self.err(
                    line,
                    format!(
                        "connection {name}: the value mapping does not apply to '{}' ({ft})",
                        spec.from
                    ),
                ));
            }
        }
        if c.to.0 == c.from.0 {
            self.warnings.push(format!(
                "{}: connection {name} feeds an instance back to itself",
                self.loc(line)
            ));
        }
        let ok = errors.is_empty();
        self.errors.extend(errors);
        ok
    }

    fn types(&self, c: &Ends) -> (VarType, VarType) {
        let ft = self.variable(c.from).var_type().unwrap();
        (ft, self.variable(c.to).var_type().unwrap())
    }

    /// Units (FMI 2.0 section 2.2.2: BaseUnit exponents must agree). A conversion factor or
    /// offset without gain/offset is a warning that gives them; `convert = true` skips the check.
    /// Exponents that differ are an error when [`System::strict_units`](crate::system::System)
    /// is set (the native TOML) and a warning otherwise (OSP files, which libcosim runs without
    /// a unit check). Exponents that differ only in `rad` are a warning either way: the SI
    /// defines the radian as m/m, of dimension one, FMI 2.0 lists `rad` as an exponent of its
    /// own (sec. 2.2.2, `BaseUnit`), and FMUs declare angles with it (`rad`, rad = 1) and
    /// without it (PythonFMU's `radian`, rad = 0).
    fn check_units(&mut self, c: &Ends) -> bool {
        let (ft, tt) = self.types(c);
        if ft != VarType::Real || tt != VarType::Real || c.spec.convert {
            return true;
        }
        let (fmd, tmd) = (self.mds[c.from.0], self.mds[c.to.0]);
        let (fsv, tsv) = (self.variable(c.from), self.variable(c.to));
        let (Some(fu), Some(tu)) = (fmd.real_unit(fsv), tmd.real_unit(tsv)) else {
            return true;
        };
        if fu == tu {
            return true;
        }
        let (name, line, spec) = (&c.name, c.spec.line, &c.spec);
        match (defined_unit(fmd, fu), defined_unit(tmd, tu)) {
            (Some(f), Some(t)) => match f.conversion_to(&t, RadRule::Strict) {
                None => {
                    // exponents (kg, m, s, A, K, mol, cd, rad) that differ in rad only?
                    let only_rad = f.exponents[..RAD] == t.exponents[..RAD];
                    return self.unit_mismatch(c, fu, tu, only_rad);
                }
                Some(conversion)
                    if (f.factor != t.factor || f.offset != t.offset)
                        && spec.gain == 1.0
                        && spec.offset == 0.0 =>
                {
                    let (g, o) = conversion.gain_offset();
                    self.warnings.push(format!(
                        "{}: connection {name} goes from {fu} to {tu} without conversion; set gain = {g} and offset = {o}",
                        self.loc(line)));
                }
                Some(_) => {}
            },
            _ => self.warnings.push(format!(
                "{}: connection {name} connects unit '{fu}' to unit '{tu}' (not comparable: no BaseUnit)", self.loc(line))),
        }
        true
    }

    /// BaseUnit exponents that differ: an error in strict mode unless only `rad` differs, else a
    /// warning that says how the other mode would treat it. Returns whether the connection stays.
    fn unit_mismatch(&mut self, c: &Ends, fu: &str, tu: &str, only_rad: bool) -> bool {
        let (name, line, spec) = (&c.name, c.spec.line, &c.spec);
        let what = format!(
            "connection {name}: incompatible units: '{}' is in {fu} but '{}' is in {tu}",
            spec.from, spec.to
        );
        if only_rad {
            self.warnings.push(format!(
                "{}: {what}, which differ only in the rad exponent (an angle declared with and without rad); connected as is",
                self.loc(line)
            ));
            true
        } else if self.sys.strict_units {
            // `convert` is a key of the native TOML; an OSP file has no such attribute.
            let toml = self.sys.source.extension().is_some_and(|e| e == "toml");
            let hint = match toml {
                true => "; if the gain converts between these quantities, set convert = true",
                false => "",
            };
            let e = self.err(line, format!("{what}{hint}"));
            self.errors.push(e);
            false
        } else {
            self.warnings.push(format!(
                "{}: {what}; connected as is, as libcosim does (--strict-units makes this an error)",
                self.loc(line)
            ));
            true
        }
    }

    /// An input is driven by one connection at most, unless every connection into it is a
    /// term of a sum (`sum = true`): then it is driven by their sum.
    fn check_driven_once(&mut self, c: &Ends, driven: &mut Driven, summed: &mut Summed) -> bool {
        let Some((prev, pline)) = driven.get(&c.to) else {
            driven.insert(c.to, (c.name.clone(), c.spec.line));
            if c.spec.sum {
                summed.insert(c.to);
            }
            return true;
        };
        if c.spec.sum && summed.contains(&c.to) {
            return true;
        }
        let at = |l: Option<usize>| l.map(|l| format!(" (line {l})")).unwrap_or_default();
        let hint = if self.sys.format == Format::Osp {
            "; to add them, connect them through a Sum function"
        } else {
            "; to add them, set sum = true on every connection into it"
        };
        let e = self.err(
            c.spec.line,
            format!(
                "input '{}' is driven twice: by {} and by {prev}{}{hint}",
                c.spec.to,
                c.name,
                at(*pline)
            ),
        );
        self.errors.push(e);
        false
    }

    fn plan_connection(&self, c: Ends) -> PlanConnection {
        let (ft, _) = self.types(&c);
        PlanConnection {
            from_instance: c.from.0,
            from_vr: self.variable(c.from).value_reference,
            to_instance: c.to.0,
            to_vr: self.variable(c.to).value_reference,
            var_type: if ft == VarType::Enumeration {
                VarType::Integer
            } else {
                ft
            },
            gain: c.spec.gain,
            offset: c.spec.offset,
            sum: c.spec.sum,
            mapping: c.spec.mapping.clone(),
            name: c.name,
        }
    }

    /// Inputs that no connection drives and that have neither a start value in the file nor
    /// one in the FMU are a warning.
    pub(super) fn unconnected_inputs(&mut self, driven: &Driven) {
        let sys = self.sys;
        for (i, inst) in sys.instances.iter().enumerate() {
            for (vi, v) in self.mds[i].model_variables.variables.iter().enumerate() {
                if v.causality == Causality::Input && !driven.contains_key(&(i, vi)) {
                    let set = inst.values.iter().any(|x| x.variable == v.name);
                    if !set && !v.has_start() {
                        self.warnings.push(format!(
                            "{}: input '{}.{}' is not connected and has no start value",
                            self.loc(inst.line),
                            inst.name,
                            v.name
                        ));
                    }
                }
            }
        }
    }
}
