//! The in-process [`Slave`]: the FMU's functions, resolved once by the importer
//! ([`crate::fmu`]), called directly. Every raw FMI call of the master is in this file, with
//! `fmi2Instantiate` and the callbacks the FMU keeps (logger, `calloc`/`free`).
//!
//! Each call is noted in the run's [`CallMonitor`], when there is one, before and after.

use super::{CallMonitor, Op, Slave, StateHandle};
use crate::error::{Error, Result};
use crate::fmu::{Api, Fmu, FmuLibrary, VR};
use crate::log::LogCtx;
use fmi2::*;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::sync::Arc;

/// An FMU instance in this process.
pub struct InProcess {
    /// The function table (in the library `lib` keeps loaded) and the component: read by every
    /// call, so they come first.
    api: *const Api,
    comp: fmi2Component,
    /// The monitor in `_monitor`, or null, and this instance's number there.
    monitor: *const CallMonitor,
    slot: u16,
    /// Keeps the library (and so `api`) loaded.
    _lib: Arc<FmuLibrary>,
    // Kept alive for the FMU, which may hold pointers to them.
    _callbacks: Box<fmi2CallbackFunctions>,
    _target: Box<LogTarget>,
    _log: Arc<LogCtx>,
    _name: CString,
    _monitor: Option<Arc<CallMonitor>>,
}

// The FMU is only called from the thread that owns the instance.
unsafe impl Send for InProcess {}

impl InProcess {
    /// `fmi2Instantiate` as co-simulation slave (FMI 2.0, sec. 2.1.5 and 4.2.1) with the logger
    /// proxy delivering to `log`, `calloc`/`free`, and the resources URI. A NULL result is an
    /// error naming the instance, with what the FMU logged.
    pub(crate) fn instantiate(
        fmu: &Fmu,
        name: &str,
        log: Arc<LogCtx>,
        monitor: Option<Arc<CallMonitor>>,
    ) -> Result<InProcess> {
        let Some(api) = fmu.lib.api.as_ref() else {
            return Err(Error::fmu(
                &fmu.path,
                format!(
                    "instance '{name}': the FMU was opened for isolated instances only (its binary is not loaded in this process)"
                ),
            ));
        };
        let name_c = CString::new(name)
            .map_err(|_| Error::Other(format!("instance name '{name}' contains a NUL byte")))?;
        let guid = CString::new(fmu.guid())
            .map_err(|_| Error::fmu(&fmu.path, "GUID contains a NUL byte"))?;
        let res = CString::new(fmu.resource_uri()).expect("no NUL in a path URI");
        let mut target = Box::new(LogTarget {
            sink: Some(log_sink),
            ctx: Arc::as_ptr(&log) as *mut c_void,
        });
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: logger_proxy(),
            allocateMemory: Some(fmi_calloc),
            freeMemory: Some(fmi_free),
            stepFinished: None,
            componentEnvironment: &mut *target as *mut LogTarget as *mut c_void,
        });
        let slot = monitor.as_ref().map(|m| m.register(name));
        let call = |logging_on: bool| unsafe {
            if let (Some(m), Some(slot)) = (&monitor, slot) {
                m.enter(slot, Op::Instantiate);
            }
            let c = (api.fmi2Instantiate)(
                name_c.as_ptr(),
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
        let comp = call(log.debug_logging);
        if comp.is_null() {
            return Err(instantiate_failed(fmu, api, name, &log, call));
        }
        Ok(InProcess {
            api,
            comp,
            monitor: monitor.as_ref().map_or(std::ptr::null(), Arc::as_ptr),
            slot: slot.unwrap_or(0),
            _lib: fmu.lib.clone(),
            _callbacks: callbacks,
            _target: target,
            _log: log,
            _name: name_c,
            _monitor: monitor,
        })
    }

    /// Calls `f` with the function table and the component, noting the call in the monitor.
    #[inline(always)]
    fn call<T>(&self, op: Op, f: impl FnOnce(&Api, fmi2Component) -> T) -> T {
        // SAFETY: `api` points into the library `self._lib` keeps loaded; `monitor` into the
        // `Arc` in `self._monitor`.
        let api = unsafe { &*self.api };
        match unsafe { self.monitor.as_ref() } {
            None => f(api, self.comp),
            Some(m) => {
                m.enter(self.slot, op);
                let r = f(api, self.comp);
                m.leave();
                r
            }
        }
    }
}

