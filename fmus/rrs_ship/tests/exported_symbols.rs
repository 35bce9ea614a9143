//! RrsShip through the `fmi2*` symbols its crate exports, as a C importer calls them: the checks
//! every FMU runs, and the FMU against `models::hull::rrs_ship` bit for bit, by variable name.

use fmi2_export::fmi2::fmi2OK;
use fmi2_export::testing::Harness;
use models::hull::rrs_ship::{RrsShip, RrsShipInputs, RrsShipOutputs};
use rrs_ship_fmu::RrsShipFmu;

fmi2_export::fmu_tests!(RrsShipFmu);

/// An instance of `model` (1, 2 or 3), initialized at t = 0.
fn initialized(model: i32) -> Harness<RrsShipFmu> {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu.set("model", model);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    fmu
}

const OUTPUTS: [&str; 11] = [
    "roll",
    "roll_rate",
    "sway",
    "yaw_rate",
    "heading",
    "heading_wrapped",
    "x",
    "y",
    "wave_sway",
    "wave_yaw",
    "wave_roll",
];

fn expected(o: &RrsShipOutputs) -> Vec<f64> {
    vec![
        o.roll,
        o.roll_rate,
        o.sway,
        o.yaw_rate,
        o.heading,
        o.heading_wrapped,
        o.x,
        o.y,
        o.wave_sway,
        o.wave_yaw,
        o.wave_roll,
    ]
}

fn check(model_preset: i32, mut model: RrsShip, h: f64) {
    let mut fmu = initialized(model_preset);
    for k in 0..1000 {
        let t = k as f64 * h;
        let inputs = RrsShipInputs {
            rudder: 0.1 * (0.3 * t).sin(),
            speed: 6.0 + 0.05 * t,
            roll_disturbance: 0.01 * (0.2 * t).sin(),
            yaw_disturbance: 0.005 * (0.1 * t).cos(),
            wave_elevation: 0.5 * (0.64 * t).sin(),
        };
        fmu.set("rudder_angle", inputs.rudder)
            .set("speed", inputs.speed)
            .set("roll_disturbance", inputs.roll_disturbance)
            .set("yaw_disturbance", inputs.yaw_disturbance)
            .set("wave_elevation", inputs.wave_elevation)
            .step(t, h);
        model.step(&inputs, h);
        assert_eq!(
            fmu.reals(&OUTPUTS),
            expected(&model.outputs()),
            "model {model_preset} step {k}"
        );
    }
    assert!(model.outputs().roll.abs() > 1e-4);
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn exported_api_reproduces_the_three_models() {
    check(1, RrsShip::simulation_22kn(), 0.1);
    check(2, RrsShip::control_model(), 0.05);
    check(3, RrsShip::control_model_table_2_5(), 0.2);
}

/// The second (wind) disturbance channel adds to the first: w_phi = 0.01 + 0.02 through both
/// inputs gives bit-for-bit the same motion as 0.03 through roll_disturbance alone (and
/// likewise for yaw).
#[test]
fn wind_disturbance_inputs_add_to_the_first_channel() {
    fn run(inputs: &[(&str, f64)]) -> Vec<f64> {
        let mut fmu = initialized(2);
        for &(name, value) in inputs {
            fmu.set(name, value);
        }
        for k in 0..200 {
            fmu.step(k as f64 * 0.1, 0.1);
        }
        let v = fmu.reals(&OUTPUTS);
        assert_eq!(fmu.terminate(), fmi2OK);
        v
    }
    let a = run(&[
        ("roll_disturbance", 0.01),
        ("wind_roll_disturbance", 0.02),
        ("yaw_disturbance", 0.001),
        ("wind_yaw_disturbance", 0.002),
    ]);
    let b = run(&[("roll_disturbance", 0.03), ("yaw_disturbance", 0.003)]);
    assert!(a[0].abs() > 1e-3, "the disturbance rolls the ship");
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-15 * y.abs().max(1.0), "{x} vs {y}");
    }
}
