//! DgpsKalman through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::observers::dgps_kalman` by variable name.

use fmi2_export::fmi2::fmi2OK;
use models::observers::dgps_kalman::{DgpsKalman, DgpsKalmanParams};

fmi2_export::fmu_tests!(dgps_kalman_fmu::DgpsKalmanFmu);

#[test]
fn exported_api_reproduces_the_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model = DgpsKalman::new(DgpsKalmanParams::default(), [0.0; 4]).unwrap();
    let outputs = [
        "velocity_north_estimate",
        "east_estimate",
        "drift_angle",
        "gain_velocity",
    ];
    for k in 0..300 {
        let t = k as f64;
        let u = [
            233.0 * (0.03 * t).sin(),
            233.0 * (1.0 - (0.03 * t).cos()),
            0.03 * t,
        ];
        fmu.set("north_measured", u[0])
            .set("east_measured", u[1])
            .set("heading", u[2])
            .step(t, 1.0);
        model.step(u[0], u[1], 1.0);
        let e = model.estimate();
        let expected = [
            e[0],
            e[3],
            model.drift_angle(u[2]),
            model.steady_gain()[(0, 0)],
        ];
        assert_eq!(fmu.reals(&outputs), expected);
    }
    assert!((model.steady_gain()[(0, 0)] - 0.042688).abs() < 1e-5);
    assert_eq!(fmu.terminate(), fmi2OK);
}

/// T8 through the C API: initial estimate v = [0, 7] m/s (course east), heading 90 deg, a
/// 0.25 m/s north current: water-related body velocity [7.0, 0.25] m/s, drift angle -2.045 deg.
#[test]
fn current_correction_t8_through_the_api() {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu.set("initial_velocity_east", 7.0)
        .set("heading", std::f64::consts::FRAC_PI_2)
        .set("current_speed", 0.25)
        .set("current_direction", 0.0);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    let v = fmu.reals(&[
        "surge_velocity_water",
        "sway_velocity_water",
        "drift_angle_water",
        "drift_angle",
    ]);
    assert!(
        (v[0] - 7.0).abs() < 1e-12 && (v[1] - 0.25).abs() < 1e-12,
        "{v:?}"
    );
    assert!((v[2].to_degrees() + 2.045).abs() < 5e-4, "{v:?}");
    assert!(v[3].abs() < 1e-12);
    assert_eq!(fmu.terminate(), fmi2OK);
}
