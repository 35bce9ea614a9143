//! The generic FMI 2.0 C API. Each function is what the `fmi2*` symbol of the same name does;
//! [`crate::export_fmu!`] forwards the symbols here. Every entry runs inside `catch_unwind`.

use crate::instance::{
    fnv1a, log_raw, mask, Core, Instance, LifeState, Snapshot, StateBox, CAT_CALLS, CAT_ERROR,
    CAT_EVENTS,
};
use crate::variables::{Access, Causality, Variability, Variable};
use crate::{FmuModel, LOG_CATEGORIES, MAX_INTERNAL_STEPS};
use fmi2::*;
use std::cell::{Cell, RefCell};
use std::ffi::{c_char, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe, PanicHookInfo};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

/// Layout version of serialized FMU states (bumped when [`Snapshot`] changes shape).
const SERIAL_VERSION: u32 = 1;

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".to_string()
    }
}

/// Where the panic being reported happened (` at file:line:column`; empty if the hook did not
/// see it).
fn panic_location() -> String {
    match PANIC_LOCATION.with(|l| l.borrow_mut().take()) {
        Some(at) => format!(" at {at}"),
        None => String::new(),
    }
}

thread_local! {
    /// Whether this thread is inside an FMI call of this library (see [`guarded`]).
    static IN_FMI_CALL: Cell<bool> = const { Cell::new(false) };
    /// Where the last panic inside an FMI call happened (kept by the panic hook for the log).
    static PANIC_LOCATION: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// This code was loaded as a shared library of its own (an FMU binary, a `cdylib` with its own
/// copy of the standard library), not linked into the program (a test of the export layer or
/// of an FMU crate). Set once by [`install_panic_hook`].
static SHARED_LIBRARY: AtomicBool = AtomicBool::new(false);

/// Whether this function lies in another object than the program's entry point
/// (`getauxval(AT_ENTRY)`, both located with `dladdr`).
#[cfg(target_os = "linux")]
fn loaded_as_shared_library() -> bool {
    // SAFETY: `dladdr` fills the given struct for any address; `getauxval` reads the process's
    // auxiliary vector.
    unsafe {
        let entry = libc::getauxval(libc::AT_ENTRY) as *const c_void;
        let mut ours: libc::Dl_info = std::mem::zeroed();
        let mut program: libc::Dl_info = std::mem::zeroed();
        if entry.is_null()
            || libc::dladdr(loaded_as_shared_library as *const c_void, &mut ours) == 0
            || libc::dladdr(entry, &mut program) == 0
        {
            return false;
        }
        ours.dli_fbase != program.dli_fbase
    }
}

#[cfg(not(target_os = "linux"))]
fn loaded_as_shared_library() -> bool {
    false
}

/// Installs, once per FMU library, a panic hook that stays silent for a panic of the FMU (the
/// FMI call catches it and reports it through the instance's logger as an fmi2Error message)
/// and defers to the hook it replaced for every other panic. An importer's stderr is not the
/// FMU's to write to (FMI 2.0, sec. 2.1.5: messages go through the logger).
///
/// In an FMU binary, every panic this hook sees is the FMU's: the library has its own copy of
/// the standard library (so the hook is its alone), and all its code runs inside FMI calls,
/// each under `catch_unwind`. There the hook is silent for every panic, in every call, the
/// getters and setters included, without a per-call flag. Linked into a program (tests), the
/// hook also sees the program's panics, and an FMI call marks its thread ([`guarded`]).
fn install_panic_hook() {
    static INSTALLED: Once = Once::new();
    INSTALLED.call_once(|| {
        let shared = loaded_as_shared_library();
        SHARED_LIBRARY.store(shared, Ordering::Relaxed);
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info: &PanicHookInfo| {
            if shared || IN_FMI_CALL.with(Cell::get) {
                let at = info.location().map(|l| l.to_string());
                PANIC_LOCATION.with(|l| *l.borrow_mut() = at);
            } else {
                previous(info)
            }
        }));
    });
}

