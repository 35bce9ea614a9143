//! Calls the `fmi2*` symbols emitted for RrsFilter (linked from this crate's rlib), as a C
//! importer would, and checks them against the model.

use fmi2::*;
use models::observers::rrs_filter::{
    RollFilterParams, RrsFilter, RrsFilterInputs, SpeedFilterParams, YawFilterParams,
};
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

fn vr(name: &str) -> u32 {
    use fmi2_export::FmuModel;
    rrs_filter_fmu::RrsFilterFmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("{name}")) as u32
}

#[test]
fn exported_api_reproduces_the_model() {
    let guid = CString::new(fmi2_export::xml::guid::<rrs_filter_fmu::RrsFilterFmu>()).unwrap();
    let name = CString::new("rrs").unwrap();
    let cb = callbacks();
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
        let mut model = RrsFilter::new(
            RollFilterParams::table_2_4(11.0, 10.0, 0.001),
            YawFilterParams::realised(11.0),
            SpeedFilterParams::realised(),
            0.1,
            11.0,
        )
        .unwrap();
        let ins = [
            vr("roll_measured"),
            vr("heading_measured"),
            vr("speed_measured"),
            vr("roll_rudder"),
            vr("course_rudder"),
        ];
        let outs = [
            vr("roll_estimate"),
            vr("heading_estimate"),
            vr("yaw_k1"),
            vr("speed_estimate"),
        ];
        let h = 0.25;
        for k in 0..400 {
            let t = k as f64 * h;
            let u = [
                0.1 * (0.63 * t).sin() + 0.02,
                0.05 * (0.02 * t).sin() + 0.01 * (0.9 * t).sin(),
                11.0 + (0.01 * t).sin(),
                0.01 * (0.63 * t).cos(),
                0.02,
            ];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 5, u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            let inp = RrsFilterInputs {
                roll: u[0],
                heading: u[1],
                speed: u[2],
                roll_rudder: u[3],
                course_rudder: u[4],
            };
            model.step(&inp, h);
            let mut v = [0.0; 4];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 4, v.as_mut_ptr()), fmi2OK);
            assert_eq!(
                v,
                [
                    model.roll.state()[0],
                    model.yaw.state()[0],
                    model.yaw.gains()[0],
                    model.speed.estimate()
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
    fmi2_export::variables::check_table(rrs_filter_fmu::RrsFilterFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<rrs_filter_fmu::RrsFilterFmu>();
    assert!(xml.contains(r#"name="roll_measured""#));
}
