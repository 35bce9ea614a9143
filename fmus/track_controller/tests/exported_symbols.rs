//! TrackController through the `fmi2*` symbols its crate exports: the checks every FMU runs, and
//! the value references that system files use.

fmi2_export::fmu_tests!(track_controller_fmu::TrackControllerFmu);

#[test]
fn value_references_are_pinned() {
    let fmu = fmu();
    assert_eq!(fmu.vr("cross_track"), 20);
    assert_eq!(fmu.vr("rudder_command"), 22);
}
