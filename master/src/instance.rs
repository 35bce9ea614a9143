//! A safe co-simulation slave instance whose lifecycle is enforced by types (FMI 2.0 section
//! 4.2.4, "State Machine of Calling Sequence from Master to Slave"):
//!
//! `Fmu::instantiate` -> [`Instance<Instantiated>`] -- `enter_initialization_mode` (after
//! `fmi2SetupExperiment`) -> [`Instance<Initializing>`] -- `exit_initialization_mode` ->
//! [`Instance<Stepping>`] -- `do_step`* -- `terminate`.
//!
//! A state transition consumes the instance, so no function can be called out of order. Dropping
//! an instance in any state calls `fmi2Terminate` (only in Step Mode: FMI 2.0, sec. 4.2.4 allows
//! only fmi2FreeInstance or fmi2Reset in Instantiated and Initialization Mode, and nothing but
//! them after fmi2Error) and `fmi2FreeInstance` (unless the FMU returned fmi2Fatal, after which
//! the standard allows no more calls), so every path, including errors and Ctrl-C, cleans up.
//!
//! An instance runs in this process (the FMU's functions are called directly) or, isolated,
//! in a `shipsim fmu-host` child process ([`crate::isolate`]): each call then goes to the
//! child's [`Client`], and a crash, exit or hang of the child is an error naming the instance,
//! the call and the time. The state machine, the status checks and the errors are the same.

use crate::error::{Error, Result};
use crate::fmu::{Api, Fmu, FmuLibrary, VR};
use crate::isolate::client::{Client, GONE};
use crate::isolate::protocol::Op;
use crate::isolate::{CallMonitor, Isolation};
use crate::model_description::CoSimulation;
use fmi2::*;
use std::collections::VecDeque;
use std::ffi::{c_char, c_int, c_void, CString};
use std::marker::PhantomData;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

/// Type states.
pub struct Instantiated;
pub struct Initializing;
pub struct Stepping;

/// States in which fmi2GetXXX is allowed.
pub trait Readable {}
impl Readable for Initializing {}
impl Readable for Stepping {}

/// One formatted FMU log message.
#[derive(Debug, Clone)]
pub struct LogRecord {
    pub instance: String,
    pub status: i32,
    pub category: String,
    pub message: String,
}

/// Where FMU log messages go. The default prints warnings and worse to stderr (all with verbose).
pub type LogSink = Arc<dyn Fn(&LogRecord) + Send + Sync>;

pub fn stderr_sink(verbose: bool) -> LogSink {
    Arc::new(move |r: &LogRecord| {
        if verbose || r.status >= fmi2Warning {
            eprintln!(
                "[{}] {} {}: {}",
                r.instance,
                status_name(r.status),
                r.category,
                r.message
            );
        }
    })
}

/// An instance's log: the sink and the last messages (for error reports).
pub(crate) struct LogCtx {
    name: String,
    sink: LogSink,
    recent: Mutex<VecDeque<String>>,
    /// The instance was instantiated with loggingOn = fmi2True (debug logging).
    debug_logging: bool,
}

impl LogCtx {
    /// The last messages, or, when the FMU logged none, one line that says so and, if debug
    /// logging was off, how to switch it on: some FMUs (PythonFMU's) report even their errors
    /// only with debug logging on.
    fn recent_or_hint(&self, debug_logging: bool) -> Vec<String> {
        let recent: Vec<String> = self
            .recent
            .lock()
            .map(|r| r.iter().cloned().collect())
            .unwrap_or_default();
        if !recent.is_empty() {
            recent
        } else if debug_logging {
            vec!["(none: the FMU logged no reason)".to_string()]
        } else {
            vec![NO_REASON_HINT.to_string()]
        }
    }

    fn is_empty(&self) -> bool {
        self.recent.lock().map(|r| r.is_empty()).unwrap_or(true)
    }

    /// The last messages.
    pub(crate) fn recent_lines(&self) -> Vec<String> {
        self.recent
            .lock()
            .map(|r| r.iter().cloned().collect())
            .unwrap_or_default()
    }

    /// One message of the FMU (`instance` as it named itself, empty for this instance): kept
    /// among the last ones and passed to the sink.
    pub(crate) fn deliver(&self, instance: String, status: i32, category: String, message: String) {
        let rec = LogRecord {
            instance: if instance.is_empty() {
                self.name.clone()
            } else {
                instance
            },
            status,
            category,
            message,
        };
        if let Ok(mut r) = self.recent.lock() {
            if r.len() == RECENT {
                r.pop_front();
            }
            r.push_back(format!(
                "{} {}: {}",
                status_name(rec.status),
                rec.category,
                rec.message
            ));
        }
        (self.sink)(&rec);
    }
}

