//! The cases of the issue-19 reliability probe (of main 616074e, `../shared/reliability/`) for
//! DpController, through the symbols its crate exports: one step of 10^9 s, tiny sub-step or sample
//! parameters, extreme in-range parameters that gave fmi2OK with non-finite outputs (or a
//! hang or a panic) and a corrupt serialized state. Each must end with the error named (or
//! finite outputs): a case that hung ends with the error of the bound on the work of one step.

use fmi2_export::testing::{check_probe, Outcome, Outcome::*};

fmi2_export::fmi2::declare_fmi2_functions!();

type Fmu = dp_controller_fmu::DpControllerFmu;

/// `integers` and `reals` set in Initialization Mode, then `steps` steps of `h` from t = 0.
fn probe(integers: &[(&str, i32)], reals: &[(&str, f64)], h: f64, steps: usize, expect: Outcome) {
    check_probe::<Fmu>(linked_fmi2_functions(), integers, reals, h, steps, expect);
}

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
