//! NomotoShip through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::hull::nomoto` bit for bit, by variable
//! name.

use fmi2_export::fmi2::{fmi2Error, fmi2OK};
use fmi2_export::testing::Harness;
use models::hull::nomoto::{NomotoInputs, NomotoOutputs, NomotoShip};
use nomoto_ship_fmu::NomotoShipFmu;

fmi2_export::fmu_tests!(NomotoShipFmu);

/// An instance in Initialization Mode at t = 0.
fn initializing() -> Harness<NomotoShipFmu> {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu
}

const OUTPUTS: [&str; 10] = [
    "sway_velocity",
    "sway_velocity_prime",
    "yaw_rate",
    "yaw_rate_prime",
    "heading",
    "heading_wrapped",
    "x",
    "y",
    "speed_over_ground",
    "time_prime",
];

fn expected(o: &NomotoOutputs) -> Vec<f64> {
    vec![
        o.sway_velocity,
        o.v_prime,
        o.yaw_rate,
        o.r_prime,
        o.heading,
        o.heading_wrapped,
        o.x,
        o.y,
        o.speed_over_ground,
        o.time_prime,
    ]
}

fn check(model_preset: i32, mut model: NomotoShip, h: f64) {
    let mut fmu = initializing();
    fmu.set("model", model_preset);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    for k in 0..1000 {
        let t = k as f64 * h;
        let inputs = NomotoInputs {
            rudder: 0.1 * (0.05 * t).sin(),
            current_speed: 0.5,
            current_direction: 1.0 + 0.001 * t,
            yaw_disturbance: 0.02 * (0.4 * t).cos(),
        };
        fmu.set("rudder_angle", inputs.rudder)
            .set("current_speed", inputs.current_speed)
            .set("current_direction", inputs.current_direction)
            .set("yaw_disturbance", inputs.yaw_disturbance)
            .step(t, h);
        model.step(&inputs, h);
        assert_eq!(
            fmu.reals(&OUTPUTS),
            expected(&model.outputs()),
            "model {model_preset} step {k}"
        );
    }
    assert!(model.outputs().heading.abs() > 1e-3);
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn exported_api_reproduces_both_models() {
    check(1, NomotoShip::ddg51(), 0.1);
    check(2, NomotoShip::esso_osaka(), 0.5);
}

#[test]
fn bad_parameter_is_refused() {
    let mut fmu = initializing();
    fmu.set("t_prime", 0.0);
    assert_eq!(fmu.exit_initialization(), fmi2Error);
}
