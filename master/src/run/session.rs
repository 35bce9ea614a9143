//! A stepping session: a run driven from outside, one macro step or a stretch at a time, with
//! variables read and set between steps, checkpoints taken and restored, and every value set
//! from outside journaled so that the session replays offline bit for bit ([`journal`]).
//!
//! A session is the run of [`super::run_into`] cut at communication points: the same
//! initialization, the same step loop ([`Stepper::advance`]), the same recording. A session
//! that only reads is therefore the run bit for bit. A value set at t_k is an event at step k
//! (after the system file's events of that step), so it acts exactly as the same change
//! written as an event in the system file: on an input, the connection that drives it takes
//! over again at the next exchange.
//!
//! Restoring a checkpoint rewinds the whole session to it: the instances' states and the
//! exchange's values ([`Checkpoint`]), the values set from outside before it, and the rows
//! recorded up to it. The journal keeps the rewinding too, so a replay follows the session's
//! final history.

use super::algorithm::{GaussSeidel, Jacobi};
use super::exchange::{Column, Exchange, Values};
use super::recorder::{MemoryRecorder, Recorder};
use super::slot::{Slot, StepCount};
use super::stepping::{Recording, Stepper};
use super::time_grid::TimeGrid;
use super::{checkpoint::Fingerprint, initialize, start_recording, Checkpoint, RunOptions};
use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::instance::Stepping;
use crate::model_description::{ModelDescription, VarType};
use crate::system::{
    Algorithm as AlgorithmChoice, EventSpec, Plan, PlanEvent, System, TypedValue, Value, VarRef,
};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

mod journal;

pub use journal::{Journal, JournalHeader, Journaling, Replay};

/// A value set from outside: at base step `step`, the event it became.
#[derive(Debug, Clone)]
pub struct Set {
    pub step: u64,
    pub event: PlanEvent,
}

/// What state a session is in.
#[derive(Debug, Clone, PartialEq)]
pub enum State {
    /// At a communication point before the end: it can step.
    Open,
    /// At the end of the run (t_n), or ended early by an instance (the reason).
    Ended(Option<String>),
    /// An FMI call failed (the error's message): the instances are in an unknown state.
    Failed(String),
    /// Closed: the instances are terminated and freed.
    Closed,
}

/// A session's checkpoint: the master checkpoint at t_k, and the session's own history up to
/// it (the values set from outside before it, the rows recorded up to it).
#[derive(Debug, Clone)]
pub struct SessionCheckpoint {
    pub checkpoint: Checkpoint,
    session: u64,
    /// The journal's number of this checkpoint.
    pub id: u64,
    sets: Vec<Set>,
    time_column: Vec<f64>,
    data: Vec<Vec<f64>>,
    fmu_steps: u64,
}

impl SessionCheckpoint {
    pub fn time(&self) -> f64 {
        self.checkpoint.time
    }
    pub fn step(&self) -> u64 {
        self.checkpoint.step
    }
}

static SESSIONS: AtomicU64 = AtomicU64::new(1);

/// A run driven from outside (see the module documentation).
pub struct Session {
    system: System,
    plan: Plan,
    fmus: Vec<Arc<Fmu>>,
    slots: Vec<Slot<Stepping>>,
    values: Values,
    columns: Vec<Column>,
    rows: MemoryRecorder,
    /// Where the rows go instead of [`Session::rows`] after [`Session::record_into`].
    stream: Option<Box<dyn Recorder + Send>>,
    row_count: u64,
    grid: TimeGrid,
    /// The next base step: the session is at t_k.
    k: u64,
    count: StepCount,
    wall: Duration,
    /// The system file's events.
    file_events: Vec<PlanEvent>,
    /// The values set from outside in the session's history, in order.
    sets: Vec<Set>,
    state: State,
    opts: RunOptions,
    id: u64,
    checkpoints: u64,
    journal: Journal,
}

/// How a session starts, beyond the run's options.
#[derive(Default)]
pub struct SessionOptions {
    pub run: RunOptions,
    /// Where the journal is kept: in memory (the default), also in a file, or not at all.
    pub journal: Journaling,
}

