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
//! The calls go to a [`Slave`] ([`crate::slave`]): in this process ([`InProcess`]) or, isolated,
//! in a `shipsim fmu-host` child process ([`Client`], [`crate::isolate`]), where a crash, exit or
//! hang of the child is an error naming the instance, the call and the time. This file holds no
//! FFI: the state machine, the status checks and the errors are the same for every slave.

use crate::error::{Error, Result};
use crate::fmu::{Fmu, VR};
use crate::isolate::{Client, Isolation};
use crate::log::{LogCtx, LogSink};
use crate::model_description::CoSimulation;
use crate::slave::{CallMonitor, InProcess, Slave, StateHandle, GONE, MAX_STATE_BYTES};
use fmi2::{fmi2Discard, fmi2Fatal, fmi2OK, fmi2Status, fmi2Warning};
use std::ffi::CString;
use std::marker::PhantomData;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Type states.
pub struct Instantiated;
pub struct Initializing;
pub struct Stepping;

/// States in which fmi2GetXXX is allowed.
pub trait Readable {}
impl Readable for Initializing {}
impl Readable for Stepping {}

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
    /// fmi2FreeInstance was called ([`Instance::terminate`]).
    Freed,
}

/// The slaves an instance can run on: one variant per [`Slave`] implementation, dispatched by a
/// `match` (no indirect call in the step loop).
enum AnySlave {
    InProcess(InProcess),
    Isolated(Box<Client>),
}

/// `impl Slave for AnySlave`: each call goes to the variant's implementation.
macro_rules! dispatch {
    ($(fn $f:ident(&mut self $(, $a:ident: $t:ty)*) -> $r:ty;)*) => {
        impl Slave for AnySlave {
            $(
                #[inline(always)]
                fn $f(&mut self $(, $a: $t)*) -> $r {
                    match self {
                        AnySlave::InProcess(s) => s.$f($($a),*),
                        AnySlave::Isolated(s) => s.$f($($a),*),
                    }
                }
            )*
            fn lost(&self) -> Option<Error> {
                match self {
                    AnySlave::InProcess(s) => s.lost(),
                    AnySlave::Isolated(s) => s.lost(),
                }
            }
        }
    };
}

dispatch! {
    fn setup_experiment(&mut self, tolerance: Option<f64>, start: f64, stop: Option<f64>) -> fmi2Status;
    fn enter_initialization_mode(&mut self) -> fmi2Status;
    fn exit_initialization_mode(&mut self) -> fmi2Status;
    fn do_step(&mut self, t: f64, h: f64) -> fmi2Status;
    fn terminate(&mut self) -> fmi2Status;
    fn free_instance(&mut self) -> fmi2Status;
    fn set_real(&mut self, vrs: &[VR], values: &[f64]) -> fmi2Status;
    fn set_integer(&mut self, vrs: &[VR], values: &[i32]) -> fmi2Status;
    fn set_boolean(&mut self, vrs: &[VR], values: &[i32]) -> fmi2Status;
    fn set_string(&mut self, vrs: &[VR], values: &[CString]) -> fmi2Status;
    fn get_real(&mut self, vrs: &[VR], out: &mut [f64]) -> fmi2Status;
    fn get_integer(&mut self, vrs: &[VR], out: &mut [i32]) -> fmi2Status;
    fn get_boolean(&mut self, vrs: &[VR], out: &mut [i32]) -> fmi2Status;
    fn get_string(&mut self, vrs: &[VR], out: &mut [String]) -> fmi2Status;
    fn terminated(&mut self) -> (fmi2Status, bool);
    fn last_successful_time(&mut self) -> (fmi2Status, f64);
    fn get_state(&mut self) -> (fmi2Status, StateHandle);
    fn set_state(&mut self, state: StateHandle) -> fmi2Status;
    fn free_state(&mut self, state: StateHandle) -> (fmi2Status, StateHandle);
    fn serialized_size(&mut self, state: StateHandle) -> (fmi2Status, usize);
    fn serialize(&mut self, state: StateHandle, size: usize) -> (fmi2Status, Vec<u8>);
    fn deserialize(&mut self, bytes: &[u8]) -> (fmi2Status, StateHandle);
}

/// What an instance knows besides its slave.
struct Core {
    name: String,
    phase: Phase,
    log: Arc<LogCtx>,
    /// The `.fmu` file, for errors about its capabilities.
    fmu_path: PathBuf,
    /// Which of canGetAndSetFMUstate and canSerializeFMUstate the FMU lacks (FMI 2.0,
    /// sec. 4.3.1), if any.
    missing_state_capability: Option<&'static str>,
}

/// An instance in any state: the slave and what the instance knows. Its drop ends the slave
/// as the phase allows.
struct Live {
    slave: AnySlave,
    core: Core,
}

