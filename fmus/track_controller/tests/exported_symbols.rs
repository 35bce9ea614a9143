//! Checks the variable table and the generated model description.

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(track_controller_fmu::TrackControllerFmu::variables())
        .unwrap();
    let xml = fmi2_export::xml::model_description::<track_controller_fmu::TrackControllerFmu>();
    assert!(xml.contains(r#"name="cross_track" valueReference="20""#));
    assert!(xml.contains(r#"name="rudder_command" valueReference="22""#));
}
