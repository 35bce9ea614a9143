//! ContainerShip through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::hull::container_ship` bit for bit, by
//! variable name.

use container_ship_fmu::ContainerShipFmu;
use fmi2_export::fmi2::{fmi2Error, fmi2OK};
use fmi2_export::testing::Harness;
use models::hull::container_ship::{
    ContainerShip, ContainerShipInputs, ContainerShipOutputs, LinearContainerShip,
    LinearContainerShipInputs,
};

fmi2_export::fmu_tests!(ContainerShipFmu);

/// An instance in Initialization Mode at t = 0.
fn initializing() -> Harness<ContainerShipFmu> {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu
}

const OUTPUTS: [&str; 16] = [
    "surge_velocity",
    "sway_velocity",
    "yaw_rate",
    "roll_rate",
    "roll",
    "heading",
    "heading_wrapped",
    "x",
    "y",
    "rudder_angle",
    "shaft_speed",
    "speed",
    "drift_angle",
    "sway_velocity_prime",
    "yaw_rate_prime",
    "roll_rate_prime",
];

fn expected(o: &ContainerShipOutputs) -> Vec<f64> {
    vec![
        o.u,
        o.v,
        o.r,
        o.p,
        o.roll,
        o.heading,
        o.heading_wrapped,
        o.x,
        o.y,
        o.rudder,
        o.shaft_rpm,
        o.speed,
        o.drift_angle,
        o.v_prime,
        o.r_prime,
        o.p_prime,
    ]
}

#[test]
fn exported_api_reproduces_the_nonlinear_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model = ContainerShip::at_equilibrium(80.0).unwrap();
    let h = 0.1;
    for k in 0..1000 {
        let t = k as f64 * h;
        let inputs = ContainerShipInputs {
            rudder_command: 0.3 * (0.05 * t).sin(),
            shaft_command_rpm: 80.0 - 10.0 * (0.01 * t).sin(),
            sway_force_ext: 1e5 * (0.1 * t).sin(),
            roll_moment_ext: 2e6 * (0.5 * t).sin(),
            yaw_moment_ext: -1e6 * (0.02 * t).cos(),
        };
        fmu.set("rudder_command", inputs.rudder_command)
            .set("shaft_speed_command", inputs.shaft_command_rpm)
            .set("sway_force", inputs.sway_force_ext)
            .set("roll_moment", inputs.roll_moment_ext)
            .set("yaw_moment", inputs.yaw_moment_ext)
            .step(t, h);
        model.step(&inputs, h);
        assert_eq!(fmu.reals(&OUTPUTS), expected(&model.outputs()), "step {k}");
    }
    assert!(model.outputs().heading.abs() > 0.1);
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn exported_api_reproduces_the_linear_model() {
    let mut fmu = initializing();
    fmu.set("variant", 2);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    let mut model = LinearContainerShip::mss_default();
    let h = 0.25;
    for k in 0..400 {
        let t = k as f64 * h;
        let rudder_command = 0.2 * (0.03 * t).sin();
        fmu.set("rudder_command", rudder_command).step(t, h);
        model.step(&LinearContainerShipInputs { rudder_command }, h);
        assert_eq!(fmu.reals(&OUTPUTS), expected(&model.outputs()), "step {k}");
    }
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn bad_parameter_is_refused() {
    let mut fmu = initializing();
    fmu.set("initial_shaft_speed", -1.0);
    assert_eq!(fmu.exit_initialization(), fmi2Error);
}
