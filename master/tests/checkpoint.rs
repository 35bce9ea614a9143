//! Master-level checkpoints on our FMUs ($SHIPSIM_FMU_DIR): a run continued from a checkpoint
//! gives, bit for bit, the rows of the uninterrupted run; a fork (warm-up without an event,
//! then the event from the checkpoint) gives, bit for bit, the cold run with the event; the
//! CLI's --checkpoint-at/--resume give the tail of the full CSV byte for byte; truncated,
//! hostile and foreign checkpoints and times off the grid are clear errors.
//!
//! Tolerance: none. Every comparison of results is of the f64 bit patterns.
mod common;
use common::*;
use shipsim::fmu::Fmu;
use shipsim::run::{
    checkpoint_step, load_fmus, resume_into, run_into, run_to_checkpoint, Checkpoint,
    CheckpointRequest, MemoryRecorder, RunOptions,
};
use shipsim::system::{Algorithm, Plan, System, Value};
use shipsim::Error;
use std::path::Path;
use std::process::Command;
use std::sync::Arc;

fn plan(sys: &System, fmus: &[Arc<Fmu>]) -> Plan {
    let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
    sys.validate(&mds).unwrap()
}

fn full_run(plan: &Plan, fmus: &[Arc<Fmu>], opts: &RunOptions) -> Vec<Vec<u64>> {
    let mut m = MemoryRecorder::new();
    run_into(plan, fmus, Some(&mut m), opts).unwrap();
    rows(&m)
}

/// The rows of a run continued from `cp` with `plan`.
fn resumed(plan: &Plan, fmus: &[Arc<Fmu>], cp: &Checkpoint) -> Vec<Vec<u64>> {
    let mut m = MemoryRecorder::new();
    let s = resume_into(plan, fmus, cp, Some(&mut m), &RunOptions::default()).unwrap();
    assert_eq!(s.macro_steps, plan.n_steps - cp.step);
    assert_eq!(s.start_time, cp.time);
    assert_eq!(s.rows as usize, m.time.len());
    rows(&m)
}

/// The index of the row at time `t` (bit-equal).
fn row_at(rows: &[Vec<u64>], t: f64) -> usize {
    rows.iter()
        .position(|r| r[0] == t.to_bits())
        .unwrap_or_else(|| panic!("no row at t = {t}"))
}

/// Checkpoint, resume and compare with the uninterrupted run, at base step `k`.
fn check_resume(plan: &Plan, fmus: &[Arc<Fmu>], k: u64, label: &str) {
    let full = full_run(plan, fmus, &RunOptions::default());
    let mut warm = MemoryRecorder::new();
    let cp = run_to_checkpoint(plan, fmus, k, Some(&mut warm), &RunOptions::default()).unwrap();
    assert_eq!(cp.step, k);
    let i = row_at(&full, cp.time);
    assert_eq!(i as u64, k, "{label}: decimation 1, row k is t_k");
    // The warm-up recorded what the full run records up to t_k.
    assert_eq!(rows(&warm), full[..=i], "{label}: warm-up rows");
    // Through a file and back: the same checkpoint.
    let d = tempfile::tempdir().unwrap();
    let file = d.path().join("cp.bin");
    cp.write(&file).unwrap();
    let back = Checkpoint::read(&file).unwrap();
    assert_eq!(back.encode().unwrap(), cp.encode().unwrap(), "{label}");
    assert_eq!(back.states, cp.states, "{label}");
    let tail = resumed(plan, fmus, &back);
    assert_eq!(tail.len(), full.len() - i, "{label}: row count");
    assert!(
        tail == full[i..],
        "{label}: resumed rows differ from the full run"
    );
}

