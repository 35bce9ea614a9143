//! Crash isolation (docs/isolation.md): FMUs that segfault, abort, call exit(), hang or return
//! NaN (tests/c/evilfmu.c, built with gcc at test time). With `--isolate` each run exits
//! non-zero with a message naming the instance, the call and the time, and its CSV holds every
//! completed step; in process, an FMU calling exit() no longer ends shipsim with status 0.
//! Isolated runs give the same bytes as runs in process, and their step loop allocates nothing.
mod common;
use common::*;
use shipsim::fmu::Unpack;
use shipsim::isolate::{IsolateMode, Isolation};
use shipsim::run::{load_fmus_with, run, Output, RunOptions};
use shipsim::system::System;
use std::alloc::{GlobalAlloc, Layout, System as SysAlloc};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::process::{Command, Output as ProcOutput};

/// Counts the allocations of each thread (the tests of this file run in parallel threads).
struct Counting;
thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}
fn allocs() -> usize {
    ALLOCS.with(|c| c.get())
}
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        SysAlloc.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        SysAlloc.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        SysAlloc.realloc(p, l, n)
    }
}
#[global_allocator]
static A: Counting = Counting;

const SHIPSIM: &str = env!("CARGO_BIN_EXE_shipsim");

/// Builds `dir/<name>.fmu` from tests/c/evilfmu.c with `defines` (the test FMU's model
/// description).
fn evil_fmu(dir: &Path, name: &str, defines: &[&str]) -> PathBuf {
    let so = compile(dir, name, &c_source("evilfmu.c"), defines);
    let fmu = dir.join(format!("{name}.fmu"));
    zip_files(
        &fmu,
        &[
            (
                "modelDescription.xml",
                model_description(GUID, "2.0").into_bytes(),
            ),
            ("binaries/linux64/testfmu.so", std::fs::read(so).unwrap()),
        ],
    );
    fmu
}

/// A 1 s run at 0.1 s of a good test FMU `good` and the FMU `evil.fmu`, both integrating
/// u = 1, recording both outputs into out.csv.
fn system(dir: &Path) -> PathBuf {
    test_fmu(dir);
    write_system(
        dir,
        "sys.toml",
        r#"
[simulation]
stop_time = 1.0
step_size = 0.1
[[instances]]
name = "good"
fmu = "testfmu.fmu"
parameters = { u = 1.0 }
[[instances]]
name = "evil"
fmu = "evil.fmu"
parameters = { u = 1.0 }
[output]
file = "out.csv"
variables = ["good.y", "evil.y"]
"#,
    )
}

