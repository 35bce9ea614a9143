//! Stepping sessions on our FMUs ($SHIPSIM_FMU_DIR): a session that only reads gives the run's
//! rows bit for bit (RRS: multi-rate, Jacobi and Gauss-Seidel); a value set between steps
//! gives what the same change written as an event gives; a restored checkpoint rewinds the
//! session, which then continues bit for bit as a run without what was undone; the journal
//! replays the session's final history bit for bit; misuse is a clear error.
//!
//! Tolerance: none. Every comparison of results is of the f64 bit patterns.
mod common;
use common::*;
use shipsim::fmu::Fmu;
use shipsim::run::{
    load_fmus, run_into, Journaling, MemoryRecorder, RunOptions, Session, SessionOptions, State,
};
use shipsim::system::{Algorithm, System, TypedValue, Value, VarRef};
use std::path::Path;
use std::sync::Arc;

/// systems/rrs.toml with our FMUs, stopping at `stop_time`, no output file, and its FMUs.
fn rrs(stop_time: f64, algorithm: Algorithm) -> (System, Vec<Arc<Fmu>>) {
    let sys = our_system("rrs.toml", stop_time, algorithm);
    let fmus = load_fmus(&sys).unwrap();
    (sys, fmus)
}

fn run_rows(sys: &System, fmus: &[Arc<Fmu>]) -> Vec<Vec<u64>> {
    let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
    let plan = sys.validate(&mds).unwrap();
    let mut m = MemoryRecorder::new();
    run_into(&plan, fmus, Some(&mut m), &RunOptions::default()).unwrap();
    rows(&m)
}

fn start(sys: &System, fmus: &[Arc<Fmu>]) -> Session {
    Session::start(sys.clone(), fmus.to_vec(), SessionOptions::default()).unwrap()
}

#[test]
fn a_session_that_only_reads_is_the_run() {
    for algorithm in [Algorithm::Jacobi, Algorithm::GaussSeidel] {
        let (sys, fmus) = rrs(30.0, algorithm);
        let expected = run_rows(&sys, &fmus);
        let mut s = start(&sys, &fmus);
        // Odd chunks across the multi-rate instances' steps, with reads between them.
        let mut n = 1;
        while *s.state() == State::Open {
            s.step(n).unwrap();
            let _ = s.get("ship.roll").unwrap();
            let _ = s.get("autopilot.roll_mode").unwrap();
            n = n % 13 + 2;
        }
        assert_eq!(s.time(), 30.0);
        assert_eq!(rows(s.rows()), expected, "{algorithm:?}");
        s.close().unwrap();
    }
}

#[test]
fn advance_to_reaches_the_time_and_refuses_points_off_the_grid() {
    let (sys, fmus) = rrs(10.0, Algorithm::Jacobi);
    let expected = run_rows(&sys, &fmus);
    let mut s = start(&sys, &fmus);
    assert_eq!(s.advance_to(2.5).unwrap(), 2.5);
    assert_eq!(s.step_index(), 50);
    let e = s.advance_to(2.525).unwrap_err().to_string();
    assert!(
        e.contains("communication point") && e.contains("h = 0.05 s"),
        "{e}"
    );
    let e = s.advance_to(1.0).unwrap_err().to_string();
    assert!(e.contains("from the session's time 2.5 s"), "{e}");
    assert_eq!(s.advance_to(10.0).unwrap(), 10.0);
    assert_eq!(*s.state(), State::Ended(None));
    let e = s.step(1).unwrap_err().to_string();
    assert!(e.contains("at the end of the run, t = 10 s"), "{e}");
    assert_eq!(rows(s.rows()), expected);
}

#[test]
fn a_value_set_between_steps_is_the_same_change_as_an_event() {
    let (sys, fmus) = rrs(40.0, Algorithm::Jacobi);
    // A tunable Integer, and a tunable Real given with a unit (deg into the FMU's rad).
    let evented = with_event(&sys, 12.5, "autopilot.roll_mode", Value::Integer(0));
    let evented = with_event(
        &evented,
        20.0,
        "autopilot.angle_max",
        Value::Text("20 deg".into()),
    );
    let expected = run_rows(&evented, &fmus);
    let mut s = start(&sys, &fmus);
    s.advance_to(12.5).unwrap();
    s.set("autopilot.roll_mode", Value::Integer(0)).unwrap();
    s.step(150).unwrap();
    assert_eq!(s.time(), 20.0);
    s.set("autopilot.angle_max", Value::Text("20 deg".into()))
        .unwrap();
    s.step(1).unwrap();
    assert_eq!(
        s.get("autopilot.angle_max").unwrap(),
        TypedValue::Real(20.0_f64.to_radians())
    );
    s.advance_to(40.0).unwrap();
    assert_eq!(rows(s.rows()), expected);
    // The unchanged run differs: the sets did something.
    assert_ne!(rows(s.rows()), run_rows(&sys, &fmus));
}

