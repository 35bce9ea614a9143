//! A stop time off the base-step grid (issue 18, interop defect "Step grid"): `last_step =
//! "drop"` (the default) stops at the last grid point before it, `last_step = "short"` (or
//! `shipsim run --last-step short`) takes a shorter last step to it, as FMPy does; the summary
//! says which. Checked on the C test FMU (tests/c/testfmu.c): with u = 1 and k = 1 its output y
//! is the sum of the step sizes it was given (explicit Euler of dx/dt = 1), t_last is t + h of
//! its last step and `steps` counts its fmi2DoStep calls. FMPy's values on SteeringGear are
//! compared in tests/python/test_last_step_fmpy.py.
mod common;
use common::*;
use shipsim::run::{run_system, Output, RunOptions, Summary};
use shipsim::system::LastStep;
use shipsim::system::System;
use std::path::Path;

/// Base step 0.25 s, stop 1.1 s (off the grid; the last grid point is 1.0 s); instance `a`
/// steps every base step, `b` every 2 (its last step, from 1.0 s, is shortened too).
fn system(d: &Path, last_step: Option<&str>) -> System {
    let line = last_step.map_or(String::new(), |l| format!("last_step = \"{l}\"\n"));
    let p = write_system(
        d,
        "off_grid.toml",
        &format!(
            r#"[simulation]
stop_time = 1.1
step_size = 0.25
{line}
[[instances]]
name = "a"
fmu = "testfmu.fmu"
parameters = {{ u = 1.0 }}
[[instances]]
name = "b"
fmu = "testfmu.fmu"
step_multiple = 2
parameters = {{ u = 1.0 }}
"#
        ),
    );
    System::load(&p).unwrap()
}

fn run(sys: &System, out: &Path) -> (Summary, Vec<String>, Vec<Vec<f64>>) {
    let (_, summary) =
        run_system(sys, Output::File(out.to_path_buf()), &RunOptions::default()).unwrap();
    let (header, rows) = read_csv(out);
    (summary, header, rows)
}

#[test]
fn short_last_step_reaches_the_stop_time() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let sys = system(d.path(), Some("short"));
    assert_eq!(sys.last_step, LastStep::Short);
    let (summary, header, rows) = run(&sys, &d.path().join("short.csv"));
    let last = rows.last().unwrap();
    // Rows at 0, 0.25, 0.5, 0.75, 1.0 and the stop time 1.1.
    assert_eq!(rows.len(), 6);
    assert_eq!(last[0], 1.1);
    assert_eq!(rows[4][0], 1.0);
    // a: four steps of 0.25 and one of 1.1 - 1.0; b: two steps of 0.5 and one of 1.1 - 1.0.
    let short = 1.1 - 1.0;
    assert_eq!(last[col(&header, "a.y")], 1.0 + short);
    assert_eq!(last[col(&header, "a.t_last")], 1.1);
    assert_eq!(last[col(&header, "a.steps")], 5.0);
    assert_eq!(last[col(&header, "b.y")], 1.0 + short);
    assert_eq!(last[col(&header, "b.t_last")], 1.1);
    assert_eq!(last[col(&header, "b.steps")], 3.0);
    assert_eq!(summary.end_time, 1.1);
    assert_eq!(summary.macro_steps, 5);
    assert_eq!(summary.fmu_steps, 8);
    let text = summary.to_string();
    assert!(
        text.contains("stop time 1.1 s is off the base-step grid: the last step was shortened to end at it (last_step = \"short\")"),
        "{text}"
    );
}

#[test]
fn drop_is_the_default_and_stops_before_the_stop_time() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    for last_step in [None, Some("drop")] {
        let sys = system(d.path(), last_step);
        assert_eq!(sys.last_step, LastStep::Drop);
        let (summary, header, rows) = run(&sys, &d.path().join("drop.csv"));
        let last = rows.last().unwrap();
        assert_eq!(rows.len(), 5);
        assert_eq!(last[0], 1.0);
        assert_eq!(last[col(&header, "a.y")], 1.0);
        assert_eq!(last[col(&header, "a.steps")], 4.0);
        assert_eq!(last[col(&header, "b.steps")], 2.0);
        assert_eq!(summary.end_time, 1.0);
        assert_eq!(summary.macro_steps, 4);
        let text = summary.to_string();
        assert!(
            text.contains("stop time 1.1 s is off the base-step grid: the run stopped before it, at the last grid point (last_step = \"drop\""),
            "{text}"
        );
    }
}

#[test]
fn a_stop_time_on_the_grid_says_nothing_about_the_last_step() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let mut sys = system(d.path(), Some("short"));
    sys.stop_time = Some(1.0);
    let (summary, _, rows) = run(&sys, &d.path().join("on.csv"));
    assert_eq!(rows.len(), 5);
    assert_eq!(summary.end_time, 1.0);
    assert!(summary.off_grid.is_none());
    assert!(!summary.to_string().contains("base-step grid"));
}

#[test]
fn short_last_step_needs_variable_step_fmus() {
    let d = tempfile::tempdir().unwrap();
    let md = model_description(GUID, "2.0").replace(
        "canHandleVariableCommunicationStepSize=\"true\"",
        "canHandleVariableCommunicationStepSize=\"false\"",
    );
    assert!(md.contains("canHandleVariableCommunicationStepSize=\"false\""));
    build_fmu(
        d.path(),
        "testfmu",
        Variant {
            md_override: Some(&md),
            ..Variant::default()
        },
    );
    let sys = system(d.path(), Some("short"));
    let err = run_system(&sys, Output::None, &RunOptions::default())
        .err()
        .expect("a short last step on a fixed-step FMU must be refused")
        .to_string();
    for inst in ["instance 'a'", "instance 'b'"] {
        assert!(err.contains(inst), "{err}");
    }
    assert!(
        err.contains("does not declare canHandleVariableCommunicationStepSize"),
        "{err}"
    );
    // On the grid nothing is shortened, so nothing is refused.
    let mut on_grid = sys.clone();
    on_grid.stop_time = Some(1.0);
    run_system(&on_grid, Output::None, &RunOptions::default()).unwrap();
}

#[test]
fn unknown_last_step_is_an_error_with_the_line() {
    let d = tempfile::tempdir().unwrap();
    let p = write_system(
        d.path(),
        "bad.toml",
        "[simulation]\nstop_time = 1.1\nstep_size = 0.25\nlast_step = \"shorter\"\n[[instances]]\nname = \"a\"\nfmu = \"testfmu.fmu\"\n",
    );
    let err = System::load(&p).err().unwrap().to_string();
    assert!(err.contains("bad.toml:4"), "{err}");
    assert!(
        err.contains("last_step = \"shorter\": expected \"drop\""),
        "{err}"
    );
}

#[test]
fn cli_last_step_flag_overrides_the_file_and_the_summary_says_so() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    system(d.path(), None);
    let out = d.path().join("cli.csv");
    let r = std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .arg("run")
        .arg(d.path().join("off_grid.toml"))
        .args(["--last-step", "short", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{stderr}");
    assert!(
        stderr.contains("simulated 0 s .. 1.1 s: 5 macro steps, 8 FMU steps"),
        "{stderr}"
    );
    assert!(stderr.contains("the last step was shortened"), "{stderr}");
    assert_eq!(read_csv(&out).1.last().unwrap()[0], 1.1);
    let r = std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .arg("run")
        .arg(d.path().join("off_grid.toml"))
        .args(["--last-step", "long"])
        .output()
        .unwrap();
    assert!(!r.status.success());
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(
        stderr.contains("[possible values: short, drop]"),
        "{stderr}"
    );
}