/// What an error report says when an FMU with debug logging off logged nothing.
const NO_REASON_HINT: &str = "(none: the FMU logged no reason with debug logging off; rerun \
     with -v (loggingOn = true): some FMUs, PythonFMU's among them, report their errors only then)";

const RECENT: usize = 8;

unsafe extern "C" fn log_sink(
    ctx: *mut c_void,
    instance: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    // Never unwind into the FMU.
    let _ = std::panic::catch_unwind(|| {
        let ctx = &*(ctx as *const LogCtx);
        ctx.deliver(
            lossy_str(instance),
            status,
            lossy_str(category),
            lossy_str(message),
        );
    });
}

extern "C" {
    fn calloc(n: usize, size: usize) -> *mut c_void;
    fn free(p: *mut c_void);
}
unsafe extern "C" fn fmi_calloc(n: usize, size: usize) -> *mut c_void {
    calloc(n, size)
}
unsafe extern "C" fn fmi_free(p: *mut c_void) {
    free(p)
}

/// The largest serialized FMU state accepted: a larger size reported by an FMU is an error,
/// not an allocation.
const MAX_STATE_BYTES: usize = 1 << 30;

/// The FMU-state capability (FMI 2.0, sec. 4.3.1) a checkpoint needs that `cs` lacks, if any.
fn missing_state_capability(cs: &CoSimulation) -> Option<&'static str> {
    if !cs.can_get_and_set_fmu_state {
        Some("canGetAndSetFMUstate")
    } else if !cs.can_serialize_fmu_state {
        Some("canSerializeFMUstate")
    } else {
        None
    }
}

/// The error for an instance of an FMU that lacks capability `cap`.
fn state_support_error(fmu: &std::path::Path, instance: &str, cap: &str) -> Error {
    Error::fmu(
        fmu,
        format!(
            "instance '{instance}': the FMU does not declare {cap}=\"true\" (FMI 2.0, sec. 4.3.1), so its state cannot be saved or restored"
        ),
    )
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Phase {
    Instantiated,
    /// In Initialization Mode: fmi2Terminate is not allowed (FMI 2.0, sec. 4.2.4).
    Initializing,
    /// In Step Mode.
    Initialized,
    Terminated,
    Failed,
    Fatal,
    /// fmi2FreeInstance was called (an isolated instance's [`Instance::terminate`]).
    Freed,
}

struct Core {
    name: String,
    lib: Arc<FmuLibrary>,
    comp: fmi2Component,
    phase: Phase,
    // Kept alive for the FMU, which may hold pointers to them (none for an isolated instance).
    _callbacks: Option<Box<fmi2CallbackFunctions>>,
    _target: Option<Box<LogTarget>>,
    log: Arc<LogCtx>,
    _name_c: CString,
    /// The `.fmu` file, for errors about its capabilities.
    fmu_path: PathBuf,
    /// Which of canGetAndSetFMUstate and canSerializeFMUstate the FMU lacks (FMI 2.0,
    /// sec. 4.3.1), if any.
    missing_state_capability: Option<&'static str>,
    /// The child process of an isolated instance.
    remote: Option<Box<Client>>,
    /// Where an in-process instance notes its calls, and its number there.
    monitor: Option<(Arc<CallMonitor>, u16)>,
}

impl Core {
    /// Ok for fmi2OK and fmi2Warning, else the error of `function` (the phase follows the
    /// status). Inlined into every call wrapper: the success path is one comparison.
    #[inline(always)]
    fn check(
        &mut self,
        function: &'static str,
        status: fmi2Status,
        time: Option<f64>,
    ) -> Result<()> {
        if status == fmi2OK || status == fmi2Warning {
            Ok(())
        } else {
            self.failed(function, status, time)
        }
    }

    #[cold]
    #[inline(never)]
    fn failed(
        &mut self,
        function: &'static str,
        status: fmi2Status,
        time: Option<f64>,
    ) -> Result<()> {
        if status == GONE {
            // The isolated instance's process died, hung or was stopped: no more calls.
            self.phase = Phase::Fatal;
            if let Some(r) = &self.remote {
                return Err(r.error());
            }
        }
        if status == fmi2Fatal {
            self.phase = Phase::Fatal;
        } else if status == fmi2Error || !(0..=5).contains(&status) {
            self.phase = Phase::Failed;
        }
        Err(self.fmi_error(function, status, time))
    }

    fn fmi_error(&self, function: &'static str, status: fmi2Status, time: Option<f64>) -> Error {
        Error::Fmi {
            instance: self.name.clone(),
            function,
            status,
            time,
            log: self.log.recent_or_hint(self.log.debug_logging),
        }
    }
}

impl Drop for Core {
    fn drop(&mut self) {
        let (terminate, free) = match self.phase {
            Phase::Initialized => (true, true),
            Phase::Fatal | Phase::Freed => (false, false),
            _ => (false, true),
        };
        if let Some(r) = self.remote.as_mut() {
            if terminate {
                r.simple(Op::Terminate);
            }
            if free {
                r.free_instance();
            }
            // Dropping the client ends the child (without calls after fmi2Fatal).
            return;
        }
        let Some(api) = self.lib.api.as_ref() else {
            return;
        };
        let monitor = self.monitor.as_ref();
        let note = |op| {
            if let Some((m, slot)) = monitor {
                m.enter(*slot, op);
            }
        };
        unsafe {
            if terminate {
                note(Op::Terminate);
                (api.fmi2Terminate)(self.comp);
            }
            if free {
                note(Op::FreeInstance);
                (api.fmi2FreeInstance)(self.comp);
            }
        }
        if let Some((m, _)) = monitor {
            m.leave();
        }
    }
}

/// A co-simulation slave instance in type state `S`.
pub struct Instance<S> {
    core: Box<Core>,
    /// `core.comp` and the library's function table, kept next to the instance: a call in the
    /// step loop loads them without going through the box and the `Arc` (null when isolated).
    comp: fmi2Component,
    api: *const Api,
    /// The client in `core.remote`, or null in process.
    remote: *mut Client,
    /// The monitor in `core.monitor`, or null, and this instance's number there.
    monitor: *const CallMonitor,
    slot: u16,
    _s: PhantomData<S>,
}

// The FMU is only called from the thread that owns the instance.
unsafe impl<S> Send for Instance<S> {}

/// Result of a `fmi2DoStep`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepOutcome {
    Ok,
    /// The slave returned fmi2Discard and reports `fmi2Terminated` = true: it ended the
    /// simulation early at `last_successful_time` (FMI 2.0 section 4.2.3).
    Terminated {
        last_successful_time: f64,
    },
}