#[test]
fn a_restored_checkpoint_rewinds_the_session() {
    let (sys, fmus) = rrs(30.0, Algorithm::Jacobi);
    let plain = run_rows(&sys, &fmus);
    let changed = run_rows(
        &with_event(&sys, 10.0, "autopilot.roll_mode", Value::Integer(0)),
        &fmus,
    );
    let mut s = start(&sys, &fmus);
    s.advance_to(10.0).unwrap();
    let cp = s.checkpoint().unwrap();
    assert_eq!((cp.time(), cp.step()), (10.0, 200));
    // A branch that is undone: a set, steps to the end.
    s.set("autopilot.roll_mode", Value::Integer(0)).unwrap();
    s.advance_to(30.0).unwrap();
    assert_eq!(rows(s.rows()), changed);
    s.restore(&cp).unwrap();
    assert_eq!(s.time(), 10.0);
    assert_eq!(*s.state(), State::Open);
    assert_eq!(s.rows().time.len(), 201);
    s.advance_to(30.0).unwrap();
    assert_eq!(rows(s.rows()), plain);
    // And again, the other way round.
    s.restore(&cp).unwrap();
    s.set("autopilot.roll_mode", Value::Integer(0)).unwrap();
    s.advance_to(30.0).unwrap();
    assert_eq!(rows(s.rows()), changed);
}

#[test]
fn the_journal_replays_the_session_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let journal = dir.path().join("session.jsonl");
    let (mut sys, fmus) = rrs(30.0, Algorithm::GaussSeidel);
    sys.set_value(VarRef::parse("waves.seed").unwrap(), Value::Integer(7))
        .unwrap();
    let opts = SessionOptions {
        journal: Journaling::File(journal.clone()),
        ..Default::default()
    };
    let mut s = Session::start(sys.clone(), fmus.clone(), opts).unwrap();
    s.advance_to(5.0).unwrap();
    s.set("autopilot.angle_max", Value::Text("25 deg".into()))
        .unwrap();
    s.advance_to(10.0).unwrap();
    let cp = s.checkpoint().unwrap();
    s.set("autopilot.roll_mode", Value::Integer(0)).unwrap();
    s.advance_to(20.0).unwrap();
    s.restore(&cp).unwrap();
    s.step(3).unwrap();
    s.set("autopilot.lambda", Value::Real(std::f64::consts::PI))
        .unwrap();
    s.advance_to(25.0).unwrap();
    s.close().unwrap();
    let text = std::fs::read_to_string(&journal).unwrap();
    assert_eq!(text.lines().count(), 1 + 6, "{text}");
    assert!(
        text.contains(r#""variable":"autopilot.angle_max","value":{"Real":0.4363323129985824}"#),
        "{text}"
    );
    let replayed = Session::replay(&journal, RunOptions::default()).unwrap();
    assert_eq!(replayed.time(), 25.0);
    assert_eq!(rows(replayed.rows()), rows(s.rows()));
    // The same history as a plain run: the undone set is not in it.
    let mut evented = with_event(
        &sys,
        5.0,
        "autopilot.angle_max",
        Value::Text("25 deg".into()),
    );
    evented = with_event(
        &evented,
        10.15,
        "autopilot.lambda",
        Value::Real(std::f64::consts::PI),
    );
    evented.stop_time = Some(30.0);
    let full = run_rows(&evented, &fmus);
    assert_eq!(rows(s.rows())[..], full[..rows(s.rows()).len()]);
    // A journal of another system version is refused, naming the difference.
    let first = &s.journal().header.fmus[0];
    let edited = text.replace(&format!("{:?}", first.sha256), "\"0000\"");
    let other = dir.path().join("other.jsonl");
    std::fs::write(&other, edited).unwrap();
    let e = Session::replay(&other, RunOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains(&format!("instance '{}'", first.instance)) && e.contains("SHA-256"),
        "{e}"
    );
}

#[test]
fn misuse_is_a_clear_error() {
    let (sys, fmus) = rrs(5.0, Algorithm::Jacobi);
    let mut s = start(&sys, &fmus);
    s.step(2).unwrap();
    let e = s
        .set("autopilot.k_dp0", Value::Real(0.0))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("'autopilot.k_dp0' is fixed parameter")
            && e.contains("only inputs and tunable parameters"),
        "{e}"
    );
    let e = s
        .set("autopilot.roll_mode", Value::Real(0.5))
        .unwrap_err()
        .to_string();
    assert!(e.contains("does not fit a Integer variable"), "{e}");
    let e = s
        .set("autopilot.angle_max", Value::Text("3 m".into()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("autopilot.angle_max") && e.contains("m"), "{e}");
    let e = s.get("autopilot.rol_mode").unwrap_err().to_string();
    assert!(
        e.contains("has no variable 'rol_mode'") && e.contains("roll_mode"),
        "{e}"
    );
    let e = s.get("autopiloot.roll_mode").unwrap_err().to_string();
    assert!(
        e.contains("no instance 'autopiloot'") && e.contains("autopilot"),
        "{e}"
    );
    let mut other = start(&sys, &fmus);
    let cp = other.checkpoint().unwrap();
    let e = s.restore(&cp).unwrap_err().to_string();
    assert!(e.contains("taken by another session"), "{e}");
    s.close().unwrap();
    s.close().unwrap();
    for e in [
        s.step(1).unwrap_err(),
        s.set("autopilot.roll_mode", Value::Integer(0)).unwrap_err(),
        s.get("ship.roll").unwrap_err(),
        s.checkpoint().unwrap_err(),
        s.restore(&cp).unwrap_err(),
    ] {
        assert!(e.to_string().contains("it is closed"), "{e}");
    }
}

