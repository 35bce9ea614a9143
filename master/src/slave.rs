//! The one layer that calls FMUs: the FMI calls the master makes on one instance, as the
//! [`Slave`] trait (libcosim's `slave` interface), and its implementations:
//!
//! - [`InProcess`]: the FMU's functions called directly. The only file with raw FMI calls is
//!   `slave/in_process.rs` (besides the loader's `fmi2GetVersion` check in [`crate::fmu`]);
//! - [`crate::isolate::Client`]: the same calls sent to a `shipsim fmu-host` child process, which
//!   serves them through an [`InProcess`] of its own ([`crate::isolate::host`]).
//!
//! Each call returns the FMU's status as it came (or [`GONE`] when an out-of-process slave can no
//! longer answer: [`Slave::lost`] says why); the typestate [`crate::instance::Instance`] checks
//! statuses, keeps the lifecycle and words the errors, the same for every implementation. An
//! FMI 3.0 instance is a third implementation of the same trait.
//!
//! [`CallMonitor`] notes which call of an in-process instance is in progress, for the CLI's
//! `exit()` hook and watchdog.

mod in_process;
mod monitor;

pub use in_process::InProcess;
pub use monitor::{CallMonitor, InProgress};

use crate::error::Error;
use crate::fmu::VR;
use fmi2::fmi2Status;
use std::ffi::CString;

/// The status of a call that got no answer: the slave is gone ([`Slave::lost`]).
pub const GONE: fmi2Status = -0x4000;

/// The largest serialized FMU state accepted: a larger size reported by an FMU is an error,
/// not an allocation.
pub const MAX_STATE_BYTES: usize = 1 << 30;

/// An FMU state handed out by a slave (FMI 2.0, sec. 2.1.8): the FMU's pointer, as a number
/// (for an isolated instance, a pointer in the child). 0 is no state.
pub type StateHandle = u64;

macro_rules! ops {
    ($($op:ident = $n:literal, $name:literal;)*) => {
        /// The FMI calls the master makes (FMI 2.0, sec. 2.1 and 4.2): the names of errors and
        /// of the call in progress, and the request tags of an isolated instance's pipe.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        #[repr(u8)]
        pub enum Op {
            $($op = $n,)*
        }
        impl Op {
            /// The FMI function's name.
            pub fn name(self) -> &'static str {
                match self {
                    $(Op::$op => $name,)*
                }
            }
            pub fn from_u32(n: u32) -> Option<Op> {
                match n {
                    $($n => Some(Op::$op),)*
                    _ => None,
                }
            }
        }
    };
}

ops! {
    Instantiate = 1, "fmi2Instantiate";
    SetupExperiment = 2, "fmi2SetupExperiment";
    EnterInitializationMode = 3, "fmi2EnterInitializationMode";
    ExitInitializationMode = 4, "fmi2ExitInitializationMode";
    DoStep = 5, "fmi2DoStep";
    Terminate = 6, "fmi2Terminate";
    FreeInstance = 7, "fmi2FreeInstance";
    SetReal = 8, "fmi2SetReal";
    SetInteger = 9, "fmi2SetInteger";
    SetBoolean = 10, "fmi2SetBoolean";
    SetString = 11, "fmi2SetString";
    GetReal = 12, "fmi2GetReal";
    GetInteger = 13, "fmi2GetInteger";
    GetBoolean = 14, "fmi2GetBoolean";
    GetString = 15, "fmi2GetString";
    GetBooleanStatus = 16, "fmi2GetBooleanStatus";
    GetRealStatus = 17, "fmi2GetRealStatus";
    GetFmuState = 18, "fmi2GetFMUstate";
    SerializedSize = 19, "fmi2SerializedFMUstateSize";
    Serialize = 20, "fmi2SerializeFMUstate";
    Deserialize = 21, "fmi2DeSerializeFMUstate";
    SetFmuState = 22, "fmi2SetFMUstate";
    FreeFmuState = 23, "fmi2FreeFMUstate";
}

/// The FMI calls the master makes on one co-simulation instance (FMI 2.0, sec. 2.1 and 4.2),
/// after it was instantiated. Arguments and results are those of the C functions; each returns
/// the FMU's status unchecked, or [`GONE`]. Value buffers are the caller's: a call of the step
/// loop allocates nothing.
pub trait Slave {
    /// `fmi2SetupExperiment` (no tolerance or stop time when None).
    fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> fmi2Status;
    fn enter_initialization_mode(&mut self) -> fmi2Status;
    fn exit_initialization_mode(&mut self) -> fmi2Status;
    /// `fmi2DoStep(t, h, noSetFMUStatePriorToCurrentPoint = true)`.
    fn do_step(&mut self, t: f64, h: f64) -> fmi2Status;
    fn terminate(&mut self) -> fmi2Status;
    /// `fmi2FreeInstance`: no call after it.
    fn free_instance(&mut self) -> fmi2Status;

    fn set_real(&mut self, vrs: &[VR], values: &[f64]) -> fmi2Status;
    fn set_integer(&mut self, vrs: &[VR], values: &[i32]) -> fmi2Status;
    /// Values are fmi2Boolean (0 or 1).
    fn set_boolean(&mut self, vrs: &[VR], values: &[i32]) -> fmi2Status;
    fn set_string(&mut self, vrs: &[VR], values: &[CString]) -> fmi2Status;
    fn get_real(&mut self, vrs: &[VR], out: &mut [f64]) -> fmi2Status;
    fn get_integer(&mut self, vrs: &[VR], out: &mut [i32]) -> fmi2Status;
    fn get_boolean(&mut self, vrs: &[VR], out: &mut [i32]) -> fmi2Status;
    /// The strings, copied into `out` (the FMU owns its own only until its next call; invalid
    /// UTF-8 becomes U+FFFD and a null pointer ""), reusing each buffer.
    fn get_string(&mut self, vrs: &[VR], out: &mut [String]) -> fmi2Status;

    /// `fmi2GetBooleanStatus(fmi2Terminated)`: the slave asks to end the simulation (after a
    /// step's fmi2Discard, FMI 2.0, sec. 4.2.3).
    fn terminated(&mut self) -> (fmi2Status, bool);
    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`.
    fn last_successful_time(&mut self) -> (fmi2Status, f64);

    /// `fmi2GetFMUstate` into a new state.
    fn get_state(&mut self) -> (fmi2Status, StateHandle);
    fn set_state(&mut self, state: StateHandle) -> fmi2Status;
    /// `fmi2FreeFMUstate`: the status and the handle after the call (0 when freed).
    fn free_state(&mut self, state: StateHandle) -> (fmi2Status, StateHandle);
    fn serialized_size(&mut self, state: StateHandle) -> (fmi2Status, usize);
    /// `fmi2SerializeFMUstate` into `size` bytes (the caller bounds `size`).
    fn serialize(&mut self, state: StateHandle, size: usize) -> (fmi2Status, Vec<u8>);
    /// `fmi2DeSerializeFMUstate` into a new state.
    fn deserialize(&mut self, bytes: &[u8]) -> (fmi2Status, StateHandle);

    /// Why a call returned [`GONE`] (the process died, hung or was interrupted), or None while
    /// the slave answers.
    fn lost(&self) -> Option<Error>;
}

#[cfg(test)]
mod tests {
    use super::Op;

    #[test]
    fn every_op_has_its_number() {
        for n in 0..40 {
            if let Some(op) = Op::from_u32(n) {
                assert_eq!(op as u32, n);
                assert!(op.name().starts_with("fmi2"));
            }
        }
        assert_eq!(Op::from_u32(5), Some(Op::DoStep));
    }
}
