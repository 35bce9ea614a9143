//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for PathWlsEstimator:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `path_wls::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    path_wls = path_wls_fmu::PathWlsFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Finite,
    }

    /// param_sweep_all.txt: extreme in-range parameters that panicked, the panic printed to the host's stderr (50 steps of the default experiment).
    extreme_parameters_that_panicked_give_an_error: probe(h = 0.2349, steps = 50) {
        ship_speed_1e6: [("ship_speed", 1000000.0)] => Finite,
    }

    /// fuzz run, `replay param PathWlsEstimator 2029 111`: a window of 2.5 ship lengths at a tiny
    /// ship speed asked for 2.9e9 samples (23 GB) and aborted the process; refused before allocating.
    a_window_of_too_many_samples_is_refused: probe(h = 1.0, steps = 1) {
        window_start_0_ship_speed_1e_neg6: [("window_start", 0.0), ("ship_speed", 1e-6)]
            => Error("more than the limit of 1e6"),
    }
}
