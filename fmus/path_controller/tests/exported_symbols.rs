//! Calls the `fmi2*` symbols that `export_fmu!` emitted for PathController (linked from this
//! crate's rlib), as a C importer would, and checks them against the model.

use fmi2::*;
use models::controllers::path::{PathController, PathControllerParams, PathInputs};
use std::ffi::CString;
use std::ptr::null;

fmi2::declare_fmi2_functions!();

#[test]
fn exported_api_reproduces_the_model() {
    let guid = CString::new(fmi2_export::xml::guid::<
        path_controller_fmu::PathControllerFmu,
    >())
    .unwrap();
    let name = CString::new("path").unwrap();
    let cb = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    };
    unsafe {
        assert_eq!(lossy_str(fmi2GetVersion()), "2.0");
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
        let mut model = PathController::new(PathControllerParams::default()).unwrap();
        let mut u = PathInputs {
            depth_ratio: 1.89,
            ..Default::default()
        };
        model.start(&u);
        let ins: [u32; 7] = [24, 25, 26, 27, 28, 29, 30];
        let outs = [38u32, 40, 45];
        for k in 0..300 {
            let t = k as f64 * 0.5;
            let x = [
                0.02 * (0.01 * t).sin(),
                1e-4 * (0.02 * t).cos(),
                0.01,
                20.0 * (0.005 * t).sin(),
                0.05,
                1e-3,
                2e-3,
            ];
            u.heading = x[0];
            u.yaw_rate = x[1];
            u.drift_angle = x[2];
            u.cross_track = x[3];
            u.rudder = x[4];
            u.yaw_moment_prime = x[5];
            u.sway_force_prime = x[6];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 7, x.as_ptr()), fmi2OK);
            let mut v = [0.0; 3];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 3, v.as_mut_ptr()), fmi2OK);
            assert_eq!(
                v,
                [model.command(&u), model.gains().c[0], model.gains().c[5]]
            );
            assert_eq!(fmi2DoStep(c, t, 0.5, 1), fmi2OK);
            model.step(&u, 0.5).unwrap();
        }
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(path_controller_fmu::PathControllerFmu::variables())
        .unwrap();
    let xml = fmi2_export::xml::model_description::<path_controller_fmu::PathControllerFmu>();
    assert!(xml.contains(r#"name="heading" valueReference="24""#));
    assert!(xml.contains(r#"name="rudder_command" valueReference="38""#));
    assert!(xml.contains(r#"name="gain_yaw_moment" valueReference="45""#));
}
