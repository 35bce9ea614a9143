//! Calls the `fmi2*` symbols emitted for DgpsKalman (linked from this crate's rlib), as a C
//! importer would, and checks them against the model.

use fmi2::*;
use models::observers::dgps_kalman::{DgpsKalman, DgpsKalmanParams};
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
    dgps_kalman_fmu::DgpsKalmanFmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("{name}")) as u32
}

#[test]
fn exported_api_reproduces_the_model() {
    let guid = CString::new(fmi2_export::xml::guid::<dgps_kalman_fmu::DgpsKalmanFmu>()).unwrap();
    let name = CString::new("dgps").unwrap();
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
        let mut model = DgpsKalman::new(DgpsKalmanParams::default(), [0.0; 4]).unwrap();
        let ins = [vr("north_measured"), vr("east_measured"), vr("heading")];
        let outs = [
            vr("velocity_north_estimate"),
            vr("east_estimate"),
            vr("drift_angle"),
            vr("gain_velocity"),
        ];
        for k in 0..300 {
            let t = k as f64;
            let u = [
                233.0 * (0.03 * t).sin(),
                233.0 * (1.0 - (0.03 * t).cos()),
                0.03 * t,
            ];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 3, u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, 1.0, 1), fmi2OK);
            model.step(u[0], u[1], 1.0);
            let mut v = [0.0; 4];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 4, v.as_mut_ptr()), fmi2OK);
            let e = model.estimate();
            assert_eq!(
                v,
                [
                    e[0],
                    e[3],
                    model.drift_angle(u[2]),
                    model.steady_gain()[(0, 0)]
                ]
            );
        }
        assert!((model.steady_gain()[(0, 0)] - 0.042688).abs() < 1e-5);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(dgps_kalman_fmu::DgpsKalmanFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<dgps_kalman_fmu::DgpsKalmanFmu>();
    assert!(xml.contains(r#"name="north_measured""#));
}

/// T8 through the C API: initial estimate v = [0, 7] m/s (course east), heading 90 deg, a
/// 0.25 m/s north current: water-related body velocity [7.0, 0.25] m/s, drift angle -2.045 deg.
#[test]
fn current_correction_t8_through_the_api() {
    let guid = CString::new(fmi2_export::xml::guid::<dgps_kalman_fmu::DgpsKalmanFmu>()).unwrap();
    let name = CString::new("dgps").unwrap();
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
        let set = [
            vr("initial_velocity_east"),
            vr("heading"),
            vr("current_speed"),
            vr("current_direction"),
        ];
        let val = [7.0, std::f64::consts::FRAC_PI_2, 0.25, 0.0];
        assert_eq!(fmi2SetReal(c, set.as_ptr(), 4, val.as_ptr()), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let outs = [
            vr("surge_velocity_water"),
            vr("sway_velocity_water"),
            vr("drift_angle_water"),
            vr("drift_angle"),
        ];
        let mut v = [0.0; 4];
        assert_eq!(fmi2GetReal(c, outs.as_ptr(), 4, v.as_mut_ptr()), fmi2OK);
        assert!(
            (v[0] - 7.0).abs() < 1e-12 && (v[1] - 0.25).abs() < 1e-12,
            "{v:?}"
        );
        assert!((v[2].to_degrees() + 2.045).abs() < 5e-4, "{v:?}");
        assert!(v[3].abs() < 1e-12);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}