impl Live {
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
            // The slave's process died, hung or was stopped: no more calls.
            self.core.phase = Phase::Fatal;
            if let Some(e) = self.slave.lost() {
                return Err(e);
            }
        }
        if status == fmi2Fatal {
            self.core.phase = Phase::Fatal;
        } else if status == fmi2::fmi2Error || !(0..=5).contains(&status) {
            self.core.phase = Phase::Failed;
        }
        Err(self.fmi_error(function, status, time))
    }

    fn fmi_error(&self, function: &'static str, status: fmi2Status, time: Option<f64>) -> Error {
        Error::Fmi {
            instance: self.core.name.clone(),
            function,
            status,
            time,
            log: self.core.log.recent_or_hint(self.core.log.debug_logging),
        }
    }
}

impl Drop for Live {
    fn drop(&mut self) {
        let (terminate, free) = match self.core.phase {
            Phase::Initialized => (true, true),
            Phase::Fatal | Phase::Freed => (false, false),
            _ => (false, true),
        };
        if terminate {
            self.slave.terminate();
        }
        if free {
            self.slave.free_instance();
        }
        // Dropping an isolated slave ends its process (without calls after fmi2Fatal).
    }
}

/// A co-simulation slave instance in type state `S`.
pub struct Instance<S> {
    live: Live,
    _s: PhantomData<S>,
}

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
        if name.contains('\0') {
            return Err(Error::Other(format!(
                "instance name '{name}' contains a NUL byte"
            )));
        }
        let log = Arc::new(LogCtx::new(name, sink, logging_on));
        let slave = match backend.isolate {
            Some(iso) => AnySlave::Isolated(Box::new(Client::spawn(
                &self.path,
                name,
                logging_on,
                log.clone(),
                iso,
                backend.interrupt,
            )?)),
            None => AnySlave::InProcess(InProcess::instantiate(
                self,
                name,
                log.clone(),
                backend.monitor,
            )?),
        };
        let core = Core {
            name: name.to_string(),
            phase: Phase::Instantiated,
            log,
            fmu_path: self.path.clone(),
            missing_state_capability: missing_state_capability(self.co_simulation()),
        };
        Ok(Instance {
            live: Live { slave, core },
            _s: PhantomData,
        })
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
        &self.live.core.name
    }

    /// The process id of an isolated instance's host (None in process).
    pub fn host_pid(&self) -> Option<u32> {
        match &self.live.slave {
            AnySlave::Isolated(c) => Some(c.pid()),
            AnySlave::InProcess(_) => None,
        }
    }

    fn transition<T>(self) -> Instance<T> {
        Instance {
            live: self.live,
            _s: PhantomData,
        }
    }

    /// The last few log messages of this instance (for error reports).
    pub fn recent_log(&self) -> Vec<String> {
        self.live.core.log.recent_lines()
    }

    /// `fmi2SetReal`, batched.
    #[inline]
    pub fn set_real(&mut self, vrs: &[VR], values: &[f64]) -> Result<()> {
        debug_assert_eq!(vrs.len(), values.len());
        if vrs.is_empty() {
            return Ok(());
        }
        let s = self.live.slave.set_real(vrs, values);
        self.live.check("fmi2SetReal", s, None)
    }

    /// `fmi2SetInteger`, batched.
    #[inline]
    pub fn set_integer(&mut self, vrs: &[VR], values: &[i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = self.live.slave.set_integer(vrs, values);
        self.live.check("fmi2SetInteger", s, None)
    }

    /// `fmi2SetBoolean`, batched (values are fmi2Boolean, 0 or 1).
    #[inline]
    pub fn set_boolean(&mut self, vrs: &[VR], values: &[i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = self.live.slave.set_boolean(vrs, values);
        self.live.check("fmi2SetBoolean", s, None)
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
        let s = self.live.slave.set_string(vrs, &cs);
        self.live.check("fmi2SetString", s, None)
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
        let s = self.live.slave.get_real(vrs, out);
        self.live.check("fmi2GetReal", s, None)
    }

    /// `fmi2GetInteger`, batched.
    #[inline]
    pub fn get_integer(&mut self, vrs: &[VR], out: &mut [i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = self.live.slave.get_integer(vrs, out);
        self.live.check("fmi2GetInteger", s, None)
    }

    /// `fmi2GetBoolean`, batched.
    #[inline]
    pub fn get_boolean(&mut self, vrs: &[VR], out: &mut [i32]) -> Result<()> {
        if vrs.is_empty() {
            return Ok(());
        }
        let s = self.live.slave.get_boolean(vrs, out);
        self.live.check("fmi2GetBoolean", s, None)
    }

    /// `fmi2GetString` into caller-owned strings (the FMU owns its strings only until the next
    /// call, so each is copied into `out[i]`, reusing its buffer: in process, no allocation once
    /// a buffer is as long as the text; invalid UTF-8 is replaced by U+FFFD, a null pointer
    /// reads as ""). For recording String variables from the step loop.
    pub fn get_string_into(&mut self, vrs: &[VR], out: &mut [String]) -> Result<()> {
        debug_assert_eq!(vrs.len(), out.len());
        if vrs.is_empty() {
            return Ok(());
        }
        let s = self.live.slave.get_string(vrs, out);
        self.live.check("fmi2GetString", s, None)
    }

    /// `fmi2GetString` (copies the strings, which the FMU owns only until the next call).
    pub fn get_string(&mut self, vrs: &[VR]) -> Result<Vec<String>> {
        let mut out = vec![String::new(); vrs.len()];
        self.get_string_into(vrs, &mut out)?;
        Ok(out)
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
        let live = &mut self.live;
        let s = live
            .slave
            .setup_experiment(tolerance, start_time, stop_time);
        live.check("fmi2SetupExperiment", s, Some(start_time))?;
        let s = live.slave.enter_initialization_mode();
        live.check("fmi2EnterInitializationMode", s, Some(start_time))?;
        live.core.phase = Phase::Initializing;
        Ok(self.transition())
    }
}

impl Instance<Initializing> {
    /// `fmi2ExitInitializationMode`: the slave is then at its first communication point.
    pub fn exit_initialization_mode(mut self) -> Result<Instance<Stepping>> {
        let s = self.live.slave.exit_initialization_mode();
        self.live.check("fmi2ExitInitializationMode", s, None)?;
        self.live.core.phase = Phase::Initialized;
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
        let s = self.live.slave.do_step(t, h);
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
        let answered = |st: fmi2Status| st == fmi2OK || st == fmi2Warning;
        if s == fmi2Discard {
            let (st, terminated) = self.live.slave.terminated();
            if answered(st) && terminated {
                let (st, last) = self.live.slave.last_successful_time();
                let last = if answered(st) { last } else { t };
                self.live.core.phase = Phase::Initialized;
                return Ok(StepOutcome::Terminated {
                    last_successful_time: last,
                });
            }
        }
        self.live.check("fmi2DoStep", s, Some(t))?;
        Err(self.live.fmi_error("fmi2DoStep", s, Some(t)))
    }

    /// The instance's complete state as bytes (FMI 2.0, sec. 2.1.8): `fmi2GetFMUstate`,
    /// `fmi2SerializedFMUstateSize`, `fmi2SerializeFMUstate`, then `fmi2FreeFMUstate` (also when
    /// serializing fails). The bytes are the FMU's own format; [`Self::restore_state`] of an
    /// instance of the same FMU takes them back. An FMU without canGetAndSetFMUstate or
    /// canSerializeFMUstate is refused before any call.
    pub fn serialize_state(&mut self) -> Result<Vec<u8>> {
        self.require_state_support()?;
        let (s, mut state) = self.live.slave.get_state();
        if let Err(e) = self.live.check("fmi2GetFMUstate", s, None) {
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
        let (s, mut state) = self.live.slave.deserialize(bytes);
        if let Err(e) = self.live.check("fmi2DeSerializeFMUstate", s, None) {
            let _ = self.free_state(&mut state);
            return Err(e);
        }
        let s = self.live.slave.set_state(state);
        let set = self.live.check("fmi2SetFMUstate", s, None);
        let freed = self.free_state(&mut state);
        set?;
        freed
    }

    /// The FMU declares both FMU-state capabilities, else an error naming the FMU.
    fn require_state_support(&self) -> Result<()> {
        let core = &self.live.core;
        match core.missing_state_capability {
            None => Ok(()),
            Some(cap) => Err(state_support_error(&core.fmu_path, &core.name, cap)),
        }
    }

    /// Serializes a state got by `fmi2GetFMUstate`.
    fn serialize_held(&mut self, state: StateHandle) -> Result<Vec<u8>> {
        let (s, size) = self.live.slave.serialized_size(state);
        self.live.check("fmi2SerializedFMUstateSize", s, None)?;
        if size > MAX_STATE_BYTES {
            return Err(Error::Other(format!(
                "instance '{}': fmi2SerializedFMUstateSize reported {size} bytes, more than the {MAX_STATE_BYTES} accepted",
                self.live.core.name
            )));
        }
        let (s, bytes) = self.live.slave.serialize(state, size);
        self.live.check("fmi2SerializeFMUstate", s, None)?;
        if bytes.len() != size {
            return Err(Error::Other(format!(
                "instance '{}': fmi2SerializeFMUstate gave {} bytes, expected {size}",
                self.live.core.name,
                bytes.len()
            )));
        }
        Ok(bytes)
    }

    /// `fmi2FreeFMUstate` of a state the FMU handed out (nothing for none or after fmi2Fatal).
    fn free_state(&mut self, state: &mut StateHandle) -> Result<()> {
        if *state == 0 || self.live.core.phase == Phase::Fatal {
            return Ok(());
        }
        let (s, left) = self.live.slave.free_state(*state);
        *state = left;
        self.live.check("fmi2FreeFMUstate", s, None)
    }

    /// `fmi2Terminate` then `fmi2FreeInstance`, both checked (an isolated instance's process
    /// may die in either).
    pub fn terminate(mut self) -> Result<()> {
        let s = self.live.slave.terminate();
        self.live.core.phase = Phase::Terminated;
        self.live.check("fmi2Terminate", s, None)?;
        let s = self.live.slave.free_instance();
        self.live.core.phase = Phase::Freed;
        self.live.check("fmi2FreeInstance", s, None)
    }
}
