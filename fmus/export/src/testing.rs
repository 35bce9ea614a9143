//! Testing an FMU through its C API by variable name.
//!
//! [`Harness`] drives one instance through an [`Fmi2Functions`] table, as an importer does:
//! either the `fmi2*` symbols an FMU crate exports (linked into its test binary by
//! [`fmu_tests!`](crate::fmu_tests)), or the generic table [`functions`] of any model type. Values
//! are set and read by name and type-checked against the variable table; every call checks its
//! status and a failure names the FMU, the variable and the FMU's last log message.
//!
//! [`fmu_tests!`](crate::fmu_tests) generates, for an FMU crate, the checks every FMU must pass:
//! the layer's table rules, the model description read back through the master's parser equal to
//! the table, every variable readable and writable by name at its start value, and an exact
//! rollback of the FMU state.

use crate::variables::{check_table, Access, BaseType, Causality, Variable};
use crate::xml::real;
use crate::FmuModel;
use fmi2::*;
use std::ffi::{c_char, c_int, c_void, CString};
use std::marker::PhantomData;
use std::ptr::{null, null_mut};
use std::sync::Mutex;

/// Generic `extern "C"` shims over [`api`], one per FMI function, for any model type.
macro_rules! shims {
    (; $($name:ident $ty:ident $impl:ident ($($arg:ident : $argty:ty),*) -> $ret:ty;)*) => {
        mod shim {
            use crate::FmuModel;
            $(
                #[allow(clippy::unused_unit)]
                pub unsafe extern "C" fn $impl<M: FmuModel>($($arg: $argty),*) -> $ret {
                    crate::api::$impl::<M>($($arg),*)
                }
            )*
        }

        /// The FMI 2.0 API of model type `M` as a function table, without exporting symbols (so
        /// that one test binary can drive several model types).
        pub fn functions<M: FmuModel>() -> Fmi2Functions {
            Fmi2Functions { $($name: shim::$impl::<M>,)* }
        }
    };
}
fmi2::fmi2_functions!(shims);

/// Log lines an instance sent to the importer: (status, category, message).
#[derive(Default)]
pub struct Log {
    lines: Mutex<Vec<(fmi2Status, String, String)>>,
}

impl Log {
    /// Every line so far.
    pub fn lines(&self) -> Vec<(fmi2Status, String, String)> {
        self.lines.lock().map(|l| l.clone()).unwrap_or_default()
    }
    /// Whether any message contains `needle`.
    pub fn contains(&self, needle: &str) -> bool {
        self.lines().iter().any(|(_, _, m)| m.contains(needle))
    }
    /// How many lines were logged in `category`.
    pub fn count(&self, category: &str) -> usize {
        self.lines()
            .iter()
            .filter(|(_, c, _)| c == category)
            .count()
    }
    /// The last message ("" if none).
    pub fn last(&self) -> String {
        self.lines().last().map(|l| l.2.clone()).unwrap_or_default()
    }
}

unsafe extern "C" fn sink(
    ctx: *mut c_void,
    _instance: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    let log = &*(ctx as *const Log);
    if let Ok(mut lines) = log.lines.lock() {
        lines.push((status, lossy_str(category), lossy_str(message)));
    }
}

/// The importer's side of an instance: the callbacks it is given, with a logger (through the C
/// proxy for the variadic `fmi2CallbackLogger`) that collects every line into a [`Log`]. It must
/// outlive the instances that use its callbacks.
pub struct Importer {
    log: Box<Log>,
    _target: Box<LogTarget>,
    callbacks: Box<fmi2CallbackFunctions>,
}

impl Default for Importer {
    fn default() -> Self {
        let log = Box::new(Log::default());
        let mut target = Box::new(LogTarget {
            sink: Some(sink),
            ctx: &*log as *const Log as *mut c_void,
        });
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: logger_proxy(),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: &mut *target as *mut LogTarget as *mut c_void,
        });
        Importer {
            log,
            _target: target,
            callbacks,
        }
    }
}

impl Importer {
    /// What the instances logged.
    pub fn log(&self) -> &Log {
        &self.log
    }
    /// The callbacks to pass to `fmi2Instantiate`.
    pub fn callbacks(&self) -> &fmi2CallbackFunctions {
        &self.callbacks
    }
}

/// A value of an FMI base type that [`Harness`] can get and set.
pub trait Value: Copy + std::fmt::Debug {
    const TYPE: BaseType;
    /// # Safety
    /// `c` must be a live instance of `f`.
    unsafe fn get(
        f: &Fmi2Functions,
        c: fmi2Component,
        vr: fmi2ValueReference,
    ) -> (fmi2Status, Self);
    /// # Safety
    /// `c` must be a live instance of `f`.
    unsafe fn set(self, f: &Fmi2Functions, c: fmi2Component, vr: fmi2ValueReference) -> fmi2Status;
}

impl Value for f64 {
    const TYPE: BaseType = BaseType::Real;
    unsafe fn get(
        f: &Fmi2Functions,
        c: fmi2Component,
        vr: fmi2ValueReference,
    ) -> (fmi2Status, Self) {
        let mut v = f64::NAN;
        ((f.fmi2GetReal)(c, &vr, 1, &mut v), v)
    }
    unsafe fn set(self, f: &Fmi2Functions, c: fmi2Component, vr: fmi2ValueReference) -> fmi2Status {
        (f.fmi2SetReal)(c, &vr, 1, &self)
    }
}

