//! The connections of an `OspSystemStructure.xml`, resolved into [`ConnectionSpec`]s the way
//! libcosim resolves them (`src/cosim/osp_config_parser.cpp`, `load_osp_config`):
//!
//! - `VariableConnection`: one connection, its direction from the variables' causalities.
//! - `VariableGroupConnection`: the two groups' nested groups pairwise by position, then their
//!   variables pairwise by position, each a `VariableConnection` (groups from the models'
//!   `OspModelDescription.xml`, [`super::variable_groups`]).
//! - `LinearTransformation` (`in`, `out`): a connection with gain `factor` and `offset`.
//! - `Sum` (`in[0]` ... `in[inputCount-1]`, `out`): one connection per input into the `out`
//!   variable, each a term of the summed input ([`ConnectionSpec::sum`]), in index order.
//! - `VectorSum` (signal groups `in[0]` ... and `out`, through `SignalGroupConnection`s): for
//!   each component j, the j-th variables of the input groups summed into the j-th variable of
//!   the output group, inputs in index order.
//!
//! libcosim adds a sum's inputs in index order from `in[0]` (`vector_sum_function::calculate`);
//! the master adds a summed input's terms in the order of the connections
//! ([`crate::run::exchange`]), which is that order here.
//!
//! Connections come out in this order: variable connections and variable group connections as
//! they come, then the functions' connections, function by function in name order
//! (LinearTransformation, then Sum, then VectorSum).

use super::variable_groups::{Group, Groups};
use super::{Connection, Endpoint, Functions, Reader, SignalEndpoint};
use crate::error::did_you_mean;
use crate::system::{ConnectionSpec, VarRef};
use std::collections::{BTreeMap, HashMap};

/// A function of the file, by kind.
pub(super) enum Function {
    Linear { factor: f64, offset: f64 },
    Sum { inputs: u32 },
    VectorSum { inputs: u32, dimension: u32 },
}

impl Function {
    fn kind(&self) -> &'static str {
        match self {
            Function::Linear { .. } => "LinearTransformation",
            Function::Sum { .. } => "Sum",
            Function::VectorSum { .. } => "VectorSum",
        }
    }

    /// Whether `signal` is one of the function's signals (`in[i]`, `out`; LT: `in`, `out`).
    fn has_signal(&self, signal: &str) -> bool {
        let indexed = |n: u32| {
            signal
                .strip_prefix("in[")
                .and_then(|r| r.strip_suffix(']'))
                .and_then(|i| i.parse::<u32>().ok())
                .is_some_and(|i| i < n)
        };
        signal == "out"
            || match self {
                Function::Linear { .. } => signal == "in",
                Function::Sum { inputs } | Function::VectorSum { inputs, .. } => indexed(*inputs),
            }
    }

    fn signals(&self) -> String {
        match self {
            Function::Linear { .. } => "'in' and 'out'".into(),
            Function::Sum { inputs } | Function::VectorSum { inputs, .. } => {
                format!("'in[0]' to 'in[{}]' and 'out'", inputs.saturating_sub(1))
            }
        }
    }
}

/// The variables (or variable groups) connected to each function signal, in file order.
type Signals = HashMap<(String, String), Vec<Endpoint>>;

fn var_ref(e: &Endpoint) -> VarRef {
    VarRef {
        instance: e.simulator.clone(),
        variable: e.name.clone(),
    }
}

/// A connection from `from` to `to` with gain 1 and offset 0.
fn plain(from: VarRef, to: VarRef, line: Option<usize>) -> ConnectionSpec {
    ConnectionSpec {
        from,
        to,
        gain: 1.0,
        offset: 0.0,
        line,
        either_direction: false,
        convert: false,
        sum: false,
        mapping: None,
    }
}

