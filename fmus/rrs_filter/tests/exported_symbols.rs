//! RrsFilter through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::observers::rrs_filter` by variable name.

use models::observers::rrs_filter::{
    RollFilterParams, RrsFilter, RrsFilterInputs, SpeedFilterParams, YawFilterParams,
};

fmi2_export::fmu_tests!(rrs_filter_fmu::RrsFilterFmu);

#[test]
fn exported_api_reproduces_the_model() {
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model = RrsFilter::new(
        RollFilterParams::table_2_4(11.0, 10.0, 0.001),
        YawFilterParams::realised(11.0),
        SpeedFilterParams::realised(),
        0.1,
        11.0,
    )
    .unwrap();
    let outputs = [
        "roll_estimate",
        "heading_estimate",
        "yaw_k1",
        "speed_estimate",
    ];
    let h = 0.25;
    for k in 0..400 {
        let t = k as f64 * h;
        let inp = RrsFilterInputs {
            roll: 0.1 * (0.63 * t).sin() + 0.02,
            heading: 0.05 * (0.02 * t).sin() + 0.01 * (0.9 * t).sin(),
            speed: 11.0 + (0.01 * t).sin(),
            roll_rudder: 0.01 * (0.63 * t).cos(),
            course_rudder: 0.02,
        };
        fmu.set("roll_measured", inp.roll)
            .set("heading_measured", inp.heading)
            .set("speed_measured", inp.speed)
            .set("roll_rudder", inp.roll_rudder)
            .set("course_rudder", inp.course_rudder)
            .step(t, h);
        model.step(&inp, h);
        let expected = [
            model.roll.state()[0],
            model.yaw.state()[0],
            model.yaw.gains()[0],
            model.speed.estimate(),
        ];
        assert_eq!(fmu.reals(&outputs), expected);
    }
    assert_eq!(fmu.terminate(), fmi2_export::fmi2::fmi2OK);
}
