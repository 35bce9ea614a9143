//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for PathEstimator:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`.

use fmi2_export::testing::Outcome::*;

fmi2_export::probe_cases!(path_estimator_fmu::PathEstimatorFmu);

/// bigstep_all.txt: one fmi2DoStep of 1e9 s.
#[test]
fn one_step_of_1e9_s_ends() {
    probe(&[], &[], 1000000000.0, 1, Finite);
}

/// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
#[test]
fn extreme_parameters_give_an_error_not_nan() {
    probe(
        &[],
        &[("sigma_heading", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("sigma_yaw_rate", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("sigma_drift_angle", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("sigma_cross_track", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("q_n", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("q_y", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("ship_length", 1e-300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("ship_speed", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("yaw_rate", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("yaw_rate", -1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("drift_angle", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("drift_angle", -1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("rudder_angle", 1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("rudder_angle", -1e+300)],
        0.2349,
        50,
        Error("output \"f22_estimate\" = NaN is not a finite number"),
    );
}