#[test]
fn resume_gives_the_uninterrupted_run_bit_for_bit() {
    // RRS (Jacobi, sensors/filter/autopilot at step multiple 2): at an even and an odd step,
    // where the slow instances are mid-step and their published outputs are older than
    // their states.
    let sys = our_system("rrs.toml", 60.0, Algorithm::Jacobi);
    let fmus = load_fmus(&sys).unwrap();
    let p = plan(&sys, &fmus);
    assert_eq!(p.n_steps, 1200);
    check_resume(&p, &fmus, 400, "rrs jacobi k=400");
    check_resume(&p, &fmus, 401, "rrs jacobi k=401");
    // Gauss-Seidel: the path-keeping system and RRS.
    let sys = our_system("path_control_current.toml", 120.0, Algorithm::GaussSeidel);
    let fmus = load_fmus(&sys).unwrap();
    let p = plan(&sys, &fmus);
    check_resume(&p, &fmus, 250, "path control gauss-seidel");
    let sys = our_system("rrs.toml", 60.0, Algorithm::GaussSeidel);
    let fmus = load_fmus(&sys).unwrap();
    check_resume(&plan(&sys, &fmus), &fmus, 333, "rrs gauss-seidel k=333");
}

#[test]
fn resume_keeps_the_decimation_phase() {
    let mut sys = our_system("rrs.toml", 30.0, Algorithm::Jacobi);
    let fmus = load_fmus(&sys).unwrap();
    let every = full_run(&plan(&sys, &fmus), &fmus, &RunOptions::default());
    sys.output.decimation = 7;
    let p = plan(&sys, &fmus);
    let full = full_run(&p, &fmus, &RunOptions::default());
    assert_eq!(full.len(), 600 / 7 + 2, "t0, every 7th step, t_n");
    let cp = run_to_checkpoint(&p, &fmus, 100, None, &RunOptions::default()).unwrap();
    let tail = resumed(&p, &fmus, &cp);
    // First the row at t_100 (not a multiple of 7), then the full run's rows after it.
    assert_eq!(tail[0], every[100]);
    let after = full
        .iter()
        .position(|r| f64::from_bits(r[0]) > cp.time)
        .unwrap();
    assert_eq!(after, 100 / 7 + 1);
    assert!(tail[1..] == full[after..]);
}

/// Options that write a checkpoint at base step `step` to `file`.
fn writing(step: u64, file: &Path) -> RunOptions {
    RunOptions {
        checkpoint: Some(CheckpointRequest {
            step,
            file: file.to_path_buf(),
        }),
        ..Default::default()
    }
}

#[test]
fn writing_a_checkpoint_during_a_run_changes_nothing() {
    let sys = our_system("rrs.toml", 40.0, Algorithm::Jacobi);
    let fmus = load_fmus(&sys).unwrap();
    let p = plan(&sys, &fmus);
    let d = tempfile::tempdir().unwrap();
    let file = d.path().join("sub/dir/cp.bin");
    let with = full_run(&p, &fmus, &writing(321, &file));
    let without = full_run(&p, &fmus, &RunOptions::default());
    assert!(with == without, "taking a checkpoint changed the run");
    let written = std::fs::read(&file).unwrap();
    let returned = run_to_checkpoint(&p, &fmus, 321, None, &RunOptions::default()).unwrap();
    assert_eq!(written, returned.encode().unwrap());
    // A resumed run may write a later checkpoint: resuming from that one gives the same tail.
    let later = d.path().join("later.bin");
    let mut m = MemoryRecorder::new();
    resume_into(&p, &fmus, &returned, Some(&mut m), &writing(700, &later)).unwrap();
    assert!(rows(&m) == without[321..]);
    let tail = resumed(&p, &fmus, &Checkpoint::read(&later).unwrap());
    assert!(tail == without[700..]);
}

