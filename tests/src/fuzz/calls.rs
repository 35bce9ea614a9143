//! FMI calls as data: each [`Call`] prints as one short line (the repro of a failure lists the
//! calls of its unit) and is executed on a [`Ctx`], which keeps the instance, its FMU states
//! and the phase of the FMI 2.0 co-simulation state machine (FMI 2.0 sec. 4.2.4) the fuzzer
//! believes the instance is in.

use super::ffi::{callbacks, Loaded};
use super::mutate::{self, Mutation};
use super::proto::Record;
use fmi2::*;
use shipsim::model_description::VarType;
use std::ffi::{c_char, CString};
use std::fmt;
use std::ptr::{null, null_mut};

/// A number in a call's text: shortest round-trip form, exponent form when large or small.
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

fn list<T: fmt::Display>(items: &[T]) -> String {
    items
        .iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// The start of the text of the oracle's own reads (watched, not counted as calls).
pub const CHECK: &str = "check: ";

/// Value references of a get or set.
#[derive(Clone, Debug)]
pub enum Vrs {
    List(Vec<u32>),
    /// `vr` NULL with `nvr` = n (the value array is valid).
    NullVr(usize),
    /// A valid `vr` array with the value array NULL.
    NullValues(Vec<u32>),
}

impl Vrs {
    pub fn len(&self) -> usize {
        match self {
            Vrs::List(v) | Vrs::NullValues(v) => v.len(),
            Vrs::NullVr(n) => *n,
        }
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn vr_ptr(&self) -> *const u32 {
        match self {
            Vrs::List(v) | Vrs::NullValues(v) => v.as_ptr(),
            Vrs::NullVr(_) => null(),
        }
    }
    fn values_null(&self) -> bool {
        matches!(self, Vrs::NullValues(_))
    }
}

impl fmt::Display for Vrs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Vrs::List(v) => write!(f, "[{}]", list(v)),
            Vrs::NullVr(n) => write!(f, "NULL,n={n}"),
            Vrs::NullValues(v) => write!(f, "[{}],values=NULL", list(v)),
        }
    }
}

/// Which FMU state a state call gets.
#[derive(Clone, Copy, Debug)]
pub enum StateRef {
    /// A live state of this instance (index modulo their number; NULL when there is none).
    Live(usize),
    Null,
    /// A state this instance has freed (the export layer claims to detect it).
    Freed(usize),
}

impl fmt::Display for StateRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StateRef::Live(i) => write!(f, "s{i}"),
            StateRef::Null => write!(f, "NULL"),
            StateRef::Freed(i) => write!(f, "freed{i}"),
        }
    }
}

/// The bytes handed to fmi2DeSerializeFMUstate, from the last serialized state.
#[derive(Clone, Debug)]
pub enum Bytes {
    Valid,
    Mutated(Vec<Mutation>),
    Zeros(usize),
    Null(usize),
}

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Bytes::Valid => write!(f, "last"),
            Bytes::Mutated(m) => write!(f, "last{{{}}}", list(m)),
            Bytes::Zeros(n) => write!(f, "zeros({n})"),
            Bytes::Null(n) => write!(f, "NULL,n={n}"),
        }
    }
}

/// Arguments of fmi2Instantiate that can be wrong.
#[derive(Clone, Debug)]
pub struct InstantiateArgs {
    pub name: Option<String>,
    pub fmu_type: i32,
    /// 0 the right GUID, 1 a wrong one, 2 NULL.
    pub guid: u8,
    /// 0 the resources URI, 1 NULL, 2 a folder that does not exist.
    pub resources: u8,
    /// 0 the callbacks, 1 without logger, 2 NULL.
    pub callbacks: u8,
    pub logging: bool,
}