/// `catch_unwind` of `f`, with the thread marked as inside an FMI call of this library when the
/// library is linked into a program (see [`install_panic_hook`]; in an FMU binary no mark is
/// needed, and none is made: a thread-local access there is a `__tls_get_addr` call).
#[inline(always)]
fn guarded<R>(f: impl FnOnce() -> R) -> std::thread::Result<R> {
    let mark = !SHARED_LIBRARY.load(Ordering::Relaxed);
    let outer = mark && IN_FMI_CALL.with(|flag| flag.replace(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    if mark {
        IN_FMI_CALL.with(|flag| flag.set(outer));
    }
    result
}

/// Runs `f` on the instance behind `c` if `function` is legal in its state; a panic becomes
/// fmi2Error, the instance moves to the Error state and the panic is logged.
///
/// Inlined into every entry, with the error paths out of line (`#[cold]`), so that a legal call
/// costs a null test, a state-mask test, a logging-flag test and the body: `catch_unwind` costs
/// nothing unless a panic unwinds.
#[inline(always)]
unsafe fn with_instance<M: FmuModel>(
    c: fmi2Component,
    function: &str,
    legal: u32,
    f: impl FnOnce(&mut Instance<M>) -> fmi2Status,
) -> fmi2Status {
    with_instance_marked::<M, true>(c, function, legal, f)
}

/// [`with_instance`] with the thread marked for the panic hook (`MARK`, see [`guarded`]) or
/// not. The getters and setters (`fmi2Get*`, `fmi2Set*`, a master's most frequent calls) run
/// unmarked, a plain `catch_unwind`: in an FMU binary the hook is silent for every panic
/// anyway, and running them through [`guarded`] cost 2.9 % more instructions on the RRS system
/// (cachegrind). A panic in them is caught and logged in every build; linked into a test
/// program it also reaches the program's hook.
#[inline(always)]
unsafe fn with_instance_marked<M: FmuModel, const MARK: bool>(
    c: fmi2Component,
    function: &str,
    legal: u32,
    f: impl FnOnce(&mut Instance<M>) -> fmi2Status,
) -> fmi2Status {
    if c.is_null() {
        return fmi2Error;
    }
    let inst = c as *mut Instance<M>;
    // SAFETY: `c` was returned by `instantiate::<M>` and not freed (importer contract).
    if let Err(status) = (*inst).check_state(function, legal) {
        return status;
    }
    let result = if MARK {
        guarded(|| f(&mut *inst))
    } else {
        catch_unwind(AssertUnwindSafe(|| f(&mut *inst)))
    };
    match result {
        Ok(status) => status,
        Err(p) => panicked(&mut *inst, function, p.as_ref()),
    }
}

/// A panic caught in `function`: the instance moves to the Error state and the panic is logged.
#[cold]
#[inline(never)]
fn panicked<M: FmuModel>(
    inst: &mut Instance<M>,
    function: &str,
    p: &(dyn std::any::Any + Send),
) -> fmi2Status {
    inst.core.state = LifeState::Error;
    inst.log(
        fmi2Error,
        CAT_ERROR,
        &format!(
            "{function}: internal error (panic: {}){}; the instance is in the Error state \
             (fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance)",
            panic_message(p),
            panic_location()
        ),
    );
    fmi2Error
}

/// An error status and a log line with `message` (out of line: only failures build messages).
#[cold]
#[inline(never)]
fn fail<M: FmuModel>(inst: &Instance<M>, message: std::fmt::Arguments) -> fmi2Status {
    inst.error(&message.to_string())
}

/// `function` got NULL for an array of `n` > 0 values. (The failures of the calls a step loop
/// makes take their arguments by value, so that the success path keeps them in registers.)
#[cold]
#[inline(never)]
fn null_array<M: FmuModel>(inst: &Instance<M>, function: &str, n: usize) -> fmi2Status {
    fail(inst, format_args!("{function}: NULL array with nvr = {n}"))
}

/// `fmi2GetTypesPlatform`.
pub fn get_types_platform<M: FmuModel>() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`.
pub fn get_version<M: FmuModel>() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2Instantiate`: NULL (with a log line where possible) on a missing/wrong GUID, a missing
/// instance name, a non-co-simulation type or missing callbacks.
///
/// # Safety
/// Arguments as the FMI 2.0 standard defines them.
pub unsafe fn instantiate<M: FmuModel>(
    name: fmi2String,
    kind: fmi2Type,
    guid: fmi2String,
    _resources: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    install_panic_hook();
    let result = guarded(|| {
        if functions.is_null() {
            return std::ptr::null_mut();
        }
        let functions = *functions;
        let (logger, env) = (functions.logger, functions.componentEnvironment);
        let name_c = if name.is_null() {
            CString::default()
        } else {
            CStr::from_ptr(name).to_owned()
        };
        let fail = |msg: &str| {
            log_raw(
                logger,
                env,
                &name_c,
                fmi2Error,
                LOG_CATEGORIES[CAT_ERROR].0,
                msg,
            );
            std::ptr::null_mut()
        };
        if name_c.as_bytes().is_empty() {
            return fail(&format!(
                "fmi2Instantiate ({}): missing instance name",
                M::MODEL_IDENTIFIER
            ));
        }
        if kind != fmi2CoSimulation {
            return fail(&format!(
                "fmi2Instantiate: {} supports only fmi2CoSimulation (fmuType = {kind})",
                M::MODEL_IDENTIFIER
            ));
        }
        // The start values, built once for the instance and, on the first call, the GUID.
        let model = M::default();
        let expected = crate::xml::guid_str_with(&model);
        if guid.is_null() {
            return fail("fmi2Instantiate: missing GUID");
        }
        let given = CStr::from_ptr(guid).to_string_lossy();
        if given != expected {
            return fail(&format!(
                "fmi2Instantiate: wrong GUID {given}; {} expects {expected} (modelDescription.xml \
                 and binary do not belong together)",
                M::MODEL_IDENTIFIER
            ));
        }
        let inst = Instance::<M>::new(
            model,
            name_c.clone(),
            logger,
            env,
            logging_on != fmi2False,
            fnv1a(expected.as_bytes()),
        );
        inst.log_fmt(
            fmi2OK,
            CAT_EVENTS,
            format_args!("instantiated {} {expected}", M::MODEL_IDENTIFIER),
        );
        Box::into_raw(Box::new(inst)) as fmi2Component
    });
    result.unwrap_or(std::ptr::null_mut())
}

/// # Safety
/// `c` must come from `instantiate::<M>` and not be used afterwards.
pub unsafe fn free_instance<M: FmuModel>(c: fmi2Component) {
    if c.is_null() {
        return;
    }
    let _ = guarded(|| {
        drop(Box::from_raw(c as *mut Instance<M>));
    });
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn set_debug_logging<M: FmuModel>(
    c: fmi2Component,
    on: fmi2Boolean,
    n: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2SetDebugLogging", mask::SET_DEBUG_LOGGING, |inst| {
        let on = on != fmi2False;
        if n == 0 {
            // On: "all debug messages shall be printed"; off: debug logging is switched off
            // (FMI 2.0, sec. 2.1.5). Errors and warnings are not debug messages: they stay on.
            inst.enabled[CAT_EVENTS] = on;
            inst.enabled[CAT_CALLS] = on;
            return fmi2OK;
        }
        if categories.is_null() {
            return inst.error("fmi2SetDebugLogging: categories is NULL but nCategories > 0");
        }
        for i in 0..n {
            let p = *categories.add(i);
            let name = lossy_str(p);
            match LOG_CATEGORIES.iter().position(|(c, _)| *c == name) {
                Some(k) => inst.enabled[k] = on,
                None => {
                    return inst.error(&format!(
                        "fmi2SetDebugLogging: unknown log category {name:?}; known: {}",
                        LOG_CATEGORIES.map(|(c, _)| c).join(", ")
                    ))
                }
            }
        }
        fmi2OK
    })
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn setup_experiment<M: FmuModel>(
    c: fmi2Component,
    _tol_defined: fmi2Boolean,
    _tol: fmi2Real,
    start: fmi2Real,
    stop_defined: fmi2Boolean,
    stop: fmi2Real,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2SetupExperiment", mask::SETUP_EXPERIMENT, |inst| {
        if !start.is_finite() {
            return inst.error(&format!(
                "fmi2SetupExperiment: startTime = {start} is not finite"
            ));
        }
        let stop = if stop_defined != fmi2False {
            if !(stop.is_finite() && stop >= start) {
                return inst.error(&format!(
                    "fmi2SetupExperiment: stopTime = {stop} must be finite and >= startTime = {start}"
                ));
            }
            Some(stop)
        } else {
            None
        };
        inst.core.start_time = start;
        inst.core.time = start;
        inst.core.stop_time = stop;
        fmi2OK
    })
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn enter_initialization_mode<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    with_instance::<M>(
        c,
        "fmi2EnterInitializationMode",
        mask::ENTER_INITIALIZATION_MODE,
        |inst| {
            inst.core.state = LifeState::InitializationMode;
            fmi2OK
        },
    )
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn exit_initialization_mode<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    with_instance::<M>(
        c,
        "fmi2ExitInitializationMode",
        mask::EXIT_INITIALIZATION_MODE,
        |inst| match inst.model.initialize(inst.core.start_time) {
            Ok(()) => {
                inst.dirty = false;
                inst.work_limit = 0.0;
                if let Some(vr) = inst.fast.non_finite_output(&inst.model) {
                    inst.core.state = LifeState::Error;
                    let t = inst.core.start_time;
                    return non_finite_output(
                        inst,
                        "fmi2ExitInitializationMode",
                        format_args!("at t = {t}"),
                        vr,
                    );
                }
                inst.core.state = LifeState::StepComplete;
                inst.log_fmt(
                    fmi2OK,
                    CAT_EVENTS,
                    format_args!("initialized at t = {}", inst.core.start_time),
                );
                fmi2OK
            }
            Err(msg) => {
                inst.core.state = LifeState::Error;
                inst.error(&format!("fmi2ExitInitializationMode: {msg}"))
            }
        },
    )
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn terminate<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    with_instance::<M>(c, "fmi2Terminate", mask::TERMINATE, |inst| {
        inst.core.state = LifeState::Terminated;
        inst.log_fmt(
            fmi2OK,
            CAT_EVENTS,
            format_args!("terminated at t = {}", inst.core.time),
        );
        fmi2OK
    })
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn reset<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    with_instance::<M>(c, "fmi2Reset", mask::RESET, |inst| {
        inst.model = M::default();
        inst.core = Core {
            state: LifeState::Instantiated,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
        };
        inst.dirty = true;
        inst.work_limit = 0.0;
        inst.log(fmi2OK, CAT_EVENTS, "reset to the start values");
        fmi2OK
    })
}

