//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for RrsAutopilot:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `rrs_autopilot::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    rrs_autopilot = rrs_autopilot_fmu::RrsAutopilotFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Error("internal steps of max_substep = "),
    }

    /// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
    tiny_internal_steps_end: probe(h = 1.0, steps = 1) {
        max_substep_1e_neg300: [("max_substep", 1e-300)]
            => Error("internal steps of max_substep = "),
    }

    /// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
    extreme_parameters_give_an_error_not_nan: probe(h = 0.1, steps = 50) {
        roll_1e300: [("roll", 1e+300)]
            => Error("output \"roll_variance\" = inf is not a finite number"),
        roll_neg_1e300: [("roll", -1e+300)]
            => Error("output \"roll_variance\" = inf is not a finite number"),
    }

    /// param_sweep_all.txt: extreme in-range parameters that hung (50 steps of the default experiment).
    extreme_parameters_that_hung_end: probe(h = 0.1, steps = 50) {
        max_substep_1e_neg300: [("max_substep", 1e-300)]
            => Error("internal steps of max_substep = "),
    }

    /// param_sweep_all.txt: extreme in-range parameters that panicked, the panic printed to the host's stderr (50 steps of the default experiment).
    extreme_parameters_that_panicked_give_an_error: probe(h = 0.1, steps = 50) {
        roll_q2_1e300: [("roll_q2", 1e+300)]
            => Error("output \"roll_gain_2\" = inf is not a finite number"),
        roll_q2_1e6: [("roll_q2", 1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        roll_q3_1e300: [("roll_q3", 1e+300)]
            => Error("output \"roll_gain_3\" = -inf is not a finite number"),
        roll_q3_1e6: [("roll_q3", 1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        r_1e_neg300: [("r", 1e-300)]
            => Error("output \"roll_gain_1\" = inf is not a finite number"),
        min_speed_1e300: [("min_speed", 1e+300)]
            => Error("output \"rudder_command\" = NaN is not a finite number"),
        min_speed_1e6: [("min_speed", 1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        innovation_scale_1e_neg300: [("innovation_scale", 1e-300)]
            => Error("output \"roll_gain_1\" = -inf is not a finite number"),
        k_dp0_1e300: [("k_dp0", 1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_dp0_neg_1e300: [("k_dp0", -1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_dp0_1e6: [("k_dp0", 1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_dp0_neg_1e6: [("k_dp0", -1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_dv0_1e300: [("k_dv0", 1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_dv0_neg_1e300: [("k_dv0", -1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_dv0_1e6: [("k_dv0", 1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_dv0_neg_1e6: [("k_dv0", -1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_vp0_1e300: [("k_vp0", 1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_vp0_neg_1e300: [("k_vp0", -1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_vp0_1e6: [("k_vp0", 1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        k_vp0_neg_1e6: [("k_vp0", -1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        t_v0_1e_neg300: [("t_v0", 1e-300)] => Error("refused: outside [1, inf]"),
        t_v0_0: [("t_v0", 0.0)] => Error("refused: outside [1, inf]"),
        z_n0_1e300: [("z_n0", 1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        z_n0_neg_1e300: [("z_n0", -1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        z_n0_1e6: [("z_n0", 1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        z_n0_neg_1e6: [("z_n0", -1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        z_n1_1e300: [("z_n1", 1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        z_n1_neg_1e300: [("z_n1", -1e+300)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        z_n1_1e6: [("z_n1", 1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        z_n1_neg_1e6: [("z_n1", -1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
        omega_n0_1e300: [("omega_n0", 1e+300)]
            => Error("output \"rudder_command\" = NaN is not a finite number"),
        omega_n0_1e6: [("omega_n0", 1000000.0)]
            => Error("output \"roll_gain_1\" = -inf is not a finite number"),
        speed_1e300: [("speed", 1e+300)]
            => Error("output \"rudder_command\" = NaN is not a finite number"),
        speed_1e6: [("speed", 1000000.0)]
            => Error("output \"roll_gain_1\" = NaN is not a finite number"),
    }

    /// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.1) is
    /// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
    /// its next step is refused by the bound.
    a_corrupt_state_is_refused_or_bounded: corrupt() {
        interval_1p5e_neg40: 0.1 -> 1.5e-40 => StepRefused("internal steps of max_substep = "),
    }
}
