//! Wind through the `fmi2*` symbols its crate exports, as a C importer calls them: the checks
//! every FMU runs, and the FMU against `models::disturbances::wind` by variable name, with a
//! state snapshot restored.

use fmi2_export::fmi2::fmi2OK;
use models::disturbances::wind::{Wind, WindParams};

fmi2_export::fmu_tests!(wind_fmu::WindFmu);

const OUTPUTS: [&str; 3] = [
    "true_wind_speed",
    "relative_wind_speed",
    "relative_wind_angle",
];

/// Ship speed and heading at `t`.
fn inputs(t: f64) -> [f64; 2] {
    std::array::from_fn(|i| (i as f64 + 1.0) * (0.01 * t).sin())
}

#[test]
fn exported_api_reproduces_the_model_and_restores_states() {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu.set("seed", 77i32);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    let params = WindParams {
        seed: 77,
        ..WindParams::default()
    };
    let mut model = Wind::new(params, 0.0).unwrap();
    let h = 0.3;
    fmu.check_replay(400, 200, |fmu, k, replaying| {
        let t = k as f64 * h;
        let u = inputs(t);
        fmu.set("ship_speed", u[0]).set("heading", u[1]).step(t, h);
        let v = fmu.reals(&OUTPUTS);
        if !replaying {
            model.set_inputs(u[0], u[1]);
            model.advance_to(t + h);
            let expected = [model.true_speed(), model.relative().0, model.relative().1];
            assert_eq!(v, expected);
        }
        v
    });
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn model_identifier_is_declared() {
    let xml = fmi2_export::xml::model_description::<wind_fmu::WindFmu>();
    assert!(xml.contains(r#"modelIdentifier="Wind""#));
}