/// One FMI call with its arguments.
#[derive(Clone, Debug)]
pub enum Call {
    Instantiate(InstantiateArgs),
    FreeInstance,
    SetDebugLogging {
        on: bool,
        categories: Option<Vec<String>>,
        n: usize,
    },
    Setup {
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    },
    Enter,
    Exit,
    Terminate,
    Reset,
    GetReal(Vrs),
    GetInteger(Vrs),
    GetBoolean(Vrs),
    GetString(Vrs),
    SetReal(Vrs, Vec<f64>),
    SetInteger(Vrs, Vec<i32>),
    SetBoolean(Vrs, Vec<i32>),
    SetString(Vrs, Vec<Option<String>>),
    /// fmi2GetFMUstate, into a new state or over a live one.
    GetState(Option<usize>),
    SetState(StateRef),
    FreeState(StateRef),
    StateSize {
        state: StateRef,
        null_size: bool,
    },
    /// fmi2SerializeFMUstate with a buffer of the size asked for, minus `short` bytes.
    Serialize {
        state: StateRef,
        short: usize,
    },
    Deserialize(Bytes),
    DirectionalDerivative {
        unknown: Vec<u32>,
        known: Vec<u32>,
        dv: Vec<f64>,
    },
    SetInputDerivatives(Vrs, Vec<i32>, Vec<f64>),
    GetOutputDerivatives(Vrs, Vec<i32>),
    DoStep {
        t: f64,
        h: f64,
        no_prior: bool,
    },
    CancelStep,
    /// fmi2Get{,Real,Integer,Boolean,String}Status (which = 0..5) of a kind, maybe into NULL.
    Status {
        which: u8,
        kind: i32,
        null_value: bool,
    },
    /// A function called with a NULL component (see [`NULL_COMPONENT_CALLS`]).
    NullComponent(u8),
}

/// The functions [`Call::NullComponent`] calls.
pub const NULL_COMPONENT_CALLS: [&str; 6] = [
    "fmi2DoStep",
    "fmi2GetReal",
    "fmi2SetReal",
    "fmi2EnterInitializationMode",
    "fmi2Terminate",
    "fmi2GetFMUstate",
];

const STATUS_FNS: [&str; 5] = [
    "getStatus",
    "getRealStatus",
    "getIntegerStatus",
    "getBooleanStatus",
    "getStringStatus",
];

impl fmt::Display for Call {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let opt = |x: Option<f64>| x.map_or("-".to_string(), num);
        match self {
            Call::Instantiate(a) => write!(
                f,
                "instantiate(name={},type={},guid={},res={},cb={},log={})",
                a.name
                    .as_deref()
                    .map_or("NULL".into(), |n| format!("{n:?}")),
                a.fmu_type,
                ["ok", "wrong", "NULL"][a.guid as usize],
                ["ok", "NULL", "missing"][a.resources as usize],
                ["ok", "nologger", "NULL"][a.callbacks as usize],
                u8::from(a.logging)
            ),
            Call::FreeInstance => write!(f, "freeInstance"),
            Call::SetDebugLogging { on, categories, n } => match categories {
                Some(c) => write!(f, "setDebugLogging({},{:?},n={n})", u8::from(*on), c),
                None => write!(f, "setDebugLogging({},NULL,n={n})", u8::from(*on)),
            },
            Call::Setup {
                tolerance,
                start,
                stop,
            } => write!(
                f,
                "setupExperiment(tol={},start={},stop={})",
                opt(*tolerance),
                num(*start),
                opt(*stop)
            ),
            Call::Enter => write!(f, "enterInitializationMode"),
            Call::Exit => write!(f, "exitInitializationMode"),
            Call::Terminate => write!(f, "terminate"),
            Call::Reset => write!(f, "reset"),
            Call::GetReal(v) => write!(f, "getReal({v})"),
            Call::GetInteger(v) => write!(f, "getInteger({v})"),
            Call::GetBoolean(v) => write!(f, "getBoolean({v})"),
            Call::GetString(v) => write!(f, "getString({v})"),
            Call::SetReal(v, x) => {
                let x: Vec<String> = x.iter().map(|x| num(*x)).collect();
                write!(f, "setReal({v}=[{}])", x.join(","))
            }
            Call::SetInteger(v, x) => write!(f, "setInteger({v}=[{}])", list(x)),
            Call::SetBoolean(v, x) => write!(f, "setBoolean({v}=[{}])", list(x)),
            Call::SetString(v, x) => write!(f, "setString({v}={x:?})"),
            Call::GetState(None) => write!(f, "getFMUstate(new)"),
            Call::GetState(Some(i)) => write!(f, "getFMUstate(over s{i})"),
            Call::SetState(s) => write!(f, "setFMUstate({s})"),
            Call::FreeState(s) => write!(f, "freeFMUstate({s})"),
            Call::StateSize { state, null_size } => write!(
                f,
                "serializedFMUstateSize({state}{})",
                if *null_size { ",size=NULL" } else { "" }
            ),
            Call::Serialize { state, short } => {
                write!(f, "serializeFMUstate({state},size-{short})")
            }
            Call::Deserialize(b) => write!(f, "deSerializeFMUstate({b})"),
            Call::DirectionalDerivative { unknown, known, dv } => write!(
                f,
                "getDirectionalDerivative([{}],[{}],[{}])",
                list(unknown),
                list(known),
                dv.iter().map(|x| num(*x)).collect::<Vec<_>>().join(",")
            ),
            Call::SetInputDerivatives(v, o, x) => write!(
                f,
                "setRealInputDerivatives({v},order=[{}],[{}])",
                list(o),
                x.iter().map(|x| num(*x)).collect::<Vec<_>>().join(",")
            ),
            Call::GetOutputDerivatives(v, o) => {
                write!(f, "getRealOutputDerivatives({v},order=[{}])", list(o))
            }
            Call::DoStep { t, h, no_prior } => write!(
                f,
                "doStep(t={},h={},noPrior={})",
                num(*t),
                num(*h),
                u8::from(*no_prior)
            ),
            Call::CancelStep => write!(f, "cancelStep"),
            Call::Status {
                which,
                kind,
                null_value,
            } => write!(
                f,
                "{}(kind={kind}{})",
                STATUS_FNS[*which as usize % 5],
                if *null_value { ",value=NULL" } else { "" }
            ),
            Call::NullComponent(i) => write!(
                f,
                "{}(component=NULL)",
                NULL_COMPONENT_CALLS[*i as usize % NULL_COMPONENT_CALLS.len()]
            ),
        }
    }
}

