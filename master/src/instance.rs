//! A safe co-simulation slave instance whose lifecycle is enforced by types (FMI 2.0 section
//! 4.2.4, "State Machine of Calling Sequence from Master to Slave"):
//!
//! `Fmu::instantiate` -> [`Instance<Instantiated>`] -- `enter_initialization_mode` (after
//! `fmi2SetupExperiment`) -> [`Instance<Initializing>`] -- `exit_initialization_mode` ->
//! [`Instance<Stepping>`] -- `do_step`* -- `terminate`.
//!
//! A state transition consumes the instance, so no function can be called out of order. Dropping
//! an instance in any state calls `fmi2Terminate` (if initialized and not failed) and
//! `fmi2FreeInstance` (unless the FMU returned fmi2Fatal, after which the standard allows no more
//! calls), so every path, including errors and Ctrl-C, cleans up.

use crate::error::{Error, Result};
use crate::fmu::{Api, Fmu, FmuLibrary, VR};
use crate::model_description::CoSimulation;
use fmi2::*;
use std::collections::VecDeque;
use std::ffi::{c_char, c_int, c_void, CString};
use std::marker::PhantomData;
use std::path::PathBuf;
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

struct LogCtx {
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
        let inst = lossy_str(instance);
        let rec = LogRecord {
            instance: if inst.is_empty() {
                ctx.name.clone()
            } else {
                inst
            },
            status,
            category: lossy_str(category),
            message: lossy_str(message),
        };
        if let Ok(mut r) = ctx.recent.lock() {
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
        (ctx.sink)(&rec);
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
    Initialized,
    Terminated,
    Failed,
    Fatal,
}

struct Core {
    name: String,
    lib: Arc<FmuLibrary>,
    comp: fmi2Component,
    phase: Phase,
    // Kept alive for the FMU, which may hold pointers to them.
    _callbacks: Box<fmi2CallbackFunctions>,
    _target: Box<LogTarget>,
    log: Box<LogCtx>,
    _name_c: CString,
    /// The `.fmu` file, for errors about its capabilities.
    fmu_path: PathBuf,
    /// Which of canGetAndSetFMUstate and canSerializeFMUstate the FMU lacks (FMI 2.0,
    /// sec. 4.3.1), if any.
    missing_state_capability: Option<&'static str>,
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
        let api = &self.lib.api;
        unsafe {
            if self.phase == Phase::Initialized {
                (api.fmi2Terminate)(self.comp);
            }
            if self.phase != Phase::Fatal {
                (api.fmi2FreeInstance)(self.comp);
            }
        }
    }
}

/// A co-simulation slave instance in type state `S`.
pub struct Instance<S> {
    core: Box<Core>,
    /// `core.comp` and the library's function table, kept next to the instance: a call in the
    /// step loop loads them without going through the box and the `Arc`.
    comp: fmi2Component,
    api: *const Api,
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

impl Fmu {
    /// `fmi2Instantiate` as co-simulation slave (FMI 2.0 section 4.2.1), with the logger proxy,
    /// `calloc`/`free`, and the resources URI. A NULL result is an error naming the instance.
    pub fn instantiate(
        &self,
        name: &str,
        logging_on: bool,
        sink: LogSink,
    ) -> Result<Instance<Instantiated>> {
        let name_c = CString::new(name)
            .map_err(|_| Error::Other(format!("instance name '{name}' contains a NUL byte")))?;
        let guid = CString::new(self.guid())
            .map_err(|_| Error::fmu(&self.path, "GUID contains a NUL byte"))?;
        let res = CString::new(self.resource_uri()).expect("no NUL in a path URI");
        let log = Box::new(LogCtx {
            name: name.to_string(),
            sink,
            recent: Mutex::new(VecDeque::new()),
            debug_logging: logging_on,
        });
        let mut target = Box::new(LogTarget {
            sink: Some(log_sink),
            ctx: &*log as *const LogCtx as *mut c_void,
        });
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: logger_proxy(),
            allocateMemory: Some(fmi_calloc),
            freeMemory: Some(fmi_free),
            stepFinished: None,
            componentEnvironment: &mut *target as *mut LogTarget as *mut c_void,
        });
        let call = |logging_on: bool| unsafe {
            (self.lib.api.fmi2Instantiate)(
                name_c.as_ptr(),
                fmi2CoSimulation,
                guid.as_ptr(),
                res.as_ptr(),
                &*callbacks,
                fmi2False,
                if logging_on { fmi2True } else { fmi2False },
            )
        };
        let comp = call(logging_on);
        if comp.is_null() {
            return Err(self.instantiate_failed(name, &log, call));
        }
        Ok(Instance {
            comp,
            api: &self.lib.api,
            core: Box::new(Core {
                name: name.to_string(),
                lib: self.lib.clone(),
                comp,
                phase: Phase::Instantiated,
                _callbacks: callbacks,
                _target: target,
                log,
                _name_c: name_c,
                fmu_path: self.path.clone(),
                missing_state_capability: missing_state_capability(self.co_simulation()),
            }),
            _s: PhantomData,
        })
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
                unsafe { (self.lib.api.fmi2FreeInstance)(comp) };
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

impl<S> Instance<S> {
    pub fn name(&self) -> &str {
        &self.core.name
    }