/// Cold run A: `sys` with the event `target = value` at t_k. Fork B: warm-up of `sys` without
/// it to t_k, then the plan with the event from the checkpoint. A and B agree bit for bit from
/// t_k on, and the event changes the run (else the test could not fail).
fn check_fork(sys: &System, k: u64, target: &str, values: &[Value], label: &str) {
    let fmus = load_fmus(sys).unwrap();
    let base = plan(sys, &fmus);
    let t = base.start_time + k as f64 * base.step_size;
    assert_eq!(checkpoint_step(&base, t).unwrap(), k);
    let warm = run_to_checkpoint(&base, &fmus, k, None, &RunOptions::default()).unwrap();
    let unchanged = full_run(&base, &fmus, &RunOptions::default());
    let i = row_at(&unchanged, warm.time);
    for value in values {
        let forked = with_event(sys, t, target, value.clone());
        let p = plan(&forked, &fmus);
        assert_eq!(p.events.last().unwrap().step, k);
        let cold = full_run(&p, &fmus, &RunOptions::default());
        let fork = resumed(&p, &fmus, &warm);
        assert!(
            fork == cold[i..],
            "{label}: fork {target} = {value} differs from the cold run"
        );
        assert!(cold[..=i] == unchanged[..=i], "{label}: before the event");
        let changed = cold[i + 1..]
            .iter()
            .zip(&unchanged[i + 1..])
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            changed > (cold.len() - i) / 2,
            "{label}: {target} = {value} changed only {changed} rows"
        );
    }
}

#[test]
fn a_fork_from_a_warm_up_equals_the_cold_run_with_the_event() {
    let rrs = our_system("rrs.toml", 90.0, Algorithm::Jacobi);
    check_fork(
        &rrs,
        601,
        "autopilot.roll_mode",
        &[Value::Integer(0)],
        "rrs jacobi",
    );
    check_fork(
        &rrs,
        600,
        "waves.wave_direction",
        &[Value::Real(0.5), Value::Real(2.5)],
        "rrs jacobi",
    );
    let rrs_gs = our_system("rrs.toml", 90.0, Algorithm::GaussSeidel);
    check_fork(
        &rrs_gs,
        600,
        "autopilot.roll_mode",
        &[Value::Integer(0)],
        "rrs gauss-seidel",
    );
    let path = our_system("path_control_current.toml", 150.0, Algorithm::GaussSeidel);
    check_fork(
        &path,
        300,
        "sensors.noise_scale",
        &[Value::Real(3.0), Value::Real(0.0)],
        "path control gauss-seidel",
    );
}

/// A checkpoint is refused by another system, naming the difference.
#[test]
fn a_checkpoint_from_another_system_is_refused() {
    let sys = our_system("rrs.toml", 30.0, Algorithm::Jacobi);
    let fmus = load_fmus(&sys).unwrap();
    let p = plan(&sys, &fmus);
    let cp = run_to_checkpoint(&p, &fmus, 200, None, &RunOptions::default()).unwrap();
    let refused = |sys: &System| -> String {
        let fmus = load_fmus(sys).unwrap();
        let p = plan(sys, &fmus);
        let e = resume_into(&p, &fmus, &cp, None, &RunOptions::default()).unwrap_err();
        e.to_string()
    };
    let e = refused(&our_system("rrs.toml", 40.0, Algorithm::Jacobi));
    assert!(
        e.contains("different system") && e.contains("600 base steps"),
        "{e}"
    );
    let e = refused(&our_system("rrs.toml", 30.0, Algorithm::GaussSeidel));
    assert!(e.contains("algorithm Jacobi in the checkpoint"), "{e}");
    let e = refused(&our_system(
        "path_control_current.toml",
        30.0,
        Algorithm::Jacobi,
    ));
    assert!(e.contains("7 instances (ship, gear, waves"), "{e}");
    let mut other = sys.clone();
    other.instances[4].step_multiple = 1;
    let e = refused(&other);
    assert!(e.contains("instance 'sensors': step_multiple 2"), "{e}");
    let mut other = sys.clone();
    other.output.variables = Some(vec!["ship.heading".into()]);
    let e = refused(&other);
    assert!(
        e.contains("connection or recorded output 23 is 'ship.roll' in the checkpoint, 'ship.heading' in this system"),
        "{e}"
    );
    other.output.variables = Some(vec!["ship.roll".into()]);
    let e = refused(&other);
    assert!(
        e.contains("36 connections and recorded outputs in the checkpoint, 23 in this system"),
        "{e}"
    );
    // Another FMU under the same instance name: the GUID differs.
    let mut other = sys.clone();
    other.instances[3].fmu = our_fmu("Waves");
    other.instances[3].values.clear();
    other
        .connections
        .retain(|c| c.from.instance != "wind" && c.to.instance != "wind");
    other.output.variables = Some(vec!["ship.roll".into()]);
    let e = refused(&other);
    assert!(
        e.contains("instance 'wind': FMU GUID") && e.contains("a different FMU"),
        "{e}"
    );
    // Start values and connection gains change the result: refused, naming them (issue 38,
    // item 3; before, a resume under them gave a hybrid of the two systems).
    let mut other = sys.clone();
    other
        .apply_overrides(&["gear.time_constant=0.5".into()])
        .unwrap();
    let e = refused(&other);
    assert!(
        e.contains("gear.time_constant is 0.2 in the checkpoint, 0.5 in this system"),
        "{e}"
    );
    let mut other = sys.clone();
    other.connections[0].gain *= 10.0;
    let e = refused(&other);
    assert!(
        e.contains("connection waves.roll_moment -> ship.roll_disturbance (gain 1, offset 0) in the checkpoint, waves.roll_moment -> ship.roll_disturbance (gain 10, offset 0) in this system"),
        "{e}"
    );
    // An event before the checkpoint made the run it holds: one added there is refused.
    let e = refused(&with_event(
        &sys,
        5.0,
        "autopilot.roll_mode",
        Value::Integer(0),
    ));
    assert!(
        e.contains("0 event(s) before t = 10 s in the checkpoint, 1 in this system"),
        "{e}"
    );
}