impl Session {
    /// Validates `system` against `fmus`, instantiates and initializes every instance, and
    /// records the first row: the session is at t_0. The plan's warnings are in
    /// [`Session::warnings`].
    pub fn start(system: System, fmus: Vec<Arc<Fmu>>, opts: SessionOptions) -> Result<Session> {
        let mds: Vec<&ModelDescription> = fmus.iter().map(|f| &f.model_description).collect();
        let plan = system.validate(&mds)?;
        let header = JournalHeader::of(&system, &fmus)?;
        let journal = Journal::new(header, &opts.journal)?;
        let Exchange {
            ports,
            mut values,
            columns,
        } = Exchange::build(&plan);
        let run = opts.run;
        let slots = match plan.algorithm {
            AlgorithmChoice::Jacobi => {
                initialize::initialize(&Jacobi, &plan, &fmus, ports, &mut values, &run)?
            }
            AlgorithmChoice::GaussSeidel => {
                let gs = GaussSeidel { order: &plan.order };
                initialize::initialize(&gs, &plan, &fmus, ports, &mut values, &run)?
            }
        };
        let mut rows = MemoryRecorder::new();
        {
            let mut rec = start_recording(&plan, &mut rows, &columns, 0, plan.n_steps)?;
            rec.row(plan.start_time, &values)?;
        }
        let state = match plan.n_steps {
            0 => State::Ended(None),
            _ => State::Open,
        };
        Ok(Session {
            grid: TimeGrid::of(&plan),
            file_events: plan.events.clone(),
            system,
            plan,
            fmus,
            slots,
            values,
            columns,
            rows,
            stream: None,
            row_count: 1,
            k: 0,
            count: StepCount::default(),
            wall: Duration::ZERO,
            sets: Vec::new(),
            state,
            opts: run,
            id: SESSIONS.fetch_add(1, Ordering::Relaxed),
            checkpoints: 0,
            journal,
        })
    }

    /// A session of `system` continued from a master checkpoint of the same system (else an
    /// error naming the difference, [`Checkpoint::check`]): fresh instances are initialized,
    /// then every state and the exchange's values are restored, and the session is at the
    /// checkpoint's time with its row recorded. For the loop analysis's forks, which keep no
    /// journal: the checkpoint's past is in no journal, so the journal is off.
    pub(crate) fn resume(
        system: System,
        fmus: Vec<Arc<Fmu>>,
        cp: &Checkpoint,
        run: RunOptions,
    ) -> Result<Session> {
        let opts = SessionOptions {
            run,
            journal: Journaling::Off,
        };
        let mut s = Session::start(system, fmus, opts)?;
        s.continue_from(cp)?;
        Ok(s)
    }

    /// Puts a freshly started session at checkpoint `cp` (see [`Session::resume`]); the
    /// session's plan (its events before the checkpoint's step included) must be the
    /// checkpoint's.
    fn continue_from(&mut self, cp: &Checkpoint) -> Result<()> {
        for (pi, fmu) in self.plan.instances.iter().zip(&self.fmus) {
            fmu.require_state_support(&pi.name)?;
        }
        cp.check(&Fingerprint::of(&self.plan, &self.fmus)?)?;
        cp.restore(&mut self.slots, &mut self.values)?;
        self.k = cp.step;
        self.rows = MemoryRecorder::new();
        {
            let mut rec = start_recording(
                &self.plan,
                &mut self.rows,
                &self.columns,
                cp.step,
                self.plan.n_steps,
            )?;
            rec.row(cp.time, &self.values)?;
        }
        self.row_count = 1;
        Ok(())
    }

    /// Sets the offset of Real connection `connection` (an index into the plan's
    /// connections) from the next step on: its destination then gets gain*source + `offset`.
    /// For the loop analysis, which injects a signal on a connection ([`crate::analysis`]);
    /// not journaled, so not part of the public session.
    pub(crate) fn set_connection_offset(&mut self, connection: usize, offset: f64) -> Result<()> {
        let c = &self.plan.connections[connection];
        let ok = self.slots[c.to_instance]
            .ports
            .set_real_offset(&c.name, c.gain, offset);
        match ok {
            true => Ok(()),
            false => Err(Error::Other(format!(
                "connection {}: not a Real connection of a single term",
                c.name
            ))),
        }
    }

