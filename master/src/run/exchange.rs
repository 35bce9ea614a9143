//! The exchange of values between instances, resolved before the first step.
//!
//! Every variable the run reads (a connection source or a recorded output) gets one place in
//! the shared [`Values`], per FMI type; an instance's observed variables of one type are a
//! contiguous range, so reading them is one batched `fmi2GetXxx` straight into that range.
//! Every connected input knows the place it reads from (and, for Real, the gain and offset; for
//! Integer and Boolean, an optional value mapping), so writing an instance's inputs is one gather into a scratch buffer and one batched
//! `fmi2SetXxx`. Nothing here allocates after [`Exchange::build`].
//!
//! The three FMI types the exchange moves (Real, Integer, Boolean; Enumeration travels as
//! Integer) are one generic [`Port`] over a [`Kind`].
//!
//! A summed input ([`PlanConnection::sum`](crate::system::PlanConnection)) gets its first
//! connection's term in the gather and every further term added after it, one at a time in
//! plan order: ((t0 + t1) + t2) + ..., each term `gain*from + offset`, starting from t0 itself
//! (not from 0.0). This is the order of libcosim's
//! `vector_sum_function::calculate` (`include/cosim/function/vector_sum.hpp`: the output is
//! assigned `in[0]`, then `in[1]`, `in[2]`, ... are added in index order), which runs OSP's
//! `Sum` and `VectorSum` functions; floating-point addition is not associative, so any other
//! order (a tree, a Kahan sum, a sum from 0.0) differs in the last bits for three or more terms.

use crate::error::Result;
use crate::fmu::VR;
use crate::instance::{Instance, Readable};
use crate::model_description::VarType;
use crate::system::{Plan, ValueMapping};
use std::collections::HashMap;

/// The current value of every observed variable, one vector per FMI type.
#[derive(Debug, Clone, Default)]
pub struct Values {
    pub real: Vec<f64>,
    pub integer: Vec<i32>,
    /// fmi2Boolean: 0 or 1.
    pub boolean: Vec<i32>,
    /// Recorded String variables (never connected: String values are only recorded), read
    /// into these buffers in place ([`Instance::get_string_into`]).
    pub string: Vec<String>,
}

/// An FMI variable type as the exchange moves it: where its values live, how a connection
/// transforms one, and the batched FMI calls that move them.
pub trait Kind {
    type Value: Copy + Default;
    /// What a connection applies to a value on its way (Real: gain and offset; Integer and
    /// Boolean: an optional [`ValueMapping`]).
    type Map;
    fn values(v: &Values) -> &[Self::Value];
    fn values_mut(v: &mut Values) -> &mut [Self::Value];
    fn map(value: Self::Value, map: &Self::Map) -> Self::Value;
    /// Adds a further term to a summed input (validation admits sums of Real inputs only;
    /// Integer wraps and Boolean is a logical or, so that the operation is defined for each).
    fn add(sum: Self::Value, term: Self::Value) -> Self::Value;
    fn set<S>(inst: &mut Instance<S>, vrs: &[VR], values: &[Self::Value]) -> Result<()>;
    fn get<S: Readable>(inst: &mut Instance<S>, vrs: &[VR], out: &mut [Self::Value]) -> Result<()>;
    /// The value as text when it is not finite (a Real NaN or infinity), else None.
    fn non_finite(_value: Self::Value) -> Option<String> {
        None
    }
}

/// `fmi2Real`.
pub struct Real;
/// `fmi2Integer` (and Enumeration).
pub struct Integer;
/// `fmi2Boolean`.
pub struct Boolean;

/// A Real connection's `to = gain*from + offset`.
#[derive(Clone, Copy, Debug)]
pub struct Linear {
    pub gain: f64,
    pub offset: f64,
}

