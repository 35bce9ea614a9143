//! The issue-19 reliability probe's cases (`../shared/reliability/`, main 616074e) for Sensors:
//! each ends with the error named or finite outputs (a case that hung, with the error of the
//! bound on the work of one step). See `fmi2_export::testing::check_probe`. One test per row,
//! `sensors::<group>::<row>` (see `fmi2_export::probe_cases!`).

fmi2_export::probe_cases! {
    sensors = sensors_fmu::SensorsFmu;

    /// bigstep_all.txt: one fmi2DoStep of 1e9 s.
    one_step_of_1e9_s_ends: probe(h = 1000000000.0, steps = 1) {
        defaults: [] => Error("internal steps of roll_interval = "),
    }

    /// tinystep_all.txt: a 1 s step with a tiny positive sub-step or sample parameter.
    tiny_internal_steps_end: probe(h = 1.0, steps = 1) {
        heading_interval_1e_neg6: [("heading_interval", 1e-06)] => Finite,
    }

    /// fuzz_state_all.txt: a state whose sub-step or sample interval (every copy of 0.23488120950323976) is
    /// 1.5e-40 (the mutated states that hung) is refused, or restores within the declared range and
    /// its next step is refused by the bound.
    a_corrupt_state_is_refused_or_bounded: corrupt() {
        interval_1p5e_neg40: 0.23488120950323976 -> 1.5e-40
            => Refused("is not a finite number in [1e-6, inf]"),
    }
}

/// Fuzz run (seed 2027): at t = 1e300 a 0.1 s sample interval is lost in rounding
/// (t0 + k*interval no longer grows with k), and `fmi2DoStep(t = 1e300, h = 0.05)` spun in the
/// sampling loop. The work bound now refuses an internal step that cannot advance the time.
/// Replay: `fuzz replay calls Sensors 2086 24`.
#[test]
fn a_step_at_a_time_too_large_for_the_sample_interval_is_refused() {
    use fmi2_export::fmi2::{fmi2Error, fmi2OK};
    use fmi2_export::testing::{functions, Harness};
    let mut fmu = Harness::<sensors_fmu::SensorsFmu>::instantiate(
        functions::<sensors_fmu::SensorsFmu>(),
        "late",
    );
    assert_eq!(fmu.setup(1e300, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    assert_eq!(fmu.try_step(1e300, 0.05), fmi2Error);
    let line = fmu.log().last();
    assert!(
        line.contains("fmi2DoStep at t = 1e300")
            && line.contains("s is lost in rounding at t + h = 1e300 s")
            && line.contains("the time is too large for this step"),
        "{line}"
    );
}

/// Fuzz run (seed 2027): a serialized state whose model copy of the parameters has an infinite
/// sample interval (heading_rate_interval, byte 300 of the state) was restored, and the next
/// fmi2DoStep spun: t0 + k·∞ ≤ t + 1e-9·∞ holds for every k, and the work bound read the
/// loop's (t − ∞)/∞ = NaN passes as 0. Replay: `fuzz replay state Sensors 2186 39`.
#[test]
fn a_state_with_an_infinite_sample_interval_is_refused() {
    use fmi2_export::fmi2::{fmi2Error, fmi2OK};
    use fmi2_export::testing::{functions, Harness};
    let mut fmu = Harness::<sensors_fmu::SensorsFmu>::instantiate(
        functions::<sensors_fmu::SensorsFmu>(),
        "restored",
    );
    fmu.initialize(0.0);
    let mut t = 0.0;
    for _ in 0..4 {
        fmu.step(t, 0.1);
        t += 0.1;
    }
    let s = fmu.get_state();
    let mut bytes = fmu.serialize(s);
    // The model's copy of the interval of channel 3, found by its value (0.1 s) after the
    // variables' copy of the same parameter.
    let interval = 0.1f64.to_le_bytes();
    let at: Vec<usize> = (0..bytes.len() - 8)
        .filter(|&i| bytes[i..i + 8] == interval)
        .collect();
    assert_eq!(
        at.len(),
        4,
        "two 0.1 s channels, each in two copies of the parameters"
    );
    bytes[at[3]..at[3] + 8].copy_from_slice(&f64::INFINITY.to_le_bytes());
    let (status, _) = fmu.deserialize(&bytes);
    assert_eq!(status, fmi2Error);
    let line = fmu.log().last();
    assert!(
        line.contains("fmi2DeSerializeFMUstate")
            && line.contains("interval")
            && line.contains("inf"),
        "{line}"
    );
    // The instance is unharmed.
    assert_eq!(fmu.try_step(t, 0.1), fmi2OK);
}