    /// Adds events the caller resolved and checked (the loop analysis's injected input),
    /// each after the events of its step. Not journaled.
    pub(crate) fn add_events(&mut self, events: impl IntoIterator<Item = PlanEvent>) {
        for e in events {
            let at = self.plan.events.partition_point(|x| x.step <= e.step);
            self.plan.events.insert(at, e);
        }
    }

    /// Records the session's rows into `recorder` from now on instead of keeping them in
    /// memory: the recorder is started with the run's columns and gets the row at t_0 at once,
    /// then every row as the session steps, and is finished when the session closes. For a
    /// long session (a paced run, [`crate::realtime`]) whose rows must not pile up in memory:
    /// [`Session::rows`] is then empty, and a checkpoint can be taken (to save it) but not
    /// restored. Only at t_0, before any value is set.
    pub fn record_into(&mut self, mut recorder: Box<dyn Recorder + Send>) -> Result<()> {
        if self.k != 0 || !self.sets.is_empty() || self.stream.is_some() {
            return Err(Error::Other(
                "a session records into a recorder only from its start, before any step or set, and once".into(),
            ));
        }
        if let Some(e) = self.unusable_to_read() {
            return Err(e);
        }
        {
            let r = recorder.as_mut() as &mut dyn Recorder;
            let mut rec = start_recording(&self.plan, r, &self.columns, 0, self.plan.n_steps)?;
            rec.row(self.plan.start_time, &self.values)?;
        }
        self.rows = MemoryRecorder::new();
        self.stream = Some(recorder);
        Ok(())
    }

    /// The validation's warnings.
    pub fn warnings(&self) -> &[String] {
        &self.plan.warnings
    }
    /// t_k, the communication point the session is at.
    pub fn time(&self) -> f64 {
        self.grid.at(self.k)
    }
    /// The base step k of [`Session::time`].
    pub fn step_index(&self) -> u64 {
        self.k
    }
    pub fn plan(&self) -> &Plan {
        &self.plan
    }
    pub fn state(&self) -> &State {
        &self.state
    }
    /// The rows recorded so far (the run's recorded variables, every `decimation` steps).
    pub fn rows(&self) -> &MemoryRecorder {
        &self.rows
    }
    pub fn journal(&self) -> &Journal {
        &self.journal
    }
    /// Writes the journal's buffered records to its file (a paced run does so at most once a
    /// wall second, so that a crash loses at most a second of inputs).
    pub fn flush_journal(&mut self) -> Result<()> {
        self.journal.flush()
    }
    /// The journal as JSON Lines, ending with the session's step if it is not closed yet (a
    /// replay of it reaches the session's time); an error if the session keeps none.
    pub fn journal_text(&self) -> Result<String> {
        if self.journal.is_off() {
            return Err(Error::Other(
                "the session keeps no journal (it was started with the journal off)".into(),
            ));
        }
        let mut text = self.journal.to_text();
        if self.state != State::Closed {
            text.push_str(&journal::end_line(self.k));
        }
        Ok(text)
    }
    /// fmi2DoStep calls so far, and the wall time spent stepping.
    pub fn counts(&self) -> (u64, Duration) {
        (self.count.fmu_steps, self.wall)
    }
    pub fn system(&self) -> &System {
        &self.system
    }
    /// The FMUs, `fmus()[i]` for instance i.
    pub fn fmus(&self) -> &[Arc<Fmu>] {
        &self.fmus
    }

    /// The error of a session that cannot do `what` in its state (closed, failed, at its
    /// end), or None when it is open.
    pub fn unusable(&self, what: &str) -> Option<Error> {
        let why = match &self.state {
            State::Open => return None,
            State::Ended(None) => format!(
                "it is at the end of the run, t = {} s (start a session with a later stop_time to go further)",
                self.time()
            ),
            State::Ended(Some(r)) => r.clone(),
            State::Failed(m) => format!("it failed: {m}"),
            State::Closed => "it is closed".to_string(),
        };
        Some(Error::Other(format!("cannot {what}: {why}")))
    }