impl Value for i32 {
    const TYPE: BaseType = BaseType::Integer;
    unsafe fn get(
        f: &Fmi2Functions,
        c: fmi2Component,
        vr: fmi2ValueReference,
    ) -> (fmi2Status, Self) {
        let mut v = 0;
        ((f.fmi2GetInteger)(c, &vr, 1, &mut v), v)
    }
    unsafe fn set(self, f: &Fmi2Functions, c: fmi2Component, vr: fmi2ValueReference) -> fmi2Status {
        (f.fmi2SetInteger)(c, &vr, 1, &self)
    }
}

impl Value for bool {
    const TYPE: BaseType = BaseType::Boolean;
    unsafe fn get(
        f: &Fmi2Functions,
        c: fmi2Component,
        vr: fmi2ValueReference,
    ) -> (fmi2Status, Self) {
        let mut v = fmi2False;
        ((f.fmi2GetBoolean)(c, &vr, 1, &mut v), v != fmi2False)
    }
    unsafe fn set(self, f: &Fmi2Functions, c: fmi2Component, vr: fmi2ValueReference) -> fmi2Status {
        let v = self as fmi2Boolean;
        (f.fmi2SetBoolean)(c, &vr, 1, &v)
    }
}

/// An FMU state of a [`Harness`] instance (`fmi2FMUstate`), valid until freed.
#[derive(Clone, Copy, Debug)]
pub struct FmuState(pub fmi2FMUstate);

/// One instance of the FMU `M`, driven through `functions` by variable name. Dropping it frees
/// the instance.
pub struct Harness<M: FmuModel> {
    f: Fmi2Functions,
    c: fmi2Component,
    importer: Importer,
    _model: PhantomData<M>,
}

impl<M: FmuModel> Harness<M> {
    /// `fmi2Instantiate` with the FMU's GUID, a capturing logger and logging off.
    pub fn instantiate(functions: Fmi2Functions, name: &str) -> Self {
        let importer = Importer::default();
        let cname = CString::new(name).expect("instance name without NUL");
        let guid = CString::new(crate::xml::guid::<M>()).expect("GUID without NUL");
        let c = unsafe {
            (functions.fmi2Instantiate)(
                cname.as_ptr(),
                fmi2CoSimulation,
                guid.as_ptr(),
                null(),
                importer.callbacks(),
                fmi2False,
                fmi2False,
            )
        };
        assert!(
            !c.is_null(),
            "{}: fmi2Instantiate returned NULL: {}",
            M::MODEL_IDENTIFIER,
            importer.log().last()
        );
        Harness {
            f: functions,
            c,
            importer,
            _model: PhantomData,
        }
    }

    /// The function table (for raw calls).
    pub fn functions(&self) -> &Fmi2Functions {
        &self.f
    }

    /// The instance (for raw calls).
    pub fn component(&self) -> fmi2Component {
        self.c
    }

    /// What the instance logged.
    pub fn log(&self) -> &Log {
        self.importer.log()
    }

    fn check(&self, what: &str, status: fmi2Status) {
        assert_eq!(
            status,
            fmi2OK,
            "{}: {what} returned {}: {}",
            M::MODEL_IDENTIFIER,
            status_name(status),
            self.log().last()
        );
    }

    /// `fmi2SetupExperiment` (no tolerance; `stop` if given).
    pub fn setup(&mut self, start: f64, stop: Option<f64>) -> fmi2Status {
        let (defined, stop) = (stop.is_some() as fmi2Boolean, stop.unwrap_or(0.0));
        unsafe { (self.f.fmi2SetupExperiment)(self.c, fmi2False, 0.0, start, defined, stop) }
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization(&mut self) -> fmi2Status {
        unsafe { (self.f.fmi2EnterInitializationMode)(self.c) }
    }

    /// `fmi2ExitInitializationMode`.
    pub fn exit_initialization(&mut self) -> fmi2Status {
        unsafe { (self.f.fmi2ExitInitializationMode)(self.c) }
    }

    /// Setup, enter and exit initialization at `start`, each checked.
    pub fn initialize(&mut self, start: f64) -> &mut Self {
        let s = self.setup(start, None);
        self.check("fmi2SetupExperiment", s);
        let s = self.enter_initialization();
        self.check("fmi2EnterInitializationMode", s);
        let s = self.exit_initialization();
        self.check("fmi2ExitInitializationMode", s);
        self
    }

    /// The table entry of `name` (panics naming the FMU if there is none).
    pub fn variable(&self, name: &str) -> &'static Variable<M> {
        &M::variables()[self.vr(name) as usize]
    }

    /// The value reference of `name` (panics naming the FMU if there is none).
    pub fn vr(&self, name: &str) -> fmi2ValueReference {
        match M::variables().iter().position(|v| v.name == name) {
            Some(i) => i as fmi2ValueReference,
            None => panic!("{} has no variable {name:?}", M::MODEL_IDENTIFIER),
        }
    }

    fn typed<T: Value>(&self, name: &str) -> fmi2ValueReference {
        let v = self.variable(name);
        assert_eq!(
            v.base_type(),
            T::TYPE,
            "{}: variable {name:?} is {}, not {}",
            M::MODEL_IDENTIFIER,
            v.base_type(),
            T::TYPE
        );
        self.vr(name)
    }