/// The error for a NULL from `fmi2Instantiate`, with what the FMU logged. If it logged nothing
/// with debug logging off, it is instantiated once more with loggingOn = fmi2True (`again`) to
/// learn why: some FMUs, PythonFMU's among them, report even their errors only with debug
/// logging on. Those messages reach the sink like any other (errors and warnings are shown by
/// default) and the error.
#[cold]
#[inline(never)]
fn instantiate_failed(
    fmu: &Fmu,
    api: &Api,
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
            unsafe { (api.fmi2FreeInstance)(comp) };
            note = " (it succeeded with loggingOn = true)";
        }
    }
    Error::fmu(
        &fmu.path,
        format!(
            "fmi2Instantiate returned NULL for instance '{name}' (GUID \"{}\"){note}; FMU log: {}{}",
            fmu.guid(),
            log.recent_or_hint(debug_logging).join(" | "),
            python_note(fmu)
        ),
    )
}

/// For an FMU that runs on the process's Python ([`crate::fmu::python`]): which one, and how
/// to choose another (its packages, e.g. numpy, must be installed there).
fn python_note(fmu: &Fmu) -> String {
    match crate::fmu::python::ensure_runtime() {
        Ok(which) if fmu.lib.python => format!(
            "; the FMU runs on {which}: install its Python packages there, or set SHIPSIM_PYTHON to a Python that has them"
        ),
        _ => String::new(),
    }
}

// SAFETY (every call below): the FMI 2.0 functions of the loaded library on the component it
// instantiated, with buffers of the lengths passed.
impl Slave for InProcess {
    fn setup_experiment(&mut self, tol: Option<f64>, start: f64, stop: Option<f64>) -> fmi2Status {
        if let Some(m) = unsafe { self.monitor.as_ref() } {
            m.at(start);
        }
        self.call(Op::SetupExperiment, |api, c| unsafe {
            (api.fmi2SetupExperiment)(
                c,
                tol.is_some() as fmi2Boolean,
                tol.unwrap_or(0.0),
                start,
                stop.is_some() as fmi2Boolean,
                stop.unwrap_or(0.0),
            )
        })
    }

    fn enter_initialization_mode(&mut self) -> fmi2Status {
        self.call(Op::EnterInitializationMode, |api, c| unsafe {
            (api.fmi2EnterInitializationMode)(c)
        })
    }

    fn exit_initialization_mode(&mut self) -> fmi2Status {
        self.call(Op::ExitInitializationMode, |api, c| unsafe {
            (api.fmi2ExitInitializationMode)(c)
        })
    }

    #[inline(always)]
    fn do_step(&mut self, t: f64, h: f64) -> fmi2Status {
        // SAFETY: as in `call`.
        let monitor = unsafe { self.monitor.as_ref() };
        if let Some(m) = monitor {
            m.enter_step(self.slot, t);
        }
        let s = unsafe { ((*self.api).fmi2DoStep)(self.comp, t, h, fmi2True) };
        if let Some(m) = monitor {
            m.at(t + h);
            m.leave();
        }
        s
    }

    fn terminate(&mut self) -> fmi2Status {
        self.call(Op::Terminate, |api, c| unsafe { (api.fmi2Terminate)(c) })
    }

    fn free_instance(&mut self) -> fmi2Status {
        if self.comp.is_null() {
            return fmi2OK;
        }
        self.call(Op::FreeInstance, |api, c| unsafe {
            (api.fmi2FreeInstance)(c)
        });
        self.comp = std::ptr::null_mut();
        fmi2OK
    }