    /// Advances `n` macro steps (fewer at the end of the run or an early end); returns the
    /// time reached.
    pub fn step(&mut self, n: u64) -> Result<f64> {
        self.advance_until(self.k.saturating_add(n), "step")
    }

    /// Advances to time `t`: a communication point of the run's grid (within 1e-6 of a step,
    /// the rule of event times), at or after the session's time and at most its stop time.
    pub fn advance_to(&mut self, t: f64) -> Result<f64> {
        let now = self.time();
        let kf = (t - self.plan.start_time) / self.plan.step_size;
        let k = kf.round();
        let end = self.grid.at(self.plan.n_steps);
        if !(k >= self.k as f64) || (kf - k).abs() > 1e-6 || k > self.plan.n_steps as f64 {
            return Err(Error::Other(format!(
                "advance_to({t}): the time must be a communication point t0 + k*h (h = {} s) from the session's time {now} s to its stop time {end} s",
                self.plan.step_size
            )));
        }
        self.advance_until(k as u64, "advance")
    }

    fn advance_until(&mut self, until: u64, what: &str) -> Result<f64> {
        if let Some(e) = self.unusable(what) {
            return Err(e);
        }
        let until = until.min(self.plan.n_steps);
        let result = match self.plan.algorithm {
            AlgorithmChoice::Jacobi => self.run_stepper(&Jacobi, until),
            AlgorithmChoice::GaussSeidel => {
                let order = std::mem::take(&mut self.plan.order);
                let r = self.run_stepper(&GaussSeidel { order: &order }, until);
                self.plan.order = order;
                r
            }
        };
        match result {
            Ok(()) => {}
            Err(e @ Error::Interrupted { .. }) => return Err(e),
            Err(e) => {
                self.state = State::Failed(e.to_string());
                return Err(e);
            }
        }
        if let Some(r) = &self.count.terminated_by {
            self.state = State::Ended(Some(r.clone()));
        } else if self.k >= self.plan.n_steps {
            self.state = State::Ended(None);
        }
        Ok(self.time())
    }

    /// The step loop of a run from t_k to t_`until`, on the session's instances and values
    /// (moved into a [`Stepper`] and back, which allocates nothing).
    fn run_stepper<A: super::algorithm::Algorithm>(
        &mut self,
        algorithm: &A,
        until: u64,
    ) -> Result<()> {
        let mut stepper = Stepper {
            grid: self.grid,
            events: &self.plan.events,
            slots: std::mem::take(&mut self.slots),
            values: std::mem::take(&mut self.values),
            recording: Some(Recording {
                recorder: match self.stream.as_deref_mut() {
                    Some(r) => r as &mut dyn Recorder,
                    None => &mut self.rows as &mut dyn Recorder,
                },
                columns: &self.columns,
                decimation: self.plan.decimation as u64,
                rows: self.row_count,
            }),
            progress: None,
            interrupt: self.opts.interrupt.as_deref(),
            k: self.k,
            count: std::mem::take(&mut self.count),
            wall: self.wall,
            profile: None,
        };
        let result = stepper.advance(algorithm, until);
        self.row_count = stepper.recording.as_ref().map_or(0, |r| r.rows);
        self.k = stepper.k;
        self.wall = stepper.wall;
        self.count = std::mem::take(&mut stepper.count);
        self.slots = std::mem::take(&mut stepper.slots);
        self.values = std::mem::take(&mut stepper.values);
        if let (Err(Error::Interrupted { .. }), Some(flag)) = (&result, &self.opts.interrupt) {
            // The session stays usable at t_k; the next call is not interrupted again.
            flag.store(false, Ordering::SeqCst);
        }
        result
    }

