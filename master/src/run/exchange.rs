//! The exchange of values between instances, resolved before the first step.
//!
//! Every variable the run reads (a connection source or a recorded output) gets one place in
//! the shared [`Values`], per FMI type; an instance's observed variables of one type are a
//! contiguous range, so reading them is one batched `fmi2GetXxx` straight into that range.
//! Every connected input knows the place it reads from (and, for Real, the gain and offset),
//! so writing an instance's inputs is one gather into a scratch buffer and one batched
//! `fmi2SetXxx`. Nothing here allocates after [`Exchange::build`].
//!
//! The three FMI types the exchange moves (Real, Integer, Boolean; Enumeration travels as
//! Integer) are one generic [`Port`] over a [`Kind`].

use crate::error::Result;
use crate::fmu::VR;
use crate::instance::{Instance, Readable};
use crate::model_description::VarType;
use crate::system::Plan;
use std::collections::HashMap;

/// The current value of every observed variable, one vector per FMI type.
#[derive(Debug, Clone, Default)]
pub struct Values {
    pub real: Vec<f64>,
    pub integer: Vec<i32>,
    /// fmi2Boolean: 0 or 1.
    pub boolean: Vec<i32>,
}

/// An FMI variable type as the exchange moves it: where its values live, how a connection
/// transforms one, and the batched FMI calls that move them.
pub trait Kind {
    type Value: Copy + Default;
    /// What a connection applies to a value on its way (Real: gain and offset).
    type Map: Copy;
    fn values(v: &Values) -> &[Self::Value];
    fn values_mut(v: &mut Values) -> &mut [Self::Value];
    fn map(value: Self::Value, map: Self::Map) -> Self::Value;
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
    fn map(value: f64, m: Linear) -> f64 {
        m.gain * value + m.offset
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
    type Map = ();
    fn values(v: &Values) -> &[i32] {
        &v.integer
    }
    fn values_mut(v: &mut Values) -> &mut [i32] {
        &mut v.integer
    }
    #[inline]
    fn map(value: i32, _: ()) -> i32 {
        value
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
    type Map = ();
    fn values(v: &Values) -> &[i32] {
        &v.boolean
    }
    fn values_mut(v: &mut Values) -> &mut [i32] {
        &mut v.boolean
    }
    #[inline]
    fn map(value: i32, _: ()) -> i32 {
        value
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

/// One connected input: where its value comes from, and what the connection applies.
struct Link<K: Kind> {
    source: usize,
    map: K::Map,
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
    /// The connections' names ("a.y -> b.u"), for errors.
    names: Vec<String>,
    scratch: Vec<K::Value>,
    observed: Observed,
}

impl<K: Kind> Default for Port<K> {
    fn default() -> Self {
        Port {
            input_vrs: Vec::new(),
            links: Vec::new(),
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

    fn connect(&mut self, vr: VR, source: usize, map: K::Map, name: &str) {
        self.names.push(name.to_string());
        self.input_vrs.push(vr);
        self.links.push(Link { source, map });
        self.scratch.push(K::Value::default());
    }

    /// Gathers the connected inputs into the scratch buffer and writes them with one batched
    /// call (none for an instance without inputs of this type: [`Instance::set_real`] and its
    /// siblings skip an empty batch).
    #[inline(always)]
    fn set_inputs<S>(&mut self, inst: &mut Instance<S>, values: &Values) -> Result<()> {
        let shared = K::values(values);
        for (x, l) in self.scratch.iter_mut().zip(&self.links) {
            *x = K::map(shared[l.source], l.map);
        }
        K::set(inst, &self.input_vrs, &self.scratch).map_err(|e| self.blame_producer(e))
    }

    /// A refused set whose values hold a non-finite one: the error names the producer first
    /// (the instance and variable the connection comes from), then the receiver's refusal.
    #[cold]
    #[inline(never)]
    fn blame_producer(&self, e: crate::error::Error) -> crate::error::Error {
        let bad = self
            .scratch
            .iter()
            .zip(&self.names)
            .find_map(|(v, name)| K::non_finite(*v).map(|v| (v, name)));
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
    /// The Integer or the Boolean port has inputs or observed variables (one test per call
    /// for the many instances that exchange only Real values).
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
        }
        Ok(())
    }

    /// The observed variables of exchange type `t` (Real, Integer or Boolean).
    fn observed_mut(&mut self, t: VarType) -> &mut Observed {
        match t {
            VarType::Real => &mut self.real.observed,
            VarType::Boolean => &mut self.boolean.observed,
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
const KINDS: [VarType; 3] = [VarType::Real, VarType::Integer, VarType::Boolean];

/// The exchange's type of a plan variable type (Enumeration is already Integer in a plan).
fn kind_of(t: VarType) -> VarType {
    match t {
        VarType::Real | VarType::Boolean => t,
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
                    _ => Column::Integer(g),
                }
            })
            .collect();
        for (c, g) in plan.connections.iter().zip(links) {
            let p = &mut ports[c.to_instance];
            match kind_of(c.var_type) {
                VarType::Real => p.real.connect(
                    c.to_vr,
                    g,
                    Linear {
                        gain: c.gain,
                        offset: c.offset,
                    },
                    &c.name,
                ),
                VarType::Boolean => p.boolean.connect(c.to_vr, g, (), &c.name),
                _ => p.integer.connect(c.to_vr, g, (), &c.name),
            }
        }
        for p in ports.iter_mut() {
            p.discrete = !(p.integer.is_empty() && p.boolean.is_empty());
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
    let mut len = [0usize; 3];
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
    }
}