/// `shipsim ARGS` in `dir` that fails with status 1: its stderr.
fn failing(dir: &Path, args: &[&str]) -> String {
    let out = shipsim(dir, args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    err
}

fn shipsim(dir: &Path, args: &[&str]) -> ProcOutput {
    Command::new(SHIPSIM)
        .current_dir(dir)
        .env("TMPDIR", dir)
        .args(args)
        .output()
        .unwrap()
}

/// The CSV holds exactly the rows t = 0, 0.1, 0.2, 0.3 (three completed steps before the
/// misbehaving fourth), with y = t (explicit Euler of dx/dt = 1 from 0: a sum of the step
/// sizes, within 1e-15 of t), the same in both instances to the bit.
fn assert_three_steps_kept(dir: &Path) {
    let (header, rows) = read_csv(&dir.join("out.csv"));
    assert_eq!(header, ["time", "good.y", "evil.y"]);
    let times: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(times, [0.0, 0.1, 0.2, 0.3]);
    for r in &rows {
        assert!(
            (r[1] - r[0]).abs() <= 1e-15,
            "good.y at t = {}: {}",
            r[0],
            r[1]
        );
        assert_eq!(r[2].to_bits(), r[1].to_bits(), "evil.y at t = {}", r[0]);
    }
}

/// No extraction directory is left behind in `dir` (the runs' TMPDIR).
fn assert_no_temp_dirs(dir: &Path) {
    let left: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("shipsim-fmu-"))
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

/// Runs the system isolated with `evil.fmu` built with `defines`; returns stderr.
fn isolated_failure(defines: &[&str], extra: &[&str]) -> (tempfile::TempDir, String) {
    let d = tempfile::tempdir().unwrap();
    evil_fmu(d.path(), "evil", defines);
    system(d.path());
    let mut args = vec!["run", "sys.toml", "-q", "--isolate"];
    args.extend_from_slice(extra);
    let err = failing(d.path(), &args);
    (d, err)
}

fn assert_names_call(err: &str, what: &str) {
    assert!(
        err.contains("error: instance 'evil': the FMU's process")
            && err.contains(what)
            && err.contains("during fmi2DoStep at t = 0.3 s"),
        "{err}"
    );
    // The FMU's last message, sent before it misbehaved, is in the error.
    assert!(err.contains("misbehaving now at t = 0.3"), "{err}");
}

/// A segfault, abort() and exit(0) in an isolated FMU: each an error naming the instance, the
/// call, the time and how its process ended; every completed step kept; nothing left behind.
#[test]
fn isolated_crashes_are_errors_and_keep_every_completed_step() {
    for (define, how) in [
        ("EVIL_SEGV", "was killed by signal 11 (SIGSEGV"),
        ("EVIL_ABORT", "was killed by signal 6 (SIGABRT"),
        (
            "EVIL_EXIT=0",
            "exited with status 0 (the FMU called exit())",
        ),
    ] {
        let (d, err) = isolated_failure(&[define], &[]);
        assert_names_call(&err, how);
        assert_three_steps_kept(d.path());
        assert_no_temp_dirs(d.path());
    }
}

/// `isolate = true` on an instance in the system file isolates it without the option: its
/// segfault is the same error, with every completed step kept (in process it would end shipsim
/// with SIGSEGV and an empty CSV). The other instance runs in process.
#[test]
fn isolate_true_in_the_system_file_isolates_that_instance() {
    let d = tempfile::tempdir().unwrap();
    evil_fmu(d.path(), "evil", &["EVIL_SEGV"]);
    let sys = system(d.path());
    let text = std::fs::read_to_string(&sys).unwrap();
    let flagged = text.replace("name = \"evil\"\n", "name = \"evil\"\nisolate = true\n");
    assert_ne!(flagged, text);
    std::fs::write(&sys, flagged).unwrap();
    let err = failing(d.path(), &["run", "sys.toml", "-q"]);
    assert_names_call(&err, "was killed by signal 11 (SIGSEGV");
    assert_three_steps_kept(d.path());
    assert_no_temp_dirs(d.path());
    // OSP and SSP cannot carry it: the exports say so.
    for (cmd, out, format) in [
        (
            "export-osp",
            "OspSystemStructure.xml",
            "OspSystemStructure.xml",
        ),
        ("export-ssp", "sys.ssp", "SSP 1.0"),
    ] {
        let o = shipsim(d.path(), &[cmd, "sys.toml", "-o", out]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{cmd}: {err}");
        assert!(
            err.contains(&format!(
                "warning: `isolate = true` (evil) is not part of {format} and is left out: run \
                 it with --isolate=evil"
            )),
            "{cmd}: {err}"
        );
    }
    // The flag is a boolean; anything else is refused at its line (11).
    std::fs::write(
        &sys,
        text.replace("name = \"evil\"\n", "name = \"evil\"\nisolate = 1\n"),
    )
    .unwrap();
    let err = failing(d.path(), &["check", "sys.toml"]);
    assert!(
        err.contains("sys.toml:11: invalid type: integer `1`, expected a boolean"),
        "{err}"
    );
}

/// A library whose load-time initializer segfaults: isolated, the master never loads it (every
/// instance of the FMU is isolated), and the child's crash is an error naming the instance and
/// the call that loads it; nothing is left behind.
#[test]
fn isolated_crash_while_loading_the_library_is_an_error() {
    let d = tempfile::tempdir().unwrap();
    evil_fmu(d.path(), "evil", &["EVIL_LOAD_SEGV"]);
    system(d.path());
    let err = failing(d.path(), &["run", "sys.toml", "-q", "--isolate=evil"]);
    assert!(
        err.contains(
            "error: instance 'evil': the FMU's process was killed by signal 11 (SIGSEGV, a \
             segmentation fault) during fmi2Instantiate (isolated: the master and the other \
             instances are unaffected)"
        ),
        "{err}"
    );
    assert_no_temp_dirs(d.path());
}

#[test]
fn isolated_hang_is_killed_after_the_call_timeout() {
    let (d, err) = isolated_failure(&["EVIL_HANG"], &["--call-timeout", "0.5"]);
    assert!(
        err.contains("error: instance 'evil': fmi2DoStep at t = 0.3 s did not return within 0.5 s (the call time limit); its process was killed"),
        "{err}"
    );
    assert_three_steps_kept(d.path());
    assert_no_temp_dirs(d.path());
}

/// A NaN returned with fmi2OK and refused by the FMU it is passed to is blamed on the FMU
/// that produced it (the error names it and its variable first), in process and isolated.
#[test]
fn a_refused_nan_is_blamed_on_its_producer() {
    let d = tempfile::tempdir().unwrap();
    evil_fmu(d.path(), "evil", &["EVIL_NAN"]);
    evil_fmu(d.path(), "strict", &["EVIL_REJECT_NAN"]);
    write_system(
        d.path(),
        "sys.toml",
        "connections = [\"evil.y -> recv.u\"]\n[simulation]\nstop_time = 1.0\nstep_size = 0.1\n\
         [[instances]]\nname = \"evil\"\nfmu = \"evil.fmu\"\nparameters = { u = 1.0 }\n\
         [[instances]]\nname = \"recv\"\nfmu = \"strict.fmu\"\n",
    );
    for isolate in [false, true] {
        let mut args = vec!["run", "sys.toml", "-q"];
        if isolate {
            args.push("--isolate");
        }
        let err = failing(d.path(), &args);
        assert!(
            err.contains("error: 'evil.y' is NaN (its FMU returned it with fmi2OK), passed on by the connection evil.y -> recv.u: instance 'recv': fmi2SetReal returned fmi2Error"),
            "{err}"
        );
    }
}

#[test]
fn in_process_exit_0_is_not_success() {
    let d = tempfile::tempdir().unwrap();
    evil_fmu(d.path(), "evil", &["EVIL_EXIT=0"]);
    system(d.path());
    let err = failing(d.path(), &["run", "sys.toml", "-q"]);
    assert!(
        err.contains("error: instance 'evil' in fmi2DoStep at t = 0.3 s: the FMU ended the process (it called exit())"),
        "{err}"
    );
}

#[test]
fn in_process_hang_ends_the_process_after_the_call_timeout() {
    let d = tempfile::tempdir().unwrap();
    evil_fmu(d.path(), "evil", &["EVIL_HANG"]);
    system(d.path());
    let err = failing(
        d.path(),
        &["run", "sys.toml", "-q", "--call-timeout", "0.3"],
    );
    assert!(
        err.contains("error: instance 'evil' in fmi2DoStep at t = 0.3 s did not return within 0.3 s (--call-timeout)"),
        "{err}"
    );
}

/// FMI 2.0, sec. 4.2.4: an instance left in Initialization Mode by another's failure is freed
/// without fmi2Terminate (the evil FMU logs an error for that call, as ours do).
#[test]
fn failed_initialization_frees_without_terminate() {
    for isolate in [false, true] {
        let d = tempfile::tempdir().unwrap();
        evil_fmu(d.path(), "evil", &[]);
        evil_fmu(d.path(), "broken", &["EVIL_INIT_FAIL"]);
        write_system(
            d.path(),
            "sys.toml",
            "[simulation]\nstop_time = 1.0\nstep_size = 0.1\n\
             [[instances]]\nname = \"broken\"\nfmu = \"broken.fmu\"\n\
             [[instances]]\nname = \"a\"\nfmu = \"evil.fmu\"\n\
             [[instances]]\nname = \"b\"\nfmu = \"evil.fmu\"\n",
        );
        let mut args = vec!["run", "sys.toml", "-q"];
        if isolate {
            args.push("--isolate");
        }
        let err = failing(d.path(), &args);
        assert!(
            err.contains("error: instance 'broken': fmi2ExitInitializationMode returned fmi2Error"),
            "{err}"
        );
        assert!(!err.contains("fmi2Terminate is not allowed"), "{err}");
        assert_no_temp_dirs(d.path());
    }
}

/// A system with connections of every type, a multi-rate instance and an event.
fn rich_system(dir: &Path, stop: f64) -> PathBuf {
    test_fmu(dir);
    write_system(
        dir,
        "rich.toml",
        &format!(
            r#"
connections = ["a.y -> b.u", {{ from = "b.y2", to = "c.u", gain = 0.5 }}, "c.n_out -> a.n_in", "a.enabled_out -> c.enabled"]
[simulation]
stop_time = {stop}
step_size = 0.001
[[instances]]
name = "a"
fmu = "testfmu.fmu"
parameters = {{ u = 1.0 }}
[[instances]]
name = "b"
fmu = "testfmu.fmu"
step_multiple = 10
[[instances]]
name = "c"
fmu = "testfmu.fmu"
[[events]]
time = 0.5
set = "a.u"
value = 2.0
[output]
file = "rich.csv"
variables = ["a.y", "b.y", "c.y", "a.n_out", "c.enabled_out", "b.t_last"]
"#
        ),
    )
}

#[test]
fn isolated_runs_give_the_same_bytes() {
    let d = tempfile::tempdir().unwrap();
    rich_system(d.path(), 2.0);
    for (args, file) in [
        (vec!["-o", "in.csv"], "in.csv"),
        (vec!["-o", "iso.csv", "--isolate"], "iso.csv"),
        (vec!["-o", "b.csv", "--isolate=b"], "b.csv"),
        (
            vec!["-o", "foreign.csv", "--isolate=foreign"],
            "foreign.csv",
        ),
    ] {
        let mut a = vec!["run", "rich.toml", "-q"];
        a.extend(args);
        let out = shipsim(d.path(), &a);
        assert!(out.status.success(), "{out:?}");
        assert!(d.path().join(file).is_file());
    }
    let reference = std::fs::read(d.path().join("in.csv")).unwrap();
    assert_eq!(reference.iter().filter(|&&b| b == b'\n').count(), 2002);
    for f in ["iso.csv", "b.csv", "foreign.csv"] {
        assert!(std::fs::read(d.path().join(f)).unwrap() == reference, "{f}");
    }
    assert_no_temp_dirs(d.path());
}

#[test]
fn isolated_step_loop_allocates_nothing() {
    let d = tempfile::tempdir().unwrap();
    let p = rich_system(d.path(), 1.0);
    let mut sys = System::load(&p).unwrap();
    let iso = Isolation {
        mode: IsolateMode::All,
        host: Some(PathBuf::from(SHIPSIM)),
        ..Default::default()
    };
    let fmus = load_fmus_with(&sys, &Unpack::default(), &iso).unwrap();
    assert!(fmus.iter().all(|f| !f.is_loaded()));
    let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
    let opts = RunOptions {
        isolation: iso.clone(),
        ..Default::default()
    };
    let mut counts = Vec::new();
    for stop in [0.6, 2.0] {
        sys.stop_time = Some(stop);
        let plan = sys.validate(&mds).unwrap();
        let before = allocs();
        let s = run(
            &plan,
            &fmus,
            Output::Writer(Box::new(std::io::sink())),
            &opts,
        )
        .unwrap();
        counts.push(allocs() - before);
        assert_eq!(s.macro_steps, (stop * 1000.0).round() as u64);
    }
    assert_eq!(
        counts[0], counts[1],
        "allocations grew with the steps: {counts:?}"
    );
}

#[test]
fn foreign_means_not_built_by_this_project() {
    let d = tempfile::tempdir().unwrap();
    let fmu = test_fmu(d.path());
    let f = shipsim::fmu::Fmu::open_unloaded(&fmu, &Default::default()).unwrap();
    // tests/c/testfmu.xml: generationTool="shipsim tests".
    assert!(!shipsim::isolate::is_ours(&f.model_description));
    let mut md = f.model_description.clone();
    md.generation_tool = Some("ship-control fmi2-export 0.1.0".into());
    assert!(shipsim::isolate::is_ours(&md));
    assert!(Isolation::foreign().applies("x", &f.model_description));
    assert!(!Isolation::foreign().applies("x", &md));
}

/// A campaign runs the instances of foreign FMUs isolated: a run whose FMU segfaults fails
/// alone, with the reason in the run table, and the campaign completes.
#[test]
fn a_campaign_survives_a_foreign_fmu_that_segfaults() {
    let d = tempfile::tempdir().unwrap();
    evil_fmu(d.path(), "evil", &["EVIL_SEGV", "EVIL_IF_U_ABOVE=1.5"]);
    system(d.path());
    write_system(
        d.path(),
        "c.toml",
        "system = \"sys.toml\"\n[[factors]]\nname = \"u\"\nvariable = \"evil.u\"\nvalues = [1, 2, 0.5]\n\
         [[kpis]]\nname = \"y_max\"\nvariable = \"good.y\"\nstat = \"max\"\n",
    );
    let out = shipsim(
        d.path(),
        &["campaign", "run", "-q", "-j", "2", "-o", "out", "c.toml"],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.code().is_some(), "killed by a signal: {out:?}");
    // The campaign completes and writes its tables; a failed run makes the exit status 2.
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("error: 1 of 3 runs failed (status and message in runs.csv"),
        "{err}"
    );
    let mut table = csv::Reader::from_path(d.path().join("out/runs.csv")).unwrap();
    let rows: Vec<csv::StringRecord> = table.records().map(|r| r.unwrap()).collect();
    let status: Vec<&str> = rows.iter().map(|r| &r[5]).collect();
    assert_eq!(status, ["ok", "error", "ok"]);
    assert!(
        rows[1][6]
            .starts_with("instance 'evil': the FMU's process was killed by signal 11 (SIGSEGV"),
        "{}",
        &rows[1][6]
    );
    assert_no_temp_dirs(d.path());
}

/// Ctrl-C stops a run whose isolated FMU hangs, without a call time limit: the master kills
/// the host and ends as interrupted (status 130), with the completed steps in the CSV.
#[test]
fn ctrl_c_stops_a_hung_isolated_fmu() {
    let d = tempfile::tempdir().unwrap();
    evil_fmu(d.path(), "evil", &["EVIL_HANG"]);
    system(d.path());
    let mut child = Command::new(SHIPSIM)
        .current_dir(d.path())
        .env("TMPDIR", d.path())
        .args(["run", "sys.toml", "-q", "--isolate"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // The evil FMU logs a warning, shown on stderr, just before it hangs in its fourth step.
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut err = String::new();
    while !err.contains("[evil] fmi2Warning logAll: misbehaving now") {
        let mut line = String::new();
        let n = std::io::BufRead::read_line(&mut stderr, &mut line).unwrap();
        assert!(n > 0, "the run ended before the hang: {err}");
        err.push_str(&line);
    }
    // SAFETY: signalling the child this test started.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    std::io::Read::read_to_string(&mut stderr, &mut err).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted at t = 0.3 s"), "{err}");
    assert_three_steps_kept(d.path());
    assert_no_temp_dirs(d.path());
}

/// The probe's case (issue 19, defect 5): `--set autopilot.t_v0=0` made RrsAutopilot output
/// a NaN rudder command, blamed on the steering gear that refused it. The error now names the
/// autopilot: since t_v0's declared minimum is 1 m (0 broke the model), the value is refused
/// before the run, naming the variable and its range (an in-range NaN is reported by the
/// autopilot's own fmi2GetReal, and a NaN that an FMU passes with fmi2OK is blamed on it by
/// the exchange: `a_refused_nan_is_blamed_on_its_producer`). No instance gets an fmi2Terminate
/// in Initialization Mode.
#[test]
fn rrs_nan_rudder_command_is_blamed_on_the_autopilot() {
    let d = tempfile::tempdir().unwrap();
    our_fmu("RrsAutopilot");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("systems/rrs.toml")).unwrap();
    let dir = format!("{}/", fmu_dir().display());
    write_system(d.path(), "rrs.toml", &text.replace("../target/fmu/", &dir));
    let err = failing(
        d.path(),
        &[
            "run",
            "rrs.toml",
            "-q",
            "--no-output",
            "--set",
            "autopilot.t_v0=0",
        ],
    );
    let blamed = err.contains("error: 'autopilot.rudder_command' is NaN")
        || err.contains(
            "instance 'autopilot', variable 't_v0': value 0 is outside the declared range [1, inf]",
        );
    assert!(blamed, "{err}");
    assert!(!err.contains("fmi2Terminate is not allowed"), "{err}");
}

/// The FMU-state calls through an isolated instance's host (fmi2GetFMUstate,
/// fmi2SerializedFMUstateSize, fmi2SerializeFMUstate and fmi2FreeFMUstate for a checkpoint;
/// fmi2DeSerializeFMUstate, fmi2SetFMUstate and fmi2FreeFMUstate for a resume) give what the
/// same calls give in process: the checkpoint file of `--isolate` is the in-process one byte
/// for byte, and a resume of isolated instances from it writes the in-process resume's rows.
#[test]
fn isolated_checkpoints_and_resumes_equal_the_in_process_ones() {
    let d = tempfile::tempdir().unwrap();
    our_fmu("RrsAutopilot");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("systems/rrs.toml")).unwrap();
    let dir = format!("{}/", fmu_dir().display());
    write_system(d.path(), "rrs.toml", &text.replace("../target/fmu/", &dir));
    let run = |args: &[&str]| {
        let mut a = vec!["run", "rrs.toml", "-q", "--stop-time", "20"];
        a.extend(args);
        let out = shipsim(d.path(), &a);
        assert!(out.status.success(), "{args:?}: {out:?}");
    };
    run(&["-o", "full.csv", "--checkpoint-at", "10", "cp_in.bin"]);
    run(&[
        "-o",
        "full_iso.csv",
        "--isolate",
        "--checkpoint-at",
        "10",
        "cp_iso.bin",
    ]);
    run(&["-o", "tail.csv", "--resume", "cp_in.bin"]);
    run(&["-o", "tail_iso.csv", "--isolate", "--resume", "cp_iso.bin"]);
    let read = |n: &str| std::fs::read(d.path().join(n)).unwrap();
    assert!(
        read("cp_iso.bin") == read("cp_in.bin"),
        "checkpoint files differ"
    );
    assert!(read("full_iso.csv") == read("full.csv"));
    let (tail, tail_iso) = (read("tail.csv"), read("tail_iso.csv"));
    assert_eq!(tail.iter().filter(|&&b| b == b'\n').count(), 1 + 201);
    assert!(tail_iso == tail, "the isolated resume's rows differ");
    assert_no_temp_dirs(d.path());
}

/// A run that fails before its first row (here in fmi2ExitInitializationMode) leaves the CSV
/// of the last run as it was (issue 36, item 1: it was truncated to its header, or to nothing).
#[test]
fn a_run_that_fails_to_initialize_keeps_the_last_csv() {
    let d = tempfile::tempdir().unwrap();
    evil_fmu(d.path(), "evil", &[]);
    evil_fmu(d.path(), "broken", &["EVIL_INIT_FAIL"]);
    let sys = |fmu: &str| {
        format!("[simulation]\nstop_time = 0.3\nstep_size = 0.1\n[[instances]]\nname = \"m\"\nfmu = \"{fmu}\"\n")
    };
    write_system(d.path(), "good.toml", &sys("evil.fmu"));
    write_system(d.path(), "bad.toml", &sys("broken.fmu"));
    let out = shipsim(d.path(), &["run", "good.toml", "-q", "-o", "out.csv"]);
    assert!(out.status.success(), "{out:?}");
    let good = std::fs::read_to_string(d.path().join("out.csv")).unwrap();
    assert_eq!(good.lines().count(), 1 + 4, "{good}");
    for isolate in [false, true] {
        let mut args = vec!["run", "bad.toml", "-q", "-o", "out.csv"];
        if isolate {
            args.push("--isolate");
        }
        let err = failing(d.path(), &args);
        assert!(
            err.contains("fmi2ExitInitializationMode returned fmi2Error"),
            "{err}"
        );
        let now = std::fs::read_to_string(d.path().join("out.csv")).unwrap();
        assert_eq!(
            now, good,
            "isolate = {isolate}: the failed run touched the CSV"
        );
    }
    // A new file is not created by a run that fails so early.
    let err = failing(d.path(), &["run", "bad.toml", "-q", "-o", "new.csv"]);
    assert!(err.contains("fmi2Error"), "{err}");
    assert!(!d.path().join("new.csv").exists());
}
