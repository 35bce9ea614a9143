//! Which FMI call of an in-process instance is in progress, for a process-wide handler the
//! caller installs: the CLI's `atexit` hook (an FMU that calls `exit()` mid-run must not end
//! `shipsim` with status 0) and its watchdog (`--call-timeout` in process). The library only
//! records; it installs nothing.
//!
//! One writer (the thread that runs the instances) stores one word before and one after each
//! call (and the time at each step); readers on other threads (or in the `atexit` hook) load
//! them. Nothing allocates after the instances are registered.

use super::Op;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::sync::Mutex;

/// The call in progress of a run's in-process instances ([`crate::run::RunOptions::monitor`]).
#[derive(Debug, Default)]
pub struct CallMonitor {
    /// `instance << 8 | op`; 0: no call in progress.
    state: AtomicU64,
    /// The simulation time of the instance's last step (its start time before the first).
    time: AtomicU64,
    names: Mutex<Vec<String>>,
}

/// A call in progress, as [`CallMonitor::in_progress`] reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct InProgress {
    pub instance: String,
    pub function: &'static str,
    pub time: f64,
    /// The call and the time as stored: the same key seen throughout a while is one call that
    /// has not returned (the watchdog's test: the time changes with every step).
    pub key: (u64, u64),
}

impl std::fmt::Display for InProgress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "instance '{}' in {} at t = {} s",
            self.instance, self.function, self.time
        )
    }
}

impl CallMonitor {
    pub fn new() -> CallMonitor {
        CallMonitor::default()
    }

    /// Registers an instance; its number for [`Self::enter`].
    pub fn register(&self, name: &str) -> u16 {
        let mut names = self.names.lock().unwrap_or_else(|e| e.into_inner());
        names.push(name.to_string());
        (names.len() - 1).min(u16::MAX as usize) as u16
    }

    /// Instance `slot` starts call `op`.
    #[inline(always)]
    pub fn enter(&self, slot: u16, op: Op) {
        self.state.store((slot as u64) << 8 | op as u64, Relaxed);
    }

    /// Instance `slot` starts a step from `t`.
    #[inline(always)]
    pub fn enter_step(&self, slot: u16, t: f64) {
        self.time.store(t.to_bits(), Relaxed);
        self.enter(slot, Op::DoStep);
    }

    /// The call returned.
    #[inline(always)]
    pub fn leave(&self) {
        self.state.store(0, Relaxed);
    }

    /// Notes the simulation time (the start time at fmi2SetupExperiment, the end of a step).
    #[inline(always)]
    pub fn at(&self, t: f64) {
        self.time.store(t.to_bits(), Relaxed);
    }

    /// The call in progress, if any. Takes the names' lock: not for the step loop.
    pub fn in_progress(&self) -> Option<InProgress> {
        let s = self.state.load(Relaxed);
        let time = self.time.load(Relaxed);
        let op = Op::from_u32((s & 0xff) as u32)?;
        let slot = ((s >> 8) & 0xffff) as usize;
        let instance = match self.names.try_lock() {
            Ok(names) => names.get(slot).cloned().unwrap_or_default(),
            Err(_) => format!("#{slot}"),
        };
        Some(InProgress {
            instance,
            function: op.name(),
            time: f64::from_bits(time),
            key: (s, time),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_the_call_in_progress() {
        let m = CallMonitor::new();
        let (a, b) = (m.register("a"), m.register("b"));
        assert_eq!(m.in_progress(), None);
        m.at(0.5);
        m.enter(a, Op::GetReal);
        let first = m.in_progress().unwrap();
        assert_eq!(
            (first.instance.as_str(), first.function),
            ("a", "fmi2GetReal")
        );
        assert_eq!(first.time, 0.5);
        m.leave();
        assert_eq!(m.in_progress(), None);
        m.enter_step(b, 1.25);
        let second = m.in_progress().unwrap();
        assert_eq!(
            second.to_string(),
            "instance 'b' in fmi2DoStep at t = 1.25 s"
        );
        assert_ne!(second.key, first.key);
    }
}
