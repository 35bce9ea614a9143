//! Why an FMU failed is shown without `-v`. Some FMUs (PythonFMU's) report even their errors
//! only when instantiated with loggingOn = fmi2True: a PythonFMU whose script imports a missing
//! module returns NULL from fmi2Instantiate and logs nothing with loggingOn = fmi2False, and
//! "Fatal py exception ... ModuleNotFoundError" with loggingOn = fmi2True. The test FMU mimics
//! that: its GUID check (the MODEL_GUID define, a GNU statement expression) returns NULL
//! silently when loggingOn = fmi2False and reports the wrong GUID as an error otherwise.

mod common;
use common::*;
use shipsim::fmu::Fmu;
use shipsim::log::LogRecord;
use std::process::Command;
use std::sync::{Arc, Mutex};

/// Fails silently without debug logging, with a logged error with it.
const QUIET_UNLESS_LOGGING: &str = "MODEL_GUID=({ if (!log) return NULL; \"{not-this-guid}\"; })";
/// Fails silently in any case.
const ALWAYS_SILENT: &str = "MODEL_GUID=({ return NULL; \"{not-this-guid}\"; })";

/// Builds the test FMU with `define` and instantiates it with loggingOn = fmi2False, which must
/// fail: what reached the log sink, and the error.
fn failed_instantiation(define: &str) -> (Vec<LogRecord>, String) {
    let d = tempfile::tempdir().unwrap();
    let p = build_fmu(
        d.path(),
        "failing",
        Variant {
            defines: &[define],
            ..Default::default()
        },
    );
    let fmu = Fmu::load(&p).unwrap();
    let seen: Arc<Mutex<Vec<LogRecord>>> = Arc::default();
    let s2 = seen.clone();
    let sink = Arc::new(move |r: &LogRecord| s2.lock().unwrap().push(r.clone()));
    let e = match fmu.instantiate("q", false, sink) {
        Ok(_) => panic!("instantiated"),
        Err(e) => e.to_string(),
    };
    let seen = seen.lock().unwrap().clone();
    (seen, e)
}

#[test]
fn instantiate_failure_silent_without_debug_logging_is_explained() {
    let (seen, e) = failed_instantiation(QUIET_UNLESS_LOGGING);
    // The FMU's own error reached the sink (so the default sink prints it) and the error.
    assert_eq!(seen.len(), 1, "{seen:?}");
    assert_eq!(seen[0].status, fmi2::fmi2Error);
    assert_eq!(
        seen[0].message,
        "Wrong GUID {shipsim-test-fmu}, expected {not-this-guid}."
    );
    assert!(
        e.contains("fmi2Instantiate returned NULL for instance 'q'"),
        "{e}"
    );
    assert!(e.contains("Wrong GUID {shipsim-test-fmu}"), "{e}");
    assert!(!e.contains("-v"), "no hint when the reason is known: {e}");
}

#[test]
fn instantiate_failure_without_any_reason_says_so() {
    let (seen, e) = failed_instantiation(ALWAYS_SILENT);
    assert!(seen.is_empty(), "{seen:?}");
    assert!(
        e.contains("fmi2Instantiate returned NULL for instance 'q'")
            && e.contains("(none: the FMU logged no reason)"),
        "{e}"
    );
}

#[test]
fn cli_shows_the_fmu_error_without_v() {
    let d = tempfile::tempdir().unwrap();
    build_fmu(
        d.path(),
        "quiet",
        Variant {
            defines: &[QUIET_UNLESS_LOGGING],
            ..Default::default()
        },
    );
    let p = write_system(
        d.path(),
        "q.toml",
        "[simulation]\nstop_time = 0.2\nstep_size = 0.1\n[[instances]]\nname = \"q\"\nfmu = \"quiet.fmu\"\n",
    );
    let o = Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .args(["run", p.to_str().unwrap(), "--no-output"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    // The default sink prints the FMU's error line, then the error names it again.
    assert!(
        err.contains("[q] fmi2Error logStatusError: Wrong GUID {shipsim-test-fmu}"),
        "{err}"
    );
    assert!(
        err.contains("quiet.fmu': fmi2Instantiate returned NULL"),
        "{err}"
    );
}
