//! FMI 2.0 co-simulation export layer.
//!
//! One generic implementation of the whole FMI 2.0 common + co-simulation C API (FMI 2.0.4
//! sections 2.1 and 4) over the [`FmuModel`] trait. An FMU crate is a model type, its variable
//! table and one line: `fmi2_export::export_fmu!(MyModel);`, which emits the 34 unprefixed
//! `fmi2*` symbols (plus two generator symbols used by `cargo xtask build-fmus`).
//!
//! What the layer guarantees, for every FMU (spec `fmi_ecosystem.md` §2.4, modelled on the
//! Modelica Reference FMUs' `fmi2Functions.c`):
//! * a call-sequence state machine: a call that is illegal in the current state returns
//!   `fmi2Error` and logs "Illegal call sequence";
//! * GUID check in `fmi2Instantiate` (wrong or missing GUID: NULL and a log line); any resource
//!   location (NULL, empty, `file:` URIs) is accepted; only `fmi2CoSimulation`;
//! * `currentCommunicationPoint` checked against the FMU's time (relative tolerance), `h > 0`;
//! * logger categories declared in the XML and filtered by `fmi2SetDebugLogging`; `%` escaped;
//! * `catch_unwind` around every entry: a panic becomes `fmi2Error`, never an abort;
//! * no global mutable state: each instance owns everything it uses;
//! * FMU state get/set/free and serialization implemented for real (a snapshot is a clone of the
//!   model plus the instance's time and state); `fmi2Reset` returns to the start values;
//! * NaN/infinite Real values are refused with a message naming the variable.

pub mod api;
mod instance;
pub mod variables;
pub mod xml;

pub use fmi2;
pub use variables::{Access, BaseType, Causality, Variability, Variable};

use serde::{de::DeserializeOwned, Serialize};

/// `<DefaultExperiment>`.
#[derive(Clone, Copy, Debug)]
pub struct DefaultExperiment {
    pub start_time: f64,
    pub stop_time: f64,
    pub step_size: f64,
}

/// Log categories declared in every FMU's `<LogCategories>`.
pub const LOG_CATEGORIES: [(&str, &str); 5] = [
    (
        "logEvents",
        "Lifecycle events: instantiated, initialized, terminated, reset, state restored (debug logging)",
    ),
    ("logStatusWarning", "Warnings"),
    (
        "logStatusError",
        "Errors: illegal calls, invalid arguments, failed steps",
    ),
    ("logStatusFatal", "Fatal errors"),
    ("logCalls", "Every FMI function call (debug logging)"),
];

/// A co-simulation model. It is a plain value: `Clone` (an FMU state is a clone), serde
/// (a serialized FMU state is its bincode bytes) and `Default` (the start values; `fmi2Reset`
/// returns to it). Parameters and inputs are fields written through the variable table.
pub trait FmuModel: Clone + Default + Serialize + DeserializeOwned + 'static {
    /// `modelIdentifier`: the FMU's file name and shared-library name.
    const MODEL_IDENTIFIER: &'static str;
    /// One-line description for the XML.
    const DESCRIPTION: &'static str;
    const DEFAULT_EXPERIMENT: DefaultExperiment;

    /// Whether outputs that declare no dependencies may depend directly on inputs. `false`: they
    /// depend on the state only, written as `dependencies=""` in ModelStructure, so importers
    /// (e.g. a Gauss-Seidel master) know there is no algebraic loop through this FMU.
    const DIRECT_FEEDTHROUGH: bool = true;

    /// The variable table; value reference = index.
    fn variables() -> &'static [Variable<Self>];

    /// HTML fragment for `documentation/index.html`: equations, sources, readings taken.
    fn documentation_html() -> &'static str;

    /// Called in `fmi2ExitInitializationMode` after parameters and start values are set:
    /// validate parameters and compute the outputs at the start time. The message should name
    /// the offending variable and value. Must be idempotent: it is also called when an importer
    /// reads outputs in Initialization Mode after changing parameters or start values.
    fn initialize(&mut self, start_time: f64) -> Result<(), String>;

    /// Called after a tunable parameter changed in step mode; on error the old value is restored.
    fn parameters_changed(&mut self) -> Result<(), String> {
        Ok(())
    }

    /// Recomputes outputs that depend directly on inputs or parameters (called lazily before a
    /// get after any set). Default: outputs depend on the state only.
    fn calculate_outputs(&mut self) {}

    /// Advances from `t` to `t + h` with the inputs held; computes the outputs at `t + h`.
    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String>;
}

