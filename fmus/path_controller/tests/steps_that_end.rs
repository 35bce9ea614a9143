//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for PathController:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `path_controller::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    path_controller = path_controller_fmu::PathControllerFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Finite,
    }

    /// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
    tiny_internal_steps_end: probe(h = 1.0, steps = 1) {
        update_interval_1e_neg300: [("update_interval", 1e-300)] => Finite,
    }

    /// fuzz run, `replay param PathController 2036 229`: r_cross_track = 1e300 spun forever in the
    /// Schur decomposition of the gain design's closed loop.
    an_extreme_weight_ends_in_an_error: probe(h = 1.0, steps = 1) {
        r_cross_track_1e300: [
            ("r_yaw_rate", 142.19367881695118),
            ("r_cross_track", 1e300),
            ("schedule_tolerance", 1e6),
        ] => Error("no convergence"),
    }
}