    /// Sets `name` and returns the status.
    pub fn try_set<T: Value>(&mut self, name: &str, value: T) -> fmi2Status {
        let vr = self.typed::<T>(name);
        unsafe { value.set(&self.f, self.c, vr) }
    }

    /// Sets `name`, checking the status.
    pub fn set<T: Value>(&mut self, name: &str, value: T) -> &mut Self {
        let s = self.try_set(name, value);
        self.check(&format!("setting {name} = {value:?}"), s);
        self
    }

    /// Reads `name` with its status.
    pub fn try_get<T: Value>(&self, name: &str) -> (fmi2Status, T) {
        let vr = self.typed::<T>(name);
        unsafe { T::get(&self.f, self.c, vr) }
    }

    /// Reads `name`, checking the status.
    pub fn get<T: Value>(&self, name: &str) -> T {
        let (s, v) = self.try_get(name);
        self.check(&format!("getting {name}"), s);
        v
    }

    /// Reads a Real.
    pub fn real(&self, name: &str) -> f64 {
        self.get(name)
    }

    /// Reads several Reals with one `fmi2GetReal` call.
    pub fn reals(&self, names: &[&str]) -> Vec<f64> {
        let vrs: Vec<fmi2ValueReference> = names.iter().map(|n| self.typed::<f64>(n)).collect();
        let mut out = vec![f64::NAN; vrs.len()];
        let s = unsafe { (self.f.fmi2GetReal)(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        self.check(&format!("getting {names:?}"), s);
        out
    }

    /// `fmi2DoStep` from `t` over `h`, returning the status.
    pub fn try_step(&mut self, t: f64, h: f64) -> fmi2Status {
        unsafe { (self.f.fmi2DoStep)(self.c, t, h, fmi2True) }
    }

    /// `fmi2DoStep` from `t` over `h`, checked.
    pub fn step(&mut self, t: f64, h: f64) -> &mut Self {
        let s = self.try_step(t, h);
        self.check(&format!("fmi2DoStep({t}, {h})"), s);
        self
    }

    /// Runs steps `0..n` through `step(self, k, replaying)`, which sets the inputs of step `k`,
    /// steps, (on the first pass) compares with the model, and returns the outputs it read. The
    /// FMU state saved before step `replay_from` is then restored and steps `replay_from..n` are
    /// run again with `replaying = true`: their outputs must repeat bit for bit.
    pub fn check_replay(
        &mut self,
        n: usize,
        replay_from: usize,
        mut step: impl FnMut(&mut Self, usize, bool) -> Vec<f64>,
    ) {
        let mut saved = None;
        let mut recorded = Vec::new();
        for k in 0..n {
            if k == replay_from {
                saved = Some(self.get_state());
            }
            let outputs = step(self, k, false);
            if k >= replay_from {
                recorded.push(outputs);
            }
        }
        let saved = saved.expect("replay_from < n");
        assert_eq!(self.set_state(saved), fmi2OK);
        for (k, expected) in (replay_from..n).zip(&recorded) {
            let again = step(self, k, true);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&again),
                bits(expected),
                "{}: replay of step {k}",
                M::MODEL_IDENTIFIER
            );
        }
        self.free_state(saved);
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) -> fmi2Status {
        unsafe { (self.f.fmi2Terminate)(self.c) }
    }

    /// `fmi2Reset`.
    pub fn reset(&mut self) -> fmi2Status {
        unsafe { (self.f.fmi2Reset)(self.c) }
    }

    /// `fmi2GetFMUstate` into a new state, checked.
    pub fn get_state(&mut self) -> FmuState {
        let mut s: fmi2FMUstate = null_mut();
        let st = unsafe { (self.f.fmi2GetFMUstate)(self.c, &mut s) };
        self.check("fmi2GetFMUstate", st);
        FmuState(s)
    }

    /// `fmi2SetFMUstate`.
    pub fn set_state(&mut self, state: FmuState) -> fmi2Status {
        unsafe { (self.f.fmi2SetFMUstate)(self.c, state.0) }
    }

    /// `fmi2FreeFMUstate`, checked.
    pub fn free_state(&mut self, state: FmuState) {
        let mut state = state.0;
        let st = unsafe { (self.f.fmi2FreeFMUstate)(self.c, &mut state) };
        self.check("fmi2FreeFMUstate", st);
    }

    /// `fmi2SerializedFMUstateSize` and `fmi2SerializeFMUstate`, checked.
    pub fn serialize(&mut self, state: FmuState) -> Vec<u8> {
        let (state, mut size) = (state.0, 0usize);
        let st = unsafe { (self.f.fmi2SerializedFMUstateSize)(self.c, state, &mut size) };
        self.check("fmi2SerializedFMUstateSize", st);
        let mut bytes = vec![0 as c_char; size];
        let st = unsafe { (self.f.fmi2SerializeFMUstate)(self.c, state, bytes.as_mut_ptr(), size) };
        self.check("fmi2SerializeFMUstate", st);
        bytes.into_iter().map(|b| b as u8).collect()
    }

    /// `fmi2DeSerializeFMUstate` into a new state, with the status.
    pub fn deserialize(&mut self, bytes: &[u8]) -> (fmi2Status, FmuState) {
        let mut s: fmi2FMUstate = null_mut();
        let p = bytes.as_ptr() as *const c_char;
        let st = unsafe { (self.f.fmi2DeSerializeFMUstate)(self.c, p, bytes.len(), &mut s) };
        (st, FmuState(s))
    }
}

