//! Signals reach the real binary (issue 19, defects 2, 7 and 8): SIGTERM and SIGHUP stop a run
//! as cleanly as SIGINT (they killed it and left its temporary directories), a second SIGINT
//! ends a process whose FMU hangs in a call and still removes them, and SIGINT stops the
//! unpacking of an FMU (it was ignored by `run` and left gigabytes behind in `inspect`).
//! Each test has a private TMPDIR that must be empty at the end.
mod common;
mod hardening;

use hardening::*;
use std::process::Stdio;

/// A run of 10^12 macro steps recording one row in 10^6; returns the sandbox.
fn long_run(defines: &'static [&'static str]) -> Sandbox {
    let s = Sandbox::new();
    common::build_fmu(
        s.path(),
        "testfmu",
        common::Variant {
            defines,
            ..Default::default()
        },
    );
    let text = system("testfmu.fmu", "a", "1e9", "0.001", "")
        .replace("[output]\n", "[output]\ndecimation = 1000000\n");
    std::fs::write(s.path().join("long.toml"), text).unwrap();
    s
}

fn csv_lines(s: &Sandbox) -> usize {
    std::fs::read_to_string(s.path().join("long.csv"))
        .map(|t| t.matches('\n').count())
        .unwrap_or(0)
}

/// SIGINT, SIGTERM and SIGHUP each stop a running simulation cleanly: exit status 130, the
/// CSV ends with a whole row, nothing left in TMPDIR.
#[test]
fn one_signal_stops_a_run_cleanly() {
    for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
        let s = long_run(&[]);
        let child = s.spawn(
            &["run", "long.toml", "-q", "-o", "long.csv"],
            Stdio::piped(),
        );
        s.wait_for("two rows in long.csv", || csv_lines(&s) >= 3);
        signal(&child, sig);
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(130), "signal {sig}: {err}");
        assert!(err.contains("interrupted at t = "), "signal {sig}: {err}");
        let csv = std::fs::read_to_string(s.path().join("long.csv")).unwrap();
        assert!(csv.ends_with('\n'), "signal {sig}: the last row is cut");
        assert_eq!(s.leftovers(), Vec::<String>::new(), "signal {sig}");
    }
}

/// An FMU that hangs inside fmi2DoStep (here: it logs at every step, with -v, into a stderr
/// pipe nobody reads, so the write blocks) does not see the first SIGINT; the second ends
/// the process with status 130 and removes the temporary directories.
#[test]
fn second_sigint_ends_a_hung_run_and_cleans_up() {
    let s = long_run(&["LOG_EVERY_STEP"]);
    let mut child = s.spawn(
        &["run", "long.toml", "-v", "-o", "long.csv"],
        Stdio::piped(),
    );
    s.wait_for("the FMU unpacked", || {
        s.leftovers().iter().any(|p| p.ends_with("testfmu.so"))
    });
    // Some time in the step loop: the 64 kB pipe fills within the first few thousand steps.
    std::thread::sleep(std::time::Duration::from_millis(1000));
    signal(&child, libc::SIGINT);
    std::thread::sleep(std::time::Duration::from_millis(500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the run was not hung; the test proves nothing"
    );
    signal(&child, libc::SIGINT);
    s.wait_for("the temporary directories removed", || {
        s.leftovers().is_empty()
    });
    drop(child.stderr.take());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
}

/// SIGINT while an FMU of 50,000 entries is being unpacked stops the unpacking (checked
/// between entries), for `inspect` and for `run`: status 130, nothing left.
#[test]
fn sigint_stops_unpacking() {
    let s = Sandbox::new();
    let extra = (0..50_000)
        .map(|i| file(&format!("resources/f{i}.txt"), "x"))
        .collect();
    testfmu_with(s.path(), "many.fmu", extra);
    std::fs::write(
        s.path().join("sys.toml"),
        system("many.fmu", "a", "1", "0.1", ""),
    )
    .unwrap();
    for args in [
        &["inspect", "many.fmu", "--max-fmu-files", "100000"][..],
        &["run", "sys.toml", "-q", "--max-fmu-files", "100000"],
    ] {
        let child = s.spawn(args, Stdio::piped());
        s.wait_for("unpacking under way", || {
            s.leftovers()
                .iter()
                .any(|p| p.ends_with("resources/f100.txt"))
        });
        signal(&child, libc::SIGINT);
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(130), "{args:?}: {err}");
        assert!(
            err.contains("interrupted: FMU 'many.fmu': ") && err.contains("unpacking interrupted"),
            "{args:?}: {err}"
        );
        assert_eq!(s.leftovers(), Vec::<String>::new(), "{args:?}");
    }
}
