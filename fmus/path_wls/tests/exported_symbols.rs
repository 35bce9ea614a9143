//! PathWlsEstimator through the `fmi2*` symbols its crate exports, as a C importer calls them:
//! the checks every FMU runs, and the value references importers use.

fmi2_export::fmu_tests!(path_wls_fmu::PathWlsFmu);

#[test]
fn value_references_are_unchanged() {
    let fmu = fmu();
    assert_eq!(fmu.vr("heading"), 12);
    assert_eq!(fmu.vr("f23_estimate"), 22);
    assert_eq!(fmu.vr("loading"), 35);
}
