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

/// fuzz run, `replay param PathController 2036 229`: r_cross_track = 1e300 spun forever in the
/// Schur decomposition of the gain design's closed loop.
#[test]
fn an_extreme_weight_ends_in_an_error() {
    probe(
        &[],
        &[
            ("r_yaw_rate", 142.19367881695118),
            ("r_cross_track", 1e300),
            ("schedule_tolerance", 1e6),
        ],
        1.0,
        1,
        Error("no convergence"),
    );
}
