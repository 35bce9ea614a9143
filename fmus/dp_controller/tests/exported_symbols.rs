//! Calls the `fmi2*` symbols that `export_fmu!` emitted for DpController (linked from this
//! crate's rlib), as a C importer would, and checks them against the model.

use fmi2::*;
use models::controllers::dp::{DpController, DpInputs, DpParams};
use std::ffi::CString;
use std::ptr::null;

fmi2::declare_fmi2_functions!();

fn callbacks() -> fmi2CallbackFunctions {
    fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    }
}

#[test]
fn exported_api_reproduces_the_model() {
    let guid =
        CString::new(fmi2_export::xml::guid::<dp_controller_fmu::DpControllerFmu>()).unwrap();
    let name = CString::new("dp").unwrap();
    let cb = callbacks();
    unsafe {
        let c = fmi2Instantiate(
            name.as_ptr(),
            fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            &cb,
            0,
            0,
        );
        assert!(!c.is_null());
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
        assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
        let (vr_amp, amp) = (11u32, 1000.0);
        assert_eq!(fmi2SetReal(c, &vr_amp, 1, &amp), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut params = DpParams::northern_clipper();
        params.test_amplitude[0] = amp;
        let mut model = DpController::new(params, 0.0).unwrap();
        let ins: Vec<u32> = (17..26).collect();
        let outs = [26u32, 27, 28];
        for k in 0..300 {
            let t = k as f64 * 0.5;
            let u = DpInputs {
                eta: [
                    3.0 * (0.02 * t).sin(),
                    -2.0 + 0.01 * t,
                    0.3 * (0.01 * t).cos(),
                ],
                nu: [0.1 * (0.03 * t).cos(), 0.02, 1e-3 * (0.05 * t).sin()],
                setpoint: [1.0, -1.0, 0.2],
            };
            let v: Vec<f64> = u
                .eta
                .iter()
                .chain(&u.nu)
                .chain(&u.setpoint)
                .copied()
                .collect();
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 9, v.as_ptr()), fmi2OK);
            let mut y = [0.0; 3];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 3, y.as_mut_ptr()), fmi2OK);
            assert_eq!(y, model.tau(&u), "feedthrough at t = {t}");
            assert_eq!(fmi2DoStep(c, t, 0.5, 1), fmi2OK);
            model.step(&u, 0.5);
            model.set_time((k + 1) as f64 * 0.5);
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 3, y.as_mut_ptr()), fmi2OK);
            assert_eq!(y, model.tau(&u), "after the step from t = {t}");
        }
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(dp_controller_fmu::DpControllerFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<dp_controller_fmu::DpControllerFmu>();
    // value references used above
    assert!(xml.contains(r#"name="test_amplitude_surge" valueReference="11""#));
    assert!(xml.contains(r#"name="north_estimate" valueReference="17""#));
    assert!(xml.contains(r#"name="heading_setpoint" valueReference="25""#));
    assert!(xml.contains(r#"name="tau_surge" valueReference="26""#));
}
