//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for PathWlsEstimator:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`.

use fmi2_export::testing::Outcome::*;

fmi2_export::probe_cases!(path_wls_fmu::PathWlsFmu);

/// bigstep_all.txt: one fmi2DoStep of 1e9 s.
#[test]
fn one_step_of_1e9_s_ends() {
    probe(&[], &[], 1000000000.0, 1, Finite);
}

/// param_sweep_all.txt: extreme in-range parameters that panicked, the panic printed to the host's stderr (50 steps of the default experiment).
#[test]
fn extreme_parameters_that_panicked_give_an_error() {
    probe(&[], &[("ship_speed", 1000000.0)], 0.2349, 50, Finite);
}

/// fuzz run, `replay param PathWlsEstimator 2029 111`: a window of 2.5 ship lengths at a tiny
/// ship speed asked for 2.9e9 samples (23 GB) and aborted the process; refused before allocating.
#[test]
fn a_window_of_too_many_samples_is_refused() {
    probe(
        &[],
        &[("window_start", 0.0), ("ship_speed", 1e-6)],
        1.0,
        1,
        Error("more than the limit of 1e6"),
    );
}
