//! One FMU instance: the model, the lifecycle state, the logger, and the FMU-state snapshot.

use crate::fast::FastAccess;
use crate::{FmuModel, LOG_CATEGORIES};
use fmi2::*;
use serde::{Deserialize, Serialize};
use std::ffi::CString;

/// Lifecycle states of an FMI 2.0 co-simulation slave (FMI 2.0 section 4.2.4), as bit flags so
/// that each function's set of legal states is a mask (as in the Reference FMUs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[repr(u32)]
pub enum LifeState {
    Instantiated = 1 << 1,
    InitializationMode = 1 << 2,
    StepComplete = 1 << 5,
    StepFailed = 1 << 7,
    Terminated = 1 << 9,
    Error = 1 << 10,
}

impl LifeState {
    pub fn name(self) -> &'static str {
        match self {
            LifeState::Instantiated => "Instantiated",
            LifeState::InitializationMode => "InitializationMode",
            LifeState::StepComplete => "StepComplete",
            LifeState::StepFailed => "StepFailed",
            LifeState::Terminated => "Terminated",
            LifeState::Error => "Error",
        }
    }
}

/// Masks of legal states per function (Reference FMUs `fmi2Functions.c`, co-simulation subset;
/// StepInProgress/StepCanceled never occur because no step is asynchronous).
pub mod mask {
    use super::LifeState::*;
    const I: u32 = Instantiated as u32;
    const IM: u32 = InitializationMode as u32;
    const SC: u32 = StepComplete as u32;
    const SF: u32 = StepFailed as u32;
    const T: u32 = Terminated as u32;
    const E: u32 = Error as u32;
    pub const SET_DEBUG_LOGGING: u32 = I | IM | SC | SF | T | E;
    pub const ANY: u32 = I | IM | SC | SF | T | E;
    pub const SETUP_EXPERIMENT: u32 = I;
    pub const ENTER_INITIALIZATION_MODE: u32 = I;
    pub const EXIT_INITIALIZATION_MODE: u32 = IM;
    pub const TERMINATE: u32 = SC | SF;
    pub const RESET: u32 = ANY;
    pub const GET: u32 = IM | SC | SF | T | E;
    pub const SET_REAL: u32 = I | IM | SC;
    pub const SET_OTHER: u32 = I | IM | SC;
    pub const FMU_STATE: u32 = ANY;
    pub const DO_STEP: u32 = SC;
    pub const GET_STATUS: u32 = SC | SF | T;
}

/// Time bookkeeping and lifecycle state, saved with every FMU state.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Core {
    pub state: LifeState,
    pub time: f64,
    pub start_time: f64,
    pub stop_time: Option<f64>,
}

/// What `fmi2GetFMUstate` hands out: the model and the core. `magic` identifies the model type.
#[repr(C)]
pub struct StateBox<M> {
    pub magic: u64,
    pub snapshot: Snapshot<M>,
}

#[derive(Clone, Serialize, Deserialize)]
#[serde(bound = "M: FmuModel")]
pub struct Snapshot<M> {
    pub model: M,
    pub core: Core,
}

pub struct Instance<M> {
    pub model: M,
    pub core: Core,
    /// Outputs need recomputing because an input or parameter was set.
    pub dirty: bool,
    pub name: CString,
    pub logger: fmi2CallbackLogger,
    pub env: fmi2ComponentEnvironment,
    pub enabled: [bool; LOG_CATEGORIES.len()],
    /// FNV-1a of the GUID: tags FMU states and serialized states of this model.
    pub magic: u64,
    /// The Real accessors by value reference, for `fmi2GetReal` and `fmi2SetReal`.
    pub fast: FastAccess<M>,
    /// A step size up to which `fmi2DoStep` needs no work-bound check: half the bound's passes
    /// of the shortest internal loop, taken when a step passed the check; 0 (check every
    /// step) after anything that may change a loop (a parameter set through the table, a
    /// restored state, initialization, reset).
    pub work_limit: f64,
    /// The FMU states this instance handed out (`fmi2GetFMUstate`, `fmi2DeSerializeFMUstate`)
    /// and not yet freed, by address. Every state call looks its pointer up here before
    /// touching it, so a freed, foreign or made-up pointer is an fmi2Error and never a read of
    /// freed memory (a second `fmi2FreeFMUstate` of one state was a double free that aborted
    /// the host: the fuzzer's `replay calls TokyoMaru 2044 28`). `fmi2FreeInstance` frees the
    /// states left here (FMI 2.0, sec. 2.1.6: it "frees all the allocated memory").
    pub states: Vec<usize>,
}

pub const CAT_EVENTS: usize = 0;
#[allow(dead_code)]
pub const CAT_WARNING: usize = 1;
pub const CAT_ERROR: usize = 2;
#[allow(dead_code)]
pub const CAT_FATAL: usize = 3;
pub const CAT_CALLS: usize = 4;

/// Per-call tracing (`logCalls`) compiled in: always, except in the variant that
/// `cargo xtask bench` builds with `--cfg shipsim_no_call_log` to measure what the check costs
/// while logging is off (the "logging off" row of docs/bench.md).
const CALL_LOG: bool = !cfg!(shipsim_no_call_log);