    fn transition<T>(self) -> Instance<T> {
        Instance {
            core: self.core,
            comp: self.comp,
            api: self.api,
            _s: PhantomData,
        }
    }

    /// The library's function table.
    #[inline(always)]
    fn api(&self) -> &Api {
        // SAFETY: `api` points into the `FmuLibrary` that `core.lib` (an `Arc`) keeps alive for
        // as long as this instance exists.
        unsafe { &*self.api }
    }

    /// The last few log messages of this instance (for error reports).
    pub fn recent_log(&self) -> Vec<String> {
        self.core
            .log
            .recent
            .lock()
            .map(|r| r.iter().cloned().collect())
            .unwrap_or_default()
    }

    /// `fmi2SetReal`, batched.
    #[inline]
    pub fn set_real(&mut self, vrs: &[VR], values: &[f64]) -> Result<()> {
        debug_assert_eq!(vrs.len(), values.len());
        if vrs.is_empty() {
            return Ok(());
        }
        let s = unsafe {
            (self.api().fmi2SetReal)(self.comp, vrs.as_ptr(), vrs.len(), values.as_ptr())
        };
        self.core.check("fmi2SetReal", s, None)
    }

    /// `fmi2SetInteger`, batched.
    #[inline]
    pub fn set_integer(&mut self, vrs: &[VR], values: &[i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = unsafe {
            (self.api().fmi2SetInteger)(self.comp, vrs.as_ptr(), vrs.len(), values.as_ptr())
        };
        self.core.check("fmi2SetInteger", s, None)
    }

    /// `fmi2SetBoolean`, batched (values are fmi2Boolean, 0 or 1).
    #[inline]
    pub fn set_boolean(&mut self, vrs: &[VR], values: &[i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = unsafe {
            (self.api().fmi2SetBoolean)(self.comp, vrs.as_ptr(), vrs.len(), values.as_ptr())
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
        let ptrs: Vec<fmi2String> = cs.iter().map(|c| c.as_ptr()).collect();
        let s = unsafe {
            (self.api().fmi2SetString)(self.comp, vrs.as_ptr(), vrs.len(), ptrs.as_ptr())
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
        let s = unsafe {
            (self.api().fmi2GetReal)(self.comp, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        };
        self.core.check("fmi2GetReal", s, None)
    }

    /// `fmi2GetInteger`, batched.
    #[inline]
    pub fn get_integer(&mut self, vrs: &[VR], out: &mut [i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = unsafe {
            (self.api().fmi2GetInteger)(self.comp, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        };
        self.core.check("fmi2GetInteger", s, None)
    }

    /// `fmi2GetBoolean`, batched.
    #[inline]
    pub fn get_boolean(&mut self, vrs: &[VR], out: &mut [i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = unsafe {
            (self.api().fmi2GetBoolean)(self.comp, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        };
        self.core.check("fmi2GetBoolean", s, None)
    }

    /// `fmi2GetString` (copies the strings, which the FMU owns only until the next call).
    pub fn get_string(&mut self, vrs: &[VR]) -> Result<Vec<String>> {
        let mut ptrs: Vec<fmi2String> = vec![std::ptr::null(); vrs.len()];
        let s = unsafe {
            (self.api().fmi2GetString)(self.comp, vrs.as_ptr(), vrs.len(), ptrs.as_mut_ptr())
        };
        self.core.check("fmi2GetString", s, None)?;
        Ok(ptrs.iter().map(|p| unsafe { lossy_str(*p) }).collect())
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
        let lib = self.core.lib.clone();
        let api = &lib.api;
        let s = unsafe {
            (api.fmi2SetupExperiment)(
                self.comp,
                tolerance.is_some() as fmi2Boolean,
                tolerance.unwrap_or(0.0),
                start_time,
                stop_time.is_some() as fmi2Boolean,
                stop_time.unwrap_or(0.0),
            )
        };
        self.core
            .check("fmi2SetupExperiment", s, Some(start_time))?;
        let s = unsafe { (api.fmi2EnterInitializationMode)(self.comp) };
        self.core
            .check("fmi2EnterInitializationMode", s, Some(start_time))?;
        self.core.phase = Phase::Initialized;
        Ok(self.transition())
    }
}

impl Instance<Initializing> {
    /// `fmi2ExitInitializationMode`: the slave is then at its first communication point.
    pub fn exit_initialization_mode(mut self) -> Result<Instance<Stepping>> {
        let s = unsafe { (self.api().fmi2ExitInitializationMode)(self.comp) };
        self.core.check("fmi2ExitInitializationMode", s, None)?;
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
        let s = unsafe { (self.api().fmi2DoStep)(self.comp, t, h, fmi2True) };
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
        let api = self.api();
        if s == fmi2Discard {
            let mut terminated: fmi2Boolean = fmi2False;
            let st =
                unsafe { (api.fmi2GetBooleanStatus)(self.comp, fmi2Terminated, &mut terminated) };
            if st <= fmi2Warning && terminated != fmi2False {
                let mut last = t;
                let st = unsafe {
                    (api.fmi2GetRealStatus)(self.comp, fmi2LastSuccessfulTime, &mut last)
                };
                if st > fmi2Warning {
                    last = t;
                }
                self.core.phase = Phase::Initialized;
                return Ok(StepOutcome::Terminated {
                    last_successful_time: last,
                });
            }
        }
        self.core.check("fmi2DoStep", s, Some(t))?;
        Err(self.core.fmi_error("fmi2DoStep", s, Some(t)))
    }

    /// The instance's complete state as bytes (FMI 2.0, sec. 2.1.8): `fmi2GetFMUstate`,
    /// `fmi2SerializedFMUstateSize`, `fmi2SerializeFMUstate`, then `fmi2FreeFMUstate` (also when
    /// serializing fails). The bytes are the FMU's own format; [`Self::restore_state`] of an
    /// instance of the same FMU takes them back. An FMU without canGetAndSetFMUstate or
    /// canSerializeFMUstate is refused before any call.
    pub fn serialize_state(&mut self) -> Result<Vec<u8>> {
        self.require_state_support()?;
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let s = unsafe { (self.api().fmi2GetFMUstate)(self.comp, &mut state) };
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
        let s = unsafe {
            (self.api().fmi2DeSerializeFMUstate)(
                self.comp,
                bytes.as_ptr() as *const fmi2Byte,
                bytes.len(),
                &mut state,
            )
        };
        if let Err(e) = self.core.check("fmi2DeSerializeFMUstate", s, None) {
            let _ = self.free_state(&mut state);
            return Err(e);
        }
        let s = unsafe { (self.api().fmi2SetFMUstate)(self.comp, state) };
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
        let s = unsafe { (self.api().fmi2SerializedFMUstateSize)(self.comp, state, &mut size) };
        self.core.check("fmi2SerializedFMUstateSize", s, None)?;
        if size > MAX_STATE_BYTES {
            return Err(Error::Other(format!(
                "instance '{}': fmi2SerializedFMUstateSize reported {size} bytes, more than the {MAX_STATE_BYTES} accepted",
                self.core.name
            )));
        }
        let mut bytes = vec![0u8; size];
        let s = unsafe {
            (self.api().fmi2SerializeFMUstate)(
                self.comp,
                state,
                bytes.as_mut_ptr() as *mut fmi2Byte,
                size,
            )
        };
        self.core.check("fmi2SerializeFMUstate", s, None)?;
        Ok(bytes)
    }

    /// `fmi2FreeFMUstate` of a state the FMU handed out (nothing for NULL or after fmi2Fatal).
    fn free_state(&mut self, state: &mut fmi2FMUstate) -> Result<()> {
        if state.is_null() || self.core.phase == Phase::Fatal {
            return Ok(());
        }
        let s = unsafe { (self.api().fmi2FreeFMUstate)(self.comp, state) };
        self.core.check("fmi2FreeFMUstate", s, None)
    }

    /// `fmi2Terminate` then `fmi2FreeInstance`.
    pub fn terminate(mut self) -> Result<()> {
        let s = unsafe { (self.api().fmi2Terminate)(self.comp) };
        self.core.phase = Phase::Terminated;
        self.core.check("fmi2Terminate", s, None)
    }
}
