//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for ParameterEkf:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `parameter_ekf::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    parameter_ekf = parameter_ekf_fmu::ParameterEkfFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Error("internal steps of max_substep = "),
    }

    /// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
    tiny_internal_steps_end: probe(h = 1.0, steps = 1) {
        max_substep_1e_neg300: [("max_substep", 1e-300)]
            => Error("internal steps of max_substep = "),
        sample_interval_1e_neg300: [("sample_interval", 1e-300)] => Finite,
    }

    /// param_sweep_all.txt: extreme in-range parameters that hung (50 steps of the default experiment).
    extreme_parameters_that_hung_end: probe(h = 1.0, steps = 50) {
        max_substep_1e_neg300: [("max_substep", 1e-300)]
            => Error("internal steps of max_substep = "),
    }

    /// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.1) is
    /// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
    /// its next step is refused by the bound.
    a_corrupt_state_is_refused_or_bounded: corrupt() {
        interval_1p5e_neg40: 0.1 -> 1.5e-40 => StepRefused("internal steps of max_substep = "),
    }
}
