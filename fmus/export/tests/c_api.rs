//! Drives the generic FMI 2.0 C API of the export layer exactly as an importer does (raw
//! pointers, C callbacks, the variadic logger through the C proxy), with small test models.
//! The `fmi2*` symbols that `export_fmu!` emits forward one-to-one to these functions.

use fmi2::*;
use fmi2_export::testing::Importer;
use fmi2_export::{api, xml, FmuDescription, FmuModel, Variable};
use serde::{Deserialize, Serialize};
use std::ffi::{c_char, CString};
use std::ptr::{null, null_mut};

// ---------------------------------------------------------------------------------------------
// Test model: y' = gain * u, with a failure and a panic trigger.

#[derive(Clone, Debug, Serialize, Deserialize)]
struct Integrator {
    gain: f64,
    offset: f64,
    panic_at: f64,
    fail_at: f64,
    mode: i32,
    enabled: bool,
    u: f64,
    y: f64,
    steps: u64,
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator {
            gain: 2.0,
            offset: 0.5,
            panic_at: 1e9,
            fail_at: 1e9,
            mode: 1,
            enabled: true,
            u: 1.0,
            y: 0.0,
            steps: 0,
        }
    }
}

fmi2_export::fmu_description! {
    Integrator => "Integrator",
    description: "test integrator",
    experiment: (0.0, 10.0, 0.1),
    documentation_html: "<p>test</p>",
    variables: {
        tunable real "gain" (gain), "gain";
        fixed real "offset" ["m"] (offset), "initial output";
        tunable real "panic_at" ["s"] (panic_at), "panic when a step starts at or after this time";
        tunable real "fail_at" ["s"] (fail_at), "return an error from do_step at or after this time";
        fixed int(1, 3) "mode" (mode), "mode";
        tunable bool "enabled" (enabled), "integrate when true";
        input real "u" ["m/s"] (u), "input";
        output real "y" ["m"] (y).depends_on(&[]), "integral";
        output real "u_times_gain" ["m/s"] (|m| m.gain * m.u).depends_on(&["u"]), "direct feedthrough";
        output bool "positive" (|m| m.y > 0.0), "y > 0";
    }
}

impl FmuModel for Integrator {
    fn initialize(&mut self, _t: f64) -> Result<(), String> {
        if self.gain > 100.0 {
            return Err(format!("parameter gain = {} must be <= 100", self.gain));
        }
        self.y = self.offset;
        Ok(())
    }
    fn parameters_changed(&mut self) -> Result<(), String> {
        if self.gain > 100.0 {
            return Err(format!("parameter gain = {} must be <= 100", self.gain));
        }
        Ok(())
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        if t >= self.panic_at {
            panic!("deliberate panic at t = {t}");
        }
        if t >= self.fail_at {
            return Err(format!("deliberate failure at t = {t}"));
        }
        if self.enabled {
            self.y += self.gain * self.u * h;
        }
        self.steps += 1;
        Ok(())
    }
}

/// A second model type, to check that FMU states cannot cross model types.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Other {
    x: f64,
}
fmi2_export::fmu_description! {
    Other => "Other",
    description: "other",
    experiment: (0.0, 10.0, 0.1),
    documentation_html: "",
    variables: {
        output real "x" (x), "x";
    }
}
impl FmuModel for Other {
    fn initialize(&mut self, _t: f64) -> Result<(), String> {
        Ok(())
    }
    fn do_step(&mut self, _t: f64, _h: f64) -> Result<(), String> {
        Ok(())
    }
}

const VR_GAIN: u32 = 0;
const VR_OFFSET: u32 = 1;
const VR_PANIC: u32 = 2;
const VR_FAIL: u32 = 3;
const VR_MODE: u32 = 4;
const VR_ENABLED: u32 = 5;
const VR_U: u32 = 6;
const VR_Y: u32 = 7;
const VR_UG: u32 = 8;
const VR_POS: u32 = 9;

// ---------------------------------------------------------------------------------------------
// Importer side: callbacks and a log collector (fmi2_export::testing::Importer).

/// An importer: owns the log target and callbacks that the instance points to.
#[derive(Default)]
struct Host(Importer);

impl Host {
    fn new() -> Self {
        Host::default()
    }

    fn instantiate_with<M: FmuModel>(
        &self,
        name: &str,
        kind: fmi2Type,
        guid: Option<&str>,
        resources: Option<&str>,
        logging_on: bool,
    ) -> fmi2Component {
        let name = CString::new(name).unwrap();
        let guid = guid.map(|g| CString::new(g).unwrap());
        let res = resources.map(|r| CString::new(r).unwrap());
        unsafe {
            api::instantiate::<M>(
                name.as_ptr(),
                kind,
                guid.as_ref().map_or(null(), |g| g.as_ptr()),
                res.as_ref().map_or(null(), |r| r.as_ptr()),
                self.0.callbacks(),
                fmi2False,
                logging_on as fmi2Boolean,
            )
        }
    }

    fn instantiate(&self, name: &str) -> Fmu {
        let c = self.instantiate_with::<Integrator>(
            name,
            fmi2CoSimulation,
            Some(&xml::guid::<Integrator>()),
            Some("file:///tmp/resources"),
            false,
        );
        assert!(!c.is_null(), "instantiate failed: {}", self.0.log().last());
        Fmu(c)
    }
}

