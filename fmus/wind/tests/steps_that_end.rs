//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for Wind:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `wind::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    wind = wind_fmu::WindFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Error("internal steps of internal_step = "),
    }

    /// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
    tiny_internal_steps_end: probe(h = 1.0, steps = 1) {
        internal_step_1e_neg6: [("internal_step", 1e-06)] => Finite,
    }

    /// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
    extreme_parameters_give_an_error_not_nan: probe(h = 0.1, steps = 50) {
        mean_wind_speed_1e300: [("mean_wind_speed", 1e+300)]
            => Error("output \"relative_wind_speed\" = inf is not a finite number"),
        direction_std_1e300: [("direction_std", 1e+300)]
            => Error("output \"true_wind_direction\" = NaN is not a finite number"),
        ship_speed_1e300: [("ship_speed", 1e+300)]
            => Error("output \"relative_wind_speed\" = inf is not a finite number"),
        ship_speed_neg_1e300: [("ship_speed", -1e+300)]
            => Error("output \"relative_wind_speed\" = inf is not a finite number"),
    }

    /// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.1) is
    /// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
    /// its next step is refused by the bound.
    a_corrupt_state_is_refused_or_bounded: corrupt() {
        interval_1p5e_neg40: 0.1 -> 1.5e-40
            => Refused("\"internal_step\" = 1.5e-40 is not a finite number in [1e-6, inf]"),
    }
}
