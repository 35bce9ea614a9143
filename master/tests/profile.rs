//! `shipsim run --profile`: the per-instance cost of the step loop. The profile counts every
//! instance's fmi2DoStep calls (multi-rate included), its shares sum to 100 %, an instance made
//! expensive on purpose has the largest share, it changes no output byte, and the profiled
//! step loop allocates nothing. The only timing assertions are orderings with a margin of
//! about 100x (the busy doStep below against doStep calls of a few ns).
//! Also `--no-output`: no CSV even when the system names one.
mod common;
use common::*;
use shipsim::run::{load_fmus, run_into, run_system, MemoryRecorder, Output, RunOptions, Sampling};
use shipsim::system::System;
use std::alloc::{GlobalAlloc, Layout, System as SysAlloc};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Counts the allocations of the current thread (tests run in parallel threads).
struct Counting;
thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCS.with(|n| n.set(n.get() + 1));
        SysAlloc.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        SysAlloc.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        ALLOCS.with(|c| c.set(c.get() + 1));
        SysAlloc.realloc(p, l, n)
    }
}
#[global_allocator]
static A: Counting = Counting;

fn allocs() -> usize {
    ALLOCS.with(Cell::get)
}

/// The test FMU `dir/<name>.fmu` that does `iterations` volatile additions (about 1.5 ns each)
/// before every `nth` fmi2DoStep (counted from its first): the C source includes testfmu.c with
/// its fmi2DoStep renamed and wraps it.
fn busy_fmu(dir: &Path, name: &str, iterations: u32, nth: u32) -> PathBuf {
    let src = c_source("testfmu.c");
    let wrapper = dir.join(format!("{name}.c"));
    std::fs::write(
        &wrapper,
        format!(
            r#"#define fmi2DoStep testfmu_do_step
#include "{}"
#undef fmi2DoStep
EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noprior) {{
    if (((Inst *)c)->n % {nth} == 0) {{
        volatile double acc = 0.0;
        for (int j = 0; j < {iterations}; j++) acc += 0.5;
    }}
    return testfmu_do_step(c, t, h, noprior);
}}
"#,
            src.display()
        ),
    )
    .unwrap();
    let so = compile(dir, name, &wrapper, &[]);
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

/// 12,000 steps of 1 ms: `a` every step, `b` every 3rd, `slow` (busy) every 2nd; each
/// records its own step count.
fn system(algorithm: &str) -> String {
    format!(
        r#"
connections = ["a.y -> b.u", "b.y2 -> slow.u", "slow.n_out -> a.n_in"]
[simulation]
stop_time = 12.0
step_size = 0.001
algorithm = "{algorithm}"
[[instances]]
name = "a"
fmu = "testfmu.fmu"
parameters = {{ u = 1.0 }}
[[instances]]
name = "b"
fmu = "testfmu.fmu"
step_multiple = 3
[[instances]]
name = "slow"
fmu = "busy.fmu"
step_multiple = 2
[[events]]
time = 6.0
set = "a.u"
value = 2.0
[output]
file = "out.csv"
variables = ["a.steps", "b.steps", "slow.steps", "a.y", "b.y", "slow.y"]
decimation = 7
"#
    )
}

fn setup(algorithm: &str) -> (tempfile::TempDir, PathBuf) {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    // Tens of µs in every doStep.
    busy_fmu(d.path(), "busy", 20_000, 1);
    let p = write_system(d.path(), "s.toml", &system(algorithm));
    (d, p)
}