/// Where an instance runs, and what watches it ([`Fmu::instantiate_on`]).
#[derive(Clone, Default)]
pub struct Backend<'a> {
    /// Run it in a `shipsim fmu-host` process with these options ([`crate::isolate`]).
    pub isolate: Option<&'a Isolation>,
    /// While a call of the isolated instance runs, the flag is checked every 100 ms; when set,
    /// the child is killed and the call fails with [`Error::Interrupted`].
    pub interrupt: Option<Arc<AtomicBool>>,
    /// In process: note each call here ([`CallMonitor`]).
    pub monitor: Option<Arc<CallMonitor>>,
}

impl Fmu {
    /// `fmi2Instantiate` as co-simulation slave (FMI 2.0 section 4.2.1), with the logger proxy,
    /// `calloc`/`free`, and the resources URI. A NULL result is an error naming the instance.
    pub fn instantiate(
        &self,
        name: &str,
        logging_on: bool,
        sink: LogSink,
    ) -> Result<Instance<Instantiated>> {
        self.instantiate_on(name, logging_on, sink, Backend::default())
    }

    /// [`Fmu::instantiate`] in this process or, with [`Backend::isolate`], in a child process.
    pub fn instantiate_on(
        &self,
        name: &str,
        logging_on: bool,
        sink: LogSink,
        backend: Backend,
    ) -> Result<Instance<Instantiated>> {
        let name_c = CString::new(name)
            .map_err(|_| Error::Other(format!("instance name '{name}' contains a NUL byte")))?;
        let log = Arc::new(LogCtx {
            name: name.to_string(),
            sink,
            recent: Mutex::new(VecDeque::new()),
            debug_logging: logging_on,
        });
        let mut core = Box::new(Core {
            name: name.to_string(),
            lib: self.lib.clone(),
            comp: std::ptr::null_mut(),
            phase: Phase::Instantiated,
            _callbacks: None,
            _target: None,
            log: log.clone(),
            _name_c: name_c,
            fmu_path: self.path.clone(),
            missing_state_capability: missing_state_capability(self.co_simulation()),
            remote: None,
            monitor: None,
        });
        match backend.isolate {
            Some(iso) => {
                let c = Client::spawn(&self.path, name, logging_on, log, iso, backend.interrupt)?;
                core.remote = Some(Box::new(c));
            }
            None => self.instantiate_here(&mut core, logging_on, backend.monitor)?,
        }
        let remote = match core.remote.as_mut() {
            Some(r) => &mut **r as *mut Client,
            None => std::ptr::null_mut(),
        };
        let (monitor, slot) = match &core.monitor {
            Some((m, slot)) => (Arc::as_ptr(m), *slot),
            None => (std::ptr::null(), 0),
        };
        Ok(Instance {
            comp: core.comp,
            api: self
                .lib
                .api
                .as_ref()
                .map_or(std::ptr::null(), |a| a as *const Api),
            core,
            remote,
            monitor,
            slot,
            _s: PhantomData,
        })
    }

