//! DpController through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::controllers::dp` by variable name.

use fmi2_export::fmi2::fmi2OK;
use models::controllers::dp::{DpController, DpInputs, DpParams};

fmi2_export::fmu_tests!(dp_controller_fmu::DpControllerFmu);

/// The inputs in the order eta, nu, setpoint.
const INPUTS: &[&str] = dp_controller_fmu::TAU_DEPS;
const OUTPUTS: [&str; 3] = ["tau_surge", "tau_sway", "tau_yaw"];

#[test]
fn exported_api_reproduces_the_model() {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    let amp = 1000.0;
    fmu.set("test_amplitude_surge", amp);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    let mut params = DpParams::northern_clipper();
    params.test_amplitude[0] = amp;
    let mut model = DpController::new(params, 0.0).unwrap();
    for k in 0..300 {
        let t = k as f64 * 0.5;
        let u = DpInputs {
            eta: [
                3.0 * (0.02 * t).sin(),
                -2.0 + 0.01 * t,
                0.3 * (0.01 * t).cos(),
            ],
            nu: [0.1 * (0.03 * t).cos(), 0.02, 1e-3 * (0.05 * t).sin()],
            setpoint: [1.0, -1.0, 0.2],
        };
        let values = u.eta.iter().chain(&u.nu).chain(&u.setpoint);
        for (name, &x) in INPUTS.iter().zip(values) {
            fmu.set(name, x);
        }
        assert_eq!(fmu.reals(&OUTPUTS), model.tau(&u), "feedthrough at t = {t}");
        fmu.step(t, 0.5);
        model.step(&u, 0.5);
        model.set_time((k + 1) as f64 * 0.5);
        assert_eq!(
            fmu.reals(&OUTPUTS),
            model.tau(&u),
            "after the step from t = {t}"
        );
    }
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn value_references_are_pinned() {
    let fmu = fmu();
    assert_eq!(fmu.vr("test_amplitude_surge"), 11);
    assert_eq!(fmu.vr("north_estimate"), 17);
    assert_eq!(fmu.vr("heading_setpoint"), 25);
    assert_eq!(fmu.vr("tau_surge"), 26);
}
