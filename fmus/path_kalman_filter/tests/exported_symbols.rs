//! PathKalmanFilter through the `fmi2*` symbols its crate exports, as a C importer calls them:
//! the checks every FMU runs, and the FMU against `models::observers::path_kalman` by variable
//! name.

use fmi2_export::fmi2::fmi2OK;
use models::hull::tokyo_maru::{L, U};
use models::observers::path_kalman::{PathKalmanConfig, PathKalmanFilter};

fmi2_export::fmu_tests!(path_kalman_filter_fmu::PathKalmanFilterFmu);

#[test]
fn exported_api_reproduces_the_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let design = PathKalmanConfig::default().design().unwrap();
    let mut model = PathKalmanFilter::new(design, [0.0; 7]).unwrap();
    let outputs = [
        "heading_estimate",
        "cross_track_estimate",
        "yaw_moment_prime_estimate",
        "sway_force_prime_estimate",
    ];
    let h = 0.005 * L / U;
    for k in 0..400 {
        let t = k as f64 * h;
        let u = [0.02 * (0.05 * t).sin(), 0.001, 3.0 + 0.01 * t, 0.05];
        fmu.set("heading_measured", u[0])
            .set("yaw_rate_measured", u[1])
            .set("cross_track_measured", u[2])
            .set("rudder_command", u[3])
            .step(t, h);
        model.step(u[0], u[1], u[2], u[3], h);
        let x = model.estimate();
        assert_eq!(fmu.reals(&outputs), [x[0], x[3] * L, x[5], x[6]]);
    }
    // gain-update event: the [Parsons1980, Table 5] K(eta', eta') = 4.0000 -> [Parsons1980, Table 6] (deep water) 4.6587
    let g = fmu.real("gain_cross_track_cross_track");
    assert!((g - 4.0000).abs() < 1e-4);
    fmu.set("design_depth_ratio", 1e12);
    let g = fmu.real("gain_cross_track_cross_track");
    assert!((g - 4.6587).abs() < 1e-4, "{g}");
    assert_eq!(fmu.terminate(), fmi2OK);
}

/// follow_design_inputs: the f*_design inputs of deep water ([Parsons1980, Table 2], H/T = inf) re-design the
/// filter at the next step: K(eta', eta') moves from [Parsons1980, Table 5]'s 4.0000 to 4.1330 (the f's of inf with
/// the gammas of 1.89 kept, as in the adaptive loop), equal to the model filter with that design;
/// unchanged inputs leave the gain alone; a non-finite input is refused.
#[test]
fn follows_the_design_inputs() {
    use models::hull::tokyo_maru::TABLE_2;
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu.set("follow_design_inputs", true);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    let h = 0.005 * L / U;
    let g = fmu.step(0.0, h).real("gain_cross_track_cross_track");
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
    for (name, value) in names.iter().zip(f) {
        fmu.set(name, value);
    }
    let g = fmu.step(h, h).real("gain_cross_track_cross_track");
    let mut design = PathKalmanConfig::default().design().unwrap();
    let cc = &mut design.coefficients;
    (cc.f22, cc.f23, cc.f25, cc.f32, cc.f33, cc.f35) = (f[0], f[1], f[2], f[3], f[4], f[5]);
    let want = PathKalmanFilter::new(design, [0.0; 7]).unwrap().gain()[(3, 2)];
    assert_eq!(g, want);
    assert!((g - 4.1330).abs() < 1e-4, "{g}");
    let g = fmu.step(2.0 * h, h).real("gain_cross_track_cross_track");
    assert_eq!(g, want);
    assert_ne!(fmu.try_set("f23_design", f64::NAN), fmi2OK);
}
