//! Checks the variable table and the generated model description.

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(heading_autopilot_fmu::HeadingAutopilotFmu::variables())
        .unwrap();
    let xml = fmi2_export::xml::model_description::<heading_autopilot_fmu::HeadingAutopilotFmu>();
    assert!(xml.contains(r#"name="heading" valueReference="14""#));
    assert!(xml.contains(r#"name="rudder_command" valueReference="16""#));
}