impl Linear {
    /// The map of a connection with this gain and offset. A plain connection (gain 1, offset 0)
    /// passes its value on unchanged, as libcosim's VariableConnection does, the sign of zero
    /// included: its offset is -0.0, since x + (-0.0) is x for every x while -0.0 + 0.0 is +0.0.
    /// Any other keeps its offset: libcosim's LinearTransformation computes offset + factor*in,
    /// which gives +0.0 for offset 0 and factor*in = -0.0, as gain*x + 0.0 does.
    pub fn of(gain: f64, offset: f64) -> Linear {
        let plain = gain == 1.0 && offset == 0.0;
        let offset = if plain { -0.0 } else { offset };
        Linear { gain, offset }
    }
}

impl Kind for Real {
    type Value = f64;
    type Map = Linear;
    fn values(v: &Values) -> &[f64] {
        &v.real
    }
    fn values_mut(v: &mut Values) -> &mut [f64] {
        &mut v.real
    }
    #[inline]
    fn map(value: f64, m: &Linear) -> f64 {
        m.gain * value + m.offset
    }
    #[inline]
    fn add(sum: f64, term: f64) -> f64 {
        sum + term
    }
    #[inline]
    fn set<S>(inst: &mut Instance<S>, vrs: &[VR], values: &[f64]) -> Result<()> {
        inst.set_real(vrs, values)
    }
    #[inline]
    fn get<S: Readable>(inst: &mut Instance<S>, vrs: &[VR], out: &mut [f64]) -> Result<()> {
        inst.get_real(vrs, out)
    }
    fn non_finite(value: f64) -> Option<String> {
        (!value.is_finite()).then(|| value.to_string())
    }
}

impl Kind for Integer {
    type Value = i32;
    type Map = Option<ValueMapping>;
    fn values(v: &Values) -> &[i32] {
        &v.integer
    }
    fn values_mut(v: &mut Values) -> &mut [i32] {
        &mut v.integer
    }
    #[inline]
    fn map(value: i32, m: &Option<ValueMapping>) -> i32 {
        mapped(value, m)
    }
    #[inline]
    fn add(sum: i32, term: i32) -> i32 {
        sum.wrapping_add(term)
    }
    #[inline]
    fn set<S>(inst: &mut Instance<S>, vrs: &[VR], values: &[i32]) -> Result<()> {
        inst.set_integer(vrs, values)
    }
    #[inline]
    fn get<S: Readable>(inst: &mut Instance<S>, vrs: &[VR], out: &mut [i32]) -> Result<()> {
        inst.get_integer(vrs, out)
    }
}

impl Kind for Boolean {
    type Value = i32;
    type Map = Option<ValueMapping>;
    fn values(v: &Values) -> &[i32] {
        &v.boolean
    }
    fn values_mut(v: &mut Values) -> &mut [i32] {
        &mut v.boolean
    }
    #[inline]
    fn map(value: i32, m: &Option<ValueMapping>) -> i32 {
        mapped(value, m)
    }
    #[inline]
    fn add(sum: i32, term: i32) -> i32 {
        i32::from(sum != 0 || term != 0)
    }
    #[inline]
    fn set<S>(inst: &mut Instance<S>, vrs: &[VR], values: &[i32]) -> Result<()> {
        inst.set_boolean(vrs, values)
    }
    #[inline]
    fn get<S: Readable>(inst: &mut Instance<S>, vrs: &[VR], out: &mut [i32]) -> Result<()> {
        inst.get_boolean(vrs, out)
    }
}

/// An Integer or Boolean value through a connection's optional value mapping (SSP mapping
/// transformations): a binary search in the table built before the first step, no allocation.
#[inline(always)]
fn mapped(value: i32, m: &Option<ValueMapping>) -> i32 {
    match m {
        None => value,
        Some(m) => m.apply(value),
    }
}

/// One connected input: where its value comes from, and what the connection applies.
struct Link<K: Kind> {
    source: usize,
    map: K::Map,
}

/// A further term of a summed input: added to the port's input `input` after its first term.
struct Term<K: Kind> {
    input: usize,
    link: Link<K>,
}