    /// `fmi2Instantiate` in this process into `core`.
    fn instantiate_here(
        &self,
        core: &mut Core,
        logging_on: bool,
        monitor: Option<Arc<CallMonitor>>,
    ) -> Result<()> {
        let Some(api) = self.lib.api.as_ref() else {
            return Err(Error::fmu(
                &self.path,
                format!(
                    "instance '{}': the FMU was opened for isolated instances only (its binary is not loaded in this process)",
                    core.name
                ),
            ));
        };
        let guid = CString::new(self.guid())
            .map_err(|_| Error::fmu(&self.path, "GUID contains a NUL byte"))?;
        let res = CString::new(self.resource_uri()).expect("no NUL in a path URI");
        let mut target = Box::new(LogTarget {
            sink: Some(log_sink),
            ctx: Arc::as_ptr(&core.log) as *mut c_void,
        });
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: logger_proxy(),
            allocateMemory: Some(fmi_calloc),
            freeMemory: Some(fmi_free),
            stepFinished: None,
            componentEnvironment: &mut *target as *mut LogTarget as *mut c_void,
        });
        let slot = monitor.as_ref().map(|m| m.register(&core.name));
        let call = |logging_on: bool| unsafe {
            if let (Some(m), Some(slot)) = (&monitor, slot) {
                m.enter(slot, Op::Instantiate);
            }
            let c = (api.fmi2Instantiate)(
                core._name_c.as_ptr(),
                fmi2CoSimulation,
                guid.as_ptr(),
                res.as_ptr(),
                &*callbacks,
                fmi2False,
                if logging_on { fmi2True } else { fmi2False },
            );
            if let Some(m) = &monitor {
                m.leave();
            }
            c
        };
        let comp = call(logging_on);
        if comp.is_null() {
            return Err(self.instantiate_failed(&core.name, &core.log, call));
        }
        core.comp = comp;
        core._callbacks = Some(callbacks);
        core._target = Some(target);
        core.monitor = monitor.zip(slot);
        Ok(())
    }
}

impl Fmu {
    /// The error for a NULL from `fmi2Instantiate`, with what the FMU logged. If it logged
    /// nothing with debug logging off, it is instantiated once more with loggingOn = fmi2True
    /// (`again`) to learn why: some FMUs, PythonFMU's among them, report even their errors only
    /// with debug logging on. Those messages reach the sink like any other (errors and warnings
    /// are shown by default) and the error.
    #[cold]
    #[inline(never)]
    fn instantiate_failed(
        &self,
        name: &str,
        log: &LogCtx,
        again: impl FnOnce(bool) -> fmi2Component,
    ) -> Error {
        let mut debug_logging = log.debug_logging;
        let mut note = "";
        if !debug_logging && log.is_empty() {
            debug_logging = true;
            let comp = again(true);
            if !comp.is_null() {
                // The failure with loggingOn = fmi2False stands; this instance is not used.
                if let Some(api) = self.lib.api.as_ref() {
                    unsafe { (api.fmi2FreeInstance)(comp) };
                }
                note = " (it succeeded with loggingOn = true)";
            }
        }
        Error::fmu(
            &self.path,
            format!(
                "fmi2Instantiate returned NULL for instance '{name}' (GUID \"{}\"){note}; FMU log: {}",
                self.guid(),
                log.recent_or_hint(debug_logging).join(" | ")
            ),
        )
    }

    /// The FMU can save and restore serialized states (canGetAndSetFMUstate and
    /// canSerializeFMUstate, FMI 2.0, sec. 4.3.1), else an error naming the FMU and `instance`.
    pub fn require_state_support(&self, instance: &str) -> Result<()> {
        match missing_state_capability(self.co_simulation()) {
            None => Ok(()),
            Some(cap) => Err(state_support_error(&self.path, instance, cap)),
        }
    }
}

/// The raw FMI calls, in process or through the child's client: each returns the status (or
/// [`GONE`]); the typed wrappers below check it.
impl<S> Instance<S> {
    /// The isolated instance's client.
    #[inline(always)]
    fn remote(&mut self) -> Option<&mut Client> {
        // SAFETY: `remote` points into `core.remote`, a box that lives as long as the instance.
        unsafe { self.remote.as_mut() }
    }

    /// Calls `f` with the function table and the component, noting the call in the monitor.
    #[inline(always)]
    fn local<T>(&self, op: Op, f: impl FnOnce(&Api, fmi2Component) -> T) -> T {
        // SAFETY: `monitor` points into `core.monitor`, an `Arc` the instance holds.
        match unsafe { self.monitor.as_ref() } {
            None => f(self.api(), self.comp),
            Some(m) => {
                m.enter(self.slot, op);
                let r = f(self.api(), self.comp);
                m.leave();
                r
            }
        }
    }