/// Looks up `vr` and checks the base type; the error names the function and the reference.
#[inline(always)]
fn lookup<'a, M: FmuModel>(
    inst: &Instance<M>,
    function: &str,
    vr: fmi2ValueReference,
    expected: crate::BaseType,
) -> Result<&'a Variable<M>, fmi2Status> {
    match M::variables().get(vr as usize) {
        Some(v) if v.base_type() == expected => Ok(v),
        found => Err(lookup_error(inst, function, vr, expected, found)),
    }
}

#[cold]
#[inline(never)]
fn lookup_error<M: FmuModel>(
    inst: &Instance<M>,
    function: &str,
    vr: fmi2ValueReference,
    expected: crate::BaseType,
    found: Option<&Variable<M>>,
) -> fmi2Status {
    match found {
        Some(v) => inst.error(&format!(
            "{function}: value reference {vr} is {} {:?}, not a {expected} variable",
            v.base_type(),
            v.name
        )),
        None => inst.error(&format!(
            "{function}: no variable with value reference {vr} in {} (valid: 0..{})",
            M::MODEL_IDENTIFIER,
            M::variables().len().saturating_sub(1)
        )),
    }
}

/// Checks that `v` may be set in the current state (FMI 2.0 section 4.2.4 and the variability
/// rules: fixed parameters only before initialization is left; tunable parameters and inputs also
/// in StepComplete; nothing else ever).
#[inline(always)]
fn check_settable<M: FmuModel>(inst: &Instance<M>, function: &str, v: &Variable<M>) -> fmi2Status {
    let fixed_after_init = inst.core.state == LifeState::StepComplete
        && v.causality == Causality::Parameter
        && v.variability == Variability::Fixed;
    if v.settable() && !fixed_after_init {
        fmi2OK
    } else {
        not_settable(inst, function, v)
    }
}

#[cold]
#[inline(never)]
fn not_settable<M: FmuModel>(inst: &Instance<M>, function: &str, v: &Variable<M>) -> fmi2Status {
    if !v.settable() {
        return inst.error(&format!(
            "{function}: variable {:?} has causality {:?} and cannot be set",
            v.name, v.causality
        ));
    }
    inst.error(&format!(
        "{function}: fixed parameter {:?} cannot be changed after initialization",
        v.name
    ))
}

/// In Initialization Mode the outputs (InitialUnknowns) must reflect the parameters and start
/// values set so far (FMI 2.0 sections 3.2.3 and 4.2.4): rebuild the model from them.
/// `initialize` is idempotent; an error is reported by fmi2ExitInitializationMode.
#[cold]
#[inline(never)]
fn initial_outputs<M: FmuModel>(inst: &mut Instance<M>) {
    if inst.model.initialize(inst.core.start_time).is_ok() {
        inst.model.calculate_outputs();
    }
    inst.dirty = false;
}

/// Brings the outputs up to date for a getter after an input or parameter changed: from the
/// parameters and start values in Initialization Mode ([`initial_outputs`]), else by
/// `calculate_outputs`. Out of line: a master's step sets inputs and steps before it reads, and
/// `fmi2DoStep` leaves the outputs current.
#[inline(never)]
fn update_outputs<M: FmuModel>(inst: &mut Instance<M>) {
    if inst.core.state == LifeState::InitializationMode {
        initial_outputs(inst);
    } else {
        inst.refresh_outputs();
    }
}

/// The finiteness check of the values `fmi2GetReal` hands out compiled in: always, except in
/// the variant that `cargo xtask bench` builds with `--cfg shipsim_no_output_check` to measure
/// what the check costs (the "output check" row of docs/bench.md; issue 19: at most 1 %).
const OUTPUT_CHECK: bool = !cfg!(shipsim_no_output_check);

/// A value a getter hands out: the bits of `x - x` for a Real (±0.0 when finite, +0.0 unless
/// the importer rounds downward; a NaN's bits, nonzero without the sign bit, for NaN and the
/// infinities), 0 for the other types. A getter ORs them
/// over its values in an integer register, which survives the getters' indirect calls (a
/// floating-point sum is spilled around each: about 0.3 % more of the RRS system).
trait Handed: Copy {
    fn not_finite(self) -> u64;
}

impl Handed for f64 {
    #[inline(always)]
    #[allow(clippy::eq_op)] // x - x: 0 or NaN, the point of the test
    fn not_finite(self) -> u64 {
        (self - self).to_bits()
    }
}

impl Handed for i32 {
    #[inline(always)]
    fn not_finite(self) -> u64 {
        0
    }
}

/// Shared body of the typed getters. `fast` reads a value reference that the fast path knows
/// (Real variables, [`crate::fast`]); any other goes through the table, which checks its type and
/// names a wrong one, and `read` reads it. No non-finite Real leaves with fmi2OK: the values'
/// [`Handed::not_finite`] are ORed in the same loop (three instructions per Real, none for the
/// other types) and a nonzero result is an error naming the variable.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
unsafe fn get_values<M: FmuModel, T: Handed>(
    c: fmi2Component,
    function: &str,
    base: crate::BaseType,
    vr: *const fmi2ValueReference,
    n: usize,
    out: *mut T,
    fast: impl Fn(&Instance<M>, fmi2ValueReference) -> Option<T>,
    read: impl Fn(&Variable<M>, &M) -> T,
) -> fmi2Status {
    with_instance_marked::<M, false>(c, function, mask::GET, |inst| {
        if n == 0 {
            return fmi2OK;
        }
        if vr.is_null() || out.is_null() {
            return null_array(inst, function, n);
        }
        if inst.dirty {
            update_outputs(inst);
        }
        let vrs = std::slice::from_raw_parts(vr, n);
        let mut bad = 0u64;
        for (i, &r) in vrs.iter().enumerate() {
            let x = match fast(inst, r) {
                Some(x) => x,
                None => match get_by_table(inst, function, base, r, &read) {
                    Ok(x) => x,
                    Err(s) => return s,
                },
            };
            if OUTPUT_CHECK {
                bad |= x.not_finite();
            }
            *out.add(i) = x;
        }
        // Shifted out: the sign bit, which a finite x - x has set when the importer rounds
        // downward (fesetround(FE_DOWNWARD) makes it -0.0).
        if bad << 1 != 0 {
            let values = std::slice::from_raw_parts(out, n);
            return non_finite_value(inst, vrs, values);
        }
        fmi2OK
    })
}

