//! The 34 functions of the FMI 2.0 co-simulation API (`fmi2FunctionTypes.h`: 25 common + 9
//! co-simulation), written out once. Everything else is generated from [`fmi2_functions!`]:
//! the `fmi2XxxTYPE` function-pointer types, the [`Fmi2Functions`] table the importer fills from
//! a shared library, [`FUNCTION_NAMES`], the `extern "C"` declarations of
//! [`declare_fmi2_functions!`](crate::declare_fmi2_functions) and, in `fmi2-export`, the exported symbols of an FMU.

/// Calls `$callback! { $($extra)* ; <the list> }` with one entry per FMI 2.0 function, in the
/// order of the standard's header:
/// `fmi2Name fmi2NameTYPE snake_name (arg: Type, ...) -> Return;`
/// (`snake_name` is the name of the export layer's implementation in `fmi2_export::api`).
#[macro_export]
macro_rules! fmi2_functions {
    ($callback:path $(, $($extra:tt)*)?) => {
        $callback! { $($($extra)*)? ;
            fmi2GetTypesPlatform fmi2GetTypesPlatformTYPE get_types_platform () -> *const $crate::fmi2Char;
            fmi2GetVersion fmi2GetVersionTYPE get_version () -> *const $crate::fmi2Char;
            fmi2SetDebugLogging fmi2SetDebugLoggingTYPE set_debug_logging (c: $crate::fmi2Component, logging_on: $crate::fmi2Boolean, n_categories: usize, categories: *const $crate::fmi2String) -> $crate::fmi2Status;
            fmi2Instantiate fmi2InstantiateTYPE instantiate (instance_name: $crate::fmi2String, fmu_type: $crate::fmi2Type, guid: $crate::fmi2String, resource_location: $crate::fmi2String, functions: *const $crate::fmi2CallbackFunctions, visible: $crate::fmi2Boolean, logging_on: $crate::fmi2Boolean) -> $crate::fmi2Component;
            fmi2FreeInstance fmi2FreeInstanceTYPE free_instance (c: $crate::fmi2Component) -> ();
            fmi2SetupExperiment fmi2SetupExperimentTYPE setup_experiment (c: $crate::fmi2Component, tolerance_defined: $crate::fmi2Boolean, tolerance: $crate::fmi2Real, start_time: $crate::fmi2Real, stop_time_defined: $crate::fmi2Boolean, stop_time: $crate::fmi2Real) -> $crate::fmi2Status;
            fmi2EnterInitializationMode fmi2EnterInitializationModeTYPE enter_initialization_mode (c: $crate::fmi2Component) -> $crate::fmi2Status;
            fmi2ExitInitializationMode fmi2ExitInitializationModeTYPE exit_initialization_mode (c: $crate::fmi2Component) -> $crate::fmi2Status;
            fmi2Terminate fmi2TerminateTYPE terminate (c: $crate::fmi2Component) -> $crate::fmi2Status;
            fmi2Reset fmi2ResetTYPE reset (c: $crate::fmi2Component) -> $crate::fmi2Status;
            fmi2GetReal fmi2GetRealTYPE get_real (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, value: *mut $crate::fmi2Real) -> $crate::fmi2Status;
            fmi2GetInteger fmi2GetIntegerTYPE get_integer (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, value: *mut $crate::fmi2Integer) -> $crate::fmi2Status;
            fmi2GetBoolean fmi2GetBooleanTYPE get_boolean (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, value: *mut $crate::fmi2Boolean) -> $crate::fmi2Status;
            fmi2GetString fmi2GetStringTYPE get_string (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, value: *mut $crate::fmi2String) -> $crate::fmi2Status;
            fmi2SetReal fmi2SetRealTYPE set_real (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, value: *const $crate::fmi2Real) -> $crate::fmi2Status;
            fmi2SetInteger fmi2SetIntegerTYPE set_integer (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, value: *const $crate::fmi2Integer) -> $crate::fmi2Status;
            fmi2SetBoolean fmi2SetBooleanTYPE set_boolean (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, value: *const $crate::fmi2Boolean) -> $crate::fmi2Status;
            fmi2SetString fmi2SetStringTYPE set_string (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, value: *const $crate::fmi2String) -> $crate::fmi2Status;
            fmi2GetFMUstate fmi2GetFMUstateTYPE get_fmu_state (c: $crate::fmi2Component, state: *mut $crate::fmi2FMUstate) -> $crate::fmi2Status;
            fmi2SetFMUstate fmi2SetFMUstateTYPE set_fmu_state (c: $crate::fmi2Component, state: $crate::fmi2FMUstate) -> $crate::fmi2Status;
            fmi2FreeFMUstate fmi2FreeFMUstateTYPE free_fmu_state (c: $crate::fmi2Component, state: *mut $crate::fmi2FMUstate) -> $crate::fmi2Status;
            fmi2SerializedFMUstateSize fmi2SerializedFMUstateSizeTYPE serialized_fmu_state_size (c: $crate::fmi2Component, state: $crate::fmi2FMUstate, size: *mut usize) -> $crate::fmi2Status;
            fmi2SerializeFMUstate fmi2SerializeFMUstateTYPE serialize_fmu_state (c: $crate::fmi2Component, state: $crate::fmi2FMUstate, bytes: *mut $crate::fmi2Byte, size: usize) -> $crate::fmi2Status;
            fmi2DeSerializeFMUstate fmi2DeSerializeFMUstateTYPE deserialize_fmu_state (c: $crate::fmi2Component, bytes: *const $crate::fmi2Byte, size: usize, state: *mut $crate::fmi2FMUstate) -> $crate::fmi2Status;
            fmi2GetDirectionalDerivative fmi2GetDirectionalDerivativeTYPE get_directional_derivative (c: $crate::fmi2Component, v_unknown: *const $crate::fmi2ValueReference, n_unknown: usize, v_known: *const $crate::fmi2ValueReference, n_known: usize, dv_known: *const $crate::fmi2Real, dv_unknown: *mut $crate::fmi2Real) -> $crate::fmi2Status;
            fmi2SetRealInputDerivatives fmi2SetRealInputDerivativesTYPE set_real_input_derivatives (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, order: *const $crate::fmi2Integer, value: *const $crate::fmi2Real) -> $crate::fmi2Status;
            fmi2GetRealOutputDerivatives fmi2GetRealOutputDerivativesTYPE get_real_output_derivatives (c: $crate::fmi2Component, vr: *const $crate::fmi2ValueReference, nvr: usize, order: *const $crate::fmi2Integer, value: *mut $crate::fmi2Real) -> $crate::fmi2Status;
            fmi2DoStep fmi2DoStepTYPE do_step (c: $crate::fmi2Component, current_communication_point: $crate::fmi2Real, communication_step_size: $crate::fmi2Real, no_set_fmu_state_prior: $crate::fmi2Boolean) -> $crate::fmi2Status;
            fmi2CancelStep fmi2CancelStepTYPE cancel_step (c: $crate::fmi2Component) -> $crate::fmi2Status;
            fmi2GetStatus fmi2GetStatusTYPE get_status (c: $crate::fmi2Component, kind: $crate::fmi2StatusKind, value: *mut $crate::fmi2Status) -> $crate::fmi2Status;
            fmi2GetRealStatus fmi2GetRealStatusTYPE get_real_status (c: $crate::fmi2Component, kind: $crate::fmi2StatusKind, value: *mut $crate::fmi2Real) -> $crate::fmi2Status;
            fmi2GetIntegerStatus fmi2GetIntegerStatusTYPE get_integer_status (c: $crate::fmi2Component, kind: $crate::fmi2StatusKind, value: *mut $crate::fmi2Integer) -> $crate::fmi2Status;
            fmi2GetBooleanStatus fmi2GetBooleanStatusTYPE get_boolean_status (c: $crate::fmi2Component, kind: $crate::fmi2StatusKind, value: *mut $crate::fmi2Boolean) -> $crate::fmi2Status;
            fmi2GetStringStatus fmi2GetStringStatusTYPE get_string_status (c: $crate::fmi2Component, kind: $crate::fmi2StatusKind, value: *mut $crate::fmi2String) -> $crate::fmi2Status;
        }
    };
}