/// The C test FMU integrating u = 1, failing (fmi2Error) or ending the run (fmi2Discard +
/// fmi2Terminated) at the given steps.
fn test_session(dir: &Path, fail_at: i32, terminate_at: i32) -> Session {
    test_fmu(dir);
    let path = write_system(
        dir,
        "fail.toml",
        &format!(
            "[simulation]\nstop_time = 1.0\nstep_size = 0.1\n[[instances]]\nname = \"m\"\n\
             fmu = \"testfmu.fmu\"\nparameters = {{ u = 1.0, fail_at_step = {fail_at}, terminate_at_step = {terminate_at} }}\n"
        ),
    );
    let sys = System::load(&path).unwrap();
    let fmus = load_fmus(&sys).unwrap();
    Session::start(sys, fmus, SessionOptions::default()).unwrap()
}

#[test]
fn a_failed_session_says_so_and_closes() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = test_session(dir.path(), 3, -1);
    s.step(2).unwrap();
    let e = s.step(5).unwrap_err();
    assert!(matches!(e, shipsim::Error::Fmi { .. }), "{e}");
    assert!(
        matches!(s.state(), State::Failed(m) if m.contains("fmi2DoStep")),
        "{:?}",
        s.state()
    );
    for e in [
        s.step(1).unwrap_err(),
        s.set("m.u", Value::Real(2.0)).unwrap_err(),
        s.get("m.y").unwrap_err(),
        s.checkpoint().unwrap_err(),
    ] {
        assert!(
            e.to_string().contains("it failed: ") && e.to_string().contains("fmi2DoStep"),
            "{e}"
        );
    }
    s.close().unwrap();
}

#[test]
fn an_fmu_that_ends_the_run_ends_the_session() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = test_session(dir.path(), -1, 4);
    assert_eq!(s.step(100).unwrap(), 0.5);
    assert!(
        matches!(s.state(), State::Ended(Some(r)) if r.contains("instance 'm' ended the simulation")),
        "{:?}",
        s.state()
    );
    let e = s.step(1).unwrap_err().to_string();
    assert!(
        e.contains("cannot step: instance 'm' ended the simulation"),
        "{e}"
    );
    // Readable still: the FMU's state at its end (it integrated four steps, y = 4 * 0.1 * u).
    assert_eq!(s.get("m.y").unwrap(), TypedValue::Real(0.4));
    s.close().unwrap();
}

#[test]
fn get_reads_what_the_connections_see_between_the_steps_of_a_slower_instance() {
    // filter and autopilot step every 2 base steps: at t = 0.05 s they are already at 0.1 s,
    // but what they published (and what the rows hold) is the value of t = 0 s.
    let (sys, fmus) = rrs(1.0, Algorithm::Jacobi);
    let mut s = start(&sys, &fmus);
    for _ in 0..6 {
        s.step(1).unwrap();
        let j = s.rows().time.len() - 1;
        for name in [
            "filter.roll_estimate",
            "autopilot.rudder_command",
            "ship.roll",
        ] {
            let recorded = s.rows().column(name).unwrap()[j];
            let got = match s.get(name).unwrap() {
                TypedValue::Real(x) => x,
                v => panic!("{v:?}"),
            };
            let t = s.time();
            assert_eq!(got.to_bits(), recorded.to_bits(), "{name} at t = {t}");
        }
    }
    assert_ne!(
        s.get("filter.roll_estimate").unwrap(),
        TypedValue::Real(0.0)
    );
}

#[test]
fn a_session_without_a_journal_keeps_none() {
    let (sys, fmus) = rrs(1.0, Algorithm::Jacobi);
    let opts = SessionOptions {
        journal: Journaling::Off,
        ..Default::default()
    };
    let mut s = Session::start(sys, fmus, opts).unwrap();
    for _ in 0..10 {
        s.set("autopilot.lambda", Value::Real(3.0)).unwrap();
        s.step(1).unwrap();
    }
    assert!(s.journal().records.is_empty());
    let e = s.journal_text().unwrap_err().to_string();
    assert!(e.contains("keeps no journal"), "{e}");
}