/// One value of a getter through the variable table (its type checked). Out of line and
/// `#[cold]`, so that the fast path's loop stays small and keeps its values in registers.
#[cold]
#[inline(never)]
fn get_by_table<M: FmuModel, T>(
    inst: &Instance<M>,
    function: &str,
    base: crate::BaseType,
    r: fmi2ValueReference,
    read: &impl Fn(&Variable<M>, &M) -> T,
) -> Result<T, fmi2Status> {
    lookup(inst, function, r, base).map(|v| read(v, &inst.model))
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_real<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    out: *mut fmi2Real,
) -> fmi2Status {
    get_values::<M, f64>(
        c,
        "fmi2GetReal",
        crate::BaseType::Real,
        vr,
        n,
        out,
        |inst, r| {
            let get = inst.fast.get_real.get(r as usize).copied().flatten()?;
            Some(get(&inst.model))
        },
        |v, m| match v.access {
            Access::Real { get, .. } => get(m),
            _ => unreachable!("type checked by lookup"),
        },
    )
}

/// A value `fmi2GetReal` read is not a finite number: fmi2Error naming the variable, its value
/// and the time; the instance moves to the Error state (the FMU produced it).
#[cold]
#[inline(never)]
fn non_finite_value<M: FmuModel, T: Handed>(
    inst: &mut Instance<M>,
    vrs: &[fmi2ValueReference],
    values: &[T],
) -> fmi2Status {
    let Some(k) = values.iter().position(|x| x.not_finite() << 1 != 0) else {
        return fmi2OK;
    };
    inst.core.state = LifeState::Error;
    let t = inst.core.time;
    non_finite_output(inst, "fmi2GetReal", format_args!("at t = {t}"), vrs[k])
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_integer<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    out: *mut fmi2Integer,
) -> fmi2Status {
    get_values::<M, i32>(
        c,
        "fmi2GetInteger",
        crate::BaseType::Integer,
        vr,
        n,
        out,
        |_, _| None,
        |v, m| match v.access {
            Access::Integer { get, .. } => get(m),
            _ => unreachable!("type checked by lookup"),
        },
    )
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_boolean<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    out: *mut fmi2Boolean,
) -> fmi2Status {
    get_values::<M, fmi2Boolean>(
        c,
        "fmi2GetBoolean",
        crate::BaseType::Boolean,
        vr,
        n,
        out,
        |_, _| None,
        |v, m| match v.access {
            Access::Boolean { get, .. } => get(m) as fmi2Boolean,
            _ => unreachable!("type checked by lookup"),
        },
    )
}

/// No String variables exist: any value reference is an error.
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_string<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    _out: *mut fmi2String,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2GetString", mask::GET, |inst| {
        if n == 0 {
            return fmi2OK;
        }
        let first = if vr.is_null() { 0 } else { *vr };
        inst.error(&format!(
            "fmi2GetString: {} has no String variables (value reference {first})",
            M::MODEL_IDENTIFIER
        ))
    })
}

/// Shared body of the typed setters. `fast` writes a value that the fast path accepts (a Real
/// input within its range, [`crate::fast`]) and says whether it did; any other value goes
/// through the table: its type and causality are checked, and `apply` validates the value and
/// writes it; it returns the old value of a parameter (`None` for an input, which is never
/// restored) or an error message naming the variable on refusal. A tunable parameter changed in
/// StepComplete is checked by `parameters_changed` and restored on refusal.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
unsafe fn set_values<M: FmuModel, T: Copy>(
    c: fmi2Component,
    function: &'static str,
    base: crate::BaseType,
    legal: u32,
    vr: *const fmi2ValueReference,
    n: usize,
    values: *const T,
    fast: impl Fn(&mut Instance<M>, fmi2ValueReference, T) -> bool,
    apply: impl Fn(&Variable<M>, &mut M, T) -> Result<Option<T>, String>,
) -> fmi2Status {
    with_instance_marked::<M, false>(c, function, legal, |inst| {
        if n == 0 {
            return fmi2OK;
        }
        if vr.is_null() || values.is_null() {
            return null_array(inst, function, n);
        }
        let vrs = std::slice::from_raw_parts(vr, n);
        let vals = std::slice::from_raw_parts(values, n);
        for (&r, &x) in vrs.iter().zip(vals) {
            if fast(inst, r, x) {
                inst.dirty = true;
            } else {
                let s = set_by_table(inst, function, base, r, x, &apply);
                if s != fmi2OK {
                    return s;
                }
            }
        }
        fmi2OK
    })
}

/// One value of a setter through the variable table: type, causality and state checked, the
/// value validated and written by `apply`, a tunable parameter changed in StepComplete checked
/// by `parameters_changed`. Out of line and `#[cold]`, so that the fast path's loop stays small
/// and keeps its values in registers.
#[cold]
#[inline(never)]
fn set_by_table<M: FmuModel, T: Copy>(
    inst: &mut Instance<M>,
    function: &str,
    base: crate::BaseType,
    r: fmi2ValueReference,
    x: T,
    apply: &impl Fn(&Variable<M>, &mut M, T) -> Result<Option<T>, String>,
) -> fmi2Status {
    let v = match lookup(inst, function, r, base) {
        Ok(v) => v,
        Err(s) => return s,
    };
    let s = check_settable(inst, function, v);
    if s != fmi2OK {
        return s;
    }
    let old = match apply(v, &mut inst.model, x) {
        Ok(old) => old,
        Err(msg) => {
            return fail(
                inst,
                format_args!(
                    "{function}: instance {:?}: {msg}",
                    inst.name.to_string_lossy()
                ),
            )
        }
    };
    inst.dirty = true;
    inst.work_limit = 0.0;
    if inst.core.state == LifeState::StepComplete && v.causality == Causality::Parameter {
        return tunable_changed(inst, function, v, old, apply);
    }
    fmi2OK
}

/// A tunable parameter changed in StepComplete: `parameters_changed` checks it; on refusal the
/// old value is restored and the error names the variable.
#[inline(never)]
fn tunable_changed<M: FmuModel, T>(
    inst: &mut Instance<M>,
    function: &str,
    v: &Variable<M>,
    old: Option<T>,
    apply: &impl Fn(&Variable<M>, &mut M, T) -> Result<Option<T>, String>,
) -> fmi2Status {
    match inst.model.parameters_changed() {
        Ok(()) => fmi2OK,
        Err(msg) => {
            if let Some(old) = old {
                let _ = apply(v, &mut inst.model, old);
            }
            inst.error(&format!(
                "{function}: instance {:?}: refused {:?}: {msg}",
                inst.name.to_string_lossy(),
                v.name
            ))
        }
    }
}

/// The old value of `v`, read only for a parameter (the only kind `set_values` restores).
#[inline(always)]
fn old_value<M, T>(v: &Variable<M>, m: &M, get: fn(&M) -> T) -> Option<T> {
    (v.causality == Causality::Parameter).then(|| get(m))
}