/// Another build of an FMU under the same GUID is another FMU: refused, naming the instance.
#[test]
fn a_checkpoint_from_another_build_of_an_fmu_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let sys = our_system("rrs.toml", 30.0, Algorithm::Jacobi);
    let fmus = load_fmus(&sys).unwrap();
    let cp =
        run_to_checkpoint(&plan(&sys, &fmus), &fmus, 200, None, &RunOptions::default()).unwrap();
    // The same archive with one more file: same GUID, other bytes.
    let copy = d.path().join("SteeringGear.fmu");
    std::fs::copy(&sys.instances[1].fmu, &copy).unwrap();
    let file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(&copy)
        .unwrap();
    let mut zip = zip::ZipWriter::new_append(file).unwrap();
    zip.start_file(
        "documentation/rebuilt.txt",
        zip::write::SimpleFileOptions::default(),
    )
    .unwrap();
    std::io::Write::write_all(&mut zip, b"another build").unwrap();
    zip.finish().unwrap();
    let mut other = sys.clone();
    other.instances[1].fmu = copy;
    let fmus = load_fmus(&other).unwrap();
    assert_eq!(fmus[1].guid(), load_fmus(&sys).unwrap()[1].guid());
    let e = resume_into(
        &plan(&other, &fmus),
        &fmus,
        &cp,
        None,
        &RunOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("instance 'gear': the FMU file has SHA-256") && e.contains("another build"),
        "{e}"
    );
}

