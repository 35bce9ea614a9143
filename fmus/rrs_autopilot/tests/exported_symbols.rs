//! RrsAutopilot through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::controllers::rrs` by variable name.

use models::controllers::rrs::{RrsAutopilot, RrsAutopilotParams, RrsInputs};

fmi2_export::fmu_tests!(rrs_autopilot_fmu::RrsAutopilotFmu);

#[test]
fn exported_api_reproduces_the_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model = RrsAutopilot::new(RrsAutopilotParams::default()).unwrap();
    let mut u = RrsInputs {
        speed: 11.0,
        ..Default::default()
    };
    let inputs = [
        "roll",
        "roll_rate",
        "sway_rudder",
        "heading_error",
        "yaw_rate",
        "yaw_offset",
        "speed",
    ];
    let outputs = ["rudder_command", "attenuation", "roll_gain_1"];
    for k in 0..600 {
        let t = k as f64 * 0.1;
        let x = [
            0.1 * (0.63 * t).sin(),
            0.063 * (0.63 * t).cos(),
            0.01 * (0.3 * t).sin(),
            0.02,
            0.001,
            0.0,
            11.0 - 0.01 * t,
        ];
        [
            u.roll,
            u.roll_rate,
            u.sway_rudder,
            u.heading_error,
            u.yaw_rate,
            u.yaw_offset,
            u.speed,
        ] = x;
        for (name, value) in inputs.into_iter().zip(x) {
            fmu.set(name, value);
        }
        let o = model.outputs(&u);
        let expected = [
            o.rudder_command,
            o.attenuation,
            model.roll_gains(u.speed)[0],
        ];
        assert_eq!(fmu.reals(&outputs), expected);
        fmu.step(t, 0.1);
        model.step(&u, 0.1);
    }
    assert_eq!(fmu.terminate(), fmi2_export::fmi2::fmi2OK);
}

#[test]
fn value_references_are_unchanged() {
    let fmu = fmu();
    assert_eq!(fmu.vr("roll"), 35);
    assert_eq!(fmu.vr("rudder_command"), 44);
    assert_eq!(fmu.vr("roll_gain_1"), 50);
}
