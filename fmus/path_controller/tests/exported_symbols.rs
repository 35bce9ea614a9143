//! PathController through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::controllers::path` by variable name.

use models::controllers::path::{PathController, PathControllerParams, PathInputs};

fmi2_export::fmu_tests!(path_controller_fmu::PathControllerFmu);

#[test]
fn exported_api_reproduces_the_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model = PathController::new(PathControllerParams::default()).unwrap();
    let mut u = PathInputs {
        depth_ratio: 1.89,
        ..Default::default()
    };
    model.start(&u);
    let inputs = [
        "heading",
        "yaw_rate",
        "drift_angle",
        "cross_track",
        "rudder_angle",
        "yaw_moment_prime",
        "sway_force_prime",
    ];
    let outputs = ["rudder_command", "gain_heading", "gain_yaw_moment"];
    for k in 0..300 {
        let t = k as f64 * 0.5;
        let x = [
            0.02 * (0.01 * t).sin(),
            1e-4 * (0.02 * t).cos(),
            0.01,
            20.0 * (0.005 * t).sin(),
            0.05,
            1e-3,
            2e-3,
        ];
        [
            u.heading,
            u.yaw_rate,
            u.drift_angle,
            u.cross_track,
            u.rudder,
            u.yaw_moment_prime,
            u.sway_force_prime,
        ] = x;
        for (name, value) in inputs.into_iter().zip(x) {
            fmu.set(name, value);
        }
        let expected = [model.command(&u), model.gains().c[0], model.gains().c[5]];
        assert_eq!(fmu.reals(&outputs), expected);
        fmu.step(t, 0.5);
        model.step(&u, 0.5).unwrap();
    }
    assert_eq!(fmu.terminate(), fmi2_export::fmi2::fmi2OK);
}

#[test]
fn value_references_are_unchanged() {
    let fmu = fmu();
    assert_eq!(fmu.vr("heading"), 24);
    assert_eq!(fmu.vr("rudder_command"), 38);
    assert_eq!(fmu.vr("gain_yaw_moment"), 45);
}