impl<M: FmuModel> Drop for Harness<M> {
    fn drop(&mut self) {
        unsafe { (self.f.fmi2FreeInstance)(self.c) }
    }
}

/// How a probe case must end (see [`check_probe`]).
#[derive(Clone, Copy, Debug)]
pub enum Outcome {
    /// A call returns fmi2Error with a log message that contains this text.
    Error(&'static str),
    /// Every call returns fmi2OK and every Real output stays finite.
    Finite,
}

impl<M: FmuModel> Harness<M> {
    /// The Real outputs that are not finite numbers, by name (read one by one: a getter's status
    /// is checked).
    pub fn non_finite_outputs(&self) -> Vec<&'static str> {
        let outputs = M::variables()
            .iter()
            .filter(|v| v.causality == Causality::Output && v.base_type() == BaseType::Real);
        outputs
            .filter(|v| !self.real(v.name).is_finite())
            .map(|v| v.name)
            .collect()
    }

    /// Sets `integers`, then `reals`, in Initialization Mode, leaves it at t = 0 and takes
    /// `steps` steps of `h`, reading every Real output after each: the first status that is not
    /// fmi2OK (of a setter, the exit, a step or a read), with the last log message and the
    /// number of steps taken (fmi2OK: all taken).
    pub fn run_probe(
        &mut self,
        integers: &[(&str, i32)],
        reals: &[(&str, f64)],
        h: f64,
        steps: usize,
    ) -> (fmi2Status, String, usize) {
        let s = self.setup(0.0, None);
        self.check("fmi2SetupExperiment", s);
        let s = self.enter_initialization();
        self.check("fmi2EnterInitializationMode", s);
        for &(name, value) in integers {
            let s = self.try_set(name, value);
            if s != fmi2OK {
                return (s, self.log().last(), 0);
            }
        }
        for &(name, value) in reals {
            let s = self.try_set(name, value);
            if s != fmi2OK {
                return (s, self.log().last(), 0);
            }
        }
        let s = self.exit_initialization();
        if s != fmi2OK {
            return (s, self.log().last(), 0);
        }
        let outputs: Vec<fmi2ValueReference> = M::variables()
            .iter()
            .enumerate()
            .filter(|(_, v)| v.causality == Causality::Output && v.base_type() == BaseType::Real)
            .map(|(vr, _)| vr as fmi2ValueReference)
            .collect();
        let mut values = vec![0.0; outputs.len()];
        for k in 0..steps {
            let s = self.try_step(k as f64 * h, h);
            if s != fmi2OK {
                return (s, self.log().last(), k);
            }
            // The outputs, as a master reads them after each step.
            let (n, vrs, out) = (outputs.len(), outputs.as_ptr(), values.as_mut_ptr());
            let s = unsafe { (self.f.fmi2GetReal)(self.c, vrs, n, out) };
            if s != fmi2OK {
                return (s, self.log().last(), k + 1);
            }
        }
        (fmi2OK, self.log().last(), steps)
    }
}

/// A case of the issue-19 reliability probe: `integers` and `reals` set in Initialization Mode,
/// then up to `steps` steps of `h` from t = 0 (see [`Harness::run_probe`]); the outcome must be
/// `expect`. A case that hangs on a model without the work bound ends here with the error of
/// the bound.
pub fn check_probe<M: FmuModel>(
    functions: Fmi2Functions,
    integers: &[(&str, i32)],
    reals: &[(&str, f64)],
    h: f64,
    steps: usize,
    expect: Outcome,
) {
    let mut fmu = Harness::<M>::instantiate(functions, "probe");
    let (status, last, taken) = fmu.run_probe(integers, reals, h, steps);
    let case = format!("{} {integers:?} {reals:?}, h = {h}", M::MODEL_IDENTIFIER);
    match expect {
        Outcome::Error(text) => {
            assert_eq!(
                status,
                fmi2Error,
                "{case}: {} after {taken} steps, outputs not finite: {:?} (last log: {last})",
                status_name(status),
                fmu.non_finite_outputs()
            );
            assert!(last.contains(text), "{case}: {last:?} lacks {text:?}");
        }
        Outcome::Finite => {
            assert_eq!(status, fmi2OK, "{case}: {}: {last}", status_name(status));
            assert_eq!(fmu.non_finite_outputs(), Vec::<&str>::new(), "{case}");
        }
    }
}

