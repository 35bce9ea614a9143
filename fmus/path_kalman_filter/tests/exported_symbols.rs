//! Calls the `fmi2*` symbols emitted for PathKalmanFilter (linked from this crate's rlib), as a C
//! importer would, and checks them against the model.

use fmi2::*;
use models::hull::tokyo_maru::{L, U};
use models::observers::path_kalman::{PathKalmanConfig, PathKalmanFilter};
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
    path_kalman_filter_fmu::PathKalmanFilterFmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("{name}")) as u32
}

#[test]
fn exported_api_reproduces_the_model() {
    let guid = CString::new(fmi2_export::xml::guid::<
        path_kalman_filter_fmu::PathKalmanFilterFmu,
    >())
    .unwrap();
    let name = CString::new("pkf").unwrap();
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
        let design = PathKalmanConfig::default().design().unwrap();
        let mut model = PathKalmanFilter::new(design, [0.0; 7]).unwrap();
        let ins = [
            vr("heading_measured"),
            vr("yaw_rate_measured"),
            vr("cross_track_measured"),
            vr("rudder_command"),
        ];
        let outs = [
            vr("heading_estimate"),
            vr("cross_track_estimate"),
            vr("yaw_moment_prime_estimate"),
            vr("sway_force_prime_estimate"),
        ];
        let h = 0.005 * L / U;
        for k in 0..400 {
            let t = k as f64 * h;
            let u = [0.02 * (0.05 * t).sin(), 0.001, 3.0 + 0.01 * t, 0.05];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 4, u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            model.step(u[0], u[1], u[2], u[3], h);
            let mut v = [0.0; 4];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 4, v.as_mut_ptr()), fmi2OK);
            let x = model.estimate();
            assert_eq!(v, [x[0], x[3] * L, x[5], x[6]]);
        }
        // gain-update event: the Table 5 K(eta', eta') = 4.0000 -> Table 6 (deep water) 4.6587
        let mut g = 0.0;
        let vg = vr("gain_cross_track_cross_track");
        assert_eq!(fmi2GetReal(c, &vg, 1, &mut g), fmi2OK);
        assert!((g - 4.0000).abs() < 1e-4);
        let deep = 1e12;
        assert_eq!(fmi2SetReal(c, &vr("design_depth_ratio"), 1, &deep), fmi2OK);
        assert_eq!(fmi2GetReal(c, &vg, 1, &mut g), fmi2OK);
        assert!((g - 4.6587).abs() < 1e-4, "{g}");
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(path_kalman_filter_fmu::PathKalmanFilterFmu::variables())
        .unwrap();
    let xml = fmi2_export::xml::model_description::<path_kalman_filter_fmu::PathKalmanFilterFmu>();
    assert!(xml.contains(r#"name="heading_measured""#));
}

/// follow_design_inputs: the f*_design inputs of deep water (Table 2, H/T = inf) re-design the
/// filter at the next step: K(eta', eta') moves from Table 5's 4.0000 to 4.1330 (the f's of inf with
/// the gammas of 1.89 kept, as in the adaptive loop), equal to the model filter with that design;
/// unchanged inputs leave the gain alone; a non-finite input is refused.
#[test]
fn follows_the_design_inputs() {
    use models::hull::tokyo_maru::TABLE_2;
    let guid = CString::new(fmi2_export::xml::guid::<
        path_kalman_filter_fmu::PathKalmanFilterFmu,
    >())
    .unwrap();
    let name = CString::new("pkf").unwrap();
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
        assert_eq!(
            fmi2SetBoolean(c, &vr("follow_design_inputs"), 1, &1),
            fmi2OK
        );
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let vg = vr("gain_cross_track_cross_track");
        let mut g = 0.0;
        let h = 0.005 * L / U;
        assert_eq!(fmi2DoStep(c, 0.0, h, 1), fmi2OK);
        assert_eq!(fmi2GetReal(c, &vg, 1, &mut g), fmi2OK);
        assert!((g - 4.0000).abs() < 1e-4, "{g}");
        let d = TABLE_2[4];
        let f = [d.f22, d.f23, d.f25, d.f32, d.f33, d.f35];
        let names = [
            "f22_design",
            "f23_design",
            "f25_design",
            "f32_design",
            "f33_design",
            "f35_design",
        ];
        let vrs: Vec<u32> = names.iter().map(|n| vr(n)).collect();
        assert_eq!(fmi2SetReal(c, vrs.as_ptr(), 6, f.as_ptr()), fmi2OK);
        assert_eq!(fmi2DoStep(c, h, h, 1), fmi2OK);
        assert_eq!(fmi2GetReal(c, &vg, 1, &mut g), fmi2OK);
        let mut design = PathKalmanConfig::default().design().unwrap();
        let cc = &mut design.coefficients;
        (cc.f22, cc.f23, cc.f25, cc.f32, cc.f33, cc.f35) = (f[0], f[1], f[2], f[3], f[4], f[5]);
        let want = PathKalmanFilter::new(design, [0.0; 7]).unwrap().gain()[(3, 2)];
        assert_eq!(g, want);
        assert!((g - 4.1330).abs() < 1e-4, "{g}");
        assert_eq!(fmi2DoStep(c, 2.0 * h, h, 1), fmi2OK);
        assert_eq!(fmi2GetReal(c, &vg, 1, &mut g), fmi2OK);
        assert_eq!(g, want);
        let nan = f64::NAN;
        assert_ne!(fmi2SetReal(c, &vrs[1], 1, &nan), fmi2OK);
        fmi2FreeInstance(c);
    }
}