/// Observed variables of one instance and type (connection sources and recorded outputs), in
/// the order of the batched fmi2GetXxx, stored at `Values[at..at + vrs.len()]`.
#[derive(Default)]
struct Observed {
    vrs: Vec<VR>,
    at: usize,
}

/// An instance's connected inputs and observed variables of one FMI type.
pub struct Port<K: Kind> {
    /// Connected inputs, in the order of the batched fmi2SetXxx.
    input_vrs: Vec<VR>,
    links: Vec<Link<K>>,
    /// The second and further terms of summed inputs, in plan order (empty without sums).
    terms: Vec<Term<K>>,
    /// The connections' names ("a.y -> b.u"), for errors: of `links`, then of `terms`.
    names: Vec<String>,
    scratch: Vec<K::Value>,
    observed: Observed,
}

impl<K: Kind> Default for Port<K> {
    fn default() -> Self {
        Port {
            input_vrs: Vec::new(),
            links: Vec::new(),
            terms: Vec::new(),
            names: Vec::new(),
            scratch: Vec::new(),
            observed: Observed::default(),
        }
    }
}

impl<K: Kind> Port<K> {
    /// No connected inputs and no observed variables.
    fn is_empty(&self) -> bool {
        self.input_vrs.is_empty() && self.observed.vrs.is_empty()
    }

    /// Connects input `vr` (its first or only term); returns its index among the inputs.
    fn connect(&mut self, vr: VR, source: usize, map: K::Map, name: &str) -> usize {
        self.names.insert(self.links.len(), name.to_string());
        self.input_vrs.push(vr);
        self.links.push(Link { source, map });
        self.scratch.push(K::Value::default());
        self.input_vrs.len() - 1
    }

    /// Connects input `vr`, or adds a further term to the summed input `first` (after the
    /// terms it has); returns the input's index.
    fn connect_term(
        &mut self,
        first: Option<usize>,
        vr: VR,
        source: usize,
        map: K::Map,
        name: &str,
    ) -> usize {
        let Some(input) = first else {
            return self.connect(vr, source, map, name);
        };
        let link = Link { source, map };
        self.terms.push(Term { input, link });
        self.names.push(name.to_string());
        input
    }

    /// Gathers the connected inputs into the scratch buffer and writes them with one batched
    /// call (none for an instance without inputs of this type: [`Instance::set_real`] and its
    /// siblings skip an empty batch).
    #[inline(always)]
    fn set_inputs<S>(&mut self, inst: &mut Instance<S>, values: &Values) -> Result<()> {
        let shared = K::values(values);
        for (x, l) in self.scratch.iter_mut().zip(&self.links) {
            *x = K::map(shared[l.source], &l.map);
        }
        for t in &self.terms {
            let x = &mut self.scratch[t.input];
            *x = K::add(*x, K::map(shared[t.link.source], &t.link.map));
        }
        K::set(inst, &self.input_vrs, &self.scratch).map_err(|e| self.blame_producer(e, shared))
    }

    /// A refused set whose values hold a non-finite one: the error names the producer first
    /// (the instance and variable the connection comes from), then the receiver's refusal.
    #[cold]
    #[inline(never)]
    fn blame_producer(&self, e: crate::error::Error, shared: &[K::Value]) -> crate::error::Error {
        // The sources of the links, then of the further terms of sums: `names` is in this order.
        let sources = self.links.iter().chain(self.terms.iter().map(|t| &t.link));
        let bad = sources
            .zip(&self.names)
            .find_map(|(l, name)| K::non_finite(shared[l.source]).map(|v| (v, name)));
        match bad {
            Some((value, name)) => {
                let from = name.split(" -> ").next().unwrap_or(name);
                crate::error::Error::Other(format!(
                    "'{from}' is {value} (its FMU returned it with fmi2OK), passed on by the connection {name}: {e}"
                ))
            }
            None => e,
        }
    }

