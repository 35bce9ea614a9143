//! PassiveObserver through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::observers::passive_observer` by variable
//! name.

use models::observers::passive_observer::{PassiveObserver, PassiveObserverParams};

fmi2_export::fmu_tests!(passive_observer_fmu::PassiveObserverFmu);

#[test]
fn exported_api_reproduces_the_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model =
        PassiveObserver::new(PassiveObserverParams::northern_clipper(), [0.0; 3]).unwrap();
    let inputs = [
        "north_measured",
        "east_measured",
        "heading_measured",
        "tau_surge",
        "tau_sway",
        "tau_yaw",
    ];
    let outputs = [
        "north_estimate",
        "heading_estimate",
        "sway_velocity_estimate",
        "bias_north_estimate",
    ];
    let k1 = fmu.real("k1_surge");
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
        for (name, value) in inputs.iter().zip(u) {
            fmu.set(name, value);
        }
        fmu.step(t, 1.0);
        model.step([u[0], u[1], u[2]], [u[3], u[4], u[5]], 1.0);
        let expected = [
            model.eta()[0],
            model.eta()[2],
            model.nu()[1],
            model.bias_force()[0],
        ];
        assert_eq!(fmu.reals(&outputs), expected);
    }
    assert_eq!(fmu.terminate(), fmi2_export::fmi2::fmi2OK);
}