/// A refusal message (out of line: only refusals build messages).
#[cold]
#[inline(never)]
fn refused(message: std::fmt::Arguments) -> String {
    message.to_string()
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn set_real<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    values: *const fmi2Real,
) -> fmi2Status {
    set_values::<M, f64>(
        c,
        "fmi2SetReal",
        crate::BaseType::Real,
        mask::SET_REAL,
        vr,
        n,
        values,
        |inst, r, x| match inst.fast.set_real.get(r as usize) {
            Some(input) if input.accepts(x) => {
                (input.set)(&mut inst.model, x);
                true
            }
            _ => false,
        },
        |v, m, x| match v.access {
            Access::Real {
                get, set, min, max, ..
            } => {
                if !x.is_finite() {
                    return Err(refused(format_args!(
                        "{:?} = {} refused: not a finite number",
                        v.name,
                        Num(x)
                    )));
                }
                if min.is_some_and(|lo| x < lo) || max.is_some_and(|hi| x > hi) {
                    return Err(refused(format_args!(
                        "{:?} = {} refused: outside [{}, {}]",
                        v.name,
                        Num(x),
                        Num(min.unwrap_or(f64::NEG_INFINITY)),
                        Num(max.unwrap_or(f64::INFINITY))
                    )));
                }
                let old = old_value(v, m, get);
                (set.expect("settable variables have setters (check_table)"))(m, x);
                Ok(old)
            }
            _ => unreachable!("type checked by lookup"),
        },
    )
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn set_integer<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    values: *const fmi2Integer,
) -> fmi2Status {
    set_values::<M, i32>(
        c,
        "fmi2SetInteger",
        crate::BaseType::Integer,
        mask::SET_OTHER,
        vr,
        n,
        values,
        |_, _, _| false,
        |v, m, x| match v.access {
            Access::Integer { get, set, min, max } => {
                if min.is_some_and(|lo| x < lo) || max.is_some_and(|hi| x > hi) {
                    return Err(refused(format_args!(
                        "{:?} = {x} refused: outside [{}, {}]",
                        v.name,
                        min.unwrap_or(i32::MIN),
                        max.unwrap_or(i32::MAX)
                    )));
                }
                let old = old_value(v, m, get);
                (set.expect("settable variables have setters (check_table)"))(m, x);
                Ok(old)
            }
            _ => unreachable!("type checked by lookup"),
        },
    )
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn set_boolean<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    values: *const fmi2Boolean,
) -> fmi2Status {
    set_values::<M, fmi2Boolean>(
        c,
        "fmi2SetBoolean",
        crate::BaseType::Boolean,
        mask::SET_OTHER,
        vr,
        n,
        values,
        |_, _, _| false,
        |v, m, x| match v.access {
            Access::Boolean { get, set } => {
                let old = old_value(v, m, get).map(|b| b as fmi2Boolean);
                (set.expect("settable variables have setters (check_table)"))(m, x != fmi2False);
                Ok(old)
            }
            _ => unreachable!("type checked by lookup"),
        },
    )
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn set_string<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    _values: *const fmi2String,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2SetString", mask::SET_OTHER, |inst| {
        if n == 0 {
            return fmi2OK;
        }
        let first = if vr.is_null() { 0 } else { *vr };
        inst.error(&format!(
            "fmi2SetString: {} has no String variables (value reference {first})",
            M::MODEL_IDENTIFIER
        ))
    })
}

/// The state `s` points to, if this instance handed it out and it was not freed (looked up in
/// [`Instance::states`] before the pointer is read); otherwise fmi2Error naming the call.
unsafe fn state_ref<'a, M: FmuModel>(
    inst: &Instance<M>,
    function: &str,
    s: fmi2FMUstate,
) -> Result<&'a mut StateBox<M>, fmi2Status> {
    if s.is_null() {
        return Err(inst.error(&format!("{function}: FMU state is NULL")));
    }
    if !inst.states.contains(&(s as usize)) {
        return Err(inst.error(&format!(
            "{function}: FMU state {s:p} was not created by this instance of {} or was \
             already freed",
            M::MODEL_IDENTIFIER
        )));
    }
    // SAFETY: a live `StateBox<M>` of this instance (registered when created, removed when
    // freed).
    Ok(&mut *(s as *mut StateBox<M>))
}

/// A new FMU state holding `snapshot`, registered with the instance.
fn new_state<M: FmuModel>(inst: &mut Instance<M>, snapshot: Snapshot<M>) -> fmi2FMUstate {
    let s = Box::into_raw(Box::new(StateBox {
        magic: inst.magic,
        snapshot,
    })) as fmi2FMUstate;
    inst.states.push(s as usize);
    s
}

/// `fmi2GetFMUstate`: a new snapshot, or overwrites the one `*s` points to.
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_fmu_state<M: FmuModel>(c: fmi2Component, s: *mut fmi2FMUstate) -> fmi2Status {
    with_instance::<M>(c, "fmi2GetFMUstate", mask::FMU_STATE, |inst| {
        if s.is_null() {
            return inst.error("fmi2GetFMUstate: FMUstate pointer is NULL");
        }
        inst.refresh_outputs();
        let snapshot = Snapshot {
            model: inst.model.clone(),
            core: inst.core.clone(),
        };
        if (*s).is_null() {
            *s = new_state(inst, snapshot);
        } else {
            match state_ref::<M>(inst, "fmi2GetFMUstate", *s) {
                Ok(b) => b.snapshot = snapshot,
                Err(st) => return st,
            }
        }
        fmi2OK
    })
}

