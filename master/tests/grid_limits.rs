//! The time grid of every system format is validated (issue 19, defects 3, 7 and 9):
//! `<Simulator stepSize="NaN"/>` panicked (exit 101, a remainder by zero), `"inf"` and
//! `"1e300"` were accepted silently, a 1e17-step run started without a word, and overflowed
//! step counts were reported as "shorter than one step" with 300-digit numbers.
mod common;
mod hardening;

use hardening::*;

fn osp(step_size: &str) -> String {
    format!(
        r#"<OspSystemStructure version="0.1"><StartTime>0</StartTime><EndTime>1</EndTime><BaseStepSize>0.01</BaseStepSize><Simulators>
<Simulator name="a" source="testfmu.fmu" stepSize="{step_size}"/></Simulators></OspSystemStructure>"#
    )
}

/// A Simulator's stepSize that is not a finite multiple of the base step, not longer than
/// the run, is an error naming the instance, never a panic.
#[test]
fn osp_simulator_step_size_nan_inf_huge() {
    let s = Sandbox::new();
    common::test_fmu(s.path());
    for step in ["NaN", "inf", "1e300"] {
        std::fs::write(s.path().join("OspSystemStructure.xml"), osp(step)).unwrap();
        for cmd in ["run", "check"] {
            let (code, err) =
                s.run(&[cmd, "OspSystemStructure.xml", "-q"][..if cmd == "run" { 3 } else { 2 }]);
            assert_eq!(code, Some(1), "{step} {cmd}: {err}");
            assert!(
                err.contains("instance 'a': step_multiple = ")
                    && err.contains(
                        "it must be a whole number of base steps from 1 to the run's 100"
                    ),
                "{step} {cmd}: {err}"
            );
            assert!(!err.contains("panicked"), "{err}");
        }
    }
    assert_eq!(s.leftovers(), Vec::<String>::new());
}

/// Infinite and overflowing times and step counts: clear errors with short numbers.
#[test]
fn toml_grid_errors_are_short_and_clear() {
    let s = Sandbox::new();
    common::test_fmu(s.path());
    let cases = [
        (
            "0",
            "1e300",
            "1e-300",
            "the run from 0 to 1e300 has inf steps of 1e-300 s",
        ),
        (
            "0",
            "10",
            "5e-324",
            "the run from 0 to 10 has inf steps of 5e-324 s, more than the 9.007199254740992e15",
        ),
        (
            "0",
            "1e17",
            "1",
            "the run from 0 to 1e17 has 1e17 steps of 1 s, more than the 9.007199254740992e15",
        ),
        (
            "1e300",
            "1.0000000000000001e300",
            "0.01",
            "must be greater than start_time",
        ),
        ("1e20", "2e20", "0.01", "has 1e22 steps"),
        (
            "1e10",
            "1.0001e10",
            "1e-9",
            "a step of 1e-9 s does not change the time at t = 10000000000",
        ),
        (
            "-inf",
            "10",
            "0.01",
            "start_time = -inf; it must be a finite number",
        ),
        (
            "0",
            "inf",
            "0.01",
            "stop_time = inf; it must be a finite number",
        ),
    ];
    for (start, stop, step, expect) in cases {
        let text = system("testfmu.fmu", "a", stop, step, "")
            .replace("start_time = 0.0", &format!("start_time = {start}"));
        std::fs::write(s.path().join("g.toml"), text).unwrap();
        let (code, err) = s.run(&["check", "g.toml"]);
        assert_eq!(code, Some(1), "{start} {stop} {step}: {err}");
        assert!(err.contains(expect), "{start} {stop} {step}: {err}");
        assert!(
            !err.contains("0000000000000000000000"),
            "a number written out in hundreds of digits: {err}"
        );
    }
}

/// More than 1e9 macro steps is a warning saying how many (the run is allowed).
#[test]
fn long_runs_are_announced() {
    let s = Sandbox::new();
    common::test_fmu(s.path());
    std::fs::write(
        s.path().join("long.toml"),
        system("testfmu.fmu", "a", "1e8", "0.01", ""),
    )
    .unwrap();
    let (code, err) = s.run(&["check", "long.toml"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("warning: long.toml: the run from 0 to 100000000 has 10000000000 macro steps of 0.01 s; it may take long"),
        "{err}"
    );
    // 1e10 steps are 1e10, not 1e10 + 10 (the old tolerance of a relative 1e-9).
    assert!(!err.contains("not on the base-step grid"), "{err}");
}