    #[inline(always)]
    fn set_real(&mut self, vrs: &[VR], values: &[f64]) -> fmi2Status {
        self.call(Op::SetReal, |api, c| unsafe {
            (api.fmi2SetReal)(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
        })
    }

    #[inline(always)]
    fn set_integer(&mut self, vrs: &[VR], values: &[i32]) -> fmi2Status {
        self.call(Op::SetInteger, |api, c| unsafe {
            (api.fmi2SetInteger)(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
        })
    }

    #[inline(always)]
    fn set_boolean(&mut self, vrs: &[VR], values: &[i32]) -> fmi2Status {
        self.call(Op::SetBoolean, |api, c| unsafe {
            (api.fmi2SetBoolean)(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
        })
    }

    fn set_string(&mut self, vrs: &[VR], values: &[CString]) -> fmi2Status {
        let ptrs: Vec<fmi2String> = values.iter().map(|c| c.as_ptr()).collect();
        let n = vrs.len().min(ptrs.len());
        self.call(Op::SetString, |api, c| unsafe {
            (api.fmi2SetString)(c, vrs.as_ptr(), n, ptrs.as_ptr())
        })
    }

    #[inline(always)]
    fn get_real(&mut self, vrs: &[VR], out: &mut [f64]) -> fmi2Status {
        self.call(Op::GetReal, |api, c| unsafe {
            (api.fmi2GetReal)(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        })
    }

    #[inline(always)]
    fn get_integer(&mut self, vrs: &[VR], out: &mut [i32]) -> fmi2Status {
        self.call(Op::GetInteger, |api, c| unsafe {
            (api.fmi2GetInteger)(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        })
    }

    #[inline(always)]
    fn get_boolean(&mut self, vrs: &[VR], out: &mut [i32]) -> fmi2Status {
        self.call(Op::GetBoolean, |api, c| unsafe {
            (api.fmi2GetBoolean)(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        })
    }

    /// In batches of up to 32 value references: no allocation once each buffer in `out` is as
    /// long as its text.
    fn get_string(&mut self, vrs: &[VR], out: &mut [String]) -> fmi2Status {
        const BATCH: usize = 32;
        let mut status = fmi2OK;
        for (vrs, out) in vrs.chunks(BATCH).zip(out.chunks_mut(BATCH)) {
            let mut ptrs: [fmi2String; BATCH] = [std::ptr::null(); BATCH];
            let s = self.call(Op::GetString, |api, c| unsafe {
                (api.fmi2GetString)(c, vrs.as_ptr(), vrs.len(), ptrs.as_mut_ptr())
            });
            if s != fmi2OK && s != fmi2Warning {
                return s;
            }
            status = status.max(s);
            for (o, p) in out.iter_mut().zip(&ptrs) {
                o.clear();
                if !p.is_null() {
                    // SAFETY: a NUL-terminated string the FMU owns until its next call.
                    o.push_str(&unsafe { CStr::from_ptr(*p) }.to_string_lossy());
                }
            }
        }
        status
    }

    fn terminated(&mut self) -> (fmi2Status, bool) {
        let mut v: fmi2Boolean = fmi2False;
        let s = self.call(Op::GetBooleanStatus, |api, c| unsafe {
            (api.fmi2GetBooleanStatus)(c, fmi2Terminated, &mut v)
        });
        (s, v != fmi2False)
    }

    fn last_successful_time(&mut self) -> (fmi2Status, f64) {
        let mut v = 0.0;
        let s = self.call(Op::GetRealStatus, |api, c| unsafe {
            (api.fmi2GetRealStatus)(c, fmi2LastSuccessfulTime, &mut v)
        });
        (s, v)
    }

    fn get_state(&mut self) -> (fmi2Status, StateHandle) {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let s = self.call(Op::GetFmuState, |api, c| unsafe {
            (api.fmi2GetFMUstate)(c, &mut state)
        });
        (s, state as usize as StateHandle)
    }

    fn set_state(&mut self, state: StateHandle) -> fmi2Status {
        self.call(Op::SetFmuState, |api, c| unsafe {
            (api.fmi2SetFMUstate)(c, state as usize as fmi2FMUstate)
        })
    }

    fn free_state(&mut self, state: StateHandle) -> (fmi2Status, StateHandle) {
        let mut state = state as usize as fmi2FMUstate;
        let s = self.call(Op::FreeFmuState, |api, c| unsafe {
            (api.fmi2FreeFMUstate)(c, &mut state)
        });
        (s, state as usize as StateHandle)
    }

    fn serialized_size(&mut self, state: StateHandle) -> (fmi2Status, usize) {
        let mut size = 0usize;
        let s = self.call(Op::SerializedSize, |api, c| unsafe {
            (api.fmi2SerializedFMUstateSize)(c, state as usize as fmi2FMUstate, &mut size)
        });
        (s, size)
    }

    fn serialize(&mut self, state: StateHandle, size: usize) -> (fmi2Status, Vec<u8>) {
        let mut bytes = vec![0u8; size];
        let s = self.call(Op::Serialize, |api, c| unsafe {
            (api.fmi2SerializeFMUstate)(
                c,
                state as usize as fmi2FMUstate,
                bytes.as_mut_ptr() as *mut fmi2Byte,
                size,
            )
        });
        (s, bytes)
    }

    fn deserialize(&mut self, bytes: &[u8]) -> (fmi2Status, StateHandle) {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let s = self.call(Op::Deserialize, |api, c| unsafe {
            (api.fmi2DeSerializeFMUstate)(
                c,
                bytes.as_ptr() as *const fmi2Byte,
                bytes.len(),
                &mut state,
            )
        });
        (s, state as usize as StateHandle)
    }

    fn lost(&self) -> Option<Error> {
        None
    }
}

/// The FMU's log callback (through [`logger_proxy`], which formats the message): delivers to the
/// instance's [`LogCtx`].
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