/// `Checkpoint::adopt`: a new value of a tunable parameter becomes an event at the
/// checkpoint's step, so the resumed run is the cold run with that event, bit for bit.
#[test]
fn a_new_tunable_value_is_adopted_as_an_event_at_the_checkpoint() {
    let sys = our_system("rrs.toml", 30.0, Algorithm::Jacobi);
    let fmus = load_fmus(&sys).unwrap();
    let cp =
        run_to_checkpoint(&plan(&sys, &fmus), &fmus, 200, None, &RunOptions::default()).unwrap();
    let mut changed = sys.clone();
    changed
        .apply_overrides(&[
            "autopilot.roll_mode=0".into(),
            "gear.time_constant=0.5".into(),
        ])
        .unwrap();
    let mut p = plan(&changed, &fmus);
    let notes = cp.adopt(&mut p, &fmus);
    assert_eq!(notes.len(), 2, "{notes:?}");
    assert!(
        notes.iter().any(
            |n| n.starts_with("gear.time_constant = 0.5: applied at t = 10 s")
                && n.ends_with("(the checkpoint's run had 0.2)")
        ),
        "{notes:?}"
    );
    let tail = resumed(&p, &fmus, &cp);
    let cold = with_event(&sys, 10.0, "autopilot.roll_mode", Value::Integer(0));
    let cold = with_event(&cold, 10.0, "gear.time_constant", Value::Real(0.5));
    let full = full_run(&plan(&cold, &fmus), &fmus, &RunOptions::default());
    assert!(
        tail == full[200..],
        "the adopted resume differs from the cold run"
    );
    assert!(tail != full_run(&plan(&sys, &fmus), &fmus, &RunOptions::default())[200..]);
    // A fixed parameter cannot change after initialization: left for `check` to refuse.
    let mut fixed = sys.clone();
    fixed
        .apply_overrides(&["gear.servo_order=2".into()])
        .unwrap();
    let mut p = plan(&fixed, &fmus);
    assert!(cp.adopt(&mut p, &fmus).is_empty());
    let e = resume_into(&p, &fmus, &cp, None, &RunOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("gear.servo_order is not set in the checkpoint, 2 in this system")
            && e.contains("a fixed parameter cannot change after initialization"),
        "{e}"
    );
}

#[test]
fn truncated_corrupt_and_hostile_files_are_clear_errors() {
    let sys = our_system("rrs.toml", 10.0, Algorithm::Jacobi);
    let fmus = load_fmus(&sys).unwrap();
    let p = plan(&sys, &fmus);
    let cp = run_to_checkpoint(&p, &fmus, 100, None, &RunOptions::default()).unwrap();
    let bytes = cp.encode().unwrap();
    let file = Path::new("/some/where/cp.bin");
    let decode_err = |b: &[u8]| match Checkpoint::decode(b, file) {
        Ok(_) => panic!("decoded {} bytes", b.len()),
        Err(e @ Error::Checkpoint { .. }) => e.to_string(),
        Err(e) => panic!("{e}"),
    };
    assert!(Checkpoint::decode(&bytes, file).is_ok());
    for n in 0..bytes.len() {
        let e = decode_err(&bytes[..n]);
        assert!(e.starts_with("checkpoint file /some/where/cp.bin: "), "{e}");
        assert!(
            e.contains("truncated") || (n < 8 && e.contains("magic")),
            "{n}: {e}"
        );
    }
    // Every byte changed: an error, never a panic, an allocation or a wrong checkpoint.
    for i in 0..bytes.len() {
        let mut b = bytes.clone();
        b[i] ^= 0x5a;
        decode_err(&b);
    }
    // A count of 2^32 - 1 instances is checked against the bytes left before any allocation.
    let mut b = bytes.clone();
    b[53..57].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = decode_err(&b);
    assert!(
        e.contains("4294967295 instances") && e.contains("truncated or corrupt"),
        "{e}"
    );
    // Version 1 (before the fingerprint covered connections, start values and events) and a
    // future version.
    for (v, said) in [
        (1u32, "from an older shipsim: take the checkpoint again"),
        (3, "from a newer shipsim"),
    ] {
        let mut b = bytes.clone();
        b[8..12].copy_from_slice(&v.to_le_bytes());
        let e = decode_err(&b);
        assert!(
            e.contains(&format!("format version {v}; this shipsim reads version 2"))
                && e.contains(said),
            "{e}"
        );
    }
    let mut b = bytes.clone();
    b.push(0);
    assert!(decode_err(&b).contains("checksum"));
    // A foreign file, and a missing one.
    let e = Checkpoint::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("Cargo.toml")
            .as_path(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("Cargo.toml: not a shipsim checkpoint"), "{e}");
    let e = Checkpoint::read(Path::new("/no/such/cp.bin")).unwrap_err();
    assert!(e.to_string().contains("/no/such/cp.bin"), "{e}");
}

