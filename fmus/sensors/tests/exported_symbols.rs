//! Sensors through the `fmi2*` symbols its crate exports, as a C importer calls them: the checks
//! every FMU runs, and the FMU against `models::sensors` by variable name, with a state snapshot
//! restored.

use fmi2_export::fmi2::fmi2OK;
use fmi2_export::testing::Harness;
use models::sensors::{SensorParams, Sensors, CHANNELS, CHANNEL_NAMES};

fmi2_export::fmu_tests!(sensors_fmu::SensorsFmu);

fn truth(t: f64) -> [f64; CHANNELS] {
    std::array::from_fn(|i| (i as f64 + 1.0) * (0.1 * t + 0.05 * i as f64).sin())
}

/// Sets every channel's true-value input by name.
fn set_inputs(fmu: &mut Harness<sensors_fmu::SensorsFmu>, x: [f64; CHANNELS]) {
    for ((name, _), x) in CHANNEL_NAMES.iter().zip(x) {
        fmu.set(name, x);
    }
}

#[test]
fn exported_api_reproduces_the_model_and_restores_states() {
    let measured = CHANNEL_NAMES.map(|(n, _)| format!("{n}_measured"));
    let outs: Vec<&str> = measured.iter().map(String::as_str).collect();
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu.set("seed", 8i32).set("roll_sigma", 0.3);
    let x0 = truth(0.0);
    set_inputs(&mut fmu, x0);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    let mut p = SensorParams {
        seed: 8,
        ..SensorParams::default()
    };
    p.channels[2].sigma = 0.3;
    let mut model = Sensors::new(p, 0.0, x0).unwrap();
    let h = 0.1;
    fmu.check_replay(300, 150, |fmu, k, replaying| {
        let t = k as f64 * h;
        let x = truth(t);
        set_inputs(fmu, x);
        let before_step = fmu.reals(&outs);
        if !replaying {
            model.set_inputs(x);
            let expected: Vec<f64> = (0..CHANNELS).map(|i| model.measured(i)).collect();
            assert_eq!(before_step, expected);
        }
        fmu.step(t, h);
        let v = fmu.reals(&outs);
        if !replaying {
            model.advance_to(t + h);
            let expected: Vec<f64> = (0..CHANNELS).map(|i| model.measured(i)).collect();
            assert_eq!(v, expected);
        }
        v
    });
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn model_identifier_and_measured_outputs_are_declared() {
    let xml = fmi2_export::xml::model_description::<sensors_fmu::SensorsFmu>();
    assert!(xml.contains(r#"name="north_measured""#));
    assert!(xml.contains(r#"modelIdentifier="Sensors""#));
}
