//! Calls the `fmi2*` symbols that `export_fmu!` emitted for RrsAutopilot (linked from this
//! crate's rlib), as a C importer would, and checks them against the model.

use fmi2::*;
use models::controllers::rrs::{RrsAutopilot, RrsAutopilotParams, RrsInputs};
use std::ffi::CString;
use std::ptr::null;

fmi2::declare_fmi2_functions!();

#[test]
fn exported_api_reproduces_the_model() {
    let guid =
        CString::new(fmi2_export::xml::guid::<rrs_autopilot_fmu::RrsAutopilotFmu>()).unwrap();
    let name = CString::new("rrs").unwrap();
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
        let mut model = RrsAutopilot::new(RrsAutopilotParams::default()).unwrap();
        let mut u = RrsInputs {
            speed: 11.0,
            ..Default::default()
        };
        let ins: [u32; 7] = [35, 36, 37, 38, 39, 40, 41];
        let outs = [44u32, 47, 50];
        for k in 0..600 {
            let t = k as f64 * 0.1;
            let x = [
                0.1 * (0.63 * t).sin(),
                0.063 * (0.63 * t).cos(),
                0.01 * (0.3 * t).sin(),
                0.02,
                0.001,
                0.0,
                11.0 - 0.01 * t,
            ];
            u.roll = x[0];
            u.roll_rate = x[1];
            u.sway_rudder = x[2];
            u.heading_error = x[3];
            u.yaw_rate = x[4];
            u.yaw_offset = x[5];
            u.speed = x[6];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 7, x.as_ptr()), fmi2OK);
            let mut v = [0.0; 3];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 3, v.as_mut_ptr()), fmi2OK);
            let o = model.outputs(&u);
            assert_eq!(
                v,
                [
                    o.rudder_command,
                    o.attenuation,
                    model.roll_gains(u.speed)[0]
                ]
            );
            assert_eq!(fmi2DoStep(c, t, 0.1, 1), fmi2OK);
            model.step(&u, 0.1);
        }
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(rrs_autopilot_fmu::RrsAutopilotFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<rrs_autopilot_fmu::RrsAutopilotFmu>();
    assert!(xml.contains(r#"name="roll" valueReference="35""#));
    assert!(xml.contains(r#"name="rudder_command" valueReference="44""#));
    assert!(xml.contains(r#"name="roll_gain_1" valueReference="50""#));
}
