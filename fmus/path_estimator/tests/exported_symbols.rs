//! PathEstimator through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the value references importers use.

fmi2_export::fmu_tests!(path_estimator_fmu::PathEstimatorFmu);

#[test]
fn value_references_are_unchanged() {
    let fmu = fmu();
    assert_eq!(fmu.vr("heading"), 13);
    assert_eq!(fmu.vr("f23_estimate"), 19);
}

#[test]
fn interval_is_range_checked_and_read_back() {
    let mut fmu = fmu();
    fmu.setup(0.0, None);
    fmu.enter_initialization();
    assert_eq!(fmu.try_set("interval", 1), fmi2_export::fmi2::fmi2Error);
    assert!(fmu.log().contains("\"interval\" = 1 refused"));
    assert_eq!(fmu.set("interval", 5).get::<i32>("interval"), 5);
    assert_eq!(fmu.exit_initialization(), fmi2_export::fmi2::fmi2OK);
    assert_eq!(fmu.get::<i32>("interval"), 5);
}
