//! `shipsim run`'s guards around FMUs in process, and its isolation flags (docs/isolation.md).
//!
//! The library only notes which call is in progress ([`CallMonitor`]); the process-wide parts
//! live here, in the CLI:
//!
//! - an `atexit` hook: an FMU that calls `exit()` inside an FMI call would otherwise end
//!   `shipsim` with the FMU's status, 0 included, and an incomplete CSV. The hook names the
//!   instance, the call and the time, and ends the process with status [`EXIT_FMU`];
//! - with `--call-timeout`, a watchdog thread: a call in process cannot be stopped, so a call
//!   longer than the limit ends the process with a message naming it (status [`EXIT_FMU`]).
//!   Isolated instances have their own limit: their process is killed and the run ends through
//!   its normal error path.

use shipsim::isolate::{IsolateMode, Isolation};
use shipsim::slave::CallMonitor;
use shipsim::system::System;
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

/// The exit status when an FMU in process ended the process or hung past the call limit.
pub const EXIT_FMU: i32 = 1;

/// The monitor of the run in progress and the thread that runs it.
static GUARDED: OnceLock<(Arc<CallMonitor>, libc::pthread_t)> = OnceLock::new();

/// `--isolate[=all|foreign|NAME,...]` and `--call-timeout SECONDS` as the options of a run of
/// `sys`: the library's parser ([`shipsim::isolate::options`]), which Python's `System.run`
/// uses too.
pub fn isolation(
    isolate: Option<&str>,
    call_timeout: Option<f64>,
    sys: &System,
) -> shipsim::Result<Isolation> {
    let mode = match isolate {
        None => IsolateMode::None,
        Some(v) => IsolateMode::parse(v)?,
    };
    let names: Vec<&str> = sys.instances.iter().map(|i| i.name.as_str()).collect();
    Ok(Isolation::from_options(
        mode,
        call_timeout,
        &sys.source,
        &names,
    )?)
}

/// Installs the `atexit` hook (and, with a limit, the watchdog) for a run on this thread; the
/// monitor for [`shipsim::run::RunOptions::monitor`].
pub fn guard(call_timeout: Option<Duration>) -> Arc<CallMonitor> {
    let monitor = Arc::new(CallMonitor::new());
    // SAFETY: pthread_self has no preconditions; the hook is a plain extern "C" function.
    let thread = unsafe { libc::pthread_self() };
    if GUARDED.set((monitor.clone(), thread)).is_ok() {
        unsafe { libc::atexit(on_exit) };
        if let Some(limit) = call_timeout {
            let m = monitor.clone();
            std::thread::spawn(move || watchdog(&m, limit));
        }
    }
    monitor
}

/// Runs inside `exit()`: when an FMU call on the run's thread is in progress, the FMU called
/// it. Named, and the status made non-zero.
extern "C" fn on_exit() {
    let Some((monitor, thread)) = GUARDED.get() else {
        return;
    };
    // SAFETY: comparing thread ids.
    if unsafe { libc::pthread_equal(libc::pthread_self(), *thread) } == 0 {
        return;
    }
    if let Some(call) = monitor.in_progress() {
        eprintln!(
            "error: {call}: the FMU ended the process (it called exit()); the run is incomplete and rows not yet written are lost (run with --isolate to keep every completed step)"
        );
        // SAFETY: ends the process at once, without running the FMU's exit handlers again.
        unsafe { libc::_exit(EXIT_FMU) };
    }
}

/// Ends the process when one call stays in progress for `limit`.
fn watchdog(monitor: &CallMonitor, limit: Duration) {
    let tick = (limit / 4).clamp(Duration::from_millis(10), Duration::from_millis(200));
    let mut seen: Option<((u64, u64), Instant)> = None;
    loop {
        std::thread::sleep(tick);
        let Some(call) = monitor.in_progress() else {
            seen = None;
            continue;
        };
        match seen {
            Some((key, since)) if key == call.key => {
                if since.elapsed() + tick >= limit {
                    eprintln!(
                        "error: {call} did not return within {} s (--call-timeout); a call in process cannot be stopped, so shipsim exits (rows not yet written are lost; run with --isolate to stop only the FMU and keep every completed step)",
                        limit.as_secs_f64()
                    );
                    // SAFETY: ends the process; the run's thread is stuck in the FMU.
                    unsafe { libc::_exit(EXIT_FMU) };
                }
            }
            _ => seen = Some((call.key, Instant::now())),
        }
    }
}