    /// fmi2EnterInitializationMode, fmi2ExitInitializationMode or fmi2Terminate.
    fn raw_simple(&mut self, op: Op) -> fmi2Status {
        match self.remote() {
            Some(r) => r.simple(op),
            None => self.local(op, |api, c| unsafe {
                match op {
                    Op::EnterInitializationMode => (api.fmi2EnterInitializationMode)(c),
                    Op::ExitInitializationMode => (api.fmi2ExitInitializationMode)(c),
                    _ => (api.fmi2Terminate)(c),
                }
            }),
        }
    }

    /// The (name, component) pair the FMU host calls with ([`crate::isolate::host`]).
    pub(crate) fn raw(&self) -> (&Api, fmi2Component) {
        (self.api(), self.comp)
    }

    /// Drops the instance without another FMI call (the host, when its master left).
    pub(crate) fn abandon(mut self) {
        self.core.phase = Phase::Fatal;
    }
}

impl<S> Instance<S> {
    pub fn name(&self) -> &str {
        &self.core.name
    }

    /// The process id of an isolated instance's host (None in process).
    pub fn host_pid(&self) -> Option<u32> {
        self.core.remote.as_ref().map(|r| r.pid())
    }

    fn transition<T>(self) -> Instance<T> {
        Instance {
            core: self.core,
            comp: self.comp,
            api: self.api,
            remote: self.remote,
            monitor: self.monitor,
            slot: self.slot,
            _s: PhantomData,
        }
    }

    /// The library's function table (only in process: `local` calls it).
    #[inline(always)]
    fn api(&self) -> &Api {
        // SAFETY: `api` points into the `FmuLibrary` that `core.lib` (an `Arc`) keeps alive for
        // as long as this instance exists; it is only read for an in-process instance, whose
        // library is loaded.
        unsafe { &*self.api }
    }

    /// The last few log messages of this instance (for error reports).
    pub fn recent_log(&self) -> Vec<String> {
        self.core.log.recent_lines()
    }

