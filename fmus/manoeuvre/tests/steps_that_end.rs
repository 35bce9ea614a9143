//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for Manoeuvre:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `manoeuvre::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    manoeuvre = manoeuvre_fmu::ManoeuvreFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Finite,
    }
}
