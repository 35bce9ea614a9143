//! SteeringGear through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::steering_gear` by variable name.

use models::steering_gear::{SteeringGear, SteeringGearParams};

fmi2_export::fmu_tests!(steering_gear_fmu::SteeringGearFmu);

#[test]
fn exported_api_reproduces_the_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model = SteeringGear::new(SteeringGearParams::rrs_klugt1987(), 0.0).unwrap();
    let outputs = [
        "rudder_angle",
        "rudder_rate",
        "limited_command",
        "rate_saturated_time",
    ];
    for k in 0..500 {
        let t = k as f64 * 0.02;
        let cmd = 0.6 * (1.3 * t).sin();
        fmu.set("rudder_command", cmd).step(t, 0.02);
        model.step(cmd, 0.02);
        let expected = [
            model.angle(),
            model.rate(),
            model.limited_command(),
            model.rate_saturated_time(),
        ];
        assert_eq!(fmu.reals(&outputs), expected);
    }
    assert_eq!(fmu.terminate(), fmi2_export::fmi2::fmi2OK);
}