/// How a corrupt serialized state must end (see [`check_corrupt_state`]).
#[derive(Clone, Copy, Debug)]
pub enum Corrupt {
    /// `fmi2DeSerializeFMUstate` refuses it with a message that contains this text.
    Refused(&'static str),
    /// It is within the declared ranges (as `fmi2SetReal` would accept it): it restores, and
    /// the next step of the default experiment returns fmi2Error with a message that contains
    /// this text (the bound on the work of one step).
    StepRefused(&'static str),
}

/// A corrupt serialized FMU state, as a file or a network could deliver it: `M` initialized at
/// t = 0 (with `integers` set first) takes three steps of its default experiment; its state is
/// serialized, and the `occurrence`-th (0-based; `None`: every) 8-byte little-endian copy of
/// `find` in the bytes is replaced by `replace`. The outcome must be `expect`.
pub fn check_corrupt_state<M: FmuModel>(
    functions: Fmi2Functions,
    integers: &[(&str, i32)],
    find: f64,
    occurrence: Option<usize>,
    replace: f64,
    expect: Corrupt,
) {
    let id = M::MODEL_IDENTIFIER;
    let mut fmu = Harness::<M>::instantiate(functions, "corrupt");
    let h = M::DEFAULT_EXPERIMENT.step_size;
    let (status, last, _) = fmu.run_probe(integers, &[], h, 3);
    assert_eq!(status, fmi2OK, "{id}: {last}");
    let state = fmu.get_state();
    let mut bytes = fmu.serialize(state);
    let at: Vec<usize> = (0..bytes.len().saturating_sub(7))
        .filter(|&i| bytes[i..i + 8] == find.to_le_bytes())
        .collect();
    let chosen: Vec<usize> = match occurrence {
        Some(k) => at.get(k).copied().into_iter().collect(),
        None => at.clone(),
    };
    assert!(
        !chosen.is_empty(),
        "{id}: occurrence {occurrence:?} of {find:?} in the state: found at {at:?}"
    );
    for i in chosen {
        bytes[i..i + 8].copy_from_slice(&replace.to_le_bytes());
    }
    let (status, restored) = fmu.deserialize(&bytes);
    let last = fmu.log().last();
    let case = format!("{id}: a state with {find:?} -> {replace:?}");
    match expect {
        Corrupt::Refused(text) => {
            assert_eq!(status, fmi2Error, "{case} was accepted");
            assert!(restored.0.is_null(), "{case}: a state was created");
            assert!(last.contains(text), "{case}: {last:?} lacks {text:?}");
            fmu.step(3.0 * h, h);
        }
        Corrupt::StepRefused(text) => {
            assert_eq!(status, fmi2OK, "{case} was refused: {last}");
            assert_eq!(
                fmu.set_state(restored),
                fmi2OK,
                "{case}: {}",
                fmu.log().last()
            );
            let s = fmu.try_step(3.0 * h, h);
            let last = fmu.log().last();
            assert_eq!(s, fmi2Error, "{case}: the step returned {}", status_name(s));
            assert!(last.contains(text), "{case}: {last:?} lacks {text:?}");
            fmu.free_state(restored);
        }
    }
    fmu.free_state(state);
}

/// The cases of the reliability probe for one FMU crate, as a table: one `#[test]` per row, named
/// `<fmu>::<group>::<row>` (so that a failure names the FMU and the case). Declares the FMI
/// symbols the crate exports, in module `<fmu>`, and runs each row over them. Use once per test
/// file:
///
/// ```text
/// fmi2_export::probe_cases! {
///     my_fmu = my_fmu::MyFmu;
///
///     /// Where the cases of this group come from.
///     group_name: probe(integers = [("order", 2)], h = 0.1, steps = 50) {
///         gain_1e300: [("gain", 1e300)] => Error("output \"y\" = NaN is not a finite number"),
///         gain_1e6: [("gain", 1e6)] => Finite,
///     }
///
///     another_group: corrupt() {
///         interval_1p5e_neg40: 0.1 -> 1.5e-40 => StepRefused("internal steps of dt = "),
///     }
/// }
/// ```
///
/// A `probe` group shares the Integers (optional, set first), the step size `h` and the number of
/// steps; each row gives the Reals to set and the [`Outcome`] (`Error(text)` or `Finite`), and is
/// a [`check_probe`]. A `corrupt` group shares the Integers; each row replaces every copy of a
/// value in the serialized state and gives the [`Corrupt`] outcome (`Refused(text)` or
/// `StepRefused(text)`), and is a [`check_corrupt_state`]. Doc comments and attributes are kept on
/// the groups (modules) and rows (tests). The probe tables name a row after what it sets, with
/// `p` for a decimal point and `neg` for a minus sign (`gm_1e300`, `max_substep_1e_neg300`,
/// `initial_sway_velocity_neg_1e6`; `defaults` when it sets nothing), and a corrupt row after the
/// value written (`interval_1p5e_neg40`).
#[macro_export]
macro_rules! probe_cases {
    (
        $fmu:ident = $model:ty;
        $(
            $(#[$group_meta:meta])*
            $group:ident : $kind:ident ( $($args:tt)* ) { $($rows:tt)* }
        )*
    ) => {
        /// The probe cases of the FMU, over the FMI symbols its crate exports.
        mod $fmu {
            $crate::fmi2::declare_fmi2_functions!();

            /// The FMU under test.
            type Model = $model;

            $(
                $(#[$group_meta])*
                mod $group {
                    $crate::__probe_rows!($kind ($($args)*) { $($rows)* });
                }
            )*
        }
    };
}

/// The rows of one group of [`probe_cases!`](crate::probe_cases), as `#[test]` functions of a
/// module inside the FMU's module.
#[doc(hidden)]
#[macro_export]
macro_rules! __probe_rows {
    (probe (h = $h:expr, steps = $steps:expr) $rows:tt) => {
        $crate::__probe_rows!(probe (integers = [], h = $h, steps = $steps) $rows);
    };
    (
        probe (integers = $integers:tt, h = $h:expr, steps = $steps:expr) {
            $(
                $(#[$meta:meta])*
                $row:ident : [ $($reals:tt)* ] => $expect:expr
            ),* $(,)?
        }
    ) => {
        $(
            $(#[$meta])*
            #[test]
            fn $row() {
                #[allow(unused_imports)]
                use $crate::testing::Outcome::*;
                $crate::testing::check_probe::<super::Model>(
                    super::linked_fmi2_functions(),
                    &$integers,
                    &[$($reals)*],
                    $h,
                    $steps,
                    $expect,
                );
            }
        )*
    };
    (corrupt () $rows:tt) => {
        $crate::__probe_rows!(corrupt (integers = []) $rows);
    };
    (
        corrupt (integers = $integers:tt) {
            $(
                $(#[$meta:meta])*
                $row:ident : $find:literal -> $replace:literal => $expect:expr
            ),* $(,)?
        }
    ) => {
        $(
            $(#[$meta])*
            #[test]
            fn $row() {
                #[allow(unused_imports)]
                use $crate::testing::Corrupt::*;
                $crate::testing::check_corrupt_state::<super::Model>(
                    super::linked_fmi2_functions(),
                    &$integers,
                    $find,
                    None,
                    $replace,
                    $expect,
                );
            }
        )*
    };
}

/// One variable as `modelDescription.xml` declares it, in a form both the table and an
/// importer's parser can produce (numbers as their shortest round-trip text).
#[derive(Clone, Debug, PartialEq)]
pub struct Declared {
    pub name: String,
    pub value_reference: u32,
    pub description: String,
    pub causality: Causality,
    pub variability: Variability,
    pub initial: Option<Initial>,
    pub base_type: &'static str,
    pub unit: Option<String>,
    pub min: Option<String>,
    pub max: Option<String>,
    pub start: Option<String>,
    /// For outputs: the 1-based indices of the inputs it depends on (`None`: all).
    pub dependencies: Option<Vec<usize>>,
}

/// What the table of `M` declares, variable by variable.
pub fn declared<M: FmuModel>() -> Vec<Declared> {
    let default = M::default();
    let vars = M::variables();
    let dependencies = |v: &Variable<M>| {
        let names = v.dependencies.or(if M::DIRECT_FEEDTHROUGH {
            None
        } else {
            Some(&[])
        })?;
        let index = |n: &&str| vars.iter().position(|w| w.name == *n).map(|k| k + 1);
        Some(names.iter().filter_map(index).collect())
    };
    vars.iter()
        .enumerate()
        .map(|(vr, v)| {
            let (base_type, min, max, start) = match &v.access {
                Access::Real { get, min, max, .. } => {
                    ("Real", min.map(real), max.map(real), real(get(&default)))
                }
                Access::Integer { get, min, max, .. } => (
                    "Integer",
                    min.map(|m| m.to_string()),
                    max.map(|m| m.to_string()),
                    get(&default).to_string(),
                ),
                Access::Boolean { get, .. } => ("Boolean", None, None, get(&default).to_string()),
            };
            Declared {
                name: v.name.to_string(),
                value_reference: vr as u32,
                description: v.description.to_string(),
                causality: v.causality,
                variability: v.variability,
                initial: v.initial(),
                base_type,
                unit: v.unit().map(str::to_string),
                min,
                max,
                start: v.has_start().then_some(start),
                dependencies: (v.causality == Causality::Output)
                    .then(|| dependencies(v))
                    .flatten(),
            }
        })
        .collect()
}

/// The layer's rules for the table of `M` (see [`check_table`]), with the problems listed.
/// The Real variable `name` of a model value, read through its table getter (without the C API:
/// for unit tests of an FMU type's own methods).
pub fn real_of<M: FmuModel>(model: &M, name: &str) -> f64 {
    match M::variables()
        .iter()
        .find(|v| v.name == name)
        .map(|v| &v.access)
    {
        Some(Access::Real { get, .. }) => get(model),
        _ => panic!("{}: no Real variable {name:?}", M::MODEL_IDENTIFIER),
    }
}

pub fn check_variable_table<M: FmuModel>() {
    if let Err(problems) = check_table(M::variables()) {
        panic!("{}: {}", M::MODEL_IDENTIFIER, problems.join("; "));
    }
}

/// Instantiates `M`, checks that every parameter and input reads back its start value by name in
/// Initialization Mode and accepts it written again, initializes, reads every variable by name,
/// writes every input and tunable parameter in Step Mode, and takes one step of the default
/// experiment.
pub fn check_every_variable<M: FmuModel>(functions: Fmi2Functions) {
    let default = M::default();
    let mut h = Harness::<M>::instantiate(functions, "every_variable");
    let s = h.setup(M::DEFAULT_EXPERIMENT.start_time, None);
    h.check("fmi2SetupExperiment", s);
    let s = h.enter_initialization();
    h.check("fmi2EnterInitializationMode", s);
    for v in M::variables().iter().filter(|v| v.settable()) {
        match &v.access {
            Access::Real { get, .. } => {
                assert_eq!(
                    h.get::<f64>(v.name).to_bits(),
                    get(&default).to_bits(),
                    "{}",
                    v.name
                );
                h.set(v.name, get(&default));
            }
            Access::Integer { get, .. } => {
                assert_eq!(h.get::<i32>(v.name), get(&default), "{}", v.name);
                h.set(v.name, get(&default));
            }
            Access::Boolean { get, .. } => {
                assert_eq!(h.get::<bool>(v.name), get(&default), "{}", v.name);
                h.set(v.name, get(&default));
            }
        }
    }
    let s = h.exit_initialization();
    h.check("fmi2ExitInitializationMode", s);
    let step_mode = |v: &&Variable<M>| {
        v.causality == Causality::Input
            || (v.causality == Causality::Parameter && v.variability == Variability::Tunable)
    };
    for v in M::variables() {
        match v.base_type() {
            BaseType::Real => {
                let x = h.get::<f64>(v.name);
                assert!(!x.is_nan(), "{}: {} is NaN", M::MODEL_IDENTIFIER, v.name);
            }
            BaseType::Integer => {
                h.get::<i32>(v.name);
            }
            BaseType::Boolean => {
                h.get::<bool>(v.name);
            }
        }
    }
    for v in M::variables().iter().filter(step_mode) {
        match &v.access {
            Access::Real { get, .. } => h.set(v.name, get(&default)),
            Access::Integer { get, .. } => h.set(v.name, get(&default)),
            Access::Boolean { get, .. } => h.set(v.name, get(&default)),
        };
    }
    let de = M::DEFAULT_EXPERIMENT;
    h.step(de.start_time, de.step_size);
    assert_eq!(h.terminate(), fmi2OK);
}

/// `fmi2GetVersion` is "2.0" and `fmi2Instantiate` refuses a wrong GUID with NULL.
pub fn check_version_and_guid<M: FmuModel>(functions: Fmi2Functions) {
    assert_eq!(unsafe { lossy_str((functions.fmi2GetVersion)()) }, "2.0");
    assert_eq!(
        unsafe { lossy_str((functions.fmi2GetTypesPlatform)()) },
        "default"
    );
    let callbacks = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: null_mut(),
    };
    let (name, wrong) = (c"wrong_guid", c"{00000000-0000-0000-0000-000000000000}");
    let c = unsafe {
        let (kind, res) = (fmi2CoSimulation, null());
        (functions.fmi2Instantiate)(name.as_ptr(), kind, wrong.as_ptr(), res, &callbacks, 0, 0)
    };
    assert!(
        c.is_null(),
        "{}: a wrong GUID was accepted",
        M::MODEL_IDENTIFIER
    );
}

/// Takes two default-experiment steps, restores the state saved after the first (directly and
/// through serialization) and checks that the second step repeats bit for bit.
pub fn check_state_rollback<M: FmuModel>(functions: Fmi2Functions) {
    let reals: Vec<&str> = M::variables()
        .iter()
        .filter(|v| v.base_type() == BaseType::Real)
        .map(|v| v.name)
        .collect();
    let de = M::DEFAULT_EXPERIMENT;
    let (t0, dt) = (de.start_time, de.step_size);
    let mut h = Harness::<M>::instantiate(functions, "rollback");
    h.initialize(t0);
    h.step(t0, dt);
    let saved = h.get_state();
    h.step(t0 + dt, dt);
    let first: Vec<u64> = h.reals(&reals).iter().map(|x| x.to_bits()).collect();
    assert_eq!(h.set_state(saved), fmi2OK);
    h.step(t0 + dt, dt);
    let again: Vec<u64> = h.reals(&reals).iter().map(|x| x.to_bits()).collect();
    assert_eq!(first, again, "{}: rollback", M::MODEL_IDENTIFIER);
    let bytes = h.serialize(saved);
    let (st, restored) = h.deserialize(&bytes);
    assert_eq!(st, fmi2OK);
    assert_eq!(h.set_state(restored), fmi2OK);
    h.step(t0 + dt, dt);
    let third: Vec<u64> = h.reals(&reals).iter().map(|x| x.to_bits()).collect();
    assert_eq!(first, third, "{}: serialized rollback", M::MODEL_IDENTIFIER);
    h.free_state(saved);
    h.free_state(restored);
}

/// The bare source numbers `000` to `004` in `text`, each with the text around it: the
/// project's first names of the five sources, which users cannot look up (docs/sources.md
/// gives their citation keys: `[Klugt1987, Fig. 2.8]`, not `003 Fig. 2.8`). A run of three
/// digits inside a longer number (`0.001`, `1,000`, `2003`, `1.004e3`) or a word is not one.
pub fn bare_source_numbers(text: &str) -> Vec<String> {
    let b = text.as_bytes();
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut found = Vec::new();
    for i in 0..b.len().saturating_sub(2) {
        if !(b[i] == b'0' && b[i + 1] == b'0' && (b'0'..=b'4').contains(&b[i + 2])) {
            continue;
        }
        let before = i.checked_sub(1).map(|k| b[k]);
        let before2 = i.checked_sub(2).map(|k| b[k]);
        let after = b.get(i + 3).copied();
        let after2 = b.get(i + 4).copied();
        let in_number_before = match before {
            Some(c) if word(c) || c == b'.' => true,
            Some(b',') => before2.is_some_and(|c| c.is_ascii_digit()),
            _ => false,
        };
        let in_number_after = match after {
            Some(c) if word(c) => true,
            Some(b'.' | b',') => after2.is_some_and(|c| c.is_ascii_digit()),
            _ => false,
        };
        if !in_number_before && !in_number_after {
            let (mut from, mut to) = (i.saturating_sub(40), (i + 43).min(text.len()));
            while !text.is_char_boundary(from) {
                from -= 1;
            }
            while !text.is_char_boundary(to) {
                to += 1;
            }
            found.push(text[from..to].to_string());
        }
    }
    found
}

/// The FMU's documentation page and model description (variable descriptions included) cite
/// the sources by their keys of docs/sources.md, never by a bare number `000` to `004`.
pub fn check_sources_cited_by_key<M: FmuModel>() {
    let texts = [
        (
            "documentation/index.html",
            crate::xml::documentation_html::<M>(),
        ),
        ("modelDescription.xml", crate::xml::model_description::<M>()),
    ];
    for (file, text) in texts {
        let bare = bare_source_numbers(&text);
        assert!(
            bare.is_empty(),
            "{}: {file} cites sources by number; use the keys of docs/sources.md \
             ([Taylor2000, ...], [Fossen1999, ...], [Artyszuk2003, ...], [Klugt1987, ...], \
             [Parsons1980, ...]):\n{}",
            M::MODEL_IDENTIFIER,
            bare.join("\n")
        );
    }
}

/// The checks every FMU crate runs, as `#[test]` functions: the table rules, the model
/// description read back through the master's parser (`shipsim`, a dev-dependency of the FMU
/// crate) equal to the table, every variable by name, an exact rollback, and sources cited by
/// their keys in the documentation and the model description. Also declares the
/// FMI symbols the crate exports and `fn fmu() -> Harness<M>` over them, for the crate's own
/// tests. Use once per test file: `fmi2_export::fmu_tests!(my_fmu::MyFmu);`.
#[macro_export]
macro_rules! fmu_tests {
    ($model:ty) => {
        $crate::fmi2::declare_fmi2_functions!();

        /// A new instance of the FMU under test, through the symbols its crate exports.
        #[allow(dead_code)]
        fn fmu() -> $crate::testing::Harness<$model> {
            $crate::testing::Harness::instantiate(linked_fmi2_functions(), "test")
        }

        #[test]
        fn variable_table_passes_the_layer_checks() {
            $crate::testing::check_variable_table::<$model>();
        }

        #[test]
        fn model_description_read_by_the_master_equals_the_table() {
            use $crate::FmuDescription;
            let xml = $crate::xml::model_description::<$model>();
            let md = ::shipsim::model_description::ModelDescription::parse(&xml)
                .expect("the master parses the model description");
            assert_eq!(
                md.co_simulation
                    .as_ref()
                    .map(|c| c.model_identifier.as_str()),
                Some(<$model>::MODEL_IDENTIFIER)
            );
            let outputs = md
                .model_structure
                .as_ref()
                .and_then(|s| s.outputs.clone())
                .unwrap_or_default()
                .unknowns;
            let parsed: Vec<_> = md
                .model_variables
                .variables
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    let (base_type, min, max, start) = if let Some(r) = &v.real {
                        (
                            "Real",
                            r.min.map($crate::xml::real),
                            r.max.map($crate::xml::real),
                            r.start.map($crate::xml::real),
                        )
                    } else if let Some(n) = &v.integer {
                        (
                            "Integer",
                            n.min.map(|x| x.to_string()),
                            n.max.map(|x| x.to_string()),
                            n.start.map(|x| x.to_string()),
                        )
                    } else if let Some(b) = &v.boolean {
                        ("Boolean", None, None, b.start.map(|x| x.to_string()))
                    } else {
                        ("other", None, None, None)
                    };
                    let output = outputs.iter().find(|u| u.index == i + 1);
                    $crate::testing::Declared {
                        name: v.name.clone(),
                        value_reference: v.value_reference,
                        description: v.description.clone().unwrap_or_default(),
                        causality: v.causality,
                        variability: v.variability,
                        initial: v.initial,
                        base_type,
                        unit: v.real.as_ref().and_then(|r| r.unit.clone()),
                        min,
                        max,
                        start,
                        dependencies: output.and_then(|u| u.dependency_indices()),
                    }
                })
                .collect();
            let table = $crate::testing::declared::<$model>();
            assert_eq!(parsed.len(), table.len());
            for (p, t) in parsed.iter().zip(&table) {
                assert_eq!(p, t);
            }
            let n_outputs = table
                .iter()
                .filter(|v| v.causality == $crate::Causality::Output)
                .count();
            assert_eq!(outputs.len(), n_outputs);
        }

        #[test]
        fn version_and_guid_are_checked() {
            $crate::testing::check_version_and_guid::<$model>(linked_fmi2_functions());
        }

        #[test]
        fn every_variable_reads_and_writes_by_name() {
            $crate::testing::check_every_variable::<$model>(linked_fmi2_functions());
        }

        #[test]
        fn state_rollback_is_exact() {
            $crate::testing::check_state_rollback::<$model>(linked_fmi2_functions());
        }

        #[test]
        fn sources_are_cited_by_key() {
            $crate::testing::check_sources_cited_by_key::<$model>();
        }
    };
}

#[cfg(test)]
mod tests {
    use super::bare_source_numbers;

    #[test]
    fn bare_source_numbers_are_found_and_numbers_are_not() {
        let found = |t: &str| bare_source_numbers(t).len();
        for cited in [
            "(003 Fig. 2.8, eq. 6.33)",
            "The OCR original of 003 (L 742-754)",
            "000's track tests",
            "(2000, source 000)",
            "seed 001.",
            "004: 0.5",
            "<td>002 DGPS</td>",
            "002",
        ] {
            assert_eq!(found(cited), 1, "{cited}");
        }
        assert_eq!(found("(003 and 000 give no levels)"), 2);
        for number in [
            "0.001",
            "lambda = 0.001)",
            "1,000 lines",
            "2003",
            "1.000e12",
            "0.0004",
            "x004",
            "004a",
            "[Klugt1987, Fig. 2.8]",
            "{3c0b1e52-0003-5004-a004-000000000042}",
        ] {
            assert_eq!(found(number), 0, "{number}");
        }
    }
}
