//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for ContainerShip:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `container_ship::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    container_ship = container_ship_fmu::ContainerShipFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Error("internal steps of max_substep = "),
    }

    /// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
    tiny_internal_steps_end: probe(h = 1.0, steps = 1) {
        max_substep_1e_neg300: [("max_substep", 1e-300)]
            => Error("internal steps of max_substep = "),
    }

    /// param_sweep_all.txt: extreme in-range parameters that gave fmi2OK with NaN or inf (50 steps of the default experiment).
    extreme_parameters_give_an_error_not_nan: probe(h = 0.1, steps = 50) {
        gm_1e300: [("gm", 1e+300)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        gm_1e6: [("gm", 1000000.0)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        min_speed_1e6: [("min_speed", 1000000.0)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        initial_shaft_speed_1e300: [("initial_shaft_speed", 1e+300)]
            => Error("output \"speed\" = inf is not a finite number"),
        initial_shaft_speed_1e_neg300: [("initial_shaft_speed", 1e-300)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        initial_shaft_speed_1e6: [("initial_shaft_speed", 1000000.0)]
            => Error("output \"speed\" = inf is not a finite number"),
        initial_sway_velocity_1e300: [("initial_sway_velocity", 1e+300)]
            => Error("output \"speed\" = inf is not a finite number"),
        initial_sway_velocity_neg_1e300: [("initial_sway_velocity", -1e+300)]
            => Error("output \"speed\" = inf is not a finite number"),
        initial_sway_velocity_1e6: [("initial_sway_velocity", 1000000.0)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        initial_sway_velocity_neg_1e6: [("initial_sway_velocity", -1000000.0)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        sway_force_1e300: [("sway_force", 1e+300)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        sway_force_neg_1e300: [("sway_force", -1e+300)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        roll_moment_1e300: [("roll_moment", 1e+300)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        roll_moment_neg_1e300: [("roll_moment", -1e+300)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        yaw_moment_1e300: [("yaw_moment", 1e+300)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
        yaw_moment_neg_1e300: [("yaw_moment", -1e+300)]
            => Error("output \"surge_velocity\" = NaN is not a finite number"),
    }

    /// param_sweep_all.txt: extreme in-range parameters that hung (50 steps of the default experiment).
    extreme_parameters_that_hung_end: probe(h = 0.1, steps = 50) {
        max_substep_1e_neg300: [("max_substep", 1e-300)]
            => Error("internal steps of max_substep = "),
    }

    /// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.05) is
    /// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
    /// its next step is refused by the bound.
    a_corrupt_state_is_refused_or_bounded: corrupt() {
        interval_1p5e_neg40: 0.05 -> 1.5e-40 => StepRefused("internal steps of max_substep = "),
    }

    /// Fuzz run (seed 2027, `replay param ContainerShip 2368 273`): rudder_rate_max = 1e-300 with
    /// max_substep = 1e-6 made a 1 s step of 1e6 RK4 sub-steps (within the work bound) run on
    /// denormal numbers, 3.0 s instead of 0.38 s. The declared minimum of rudder_rate_max is now
    /// 1e-3 rad/s; at that minimum the same step ends with finite outputs.
    rudder_rates_below_the_declared_minimum_are_refused: probe(h = 1.0, steps = 1) {
        rudder_rate_max_1e_neg300: [("rudder_rate_max", 1e-300)]
            => Error("\"rudder_rate_max\" = 1e-300 refused: outside [0.001, inf]"),
        rudder_rate_max_0p001_max_substep_1e_neg6: [
            ("rudder_rate_max", 1e-3),
            ("max_substep", 1e-6),
        ] => Finite,
    }
}
