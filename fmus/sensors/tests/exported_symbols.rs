//! Calls the `fmi2*` symbols that `export_fmu!` emitted for Sensors (linked from this crate's
//! rlib), as a C importer would, and checks them against the model; state snapshot restore.

use fmi2::*;
use models::sensors::{SensorParams, Sensors, CHANNELS};
use std::ffi::CString;
use std::ptr::null;

fmi2::declare_fmi2_functions!();

fn vr(name: &str) -> u32 {
    use fmi2_export::FmuModel;
    sensors_fmu::SensorsFmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}")) as u32
}

fn truth(t: f64) -> [f64; CHANNELS] {
    std::array::from_fn(|i| (i as f64 + 1.0) * (0.1 * t + 0.05 * i as f64).sin())
}

#[test]
fn exported_api_reproduces_the_model_and_restores_states() {
    let guid = CString::new(fmi2_export::xml::guid::<sensors_fmu::SensorsFmu>()).unwrap();
    let name = CString::new("sensors").unwrap();
    let cb = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    };
    let names = models::sensors::CHANNEL_NAMES.map(|(n, _)| n);
    let ins: Vec<u32> = names.iter().map(|n| vr(n)).collect();
    let outs: Vec<u32> = names.iter().map(|n| vr(&format!("{n}_measured"))).collect();
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
        let seed = 8i32;
        assert_eq!(fmi2SetInteger(c, &vr("seed"), 1, &seed), fmi2OK);
        let sig = 0.3;
        assert_eq!(fmi2SetReal(c, &vr("roll_sigma"), 1, &sig), fmi2OK);
        let x0 = truth(0.0);
        assert_eq!(fmi2SetReal(c, ins.as_ptr(), CHANNELS, x0.as_ptr()), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut p = SensorParams::default();
        p.seed = 8;
        p.channels[2].sigma = 0.3;
        let mut model = Sensors::new(p, 0.0, x0).unwrap();
        let h = 0.1;
        let mut snapshot: fmi2FMUstate = std::ptr::null_mut();
        let mut after = Vec::new();
        for k in 0..300 {
            let t = k as f64 * h;
            let x = truth(t);
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), CHANNELS, x.as_ptr()), fmi2OK);
            model.set_inputs(x);
            let mut v = [0.0; CHANNELS];
            assert_eq!(
                fmi2GetReal(c, outs.as_ptr(), CHANNELS, v.as_mut_ptr()),
                fmi2OK
            );
            assert_eq!(v, std::array::from_fn(|i| model.measured(i)));
            if k == 150 {
                assert_eq!(fmi2GetFMUstate(c, &mut snapshot), fmi2OK);
            }
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            model.advance_to(t + h);
            assert_eq!(
                fmi2GetReal(c, outs.as_ptr(), CHANNELS, v.as_mut_ptr()),
                fmi2OK
            );
            assert_eq!(v, std::array::from_fn(|i| model.measured(i)));
            if k >= 150 {
                after.push(v);
            }
        }
        assert_eq!(fmi2SetFMUstate(c, snapshot), fmi2OK);
        for k in 150..300 {
            let t = k as f64 * h;
            let x = truth(t);
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), CHANNELS, x.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            let mut v = [0.0; CHANNELS];
            assert_eq!(
                fmi2GetReal(c, outs.as_ptr(), CHANNELS, v.as_mut_ptr()),
                fmi2OK
            );
            assert_eq!(v, after[k - 150]);
        }
        assert_eq!(fmi2FreeFMUstate(c, &mut snapshot), fmi2OK);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(sensors_fmu::SensorsFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<sensors_fmu::SensorsFmu>();
    assert!(xml.contains(r#"name="north_measured""#));
    assert!(xml.contains(r#"modelIdentifier="Sensors""#));
}
