//! Checks the variable table and the generated model description.

#[test]
fn variable_table_passes_the_layer_checks() {
    use fmi2_export::FmuModel;
    fmi2_export::variables::check_table(path_wls_fmu::PathWlsFmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<path_wls_fmu::PathWlsFmu>();
    assert!(xml.contains(r#"name="heading" valueReference="12""#));
    assert!(xml.contains(r#"name="f23_estimate" valueReference="22""#));
    assert!(xml.contains(r#"name="loading" valueReference="35""#));
}
