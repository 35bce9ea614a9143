//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for PathEstimator:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `path_estimator::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    path_estimator = path_estimator_fmu::PathEstimatorFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Finite,
    }

    /// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
    extreme_parameters_give_an_error_not_nan: probe(h = 0.2349, steps = 50) {
        sigma_heading_1e300: [("sigma_heading", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        sigma_yaw_rate_1e300: [("sigma_yaw_rate", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        sigma_drift_angle_1e300: [("sigma_drift_angle", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        sigma_cross_track_1e300: [("sigma_cross_track", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        q_n_1e300: [("q_n", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        q_y_1e300: [("q_y", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        ship_length_1e_neg300: [("ship_length", 1e-300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        ship_speed_1e300: [("ship_speed", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        yaw_rate_1e300: [("yaw_rate", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        yaw_rate_neg_1e300: [("yaw_rate", -1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        drift_angle_1e300: [("drift_angle", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        drift_angle_neg_1e300: [("drift_angle", -1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        rudder_angle_1e300: [("rudder_angle", 1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
        rudder_angle_neg_1e300: [("rudder_angle", -1e+300)]
            => Error("output \"f22_estimate\" = NaN is not a finite number"),
    }
}
