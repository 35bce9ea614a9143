//! ParameterEkf through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::observers::parameter_ekf` by variable
//! name.

use fmi2_export::fmi2::fmi2OK;
use fmi2_export::testing::Harness;
use models::observers::parameter_ekf::ParameterEkf;
use parameter_ekf_fmu::ParameterEkfFmu;

fmi2_export::fmu_tests!(ParameterEkfFmu);

const INPUTS: [&str; 5] = [
    "surge_velocity_measured",
    "sway_velocity_measured",
    "yaw_rate_measured",
    "shaft_speed_measured",
    "rudder_angle",
];

fn inputs(t: f64) -> [f64; 5] {
    let s = (0.02 * t).sin();
    [
        5.0,
        0.3 * s,
        -0.004 * (0.02 * t).cos(),
        80.0,
        0.17 * s.signum(),
    ]
}

/// One step of the FMU and the model from `t` over 0.5 s with `inputs(t)`, then the outputs
/// compared.
fn step_both(fmu: &mut Harness<ParameterEkfFmu>, model: &mut ParameterEkf, t: f64) {
    let u = inputs(t);
    for (name, value) in INPUTS.iter().zip(u) {
        fmu.set(name, value);
    }
    fmu.step(t, 0.5);
    model.step(t, 0.5, [u[0], u[1], u[2], u[3]], u[4]);
    let outputs = [
        "sway_velocity_estimate",
        "neg_y_v_estimate",
        "mxg_minus_n_r_mean",
        "nomoto_gain_prime",
    ];
    let expected = [
        model.dimensional_states()[1],
        model.coefficients()[0],
        model.averaged_coefficients()[3],
        model.identified_nomoto().1,
    ];
    assert_eq!(fmu.reals(&outputs), expected);
}

#[test]
fn exported_api_reproduces_the_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model = ParameterEkf::new(parameter_ekf_fmu::default_params(), 0.0).unwrap();
    let mut snapshot = None;
    for k in 0..400 {
        step_both(&mut fmu, &mut model, k as f64 * 0.5);
        if k == 199 {
            snapshot = Some((fmu.get_state(), model.clone()));
        }
    }
    assert_eq!(model.updates(), 200);
    // Restore the FMU state and replay: bit-identical.
    let (state, mut model) = snapshot.unwrap();
    assert_eq!(fmu.set_state(state), fmi2OK);
    for k in 200..400 {
        step_both(&mut fmu, &mut model, k as f64 * 0.5);
    }
    fmu.free_state(state);
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn outputs_depend_on_the_state_only() {
    let xml = fmi2_export::xml::model_description::<ParameterEkfFmu>();
    assert!(xml.contains(r#"dependencies="""#));
}
