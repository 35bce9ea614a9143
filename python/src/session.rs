//! `shipsim._native.Session`: a stepping session of the master ([`shipsim::run::Session`]),
//! driven from Python one step or a stretch at a time. Conversions and errors only: the
//! session is the library's.
//!
//! Stepping releases the GIL. A short call (at most [`DETACHED_STEPS`] macro steps) runs on the
//! calling thread; a longer one runs as a run does ([`run_detached`]), so that Ctrl-C stops it
//! at its next communication point, where the session stays usable. A session is used by one
//! thread at a time: a second thread that calls it while it steps gets a [`SessionError`] at
//! once, never a wait.

use super::{
    obj, py_err, rows_dict, run_detached, run_options, to_value, Logs, SessionError, VariableError,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use shipsim::error::Error;
use shipsim::isolate::Isolation;
use shipsim::run::{Journaling, Session, SessionCheckpoint, SessionOptions, State};
use shipsim::system::{System, TypedValue};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex, MutexGuard, TryLockError};

/// Longer calls run on a thread of their own and can be interrupted by Ctrl-C.
const DETACHED_STEPS: u64 = 2000;

#[pyclass(module = "shipsim._native", name = "Session")]
pub struct PySession {
    /// Locked by the call that uses it; a second thread's `try_lock` fails at once.
    inner: Mutex<Session>,
    logs: Logs,
    interrupt: Arc<AtomicBool>,
}

#[pyclass(module = "shipsim._native", name = "Checkpoint")]
pub struct PyCheckpoint {
    inner: SessionCheckpoint,
}

/// The error of a second thread calling a session that is stepping.
fn busy(what: &str) -> PyErr {
    SessionError::new_err(format!(
        "{what}: the session is being stepped by another thread; a session is used by one \
         thread at a time (start one session per thread)"
    ))
}

/// A session error: a state refusal is a [`SessionError`], an interrupt a KeyboardInterrupt,
/// an FMI failure a SimulationError ([`py_err`]).
fn session_err(py: Python<'_>, e: Error) -> PyErr {
    match e {
        Error::Other(m) => SessionError::new_err(m),
        e => py_err(py, e),
    }
}

/// A set or get that names a variable it cannot use: a [`VariableError`].
fn variable_err(py: Python<'_>, e: Error) -> PyErr {
    match e {
        Error::Other(m) => VariableError::new_err(m),
        Error::System { message, .. } => VariableError::new_err(message),
        e => py_err(py, e),
    }
}

impl PySession {
    pub fn start(
        py: Python<'_>,
        system: System,
        fmus: Vec<Arc<shipsim::fmu::Fmu>>,
        verbose: bool,
        isolation: Isolation,
        journal: Journaling,
    ) -> PyResult<PySession> {
        let (run, logs, interrupt) = run_options(verbose, isolation);
        let opts = SessionOptions { run, journal };
        let started = py.detach(|| Session::start(system, fmus, opts));
        logs.emit(py)?;
        Ok(PySession {
            inner: Mutex::new(started.map_err(|e| py_err(py, e))?),
            logs,
            interrupt,
        })
    }

    /// The session, if no other thread is using it (`what` names the call for the error).
    fn lock(&self, what: &str) -> PyResult<MutexGuard<'_, Session>> {
        match self.inner.try_lock() {
            Ok(g) => Ok(g),
            // A panic in the master while stepping: the session is unusable, not the process.
            Err(TryLockError::Poisoned(p)) => Ok(p.into_inner()),
            Err(TryLockError::WouldBlock) => Err(busy(what)),
        }
    }

    /// Steps to base step `until` (or to time `t`) with the GIL released (see the module
    /// documentation).
    fn advance(&self, py: Python<'_>, what: &str, n: Option<u64>, t: Option<f64>) -> PyResult<f64> {
        let mut guard = self.lock(what)?;
        if let Some(e) = guard.unusable("step") {
            return Err(SessionError::new_err(e.to_string()));
        }
        let inner: &mut Session = &mut guard;
        let until = match (n, t) {
            (Some(n), _) => inner.step_index().saturating_add(n),
            (None, Some(t)) => {
                ((t - inner.plan().start_time) / inner.plan().step_size).max(0.0) as u64
            }
            (None, None) => inner.step_index(),
        };
        let long = until.saturating_sub(inner.step_index()) > DETACHED_STEPS;
        let go = move |s: &mut Session| match t {
            Some(t) => s.advance_to(t),
            None => s.step(n.unwrap_or(0)),
        };
        let result = match long {
            false => py.detach(|| go(inner)),
            true => run_detached(py, &self.interrupt, |_| Ok(()), || go(inner))?,
        };
        self.logs.emit(py)?;
        result.map_err(|e| session_err(py, e))
    }
}

