//! TokyoMaru through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::hull::tokyo_maru` bit for bit, by variable
//! name.

use fmi2_export::fmi2::{fmi2Error, fmi2OK};
use fmi2_export::testing::Harness;
use models::hull::tokyo_maru::{
    TokyoMaru, TokyoMaruInputs, TokyoMaruIntegration, TokyoMaruOutputs,
};
use tokyo_maru_fmu::TokyoMaruFmu;

fmi2_export::fmu_tests!(TokyoMaruFmu);

const OUTPUTS: [&str; 12] = [
    "heading",
    "heading_wrapped",
    "yaw_rate",
    "yaw_rate_prime",
    "drift_angle",
    "sway_velocity",
    "cross_track",
    "cross_track_prime",
    "x",
    "y",
    "rudder_angle_actual",
    "time_prime",
];

fn expected(o: &TokyoMaruOutputs) -> Vec<f64> {
    vec![
        o.heading,
        o.heading_wrapped,
        o.yaw_rate,
        o.yaw_rate_prime,
        o.drift_angle,
        o.sway_velocity,
        o.cross_track,
        o.cross_track_prime,
        o.x,
        o.y,
        o.rudder,
        o.time_prime,
    ]
}

/// Runs `steps` steps from `k0` with the same inputs into the FMU and the model.
fn run(
    fmu: &mut Harness<TokyoMaruFmu>,
    model: &mut TokyoMaru,
    gear: bool,
    k0: usize,
    steps: usize,
    h: f64,
) {
    let rudder = if gear {
        "rudder_command"
    } else {
        "rudder_angle"
    };
    for k in k0..k0 + steps {
        let t = k as f64 * h;
        let inputs = TokyoMaruInputs {
            rudder: 0.1 * (0.02 * t).sin(),
            yaw_moment_prime: 1e-4 * (0.01 * t).sin(),
            sway_force_prime: 2e-3 * (0.015 * t).cos(),
            current_lateral: 0.2 * (0.005 * t).cos(),
        };
        fmu.set(rudder, inputs.rudder)
            .set("yaw_moment_prime", inputs.yaw_moment_prime)
            .set("sway_force_prime", inputs.sway_force_prime)
            .set("current_lateral", inputs.current_lateral)
            .step(t, h);
        model.step(&inputs, h);
        assert_eq!(fmu.reals(&OUTPUTS), expected(&model.outputs()), "step {k}");
    }
}

#[test]
fn exported_api_reproduces_the_model_and_a_depth_change() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model = TokyoMaru::design_depth();
    run(&mut fmu, &mut model, false, 0, 300, 1.0);
    // tunable H/T in step mode
    let ht = 1.4;
    fmu.set("depth_ratio", ht);
    model.depth_ratio = ht;
    run(&mut fmu, &mut model, false, 300, 300, 1.0);
    fmu.set("deep_water", true);
    model.depth_ratio = f64::INFINITY;
    run(&mut fmu, &mut model, false, 600, 300, 1.0);
    assert!(model.outputs().cross_track.abs() > 1.0);
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn exported_api_reproduces_the_internal_gear_and_euler() {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu.set("internal_steering_gear", true)
        .set("integration", 2);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    let mut model = TokyoMaru::design_depth();
    model.internal_steering_gear = true;
    model.integration = TokyoMaruIntegration::Euler {
        max_substep_prime: 0.005,
    };
    run(&mut fmu, &mut model, true, 0, 400, 0.5);
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn bad_depth_ratio_in_step_mode_is_refused_and_the_old_value_kept() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    assert_eq!(fmu.try_set("depth_ratio", 0.0), fmi2Error);
    assert_eq!(fmu.real("depth_ratio"), 1.89);
}