/// A thin safe handle over the generic API, as an importer's wrapper would be.
struct Fmu(fmi2Component);

impl Fmu {
    fn setup(&self, start: f64, stop: Option<f64>) -> fmi2Status {
        unsafe {
            api::setup_experiment::<Integrator>(
                self.0,
                fmi2False,
                0.0,
                start,
                stop.is_some() as fmi2Boolean,
                stop.unwrap_or(0.0),
            )
        }
    }
    fn enter(&self) -> fmi2Status {
        unsafe { api::enter_initialization_mode::<Integrator>(self.0) }
    }
    fn exit(&self) -> fmi2Status {
        unsafe { api::exit_initialization_mode::<Integrator>(self.0) }
    }
    fn init(&self) {
        assert_eq!(self.setup(0.0, None), fmi2OK);
        assert_eq!(self.enter(), fmi2OK);
        assert_eq!(self.exit(), fmi2OK);
    }
    fn step(&self, t: f64, h: f64) -> fmi2Status {
        unsafe { api::do_step::<Integrator>(self.0, t, h, fmi2True) }
    }
    fn terminate(&self) -> fmi2Status {
        unsafe { api::terminate::<Integrator>(self.0) }
    }
    fn reset(&self) -> fmi2Status {
        unsafe { api::reset::<Integrator>(self.0) }
    }
    fn get_reals(&self, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
        let mut out = vec![f64::NAN; vrs.len()];
        let s = unsafe {
            api::get_real::<Integrator>(self.0, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
        };
        (s, out)
    }
    fn get(&self, vr: u32) -> f64 {
        let (s, v) = self.get_reals(&[vr]);
        assert_eq!(s, fmi2OK);
        v[0]
    }
    fn set(&self, vr: u32, v: f64) -> fmi2Status {
        unsafe { api::set_real::<Integrator>(self.0, &vr, 1, &v) }
    }
    fn set_int(&self, vr: u32, v: i32) -> fmi2Status {
        unsafe { api::set_integer::<Integrator>(self.0, &vr, 1, &v) }
    }
    fn get_int(&self, vr: u32) -> (fmi2Status, i32) {
        let mut v = 0;
        let s = unsafe { api::get_integer::<Integrator>(self.0, &vr, 1, &mut v) };
        (s, v)
    }
    fn set_bool(&self, vr: u32, v: bool) -> fmi2Status {
        let v = v as fmi2Boolean;
        unsafe { api::set_boolean::<Integrator>(self.0, &vr, 1, &v) }
    }
    fn get_bool(&self, vr: u32) -> (fmi2Status, bool) {
        let mut v = 0;
        let s = unsafe { api::get_boolean::<Integrator>(self.0, &vr, 1, &mut v) };
        (s, v != 0)
    }
    fn get_state(&self) -> fmi2FMUstate {
        let mut s: fmi2FMUstate = null_mut();
        assert_eq!(
            unsafe { api::get_fmu_state::<Integrator>(self.0, &mut s) },
            fmi2OK
        );
        s
    }
    fn set_state(&self, s: fmi2FMUstate) -> fmi2Status {
        unsafe { api::set_fmu_state::<Integrator>(self.0, s) }
    }
    fn free_state(&self, mut s: fmi2FMUstate) {
        assert_eq!(
            unsafe { api::free_fmu_state::<Integrator>(self.0, &mut s) },
            fmi2OK
        );
        assert!(s.is_null());
    }
    fn serialize(&self, s: fmi2FMUstate) -> Vec<u8> {
        let mut size = 0usize;
        assert_eq!(
            unsafe { api::serialized_fmu_state_size::<Integrator>(self.0, s, &mut size) },
            fmi2OK
        );
        let mut bytes = vec![0 as c_char; size];
        assert_eq!(
            unsafe { api::serialize_fmu_state::<Integrator>(self.0, s, bytes.as_mut_ptr(), size) },
            fmi2OK
        );
        bytes.into_iter().map(|b| b as u8).collect()
    }
    fn deserialize(&self, bytes: &[u8]) -> (fmi2Status, fmi2FMUstate) {
        let mut s: fmi2FMUstate = null_mut();
        let st = unsafe {
            api::deserialize_fmu_state::<Integrator>(
                self.0,
                bytes.as_ptr() as *const c_char,
                bytes.len(),
                &mut s,
            )
        };
        (st, s)
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        unsafe { api::free_instance::<Integrator>(self.0) }
    }
}

// ---------------------------------------------------------------------------------------------

#[test]
fn variable_table_and_model_description_are_consistent() {
    fmi2_export::variables::check_table(Integrator::variables()).unwrap();
    let xml = xml::model_description::<Integrator>();
    let guid = xml::guid::<Integrator>();
    assert!(xml.contains(&format!("guid=\"{guid}\"")));
    // deterministic, and different models get different GUIDs
    assert_eq!(guid, xml::guid::<Integrator>());
    assert_ne!(guid, xml::guid::<Other>());
    assert!(guid.starts_with('{') && guid.ends_with('}') && guid.len() == 38);
    // outputs at 1-based positions 8, 9, 10 are the Outputs (with the declared dependencies:
    // y on the state only, u_times_gain on u = index 7, positive undeclared = all) and the
    // InitialUnknowns
    assert!(xml.contains(r#"<Unknown index="8" dependencies=""/>"#));
    assert!(xml.contains(r#"<Unknown index="9" dependencies="7"/>"#));
    assert_eq!(xml.matches(r#"<Unknown index="10"/>"#).count(), 2);
    for i in [8, 9] {
        assert_eq!(xml.matches(&format!("<Unknown index=\"{i}\"/>")).count(), 1);
    }
    // a dependency on something that is not an input is a table error
    let bad: &[Variable<Integrator>] = fmi2_export::variables!(Integrator;
        input real "u" (u), "u";
        output real "y" (y).depends_on(&["gain"]), "y";
    );
    let problems = fmi2_export::variables::check_table(bad).unwrap_err();
    assert!(
        problems[0].contains("dependency \"gain\" is not an input"),
        "{problems:?}"
    );
    assert!(xml.contains(r#"name="gain" valueReference="0""#));
    assert!(xml.contains(r#"<Real unit="m/s" displayUnit="kn" start="1.0"/>"#));
    assert!(xml.contains(r#"<Integer min="1" max="3" start="1"/>"#));
    assert!(xml.contains(r#"<Category name="logStatusError""#));
    assert!(xml.contains(r#"<BaseUnit m="1" s="-1"/>"#));
    let html = xml::documentation_html::<Integrator>();
    assert!(html.contains("<code>u_times_gain</code>"));
}

#[test]
fn types_platform_and_version() {
    unsafe {
        assert_eq!(
            lossy_str(api::get_types_platform::<Integrator>()),
            "default"
        );
        assert_eq!(lossy_str(api::get_version::<Integrator>()), "2.0");
    }
}

#[test]
fn instantiate_checks_guid_type_name_and_callbacks() {
    let host = Host::new();
    let good = xml::guid::<Integrator>();
    // wrong GUID: NULL with a log line naming both GUIDs
    let c =
        host.instantiate_with::<Integrator>("a", fmi2CoSimulation, Some("{wrong}"), None, false);
    assert!(c.is_null());
    assert!(host.0.log().contains("wrong GUID {wrong}") && host.0.log().contains(&good));
    // missing GUID
    let c = host.instantiate_with::<Integrator>("a", fmi2CoSimulation, None, None, false);
    assert!(c.is_null());
    assert!(host.0.log().contains("missing GUID"));
    // model exchange is not offered
    let c = host.instantiate_with::<Integrator>("a", fmi2ModelExchange, Some(&good), None, false);
    assert!(c.is_null());
    assert!(host.0.log().contains("supports only fmi2CoSimulation"));
    // empty instance name
    let c = host.instantiate_with::<Integrator>("", fmi2CoSimulation, Some(&good), None, false);
    assert!(c.is_null());
    // NULL callbacks
    let name = CString::new("a").unwrap();
    let g = CString::new(good.clone()).unwrap();
    let c = unsafe {
        api::instantiate::<Integrator>(
            name.as_ptr(),
            fmi2CoSimulation,
            g.as_ptr(),
            null(),
            null(),
            0,
            0,
        )
    };
    assert!(c.is_null());
    // every resource-location form importers use is accepted
    for res in [
        None,
        Some(""),
        Some("file:/tmp/x"),
        Some("file:///tmp/x/"),
        Some("not a uri"),
    ] {
        let c = host.instantiate_with::<Integrator>("a", fmi2CoSimulation, Some(&good), res, false);
        assert!(!c.is_null(), "resource location {res:?}");
        unsafe { api::free_instance::<Integrator>(c) };
    }
    // a NULL logger is tolerated (no logging)
    let quiet = fmi2CallbackFunctions {
        logger: None,
        ..*host.0.callbacks()
    };
    let c = unsafe {
        api::instantiate::<Integrator>(
            name.as_ptr(),
            fmi2CoSimulation,
            g.as_ptr(),
            null(),
            &quiet,
            0,
            1,
        )
    };
    assert!(!c.is_null());
    unsafe { api::free_instance::<Integrator>(c) };
}

/// Every illegal transition of the Reference FMUs' state table returns fmi2Error, logs
/// "Illegal call sequence" and leaves the instance usable.
#[test]
fn illegal_call_sequences_are_errors() {
    let host = Host::new();
    let fmu = host.instantiate("seq");
    let illegal = |what: &str, s: fmi2Status| {
        assert_eq!(s, fmi2Error, "{what} should be illegal");
        assert!(
            host.0.log().last().contains("Illegal call sequence"),
            "{what}: {}",
            host.0.log().last()
        );
    };
    // Instantiated
    illegal("DoStep in Instantiated", fmu.step(0.0, 0.1));
    illegal("ExitInit in Instantiated", fmu.exit());
    illegal("Terminate in Instantiated", fmu.terminate());
    illegal("GetReal in Instantiated", fmu.get_reals(&[VR_Y]).0);
    illegal("GetRealStatus in Instantiated", unsafe {
        api::get_real_status::<Integrator>(fmu.0, fmi2LastSuccessfulTime, &mut 0.0)
    });
    assert_eq!(fmu.set(VR_U, 3.0), fmi2OK);
    assert_eq!(fmu.setup(0.0, Some(1.0)), fmi2OK);
    assert_eq!(fmu.enter(), fmi2OK);
    // InitializationMode
    illegal("Setup in InitializationMode", fmu.setup(0.0, None));
    illegal("EnterInit in InitializationMode", fmu.enter());
    illegal("DoStep in InitializationMode", fmu.step(0.0, 0.1));
    illegal("Terminate in InitializationMode", fmu.terminate());
    assert_eq!(fmu.get_reals(&[VR_U]).0, fmi2OK);
    assert_eq!(fmu.exit(), fmi2OK);
    // StepComplete
    illegal("Setup in StepComplete", fmu.setup(0.0, None));
    illegal("EnterInit in StepComplete", fmu.enter());
    illegal("ExitInit in StepComplete", fmu.exit());
    assert_eq!(fmu.step(0.0, 0.5), fmi2OK);
    assert_eq!(fmu.terminate(), fmi2OK);
    // Terminated
    illegal("DoStep in Terminated", fmu.step(0.5, 0.1));
    illegal("SetReal in Terminated", fmu.set(VR_U, 1.0));
    illegal("Terminate in Terminated", fmu.terminate());
    illegal("EnterInit in Terminated", fmu.enter());
    assert_eq!(fmu.get(VR_Y), 0.5 + 2.0 * 3.0 * 0.5);
    // Reset returns to Instantiated with the start values
    assert_eq!(fmu.reset(), fmi2OK);
    illegal("GetReal after Reset", fmu.get_reals(&[VR_Y]).0);
    fmu.init();
    assert_eq!(fmu.get(VR_U), 1.0);
    assert_eq!(fmu.get(VR_Y), 0.5);
}

#[test]
fn unsupported_functions_return_error_with_a_reason() {
    let host = Host::new();
    let fmu = host.instantiate("u");
    fmu.init();
    let s = unsafe {
        api::unsupported::<Integrator>(
            fmu.0,
            "fmi2CancelStep",
            "fmi2DoStep never returns fmi2Pending",
        )
    };
    assert_eq!(s, fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("fmi2CancelStep is not supported"));
    let mut status = 0;
    assert_eq!(
        unsafe { api::get_status::<Integrator>(fmu.0, fmi2DoStepStatus, &mut status) },
        fmi2Error
    );
    let mut v = 0;
    assert_eq!(
        unsafe { api::get_integer_status::<Integrator>(fmu.0, fmi2DoStepStatus, &mut v) },
        fmi2Error
    );
    let vr = 0u32;
    let mut sp: fmi2String = null();
    assert_eq!(
        unsafe { api::get_string::<Integrator>(fmu.0, &vr, 1, &mut sp) },
        fmi2Error
    );
    assert_eq!(
        unsafe { api::get_string::<Integrator>(fmu.0, &vr, 0, &mut sp) },
        fmi2OK
    );
    // status functions that are defined
    assert_eq!(fmu.step(0.0, 0.25), fmi2OK);
    let mut t = 0.0;
    assert_eq!(
        unsafe { api::get_real_status::<Integrator>(fmu.0, fmi2LastSuccessfulTime, &mut t) },
        fmi2OK
    );
    assert_eq!(t, 0.25);
    let mut term = 1;
    assert_eq!(
        unsafe { api::get_boolean_status::<Integrator>(fmu.0, fmi2Terminated, &mut term) },
        fmi2OK
    );
    assert_eq!(term, fmi2False);
}

#[test]
fn do_step_checks_communication_point_step_size_and_stop_time() {
    let host = Host::new();
    let fmu = host.instantiate("t");
    assert_eq!(fmu.setup(0.0, Some(1.0)), fmi2OK);
    assert_eq!(fmu.enter(), fmi2OK);
    assert_eq!(fmu.exit(), fmi2OK);
    assert_eq!(fmu.step(0.0, 0.0), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("communicationStepSize = 0 must be > 0"));
    assert_eq!(fmu.step(0.0, -0.1), fmi2Error);
    assert_eq!(fmu.step(0.0, f64::NAN), fmi2Error);
    assert_eq!(fmu.step(0.1, 0.1), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("does not match the FMU's time 0"));
    // a master computing t_k = k*h passes points that differ from t + h by rounding only
    let h = 0.1;
    for k in 0..10 {
        assert_eq!(
            fmu.step(k as f64 * h, h),
            fmi2OK,
            "k = {k}: {}",
            host.0.log().last()
        );
    }
    // 10 * 0.1 accumulated differs from 1.0 by rounding: still accepted; past stopTime is not
    assert_eq!(fmu.step(1.0, 0.1), fmi2Error);
    assert!(host.0.log().last().contains("passes stopTime"));
    // variable step sizes are accepted (canHandleVariableCommunicationStepSize)
    let fmu2 = host.instantiate("v");
    fmu2.init();
    let mut t = 0.0;
    for h in [0.1, 0.013, 1.7, 1e-6] {
        assert_eq!(fmu2.step(t, h), fmi2OK);
        t += h;
    }
    assert!((fmu2.get(VR_Y) - (0.5 + 2.0 * t)).abs() < 1e-12);
}

#[test]
fn values_are_validated_and_errors_name_the_variable() {
    let host = Host::new();
    let fmu = host.instantiate("vals");
    assert_eq!(fmu.set(VR_U, f64::NAN), fmi2Error);
    assert!(
        host.0.log().last().contains("\"u\" = NaN refused"),
        "{}",
        host.0.log().last()
    );
    assert_eq!(fmu.set(VR_GAIN, f64::INFINITY), fmi2Error);
    assert!(host.0.log().last().contains("\"gain\" = inf refused"));
    assert_eq!(fmu.set(VR_Y, 1.0), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("\"y\" has causality Output and cannot be set"));
    assert_eq!(fmu.set(99, 1.0), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("no variable with value reference 99"));
    assert_eq!(fmu.set(VR_MODE, 1.0), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("is Integer \"mode\", not a Real variable"));
    assert_eq!(fmu.set_int(VR_MODE, 7), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("\"mode\" = 7 refused: outside [1, 3]"));
    assert_eq!(fmu.set_int(VR_MODE, 3), fmi2OK);
    // a batched set with an error stops at the bad element and reports it
    let vrs = [VR_U, VR_GAIN];
    let vals = [4.0, f64::NAN];
    assert_eq!(
        unsafe { api::set_real::<Integrator>(fmu.0, vrs.as_ptr(), 2, vals.as_ptr()) },
        fmi2Error
    );
    // NULL arrays with n > 0
    assert_eq!(
        unsafe { api::set_real::<Integrator>(fmu.0, null(), 1, null()) },
        fmi2Error
    );
    fmu.init();
    assert_eq!(fmu.get(VR_U), 4.0);
    assert_eq!(fmu.get_int(VR_MODE), (fmi2OK, 3));
    // fixed parameters are frozen after initialization; tunable ones are not
    assert_eq!(fmu.set(VR_OFFSET, 1.0), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("fixed parameter \"offset\" cannot be changed"));
    assert_eq!(fmu.set_int(VR_MODE, 2), fmi2Error);
    assert_eq!(fmu.set(VR_GAIN, 3.0), fmi2OK);
    // a tunable change the model refuses is reported and rolled back
    assert_eq!(fmu.set(VR_GAIN, 1000.0), fmi2Error);
    assert!(host.0.log().last().contains("gain = 1000 must be <= 100"));
    assert_eq!(fmu.get(VR_GAIN), 3.0);
    // direct feedthrough output reflects a new input before the next step
    assert_eq!(fmu.set(VR_U, 5.0), fmi2OK);
    assert_eq!(fmu.get(VR_UG), 15.0);
    // Boolean parameter and output
    assert_eq!(fmu.get_bool(VR_POS), (fmi2OK, true));
    assert_eq!(fmu.set_bool(VR_ENABLED, false), fmi2OK);
    assert_eq!(fmu.step(0.0, 1.0), fmi2OK);
    assert_eq!(fmu.get(VR_Y), 0.5);
    assert_eq!(fmu.get_bool(VR_ENABLED), (fmi2OK, false));
}

/// In Initialization Mode the outputs reflect the parameters set so far (InitialUnknowns).
#[test]
fn outputs_in_initialization_mode_follow_the_parameters() {
    let host = Host::new();
    let fmu = host.instantiate("init");
    assert_eq!(fmu.set(VR_OFFSET, 3.0), fmi2OK);
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter(), fmi2OK);
    assert_eq!(fmu.get(VR_Y), 3.0);
    assert_eq!(fmu.set(VR_OFFSET, 4.0), fmi2OK);
    assert_eq!(fmu.get(VR_Y), 4.0);
    assert_eq!(fmu.exit(), fmi2OK);
    assert_eq!(fmu.get(VR_Y), 4.0);
}

#[test]
fn invalid_parameters_fail_initialization_with_the_name() {
    let host = Host::new();
    let fmu = host.instantiate("p");
    assert_eq!(fmu.set(VR_GAIN, 500.0), fmi2OK); // range is checked by the model at init
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter(), fmi2OK);
    assert_eq!(fmu.exit(), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("parameter gain = 500 must be <= 100"));
    assert_eq!(fmu.step(0.0, 0.1), fmi2Error);
    assert_eq!(fmu.reset(), fmi2OK);
    fmu.init();
}

#[test]
fn a_panic_in_the_model_is_an_error_status_not_an_abort() {
    let host = Host::new();
    let fmu = host.instantiate("panicky");
    assert_eq!(fmu.set(VR_PANIC, 0.3), fmi2OK);
    fmu.init();
    assert_eq!(fmu.step(0.0, 0.2), fmi2OK);
    assert_eq!(fmu.step(0.2, 0.2), fmi2OK);
    let before = fmu.get_state();
    assert_eq!(fmu.step(0.4, 0.2), fmi2Error);
    assert!(host
        .0
        .log()
        .contains("internal error (panic: deliberate panic at t = 0.4)"));
    // the instance is in the Error state: stepping is refused, reading is allowed
    assert_eq!(fmu.step(0.4, 0.2), fmi2Error);
    assert!(host.0.log().last().contains("not allowed in state Error"));
    assert_eq!(fmu.get_reals(&[VR_Y]).0, fmi2OK);
    // rollback to a state before the failure recovers the instance
    assert_eq!(fmu.set_state(before), fmi2OK);
    assert_eq!(fmu.set(VR_PANIC, 1e9), fmi2OK);
    assert_eq!(fmu.step(0.4, 0.2), fmi2OK);
    fmu.free_state(before);
    // a model error (not a panic) is reported with time and instance name
    let fmu = host.instantiate("failing");
    assert_eq!(fmu.set(VR_FAIL, 0.0), fmi2OK);
    fmu.init();
    assert_eq!(fmu.step(0.0, 0.1), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("fmi2DoStep at t = 0, h = 0.1: instance \"failing\": deliberate failure"));
    assert_eq!(fmu.reset(), fmi2OK);
}

/// Runs `n` steps of 0.1 with u(k) = sin(k) and returns y after each.
fn trajectory(fmu: &Fmu, from: usize, n: usize) -> Vec<f64> {
    (from..from + n)
        .map(|k| {
            assert_eq!(fmu.set(VR_U, (k as f64).sin()), fmi2OK);
            assert_eq!(fmu.step(k as f64 * 0.1, 0.1), fmi2OK);
            fmu.get(VR_Y)
        })
        .collect()
}

#[test]
fn instances_are_independent() {
    let host = Host::new();
    let solo_a = host.instantiate("solo_a");
    solo_a.init();
    let ref_a = trajectory(&solo_a, 0, 50);
    let solo_b = host.instantiate("solo_b");
    assert_eq!(solo_b.set(VR_GAIN, -1.5), fmi2OK);
    solo_b.init();
    let ref_b = trajectory(&solo_b, 0, 50);
    let a = host.instantiate("a");
    let b = host.instantiate("b");
    assert_eq!(b.set(VR_GAIN, -1.5), fmi2OK);
    a.init();
    b.init();
    let (mut ya, mut yb) = (vec![], vec![]);
    for k in 0..50 {
        ya.extend(trajectory(&a, k, 1));
        yb.extend(trajectory(&b, k, 1));
    }
    assert_eq!(ya, ref_a);
    assert_eq!(yb, ref_b);
    assert_ne!(ref_a, ref_b);
}

#[test]
fn fmu_state_restores_bit_for_bit_and_serializes() {
    let host = Host::new();
    let fmu = host.instantiate("state");
    fmu.init();
    trajectory(&fmu, 0, 10);
    let s = fmu.get_state();
    let first = trajectory(&fmu, 10, 20);
    assert_eq!(fmu.set_state(s), fmi2OK);
    assert_eq!(trajectory(&fmu, 10, 20), first);
    // serialize the t = 1 snapshot, deserialize into a fresh instance and continue there
    let s_before = s;
    let bytes = fmu.serialize(s_before);
    let other = host.instantiate("restored");
    let (st, restored) = other.deserialize(&bytes);
    assert_eq!(st, fmi2OK);
    assert_eq!(other.set_state(restored), fmi2OK);
    assert_eq!(trajectory(&other, 10, 20), first);
    // the same bytes again
    assert_eq!(other.serialize(restored), bytes);
    // corrupt or foreign bytes are refused
    let mut bad = bytes.clone();
    bad[0] ^= 0xff;
    assert_eq!(other.deserialize(&bad).0, fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("not a serialized state of this Integrator"));
    assert_eq!(other.deserialize(&bytes[..bytes.len() - 3]).0, fmi2Error);
    assert!(host.0.log().last().contains("corrupt state"));
    assert_eq!(other.deserialize(&[]).0, fmi2Error);
    // a state made by another model type is refused
    let other_model = host.instantiate_with::<Other>(
        "other",
        fmi2CoSimulation,
        Some(&xml::guid::<Other>()),
        None,
        false,
    );
    let mut foreign: fmi2FMUstate = null_mut();
    assert_eq!(
        unsafe { api::get_fmu_state::<Other>(other_model, &mut foreign) },
        fmi2OK
    );
    assert_eq!(fmu.set_state(foreign), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("was not created by this instance of Integrator"));
    assert_eq!(
        unsafe { api::free_fmu_state::<Other>(other_model, &mut foreign) },
        fmi2OK
    );
    unsafe { api::free_instance::<Other>(other_model) };
    // reusing an existing state object overwrites it in place
    let y_now = fmu.get(VR_Y);
    let mut s2 = s;
    assert_eq!(
        unsafe { api::get_fmu_state::<Integrator>(fmu.0, &mut s2) },
        fmi2OK
    );
    assert_eq!(s2, s);
    trajectory(&fmu, 30, 5);
    assert_eq!(fmu.set_state(s), fmi2OK);
    assert_eq!(fmu.get(VR_Y), y_now);
    // a state of another instance of the same model is refused: states belong to the
    // instance that made them (serialized bytes carry a state across instances)
    assert_eq!(other.set_state(s), fmi2Error);
    assert!(host
        .0
        .log()
        .last()
        .contains("was not created by this instance of Integrator or was already freed"));
    fmu.free_state(s);
    other.free_state(restored);
    // a freed state is refused by every state call without being read: a second free was a
    // double free that aborted the host (fuzzer: `replay calls TokyoMaru 2044 28`)
    let mut freed = s;
    assert_eq!(
        unsafe { api::free_fmu_state::<Integrator>(fmu.0, &mut freed) },
        fmi2Error
    );
    assert!(host.0.log().last().contains("or was already freed"));
    assert_eq!(fmu.set_state(s), fmi2Error);
    let mut size = 0usize;
    assert_eq!(
        unsafe { api::serialized_fmu_state_size::<Integrator>(fmu.0, s, &mut size) },
        fmi2Error
    );
    let mut buf = [0 as c_char; 16];
    assert_eq!(
        unsafe { api::serialize_fmu_state::<Integrator>(fmu.0, s, buf.as_mut_ptr(), 16) },
        fmi2Error
    );
    let mut reuse = s;
    assert_eq!(
        unsafe { api::get_fmu_state::<Integrator>(fmu.0, &mut reuse) },
        fmi2Error
    );
    // a pointer that was never a state is refused too
    let mut made_up = 0x1000 as fmi2FMUstate;
    assert_eq!(
        unsafe { api::free_fmu_state::<Integrator>(fmu.0, &mut made_up) },
        fmi2Error
    );
    // states the importer leaves are freed with the instance (FMI 2.0, sec. 2.1.6)
    let left = host.instantiate("left");
    left.init();
    let _kept = [left.get_state(), left.get_state()];
    drop(left);
    // freeing NULL is fine
    let mut nothing: fmi2FMUstate = null_mut();
    assert_eq!(
        unsafe { api::free_fmu_state::<Integrator>(fmu.0, &mut nothing) },
        fmi2OK
    );
}

#[test]
fn debug_logging_filters_categories_and_escapes_percent() {
    let host = Host::new();
    let fmu = host.instantiate("log");
    // loggingOn = false: no call or event logging, errors still reported
    fmu.init();
    assert_eq!(host.0.log().count("logCalls"), 0);
    assert_eq!(host.0.log().count("logEvents"), 0);
    let cats = [CString::new("logCalls").unwrap()];
    let ptrs: Vec<fmi2String> = cats.iter().map(|c| c.as_ptr()).collect();
    assert_eq!(
        unsafe { api::set_debug_logging::<Integrator>(fmu.0, fmi2True, 1, ptrs.as_ptr()) },
        fmi2OK
    );
    assert_eq!(fmu.step(0.0, 0.1), fmi2OK);
    assert!(host.0.log().count("logCalls") >= 1);
    assert_eq!(host.0.log().count("logEvents"), 0);
    // debug logging off: per-call lines stop, errors are still reported (tests/logging.rs)
    assert_eq!(
        unsafe { api::set_debug_logging::<Integrator>(fmu.0, fmi2False, 0, null()) },
        fmi2OK
    );
    let calls = host.0.log().count("logCalls");
    assert_eq!(fmu.set(VR_U, f64::NAN), fmi2Error);
    assert_eq!(host.0.log().count("logCalls"), calls);
    assert_eq!(host.0.log().count("logStatusError"), 1);
    // all on: events are logged
    assert_eq!(
        unsafe { api::set_debug_logging::<Integrator>(fmu.0, fmi2True, 0, null()) },
        fmi2OK
    );
    assert_eq!(fmu.terminate(), fmi2OK);
    assert!(host.0.log().count("logEvents") >= 1);
    // an unknown category is an error; its name (with printf directives) arrives verbatim
    let cats = [CString::new("log%s%d%n").unwrap()];
    let ptrs: Vec<fmi2String> = cats.iter().map(|c| c.as_ptr()).collect();
    assert_eq!(
        unsafe { api::set_debug_logging::<Integrator>(fmu.0, fmi2True, 1, ptrs.as_ptr()) },
        fmi2Error
    );
    assert!(host
        .0
        .log()
        .last()
        .contains("unknown log category \"log%s%d%n\""));
}

// ---------------------------------------------------------------------------------------------
// The table language (fmu_description!/variables!) and the by-name harness.

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
enum Order {
    First,
    Second,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
struct Pose {
    heading: f64,
    heading_wrapped: f64,
    x: f64,
    y: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
struct Table {
    order: Order,
    seed: u64,
    gains: [f64; 2],
    flag: bool,
    pose: Pose,
}

impl Default for Table {
    fn default() -> Self {
        let pose = Pose {
            heading: 4.0,
            heading_wrapped: 4.0 - 2.0 * std::f64::consts::PI,
            x: 1.0,
            y: 2.0,
        };
        Table {
            order: Order::Second,
            seed: 7,
            gains: [0.5, 1.5],
            flag: true,
            pose,
        }
    }
}

fmi2_export::fmu_description! {
    Table => "Table",
    description: "table language",
    experiment: (0.0, 1.0, 0.5),
    direct_feedthrough: false,
    documentation_html: "",
    variables: {
        fixed int "order" (order => { 1: Order::First, 2: Order::Second }), "servo order";
        fixed int(0, i32::MAX) "seed" (seed as u64), "seed";
        tunable real "gain_b" (gains[1]).range(0.0, 2.0), "second gain";
        tunable int(0, 1) "flag_code" (|m| m.flag as i32, |m, v| m.flag = v == 1), "flag as a code";
        pose!(pose);
        output real "sum" (|m| m.gains[0] + m.gains[1]), "sum of the gains";
    }
}

impl FmuModel for Table {
    fn initialize(&mut self, _t: f64) -> Result<(), String> {
        Ok(())
    }
    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.pose.x += self.gains[1] * h;
        Ok(())
    }
}

#[test]
fn the_table_language_declares_enumerations_casts_paths_and_fragments() {
    use fmi2_export::testing::{check_every_variable, check_state_rollback, functions, Harness};
    fmi2_export::variables::check_table(Table::variables()).unwrap();
    let xml = xml::model_description::<Table>();
    // an enumeration's range is that of its codes; the start is the default's code
    assert!(xml.contains(r#"name="order" valueReference="0""#));
    assert!(
        xml.contains(r#"<Integer min="1" max="2" start="2"/>"#),
        "{xml}"
    );
    assert!(xml.contains(r#"<Integer min="0" max="2147483647" start="7"/>"#));
    assert!(xml.contains(r#"<Real min="0.0" max="2.0" start="1.5"/>"#));
    // the fragment splices its four entries in at its position
    let names: Vec<&str> = Table::variables().iter().map(|v| v.name).collect();
    assert_eq!(
        names,
        [
            "order",
            "seed",
            "gain_b",
            "flag_code",
            "heading",
            "heading_wrapped",
            "x",
            "y",
            "sum"
        ]
    );
    assert!(xml.contains(r#"<Unknown index="7" dependencies=""/>"#));

    let mut fmu = Harness::<Table>::instantiate(functions::<Table>(), "table");
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    assert_eq!(fmu.get::<i32>("order"), 2);
    fmu.set("order", 1)
        .set("seed", 12)
        .set("gain_b", 2.0)
        .set("flag_code", 0);
    assert_eq!(fmu.get::<i32>("order"), 1);
    assert_eq!(fmu.get::<i32>("seed"), 12);
    assert_eq!(fmu.get::<i32>("flag_code"), 0);
    // out of the enumeration's range, and out of a Real range: refused, value kept
    assert_eq!(fmu.try_set("order", 3), fmi2Error);
    assert!(fmu.log().last().contains("order"), "{}", fmu.log().last());
    assert_eq!(fmu.get::<i32>("order"), 1);
    assert_eq!(fmu.try_set("gain_b", 2.5), fmi2Error);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    fmu.step(0.0, 0.5);
    assert_eq!(
        fmu.reals(&["x", "y", "sum", "heading"]),
        [2.0, 2.0, 2.5, 4.0]
    );
    // an enumeration with a gap: code 2 passes the range check but no variant takes it
    let gap: &[Variable<Table>] = fmi2_export::variables!(Table;
        fixed int "order" (order => { 1: Order::First, 3: Order::Second }), "gapped";
    );
    let problems = fmi2_export::variables::check_table(gap).unwrap_err();
    assert!(
        problems[0].contains("order: 2 lies in the declared range"),
        "{problems:?}"
    );
    check_every_variable::<Table>(functions::<Table>());
    check_state_rollback::<Table>(functions::<Table>());
    check_every_variable::<Integrator>(functions::<Integrator>());
    check_state_rollback::<Integrator>(functions::<Integrator>());
}

#[test]
#[should_panic(expected = "Table: variable \"seed\" is Integer, not Real")]
fn the_harness_refuses_a_value_of_the_wrong_type() {
    use fmi2_export::testing::{functions, Harness};
    let mut fmu = Harness::<Table>::instantiate(functions::<Table>(), "table");
    fmu.set("seed", 1.0);
}

#[test]
#[should_panic(expected = "Table has no variable \"speed\"")]
fn the_harness_names_a_missing_variable() {
    use fmi2_export::testing::{functions, Harness};
    let fmu = Harness::<Table>::instantiate(functions::<Table>(), "table");
    fmu.real("speed");
}

/// The finiteness check of `fmi2GetReal` holds whatever the importer's rounding mode: rounding
/// downward, x - x of a finite x is -0.0 (sign bit set), which is no reason for an error.
#[test]
fn finite_outputs_pass_the_check_when_the_importer_rounds_downward() {
    extern "C" {
        fn fesetround(round: i32) -> i32;
        fn fegetround() -> i32;
    }
    // <fenv.h> on x86-64 and aarch64 Linux.
    #[cfg(target_arch = "x86_64")]
    const FE_DOWNWARD: i32 = 0x400;
    #[cfg(target_arch = "aarch64")]
    const FE_DOWNWARD: i32 = 0x800000;
    let host = Host::new();
    let fmu = host.instantiate("rounding");
    fmu.init();
    trajectory(&fmu, 0, 3);
    let before = unsafe { fegetround() };
    assert_eq!(unsafe { fesetround(FE_DOWNWARD) }, 0);
    let x = std::hint::black_box(0.1f64);
    assert!((x - x).is_sign_negative(), "the rounding mode took effect");
    let got = fmu.get_reals(&[VR_Y, VR_GAIN]);
    unsafe { fesetround(before) };
    assert_eq!(got.0, fmi2OK, "{}", host.0.log().last());
}
