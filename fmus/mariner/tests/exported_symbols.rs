//! Mariner through the `fmi2*` symbols its crate exports, as a C importer calls them: the checks
//! every FMU runs, and the FMU against `models::hull::mariner` bit for bit, by variable name.

use fmi2_export::fmi2::{fmi2Error, fmi2OK};
use fmi2_export::testing::Harness;
use mariner_fmu::MarinerFmu;
use models::hull::mariner::{Mariner, MarinerInputs, MarinerOutputs, U0_DEFAULT};

fmi2_export::fmu_tests!(MarinerFmu);

const OUTPUTS: [&str; 14] = [
    "surge_velocity",
    "surge_perturbation",
    "sway_velocity",
    "yaw_rate",
    "heading",
    "heading_wrapped",
    "x",
    "y",
    "rudder_angle",
    "speed",
    "drift_angle",
    "surge_perturbation_prime",
    "sway_velocity_prime",
    "yaw_rate_prime",
];

fn expected(o: &MarinerOutputs) -> Vec<f64> {
    vec![
        o.u,
        o.delta_u,
        o.v,
        o.r,
        o.heading,
        o.heading_wrapped,
        o.x,
        o.y,
        o.rudder,
        o.speed,
        o.drift_angle,
        o.u_prime,
        o.v_prime,
        o.r_prime,
    ]
}

/// An instance in Initialization Mode at t = 0.
fn initializing() -> Harness<MarinerFmu> {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu
}

/// Steps the FMU and `model` with the same rudder command and compares every output.
fn run(fmu: &mut Harness<MarinerFmu>, mut model: Mariner, h: f64, steps: usize) -> Mariner {
    for k in 0..steps {
        let t = k as f64 * h;
        let rudder_command = 0.5 * (0.04 * t).sin();
        fmu.set("rudder_command", rudder_command).step(t, h);
        model.step(&MarinerInputs { rudder_command }, h);
        assert_eq!(fmu.reals(&OUTPUTS), expected(&model.outputs()), "step {k}");
    }
    model
}

#[test]
fn exported_api_reproduces_the_trimmed_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    assert_eq!(
        fmu.real("trim_rudder_command"),
        Mariner::trim_input(U0_DEFAULT)
    );
    let model = run(&mut fmu, Mariner::trimmed(U0_DEFAULT).unwrap(), 0.1, 1500);
    assert!(model.outputs().heading.abs() > 0.1);
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn exported_api_reproduces_the_mss_start() {
    let mut fmu = initializing();
    fmu.set("trimmed", false);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    run(&mut fmu, Mariner::mss_default(), 0.3, 500);
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn bad_parameter_is_refused() {
    let mut fmu = initializing();
    assert_eq!(fmu.try_set("rudder_max", -1.0), fmi2Error);
    assert_eq!(fmu.try_set("max_substep", 0.0), fmi2OK);
    assert_eq!(fmu.exit_initialization(), fmi2Error);
}
