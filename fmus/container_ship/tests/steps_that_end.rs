//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for ContainerShip:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`.

use fmi2_export::testing::{Corrupt, Outcome::*};

fmi2_export::probe_cases!(container_ship_fmu::ContainerShipFmu);

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
        &[("gm", 1e+300)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("gm", 1000000.0)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("min_speed", 1000000.0)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("initial_shaft_speed", 1e+300)],
        0.1,
        50,
        Error("output \"speed\" = inf is not a finite number"),
    );
    probe(
        &[],
        &[("initial_shaft_speed", 1e-300)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("initial_shaft_speed", 1000000.0)],
        0.1,
        50,
        Error("output \"speed\" = inf is not a finite number"),
    );
    probe(
        &[],
        &[("initial_sway_velocity", 1e+300)],
        0.1,
        50,
        Error("output \"speed\" = inf is not a finite number"),
    );
    probe(
        &[],
        &[("initial_sway_velocity", -1e+300)],
        0.1,
        50,
        Error("output \"speed\" = inf is not a finite number"),
    );
    probe(
        &[],
        &[("initial_sway_velocity", 1000000.0)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("initial_sway_velocity", -1000000.0)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("sway_force", 1e+300)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("sway_force", -1e+300)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("roll_moment", 1e+300)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("roll_moment", -1e+300)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("yaw_moment", 1e+300)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
    );
    probe(
        &[],
        &[("yaw_moment", -1e+300)],
        0.1,
        50,
        Error("output \"surge_velocity\" = NaN is not a finite number"),
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

/// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.05) is
/// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
/// its next step is refused by the bound.
#[test]
fn a_corrupt_state_is_refused_or_bounded() {
    corrupt(
        &[],
        0.05,
        1.5e-40,
        Corrupt::StepRefused("internal steps of max_substep = "),
    );
}

/// Fuzz run (seed 2027, `replay param ContainerShip 2368 273`): rudder_rate_max = 1e-300 with
/// max_substep = 1e-6 made a 1 s step of 1e6 RK4 sub-steps (within the work bound) run on
/// denormal numbers, 3.0 s instead of 0.38 s. The declared minimum of rudder_rate_max is now
/// 1e-3 rad/s; at that minimum the same step ends with finite outputs.
#[test]
fn rudder_rates_below_the_declared_minimum_are_refused() {
    probe(
        &[],
        &[("rudder_rate_max", 1e-300)],
        1.0,
        1,
        Error("\"rudder_rate_max\" = 1e-300 refused: outside [0.001, inf]"),
    );
    probe(
        &[],
        &[("rudder_rate_max", 1e-3), ("max_substep", 1e-6)],
        1.0,
        1,
        Finite,
    );
}
