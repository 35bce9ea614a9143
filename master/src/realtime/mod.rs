//! Real time: a stepping session ([`crate::run::Session`]) paced to the wall clock and put on
//! the wire by the system file's `[[io]]` channels ([`channels`]: NMEA 0183 and plain UDP, in
//! and out; [`nmea`]: the sentence codec).
//!
//! [`run`] drives an open session one macro step at a time. At each boundary t_k: the inputs
//! received since the last boundary are applied in arrival order through [`Session::set`]
//! (journaled, so the session replays bit for bit), the quiet rules of the inputs are checked,
//! the step to t_(k+1) is taken, the run waits for t_(k+1)'s deadline ([`pacing`]), and the
//! outputs due at t_(k+1) are sent. The delay from a datagram's arrival to the first
//! communication point that reflects it (its value applied, a step taken, the point reached
//! and its outputs sent) is measured, and separately to the first datagram sent after it.
//!
//! Without pacing and without `[[io]]` nothing here runs: `shipsim run` takes the ordinary
//! run path ([`crate::run::run`]).

pub mod channels;
pub mod nmea;
pub mod pacing;

use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::run::{Journaling, Recorder, RunOptions, Session, SessionOptions, State};
use crate::system::io::IoSpec;
use crate::system::System;
use channels::{inputs::Inputs, inputs::Log, outputs::Outputs};
use pacing::{Histogram, Pacer, Waited};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A real-time run writes the journal's buffered records to its file at most this often (so
/// that a crash loses at most this much of the inputs; a flush is one `write` call).
pub const JOURNAL_FLUSH_EVERY: Duration = Duration::from_secs(1);

/// How a real-time run goes.
#[derive(Clone)]
pub struct RealTimeOptions {
    /// Simulated seconds per wall second (1: real time); None: as fast as it can (I/O only).
    pub factor: Option<f64>,
    pub interrupt: Option<Arc<AtomicBool>>,
    /// A session checkpoint every T s of simulated time, written to files `{stem}-{t}.ckpt`
    /// beside the given path (with the journal's checkpoint records).
    pub checkpoint_every: Option<(f64, PathBuf)>,
    /// Where messages go while the run goes (the CLI: stderr).
    pub log: Log,
    /// Between two "cannot keep up" messages at least this much wall time.
    pub report_every: Duration,
}

impl Default for RealTimeOptions {
    fn default() -> RealTimeOptions {
        RealTimeOptions {
            factor: Some(1.0),
            interrupt: None,
            checkpoint_every: None,
            log: Arc::new(|m: &str| eprintln!("{m}")),
            report_every: Duration::from_secs(10),
        }
    }
}

/// What a real-time run did.
#[derive(Debug, Clone, Default)]
pub struct Report {
    pub start_time: f64,
    pub end_time: f64,
    pub macro_steps: u64,
    pub wall: Duration,
    /// The factor, the lateness of every communication point, and the late ones.
    pub factor: Option<f64>,
    pub lateness: Histogram,
    pub overruns: u64,
    /// Input values applied; rejected inputs by kind.
    pub applied: u64,
    pub rejected: BTreeMap<String, u64>,
    /// Arrival to the first communication point that reflects it; to the first datagram sent.
    pub delay: Histogram,
    pub delay_to_datagram: Histogram,
    pub datagrams_sent: u64,
    /// Why the run ended before its stop time (an input's quiet rule, an FMU).
    pub ended_by: Option<String>,
    pub checkpoints: Vec<PathBuf>,
    /// The journal's flushes during the run (one per [`JOURNAL_FLUSH_EVERY`] at most).
    pub journal_flushes: u64,
}