/// Where the instance is in the co-simulation state machine (FMI 2.0 sec. 4.2.4), as far as
/// the fuzzer knows from the statuses it got.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    NoInstance,
    Instantiated,
    Init,
    Step,
    Terminated,
    /// After fmi2Error: only gets, reset and free are allowed, values undefined.
    Error,
    Fatal,
}

/// One instance under test with its FMU states and the last serialized state.
pub struct Ctx<'a> {
    pub fmu: &'a Loaded,
    pub comp: fmi2Component,
    pub phase: Phase,
    /// The FMU's time after the last successful step (or setup).
    pub time: f64,
    pub states: Vec<fmi2FMUstate>,
    pub freed: Vec<fmi2FMUstate>,
    pub bytes: Vec<u8>,
    /// Calls made (the oracle's own output reads are not counted).
    pub calls: u64,
    /// Set once an fmi2OK call left a non-finite Real output (the unit then ends).
    pub nonfinite: bool,
}

impl<'a> Ctx<'a> {
    pub fn new(fmu: &'a Loaded) -> Ctx<'a> {
        Ctx {
            fmu,
            comp: null_mut(),
            phase: Phase::NoInstance,
            time: 0.0,
            states: Vec::new(),
            freed: Vec::new(),
            bytes: Vec::new(),
            calls: 0,
            nonfinite: false,
        }
    }

    /// Runs one call: reports it, executes it, reports the status, updates the phase and, after
    /// fmi2OK, checks every Real output.
    pub fn run(&mut self, call: &Call) -> fmi2Status {
        let text = self.annotate(call);
        Record::Begin(text.clone()).send();
        // SAFETY: the arguments are built by `exec` from owned buffers of the stated lengths;
        // the component is NULL or a live instance of this FMU.
        let status = unsafe { self.exec(call) };
        Record::End(status).send();
        self.calls += 1;
        self.after(call, status);
        if status == fmi2OK {
            if let Some(bad) = self.check_outputs() {
                self.report_nonfinite(&text, &bad);
            }
        }
        status
    }

    /// The call's text, with the names of the variables a set call names (for the repro).
    fn annotate(&self, call: &Call) -> String {
        let (ty, vrs) = match call {
            Call::SetReal(Vrs::List(v), _) => (VarType::Real, v),
            Call::SetInteger(Vrs::List(v), _) => (VarType::Integer, v),
            Call::SetBoolean(Vrs::List(v), _) => (VarType::Boolean, v),
            _ => return call.to_string(),
        };
        let vars = self.fmu.model.of(ty);
        let names: Vec<&str> = vrs
            .iter()
            .map(|vr| {
                vars.iter()
                    .find(|v| v.vr == *vr)
                    .map_or("?", |v| v.name.as_str())
            })
            .collect();
        format!("{call} {{{}}}", names.join(","))
    }

    fn report_nonfinite(&mut self, call: &str, what: &str) {
        if !self.nonfinite {
            Record::NonFinite(format!(
                "{}: {call} returned fmi2OK; {what}",
                self.fmu.model.name
            ))
            .send();
        }
        self.nonfinite = true;
    }

    /// Reads every Real output when the phase allows it; the first non-finite one.
    fn check_outputs(&mut self) -> Option<String> {
        if !matches!(self.phase, Phase::Init | Phase::Step | Phase::Terminated)
            || self.comp.is_null()
        {
            return None;
        }
        let vrs = &self.fmu.model.real_outputs;
        if vrs.is_empty() {
            return None;
        }
        let mut values = vec![0.0; vrs.len()];
        // The read is watched like any call (it can hang: a model may compute its outputs
        // there), but not counted as one.
        Record::Begin(format!("{CHECK}fmi2GetReal of every Real output")).send();
        // SAFETY: both arrays have vrs.len() elements; the component is live.
        let st = unsafe {
            (self.fmu.api.fmi2GetReal)(self.comp, vrs.as_ptr(), vrs.len(), values.as_mut_ptr())
        };
        Record::End(st).send();
        if st != fmi2OK {
            return None;
        }
        self.first_nonfinite(vrs, &values)
            .map(|s| format!("then fmi2GetReal of the outputs gave {s}"))
    }

    fn first_nonfinite(&self, vrs: &[u32], values: &[f64]) -> Option<String> {
        let i = values.iter().position(|x| !x.is_finite())?;
        let name = self
            .fmu
            .model
            .real
            .iter()
            .find(|v| v.vr == vrs[i] && v.causality == Causality::Output)
            .map_or(format!("vr {}", vrs[i]), |v| v.name.clone());
        Some(format!("{name} = {}", values[i]))
    }

    fn state(&self, r: StateRef) -> fmi2FMUstate {
        match r {
            StateRef::Live(i) if !self.states.is_empty() => self.states[i % self.states.len()],
            StateRef::Freed(i) if !self.freed.is_empty() => self.freed[i % self.freed.len()],
            _ => null_mut(),
        }
    }

    /// The new phase after `call` returned `status`.
    #[allow(non_upper_case_globals)] // the FMI status constants
    fn after(&mut self, call: &Call, status: fmi2Status) {
        match status {
            fmi2Error => {
                if self.phase != Phase::NoInstance {
                    self.phase = Phase::Error;
                }
                return;
            }
            fmi2Fatal => {
                if self.phase != Phase::NoInstance {
                    self.phase = Phase::Fatal;
                }
                return;
            }
            fmi2OK | fmi2Warning => {}
            _ => return,
        }
        self.phase = match (call, self.phase) {
            (Call::Enter, Phase::Instantiated) => Phase::Init,
            (Call::Exit, Phase::Init) => Phase::Step,
            (Call::Terminate, Phase::Init | Phase::Step) => Phase::Terminated,
            (Call::Reset, p) if p != Phase::NoInstance => Phase::Instantiated,
            (Call::Setup { start, .. }, Phase::Instantiated) => {
                self.time = *start;
                Phase::Instantiated
            }
            (Call::DoStep { t, h, .. }, Phase::Step) => {
                self.time = t + h;
                Phase::Step
            }
            (_, p) => p,
        };
        if matches!(call, Call::Reset) {
            self.time = 0.0;
        }
    }
}

impl Ctx<'_> {
    /// Executes `call` (no reporting).
    ///
    /// # Safety
    /// `self.comp` is NULL or a live instance of `self.fmu`.
    unsafe fn exec(&mut self, call: &Call) -> fmi2Status {
        let api = &self.fmu.api;
        let c = self.comp;
        match call {
            Call::Instantiate(a) => self.instantiate(a),
            Call::FreeInstance => {
                (api.fmi2FreeInstance)(c);
                self.comp = null_mut();
                self.phase = Phase::NoInstance;
                // The instance's states went with it.
                self.states.clear();
                self.freed.clear();
                fmi2OK
            }
            Call::SetDebugLogging { on, categories, n } => {
                let owned: Vec<CString> = categories
                    .iter()
                    .flatten()
                    .map(|s| CString::new(s.as_str()).unwrap_or_default())
                    .collect();
                let ptrs: Vec<*const c_char> = owned.iter().map(|s| s.as_ptr()).collect();
                let p = if categories.is_some() {
                    ptrs.as_ptr()
                } else {
                    null()
                };
                let n = if categories.is_some() { ptrs.len() } else { *n };
                (api.fmi2SetDebugLogging)(c, i32::from(*on), n, p)
            }
            Call::Setup {
                tolerance,
                start,
                stop,
            } => (api.fmi2SetupExperiment)(
                c,
                i32::from(tolerance.is_some()),
                tolerance.unwrap_or(0.0),
                *start,
                i32::from(stop.is_some()),
                stop.unwrap_or(0.0),
            ),
            Call::Enter => (api.fmi2EnterInitializationMode)(c),
            Call::Exit => (api.fmi2ExitInitializationMode)(c),
            Call::Terminate => (api.fmi2Terminate)(c),
            Call::Reset => (api.fmi2Reset)(c),
            Call::GetReal(v) => get(v, 0.0, |vr, n, out| (api.fmi2GetReal)(c, vr, n, out)),
            Call::GetInteger(v) => get(v, 0, |vr, n, out| (api.fmi2GetInteger)(c, vr, n, out)),
            Call::GetBoolean(v) => get(v, 0, |vr, n, out| (api.fmi2GetBoolean)(c, vr, n, out)),
            Call::GetString(v) => {
                let mut out: Vec<fmi2String> = vec![null(); v.len()];
                let p = if v.values_null() {
                    null_mut()
                } else {
                    out.as_mut_ptr()
                };
                let st = (api.fmi2GetString)(c, v.vr_ptr(), v.len(), p);
                if st == fmi2OK {
                    // The strings must be readable (FMI 2.0 sec. 2.1.7).
                    for s in &out {
                        let _ = lossy_str(*s);
                    }
                }
                st
            }
            Call::SetReal(v, x) => set(v, x, |vr, n, p| (api.fmi2SetReal)(c, vr, n, p)),
            Call::SetInteger(v, x) => set(v, x, |vr, n, p| (api.fmi2SetInteger)(c, vr, n, p)),
            Call::SetBoolean(v, x) => set(v, x, |vr, n, p| (api.fmi2SetBoolean)(c, vr, n, p)),
            Call::SetString(v, x) => {
                let owned: Vec<Option<CString>> = x
                    .iter()
                    .map(|s| {
                        s.as_ref()
                            .map(|s| CString::new(s.as_str()).unwrap_or_default())
                    })
                    .collect();
                let ptrs: Vec<fmi2String> = owned
                    .iter()
                    .map(|s| s.as_ref().map_or(null(), |s| s.as_ptr()))
                    .collect();
                set(v, &ptrs, |vr, n, p| (api.fmi2SetString)(c, vr, n, p))
            }
            Call::GetState(over) => {
                let mut s = match over {
                    Some(i) => self.state(StateRef::Live(*i)),
                    None => null_mut(),
                };
                let was = s;
                let st = (api.fmi2GetFMUstate)(c, &mut s);
                if st == fmi2OK && !s.is_null() && s != was {
                    self.states.push(s);
                }
                st
            }
            Call::SetState(r) => (api.fmi2SetFMUstate)(c, self.state(*r)),
            Call::FreeState(r) => {
                let s0 = self.state(*r);
                let mut s = s0;
                let st = (api.fmi2FreeFMUstate)(c, &mut s);
                if st == fmi2OK && !s0.is_null() {
                    if let Some(i) = self.states.iter().position(|x| *x == s0) {
                        self.states.remove(i);
                        self.freed.push(s0);
                    }
                }
                st
            }
            Call::StateSize { state, null_size } => {
                let mut n = 0usize;
                let p = if *null_size {
                    null_mut()
                } else {
                    &mut n as *mut usize
                };
                (api.fmi2SerializedFMUstateSize)(c, self.state(*state), p)
            }
            Call::Serialize { state, short } => {
                let s = self.state(*state);
                let mut n = 0usize;
                let st = (api.fmi2SerializedFMUstateSize)(c, s, &mut n);
                if st != fmi2OK {
                    return st;
                }
                // Never more than 256 MiB, whatever the FMU claims.
                let size = n.min(1 << 28).saturating_sub(*short);
                let mut buf = vec![0u8; size];
                let st = (api.fmi2SerializeFMUstate)(c, s, buf.as_mut_ptr() as *mut fmi2Byte, size);
                if st == fmi2OK {
                    self.bytes = buf;
                }
                st
            }
            Call::Deserialize(b) => self.deserialize(b),
            Call::DirectionalDerivative { unknown, known, dv } => {
                let mut out = vec![0.0; unknown.len()];
                (api.fmi2GetDirectionalDerivative)(
                    c,
                    unknown.as_ptr(),
                    unknown.len(),
                    known.as_ptr(),
                    known.len().min(dv.len()),
                    dv.as_ptr(),
                    out.as_mut_ptr(),
                )
            }
            Call::SetInputDerivatives(v, o, x) => {
                let n = v.len().min(o.len()).min(x.len());
                (api.fmi2SetRealInputDerivatives)(c, v.vr_ptr(), n, o.as_ptr(), x.as_ptr())
            }
            Call::GetOutputDerivatives(v, o) => {
                let n = v.len().min(o.len());
                let mut out = vec![0.0; n];
                (api.fmi2GetRealOutputDerivatives)(c, v.vr_ptr(), n, o.as_ptr(), out.as_mut_ptr())
            }
            Call::DoStep { t, h, no_prior } => (api.fmi2DoStep)(c, *t, *h, i32::from(*no_prior)),
            Call::CancelStep => (api.fmi2CancelStep)(c),
            Call::Status {
                which,
                kind,
                null_value,
            } => self.status(*which, *kind, *null_value),
            Call::NullComponent(i) => null_component(api, *i),
        }
    }

