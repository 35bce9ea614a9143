//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for RrsAutopilot:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`.

use fmi2_export::testing::{Corrupt, Outcome::*};

fmi2_export::probe_cases!(rrs_autopilot_fmu::RrsAutopilotFmu);

/// bigstep_all.txt: one fmi2DoStep of 1e9 s.
#[test]
fn one_step_of_1e9_s_ends() {
    probe(
        &[],
        &[],
        1000000000.0,
        1,
        Error("internal steps of max_substep = "),
    );
}

/// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
#[test]
fn tiny_internal_steps_end() {
    probe(
        &[],
        &[("max_substep", 1e-300)],
        1.0,
        1,
        Error("internal steps of max_substep = "),
    );
}

/// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
#[test]
fn extreme_parameters_give_an_error_not_nan() {
    probe(
        &[],
        &[("roll", 1e+300)],
        0.1,
        50,
        Error("output \"roll_variance\" = inf is not a finite number"),
    );
    probe(
        &[],
        &[("roll", -1e+300)],
        0.1,
        50,
        Error("output \"roll_variance\" = inf is not a finite number"),
    );
}

/// param_sweep_all.txt: extreme in-range parameters that hung (50 steps of the default experiment).
#[test]
fn extreme_parameters_that_hung_end() {
    probe(
        &[],
        &[("max_substep", 1e-300)],
        0.1,
        50,
        Error("internal steps of max_substep = "),
    );
}

/// param_sweep_all.txt: extreme in-range parameters that panicked, the panic printed to the host's stderr (50 steps of the default experiment).
#[test]
fn extreme_parameters_that_panicked_give_an_error() {
    probe(
        &[],
        &[("roll_q2", 1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_2\" = inf is not a finite number"),
    );
    probe(
        &[],
        &[("roll_q2", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("roll_q3", 1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_3\" = -inf is not a finite number"),
    );
    probe(
        &[],
        &[("roll_q3", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("r", 1e-300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = inf is not a finite number"),
    );
    probe(
        &[],
        &[("min_speed", 1e+300)],
        0.1,
        50,
        Error("output \"rudder_command\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("min_speed", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("innovation_scale", 1e-300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = -inf is not a finite number"),
    );
    probe(
        &[],
        &[("k_dp0", 1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_dp0", -1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_dp0", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_dp0", -1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_dv0", 1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_dv0", -1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_dv0", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_dv0", -1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_vp0", 1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_vp0", -1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_vp0", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("k_vp0", -1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("t_v0", 1e-300)],
        0.1,
        50,
        Error("refused: outside [1, inf]"),
    );
    probe(
        &[],
        &[("t_v0", 0.0)],
        0.1,
        50,
        Error("refused: outside [1, inf]"),
    );
    probe(
        &[],
        &[("z_n0", 1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("z_n0", -1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("z_n0", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("z_n0", -1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("z_n1", 1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("z_n1", -1e+300)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("z_n1", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("z_n1", -1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("omega_n0", 1e+300)],
        0.1,
        50,
        Error("output \"rudder_command\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("omega_n0", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = -inf is not a finite number"),
    );
    probe(
        &[],
        &[("speed", 1e+300)],
        0.1,
        50,
        Error("output \"rudder_command\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("speed", 1000000.0)],
        0.1,
        50,
        Error("output \"roll_gain_1\" = NaN is not a finite number"),
    );
}

/// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.1) is
/// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
/// its next step is refused by the bound.
#[test]
fn a_corrupt_state_is_refused_or_bounded() {
    corrupt(
        &[],
        0.1,
        1.5e-40,
        Corrupt::StepRefused("internal steps of max_substep = "),
    );
}