impl std::fmt::Display for Report {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "real-time run: simulated {} s .. {} s in {:.3} s wall, {} macro steps",
            self.start_time,
            self.end_time,
            self.wall.as_secs_f64(),
            self.macro_steps
        )?;
        if let Some(x) = self.factor {
            write!(
                f,
                "\npaced at {x}x real time: lateness {}; {} late steps (overruns)",
                self.lateness.describe_ms(),
                self.overruns
            )?;
        }
        if self.datagrams_sent > 0 {
            write!(f, "\n{} datagrams sent", self.datagrams_sent)?;
        }
        if self.applied > 0 || self.delay.count() > 0 {
            write!(
                f,
                "\n{} input values applied; arrival to the communication point that reflects it: {}",
                self.applied,
                self.delay.describe_ms()
            )?;
            if self.delay_to_datagram.count() > 0 {
                write!(
                    f,
                    "; to the next datagram sent: {}",
                    self.delay_to_datagram.describe_ms()
                )?;
            }
        }
        if !self.rejected.is_empty() {
            let kinds: Vec<String> = self
                .rejected
                .iter()
                .map(|(k, n)| format!("{k}: {n}"))
                .collect();
            write!(f, "\nrejected inputs: {}", kinds.join(", "))?;
        }
        if let Some(r) = &self.ended_by {
            write!(f, "\nended at t = {} s: {r}", self.end_time)?;
        }
        Ok(())
    }
}

/// A system's paced run: the one runner of `shipsim run --real-time` and of Python's
/// `System.run(real_time=...)`.
pub struct PacedRun {
    pub run: RunOptions,
    /// The journal of every input applied (a file for `shipsim replay`; Python: off).
    pub journal: Journaling,
    /// The `[[io]]` channels (none: pacing only).
    pub io: Vec<IoSpec>,
    /// Where the rows are streamed; None: kept in the session ([`Session::rows`]).
    pub rows: Option<Box<dyn Recorder + Send>>,
    pub realtime: RealTimeOptions,
}

/// Starts a session of `sys` and drives it to its end with [`run`]; the session comes back
/// closed (its rows in memory unless streamed), with the run's report. The session's warnings
/// go to the log first.
pub fn run_system(sys: System, fmus: Vec<Arc<Fmu>>, p: PacedRun) -> Result<(Session, Report)> {
    let opts = SessionOptions {
        run: p.run,
        journal: p.journal,
    };
    let mut session = Session::start(sys, fmus, opts)?;
    for w in session.warnings() {
        (p.realtime.log)(&format!("warning: {w}"));
    }
    if let Some(rows) = p.rows {
        session.record_into(rows)?;
    }
    let result = run(&mut session, &p.io, &p.realtime);
    let closed = session.close();
    let report = result?;
    closed?;
    Ok((session, report))
}

/// Drives `session` to its end (or an interrupt, or an input's end rule), paced and with the
/// `[[io]]` channels of `io`. The session stays open (close it to end the journal and the
/// output). On Ctrl-C the error is [`Error::Interrupted`] and the report so far is lost.
pub fn run(session: &mut Session, io: &[IoSpec], opts: &RealTimeOptions) -> Result<Report> {
    let mut inputs = Inputs::open(session, io, opts.log.clone())?;
    let mut outputs = Outputs::open(session, io)?;
    let mut d = Driver {
        report: Report {
            start_time: session.time(),
            factor: opts.factor,
            ..Report::default()
        },
        pacer: opts.factor.map(|x| Pacer::new(session.time(), x)),
        opts,
        began: Instant::now(),
        last_note: None,
        noted_overruns: 0,
        waiting_datagram: Vec::new(),
        last_flush: Instant::now(),
        journal_flushes: 0,
        next_checkpoint: opts
            .checkpoint_every
            .as_ref()
            .map(|(t, _)| session.time() + t),
    };
    if let Some(x) = opts.factor {
        if !(x > 0.0 && x.is_finite()) {
            return Err(Error::Other(format!(
                "real-time factor {x}: it must be positive"
            )));
        }
    }
    outputs.publish(session)?;
    let result = d.steps(session, &mut inputs, &mut outputs);
    d.report.wall = d.began.elapsed();
    d.report.end_time = session.time();
    d.report.rejected = inputs.rejections();
    d.report.applied = inputs.applied;
    d.report.datagrams_sent = outputs.sent;
    d.report.journal_flushes = d.journal_flushes;
    if let Some(p) = d.pacer.take() {
        d.report.lateness = p.lateness;
        d.report.overruns = p.overruns;
    }
    if let State::Ended(Some(r)) = session.state() {
        d.report.ended_by.get_or_insert(r.clone());
    }
    result.map(|()| d.report)
}