#[pymethods]
impl PySession {
    /// Advances `n` macro steps (fewer at the end); returns the time reached.
    #[pyo3(signature = (n=1))]
    fn step(&self, py: Python<'_>, n: i64) -> PyResult<f64> {
        if n < 0 {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "step(n={n}): n is a number of macro steps, 0 or more"
            )));
        }
        self.advance(py, "step", Some(n as u64), None)
    }

    /// Advances to time `t`, a communication point of the run's grid.
    fn advance_to(&self, py: Python<'_>, t: f64) -> PyResult<f64> {
        self.advance(py, "advance_to", None, Some(t))
    }

    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.lock("time")?.time())
    }
    #[getter]
    fn step_index(&self) -> PyResult<u64> {
        Ok(self.lock("step_index")?.step_index())
    }
    #[getter]
    fn stop_time(&self) -> PyResult<f64> {
        Ok(self.lock("stop_time")?.plan().stop_time)
    }
    #[getter]
    fn step_size(&self) -> PyResult<f64> {
        Ok(self.lock("step_size")?.plan().step_size)
    }
    #[getter]
    fn warnings(&self) -> PyResult<Vec<String>> {
        Ok(self.lock("warnings")?.warnings().to_vec())
    }
    /// "open", "ended", "failed" or "closed", and the reason (an early end, the failure).
    #[getter]
    fn state(&self) -> PyResult<(String, Option<String>)> {
        let this = self.lock("state")?;
        Ok(match this.state() {
            State::Open => ("open".into(), None),
            State::Ended(r) => ("ended".into(), r.clone()),
            State::Failed(m) => ("failed".into(), Some(m.clone())),
            State::Closed => ("closed".into(), None),
        })
    }

    /// The current value of `instance.variable`, in the FMU's unit.
    fn get(&self, py: Python<'_>, name: &str) -> PyResult<Py<PyAny>> {
        let mut this = self.lock("get")?;
        if let Some(e) = this.unusable_to_read() {
            return Err(SessionError::new_err(e.to_string()));
        }
        let v = this.get(name).map_err(|e| variable_err(py, e))?;
        Ok(match v {
            TypedValue::Real(x) => obj(py, x),
            TypedValue::Integer(x) => obj(py, x),
            TypedValue::Boolean(x) => obj(py, x),
            TypedValue::String(x) => obj(py, x),
        })
    }

    /// Sets an input or tunable parameter before the next step, as an event at this time.
    fn set(&self, py: Python<'_>, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut this = self.lock("set")?;
        if let Some(e) = this.unusable("set a value") {
            return Err(SessionError::new_err(e.to_string()));
        }
        let (_, sv) = this.variable(name).map_err(|e| variable_err(py, e))?;
        let v = to_value(name, sv, value)?;
        this.set(name, v).map_err(|e| variable_err(py, e))
    }

    /// The rows recorded so far (the layout of `System.run`'s).
    fn rows<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let this = self.lock("rows")?;
        let s: &Session = &this;
        let mds: Vec<_> = s.fmus().iter().map(|f| &f.model_description).collect();
        let out = rows_dict(py, s.plan(), s.system(), &mds, s.rows())?;
        let (fmu_steps, wall) = s.counts();
        out.set_item("fmu_steps", fmu_steps)?;
        out.set_item("wall_time", wall.as_secs_f64())?;
        out.set_item("warnings", s.warnings().to_vec())?;
        Ok(out)
    }

    /// The session at this time, to restore later.
    fn checkpoint(&self, py: Python<'_>) -> PyResult<PyCheckpoint> {
        let mut this = self.lock("checkpoint")?;
        let s: &mut Session = &mut this;
        let cp = py.detach(|| s.checkpoint());
        cp.map(|inner| PyCheckpoint { inner })
            .map_err(|e| session_err(py, e))
    }

    /// Rewinds the session to one of its checkpoints.
    fn restore(&self, py: Python<'_>, checkpoint: &Bound<'_, PyCheckpoint>) -> PyResult<()> {
        let mut this = self.lock("restore")?;
        let s: &mut Session = &mut this;
        let cp = checkpoint.borrow();
        let cp: &SessionCheckpoint = &cp.inner;
        let r = py.detach(|| s.restore(cp));
        r.map_err(|e| session_err(py, e))
    }

    /// Terminates and frees the instances and ends the journal; closing twice does nothing.
    fn close(&self, py: Python<'_>) -> PyResult<()> {
        let mut this = self.lock("close")?;
        let s: &mut Session = &mut this;
        let r = py.detach(|| s.close());
        drop(this);
        self.logs.emit(py)?;
        r.map_err(|e| py_err(py, e))
    }

    /// The journal file, if the session writes one.
    #[getter]
    fn journal_path(&self) -> PyResult<Option<PathBuf>> {
        let this = self.lock("journal_path")?;
        Ok(this.journal().path().map(|p| p.to_path_buf()))
    }

    /// The journal so far, as JSON Lines.
    fn journal_text(&self) -> PyResult<String> {
        let this = self.lock("journal_text")?;
        this.journal_text()
            .map_err(|e| SessionError::new_err(e.to_string()))
    }
}

#[pymethods]
impl PyCheckpoint {
    #[getter]
    fn time(&self) -> f64 {
        self.inner.time()
    }
    #[getter]
    fn step(&self) -> u64 {
        self.inner.step()
    }
    /// Writes the master checkpoint (`shipsim run --resume FILE` continues from it).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        self.inner
            .checkpoint
            .write(&path)
            .map_err(|e| py_err(py, e))
    }
    fn __repr__(&self) -> String {
        format!(
            "Checkpoint(t = {} s, step {})",
            self.inner.time(),
            self.inner.step()
        )
    }
}

/// Replays a session journal; returns its rows (the layout of `System.run`'s).
#[pyfunction]
#[pyo3(signature = (journal, verbose=false))]
pub fn replay<'py>(
    py: Python<'py>,
    journal: PathBuf,
    verbose: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (run, logs, interrupt) = run_options(verbose, Default::default());
    let result = run_detached(
        py,
        &interrupt,
        |_| Ok(()),
        || Session::replay(&journal, run),
    );
    logs.emit(py)?;
    let mut s = result?.map_err(|e| py_err(py, e))?;
    let mds: Vec<_> = s.fmus().iter().map(|f| &f.model_description).collect();
    let out = rows_dict(py, s.plan(), s.system(), &mds, s.rows())?;
    out.set_item("warnings", s.warnings().to_vec())?;
    drop(mds);
    s.close().map_err(|e| py_err(py, e))?;
    Ok(out)
}