#[test]
fn checkpoint_times_must_be_inside_the_grid() {
    let sys = our_system("rrs.toml", 10.0, Algorithm::Jacobi);
    let fmus = load_fmus(&sys).unwrap();
    let p = plan(&sys, &fmus);
    assert_eq!(checkpoint_step(&p, 5.0).unwrap(), 100);
    assert_eq!(checkpoint_step(&p, 0.05).unwrap(), 1);
    for t in [5.01, 0.0, 10.0, 12.0, -1.0, f64::NAN] {
        let e = checkpoint_step(&p, t).unwrap_err().to_string();
        assert!(e.contains("base-step point"), "{t}: {e}");
    }
    let e = run_to_checkpoint(&p, &fmus, 200, None, &RunOptions::default()).unwrap_err();
    assert!(e.to_string().contains("before the end at step 200"), "{e}");
}

#[test]
fn an_fmu_without_state_functions_is_refused_before_the_run() {
    let d = tempfile::tempdir().unwrap();
    let fmu = test_fmu(d.path());
    let p = write_system(
        d.path(),
        "a.toml",
        "[simulation]\nstop_time = 1.0\nstep_size = 0.1\n[[instances]]\nname = \"a\"\nfmu = \"testfmu.fmu\"\n",
    );
    let sys = System::load(&p).unwrap();
    let fmus = load_fmus(&sys).unwrap();
    let plan = plan(&sys, &fmus);
    let mut m = MemoryRecorder::new();
    let e = run_to_checkpoint(&plan, &fmus, 5, Some(&mut m), &RunOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("FMU '{}'", fmu.display()))
            && e.contains("instance 'a'")
            && e.contains("canGetAndSetFMUstate"),
        "{e}"
    );
    assert!(m.time.is_empty(), "refused before the first row");
}

// ---- the command line ----

/// `shipsim run SYSTEM --stop-time 30 -q ARGS`: (success, stderr).
fn shipsim_run(system: &Path, args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .arg("run")
        .arg(system)
        .args(["--stop-time", "30", "-q"])
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn cli_checkpoint_then_resume_gives_the_tail_of_the_full_csv() {
    let d = tempfile::tempdir().unwrap();
    let sys = rrs_file(d.path());
    let path = |n: &str| d.path().join(n).display().to_string();
    let (ok, err) = shipsim_run(&sys, &["-o", &path("plain.csv")]);
    assert!(ok, "{err}");
    let (ok, err) = shipsim_run(
        &sys,
        &[
            "-o",
            &path("full.csv"),
            "--checkpoint-at",
            "12.35",
            &path("cp.bin"),
        ],
    );
    assert!(ok, "{err}");
    let (ok, err) = shipsim_run(
        &sys,
        &["-o", &path("tail.csv"), "--resume", &path("cp.bin")],
    );
    assert!(ok, "{err}");
    let read = |n: &str| std::fs::read_to_string(d.path().join(n)).unwrap();
    let (plain, full, tail) = (read("plain.csv"), read("full.csv"), read("tail.csv"));
    assert_eq!(plain, full, "--checkpoint-at changed the output");
    let full: Vec<&str> = full.lines().collect();
    let tail: Vec<&str> = tail.lines().collect();
    assert_eq!(full.len(), 1 + 601);
    assert!(full[1 + 247].starts_with("12.35,"), "{}", full[1 + 247]);
    assert_eq!(tail[0], full[0], "header");
    assert_eq!(tail[1..], full[1 + 247..]);

    // Resuming under another --stop-time is refused, naming the file and the difference.
    let out = Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .arg("run")
        .arg(&sys)
        .args(["--stop-time", "31", "-q", "--resume", &path("cp.bin")])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains(&format!("checkpoint file {}", path("cp.bin")))
            && err.contains("different system")
            && err.contains("620 (t = 31 s) in this system"),
        "{err}"
    );
}