/// Generates, from the list: the `fmi2XxxTYPE` aliases, [`Fmi2Functions`] and [`FUNCTION_NAMES`].
macro_rules! define_abi {
    (; $($name:ident $ty:ident $impl:ident ($($arg:ident : $argty:ty),*) -> $ret:ty;)*) => {
        $(
            #[doc = concat!("`", stringify!($name), "` (FMI 2.0 `fmi2FunctionTypes.h`).")]
            pub type $ty = unsafe extern "C" fn($($argty),*) -> $ret;
        )*

        /// Every FMI 2.0 co-simulation function of one FMU binary, resolved once: the importer
        /// fills it from a shared library ([`Fmi2Functions::resolve`]), tests from the symbols
        /// linked into their binary (`declare_fmi2_functions!`).
        #[derive(Clone, Copy)]
        pub struct Fmi2Functions {
            $(pub $name: $ty,)*
        }

        impl Fmi2Functions {
            /// Resolves every function through `lookup`, which returns a symbol's address
            /// (NULL when the library does not export it). The first missing function is
            /// reported by name.
            ///
            /// # Safety
            /// Every non-NULL address `lookup` returns must be a function of the FMI 2.0 signature
            /// of that name, valid for as long as the returned table is used.
            pub unsafe fn resolve(
                mut lookup: impl FnMut(&str) -> Result<*const ::std::ffi::c_void, String>,
            ) -> Result<Self, String> {
                Ok(Fmi2Functions {
                    $($name: {
                        let p = lookup(stringify!($name))?;
                        if p.is_null() {
                            return Err(format!(
                                "the shared library does not export '{}'",
                                stringify!($name)
                            ));
                        }
                        ::std::mem::transmute::<*const ::std::ffi::c_void, $ty>(p)
                    },)*
                })
            }
        }

        /// The names of every FMI 2.0 function a co-simulation FMU exports (25 common + 9
        /// co-simulation), in the order of the standard's header. FMPy resolves each of these at
        /// load time.
        pub const FUNCTION_NAMES: [&str; [$(stringify!($name)),*].len()] = [$(stringify!($name)),*];
    };
}

pub(crate) use define_abi;

/// Declares the 34 FMI 2.0 co-simulation functions as `extern "C"` items and defines
/// `linked_fmi2_functions()`, which returns them as an [`Fmi2Functions`](crate::Fmi2Functions) table: for tests that call
/// the symbols an FMU crate exports (linked from its rlib) exactly as a C importer would.
/// Use once at module level: `fmi2::declare_fmi2_functions!();`.
#[macro_export]
macro_rules! declare_fmi2_functions {
    () => {
        $crate::fmi2_functions!($crate::__declare_extern);
    };
}

#[doc(hidden)]
#[macro_export]
macro_rules! __declare_extern {
    (; $($name:ident $ty:ident $impl:ident ($($arg:ident : $argty:ty),*) -> $ret:ty;)*) => {
        #[allow(dead_code, clippy::unused_unit)]
        extern "C" {
            $(fn $name($($arg: $argty),*) -> $ret;)*
        }
        /// The FMI functions linked into this binary, as the importer's function table.
        #[allow(dead_code)]
        fn linked_fmi2_functions() -> $crate::Fmi2Functions {
            $crate::Fmi2Functions { $($name,)* }
        }
    };
}
