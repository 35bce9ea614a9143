//! A system file with tens of thousands of `[[events]]` reads in linear time, and its errors
//! still name the right lines (issue 36, item 3): the reader counted the newlines from the
//! start of the file once per entry, so `shipsim check` of 8,000 / 16,000 / 32,000 events took
//! 1.8 / 7.4 / 29 s; with the lines indexed once it takes 0.09 / 0.09 / 0.2 s.
mod common;
use common::*;
use shipsim::system::System;
use std::path::Path;
use std::time::{Duration, Instant};

/// Lines of the file before the first `[[events]]`.
const HEAD: &str = "[simulation]\nstop_time = 4000.0\nstep_size = 0.1\n\n[[instances]]\nname = \"ctrl\"\nfmu = \"testfmu.fmu\"\n\n";
/// Lines of one event (`[[events]]`, time, set, value, a blank line).
const EVENT_LINES: usize = 5;

/// A system of the test FMU and `n` events on `ctrl.u`, one per base step; `edit` may change
/// the text of event `i` (0-based).
fn system(n: usize, edit: impl Fn(usize, String) -> String) -> String {
    let mut text = String::from(HEAD);
    for i in 0..n {
        let event = format!(
            "[[events]]\ntime = {}.{}\nset = \"ctrl.u\"\nvalue = {}.0\n\n",
            i / 10,
            i % 10,
            i % 7
        );
        text.push_str(&edit(i, event));
    }
    text
}

/// The 1-based line of the `[[events]]` header of event `i` (0-based) of [`system`].
fn event_line(i: usize) -> usize {
    HEAD.lines().count() + i * EVENT_LINES + 1
}

/// Reads the system file and validates it against the test FMU, as `shipsim check` does.
fn check(dir: &Path, text: &str) -> shipsim::Result<usize> {
    let p = write_system(dir, "sys.toml", text);
    let s = System::load(&p)?;
    let u = shipsim::fmu::UnpackedFmu::open(&dir.join("testfmu.fmu")).unwrap();
    let mds: Vec<_> = s.instances.iter().map(|_| &u.model_description).collect();
    Ok(s.validate(&mds)?.events.len())
}

fn timed(dir: &Path, text: &str) -> Duration {
    let t0 = Instant::now();
    let n = check(dir, text).unwrap();
    let t = t0.elapsed();
    assert!(n > 0);
    t
}

/// 32,000 events take about 8 times as long as 4,000 (linear), not 64 times (quadratic). A ratio
/// rather than a time bound, so that neither the machine's speed nor a debug build matters:
/// measured in release on a shared 2-core machine, 4,000 events read and validate in 45 ms and
/// 32,000 in 0.29 s (ratio 6.5); before the fix 0.42 s and 28 to 50 s (ratio 65 or more). The
/// bound is 24 times; the small file's time is the fastest of 3, and the large one may try 3
/// times.
#[test]
fn events_read_in_linear_time() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let small = system(4_000, |_, e| e);
    let large = system(32_000, |_, e| e);
    let t_small = (0..3).map(|_| timed(d.path(), &small)).min().unwrap();
    let bound = t_small * 24;
    let mut tries = Vec::new();
    for _ in 0..3 {
        tries.push(timed(d.path(), &large));
        if *tries.last().unwrap() <= bound {
            eprintln!("4,000 events: {t_small:?}; 32,000: {tries:?}");
            return;
        }
    }
    panic!(
        "32,000 events took {tries:?}, 4,000 took {t_small:?}: more than 24 times as long for 8 \
         times the events"
    );
}

/// Errors in the 20,000th of 32,000 events name its line: a reader error, a validation error
/// and a TOML syntax error.
#[test]
fn errors_in_a_late_event_name_its_line() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let at = 19_999;
    let line = event_line(at);
    let edited = |from: &'static str, to: &'static str| {
        system(
            32_000,
            move |i, e| if i == at { e.replace(from, to) } else { e },
        )
    };
    let text = edited("ctrl.u", "ctrlu");
    assert_eq!(text.lines().nth(line - 1), Some("[[events]]"));
    let e = check(d.path(), &text).unwrap_err().to_string();
    assert!(
        e.contains(&format!(
            "sys.toml:{line}: event: set = \"ctrlu\" must be written instance.variable"
        )),
        "{e}"
    );
    let e = check(d.path(), &edited("ctrl.u", "ctrl.uu"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("sys.toml:{line}: event 'ctrl.uu'")) && e.contains("no variable 'uu'"),
        "{e}"
    );
    let e = check(d.path(), &edited("value = ", "value = = "))
        .unwrap_err()
        .to_string();
    assert!(e.contains(&format!("sys.toml:{}:", line + 3)), "{e}");
    assert_eq!(check(d.path(), &system(32_000, |_, e| e)).unwrap(), 32_000);
}
