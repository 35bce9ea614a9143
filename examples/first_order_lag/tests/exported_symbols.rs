//! FirstOrderLag through the symbols its crate exports: the checks every FMU runs, and the step
//! response against the closed form y(t) = K u (1 - exp(-t/T)).

fmi2_export::fmu_tests!(first_order_lag_fmu::FirstOrderLag);

#[test]
fn step_response_is_the_closed_form() {
    let mut fmu = fmu();
    fmu.set("gain", 3.0).set("time_constant", 0.5);
    fmu.initialize(0.0).set("u", 2.0);
    let h = 0.01;
    for k in 0..300 {
        fmu.step(k as f64 * h, h);
        let t = (k + 1) as f64 * h;
        let exact = 3.0 * 2.0 * (1.0 - (-t / 0.5).exp());
        assert!((fmu.real("y") - exact).abs() < 1e-12, "t = {t}");
    }
}

#[test]
fn a_time_constant_of_zero_is_refused_with_its_name() {
    let mut fmu = fmu();
    fmu.set("time_constant", 0.0);
    assert_eq!(fmu.setup(0.0, None), fmi2_export::fmi2::fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2_export::fmi2::fmi2OK);
    assert_eq!(fmu.exit_initialization(), fmi2_export::fmi2::fmi2Error);
    assert!(
        fmu.log().contains("time_constant = 0 must be > 0"),
        "{}",
        fmu.log().last()
    );
}
