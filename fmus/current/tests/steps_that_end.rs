//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for Current:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`.

use fmi2_export::testing::{Corrupt, Outcome::*};

fmi2_export::probe_cases!(current_fmu::CurrentFmu);

/// bigstep_all.txt: one fmi2DoStep of 1e9 s.
#[test]
fn one_step_of_1e9_s_ends() {
    probe(
        &[],
        &[],
        1000000000.0,
        1,
        Error("internal steps of internal_step = "),
    );
}

/// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
#[test]
fn tiny_internal_steps_end() {
    probe(&[], &[("internal_step", 1e-06)], 1.0, 1, Finite);
}

/// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
#[test]
fn extreme_parameters_give_an_error_not_nan() {
    probe(
        &[],
        &[("reference_speed", 1e+300)],
        0.2349,
        50,
        Error("output \"yaw_moment\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("ship_length", 1e+300)],
        0.2349,
        50,
        Error("output \"yaw_moment\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("white_sigma_n", 1e+300)],
        0.2349,
        50,
        Error("output \"yaw_moment\" = -inf is not a finite number"),
    );
    probe(
        &[],
        &[("white_sigma_y", 1e+300)],
        0.2349,
        50,
        Error("output \"side_force\" = inf is not a finite number"),
    );
    probe(
        &[],
        &[("shaping_sigma_n", 1e+300)],
        0.2349,
        50,
        Error("output \"n_prime\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("shaping_sigma_y", 1e+300)],
        0.2349,
        50,
        Error("output \"y_prime\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("bias_psi_x", 1e+300)],
        0.2349,
        50,
        Error("output \"bias_x\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("bias_psi_y", 1e+300)],
        0.2349,
        50,
        Error("output \"bias_y\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("bias_psi_n", 1e+300)],
        0.2349,
        50,
        Error("output \"bias_n\" = NaN is not a finite number"),
    );
}

/// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.2348812095032397) is
/// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
/// its next step is refused by the bound.
#[test]
fn a_corrupt_state_is_refused_or_bounded() {
    corrupt(
        &[],
        0.2348812095032397,
        1.5e-40,
        Corrupt::Refused("\"internal_step\" = 1.5e-40 is not a finite number in [1e-6, inf]"),
    );
}