    /// `fmi2SetReal`, batched.
    #[inline]
    pub fn set_real(&mut self, vrs: &[VR], values: &[f64]) -> Result<()> {
        debug_assert_eq!(vrs.len(), values.len());
        if vrs.is_empty() {
            return Ok(());
        }
        let s = match self.remote() {
            Some(r) => r.set(Op::SetReal, vrs, values),
            None => self.local(Op::SetReal, |api, c| unsafe {
                (api.fmi2SetReal)(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
            }),
        };
        self.core.check("fmi2SetReal", s, None)
    }

    /// `fmi2SetInteger`, batched.
    #[inline]
    pub fn set_integer(&mut self, vrs: &[VR], values: &[i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = match self.remote() {
            Some(r) => r.set(Op::SetInteger, vrs, values),
            None => self.local(Op::SetInteger, |api, c| unsafe {
                (api.fmi2SetInteger)(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
            }),
        };
        self.core.check("fmi2SetInteger", s, None)
    }

    /// `fmi2SetBoolean`, batched (values are fmi2Boolean, 0 or 1).
    #[inline]
    pub fn set_boolean(&mut self, vrs: &[VR], values: &[i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = match self.remote() {
            Some(r) => r.set(Op::SetBoolean, vrs, values),
            None => self.local(Op::SetBoolean, |api, c| unsafe {
                (api.fmi2SetBoolean)(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
            }),
        };
        self.core.check("fmi2SetBoolean", s, None)
    }

    /// `fmi2SetString`.
    pub fn set_string(&mut self, vrs: &[VR], values: &[&str]) -> Result<()> {
        let cs: Vec<CString> = values
            .iter()
            .map(|v| {
                CString::new(*v)
                    .map_err(|_| Error::Other(format!("string value {v:?} contains a NUL byte")))
            })
            .collect::<Result<_>>()?;
        let s = match self.remote() {
            Some(r) => r.set_string(vrs, values),
            None => {
                let ptrs: Vec<fmi2String> = cs.iter().map(|c| c.as_ptr()).collect();
                self.local(Op::SetString, |api, c| unsafe {
                    (api.fmi2SetString)(c, vrs.as_ptr(), vrs.len(), ptrs.as_ptr())
                })
            }
        };
        self.core.check("fmi2SetString", s, None)
    }
}

impl<S: Readable> Instance<S> {
    /// `fmi2GetReal`, batched into a caller-provided buffer (no allocation).
    #[inline]
    pub fn get_real(&mut self, vrs: &[VR], out: &mut [f64]) -> Result<()> {
        debug_assert_eq!(vrs.len(), out.len());
        if vrs.is_empty() {
            return Ok(());
        }
        let s = match self.remote() {
            Some(r) => r.get_real(vrs, out),
            None => self.local(Op::GetReal, |api, c| unsafe {
                (api.fmi2GetReal)(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
            }),
        };
        self.core.check("fmi2GetReal", s, None)
    }

    /// `fmi2GetInteger`, batched.
    #[inline]
    pub fn get_integer(&mut self, vrs: &[VR], out: &mut [i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = match self.remote() {
            Some(r) => r.get_int(Op::GetInteger, vrs, out),
            None => self.local(Op::GetInteger, |api, c| unsafe {
                (api.fmi2GetInteger)(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
            }),
        };
        self.core.check("fmi2GetInteger", s, None)
    }

    /// `fmi2GetBoolean`, batched.
    #[inline]
    pub fn get_boolean(&mut self, vrs: &[VR], out: &mut [i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = match self.remote() {
            Some(r) => r.get_int(Op::GetBoolean, vrs, out),
            None => self.local(Op::GetBoolean, |api, c| unsafe {
                (api.fmi2GetBoolean)(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
            }),
        };
        self.core.check("fmi2GetBoolean", s, None)
    }

    /// `fmi2GetString` into caller-owned strings, in batches of up to 32 value references
    /// (the FMU owns its strings only until the next call, so each is copied into `out[i]`,
    /// reusing its buffer: in process, no allocation once a buffer is as long as the text;
    /// invalid UTF-8 is replaced by U+FFFD, a null pointer reads as ""). For recording String
    /// variables from the step loop.
    pub fn get_string_into(&mut self, vrs: &[VR], out: &mut [String]) -> Result<()> {
        debug_assert_eq!(vrs.len(), out.len());
        if vrs.is_empty() {
            return Ok(());
        }
        if let Some(r) = self.remote() {
            let (s, values) = r.get_string(vrs);
            self.core.check("fmi2GetString", s, None)?;
            for (o, v) in out.iter_mut().zip(values) {
                *o = v;
            }
            return Ok(());
        }
        const BATCH: usize = 32;
        for (vrs, out) in vrs.chunks(BATCH).zip(out.chunks_mut(BATCH)) {
            let mut ptrs: [fmi2String; BATCH] = [std::ptr::null(); BATCH];
            let s = self.local(Op::GetString, |api, c| unsafe {
                (api.fmi2GetString)(c, vrs.as_ptr(), vrs.len(), ptrs.as_mut_ptr())
            });
            self.core.check("fmi2GetString", s, None)?;
            for (o, p) in out.iter_mut().zip(&ptrs) {
                o.clear();
                if !p.is_null() {
                    // SAFETY: a NUL-terminated string the FMU owns until its next call.
                    o.push_str(&unsafe { std::ffi::CStr::from_ptr(*p) }.to_string_lossy());
                }
            }
        }
        Ok(())
    }

    /// `fmi2GetString` (copies the strings, which the FMU owns only until the next call).
    pub fn get_string(&mut self, vrs: &[VR]) -> Result<Vec<String>> {
        let (s, values) = match self.remote() {
            Some(r) => r.get_string(vrs),
            None => {
                let mut ptrs: Vec<fmi2String> = vec![std::ptr::null(); vrs.len()];
                let s = self.local(Op::GetString, |api, c| unsafe {
                    (api.fmi2GetString)(c, vrs.as_ptr(), vrs.len(), ptrs.as_mut_ptr())
                });
                (s, ptrs.iter().map(|p| unsafe { lossy_str(*p) }).collect())
            }
        };
        self.core.check("fmi2GetString", s, None)?;
        Ok(values)
    }
}

impl Instance<Instantiated> {
    /// `fmi2SetupExperiment` then `fmi2EnterInitializationMode` (FMI 2.0 sections 2.1.6, 4.2.4).
    pub fn enter_initialization_mode(
        mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Result<Instance<Initializing>> {
        // SAFETY: as in `local`.
        if let Some(m) = unsafe { self.monitor.as_ref() } {
            m.at(start_time);
        }
        let s = match self.remote() {
            Some(r) => r.setup_experiment(tolerance, start_time, stop_time),
            None => self.local(Op::SetupExperiment, |api, c| unsafe {
                (api.fmi2SetupExperiment)(
                    c,
                    tolerance.is_some() as fmi2Boolean,
                    tolerance.unwrap_or(0.0),
                    start_time,
                    stop_time.is_some() as fmi2Boolean,
                    stop_time.unwrap_or(0.0),
                )
            }),
        };
        self.core
            .check("fmi2SetupExperiment", s, Some(start_time))?;
        let s = self.raw_simple(Op::EnterInitializationMode);
        self.core
            .check("fmi2EnterInitializationMode", s, Some(start_time))?;
        self.core.phase = Phase::Initializing;
        Ok(self.transition())
    }
}

impl Instance<Initializing> {
    /// `fmi2ExitInitializationMode`: the slave is then at its first communication point.
    pub fn exit_initialization_mode(mut self) -> Result<Instance<Stepping>> {
        let s = self.raw_simple(Op::ExitInitializationMode);
        self.core.check("fmi2ExitInitializationMode", s, None)?;
        self.core.phase = Phase::Initialized;
        Ok(self.transition())
    }
}

impl Instance<Stepping> {
    /// `fmi2DoStep(t, h, noSetFMUStatePriorToCurrentPoint = true)` (FMI 2.0 section 4.2.2).
    /// fmi2Discard with `fmi2Terminated` = true is an early end, reported as
    /// [`StepOutcome::Terminated`]; any other status worse than fmi2Warning is an error naming
    /// the instance, the time and the status, with the FMU's last log lines.
    #[inline(always)]
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<StepOutcome> {
        let s = match self.remote() {
            Some(r) => r.do_step(t, h),
            None => {
                // SAFETY: as in `local`.
                let monitor = unsafe { self.monitor.as_ref() };
                if let Some(m) = monitor {
                    m.enter_step(self.slot, t);
                }
                let s = unsafe { (self.api().fmi2DoStep)(self.comp, t, h, fmi2True) };
                if let Some(m) = monitor {
                    m.at(t + h);
                    m.leave();
                }
                s
            }
        };
        if s == fmi2OK || s == fmi2Warning {
            return Ok(StepOutcome::Ok);
        }
        self.step_not_ok(t, s)
    }

    /// fmi2DoStep returned `s`, worse than fmi2Warning: an early end (fmi2Discard with
    /// `fmi2Terminated`) or an error.
    #[cold]
    #[inline(never)]
    fn step_not_ok(&mut self, t: f64, s: fmi2Status) -> Result<StepOutcome> {
        if s == fmi2Discard {
            let (st, terminated) = self.status_query(Op::GetBooleanStatus, fmi2Terminated);
            if (fmi2OK..=fmi2Warning).contains(&st) && terminated != 0.0 {
                let (st, last) = self.status_query(Op::GetRealStatus, fmi2LastSuccessfulTime);
                let last = match (fmi2OK..=fmi2Warning).contains(&st) {
                    true => last,
                    false => t,
                };
                self.core.phase = Phase::Initialized;
                return Ok(StepOutcome::Terminated {
                    last_successful_time: last,
                });
            }
        }
        self.core.check("fmi2DoStep", s, Some(t))?;
        Err(self.core.fmi_error("fmi2DoStep", s, Some(t)))
    }

    /// fmi2GetBooleanStatus (as 0.0 or 1.0) or fmi2GetRealStatus of `kind`.
    fn status_query(&mut self, op: Op, kind: fmi2StatusKind) -> (fmi2Status, f64) {
        if let Some(r) = self.remote() {
            return r.status_query(op, kind);
        }
        self.local(op, |api, c| unsafe {
            if op == Op::GetBooleanStatus {
                let mut v: fmi2Boolean = fmi2False;
                let s = (api.fmi2GetBooleanStatus)(c, kind, &mut v);
                (s, (v != fmi2False) as i32 as f64)
            } else {
                let mut v = 0.0;
                let s = (api.fmi2GetRealStatus)(c, kind, &mut v);
                (s, v)
            }
        })
    }

    /// The instance's complete state as bytes (FMI 2.0, sec. 2.1.8): `fmi2GetFMUstate`,
    /// `fmi2SerializedFMUstateSize`, `fmi2SerializeFMUstate`, then `fmi2FreeFMUstate` (also when
    /// serializing fails). The bytes are the FMU's own format; [`Self::restore_state`] of an
    /// instance of the same FMU takes them back. An FMU without canGetAndSetFMUstate or
    /// canSerializeFMUstate is refused before any call.
    pub fn serialize_state(&mut self) -> Result<Vec<u8>> {
        self.require_state_support()?;
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let s = match self.remote() {
            Some(r) => {
                let (s, h) = r.state_call(Op::GetFmuState, 0, 0);
                state = h as usize as fmi2FMUstate;
                s
            }
            None => self.local(Op::GetFmuState, |api, c| unsafe {
                (api.fmi2GetFMUstate)(c, &mut state)
            }),
        };
        if let Err(e) = self.core.check("fmi2GetFMUstate", s, None) {
            let _ = self.free_state(&mut state);
            return Err(e);
        }
        let bytes = self.serialize_held(state);
        let freed = self.free_state(&mut state);
        let bytes = bytes?;
        freed?;
        Ok(bytes)
    }

    /// Sets the instance to a state from [`Self::serialize_state`] (FMI 2.0, sec. 2.1.8):
    /// `fmi2DeSerializeFMUstate`, `fmi2SetFMUstate`, then `fmi2FreeFMUstate`.
    pub fn restore_state(&mut self, bytes: &[u8]) -> Result<()> {
        self.require_state_support()?;
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let s = match self.remote() {
            Some(r) => {
                let (s, h) = r.deserialize(bytes);
                state = h as usize as fmi2FMUstate;
                s
            }
            None => self.local(Op::Deserialize, |api, c| unsafe {
                (api.fmi2DeSerializeFMUstate)(
                    c,
                    bytes.as_ptr() as *const fmi2Byte,
                    bytes.len(),
                    &mut state,
                )
            }),
        };
        if let Err(e) = self.core.check("fmi2DeSerializeFMUstate", s, None) {
            let _ = self.free_state(&mut state);
            return Err(e);
        }
        let s = match self.remote() {
            Some(r) => r.state_call(Op::SetFmuState, state as usize as u64, 0).0,
            None => self.local(Op::SetFmuState, |api, c| unsafe {
                (api.fmi2SetFMUstate)(c, state)
            }),
        };
        let set = self.core.check("fmi2SetFMUstate", s, None);
        let freed = self.free_state(&mut state);
        set?;
        freed
    }

    /// The FMU declares both FMU-state capabilities, else an error naming the FMU.
    fn require_state_support(&self) -> Result<()> {
        match self.core.missing_state_capability {
            None => Ok(()),
            Some(cap) => Err(state_support_error(
                &self.core.fmu_path,
                &self.core.name,
                cap,
            )),
        }
    }

    /// Serializes a state got by `fmi2GetFMUstate`.
    fn serialize_held(&mut self, state: fmi2FMUstate) -> Result<Vec<u8>> {
        let mut size = 0usize;
        let s = match self.remote() {
            Some(r) => {
                let (s, n) = r.state_call(Op::SerializedSize, state as usize as u64, 0);
                size = n as usize;
                s
            }
            None => self.local(Op::SerializedSize, |api, c| unsafe {
                (api.fmi2SerializedFMUstateSize)(c, state, &mut size)
            }),
        };
        self.core.check("fmi2SerializedFMUstateSize", s, None)?;
        if size > MAX_STATE_BYTES {
            return Err(Error::Other(format!(
                "instance '{}': fmi2SerializedFMUstateSize reported {size} bytes, more than the {MAX_STATE_BYTES} accepted",
                self.core.name
            )));
        }
        let (s, bytes) = match self.remote() {
            Some(r) => r.serialize(state as usize as u64, size),
            None => {
                let mut bytes = vec![0u8; size];
                let s = self.local(Op::Serialize, |api, c| unsafe {
                    (api.fmi2SerializeFMUstate)(c, state, bytes.as_mut_ptr() as *mut fmi2Byte, size)
                });
                (s, bytes)
            }
        };
        self.core.check("fmi2SerializeFMUstate", s, None)?;
        if bytes.len() != size {
            return Err(Error::Other(format!(
                "instance '{}': fmi2SerializeFMUstate gave {} bytes, expected {size}",
                self.core.name,
                bytes.len()
            )));
        }
        Ok(bytes)
    }

    /// `fmi2FreeFMUstate` of a state the FMU handed out (nothing for NULL or after fmi2Fatal).
    fn free_state(&mut self, state: &mut fmi2FMUstate) -> Result<()> {
        if state.is_null() || self.core.phase == Phase::Fatal {
            return Ok(());
        }
        let s = match self.remote() {
            Some(r) => {
                let (s, h) = r.state_call(Op::FreeFmuState, *state as usize as u64, 0);
                *state = h as usize as fmi2FMUstate;
                s
            }
            None => self.local(Op::FreeFmuState, |api, c| unsafe {
                (api.fmi2FreeFMUstate)(c, state)
            }),
        };
        self.core.check("fmi2FreeFMUstate", s, None)
    }

    /// `fmi2Terminate` then `fmi2FreeInstance` (for an isolated instance the free is checked
    /// too: its process may die in it).
    pub fn terminate(mut self) -> Result<()> {
        let s = self.raw_simple(Op::Terminate);
        self.core.phase = Phase::Terminated;
        self.core.check("fmi2Terminate", s, None)?;
        if let Some(r) = self.remote() {
            let s = r.free_instance();
            self.core.phase = Phase::Freed;
            self.core.check("fmi2FreeInstance", s, None)?;
        }
        Ok(())
    }
}