    /// The variable `instance.variable` of the system, with its instance index; an unknown
    /// name is an error with close names.
    pub fn variable(
        &self,
        name: &str,
    ) -> Result<(usize, &crate::model_description::ScalarVariable)> {
        let r = VarRef::parse(name)
            .ok_or_else(|| Error::Other(format!("'{name}' is not instance.variable")))?;
        let Some(i) = self
            .plan
            .instances
            .iter()
            .position(|p| p.name == r.instance)
        else {
            return Err(Error::Other(format!(
                "'{name}': no instance '{}' in {}{}",
                r.instance,
                self.system.source.display(),
                crate::error::did_you_mean(
                    &r.instance,
                    self.plan.instances.iter().map(|p| p.name.as_str())
                )
            )));
        };
        let md = &self.fmus[i].model_description;
        match self.fmus[i].variable(&r.variable) {
            Some(v) => Ok((i, v)),
            None => Err(Error::Other(format!(
                "'{name}': instance '{}' ({}) has no variable '{}'{}",
                r.instance,
                self.system.instances[i].fmu.display(),
                r.variable,
                crate::error::did_you_mean(
                    &r.variable,
                    md.model_variables.variables.iter().map(|v| v.name.as_str())
                )
            ))),
        }
    }

    /// The current value of any variable of any instance, in the FMU's unit: a connection
    /// source or recorded output as published at t_k (what the rows and the connections see),
    /// any other variable by fmi2GetXXX (for an instance with a step multiple above 1, between
    /// its steps, that is its value at the end of its current step). Reading changes nothing.
    pub fn get(&mut self, name: &str) -> Result<TypedValue> {
        if let Some(e) = self.unusable_to_read() {
            return Err(e);
        }
        let (i, sv) = self.variable(name)?;
        let (vr, t) = (sv.value_reference, sv.var_type());
        if let Some(v) = self.published(i, vr, t) {
            return Ok(v);
        }
        let inst = &mut self.slots[i].inst;
        Ok(match t {
            Some(VarType::Real) => {
                let mut x = [0.0];
                inst.get_real(&[vr], &mut x)?;
                TypedValue::Real(x[0])
            }
            Some(VarType::Integer | VarType::Enumeration) => {
                let mut x = [0];
                inst.get_integer(&[vr], &mut x)?;
                TypedValue::Integer(x[0])
            }
            Some(VarType::Boolean) => {
                let mut x = [0];
                inst.get_boolean(&[vr], &mut x)?;
                TypedValue::Boolean(x[0] != 0)
            }
            Some(VarType::String) | None => {
                TypedValue::String(inst.get_string(&[vr])?.pop().unwrap_or_default())
            }
        })
    }

    /// An observed variable's value (a connection source or a recorded output) as published
    /// at t_k: what the rows and the connections see. An instance with a step multiple m > 1
    /// is, between its steps, already at the end of its current step (under Jacobi its outputs
    /// are published when that step ends), so its FMU would answer with a later value.
    fn published(&self, i: usize, vr: crate::fmu::VR, t: Option<VarType>) -> Option<TypedValue> {
        let v = &self.values;
        Some(match self.slots[i].ports.observed_column(t?, vr)? {
            Column::Real(g) => TypedValue::Real(v.real[g]),
            Column::Integer(g) => TypedValue::Integer(v.integer[g]),
            Column::Boolean(g) => TypedValue::Boolean(v.boolean[g] != 0),
            Column::String(g) => TypedValue::String(v.string[g].clone()),
        })
    }

    /// Reading needs live instances: open or at the end, not failed or closed.
    pub fn unusable_to_read(&self) -> Option<Error> {
        match self.state {
            State::Open | State::Ended(_) => None,
            _ => self.unusable("read"),
        }
    }

    /// Sets an input or tunable parameter at t_k: an event at step k, checked as one
    /// ([`System::resolve_event`]: name, type, unit, declared range, causality), applied
    /// before the next step after the system file's events of that step, and journaled.
    pub fn set(&mut self, name: &str, value: Value) -> Result<()> {
        if let Some(e) = self.unusable("set a value") {
            return Err(e);
        }
        let target = VarRef::parse(name)
            .ok_or_else(|| Error::Other(format!("'{name}' is not instance.variable")))?;
        self.variable(name)?;
        let spec = EventSpec {
            time: self.time(),
            target,
            value,
            line: None,
        };
        let mds: Vec<&ModelDescription> = self.fmus.iter().map(|f| &f.model_description).collect();
        let end = self.grid.at(self.plan.n_steps);
        let event = self
            .system
            .resolve_event(&mds, &spec, self.plan.n_steps, end)?;
        self.journal.set(self.k, self.time(), &event)?;
        self.push(Set {
            step: self.k,
            event,
        });
        Ok(())
    }