    unsafe fn instantiate(&mut self, a: &InstantiateArgs) -> fmi2Status {
        let api = &self.fmu.api;
        let name = a
            .name
            .as_ref()
            .map(|n| CString::new(n.as_str()).unwrap_or_default());
        let wrong = CString::new("{00000000-fuzz-0000-0000-000000000000}").unwrap();
        let missing = CString::new("file:///nonexistent/shipsim-fuzz/resources").unwrap();
        let guid = match a.guid {
            0 => self.fmu.guid.as_ptr(),
            1 => wrong.as_ptr(),
            _ => null(),
        };
        let res = match a.resources {
            0 => self.fmu.resources.as_ptr(),
            1 => null(),
            _ => missing.as_ptr(),
        };
        let cb = match a.callbacks {
            0 => callbacks(false),
            1 => callbacks(true),
            _ => null(),
        };
        let comp = (api.fmi2Instantiate)(
            name.as_ref().map_or(null(), |n| n.as_ptr()),
            a.fmu_type,
            guid,
            res,
            cb,
            fmi2False,
            i32::from(a.logging),
        );
        if comp.is_null() {
            return fmi2Error;
        }
        if !self.comp.is_null() {
            // A second instance: freed at once (the fuzzer drives one instance at a time).
            (api.fmi2FreeInstance)(comp);
            return fmi2OK;
        }
        self.comp = comp;
        self.phase = Phase::Instantiated;
        self.time = 0.0;
        fmi2OK
    }