/// `fmi2SetFMUstate`: restores model, time and lifecycle state.
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn set_fmu_state<M: FmuModel>(c: fmi2Component, s: fmi2FMUstate) -> fmi2Status {
    with_instance::<M>(
        c,
        "fmi2SetFMUstate",
        mask::FMU_STATE,
        |inst| match state_ref::<M>(inst, "fmi2SetFMUstate", s) {
            Ok(b) => {
                if let Err(msg) = check_snapshot(&b.snapshot) {
                    return refused_state(inst, "fmi2SetFMUstate", &msg);
                }
                inst.model = b.snapshot.model.clone();
                inst.core = b.snapshot.core.clone();
                inst.dirty = false;
                inst.work_limit = 0.0;
                inst.log_fmt(
                    fmi2OK,
                    CAT_EVENTS,
                    format_args!("state restored to t = {}", inst.core.time),
                );
                fmi2OK
            }
            Err(st) => st,
        },
    )
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn free_fmu_state<M: FmuModel>(c: fmi2Component, s: *mut fmi2FMUstate) -> fmi2Status {
    with_instance::<M>(c, "fmi2FreeFMUstate", mask::FMU_STATE, |inst| {
        if s.is_null() || (*s).is_null() {
            return fmi2OK;
        }
        match state_ref::<M>(inst, "fmi2FreeFMUstate", *s) {
            Ok(b) => {
                inst.states.retain(|&a| a != *s as usize);
                drop(Box::from_raw(b as *mut StateBox<M>));
                *s = std::ptr::null_mut();
                fmi2OK
            }
            Err(st) => st,
        }
    })
}

/// What a restored FMU state must satisfy, as the setters and the step enforce it on the way
/// in (the bytes of a serialized state, or a state a caller wrote over, prove nothing): the times
/// finite; every parameter and input finite and within its declared range (as `fmi2SetReal` and
/// `fmi2SetInteger` enforce); every internal loop of the model a positive length
/// ([`FmuModel::internal_steps`]); and the model's own checks ([`FmuModel::check_restored`]).
/// The message names the value.
fn check_snapshot<M: FmuModel>(snap: &Snapshot<M>) -> Result<(), String> {
    let core = &snap.core;
    for (name, t) in [
        ("time", core.time),
        ("startTime", core.start_time),
        ("stopTime", core.stop_time.unwrap_or(0.0)),
    ] {
        if !t.is_finite() {
            return Err(format!("{name} = {t} is not finite"));
        }
    }
    let m = &snap.model;
    let settable =
        |v: &&Variable<M>| matches!(v.causality, Causality::Parameter | Causality::Input);
    for v in M::variables().iter().filter(settable) {
        let out_of_range = match v.access {
            Access::Real { get, min, max, .. } => {
                let x = get(m);
                let inside =
                    x.is_finite() && min.is_none_or(|lo| x >= lo) && max.is_none_or(|hi| x <= hi);
                (!inside).then(|| (format!("{x:?}"), real_range(min, max)))
            }
            Access::Integer { get, min, max, .. } => {
                let x = get(m);
                let inside = min.is_none_or(|lo| x >= lo) && max.is_none_or(|hi| x <= hi);
                let range = || {
                    let (lo, hi) = (min.unwrap_or(i32::MIN), max.unwrap_or(i32::MAX));
                    format!("[{lo}, {hi}]")
                };
                (!inside).then(|| (x.to_string(), range()))
            }
            Access::Boolean { .. } => None,
        };
        if let Some((x, range)) = out_of_range {
            return Err(format!(
                "{:?} = {x} is not a finite number in {range}",
                v.name
            ));
        }
    }
    // Every loop's length is a positive number and, where the model keeps a copy of the
    // parameter that sets it (a noise grid's step, a sample interval), obeys the parameter's
    // declared minimum, as `fmi2SetReal` does.
    let mut bad = None;
    m.internal_steps(core.time, 0.0, &mut |name, length, _| {
        let lo = declared_min_seconds::<M>(name).unwrap_or(0.0);
        if bad.is_none() && !positive(length) {
            bad = Some(format!(
                "internal step {name} = {length:?} s is not a positive number"
            ));
        } else if bad.is_none() && !length.ge(&lo) {
            bad = Some(format!(
                "internal step {name} = {length:?} s is below its declared minimum {lo:?} s"
            ));
        }
    });
    bad.map_or(Ok(()), Err)?;
    // After initialization the loops are at the state's time: a step of length 0 from it takes
    // no passes but those of a grid that lags behind (before, `initialize` rebuilds them).
    if !matches!(
        core.state,
        LifeState::Instantiated | LifeState::InitializationMode
    ) {
        work(m, core.time, 0.0)?;
    }
    m.check_restored(core.time)
}

/// The declared minimum of the Real parameter `name` if its unit is the second (the lengths of
/// [`FmuModel::internal_steps`] are in seconds; a parameter in other units is not compared).
fn declared_min_seconds<M: FmuModel>(name: &str) -> Option<f64> {
    let v = M::variables().iter().find(|v| v.name == name)?;
    match v.access {
        Access::Real {
            unit: Some("s"),
            min,
            ..
        } if v.causality == Causality::Parameter => min,
        _ => None,
    }
}

/// Whether `x` is a positive number (false for NaN).
#[inline(always)]
fn positive(x: f64) -> bool {
    x > 0.0
}

fn real_range(min: Option<f64>, max: Option<f64>) -> String {
    let (lo, hi) = (
        min.unwrap_or(f64::NEG_INFINITY),
        max.unwrap_or(f64::INFINITY),
    );
    format!("[{lo:?}, {hi:?}]")
}

/// A restored state refused by [`check_snapshot`]; the instance is left as it was.
#[cold]
#[inline(never)]
fn refused_state<M: FmuModel>(inst: &Instance<M>, function: &str, msg: &str) -> fmi2Status {
    inst.error(&format!(
        "{function}: instance {:?}: the FMU state is refused: {msg}",
        inst.name.to_string_lossy()
    ))
}

fn serialize_snapshot<M: FmuModel>(magic: u64, snap: &Snapshot<M>) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::with_capacity(64);
    bytes.extend_from_slice(&magic.to_le_bytes());
    bytes.extend_from_slice(&SERIAL_VERSION.to_le_bytes());
    bincode::serialize_into(&mut bytes, snap).map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn serialized_fmu_state_size<M: FmuModel>(
    c: fmi2Component,
    s: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2SerializedFMUstateSize", mask::FMU_STATE, |inst| {
        if size.is_null() {
            return inst.error("fmi2SerializedFMUstateSize: size pointer is NULL");
        }
        match state_ref::<M>(inst, "fmi2SerializedFMUstateSize", s) {
            Ok(b) => match bincode::serialized_size(&b.snapshot) {
                Ok(n) => {
                    *size = n as usize + 12;
                    fmi2OK
                }
                Err(e) => inst.error(&format!("fmi2SerializedFMUstateSize: {e}")),
            },
            Err(st) => st,
        }
    })
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn serialize_fmu_state<M: FmuModel>(
    c: fmi2Component,
    s: fmi2FMUstate,
    out: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2SerializeFMUstate", mask::FMU_STATE, |inst| {
        let b = match state_ref::<M>(inst, "fmi2SerializeFMUstate", s) {
            Ok(b) => b,
            Err(st) => return st,
        };
        let bytes = match serialize_snapshot(inst.magic, &b.snapshot) {
            Ok(v) => v,
            Err(e) => return inst.error(&format!("fmi2SerializeFMUstate: {e}")),
        };
        if out.is_null() || size != bytes.len() {
            return inst.error(&format!(
                "fmi2SerializeFMUstate: buffer of {size} bytes given, {} needed \
                 (fmi2SerializedFMUstateSize)",
                bytes.len()
            ));
        }
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), out as *mut u8, size);
        fmi2OK
    })
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn deserialize_fmu_state<M: FmuModel>(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    s: *mut fmi2FMUstate,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2DeSerializeFMUstate", mask::FMU_STATE, |inst| {
        if bytes.is_null() || s.is_null() {
            return inst.error("fmi2DeSerializeFMUstate: NULL argument");
        }
        let data = std::slice::from_raw_parts(bytes as *const u8, size);
        if size < 12 || data[..8] != inst.magic.to_le_bytes() {
            return inst.error(&format!(
                "fmi2DeSerializeFMUstate: the {size} bytes are not a serialized state of this \
                 {} (GUID mismatch)",
                M::MODEL_IDENTIFIER
            ));
        }
        let version = u32::from_le_bytes([data[8], data[9], data[10], data[11]]);
        if version != SERIAL_VERSION {
            return inst.error(&format!(
                "fmi2DeSerializeFMUstate: serialized state layout {version}, expected \
                 {SERIAL_VERSION}"
            ));
        }
        let snapshot: Snapshot<M> = match bincode::deserialize(&data[12..]) {
            Ok(v) => v,
            Err(e) => return inst.error(&format!("fmi2DeSerializeFMUstate: corrupt state: {e}")),
        };
        if let Err(msg) = check_snapshot(&snapshot) {
            return refused_state(inst, "fmi2DeSerializeFMUstate", &msg);
        }
        if (*s).is_null() {
            *s = new_state(inst, snapshot);
        } else {
            match state_ref::<M>(inst, "fmi2DeSerializeFMUstate", *s) {
                Ok(b) => b.snapshot = snapshot,
                Err(st) => return st,
            }
        }
        fmi2OK
    })
}