#[test]
fn profile_counts_every_call_and_the_busy_instance_leads() {
    for algorithm in ["jacobi", "gauss-seidel"] {
        let (_d, p) = setup(algorithm);
        let sys = System::load(&p).unwrap();
        let opts = RunOptions {
            profile: Some(Sampling::default()),
            ..Default::default()
        };
        let (_, summary) = run_system(&sys, Output::None, &opts).unwrap();
        let prof = summary.profile.expect("a profile when asked for");
        let names: Vec<&str> = prof.instances.iter().map(|i| i.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "slow"], "{algorithm}");
        let calls: Vec<u64> = prof.instances.iter().map(|i| i.do_step_calls).collect();
        // 12,000 base steps: every step, every 3rd, every 2nd.
        assert_eq!(calls, [12000, 4000, 6000], "{algorithm}");
        assert_eq!(calls.iter().sum::<u64>(), summary.fmu_steps);
        assert_eq!(prof.macro_steps, 12000);
        // Steps k < 12000 with k % 127 == 63: 63, 190, ..., 63 + 93 * 127 = 11874.
        assert_eq!((prof.stride, prof.sampled_steps), (127, 94), "{algorithm}");

        // Shares of the sampled total: instances and master sum to 100 % (f64 rounding).
        let shares: f64 = prof
            .instances
            .iter()
            .map(|i| prof.share(i.do_step + i.exchange))
            .sum::<f64>()
            + prof.share(prof.master);
        assert!((shares - 100.0).abs() < 1e-9, "{algorithm}: {shares}");

        // The busy doStep (tens of µs) against doStep calls and exchanges of a few hundred ns
        // at most: the largest share by far.
        let slow = &prof.instances[2];
        assert_eq!(prof.most_expensive().unwrap().name, "slow");
        for other in &prof.instances[..2] {
            assert!(
                slow.do_step > 10 * (other.do_step + other.exchange),
                "{algorithm}: {prof:?}"
            );
        }
        assert!(slow.do_step > 10 * prof.master, "{algorithm}: {prof:?}");
        assert!(slow.do_step > 10 * slow.exchange, "{algorithm}: {prof:?}");

        let plain = run_system(&sys, Output::None, &RunOptions::default()).unwrap();
        assert!(plain.1.profile.is_none());
    }
}

/// The profile's doStep counts are the FMUs' own step counts (their `steps` outputs).
#[test]
fn profile_counts_are_the_fmus_own_step_counts() {
    let (_d, p) = setup("jacobi");
    let sys = System::load(&p).unwrap();
    let fmus = load_fmus(&sys).unwrap();
    let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
    let plan = sys.validate(&mds).unwrap();
    let mut memory = MemoryRecorder::new();
    let opts = RunOptions {
        profile: Some(Sampling::default()),
        ..Default::default()
    };
    let s = run_into(&plan, &fmus, Some(&mut memory), &opts).unwrap();
    let prof = s.profile.unwrap();
    for inst in &prof.instances {
        let steps = memory.column(&format!("{}.steps", inst.name)).unwrap();
        assert_eq!(
            inst.do_step_calls as f64,
            *steps.last().unwrap(),
            "{}",
            inst.name
        );
    }
}

fn shipsim(args: &[&str], dir: &Path) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "shipsim {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn profile_changes_no_output_byte_and_prints_table_or_json() {
    let (d, p) = setup("jacobi");
    let dir = d.path();
    let sys = p.to_str().unwrap();
    let plain = shipsim(&["run", "-q", sys, "-o", "plain.csv"], dir);
    assert!(plain.stdout.is_empty());
    let table = shipsim(&["run", sys, "-o", "table.csv", "--profile"], dir);
    let json = shipsim(&["run", "-q", sys, "-o", "json.csv", "--profile=json"], dir);
    let reference = std::fs::read(dir.join("plain.csv")).unwrap();
    assert!(reference.len() > 1000);
    for f in ["table.csv", "json.csv"] {
        assert!(
            std::fs::read(dir.join(f)).unwrap() == reference,
            "{f} differs"
        );
    }

    let err = String::from_utf8(table.stderr).unwrap();
    let summary_at = err.find("macro steps, ").expect("the summary");
    let profile_at = err.find("profile (sampled: 94 of 12000").expect(&err);
    assert!(
        summary_at < profile_at,
        "the table follows the summary:\n{err}"
    );
    for (name, calls) in [("a", 12000), ("b", 4000), ("slow", 6000)] {
        let row = err
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("no row for {name}:\n{err}"));
        assert_eq!(
            row.split_whitespace().nth(1),
            Some(calls.to_string().as_str())
        );
    }
    assert!(table.stdout.is_empty());

    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(v["macro_steps"], 12000);
    let calls: Vec<u64> = v["profile"]["instances"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["do_step_calls"].as_u64().unwrap())
        .collect();
    assert_eq!(calls, [12000, 4000, 6000]);
    let shares: f64 = v["profile"]["instances"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["share"].as_f64().unwrap())
        .sum::<f64>()
        + v["profile"]["master_share"].as_f64().unwrap();
    assert!((shares - 100.0).abs() < 1e-9, "{shares}");
    assert_eq!(v["profile"]["instances"][2]["name"], "slow");
}

