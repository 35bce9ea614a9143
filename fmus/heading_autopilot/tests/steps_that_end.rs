//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for HeadingAutopilot:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`.

use fmi2_export::testing::{Corrupt, Outcome::*};

fmi2_export::probe_cases!(heading_autopilot_fmu::HeadingAutopilotFmu);

/// bigstep_all.txt: one fmi2DoStep of 1e9 s.
#[test]
fn one_step_of_1e9_s_ends() {
    probe(
        &[],
        &[],
        1000000000.0,
        1,
        Error("internal steps of sample_step = "),
    );
}

/// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
#[test]
fn tiny_internal_steps_end() {
    probe(
        &[],
        &[("sample_step", 1e-300)],
        1.0,
        1,
        Error("internal steps of sample_step = "),
    );
}

/// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
#[test]
fn extreme_parameters_give_an_error_not_nan() {
    probe(
        &[],
        &[("omega_n", 1e+300)],
        0.05,
        50,
        Error("output \"rudder_command\" = NaN is not a finite number"),
    );
}

/// param_sweep_all.txt: extreme in-range parameters that hung (50 steps of the default experiment).
#[test]
fn extreme_parameters_that_hung_end() {
    probe(
        &[],
        &[("sample_step", 1e-300)],
        0.05,
        50,
        Error("internal steps of sample_step = "),
    );
    probe(
        &[],
        &[("ship_length", 1e-300)],
        0.05,
        50,
        Error("internal steps of sample_step = "),
    );
    probe(
        &[],
        &[("ship_speed", 1e+300)],
        0.05,
        50,
        Error("internal steps of sample_step = "),
    );
}

/// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.01) is
/// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
/// its next step is refused by the bound.
#[test]
fn a_corrupt_state_is_refused_or_bounded() {
    corrupt(
        &[],
        0.01,
        1.5e-40,
        Corrupt::StepRefused("internal steps of sample_step = "),
    );
}
