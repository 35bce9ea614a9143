//! Calls the `fmi2*` symbols emitted for ParameterEkf (linked from this crate's rlib), as a C
//! importer would, and checks them against the model.

use fmi2::*;
use models::observers::parameter_ekf::ParameterEkf;
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
    parameter_ekf_fmu::ParameterEkfFmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("{name}")) as u32
}

fn inputs(t: f64) -> [f64; 5] {
    let s = (0.02 * t).sin();
    [
        5.0,
        0.3 * s,
        -0.004 * (0.02 * t).cos(),
        80.0,
        0.17 * s.signum(),
    ]
}

#[test]
fn exported_api_reproduces_the_model() {
    let guid =
        CString::new(fmi2_export::xml::guid::<parameter_ekf_fmu::ParameterEkfFmu>()).unwrap();
    let name = CString::new("ekf").unwrap();
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
        let mut model = ParameterEkf::new(parameter_ekf_fmu::default_params(), 0.0).unwrap();
        let ins = [
            vr("surge_velocity_measured"),
            vr("sway_velocity_measured"),
            vr("yaw_rate_measured"),
            vr("shaft_speed_measured"),
            vr("rudder_angle"),
        ];
        let outs = [
            vr("sway_velocity_estimate"),
            vr("neg_y_v_estimate"),
            vr("mxg_minus_n_r_mean"),
            vr("nomoto_gain_prime"),
        ];
        let check = |model: &ParameterEkf, c: fmi2Component| {
            let mut v = [0.0; 4];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 4, v.as_mut_ptr()), fmi2OK);
            assert_eq!(
                v,
                [
                    model.dimensional_states()[1],
                    model.coefficients()[0],
                    model.averaged_coefficients()[3],
                    model.identified_nomoto().1
                ]
            );
        };
        let mut snapshot: fmi2FMUstate = std::ptr::null_mut();
        let mut model_at_snapshot = None;
        for k in 0..400 {
            let t = k as f64 * 0.5;
            let u = inputs(t);
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 5, u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, 0.5, 1), fmi2OK);
            model.step(t, 0.5, [u[0], u[1], u[2], u[3]], u[4]);
            check(&model, c);
            if k == 199 {
                assert_eq!(fmi2GetFMUstate(c, &mut snapshot), fmi2OK);
                model_at_snapshot = Some(model.clone());
            }
        }
        assert_eq!(model.updates(), 200);
        // Restore the FMU state and replay: bit-identical.
        assert_eq!(fmi2SetFMUstate(c, snapshot), fmi2OK);
        let mut model = model_at_snapshot.unwrap();
        for k in 200..400 {
            let t = k as f64 * 0.5;
            let u = inputs(t);
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 5, u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, 0.5, 1), fmi2OK);
            model.step(t, 0.5, [u[0], u[1], u[2], u[3]], u[4]);
            check(&model, c);
        }
        assert_eq!(fmi2FreeFMUstate(c, &mut snapshot), fmi2OK);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(parameter_ekf_fmu::ParameterEkfFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<parameter_ekf_fmu::ParameterEkfFmu>();
    assert!(xml.contains(r#"name="neg_y_v_mean""#));
    // outputs depend on the state only
    assert!(xml.contains(r#"dependencies="""#));
}
