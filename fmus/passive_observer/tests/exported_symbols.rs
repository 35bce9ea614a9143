//! Calls the `fmi2*` symbols emitted for PassiveObserver (linked from this crate's rlib), as a C
//! importer would, and checks them against the model.

use fmi2::*;
use models::observers::passive_observer::{PassiveObserver, PassiveObserverParams};
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
    passive_observer_fmu::PassiveObserverFmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("{name}")) as u32
}

#[test]
fn exported_api_reproduces_the_model() {
    let guid = CString::new(fmi2_export::xml::guid::<
        passive_observer_fmu::PassiveObserverFmu,
    >())
    .unwrap();
    let name = CString::new("po").unwrap();
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
        let mut model =
            PassiveObserver::new(PassiveObserverParams::northern_clipper(), [0.0; 3]).unwrap();
        let ins = [
            vr("north_measured"),
            vr("east_measured"),
            vr("heading_measured"),
            vr("tau_surge"),
            vr("tau_sway"),
            vr("tau_yaw"),
        ];
        let outs = [
            vr("north_estimate"),
            vr("heading_estimate"),
            vr("sway_velocity_estimate"),
            vr("bias_north_estimate"),
        ];
        let mut k1 = 0.0;
        assert_eq!(fmi2GetReal(c, &vr("k1_surge"), 1, &mut k1), fmi2OK);
        assert!((k1 + 2.2059).abs() < 0.5e-4);
        for k in 0..300 {
            let t = k as f64;
            let u = [
                3.0 * (0.9 * t).sin() + 0.01 * t,
                -2.0 * (0.85 * t).cos(),
                0.1 + 0.01 * (0.9 * t).sin(),
                1e5 * (0.05 * t).sin(),
                1e5,
                -1e7,
            ];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 6, u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, 1.0, 1), fmi2OK);
            model.step([u[0], u[1], u[2]], [u[3], u[4], u[5]], 1.0);
            let mut v = [0.0; 4];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 4, v.as_mut_ptr()), fmi2OK);
            assert_eq!(
                v,
                [
                    model.eta()[0],
                    model.eta()[2],
                    model.nu()[1],
                    model.bias_force()[0]
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
    fmi2_export::variables::check_table(passive_observer_fmu::PassiveObserverFmu::variables())
        .unwrap();
    let xml = fmi2_export::xml::model_description::<passive_observer_fmu::PassiveObserverFmu>();
    assert!(xml.contains(r#"name="north_measured""#));
}
