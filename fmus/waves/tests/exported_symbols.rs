//! Calls the `fmi2*` symbols that `export_fmu!` emitted for Waves (linked from this crate's
//! rlib), as a C importer would, and checks them against the model; state snapshot restore.

use fmi2::*;
use models::disturbances::waves::{encounter_angle, WaveParams, Waves};
use std::ffi::CString;
use std::ptr::null;

fmi2::declare_fmi2_functions!();

fn vr(name: &str) -> u32 {
    use fmi2_export::FmuModel;
    waves_fmu::WavesFmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}")) as u32
}

#[test]
fn exported_api_reproduces_the_model_and_restores_states() {
    let guid = CString::new(fmi2_export::xml::guid::<waves_fmu::WavesFmu>()).unwrap();
    let name = CString::new("waves").unwrap();
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
        let seed = 99i32;
        assert_eq!(fmi2SetInteger(c, &vr("seed"), 1, &seed), fmi2OK);
        let gains = [1.0e6, 3.0e5, 0.4];
        let gvr = [vr("roll_gain"), vr("yaw_gain"), vr("wave_direction")];
        assert_eq!(fmi2SetReal(c, gvr.as_ptr(), 3, gains.as_ptr()), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);

        let mut p = WaveParams::default();
        p.seed = 99;
        p.roll_gain = 1.0e6;
        p.yaw_gain = 3.0e5;
        let mut model = Waves::new(p, 0.0).unwrap();
        let ins = [vr("ship_speed"), vr("heading")];
        let outs = [
            vr("wave_elevation"),
            vr("roll_moment"),
            vr("yaw_moment"),
            vr("wf_motion_yaw"),
        ];
        let h = 0.1;
        let mut snapshot: fmi2FMUstate = std::ptr::null_mut();
        let mut after = Vec::new();
        for k in 0..400 {
            let t = k as f64 * h;
            let u = [6.0 + 0.01 * k as f64, 0.3 * (0.05 * t).sin()];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 2, u.as_ptr()), fmi2OK);
            if k == 200 {
                assert_eq!(fmi2GetFMUstate(c, &mut snapshot), fmi2OK);
            }
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            model.set_inputs(u[0], encounter_angle(0.4, u[1]));
            model.advance_to(t + h);
            let mut v = [0.0; 4];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 4, v.as_mut_ptr()), fmi2OK);
            let m = model.wf_motion();
            assert_eq!(
                v,
                [
                    model.elevation(),
                    model.roll_moment(),
                    model.yaw_moment(),
                    m[2]
                ]
            );
            if k >= 200 {
                after.push(v);
            }
        }
        // restore the state of t = 20 s and repeat: bit-identical
        assert_eq!(fmi2SetFMUstate(c, snapshot), fmi2OK);
        for k in 200..400 {
            let t = k as f64 * h;
            let u = [6.0 + 0.01 * k as f64, 0.3 * (0.05 * t).sin()];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 2, u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            let mut v = [0.0; 4];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 4, v.as_mut_ptr()), fmi2OK);
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
    fmi2_export::variables::check_table(waves_fmu::WavesFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<waves_fmu::WavesFmu>();
    assert!(xml.contains(r#"name="wave_elevation""#));
    assert!(xml.contains(r#"modelIdentifier="Waves""#));
}