/// Which log categories `fmi2Instantiate` enables. The status categories (`logStatusWarning`,
/// `logStatusError`, `logStatusFatal`) are always on: an FMU reports its errors whatever the
/// debug setting. `loggingOn` switches debug logging (FMI 2.0, sec. 2.1.5, `fmi2Instantiate`:
/// "If loggingOn=fmi2True, debug logging is enabled ... Which LogCategories the FMU sets is
/// unspecified"); here it enables `logEvents` (a few lifecycle lines per instance) but never
/// `logCalls` (one line per FMI call). Per-call tracing needs `fmi2SetDebugLogging` with
/// `logCalls` named, or with loggingOn = fmi2True and no categories ("all debug messages",
/// FMI 2.0, sec. 2.1.5, `fmi2SetDebugLogging`).
fn debug_categories_at_instantiation(logging_on: bool) -> [bool; LOG_CATEGORIES.len()] {
    let mut enabled = [true; LOG_CATEGORIES.len()];
    enabled[CAT_EVENTS] = logging_on;
    enabled[CAT_CALLS] = false;
    enabled
}

/// FNV-1a 64-bit.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf29ce484222325;
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x100000001b3);
    }
    h
}

impl<M> Drop for Instance<M> {
    /// Frees the FMU states the importer did not free.
    fn drop(&mut self) {
        for addr in self.states.drain(..) {
            // SAFETY: every address in `states` came from `Box::into_raw` of a `StateBox<M>`
            // and is removed from `states` when freed.
            drop(unsafe { Box::from_raw(addr as *mut StateBox<M>) });
        }
    }
}

impl<M: FmuModel> Instance<M> {
    /// An instance of `model` (the start values, `M::default()`).
    pub fn new(
        model: M,
        name: CString,
        logger: fmi2CallbackLogger,
        env: fmi2ComponentEnvironment,
        logging_on: bool,
        magic: u64,
    ) -> Self {
        // Per-call tracing only on the importer's explicit request: libcosim (through FMI
        // Library) always instantiates with loggingOn = fmi2True.
        let enabled = debug_categories_at_instantiation(logging_on);
        Instance {
            model,
            core: Core {
                state: LifeState::Instantiated,
                time: 0.0,
                start_time: 0.0,
                stop_time: None,
            },
            dirty: true,
            name,
            logger,
            env,
            enabled,
            magic,
            fast: FastAccess::new(),
            work_limit: 0.0,
            states: Vec::new(),
        }
    }

    /// Sends a message through the importer's logger if its category is enabled. `%` is escaped
    /// because importers format the message with printf.
    pub fn log(&self, status: fmi2Status, category: usize, message: &str) {
        if !self.enabled[category] {
            return;
        }
        log_raw(
            self.logger,
            self.env,
            &self.name,
            status,
            LOG_CATEGORIES[category].0,
            message,
        );
    }

    /// [`Instance::log`] of a message that is formatted only if its category is enabled.
    pub fn log_fmt(&self, status: fmi2Status, category: usize, message: std::fmt::Arguments) {
        if self.enabled[category] {
            self.log(status, category, &message.to_string());
        }
    }

    pub fn error(&self, message: &str) -> fmi2Status {
        self.log(fmi2Error, CAT_ERROR, message);
        fmi2Error
    }

    /// Returns an error status and a log line unless the current state is in `mask`.
    /// Inlined into every entry: the legal, logging-off path is a mask test and a flag test.
    #[inline(always)]
    pub fn check_state(&self, function: &str, mask: u32) -> Result<(), fmi2Status> {
        if self.core.state as u32 & mask != 0 {
            if CALL_LOG && self.enabled[CAT_CALLS] {
                self.log_call(function);
            }
            Ok(())
        } else {
            Err(self.illegal_call(function))
        }
    }

    #[cold]
    #[inline(never)]
    fn log_call(&self, function: &str) {
        self.log(fmi2OK, CAT_CALLS, function);
    }

    #[cold]
    #[inline(never)]
    fn illegal_call(&self, function: &str) -> fmi2Status {
        self.error(&format!(
            "Illegal call sequence: {function} is not allowed in state {}.",
            self.core.state.name()
        ))
    }

    #[inline(always)]
    pub fn refresh_outputs(&mut self) {
        if self.dirty {
            self.model.calculate_outputs();
            self.dirty = false;
        }
    }
}

/// Logs through a logger callback without an instance (used before one exists).
pub fn log_raw(
    logger: fmi2CallbackLogger,
    env: fmi2ComponentEnvironment,
    name: &CString,
    status: fmi2Status,
    category: &str,
    message: &str,
) {
    let Some(logger) = logger else { return };
    let escaped = message.replace('%', "%%").replace('\0', " ");
    let (Ok(msg), Ok(cat)) = (CString::new(escaped), CString::new(category)) else {
        return;
    };
    // SAFETY: the importer guarantees the logger is callable with these arguments; all strings
    // are NUL-terminated and live for the duration of the call.
    unsafe { logger(env, name.as_ptr(), status, cat.as_ptr(), msg.as_ptr()) };
}
