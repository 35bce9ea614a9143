//! Checks the variable table and the generated model description.

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(path_estimator_fmu::PathEstimatorFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<path_estimator_fmu::PathEstimatorFmu>();
    assert!(xml.contains(r#"name="heading" valueReference="13""#));
    assert!(xml.contains(r#"name="f23_estimate" valueReference="19""#));
}
