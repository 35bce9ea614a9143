//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for DpController:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`.

use fmi2_export::testing::Outcome::*;

fmi2_export::probe_cases!(dp_controller_fmu::DpControllerFmu);

/// bigstep_all.txt: one fmi2DoStep of 1e9 s.
#[test]
fn one_step_of_1e9_s_ends() {
    probe(&[], &[], 1000000000.0, 1, Finite);
}

/// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
#[test]
fn extreme_parameters_give_an_error_not_nan() {
    probe(
        &[],
        &[("bandwidth_surge", 1e+300)],
        1.0,
        50,
        Error("output \"tau_surge\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("bandwidth_sway", 1e+300)],
        1.0,
        50,
        Error("output \"tau_sway\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("bandwidth_yaw", 1e+300)],
        1.0,
        50,
        Error("output \"tau_yaw\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("relative_damping", 1e+300)],
        1.0,
        50,
        Error("output \"tau_surge\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("relative_damping", 1000000.0)],
        1.0,
        50,
        Error("output \"tau_surge\" = NaN is not a finite number"),
    );
}
