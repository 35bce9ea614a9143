//! Calls the `fmi2*` symbols that `export_fmu!` emitted for SteeringGear (linked from this
//! crate's rlib), as a C importer would, and checks them against the model.

use fmi2::*;
use models::steering_gear::{SteeringGear, SteeringGearParams};
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
        CString::new(fmi2_export::xml::guid::<steering_gear_fmu::SteeringGearFmu>()).unwrap();
    let name = CString::new("gear").unwrap();
    let cb = callbacks();
    unsafe {
        assert_eq!(lossy_str(fmi2GetVersion()), "2.0");
        let wrong = CString::new("{00000000-0000-0000-0000-000000000000}").unwrap();
        assert!(fmi2Instantiate(
            name.as_ptr(),
            fmi2CoSimulation,
            wrong.as_ptr(),
            null(),
            &cb,
            0,
            0
        )
        .is_null());
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
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut model = SteeringGear::new(SteeringGearParams::rrs_003(), 0.0).unwrap();
        let (vr_cmd, outs) = (9u32, [10u32, 11, 12, 15]);
        for k in 0..500 {
            let t = k as f64 * 0.02;
            let cmd = 0.6 * (1.3 * t).sin();
            assert_eq!(fmi2SetReal(c, &vr_cmd, 1, &cmd), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, 0.02, 1), fmi2OK);
            model.step(cmd, 0.02);
            let mut v = [0.0; 4];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 4, v.as_mut_ptr()), fmi2OK);
            assert_eq!(
                v,
                [
                    model.angle(),
                    model.rate(),
                    model.limited_command(),
                    model.rate_saturated_time()
                ]
            );
        }
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(steering_gear_fmu::SteeringGearFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<steering_gear_fmu::SteeringGearFmu>();
    // value references used above
    assert!(xml.contains(r#"name="rudder_command" valueReference="9""#));
    assert!(xml.contains(r#"name="rate_saturated_time" valueReference="15""#));
}
