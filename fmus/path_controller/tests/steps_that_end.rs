//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for PathController:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`.

use fmi2_export::testing::Outcome::*;

fmi2_export::probe_cases!(path_controller_fmu::PathControllerFmu);

/// bigstep_all.txt: one fmi2DoStep of 1e9 s.
#[test]
fn one_step_of_1e9_s_ends() {
    probe(&[], &[], 1000000000.0, 1, Finite);
}

/// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
#[test]
fn tiny_internal_steps_end() {
    probe(&[], &[("update_interval", 1e-300)], 1.0, 1, Finite);
}