#[test]
fn no_output_writes_no_csv() {
    let (d, p) = setup("jacobi");
    let sys = p.to_str().unwrap();
    let out = shipsim(&["run", sys, "--no-output"], d.path());
    assert!(!d.path().join("out.csv").exists());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("12000 macro steps") && !err.contains("rows written"),
        "{err}"
    );
    shipsim(&["run", "-q", sys], d.path());
    assert!(
        d.path().join("out.csv").exists(),
        "the system's own output file"
    );
    let both = Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .args(["run", sys, "--no-output", "-o", "x.csv"])
        .output()
        .unwrap();
    assert!(!both.status.success(), "--no-output and -o conflict");
}

/// The profiled step loop allocates nothing: as many allocations for 7,000 as for 70,000 steps.
#[test]
fn profiled_step_loop_allocates_nothing() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    // The same system with every instance cheap.
    let cheap = system("jacobi").replace("busy.fmu", "testfmu.fmu");
    let mut sys = System::load(&write_system(d.path(), "s.toml", &cheap)).unwrap();
    let fmus = load_fmus(&sys).unwrap();
    let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
    let mut counts = Vec::new();
    for stop in [7.0, 70.0] {
        sys.stop_time = Some(stop);
        let plan = sys.validate(&mds).unwrap();
        let opts = RunOptions {
            profile: Some(Sampling::default()),
            ..Default::default()
        };
        let mut memory = MemoryRecorder::new();
        let before = allocs();
        let s = run_into(&plan, &fmus, Some(&mut memory), &opts).unwrap();
        counts.push(allocs() - before);
        assert!(s.profile.unwrap().sampled_steps >= 16);
    }
    assert_eq!(
        counts[0], counts[1],
        "allocations, 7e3 vs 7e4 steps: {counts:?}"
    );
}

/// `Sampling { every: 1 }` times every step, and so catches work done on few steps: an instance
/// busy on every 127th of its steps only (a period the default sample, k % 127 == 63, never
/// meets for an instance stepping every base step at k % 127 == 0) has the largest share.
#[test]
fn profile_every_step_catches_rare_costly_steps() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    // About 0.3 ms on steps 0, 127, 254, ...: 95 of 12,000 steps, about 30 ms in all.
    busy_fmu(d.path(), "rare", 200_000, 127);
    let text = system("jacobi")
        .replace("busy.fmu", "rare.fmu")
        .replace("step_multiple = 2\n", "");
    let p = write_system(d.path(), "s.toml", &text);
    let sys = System::load(&p).unwrap();
    let opts = RunOptions {
        profile: Some(Sampling { every: 1 }),
        ..Default::default()
    };
    let (_, summary) = run_system(&sys, Output::None, &opts).unwrap();
    let prof = summary.profile.unwrap();
    assert_eq!((prof.stride, prof.sampled_steps), (1, 12000));
    let calls: Vec<u64> = prof.instances.iter().map(|i| i.do_step_calls).collect();
    assert_eq!(calls, [12000, 4000, 12000]);
    // 30 ms of busy work against 16,000 cheap doStep calls and exchanges of well under 1 µs.
    let rare = &prof.instances[2];
    assert_eq!(prof.most_expensive().unwrap().name, "slow");
    for other in &prof.instances[..2] {
        assert!(
            rare.do_step > 5 * (other.do_step + other.exchange),
            "{prof:?}"
        );
    }
}

#[test]
fn profile_every_on_the_command_line() {
    let (d, p) = setup("jacobi");
    let sys = p.to_str().unwrap();
    let args = [
        "run",
        "-q",
        sys,
        "--no-output",
        "--profile=json",
        "--profile-every",
    ];
    let out = shipsim(&[&args[..], &["1"]].concat(), d.path());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["profile"]["stride"], 1);
    assert_eq!(v["profile"]["sampled_steps"], 12000);
    let out = shipsim(&[&args[..], &["61"]].concat(), d.path());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Steps k < 12000 with k % 61 == 30: 30, 91, ..., 30 + 196 * 61 = 11986.
    assert_eq!(
        (
            v["profile"]["stride"].as_u64(),
            v["profile"]["sampled_steps"].as_u64()
        ),
        (Some(61), Some(197))
    );
    for bad in [
        &[&args[..], &["0"]].concat()[..],
        &["run", "-q", sys, "--no-output", "--profile-every", "5"][..],
    ] {
        let r = Command::new(env!("CARGO_BIN_EXE_shipsim"))
            .current_dir(d.path())
            .args(bad)
            .output()
            .unwrap();
        assert!(!r.status.success(), "{bad:?} must be refused");
    }
}