    /// Adds a set to the history and its event to the step loop's, after those of its step.
    fn push(&mut self, set: Set) {
        let at = self.plan.events.partition_point(|e| e.step <= set.step);
        self.plan.events.insert(at, set.event.clone());
        self.sets.push(set);
    }

    /// The session at t_k as a checkpoint (every FMU's serialized state; the FMUs must
    /// support it): restore it later with [`Session::restore`], or write its master
    /// checkpoint to a file ([`Checkpoint::write`]).
    pub fn checkpoint(&mut self) -> Result<SessionCheckpoint> {
        if let Some(e) = self.unusable("take a checkpoint") {
            return Err(e);
        }
        for (pi, fmu) in self.plan.instances.iter().zip(&self.fmus) {
            fmu.require_state_support(&pi.name)?;
        }
        let fp = Fingerprint::of(&self.plan, &self.fmus)?;
        let cp = Checkpoint::capture(fp, self.k, &mut self.slots, &self.values)?;
        self.checkpoints += 1;
        let id = self.checkpoints;
        self.journal.checkpoint(id, self.k)?;
        // A streaming session keeps no rows to copy (and cannot be restored).
        let n = self.rows.time.len().min(self.row_count as usize);
        Ok(SessionCheckpoint {
            checkpoint: cp,
            session: self.id,
            id,
            sets: self.sets.clone(),
            time_column: self.rows.time[..n].to_vec(),
            data: self.rows.data.iter().map(|c| c[..n].to_vec()).collect(),
            fmu_steps: self.count.fmu_steps,
        })
    }

    /// Rewinds the session to a checkpoint it took: the instances' states, the exchange's
    /// values, the values set from outside and the rows recorded are those of that time.
    /// A session that ended can be rewound; one that failed or was closed cannot.
    pub fn restore(&mut self, cp: &SessionCheckpoint) -> Result<()> {
        if matches!(self.state, State::Failed(_) | State::Closed) {
            return Err(self.unusable("restore a checkpoint").expect("not open"));
        }
        if self.stream.is_some() {
            return Err(Error::Other(format!(
                "cannot restore the checkpoint at t = {} s: the session streams its rows into a recorder, which cannot take them back",
                cp.time()
            )));
        }
        if cp.session != self.id {
            return Err(Error::Other(format!(
                "cannot restore the checkpoint at t = {} s: it was taken by another session (a session restores its own checkpoints; a checkpoint saved to a file starts a session of the same system with resume)",
                cp.time()
            )));
        }
        if let Err(e) = cp.checkpoint.restore(&mut self.slots, &mut self.values) {
            self.state = State::Failed(e.to_string());
            return Err(e);
        }
        self.journal.restore(cp.id, cp.step())?;
        self.k = cp.step();
        self.count = StepCount {
            fmu_steps: cp.fmu_steps,
            terminated_by: None,
        };
        self.plan.events = self.file_events.clone();
        self.sets.clear();
        for s in &cp.sets {
            self.push(s.clone());
        }
        self.rows.time.clear();
        self.rows.time.extend_from_slice(&cp.time_column);
        for (col, saved) in self.rows.data.iter_mut().zip(&cp.data) {
            col.clear();
            col.extend_from_slice(saved);
        }
        self.row_count = cp.time_column.len() as u64;
        self.state = State::Open;
        Ok(())
    }

