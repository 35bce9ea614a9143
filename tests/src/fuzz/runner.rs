//! The parent: runs FMU units in child processes (the fuzz binary itself, `fuzz child ...`),
//! watches every call against the limits, turns deaths, overruns, non-finite outputs and panic
//! messages into failures, and restarts a child after the unit that killed the previous one.

use super::calls::CHECK;
use super::ffi::Unpacked;
use super::files::{self, Family};
use super::proto::Record;
use super::report::{FailKind, Failure, Report};
use super::units::Kind;
use super::watch::{describe_exit, InCall, Limits, Poll, Watched};
use std::collections::VecDeque;
use std::ops::Range;
use std::path::PathBuf;
use std::process::Command;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// One FMU under test, unpacked once for the whole run.
pub struct Target {
    pub name: String,
    pub unpacked: Unpacked,
}

/// What every task needs.
pub struct Env {
    /// The fuzz binary (children are `<exe> child ...`).
    pub exe: PathBuf,
    pub targets: Vec<Target>,
    pub limits: Limits,
    /// shipsim and the malformed-file bases (None: no file cases).
    pub files: Option<files::Bases>,
}

/// A batch of units of one kind on one FMU, or of malformed files of one family.
#[derive(Clone, Debug)]
pub enum Task {
    Fmu {
        kind: Kind,
        target: usize,
        seed: u64,
        units: Range<u64>,
    },
    File {
        family: Family,
        seed: u64,
        units: Range<u64>,
    },
}

impl Task {
    /// The case kind: calls, state, param, toml, osp or md.
    pub fn case(&self) -> &'static str {
        match self {
            Task::Fmu { kind, .. } => kind.name(),
            Task::File { family, .. } => family.name(),
        }
    }

    pub fn run(&self, env: &Env) -> Report {
        match self {
            Task::Fmu {
                kind,
                target,
                seed,
                units,
            } => run_fmu(env, *kind, *target, *seed, units.clone()),
            Task::File {
                family,
                seed,
                units,
            } => match &env.files {
                Some(b) => {
                    let mut r = Report::default();
                    for u in units.clone() {
                        r.merge(files::run_unit(b, &env.limits, *family, *seed, u));
                    }
                    r
                }
                None => Report::default(),
            },
        }
    }
}

/// The state of one child as its records arrive.
struct Progress {
    kind: &'static str,
    /// The child reported that it could not set up (its failure is recorded).
    setup: bool,
    /// The call in progress is the oracle's read of the outputs.
    check: bool,
    /// The first line of stray output of this unit (shown with a crash: an abort says why).
    stray: Option<String>,
    /// This unit printed a panic message: how many more of its lines go into the failure.
    panic: Option<u8>,
    unit: Option<u64>,
    calls: Vec<String>,
    in_call: Option<InCall>,
    next: u64,
}

fn run_fmu(env: &Env, kind: Kind, target: usize, seed: u64, units: Range<u64>) -> Report {
    let t = &env.targets[target];
    let mut report = Report::default();
    let mut next = units.start;
    while next < units.end {
        let mut cmd = Command::new(&env.exe);
        cmd.arg("child")
            .arg(kind.name())
            .arg(&t.unpacked.dir)
            .arg(seed.to_string())
            .arg(next.to_string())
            .arg(units.end.to_string());
        cmd.env_remove("RUST_BACKTRACE");
        super::child_limits(&mut cmd);
        let fail = |fail, unit, detail: String, calls: Vec<String>| Failure {
            fail,
            case: kind.name(),
            target: t.name.clone(),
            seed,
            unit,
            detail,
            calls,
        };
        let mut w = match Watched::spawn(cmd) {
            Ok(w) => w,
            Err(e) => {
                report.failures.push(fail(
                    FailKind::Setup,
                    next,
                    format!("cannot start the child: {e}"),
                    Vec::new(),
                ));
                break;
            }
        };
        let mut p = Progress {
            kind: kind.name(),
            setup: false,
            panic: None,
            check: false,
            stray: None,
            unit: None,
            calls: Vec::new(),
            in_call: None,
            next,
        };
        let mut ended = None;
        loop {
            match w.poll(Duration::from_millis(20)) {
                Poll::Line(line) => {
                    if let Some(f) = on_line(&mut p, &mut report, &line, &w) {
                        let unit = p.unit.unwrap_or(p.next);
                        report.failures.push(fail(f.0, unit, f.1, p.calls.clone()));
                    }
                }
                Poll::Quiet => {}
                Poll::Eof => break,
            }
            if let Some(c) = p.in_call {
                if let Some(why) = c.over(&w, &env.limits) {
                    w.kill();
                    let unit = p.unit.unwrap_or(p.next);
                    let last = p.calls.last().cloned().unwrap_or_default();
                    report.failures.push(fail(
                        FailKind::Hang,
                        unit,
                        format!("{last}: {why}"),
                        p.calls.clone(),
                    ));
                    if !p.check {
                        report.calls += 1;
                    }
                    *report.units.entry(kind.name()).or_default() += 1;
                    ended = Some(unit + 1);
                    break;
                }
            }
        }
        if ended.is_none() {
            let status = w.child.wait();
            let clean = status.as_ref().is_ok_and(|s| s.success());
            if clean && p.next >= units.end {
                break;
            }
            let why = status.map_or_else(|e| e.to_string(), describe_exit);
            match p.unit {
                Some(unit) if p.next <= unit => {
                    let last = p.calls.last().cloned().unwrap_or_default();
                    report.failures.push(fail(
                        FailKind::Crash,
                        unit,
                        match &p.stray {
                            Some(out) => {
                                format!("{last}: the process {why}; its output: {out}")
                            }
                            None => format!("{last}: the process {why}"),
                        },
                        p.calls.clone(),
                    ));
                    if p.in_call.is_some() && !p.check {
                        report.calls += 1;
                    }
                    *report.units.entry(kind.name()).or_default() += 1;
                    ended = Some(unit + 1);
                }
                _ if p.setup => ended = Some(units.end),
                _ => {
                    report.failures.push(fail(
                        FailKind::Setup,
                        p.next,
                        format!("the child {why} before its first unit"),
                        Vec::new(),
                    ));
                    ended = Some(units.end);
                }
            }
        }
        next = ended.unwrap_or(units.end);
    }
    report
}

