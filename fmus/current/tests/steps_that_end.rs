//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for Current:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `current::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    current = current_fmu::CurrentFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Error("internal steps of internal_step = "),
    }

    /// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
    tiny_internal_steps_end: probe(h = 1.0, steps = 1) {
        internal_step_1e_neg6: [("internal_step", 1e-06)] => Finite,
    }

    /// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
    extreme_parameters_give_an_error_not_nan: probe(h = 0.2349, steps = 50) {
        reference_speed_1e300: [("reference_speed", 1e+300)]
            => Error("output \"yaw_moment\" = NaN is not a finite number"),
        ship_length_1e300: [("ship_length", 1e+300)]
            => Error("output \"yaw_moment\" = NaN is not a finite number"),
        white_sigma_n_1e300: [("white_sigma_n", 1e+300)]
            => Error("output \"yaw_moment\" = -inf is not a finite number"),
        white_sigma_y_1e300: [("white_sigma_y", 1e+300)]
            => Error("output \"side_force\" = inf is not a finite number"),
        shaping_sigma_n_1e300: [("shaping_sigma_n", 1e+300)]
            => Error("output \"n_prime\" = NaN is not a finite number"),
        shaping_sigma_y_1e300: [("shaping_sigma_y", 1e+300)]
            => Error("output \"y_prime\" = NaN is not a finite number"),
        bias_psi_x_1e300: [("bias_psi_x", 1e+300)]
            => Error("output \"bias_x\" = NaN is not a finite number"),
        bias_psi_y_1e300: [("bias_psi_y", 1e+300)]
            => Error("output \"bias_y\" = NaN is not a finite number"),
        bias_psi_n_1e300: [("bias_psi_n", 1e+300)]
            => Error("output \"bias_n\" = NaN is not a finite number"),
    }

    /// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.2348812095032397) is
    /// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
    /// its next step is refused by the bound.
    a_corrupt_state_is_refused_or_bounded: corrupt() {
        interval_1p5e_neg40: 0.2348812095032397 -> 1.5e-40
            => Refused("\"internal_step\" = 1.5e-40 is not a finite number in [1e-6, inf]"),
    }
}