#[test]
fn cli_refuses_times_off_the_grid_and_truncated_files() {
    let d = tempfile::tempdir().unwrap();
    let sys = rrs_file(d.path());
    let cp = d.path().join("cp.bin").display().to_string();
    for t in ["12.34", "0", "30", "45", "soon"] {
        let (ok, err) = shipsim_run(&sys, &["--checkpoint-at", t, &cp]);
        assert!(!ok && err.contains("--checkpoint-at"), "{t}: {err}");
        assert!(
            err.contains("base-step point") || err.contains("a time in seconds"),
            "{t}: {err}"
        );
    }
    assert!(!Path::new(&cp).exists());
    let (ok, err) = shipsim_run(&sys, &["--checkpoint-at", "10", &cp]);
    assert!(ok, "{err}");
    let bytes = std::fs::read(&cp).unwrap();
    std::fs::write(&cp, &bytes[..bytes.len() / 2]).unwrap();
    let (ok, err) = shipsim_run(&sys, &["--resume", &cp]);
    assert!(
        !ok && err.contains(&format!("checkpoint file {cp}: truncated")),
        "{err}"
    );
}

/// `--resume` with `--set` (issue 38, item 3): a tunable parameter's new value applies at the
/// checkpoint's time, said in a note, and the rows are those of the cold run with that event
/// (before, they were those of the unchanged run); a fixed parameter's new value and an edited
/// connection gain are refused, naming them.
#[test]
fn cli_resume_applies_a_tunable_set_at_the_checkpoint_and_refuses_the_rest() {
    let d = tempfile::tempdir().unwrap();
    let sys = rrs_file(d.path());
    let path = |n: &str| d.path().join(n).display().to_string();
    let (ok, err) = shipsim_run(
        &sys,
        &[
            "-o",
            &path("full.csv"),
            "--checkpoint-at",
            "12.35",
            &path("cp.bin"),
        ],
    );
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&sys).unwrap();
    let cold = text.replace(
        "\n[output]",
        "\n[[events]]\ntime = 12.35\nset = \"autopilot.roll_mode\"\nvalue = 0\n\n[output]",
    );
    assert_ne!(cold, text);
    let cold_sys = write_system(d.path(), "cold.toml", &cold);
    let (ok, err) = shipsim_run(&cold_sys, &["-o", &path("cold.csv")]);
    assert!(ok, "{err}");
    let (ok, err) = shipsim_run(
        &sys,
        &[
            "-o",
            &path("tail.csv"),
            "--resume",
            &path("cp.bin"),
            "--set",
            "autopilot.roll_mode=0",
        ],
    );
    assert!(ok, "{err}");
    assert!(
        err.contains("note: autopilot.roll_mode = 0: applied at t = 12.35 s, the checkpoint's time, as an event (the checkpoint's run had 1)"),
        "{err}"
    );
    let read = |n: &str| std::fs::read_to_string(d.path().join(n)).unwrap();
    let (full, cold, tail) = (read("full.csv"), read("cold.csv"), read("tail.csv"));
    let lines = |t: &str| t.lines().map(str::to_string).collect::<Vec<_>>();
    let (full, cold, tail) = (lines(&full), lines(&cold), lines(&tail));
    assert_eq!(
        tail[1..],
        cold[1 + 247..],
        "the resume is not the cold run with the event"
    );
    assert_ne!(tail[1..], full[1 + 247..], "roll_mode=0 changed nothing");

    let (ok, err) = shipsim_run(
        &sys,
        &[
            "--no-output",
            "--resume",
            &path("cp.bin"),
            "--set",
            "gear.servo_order=2",
        ],
    );
    assert!(
        !ok && err.contains("gear.servo_order is not set in the checkpoint, 2 in this system"),
        "{err}"
    );
    let edited = write_system(
        d.path(),
        "edited.toml",
        &text.replacen("convert = true", "convert = true\ngain = 10.0", 1),
    );
    let (ok, err) = shipsim_run(&edited, &["--no-output", "--resume", &path("cp.bin")]);
    assert!(
        !ok && err.contains(&format!("checkpoint file {}", path("cp.bin")))
            && err.contains("(gain 10, offset 0) in this system"),
        "{err}"
    );
}