/// Handles one line of a child; a failure it reveals.
fn on_line(
    p: &mut Progress,
    report: &mut Report,
    line: &str,
    w: &Watched,
) -> Option<(FailKind, String)> {
    let Some(rec) = Record::parse(line) else {
        report.stray += 1;
        if p.stray.is_none() {
            p.stray = Some(line.chars().take(300).collect());
        }
        // A panic message is several lines: one failure per unit, with its next two lines.
        if let Some(more) = &mut p.panic {
            if *more > 0 {
                *more -= 1;
                let f = report.failures.last_mut().expect("the panic failure");
                f.detail.push_str(" / ");
                f.detail.push_str(line);
            }
            return None;
        }
        if line.contains("panicked") {
            p.panic = Some(2);
            let last = p.calls.last().cloned().unwrap_or_default();
            return Some((FailKind::Panic, format!("{last}: stderr: {line}")));
        }
        return None;
    };
    match rec {
        Record::Unit(u) => {
            p.unit = Some(u);
            p.panic = None;
            p.stray = None;
            p.calls.clear();
        }
        Record::Begin(t) => {
            if t.starts_with("deSerializeFMUstate(last{") {
                report.states += 1;
            }
            p.check = t.starts_with(CHECK);
            // The oracle's reads appear in a failure only when they are the failing call.
            if p.calls.last().is_some_and(|c| c.starts_with(CHECK)) {
                p.calls.pop();
            }
            p.calls.push(t);
            p.in_call = Some(InCall::now(w));
        }
        Record::End(_) => {
            if !p.check {
                report.calls += 1;
            }
            p.in_call = None;
        }
        Record::NonFinite(d) => return Some((FailKind::NonFinite, d)),
        Record::Setup(d) => {
            p.setup = true;
            return Some((FailKind::Setup, d));
        }
        Record::Done(u) => {
            *report.units.entry(p.kind).or_default() += 1;
            p.next = u + 1;
            p.unit = None;
        }
    }
    None
}

/// Runs `tasks` on `jobs` threads; `more` is asked for further tasks when the queue runs dry
/// (the long run), until it returns none. `tick` sees the report so far about every `every`.
pub fn run_all(
    env: &Env,
    tasks: Vec<Task>,
    jobs: usize,
    more: &(dyn Fn() -> Vec<Task> + Sync),
    tick: &(dyn Fn(&Report) + Sync),
    every: Duration,
) -> Report {
    let queue = Mutex::new(VecDeque::from(tasks));
    let total = Mutex::new(Report::default());
    let last_tick = Mutex::new(Instant::now());
    std::thread::scope(|s| {
        for _ in 0..jobs.max(1) {
            s.spawn(|| loop {
                let task = {
                    let mut q = queue.lock().unwrap();
                    if q.is_empty() {
                        q.extend(more());
                    }
                    q.pop_front()
                };
                let Some(task) = task else { break };
                let r = task.run(env);
                let mut t = total.lock().unwrap();
                t.merge(r);
                let mut lt = last_tick.lock().unwrap();
                if lt.elapsed() >= every {
                    *lt = Instant::now();
                    tick(&t);
                }
            });
        }
    });
    total.into_inner().unwrap()
}