    #[inline(always)]
    fn get_outputs<S: Readable>(&self, inst: &mut Instance<S>, values: &mut Values) -> Result<()> {
        let Observed { vrs, at } = &self.observed;
        if vrs.is_empty() {
            return Ok(());
        }
        K::get(inst, vrs, &mut K::values_mut(values)[*at..*at + vrs.len()])
    }
}

/// An instance's ports, one per FMI type.
#[derive(Default)]
pub struct Ports {
    real: Port<Real>,
    integer: Port<Integer>,
    boolean: Port<Boolean>,
    /// Recorded String variables, stored at `Values::string[at..]`.
    string: Observed,
    /// The Integer or the Boolean port has inputs or observed variables, or String variables
    /// are recorded (one test per call for the many instances that exchange only Real values).
    discrete: bool,
}

impl Ports {
    /// Writes the instance's connected inputs from `values` (Real, then Integer, then Boolean).
    #[inline(always)]
    pub fn set_inputs<S>(&mut self, inst: &mut Instance<S>, values: &Values) -> Result<()> {
        self.real.set_inputs(inst, values)?;
        if self.discrete {
            self.integer.set_inputs(inst, values)?;
            self.boolean.set_inputs(inst, values)?;
        }
        Ok(())
    }

    /// Reads the instance's observed variables into `values` (Real, then Integer, then Boolean).
    #[inline(always)]
    pub fn get_outputs<S: Readable>(
        &self,
        inst: &mut Instance<S>,
        values: &mut Values,
    ) -> Result<()> {
        self.real.get_outputs(inst, values)?;
        if self.discrete {
            self.integer.get_outputs(inst, values)?;
            self.boolean.get_outputs(inst, values)?;
            let Observed { vrs, at } = &self.string;
            inst.get_string_into(vrs, &mut values.string[*at..*at + vrs.len()])?;
        }
        Ok(())
    }

    /// Where the observed variable `vr` of type `t` of this instance is kept in [`Values`]
    /// (a connection source or a recorded output), or None if it is not observed.
    pub fn observed_column(&self, t: VarType, vr: VR) -> Option<Column> {
        let t = kind_of(t);
        let o = match t {
            VarType::Real => &self.real.observed,
            VarType::Boolean => &self.boolean.observed,
            VarType::String => &self.string,
            _ => &self.integer.observed,
        };
        let g = o.at + o.vrs.iter().position(|v| *v == vr)?;
        Some(match t {
            VarType::Real => Column::Real(g),
            VarType::Boolean => Column::Boolean(g),
            VarType::String => Column::String(g),
            _ => Column::Integer(g),
        })
    }

    /// Gives the Real connection named `name` (the first term of its input) the map
    /// gain*x + `offset`; false if the port has no such single-term connection.
    pub fn set_real_offset(&mut self, name: &str, gain: f64, offset: f64) -> bool {
        let p = &mut self.real;
        match p.names[..p.links.len()].iter().position(|n| n == name) {
            Some(i) if p.terms.is_empty() => {
                p.links[i].map = Linear { gain, offset };
                true
            }
            _ => false,
        }
    }

    /// The observed variables of exchange type `t` (Real, Integer, Boolean or String).
    fn observed_mut(&mut self, t: VarType) -> &mut Observed {
        match t {
            VarType::Real => &mut self.real.observed,
            VarType::Boolean => &mut self.boolean.observed,
            VarType::String => &mut self.string,
            _ => &mut self.integer.observed,
        }
    }
}

/// Where a recorded column lives in [`Values`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Column {
    Real(usize),
    Integer(usize),
    Boolean(usize),
    String(usize),
}

/// The resolved exchange of a plan: per-instance ports, the shared values, and the place of
/// every recorded output.
pub struct Exchange {
    pub ports: Vec<Ports>,
    pub values: Values,
    /// `plan.outputs[j]` is at `columns[j]`.
    pub columns: Vec<Column>,
}

