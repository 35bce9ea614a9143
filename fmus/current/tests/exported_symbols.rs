//! Calls the `fmi2*` symbols that `export_fmu!` emitted for Current (linked from this crate's
//! rlib), as a C importer would, and checks them against the model; state snapshot restore.

use fmi2::*;
use models::disturbances::current::{Current, CurrentParams};
use std::ffi::CString;
use std::ptr::null;

fmi2::declare_fmi2_functions!();

fn vr(name: &str) -> u32 {
    use fmi2_export::FmuModel;
    current_fmu::CurrentFmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}")) as u32
}

#[test]
fn exported_api_reproduces_the_model_and_restores_states() {
    let guid = CString::new(fmi2_export::xml::guid::<current_fmu::CurrentFmu>()).unwrap();
    let name = CString::new("instance").unwrap();
    let cb = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    };
    let ins = [vr("heading")];
    let outs = [
        vr("n_prime"),
        vr("y_prime"),
        vr("current_sway"),
        vr("bias_surge"),
    ];
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
        let seed = 77i32;
        assert_eq!(fmi2SetInteger(c, &vr("seed"), 1, &seed), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut model = Current::new(
            CurrentParams {
                seed: 77,
                ..CurrentParams::default()
            },
            0.0,
        )
        .unwrap();
        let h = 0.3;
        let mut snapshot: fmi2FMUstate = std::ptr::null_mut();
        let mut after = Vec::new();
        for k in 0..400 {
            let t = k as f64 * h;
            let u: [f64; 1] = std::array::from_fn(|i| (i as f64 + 1.0) * (0.01 * t).sin());
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), ins.len(), u.as_ptr()), fmi2OK);
            if k == 200 {
                assert_eq!(fmi2GetFMUstate(c, &mut snapshot), fmi2OK);
            }
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            model.set_heading(u[0]);
            model.advance_to(t + h);
            let mut v = [0.0; 4];
            assert_eq!(
                fmi2GetReal(c, outs.as_ptr(), outs.len(), v.as_mut_ptr()),
                fmi2OK
            );
            assert_eq!(
                v,
                [
                    model.disturbance()[0],
                    model.disturbance()[1],
                    model.current_body()[1],
                    model.bias_body()[0]
                ]
            );
            if k >= 200 {
                after.push(v);
            }
        }
        assert_eq!(fmi2SetFMUstate(c, snapshot), fmi2OK);
        for k in 200..400 {
            let t = k as f64 * h;
            let u: [f64; 1] = std::array::from_fn(|i| (i as f64 + 1.0) * (0.01 * t).sin());
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), ins.len(), u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            let mut v = [0.0; 4];
            assert_eq!(
                fmi2GetReal(c, outs.as_ptr(), outs.len(), v.as_mut_ptr()),
                fmi2OK
            );
            assert_eq!(v, after[k - 200]);
        }
        assert_eq!(fmi2FreeFMUstate(c, &mut snapshot), fmi2OK);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(current_fmu::CurrentFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<current_fmu::CurrentFmu>();
    assert!(xml.contains(r#"modelIdentifier="Current""#));
}