    unsafe fn deserialize(&mut self, b: &Bytes) -> fmi2Status {
        let data = match b {
            Bytes::Valid => self.bytes.clone(),
            Bytes::Mutated(m) => mutate::apply(&self.bytes, m),
            Bytes::Zeros(n) => vec![0u8; *n],
            Bytes::Null(_) => Vec::new(),
        };
        let (p, n) = match b {
            Bytes::Null(n) => (null(), *n),
            _ => (data.as_ptr() as *const fmi2Byte, data.len()),
        };
        let mut s: fmi2FMUstate = null_mut();
        let st = (self.fmu.api.fmi2DeSerializeFMUstate)(self.comp, p, n, &mut s);
        if st == fmi2OK && !s.is_null() {
            self.states.push(s);
        }
        st
    }

    unsafe fn status(&mut self, which: u8, kind: i32, null_value: bool) -> fmi2Status {
        let api = &self.fmu.api;
        let c = self.comp;
        macro_rules! one {
            ($f:ident, $t:ty, $zero:expr) => {{
                let mut v: $t = $zero;
                let p = if null_value {
                    null_mut()
                } else {
                    &mut v as *mut $t
                };
                (api.$f)(c, kind, p)
            }};
        }
        match which % 5 {
            0 => one!(fmi2GetStatus, fmi2Status, 0),
            1 => one!(fmi2GetRealStatus, f64, 0.0),
            2 => one!(fmi2GetIntegerStatus, i32, 0),
            3 => one!(fmi2GetBooleanStatus, i32, 0),
            _ => one!(fmi2GetStringStatus, fmi2String, null()),
        }
    }