impl Reader<'_> {
    /// The functions by name (BTreeMap: name order); a name used twice is an error.
    pub(super) fn functions(&mut self, f: Functions) -> BTreeMap<String, Function> {
        let linear = f.linear.into_iter().map(|l| {
            let factor = l.factor.unwrap_or(1.0);
            let offset = l.offset.unwrap_or(0.0);
            (l.name, Function::Linear { factor, offset })
        });
        let sums = f.sum.into_iter().map(|s| {
            let inputs = s.input_count;
            (s.name, Function::Sum { inputs })
        });
        let vector_sums = f.vector_sum.into_iter().map(|v| {
            let (inputs, dimension) = (v.input_count, v.dimension);
            (v.name, Function::VectorSum { inputs, dimension })
        });
        let mut out = BTreeMap::new();
        for (name, function) in linear.chain(sums).chain(vector_sums) {
            if out.contains_key(&name) {
                let line = self.line_of(&format!("name=\"{name}\""));
                self.error(line, format!("function name '{name}' is used twice"));
            }
            out.insert(name, function);
        }
        out
    }

    /// Every connection of the file (see the module documentation for the order).
    pub(super) fn connections(
        &mut self,
        list: Vec<Connection>,
        functions: &BTreeMap<String, Function>,
    ) -> Vec<ConnectionSpec> {
        let mut connections = Vec::new();
        let mut signals = Signals::new();
        let mut group_signals = Signals::new();
        for c in list {
            match c {
                Connection::VariableConnection { variables } => {
                    connections.extend(self.variable_connection(&variables));
                }
                Connection::VariableGroupConnection { groups } => {
                    connections.extend(self.variable_group_connection(&groups));
                }
                Connection::SignalConnection { variable, signal } => {
                    self.signal(variable, signal, functions, false, &mut signals);
                }
                Connection::SignalGroupConnection { group, signal } => {
                    self.signal(group, signal, functions, true, &mut group_signals);
                }
            }
        }
        let order = ["LinearTransformation", "Sum", "VectorSum"];
        for kind in order {
            for (name, f) in functions.iter().filter(|(_, f)| f.kind() == kind) {
                let terms = match f {
                    Function::Linear { factor, offset } => {
                        self.transformed(name, *factor, *offset, &signals)
                    }
                    Function::Sum { inputs } => self.sum(name, *inputs, &signals),
                    Function::VectorSum { inputs, dimension } => {
                        self.vector_sum(name, *inputs, *dimension, &group_signals)
                    }
                };
                connections.extend(terms);
            }
        }
        connections
    }

    fn variable_connection(&mut self, variables: &[Endpoint]) -> Option<ConnectionSpec> {
        if variables.len() != 2 {
            self.error(
                None,
                "VariableConnection must have exactly two Variable elements",
            );
            return None;
        }
        let line = self.line_of(&format!(
            "name=\"{}\"",
            variables[1].name.replace('"', "&quot;")
        ));
        let mut c = plain(var_ref(&variables[0]), var_ref(&variables[1]), line);
        c.either_direction = true;
        Some(c)
    }

    /// A SignalConnection (`group` false) or SignalGroupConnection (`group` true): the function
    /// exists, takes this kind of connection, and has the signal.
    fn signal(
        &mut self,
        variable: Endpoint,
        signal: SignalEndpoint,
        functions: &BTreeMap<String, Function>,
        group: bool,
        signals: &mut Signals,
    ) {
        let line = self.line_of(&format!("function=\"{}\"", signal.function));
        let element = if group {
            "SignalGroupConnection"
        } else {
            "SignalConnection"
        };
        let Some(f) = functions.get(&signal.function) else {
            let names = functions.keys().map(String::as_str);
            let hint = did_you_mean(&signal.function, names);
            self.error(
                line,
                format!(
                    "{element} refers to unknown function '{}'{hint}",
                    signal.function
                ),
            );
            return;
        };
        if group != matches!(f, Function::VectorSum { .. }) {
            let wanted = if group {
                "SignalConnection"
            } else {
                "SignalGroupConnection"
            };
            self.error(
                line,
                format!(
                    "{element} to {} '{}': a {} is connected through {wanted}",
                    f.kind(),
                    signal.function,
                    f.kind()
                ),
            );
            return;
        }
        if !f.has_signal(&signal.name) {
            self.error(
                line,
                format!(
                    "function '{}': unknown signal '{}' ({} has {})",
                    signal.function,
                    signal.name,
                    f.kind(),
                    f.signals()
                ),
            );
            return;
        }
        signals
            .entry((signal.function, signal.name))
            .or_default()
            .push(variable);
    }

    /// The variable connected to signal `name` of function `f` (the first one, as libcosim's
    /// `find_signal_connection` takes), or an error naming the function and the signal.
    fn signal_end<'s>(
        &mut self,
        f: &str,
        name: &str,
        signals: &'s Signals,
    ) -> Option<&'s Endpoint> {
        let end = signals
            .get(&(f.to_string(), name.to_string()))
            .and_then(|v| v.first());
        if end.is_none() {
            let line = self.line_of(&format!("name=\"{f}\""));
            self.error(
                line,
                format!("function '{f}': nothing is connected to its signal '{name}'"),
            );
        }
        end
    }

    /// The connections through LinearTransformation `f`: one per "out".
    fn transformed(
        &mut self,
        f: &str,
        gain: f64,
        offset: f64,
        signals: &Signals,
    ) -> Vec<ConnectionSpec> {
        let key = |s: &str| (f.to_string(), s.to_string());
        let (Some(src), Some(dsts)) = (signals.get(&key("in")), signals.get(&key("out"))) else {
            let line = self.line_of(&format!("name=\"{f}\""));
            self.error(
                line,
                format!("LinearTransformation '{f}' needs one 'in' and at least one 'out' SignalConnection"),
            );
            return Vec::new();
        };
        let line = self.line_of(&format!("function=\"{f}\""));
        dsts.iter()
            .map(|d| ConnectionSpec {
                gain,
                offset,
                // a LinearTransformation may map one quantity onto another
                convert: gain != 1.0 || offset != 0.0,
                ..plain(var_ref(&src[0]), var_ref(d), line)
            })
            .collect()
    }

    /// The terms of Sum `f`: `in[0]`, `in[1]`, ... into its `out`.
    fn sum(&mut self, f: &str, inputs: u32, signals: &Signals) -> Vec<ConnectionSpec> {
        let line = self.line_of(&format!("function=\"{f}\""));
        let out = self.signal_end(f, "out", signals).map(var_ref);
        let ins: Vec<_> = (0..inputs)
            .filter_map(|i| self.signal_end(f, &format!("in[{i}]"), signals))
            .map(var_ref)
            .collect();
        let Some(out) = out else {
            return Vec::new();
        };
        ins.into_iter()
            .map(|from| ConnectionSpec {
                sum: true,
                ..plain(from, out.clone(), line)
            })
            .collect()
    }

    /// The terms of VectorSum `f`: component j of each input group `in[i]` into component j of
    /// the `out` group, input after input.
    fn vector_sum(
        &mut self,
        f: &str,
        inputs: u32,
        dimension: u32,
        signals: &Signals,
    ) -> Vec<ConnectionSpec> {
        let line = self.line_of(&format!("function=\"{f}\""));
        let component = |r: &mut Self, signal: &str| -> Option<Vec<VarRef>> {
            let end = r.signal_end(f, signal, signals)?.clone();
            let vars = r.top_level_group(&end, line)?.variables;
            if vars.len() < dimension as usize {
                r.error(
                    line,
                    format!(
                        "VectorSum '{f}' has dimension {dimension}, but variable group '{}' of simulator '{}' (signal '{signal}') has {} variable(s)",
                        end.name, end.simulator, vars.len()
                    ),
                );
                return None;
            }
            let at = |v: &String| VarRef {
                instance: end.simulator.clone(),
                variable: v.clone(),
            };
            Some(vars[..dimension as usize].iter().map(at).collect())
        };
        let out = component(self, "out");
        let ins: Vec<_> = (0..inputs)
            .filter_map(|i| component(self, &format!("in[{i}]")))
            .collect();
        let Some(out) = out else {
            return Vec::new();
        };
        let mut terms = Vec::new();
        for group in ins {
            for (from, to) in group.into_iter().zip(&out) {
                terms.push(ConnectionSpec {
                    sum: true,
                    ..plain(from, to.clone(), line)
                });
            }
        }
        terms
    }

    /// The variable groups of simulator `sim`, read once; an error naming the simulator when it
    /// has no OspModelDescription.xml.
    fn groups_of(&mut self, sim: &str, line: Option<usize>) -> Option<&Groups> {
        if !self.groups.contains_key(sim) {
            let Some(fmu) = self.fmus.get(sim).cloned() else {
                let names: Vec<String> = self.fmus.keys().cloned().collect();
                let hint = did_you_mean(sim, names.iter().map(String::as_str));
                self.error(line, format!("no simulator '{sim}'{hint}"));
                return None;
            };
            let dir = self.path.parent().unwrap_or(std::path::Path::new("."));
            let groups = match super::variable_groups::load(&fmu, dir) {
                Ok(g) => g,
                Err(e) => {
                    self.errors.push(e);
                    None
                }
            };
            if groups.is_none() {
                self.error(
                    line,
                    format!(
                        "simulator '{sim}': variable groups need the model's <modelName>_OspModelDescription.xml beside its FMU '{}' or beside this file; there is none",
                        fmu.display()
                    ),
                );
            }
            self.groups.insert(sim.to_string(), groups);
        }
        self.groups.get(sim).and_then(Option::as_ref)
    }

    /// The variable group `end` names, anywhere in its simulator's groups.
    fn group(&mut self, end: &Endpoint, line: Option<usize>) -> Option<Group> {
        self.named_group(end, line, false)
    }

    /// The top-level variable group `end` names (VectorSum signals, as libcosim looks them up).
    fn top_level_group(&mut self, end: &Endpoint, line: Option<usize>) -> Option<Group> {
        self.named_group(end, line, true)
    }

    fn named_group(&mut self, end: &Endpoint, line: Option<usize>, top: bool) -> Option<Group> {
        let path = self.path.to_path_buf();
        let groups = self.groups_of(&end.simulator, line)?;
        let found = match top {
            true => groups.top_level(&end.name),
            false => groups.find(&end.name),
        };
        if let Some(g) = found {
            return Some(g.clone());
        }
        let file = groups.file.display().to_string();
        let names: Vec<&str> = groups.top.iter().map(|g| g.name.as_str()).collect();
        let hint = did_you_mean(&end.name, names);
        let place = if top {
            "top-level variable group"
        } else {
            "variable group"
        };
        self.errors.push(crate::error::Error::system(
            &path,
            line,
            format!(
                "simulator '{}' has no {place} '{}' (in {file}){hint}",
                end.simulator, end.name
            ),
        ));
        None
    }

    /// A VariableGroupConnection: nested groups pairwise, then variables pairwise, each pair a
    /// VariableConnection (its direction from the causalities), as libcosim's
    /// `connect_variable_groups` does.
    fn variable_group_connection(&mut self, ends: &[Endpoint]) -> Vec<ConnectionSpec> {
        let [a, b] = ends else {
            self.error(
                None,
                "VariableGroupConnection must have exactly two VariableGroup elements",
            );
            return Vec::new();
        };
        let line = self.line_of(&format!("name=\"{}\"", b.name.replace('"', "&quot;")));
        let (Some(ga), Some(gb)) = (self.group(a, line), self.group(b, line)) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        self.connect_groups((a, &ga), (b, &gb), line, &mut out);
        out
    }

    fn connect_groups(
        &mut self,
        (a, ga): (&Endpoint, &Group),
        (b, gb): (&Endpoint, &Group),
        line: Option<usize>,
        out: &mut Vec<ConnectionSpec>,
    ) {
        let sizes = [
            ("nested groups", ga.groups.len(), gb.groups.len()),
            ("variables", ga.variables.len(), gb.variables.len()),
        ];
        for (what, na, nb) in sizes {
            if na != nb {
                self.error(
                    line,
                    format!(
                        "VariableGroupConnection: group '{}' of simulator '{}' has {na} {what} but group '{}' of simulator '{}' has {nb}",
                        ga.name, a.simulator, gb.name, b.simulator
                    ),
                );
                return;
            }
        }
        for (sa, sb) in ga.groups.iter().zip(&gb.groups) {
            self.connect_groups((a, sa), (b, sb), line, out);
        }
        for (va, vb) in ga.variables.iter().zip(&gb.variables) {
            let at = |e: &Endpoint, v: &String| VarRef {
                instance: e.simulator.clone(),
                variable: v.clone(),
            };
            let mut c = plain(at(a, va), at(b, vb), line);
            c.either_direction = true;
            out.push(c);
        }
    }
}