struct Driver<'o> {
    report: Report,
    pacer: Option<Pacer>,
    opts: &'o RealTimeOptions,
    began: Instant,
    last_note: Option<Instant>,
    noted_overruns: u64,
    /// Arrivals applied whose values no datagram has carried yet.
    waiting_datagram: Vec<Instant>,
    /// The journal's last flush (at most one a wall second), and how many there were.
    last_flush: Instant,
    journal_flushes: u64,
    next_checkpoint: Option<f64>,
}

impl Driver<'_> {
    fn steps(
        &mut self,
        session: &mut Session,
        inputs: &mut Inputs,
        outputs: &mut Outputs,
    ) -> Result<()> {
        let interrupt = self.opts.interrupt.as_deref();
        while *session.state() == State::Open {
            if interrupt.is_some_and(|f| f.load(std::sync::atomic::Ordering::SeqCst)) {
                return Err(Error::Interrupted {
                    time: session.time(),
                });
            }
            if let Some(reason) = inputs.apply(session)? {
                self.report.ended_by = Some(reason);
                return Ok(());
            }
            let applied_now = std::mem::take(&mut inputs.pending);
            session.step(1)?;
            self.report.macro_steps += 1;
            let t = session.time();
            if let Some(p) = self.pacer.as_mut() {
                let (waited, late) = p.wait(t, interrupt);
                if waited == Waited::Interrupted {
                    return Err(Error::Interrupted { time: t });
                }
                if late {
                    self.note_late(t);
                }
            }
            let sent = outputs.publish(session)?;
            let now = Instant::now();
            for a in &applied_now {
                self.report.delay.add(now - *a);
            }
            self.waiting_datagram.extend(applied_now);
            if sent {
                for a in self.waiting_datagram.drain(..) {
                    self.report.delay_to_datagram.add(now - a);
                }
            }
            if now - self.last_flush >= JOURNAL_FLUSH_EVERY {
                session.flush_journal()?;
                self.last_flush = now;
                self.journal_flushes += 1;
            }
            self.checkpoint(session, t)?;
        }
        Ok(())
    }

    /// The first late step is said at once; then a count at most every `report_every`.
    fn note_late(&mut self, t: f64) {
        let Some(p) = &self.pacer else { return };
        let now = Instant::now();
        let x = self.opts.factor.unwrap_or(1.0);
        match self.last_note {
            None => (self.opts.log)(&format!(
                "warning: the run cannot keep up with {x}x real time: the step to t = {t} s ended {:.3} ms after its deadline (late steps are counted, never skipped)",
                p.worst.as_secs_f64() * 1e3
            )),
            Some(last) if now - last >= self.opts.report_every && p.overruns > self.noted_overruns => {
                (self.opts.log)(&format!(
                    "warning: {} late steps so far (t = {t} s, worst {:.3} ms)",
                    p.overruns,
                    p.worst.as_secs_f64() * 1e3
                ))
            }
            Some(_) => return,
        }
        self.last_note = Some(now);
        self.noted_overruns = p.overruns;
    }

    fn checkpoint(&mut self, session: &mut Session, t: f64) -> Result<()> {
        let (Some(next), Some((every, path))) = (self.next_checkpoint, &self.opts.checkpoint_every)
        else {
            return Ok(());
        };
        if t + 1e-9 < next || *session.state() != State::Open {
            return Ok(());
        }
        self.next_checkpoint = Some(next + every);
        let cp = session.checkpoint()?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let file = path.with_file_name(format!("{stem}-{t}.ckpt"));
        cp.checkpoint.write(&file)?;
        self.report.checkpoints.push(file);
        Ok(())
    }
}
