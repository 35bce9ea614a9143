//! FMI 2.0 C ABI types (fmi2TypesPlatform.h, fmi2FunctionTypes.h of the FMI 2.0.x standard),
//! shared by the FMU export layer (`fmi2-export`) and the importer in `master/`.
//!
//! Also provides [`LogTarget`] and [`logger_proxy`]: the C-variadic `fmi2CallbackLogger` cannot be
//! defined in stable Rust, so a small C function formats the message and forwards it to a plain
//! Rust callback.
#![allow(non_camel_case_types, non_snake_case, non_upper_case_globals)]

use std::ffi::{c_char, c_double, c_int, c_uint, c_void, CStr};

pub type fmi2Component = *mut c_void;
pub type fmi2ComponentEnvironment = *mut c_void;
pub type fmi2FMUstate = *mut c_void;
pub type fmi2ValueReference = c_uint;
pub type fmi2Real = c_double;
pub type fmi2Integer = c_int;
pub type fmi2Boolean = c_int;
pub type fmi2Char = c_char;
pub type fmi2String = *const fmi2Char;
pub type fmi2Byte = c_char;

pub const fmi2True: fmi2Boolean = 1;
pub const fmi2False: fmi2Boolean = 0;

/// `fmi2Status` as an ABI-stable integer (an FMU may hand back any value; never transmute).
pub type fmi2Status = c_int;
pub const fmi2OK: fmi2Status = 0;
pub const fmi2Warning: fmi2Status = 1;
pub const fmi2Discard: fmi2Status = 2;
pub const fmi2Error: fmi2Status = 3;
pub const fmi2Fatal: fmi2Status = 4;
pub const fmi2Pending: fmi2Status = 5;

/// `fmi2Type`.
pub type fmi2Type = c_int;
pub const fmi2ModelExchange: fmi2Type = 0;
pub const fmi2CoSimulation: fmi2Type = 1;

/// `fmi2StatusKind`.
pub type fmi2StatusKind = c_int;
pub const fmi2DoStepStatus: fmi2StatusKind = 0;
pub const fmi2PendingStatus: fmi2StatusKind = 1;
pub const fmi2LastSuccessfulTime: fmi2StatusKind = 2;
pub const fmi2Terminated: fmi2StatusKind = 3;

/// `fmi2CallbackLogger`: C-variadic (`message` is a printf format string).
pub type fmi2CallbackLogger = Option<
    unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    ),
>;
pub type fmi2CallbackAllocateMemory = Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>;
pub type fmi2CallbackFreeMemory = Option<unsafe extern "C" fn(*mut c_void)>;
pub type fmi2StepFinished = Option<unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2Status)>;

/// `fmi2CallbackFunctions`.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct fmi2CallbackFunctions {
    pub logger: fmi2CallbackLogger,
    pub allocateMemory: fmi2CallbackAllocateMemory,
    pub freeMemory: fmi2CallbackFreeMemory,
    pub stepFinished: fmi2StepFinished,
    pub componentEnvironment: fmi2ComponentEnvironment,
}

/// Human-readable name of a status value.
pub fn status_name(status: fmi2Status) -> &'static str {
    match status {
        fmi2OK => "fmi2OK",
        fmi2Warning => "fmi2Warning",
        fmi2Discard => "fmi2Discard",
        fmi2Error => "fmi2Error",
        fmi2Fatal => "fmi2Fatal",
        fmi2Pending => "fmi2Pending",
        _ => "invalid fmi2Status",
    }
}

mod attributes;
mod functions;

pub use attributes::{Causality, Initial, Variability};

fmi2_functions!(functions::define_abi);
/// A non-variadic receiver of formatted log messages: (ctx, instance, status, category, message).
pub type LogSinkFn =
    unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char);

/// What an importer passes as `componentEnvironment` when it installs [`logger_proxy`] as the
/// logger: the proxy formats the message and calls `sink(ctx, ...)`. Must outlive the instance.
#[repr(C)]
pub struct LogTarget {
    pub sink: Option<LogSinkFn>,
    pub ctx: *mut c_void,
}

extern "C" {
    /// The C proxy (c/logger_proxy.c) with the exact `fmi2CallbackLogger` signature.
    fn fmi2_logger_proxy(
        env: fmi2ComponentEnvironment,
        instance: fmi2String,
        status: fmi2Status,
        category: fmi2String,
        message: fmi2String,
        ...
    );
}

/// The logger proxy as an `fmi2CallbackLogger` value, for `fmi2CallbackFunctions.logger`.
pub fn logger_proxy() -> fmi2CallbackLogger {
    Some(fmi2_logger_proxy)
}

/// Reads a possibly-NULL C string lossily (for log sinks and diagnostics).
///
/// # Safety
/// `p` must be NULL or point to a NUL-terminated string.
pub unsafe fn lossy_str(p: *const c_char) -> String {
    if p.is_null() {
        String::new()
    } else {
        CStr::from_ptr(p).to_string_lossy().into_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CString;
    use std::sync::Mutex;

    unsafe extern "C" fn sink(
        ctx: *mut c_void,
        inst: *const c_char,
        status: c_int,
        cat: *const c_char,
        msg: *const c_char,
    ) {
        let out = &*(ctx as *const Mutex<Vec<String>>);
        out.lock().unwrap().push(format!(
            "{}|{}|{}|{}",
            lossy_str(inst),
            status,
            lossy_str(cat),
            lossy_str(msg)
        ));
    }

    #[test]
    fn proxy_formats_printf_style_and_forwards() {
        let seen = Mutex::new(Vec::<String>::new());
        let mut target = LogTarget {
            sink: Some(sink),
            ctx: &seen as *const _ as *mut c_void,
        };
        let logger = logger_proxy().unwrap();
        let inst = CString::new("gear").unwrap();
        let cat = CString::new("logStatusError").unwrap();
        let fmt = CString::new("value %d is 100%% wrong: %s").unwrap();
        let arg = CString::new("x").unwrap();
        unsafe {
            logger(
                &mut target as *mut LogTarget as *mut c_void,
                inst.as_ptr(),
                fmi2Error,
                cat.as_ptr(),
                fmt.as_ptr(),
                42 as c_int,
                arg.as_ptr(),
            );
        }
        // A message longer than the proxy's stack buffer takes the heap path.
        let long = CString::new("y".repeat(5000)).unwrap();
        unsafe {
            logger(
                &mut target as *mut LogTarget as *mut c_void,
                inst.as_ptr(),
                fmi2OK,
                cat.as_ptr(),
                long.as_ptr(),
            );
        }
        let seen = seen.lock().unwrap();
        assert_eq!(seen[0], "gear|3|logStatusError|value 42 is 100% wrong: x");
        assert_eq!(seen[1].len(), "gear|0|logStatusError|".len() + 5000);
    }

    #[test]
    fn function_list_is_complete_and_unique() {
        let mut names = FUNCTION_NAMES.to_vec();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), 34);
    }
}