    /// Ends the session: the journal is closed with the session's last step, the instances
    /// are terminated and freed. Closing twice does nothing.
    pub fn close(&mut self) -> Result<()> {
        if self.state == State::Closed {
            return Ok(());
        }
        let failed = matches!(self.state, State::Failed(_));
        self.state = State::Closed;
        let end = self.journal.end(self.k);
        let _ = self.rows.finish();
        let streamed = self.stream.as_mut().map_or(Ok(()), |r| r.finish());
        let slots = std::mem::take(&mut self.slots);
        let mut first_error = None;
        for s in slots {
            // A failed instance is freed by the drop, without fmi2Terminate.
            if failed {
                drop(s);
            } else if let Err(e) = s.inst.terminate() {
                first_error.get_or_insert(e);
            }
        }
        end?;
        streamed?;
        first_error.map_or(Ok(()), Err)
    }

    /// Replays a journal ([`journal`]): the system it names (its file and FMUs must have the
    /// hashes the journal gives), with the values set from outside that made the session's
    /// final history, to the session's last time. The rows equal the session's bit for bit.
    pub fn replay(path: &Path, run: RunOptions) -> Result<Session> {
        let replay = Replay::read(path)?;
        let (system, fmus) = replay.system(&run)?;
        let opts = SessionOptions {
            run,
            journal: Journaling::Off,
        };
        let mut session = Session::start(system, fmus, opts)?;
        let end = replay.end_step();
        session.push_replayed(path, replay.sets())?;
        session.advance_until(end, "replay")?;
        Ok(session)
    }

    /// Replays a journal from a checkpoint of its session (a paced run's `--checkpoint-every`,
    /// [`Checkpoint::read`]): the session resumed at the checkpoint's step k ([`Session::resume`],
    /// which checks that the checkpoint belongs to the journal's system and its values set
    /// before step k), the journal's values set at step k or later applied, to the session's last time. Its rows are the full
    /// replay's from t_k on, bit for bit.
    pub fn replay_from(path: &Path, checkpoint: &Path, run: RunOptions) -> Result<Session> {
        let replay = Replay::read(path)?;
        let bad = |message: String| Error::Checkpoint {
            file: checkpoint.to_path_buf(),
            message,
        };
        let cp = Checkpoint::read(checkpoint)?;
        let end = replay.end_step();
        if cp.step > end {
            return Err(bad(format!(
                "its step {} (t = {} s) is after the journal's last step {end}",
                cp.step, cp.time
            )));
        }
        let (system, fmus) = replay.system(&run)?;
        let opts = SessionOptions {
            run,
            journal: Journaling::Off,
        };
        let mut session = Session::start(system, fmus, opts)?;
        // Every value set is an event of the plan (those before the checkpoint are part of what
        // the checkpoint is checked against); from the checkpoint on, those at or after its step
        // are applied.
        session.push_replayed(path, replay.sets())?;
        session.continue_from(&cp).map_err(|e| bad(e.to_string()))?;
        session.advance_until(end, "replay")?;
        Ok(session)
    }

    /// A journal's values set, as events of this session at their steps.
    fn push_replayed(&mut self, path: &Path, sets: Vec<(u64, String, Value)>) -> Result<()> {
        let mds_len = self.fmus.len();
        debug_assert_eq!(mds_len, self.plan.instances.len());
        for (step, name, value) in sets {
            let spec = EventSpec {
                time: self.grid.at(step),
                target: VarRef::parse(&name).ok_or_else(|| {
                    Error::Other(format!(
                        "{}: '{name}' is not instance.variable",
                        path.display()
                    ))
                })?,
                value,
                line: None,
            };
            let mds: Vec<&ModelDescription> =
                self.fmus.iter().map(|f| &f.model_description).collect();
            let end_t = self.grid.at(self.plan.n_steps);
            let event = self
                .system
                .resolve_event(&mds, &spec, self.plan.n_steps, end_t)
                .map_err(|e| Error::Other(format!("{}: {e}", path.display())))?;
            self.push(Set { step, event });
        }
        Ok(())
    }
}

impl Drop for Session {
    /// A session dropped without [`Session::close`] ends its journal where it stood (so a
    /// replay goes as far), and its instances free themselves as they drop.
    fn drop(&mut self) {
        if self.state != State::Closed {
            let _ = self.journal.end(self.k);
        }
    }
}
