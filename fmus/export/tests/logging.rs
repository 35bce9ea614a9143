//! Which log lines an instance sends, by `loggingOn` and `fmi2SetDebugLogging` (FMI 2.0,
//! sec. 2.1.5): per-call tracing (`logCalls`) only when the importer asks for it with
//! `fmi2SetDebugLogging`, never from `loggingOn = fmi2True` alone (libcosim always passes it);
//! errors always.

use fmi2::*;
use fmi2_export::testing::Importer;
use fmi2_export::{api, xml, FmuModel};
use serde::{Deserialize, Serialize};
use std::ffi::CString;
use std::ptr::null;

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Lag {
    u: f64,
    y: f64,
}

fmi2_export::fmu_description! {
    Lag => "Lag",
    description: "y' = u - y",
    experiment: (0.0, 1.0, 0.1),
    documentation_html: "",
    variables: {
        input real "u" (u), "input";
        output real "y" (y).depends_on(&[]), "state";
    }
}

impl FmuModel for Lag {
    fn initialize(&mut self, _t: f64) -> Result<(), String> {
        Ok(())
    }
    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.y += h * (self.u - self.y);
        Ok(())
    }
}

const VR_U: u32 = 0;
const VR_Y: u32 = 1;

fn instantiate(host: &Importer, logging_on: bool) -> fmi2Component {
    let name = CString::new("lag").unwrap();
    let guid = CString::new(xml::guid::<Lag>()).unwrap();
    let c = unsafe {
        api::instantiate::<Lag>(
            name.as_ptr(),
            fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            host.callbacks(),
            fmi2False,
            logging_on as fmi2Boolean,
        )
    };
    assert!(!c.is_null(), "{}", host.log().last());
    c
}

/// Initialization and `steps` steps of 0.1 s, each with one set and one get, as a master does:
/// 3 + 3 * steps FMI calls after fmi2Instantiate.
fn run(c: fmi2Component, steps: usize) {
    unsafe {
        assert_eq!(
            api::setup_experiment::<Lag>(c, fmi2False, 0.0, 0.0, fmi2False, 0.0),
            fmi2OK
        );
        assert_eq!(api::enter_initialization_mode::<Lag>(c), fmi2OK);
        assert_eq!(api::exit_initialization_mode::<Lag>(c), fmi2OK);
        for k in 0..steps {
            assert_eq!(api::set_real::<Lag>(c, &VR_U, 1, &1.0), fmi2OK);
            assert_eq!(
                api::do_step::<Lag>(c, k as f64 * 0.1, 0.1, fmi2True),
                fmi2OK
            );
            let mut y = 0.0;
            assert_eq!(api::get_real::<Lag>(c, &VR_Y, 1, &mut y), fmi2OK);
        }
    }
}

fn set_debug_logging(c: fmi2Component, on: bool, categories: &[&str]) -> fmi2Status {
    let names: Vec<CString> = categories
        .iter()
        .map(|s| CString::new(*s).unwrap())
        .collect();
    let ptrs: Vec<fmi2String> = names.iter().map(|s| s.as_ptr()).collect();
    unsafe {
        api::set_debug_logging::<Lag>(
            c,
            on as fmi2Boolean,
            ptrs.len(),
            if ptrs.is_empty() {
                null()
            } else {
                ptrs.as_ptr()
            },
        )
    }
}

/// An error the FMU must report: a NaN input (fmi2Error with one logStatusError line).
fn provoke_error(host: &Importer, c: fmi2Component) {
    let before = host.log().count("logStatusError");
    assert_eq!(
        unsafe { api::set_real::<Lag>(c, &VR_U, 1, &f64::NAN) },
        fmi2Error
    );
    assert_eq!(host.log().count("logStatusError"), before + 1);
}

#[test]
fn logging_off_sends_nothing_but_errors() {
    let host = Importer::default();
    let c = instantiate(&host, false);
    run(c, 100);
    assert_eq!(host.log().lines().len(), 0, "{:?}", host.log().lines());
    provoke_error(&host, c);
    assert_eq!(host.log().lines().len(), 1);
    unsafe { api::free_instance::<Lag>(c) };
}

#[test]
fn logging_on_at_instantiation_logs_events_not_calls() {
    let host = Importer::default();
    let c = instantiate(&host, true);
    run(c, 100);
    assert_eq!(unsafe { api::terminate::<Lag>(c) }, fmi2OK);
    // instantiated, initialized, terminated: three lines, none per call
    assert_eq!(host.log().count("logCalls"), 0);
    assert_eq!(host.log().count("logEvents"), 3, "{:?}", host.log().lines());
    assert_eq!(host.log().lines().len(), 3);
    unsafe { api::free_instance::<Lag>(c) };
}

#[test]
fn calls_are_traced_only_when_the_category_is_enabled() {
    let host = Importer::default();
    let c = instantiate(&host, true);
    assert_eq!(set_debug_logging(c, true, &["logCalls"]), fmi2OK);
    run(c, 10);
    // one line per call after fmi2SetDebugLogging: 3 to initialize, 3 per step
    assert_eq!(host.log().count("logCalls"), 3 + 3 * 10);
    // the category switched off again: no more lines
    assert_eq!(set_debug_logging(c, false, &["logCalls"]), fmi2OK);
    let n = host.log().count("logCalls");
    assert_eq!(
        unsafe { api::do_step::<Lag>(c, 1.0, 0.1, fmi2True) },
        fmi2OK
    );
    assert_eq!(host.log().count("logCalls"), n);
    unsafe { api::free_instance::<Lag>(c) };
}

#[test]
fn no_categories_means_all_debug_messages_on_and_debug_logging_off() {
    let host = Importer::default();
    let c = instantiate(&host, false);
    // loggingOn = fmi2True, nCategories = 0: "all debug messages" (FMI 2.0, sec. 2.1.5)
    assert_eq!(set_debug_logging(c, true, &[]), fmi2OK);
    run(c, 2);
    assert_eq!(host.log().count("logCalls"), 3 + 3 * 2);
    assert_eq!(host.log().count("logEvents"), 1);
    // loggingOn = fmi2False, nCategories = 0: debug logging off, errors still reported
    assert_eq!(set_debug_logging(c, false, &[]), fmi2OK);
    let n = host.log().lines().len();
    assert_eq!(
        unsafe { api::do_step::<Lag>(c, 0.2, 0.1, fmi2True) },
        fmi2OK
    );
    assert_eq!(unsafe { api::terminate::<Lag>(c) }, fmi2OK);
    assert_eq!(host.log().lines().len(), n);
    let c2 = instantiate(&host, false);
    run(c2, 1);
    assert_eq!(set_debug_logging(c2, false, &[]), fmi2OK);
    provoke_error(&host, c2);
    unsafe { api::free_instance::<Lag>(c) };
    unsafe { api::free_instance::<Lag>(c2) };
}