/// The exchange types, in the order of the batched calls and of [`Values`].
const KINDS: [VarType; 4] = [
    VarType::Real,
    VarType::Integer,
    VarType::Boolean,
    VarType::String,
];

/// The exchange's type of a plan variable type (Enumeration is already Integer in a plan).
fn kind_of(t: VarType) -> VarType {
    match t {
        VarType::Real | VarType::Boolean | VarType::String => t,
        _ => VarType::Integer,
    }
}

impl Exchange {
    /// Resolves every connection and recorded output of `plan`.
    pub fn build(plan: &Plan) -> Exchange {
        let n = plan.instances.len();
        let mut ports: Vec<Ports> = (0..n).map(|_| Ports::default()).collect();
        // (instance, type, vr) -> index among the instance's observed variables of that type
        let mut local: HashMap<(usize, VarType, VR), usize> = HashMap::new();
        let sources = plan
            .connections
            .iter()
            .map(|c| (c.from_instance, c.var_type, c.from_vr));
        let recorded = plan.outputs.iter().map(|o| (o.instance, o.var_type, o.vr));
        for (i, t, vr) in sources.chain(recorded) {
            let t = kind_of(t);
            local.entry((i, t, vr)).or_insert_with(|| {
                let observed = ports[i].observed_mut(t);
                observed.vrs.push(vr);
                observed.vrs.len() - 1
            });
        }
        let values = place_outputs(&mut ports);
        let mut global = |i: usize, t: VarType, vr: VR| -> usize {
            let t = kind_of(t);
            ports[i].observed_mut(t).at + local[&(i, t, vr)]
        };
        let links: Vec<usize> = plan
            .connections
            .iter()
            .map(|c| global(c.from_instance, c.var_type, c.from_vr))
            .collect();
        let columns = plan
            .outputs
            .iter()
            .map(|o| {
                let g = global(o.instance, o.var_type, o.vr);
                match kind_of(o.var_type) {
                    VarType::Real => Column::Real(g),
                    VarType::Boolean => Column::Boolean(g),
                    VarType::String => Column::String(g),
                    _ => Column::Integer(g),
                }
            })
            .collect();
        // (instance, type, vr) of a summed input -> its index among the port's inputs
        let mut summed: HashMap<(usize, VarType, VR), usize> = HashMap::new();
        for (c, g) in plan.connections.iter().zip(links) {
            let p = &mut ports[c.to_instance];
            let t = kind_of(c.var_type);
            let key = (c.to_instance, t, c.to_vr);
            let first = summed.get(&key).copied();
            let input = match t {
                VarType::Real => {
                    p.real
                        .connect_term(first, c.to_vr, g, Linear::of(c.gain, c.offset), &c.name)
                }
                VarType::Boolean => {
                    p.boolean
                        .connect_term(first, c.to_vr, g, c.mapping.clone(), &c.name)
                }
                _ => p
                    .integer
                    .connect_term(first, c.to_vr, g, c.mapping.clone(), &c.name),
            };
            if c.sum {
                summed.insert(key, input);
            }
        }
        for p in ports.iter_mut() {
            p.discrete = !(p.integer.is_empty() && p.boolean.is_empty() && p.string.vrs.is_empty());
        }
        Exchange {
            ports,
            values,
            columns,
        }
    }
}

/// Lays the observed variables out instance after instance; returns the zeroed shared values.
fn place_outputs(ports: &mut [Ports]) -> Values {
    let mut len = [0usize; 4];
    for p in ports.iter_mut() {
        for (n, t) in len.iter_mut().zip(KINDS) {
            let observed = p.observed_mut(t);
            observed.at = *n;
            *n += observed.vrs.len();
        }
    }
    Values {
        real: vec![0.0; len[0]],
        integer: vec![0; len[1]],
        boolean: vec![0; len[2]],
        string: vec![String::new(); len[3]],
    }
}