/// A function for a capability the FMU declares absent: fmi2Error and a log line.
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn unsupported<M: FmuModel>(c: fmi2Component, function: &str, why: &str) -> fmi2Status {
    with_instance::<M>(c, function, mask::ANY, |inst| {
        inst.error(&format!("{function} is not supported: {why}"))
    })
}

/// `fmi2GetDirectionalDerivative`: not provided (`providesDirectionalDerivative="false"`).
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_directional_derivative<M: FmuModel>(
    c: fmi2Component,
    _v_unknown: *const fmi2ValueReference,
    _n_unknown: usize,
    _v_known: *const fmi2ValueReference,
    _n_known: usize,
    _dv_known: *const fmi2Real,
    _dv_unknown: *mut fmi2Real,
) -> fmi2Status {
    let why = "providesDirectionalDerivative=\"false\"";
    unsupported::<M>(c, "fmi2GetDirectionalDerivative", why)
}

/// `fmi2SetRealInputDerivatives`: not supported (`canInterpolateInputs="false"`).
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn set_real_input_derivatives<M: FmuModel>(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *const fmi2Real,
) -> fmi2Status {
    let why = "canInterpolateInputs=\"false\"";
    unsupported::<M>(c, "fmi2SetRealInputDerivatives", why)
}

/// `fmi2GetRealOutputDerivatives`: not supported (`maxOutputDerivativeOrder="0"`).
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_real_output_derivatives<M: FmuModel>(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> fmi2Status {
    let why = "maxOutputDerivativeOrder=\"0\"";
    unsupported::<M>(c, "fmi2GetRealOutputDerivatives", why)
}

/// `fmi2CancelStep`: fmi2DoStep never returns fmi2Pending.
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn cancel_step<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    let why = "fmi2DoStep never returns fmi2Pending (canRunAsynchronuously=\"false\")";
    unsupported::<M>(c, "fmi2CancelStep", why)
}

/// `fmi2DoStep`: checks the communication point and step size, then advances the model.
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn do_step<M: FmuModel>(
    c: fmi2Component,
    t: fmi2Real,
    h: fmi2Real,
    _no_set_prior: fmi2Boolean,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2DoStep", mask::DO_STEP, |inst| {
        let now = inst.core.time;
        // h finite and > 0; t finite and not off `now` by more than a relative 1e-10. A master
        // on the FMU's own grid hands `t == now` exactly, which needs no tolerance.
        if !(h > 0.0 && h.is_finite()) {
            return step_size_refused(inst, h);
        }
        let off = || (t - now).abs() > 1e-10 * now.abs().max(1.0);
        if !(t.is_finite() && (t == now || !off())) {
            return off_time(inst, t, now);
        }
        if let Some(stop) = inst.core.stop_time {
            // Past stopTime by more than a relative 1e-10 (first: past it at all).
            let end = t + h;
            if end > stop && end > stop + 1e-10 * stop.abs().max(1.0) {
                return past_stop(inst, end, stop);
            }
        }
        if h > inst.work_limit {
            if let Err(status) = check_work(inst, t, h) {
                return status;
            }
        }
        match inst.model.do_step(t, h) {
            Ok(()) => {
                inst.core.time = t + h;
                inst.dirty = false;
                fmi2OK
            }
            Err(msg) => step_failed(inst, t, h, &msg),
        }
    })
}

/// The work bound of one `fmi2DoStep`: each of the model's internal loops
/// ([`FmuModel::internal_steps`]) takes at most [`MAX_INTERNAL_STEPS`] passes over
/// `[t, t + h]`, and its length is a positive number that the time can still resolve at
/// `t + h` (one internal step must advance the time: at t = 1e300 a 0.1 s step is lost in
/// rounding, and a loop that advances by it never ends, as the fuzzer found in Sensors with
/// `fmi2DoStep(t = 1e300, h = 0.05)`). Refused before the model is touched: the
/// instance stays in StepComplete (as for a refused step size), so a master may retry with a
/// smaller step.
///
/// A step that passes sets [`Instance::work_limit`] to half the bound's passes of the shortest
/// loop: later steps up to that size skip the check (their loops' lengths are unchanged until
/// the limit is reset, and a loop lags at most one pass behind after a step).
#[inline(never)]
fn check_work<M: FmuModel>(inst: &mut Instance<M>, t: f64, h: f64) -> Result<(), fmi2Status> {
    match work(&inst.model, t, h) {
        Ok(()) => {
            let mut shortest = f64::INFINITY;
            inst.model
                .internal_steps(t, h, &mut |_, length, _| shortest = shortest.min(length));
            inst.work_limit = 0.5 * MAX_INTERNAL_STEPS * shortest;
            Ok(())
        }
        Err(msg) => Err(too_much_work(inst, t, h, &msg)),
    }
}

/// [`check_work`] of a model: the message names the step size, the longest loop and its length.
#[inline(always)]
fn work<M: FmuModel>(m: &M, t: f64, h: f64) -> Result<(), String> {
    let mut within = true;
    let end = t + h;
    m.internal_steps(t, h, &mut |_, length, passes| {
        // NaN passes fail the comparison, like a length that is not a positive number.
        // A step (h > 0) must also advance the time; a restored state is checked at h = 0.
        within &= length > 0.0 && passes <= MAX_INTERNAL_STEPS && (h == 0.0 || end + length > end);
    });
    if within {
        Ok(())
    } else {
        Err(work_message(m, t, h))
    }
}

/// The next double above a finite `x` (`f64::next_up`, which needs rustc 1.86: the win64 FMUs
/// are built with Debian bookworm's rustc 1.85 where rustup cannot add the target).
fn next_up(x: f64) -> f64 {
    let bits = x.to_bits();
    if x == 0.0 {
        f64::from_bits(1)
    } else if x > 0.0 {
        f64::from_bits(bits + 1)
    } else {
        f64::from_bits(bits - 1)
    }
}