    /// Frees every state and the instance (the end of every unit).
    pub fn close(&mut self) {
        let live = self.states.len();
        for _ in 0..live {
            if self.states.is_empty() || self.phase == Phase::NoInstance {
                break;
            }
            let before = self.states.len();
            self.run(&Call::FreeState(StateRef::Live(0)));
            // A refused free leaves the state: forget it rather than loop.
            if self.states.len() == before {
                self.states.remove(0);
            }
        }
        if !self.comp.is_null() {
            self.run(&Call::FreeInstance);
        }
    }
}

/// A get into a buffer of the right length (or NULL values).
unsafe fn get<T: Clone>(
    v: &Vrs,
    zero: T,
    f: impl FnOnce(*const u32, usize, *mut T) -> fmi2Status,
) -> fmi2Status {
    let mut out = vec![zero; v.len()];
    let p = if v.values_null() {
        null_mut()
    } else {
        out.as_mut_ptr()
    };
    f(v.vr_ptr(), v.len(), p)
}

/// A set from `x` (as long as the value references; NULL values on request).
unsafe fn set<T: Clone>(
    v: &Vrs,
    x: &[T],
    f: impl FnOnce(*const u32, usize, *const T) -> fmi2Status,
) -> fmi2Status {
    let n = v.len().min(x.len());
    let p = if v.values_null() { null() } else { x.as_ptr() };
    f(v.vr_ptr(), n, p)
}

unsafe fn null_component(api: &Fmi2Functions, i: u8) -> fmi2Status {
    let c = null_mut();
    let vr = [0u32];
    let mut x = [0.0f64];
    match i as usize % NULL_COMPONENT_CALLS.len() {
        0 => (api.fmi2DoStep)(c, 0.0, 0.1, fmi2True),
        1 => (api.fmi2GetReal)(c, vr.as_ptr(), 1, x.as_mut_ptr()),
        2 => (api.fmi2SetReal)(c, vr.as_ptr(), 1, x.as_ptr()),
        3 => (api.fmi2EnterInitializationMode)(c),
        4 => (api.fmi2Terminate)(c),
        _ => {
            let mut s = null_mut();
            (api.fmi2GetFMUstate)(c, &mut s)
        }
    }
}
