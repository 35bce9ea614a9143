//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for Sensors:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`.

use fmi2_export::testing::{Corrupt, Outcome::*};

fmi2_export::probe_cases!(sensors_fmu::SensorsFmu);

/// bigstep_all.txt: one fmi2DoStep of 1e9 s.
#[test]
fn one_step_of_1e9_s_ends() {
    probe(
        &[],
        &[],
        1000000000.0,
        1,
        Error("internal steps of roll_interval = "),
    );
}

/// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
#[test]
fn tiny_internal_steps_end() {
    probe(&[], &[("heading_interval", 1e-06)], 1.0, 1, Finite);
}

/// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.23488120950323976) is
/// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
/// its next step is refused by the bound.
#[test]
fn a_corrupt_state_is_refused_or_bounded() {
    corrupt(
        &[],
        0.23488120950323976,
        1.5e-40,
        Corrupt::Refused("is not a finite number in [1e-6, inf]"),
    );
}