#[cold]
#[inline(never)]
fn work_message<M: FmuModel>(m: &M, t: f64, h: f64) -> String {
    let mut worst = None::<(&str, f64, f64)>;
    let mut not_positive = None;
    let mut unresolved = None;
    let end = t + h;
    m.internal_steps(t, h, &mut |name, length, passes| {
        if !positive(length) {
            not_positive.get_or_insert((name, length));
        } else if h != 0.0 && !(end + length > end) {
            unresolved.get_or_insert((name, length));
        }
        let passes = if passes.is_nan() {
            f64::INFINITY
        } else {
            passes
        };
        if !worst.is_some_and(|(_, _, most)| most >= passes) {
            worst = Some((name, length, passes));
        }
    });
    if let Some((name, length)) = not_positive {
        return format!("internal step {name} = {length:?} s is not a positive number");
    }
    let (name, length, passes) = worst.unwrap_or(("?", f64::NAN, f64::NAN));
    // Too many passes says more (and what to change); a step lost in rounding can take few.
    if let Some((name, length)) = unresolved.filter(|_| passes <= MAX_INTERNAL_STEPS) {
        return format!(
            "internal step {name} = {length:?} s is lost in rounding at t + h = {end:e} s \
             (the doubles there are {:e} s apart): the time is too large for this step",
            next_up(end) - end
        );
    }
    if h == 0.0 {
        return format!(
            "the internal steps of {name} = {length:?} s lag {passes:.3e} steps behind the \
             time {t} s"
        );
    }
    format!(
        "communicationStepSize = {h} s would take {passes:.3e} internal steps of {name} = \
         {length:?} s; at most {MAX_INTERNAL_STEPS:e} per fmi2DoStep: use a smaller \
         communication step size or a larger {name}"
    )
}

#[cold]
#[inline(never)]
fn too_much_work<M: FmuModel>(inst: &Instance<M>, t: f64, h: f64, msg: &str) -> fmi2Status {
    fail(
        inst,
        format_args!(
            "fmi2DoStep at t = {}, h = {}: instance {:?}: {msg}",
            Num(t),
            Num(h),
            inst.name.to_string_lossy()
        ),
    )
}

/// A number for a message: plain (`0.3`, `1000000000`) unless very large or small, then in
/// exponent form (`1e300`, not 301 digits).
struct Num(f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a != 0.0 && !(1e-5..1e16).contains(&a) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// An output that is not a finite number after `function` (`at`: the time, and the step):
/// fmi2Error naming the variable and its value instead of fmi2OK with NaN.
#[cold]
#[inline(never)]
fn non_finite_output<M: FmuModel>(
    inst: &Instance<M>,
    function: &str,
    at: std::fmt::Arguments,
    vr: fmi2ValueReference,
) -> fmi2Status {
    let v = &M::variables()[vr as usize];
    let value = match v.access {
        Access::Real { get, .. } => get(&inst.model),
        _ => f64::NAN,
    };
    fail(
        inst,
        format_args!(
            "{function} {at}: instance {:?}: output {:?} = {value} is not a finite number \
             (parameters or inputs outside what the model can handle?)",
            inst.name.to_string_lossy(),
            v.name
        ),
    )
}

#[cold]
#[inline(never)]
fn step_size_refused<M: FmuModel>(inst: &Instance<M>, h: f64) -> fmi2Status {
    fail(
        inst,
        format_args!("fmi2DoStep: communicationStepSize = {h} must be > 0"),
    )
}

#[cold]
#[inline(never)]
fn off_time<M: FmuModel>(inst: &Instance<M>, t: f64, now: f64) -> fmi2Status {
    fail(
        inst,
        format_args!(
            "fmi2DoStep: currentCommunicationPoint = {t} does not match the FMU's time {now}"
        ),
    )
}

#[cold]
#[inline(never)]
fn past_stop<M: FmuModel>(inst: &Instance<M>, end: f64, stop: f64) -> fmi2Status {
    fail(
        inst,
        format_args!("fmi2DoStep: step to {end} passes stopTime = {stop}"),
    )
}

/// The model refused a step: the instance moves to the Error state.
#[cold]
#[inline(never)]
fn step_failed<M: FmuModel>(inst: &mut Instance<M>, t: f64, h: f64, msg: &str) -> fmi2Status {
    inst.core.state = LifeState::Error;
    inst.error(&format!(
        "fmi2DoStep at t = {t}, h = {h}: instance {:?}: {msg}",
        inst.name.to_string_lossy()
    ))
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_status<M: FmuModel>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    _v: *mut fmi2Status,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2GetStatus", mask::GET_STATUS, |inst| {
        inst.error(&format!(
            "fmi2GetStatus(kind {kind}): only meaningful after fmi2DoStep returned fmi2Pending, \
             which this FMU never does"
        ))
    })
}

/// `fmi2LastSuccessfulTime` is the time reached by the last completed step.
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_real_status<M: FmuModel>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    v: *mut fmi2Real,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2GetRealStatus", mask::GET_STATUS, |inst| {
        if kind != fmi2LastSuccessfulTime {
            return inst.error(&format!(
                "fmi2GetRealStatus: status kind {kind} is not fmi2LastSuccessfulTime"
            ));
        }
        if v.is_null() {
            return inst.error("fmi2GetRealStatus: value pointer is NULL");
        }
        *v = inst.core.time;
        fmi2OK
    })
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_integer_status<M: FmuModel>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    _v: *mut fmi2Integer,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2GetIntegerStatus", mask::GET_STATUS, |inst| {
        inst.error(&format!(
            "fmi2GetIntegerStatus: no integer status (kind {kind}) is defined"
        ))
    })
}

/// `fmi2Terminated`: whether the FMU asks to stop (never, here: fmi2False).
///
/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_boolean_status<M: FmuModel>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    v: *mut fmi2Boolean,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2GetBooleanStatus", mask::GET_STATUS, |inst| {
        if kind != fmi2Terminated {
            return inst.error(&format!(
                "fmi2GetBooleanStatus: status kind {kind} is not fmi2Terminated"
            ));
        }
        if v.is_null() {
            return inst.error("fmi2GetBooleanStatus: value pointer is NULL");
        }
        *v = fmi2False;
        fmi2OK
    })
}

/// # Safety
/// FMI 2.0 arguments.
pub unsafe fn get_string_status<M: FmuModel>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    _v: *mut fmi2String,
) -> fmi2Status {
    with_instance::<M>(c, "fmi2GetStringStatus", mask::GET_STATUS, |inst| {
        inst.error(&format!(
            "fmi2GetStringStatus(kind {kind}): only meaningful after fmi2DoStep returned \
             fmi2Pending, which this FMU never does"
        ))
    })
}

/// Hands generated text to the caller of a generator entry point.
///
/// # Safety
/// `write` must be callable with `out` and a byte slice.
pub unsafe fn emit_text(
    out: *mut c_void,
    write: unsafe extern "C" fn(*mut c_void, *const u8, usize),
    text: &str,
) {
    let _ = guarded(|| write(out, text.as_ptr(), text.len()));
}
