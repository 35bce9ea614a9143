//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for DpController:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `dp_controller::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    dp_controller = dp_controller_fmu::DpControllerFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Finite,
    }

    /// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
    extreme_parameters_give_an_error_not_nan: probe(h = 1.0, steps = 50) {
        bandwidth_surge_1e300: [("bandwidth_surge", 1e+300)]
            => Error("output \"tau_surge\" = NaN is not a finite number"),
        bandwidth_sway_1e300: [("bandwidth_sway", 1e+300)]
            => Error("output \"tau_sway\" = NaN is not a finite number"),
        bandwidth_yaw_1e300: [("bandwidth_yaw", 1e+300)]
            => Error("output \"tau_yaw\" = NaN is not a finite number"),
        relative_damping_1e300: [("relative_damping", 1e+300)]
            => Error("output \"tau_surge\" = NaN is not a finite number"),
        relative_damping_1e6: [("relative_damping", 1000000.0)]
            => Error("output \"tau_surge\" = NaN is not a finite number"),
    }
}