/// Emits the FMI 2.0 C API for a model type. Use once per FMU crate (a `cdylib`).
#[macro_export]
macro_rules! export_fmu {
    ($model:ty) => {
        const _: () = {
            use ::std::ffi::{c_char, c_void};
            use $crate::api;
            use $crate::fmi2::*;

            #[no_mangle]
            pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
                api::types_platform()
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetVersion() -> *const c_char {
                api::version()
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetDebugLogging(
                c: fmi2Component,
                on: fmi2Boolean,
                n: usize,
                cats: *const fmi2String,
            ) -> fmi2Status {
                api::set_debug_logging::<$model>(c, on, n, cats)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Instantiate(
                name: fmi2String,
                kind: fmi2Type,
                guid: fmi2String,
                resources: fmi2String,
                functions: *const fmi2CallbackFunctions,
                visible: fmi2Boolean,
                logging_on: fmi2Boolean,
            ) -> fmi2Component {
                api::instantiate::<$model>(
                    name, kind, guid, resources, functions, visible, logging_on,
                )
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
                api::free_instance::<$model>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetupExperiment(
                c: fmi2Component,
                tol_defined: fmi2Boolean,
                tol: fmi2Real,
                start: fmi2Real,
                stop_defined: fmi2Boolean,
                stop: fmi2Real,
            ) -> fmi2Status {
                api::setup_experiment::<$model>(c, tol_defined, tol, start, stop_defined, stop)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
                api::enter_initialization_mode::<$model>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
                api::exit_initialization_mode::<$model>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
                api::terminate::<$model>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
                api::reset::<$model>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetReal(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *mut fmi2Real,
            ) -> fmi2Status {
                api::get_real::<$model>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetInteger(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *mut fmi2Integer,
            ) -> fmi2Status {
                api::get_integer::<$model>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBoolean(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *mut fmi2Boolean,
            ) -> fmi2Status {
                api::get_boolean::<$model>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetString(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *mut fmi2String,
            ) -> fmi2Status {
                api::get_string::<$model>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetReal(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *const fmi2Real,
            ) -> fmi2Status {
                api::set_real::<$model>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetInteger(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *const fmi2Integer,
            ) -> fmi2Status {
                api::set_integer::<$model>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetBoolean(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *const fmi2Boolean,
            ) -> fmi2Status {
                api::set_boolean::<$model>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetString(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *const fmi2String,
            ) -> fmi2Status {
                api::set_string::<$model>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetFMUstate(
                c: fmi2Component,
                s: *mut fmi2FMUstate,
            ) -> fmi2Status {
                api::get_fmu_state::<$model>(c, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetFMUstate(
                c: fmi2Component,
                s: fmi2FMUstate,
            ) -> fmi2Status {
                api::set_fmu_state::<$model>(c, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeFMUstate(
                c: fmi2Component,
                s: *mut fmi2FMUstate,
            ) -> fmi2Status {
                api::free_fmu_state::<$model>(c, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
                c: fmi2Component,
                s: fmi2FMUstate,
                size: *mut usize,
            ) -> fmi2Status {
                api::serialized_fmu_state_size::<$model>(c, s, size)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializeFMUstate(
                c: fmi2Component,
                s: fmi2FMUstate,
                bytes: *mut fmi2Byte,
                size: usize,
            ) -> fmi2Status {
                api::serialize_fmu_state::<$model>(c, s, bytes, size)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
                c: fmi2Component,
                bytes: *const fmi2Byte,
                size: usize,
                s: *mut fmi2FMUstate,
            ) -> fmi2Status {
                api::deserialize_fmu_state::<$model>(c, bytes, size, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
                c: fmi2Component,
                _vu: *const fmi2ValueReference,
                _nu: usize,
                _vk: *const fmi2ValueReference,
                _nk: usize,
                _dvk: *const fmi2Real,
                _dvu: *mut fmi2Real,
            ) -> fmi2Status {
                api::unsupported::<$model>(
                    c,
                    "fmi2GetDirectionalDerivative",
                    "providesDirectionalDerivative=\"false\"",
                )
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
                c: fmi2Component,
                _vr: *const fmi2ValueReference,
                _n: usize,
                _order: *const fmi2Integer,
                _v: *const fmi2Real,
            ) -> fmi2Status {
                api::unsupported::<$model>(
                    c,
                    "fmi2SetRealInputDerivatives",
                    "canInterpolateInputs=\"false\"",
                )
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
                c: fmi2Component,
                _vr: *const fmi2ValueReference,
                _n: usize,
                _order: *const fmi2Integer,
                _v: *mut fmi2Real,
            ) -> fmi2Status {
                api::unsupported::<$model>(
                    c,
                    "fmi2GetRealOutputDerivatives",
                    "maxOutputDerivativeOrder=\"0\"",
                )
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DoStep(
                c: fmi2Component,
                t: fmi2Real,
                h: fmi2Real,
                no_prior: fmi2Boolean,
            ) -> fmi2Status {
                api::do_step::<$model>(c, t, h, no_prior)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
                api::unsupported::<$model>(
                    c,
                    "fmi2CancelStep",
                    "fmi2DoStep never returns fmi2Pending (canRunAsynchronuously=\"false\")",
                )
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2Status,
            ) -> fmi2Status {
                api::get_status::<$model>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2Real,
            ) -> fmi2Status {
                api::get_real_status::<$model>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetIntegerStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2Integer,
            ) -> fmi2Status {
                api::get_integer_status::<$model>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBooleanStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2Boolean,
            ) -> fmi2Status {
                api::get_boolean_status::<$model>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStringStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2String,
            ) -> fmi2Status {
                api::get_string_status::<$model>(c, kind, v)
            }

            /// Generator entry (not FMI): the model description, for `cargo xtask build-fmus`.
            #[no_mangle]
            pub unsafe extern "C" fn shipfmu_model_description(
                out: *mut c_void,
                write: unsafe extern "C" fn(*mut c_void, *const u8, usize),
            ) {
                api::emit_text(out, write, &$crate::xml::model_description::<$model>())
            }
            /// Generator entry (not FMI): documentation/index.html.
            #[no_mangle]
            pub unsafe extern "C" fn shipfmu_documentation_html(
                out: *mut c_void,
                write: unsafe extern "C" fn(*mut c_void, *const u8, usize),
            ) {
                api::emit_text(out, write, &$crate::xml::documentation_html::<$model>())
            }
        };
    };
}
