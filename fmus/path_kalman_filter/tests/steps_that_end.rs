//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for PathKalmanFilter:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `path_kalman_filter::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    path_kalman_filter = path_kalman_filter_fmu::PathKalmanFilterFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Error("internal steps of euler_step_prime = "),
    }

    /// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
    tiny_internal_steps_end: probe(h = 1.0, steps = 1) {
        euler_step_prime_1e_neg300: [("euler_step_prime", 1e-300)]
            => Error("internal steps of euler_step_prime = "),
    }

    /// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
    extreme_parameters_give_an_error_not_nan: probe(h = 0.2348812095032397, steps = 50) {
        initial_heading_1e300: [("initial_heading", 1e+300)]
            => Error("output \"innovation_rms_heading\" = inf is not a finite number"),
        initial_heading_neg_1e300: [("initial_heading", -1e+300)]
            => Error("output \"innovation_rms_heading\" = inf is not a finite number"),
        initial_yaw_rate_1e300: [("initial_yaw_rate", 1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        initial_yaw_rate_neg_1e300: [("initial_yaw_rate", -1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        initial_drift_angle_1e300: [("initial_drift_angle", 1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        initial_drift_angle_neg_1e300: [("initial_drift_angle", -1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        initial_cross_track_1e300: [("initial_cross_track", 1e+300)]
            => Error("output \"innovation_rms_cross_track\" = inf is not a finite number"),
        initial_cross_track_neg_1e300: [("initial_cross_track", -1e+300)]
            => Error("output \"innovation_rms_cross_track\" = inf is not a finite number"),
        initial_rudder_1e300: [("initial_rudder", 1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        initial_rudder_neg_1e300: [("initial_rudder", -1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        initial_yaw_moment_prime_1e300: [("initial_yaw_moment_prime", 1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        initial_yaw_moment_prime_neg_1e300: [("initial_yaw_moment_prime", -1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        initial_sway_force_prime_1e300: [("initial_sway_force_prime", 1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        initial_sway_force_prime_neg_1e300: [("initial_sway_force_prime", -1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        heading_measured_1e300: [("heading_measured", 1e+300)]
            => Error("output \"innovation_rms_heading\" = inf is not a finite number"),
        heading_measured_neg_1e300: [("heading_measured", -1e+300)]
            => Error("output \"innovation_rms_heading\" = inf is not a finite number"),
        yaw_rate_measured_1e300: [("yaw_rate_measured", 1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        yaw_rate_measured_neg_1e300: [("yaw_rate_measured", -1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        cross_track_measured_1e300: [("cross_track_measured", 1e+300)]
            => Error("output \"innovation_rms_cross_track\" = inf is not a finite number"),
        cross_track_measured_neg_1e300: [("cross_track_measured", -1e+300)]
            => Error("output \"innovation_rms_cross_track\" = inf is not a finite number"),
        rudder_command_1e300: [("rudder_command", 1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
        rudder_command_neg_1e300: [("rudder_command", -1e+300)]
            => Error("output \"innovation_rms_yaw_rate\" = inf is not a finite number"),
    }

    /// param_sweep_all.txt: extreme in-range parameters that hung (50 steps of the default experiment).
    extreme_parameters_that_hung_end: probe(h = 0.2348812095032397, steps = 50) {
        euler_step_prime_1e_neg300: [("euler_step_prime", 1e-300)]
            => Error("internal steps of euler_step_prime = "),
    }

    /// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.005) is
    /// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
    /// its next step is refused by the bound.
    a_corrupt_state_is_refused_or_bounded: corrupt() {
        interval_1p5e_neg40: 0.005 -> 1.5e-40
            => StepRefused("internal steps of euler_step_prime = "),
    }

    /// fuzz run, `replay calls PathKalmanFilter 2028 17`: r_cross_track = 1.7e173 spun forever in
    /// fmi2ExitInitializationMode (the Schur decomposition of the Kalman design's closed loop).
    an_extreme_weight_ends_in_an_error: probe(h = 1.0, steps = 1) {
        r_cross_track_1p7e173: [
            ("euler_step_prime", 3.6265768353767425),
            ("r_cross_track", 1.743975019132907e173),
        ] => Error("no convergence"),
    }
}
