//! Current through the `fmi2*` symbols its crate exports, as a C importer calls them: the checks
//! every FMU runs, and the FMU against `models::disturbances::current` by variable name, with a
//! state snapshot restored.

use fmi2_export::fmi2::fmi2OK;
use models::disturbances::current::{Current, CurrentParams};

fmi2_export::fmu_tests!(current_fmu::CurrentFmu);

const OUTPUTS: [&str; 4] = ["n_prime", "y_prime", "current_sway", "bias_surge"];

fn heading(t: f64) -> f64 {
    (0.01 * t).sin()
}

#[test]
fn exported_api_reproduces_the_model_and_restores_states() {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu.set("seed", 77i32);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    let params = CurrentParams {
        seed: 77,
        ..CurrentParams::default()
    };
    let mut model = Current::new(params, 0.0).unwrap();
    let h = 0.3;
    fmu.check_replay(400, 200, |fmu, k, replaying| {
        let t = k as f64 * h;
        fmu.set("heading", heading(t)).step(t, h);
        let v = fmu.reals(&OUTPUTS);
        if !replaying {
            model.set_heading(heading(t));
            model.advance_to(t + h);
            let expected = [
                model.disturbance()[0],
                model.disturbance()[1],
                model.current_body()[1],
                model.bias_body()[0],
            ];
            assert_eq!(v, expected);
        }
        v
    });
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn model_identifier_is_declared() {
    let xml = fmi2_export::xml::model_description::<current_fmu::CurrentFmu>();
    assert!(xml.contains(r#"modelIdentifier="Current""#));
}
