//! `shipsim._native`: the Python bindings of the shipsim master.
//!
//! Nothing is computed here: every function calls the `shipsim` library crate (the master the
//! CLI runs), and converts its results into plain Python values (dicts, lists, and `bytearray`
//! buffers of little-endian f64/i64 that the Python layer in `python/shipsim/` turns into numpy
//! arrays and pandas DataFrames without copying them again).
//!
//! Long calls (a run, a campaign, a chunk of runs) release the GIL and run on a thread of
//! their own, while the calling thread waits in slices of 50 ms: between slices it takes the
//! GIL to report progress and to check Python's signal state (`PyErr_CheckSignals`). A
//! pending KeyboardInterrupt sets the master's interrupt flag, which stops the run cleanly at
//! its next communication point (instances terminated and freed), and is then raised. No
//! process-wide signal handler is installed.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes, PyDict, PyList};
use shipsim::campaign::execute::{self, CampaignOptions, Observer};
use shipsim::campaign::journal::RunRecord;
use shipsim::campaign::remote::{self, Collector, Worker};
use shipsim::campaign::table::{ColumnData, Table};
use shipsim::campaign::{Campaign, Run};
use shipsim::error::{did_you_mean, Error};
use shipsim::fmu::{Fmu, UnpackedFmu};
use shipsim::log::{LogRecord, LogSink};
use shipsim::model_description::{ModelDescription, ScalarVariable, VarType};
use shipsim::run::{self, MemoryRecorder, RunOptions, Summary};
use shipsim::system::{System, Value, VarRef};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

mod analysis;
mod session;

create_exception!(
    shipsim,
    ShipsimError,
    PyException,
    "Base class of every error shipsim raises."
);
create_exception!(
    shipsim,
    FmuError,
    ShipsimError,
    "An FMU archive, its modelDescription.xml or its binary cannot be used."
);
create_exception!(
    shipsim,
    SystemFileError,
    ShipsimError,
    "A system or campaign file cannot be read, or does not validate against its FMUs."
);
create_exception!(
    shipsim,
    VariableError,
    ShipsimError,
    "No such instance or variable (the message suggests close names)."
);
create_exception!(
    shipsim,
    SimulationError,
    ShipsimError,
    "An FMU failed during a run: an FMI call returned fmi2Error or fmi2Fatal."
);
create_exception!(
    shipsim,
    CheckpointError,
    ShipsimError,
    "A checkpoint file cannot be used."
);

create_exception!(
    shipsim,
    SessionError,
    ShipsimError,
    "A stepping session cannot do what was asked in its state: it is closed, it failed, it \
     is at its end, or another thread is stepping it."
);

/// A shipsim error as the Python exception of its kind, with the same message as the CLI
/// and the fields that locate it as attributes (`path`, `file`, `line`, `instance`,
/// `function`, `status`, `time`).
fn py_err(py: Python<'_>, e: Error) -> PyErr {
    let message = e.to_string();
    let (err, attrs): (PyErr, Vec<(&str, Py<PyAny>)>) = match e {
        Error::Fmu { path, .. } => (FmuError::new_err(message), vec![("path", obj(py, path))]),
        Error::Fmi {
            instance,
            function,
            status,
            time,
            ..
        } => (
            SimulationError::new_err(message),
            vec![
                ("instance", obj(py, instance)),
                ("function", obj(py, function)),
                ("status", obj(py, fmi_status(status))),
                ("time", obj(py, time)),
            ],
        ),
        Error::Isolated {
            instance,
            function,
            time,
            ..
        } => (
            SimulationError::new_err(message),
            vec![
                ("instance", obj(py, instance)),
                ("function", obj(py, function)),
                ("status", py.None()),
                ("time", obj(py, time)),
            ],
        ),
        Error::System { file, line, .. } => (
            SystemFileError::new_err(message),
            vec![("file", obj(py, file)), ("line", obj(py, line))],
        ),
        Error::Many(ref all) if all.iter().all(|e| matches!(e, Error::System { .. })) => {
            (SystemFileError::new_err(message), Vec::new())
        }
        Error::Checkpoint { file, .. } => (
            CheckpointError::new_err(message),
            vec![("file", obj(py, file))],
        ),
        Error::Interrupted { .. } => (PyKeyboardInterrupt::new_err(message), Vec::new()),
        _ => (ShipsimError::new_err(message), Vec::new()),
    };
    let value = err.value(py);
    for (k, v) in attrs {
        let _ = value.setattr(k, v);
    }
    err
}

/// The FMI status name of a status code.
fn fmi_status(status: i32) -> &'static str {
    match status {
        0 => "fmi2OK",
        1 => "fmi2Warning",
        2 => "fmi2Discard",
        3 => "fmi2Error",
        4 => "fmi2Fatal",
        5 => "fmi2Pending",
        _ => "unknown",
    }
}

fn obj<'py, T: IntoPyObject<'py>>(py: Python<'py>, v: T) -> Py<PyAny> {
    use pyo3::IntoPyObjectExt;
    v.into_py_any(py).unwrap_or_else(|_| py.None())
}

/// Runs `work` on a thread of its own with the GIL released. Every 50 ms, and once at the
/// end, `poll` runs with the GIL (progress), and Python's signal state is checked: a pending
/// exception (KeyboardInterrupt from Ctrl-C) sets `interrupt`, waits for `work` to stop and
/// is raised.
fn run_detached<T: Send>(
    py: Python<'_>,
    interrupt: &Arc<AtomicBool>,
    mut poll: impl FnMut(Python<'_>) -> PyResult<()>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    std::thread::scope(|scope| {
        let (tx, rx) = std::sync::mpsc::channel();
        let rx = Mutex::new(rx);
        let handle = scope.spawn(move || {
            let out = work();
            let _ = tx.send(());
            out
        });
        loop {
            let finished = py.detach(|| {
                rx.lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .recv_timeout(Duration::from_millis(50))
                    .is_ok()
            });
            // A pending signal (KeyboardInterrupt) or a failing progress callback stops the
            // work cleanly, without holding the GIL while it winds down.
            if let Err(e) = poll(py).and_then(|()| match finished || handle.is_finished() {
                true => Ok(()),
                false => py.check_signals(),
            }) {
                interrupt.store(true, Ordering::SeqCst);
                let _ = py.detach(|| handle.join());
                return Err(e);
            }
            if finished || handle.is_finished() {
                break;
            }
        }
        py.detach(|| handle.join()).map_err(|panic| {
            let m = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "a panic without a message".into());
            ShipsimError::new_err(format!("panic in the master: {m}"))
        })
    })
}

/// The options of a run from Python: its own interrupt flag (set by [`run_detached`] on
/// Ctrl-C) and FMU messages collected for Python's `logging` ([`Logs`]).
fn run_options(
    verbose: bool,
    isolation: shipsim::isolate::Isolation,
) -> (RunOptions, Logs, Arc<AtomicBool>) {
    let interrupt = Arc::new(AtomicBool::new(false));
    let logs = Logs::default();
    let opts = RunOptions {
        verbose,
        interrupt: Some(interrupt.clone()),
        log_sink: Some(logs.sink(verbose)),
        isolation,
        ..Default::default()
    };
    (opts, logs, interrupt)
}

/// FMU log messages collected during a call, handed to Python's `logging` afterwards (the
/// master's threads do not hold the GIL).
#[derive(Clone, Default)]
struct Logs(Arc<Mutex<Vec<LogRecord>>>);

impl Logs {
    fn sink(&self, verbose: bool) -> LogSink {
        let logs = self.0.clone();
        Arc::new(move |r: &LogRecord| {
            if verbose || r.status >= 1 {
                let mut v = logs.lock().unwrap_or_else(|e| e.into_inner());
                // Bounded: a chatty FMU cannot grow memory without limit.
                if v.len() < 10_000 {
                    v.push(r.clone());
                }
            }
        })
    }

    /// Emits the collected messages on the `shipsim.fmu` logger (status -> level).
    fn emit(&self, py: Python<'_>) -> PyResult<()> {
        let records = std::mem::take(&mut *self.0.lock().unwrap_or_else(|e| e.into_inner()));
        if records.is_empty() {
            return Ok(());
        }
        let logger = py
            .import("logging")?
            .call_method1("getLogger", ("shipsim.fmu",))?;
        for r in records {
            let level = match r.status {
                0 => 20,     // INFO
                1 | 2 => 30, // WARNING
                3 => 40,     // ERROR
                _ => 50,     // CRITICAL
            };
            let text = format!(
                "[{}] {} {}: {}",
                r.instance,
                fmi_status(r.status),
                r.category,
                r.message
            );
            logger.call_method1("log", (level, text))?;
        }
        Ok(())
    }
}

/// A variable's start value as a Python value of its type.
fn start_value(py: Python<'_>, v: &ScalarVariable) -> Py<PyAny> {
    if let Some(r) = &v.real {
        return obj(py, r.start);
    }
    if let Some(i) = v.integer.as_ref().or(v.enumeration.as_ref()) {
        return obj(py, i.start);
    }
    if let Some(b) = &v.boolean {
        return obj(py, b.start);
    }
    if let Some(s) = &v.string {
        return obj(py, s.start.clone());
    }
    py.None()
}

/// One variable of a model description as a dict.
fn variable_dict<'py>(
    py: Python<'py>,
    md: &ModelDescription,
    v: &ScalarVariable,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", &v.name)?;
    d.set_item("value_reference", v.value_reference)?;
    d.set_item("type", v.var_type().map(VarType::name))?;
    d.set_item("causality", v.causality.xml_name())?;
    d.set_item("variability", v.variability.xml_name())?;
    d.set_item("initial", v.effective_initial().map(|i| i.xml_name()))?;
    d.set_item("start", start_value(py, v))?;
    d.set_item("description", v.description.clone())?;
    let real = v.real.as_ref();
    let int = v.integer.as_ref().or(v.enumeration.as_ref());
    d.set_item("unit", md.real_unit(v))?;
    d.set_item("display_unit", real.and_then(|r| r.display_unit.clone()))?;
    let declared = real
        .and_then(|r| r.declared_type.clone())
        .or_else(|| int.and_then(|i| i.declared_type.clone()));
    d.set_item("declared_type", declared)?;
    d.set_item(
        "min",
        match (real, int) {
            (Some(r), _) => obj(py, r.min),
            (_, Some(i)) => obj(py, i.min),
            _ => py.None(),
        },
    )?;
    d.set_item(
        "max",
        match (real, int) {
            (Some(r), _) => obj(py, r.max),
            (_, Some(i)) => obj(py, i.max),
            _ => py.None(),
        },
    )?;
    d.set_item("nominal", real.and_then(|r| r.nominal))?;
    Ok(d)
}

/// `shipsim.inspect(path)`: an FMU's model description (without loading its binary).
#[pyfunction]
fn inspect<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let u = UnpackedFmu::open(&path).map_err(|e| py_err(py, e))?;
    let cs = u.check().map_err(|e| py_err(py, e))?.clone();
    let md = &u.model_description;
    let d = PyDict::new(py);
    d.set_item("path", &path)?;
    d.set_item("model_name", &md.model_name)?;
    d.set_item("fmi_version", &md.fmi_version)?;
    d.set_item("guid", &md.guid)?;
    d.set_item("description", md.description.clone())?;
    d.set_item("generation_tool", md.generation_tool.clone())?;
    d.set_item("model_identifier", &cs.model_identifier)?;
    let caps = PyDict::new(py);
    for (k, v) in [
        (
            "can_handle_variable_communication_step_size",
            cs.can_handle_variable_communication_step_size,
        ),
        (
            "can_be_instantiated_only_once_per_process",
            cs.can_be_instantiated_only_once_per_process,
        ),
        ("can_get_and_set_fmu_state", cs.can_get_and_set_fmu_state),
        ("can_serialize_fmu_state", cs.can_serialize_fmu_state),
        ("needs_execution_tool", cs.needs_execution_tool),
        (
            "provides_directional_derivative",
            cs.provides_directional_derivative,
        ),
    ] {
        caps.set_item(k, v)?;
    }
    d.set_item("capabilities", caps)?;
    let exp = PyDict::new(py);
    if let Some(e) = &md.default_experiment {
        exp.set_item("start_time", e.start_time)?;
        exp.set_item("stop_time", e.stop_time)?;
        exp.set_item("tolerance", e.tolerance)?;
        exp.set_item("step_size", e.step_size)?;
    }
    d.set_item("default_experiment", exp)?;
    let vars = PyList::empty(py);
    for v in &md.model_variables.variables {
        vars.append(variable_dict(py, md, v)?)?;
    }
    d.set_item("variables", vars)?;
    Ok(d)
}

/// A Python value as the value of variable `name` (`sv`): bool (and numpy's bool for a Boolean
/// variable), int and float as themselves,
/// str as text parsed by the variable's type (as `--set` does). An Integer or Enumeration
/// variable takes a whole float (3.0, numpy's float64(3.0)) as that integer, as campaign
/// factors do; a float that is not whole, or a whole number outside fmi2Integer's 32 bits, is a
/// [`VariableError`] naming the variable, the value and the range ([`refused`]); a value inside
/// them but outside the declared min and max is the validation's error, as for `--set`. A Real
/// variable takes an int of any size as the nearest double (an OverflowError of Python's int
/// conversion before).
fn to_value(name: &str, sv: &ScalarVariable, value: &Bound<'_, PyAny>) -> PyResult<Value> {
    let t = sv.var_type();
    let whole = matches!(t, Some(VarType::Integer | VarType::Enumeration));
    if let Ok(b) = value.cast::<pyo3::types::PyBool>() {
        return Ok(Value::Boolean(b.is_true()));
    }
    // numpy's bool (`np.True_`, an element of a boolean array) is no bool, and its __float__
    // would make it a Real: a Boolean variable takes it as what it is.
    if t == Some(VarType::Boolean) && is_numpy_bool(value)? {
        return Ok(Value::Boolean(value.is_truthy()?));
    }
    let float = value.cast::<pyo3::types::PyFloat>().is_ok();
    // int, and numpy's integers (which have __index__ but are no int)
    if value.cast::<pyo3::types::PyInt>().is_ok() || (!float && value.hasattr("__index__")?) {
        return match value.extract::<i64>() {
            Ok(i) if whole && i32::try_from(i).is_err() => Err(refused(name, sv, value)),
            Ok(i) => Ok(Value::Integer(i)),
            Err(_) if t == Some(VarType::Real) => match value.extract::<f64>() {
                Ok(x) => Ok(Value::Real(x)),
                Err(_) => Err(VariableError::new_err(format!(
                    "'{name}' = {}: variable '{}' is a Real, and this number is beyond the \
                     largest double (about 1.8e308); give a smaller one",
                    shown(value),
                    sv.name
                ))),
            },
            Err(_) => Err(refused(name, sv, value)),
        };
    }
    if let Ok(f) = value.extract::<f64>() {
        if whole {
            if f.fract() == 0.0 && f >= f64::from(i32::MIN) && f <= f64::from(i32::MAX) {
                return Ok(Value::Integer(f as i64));
            }
            return Err(refused(name, sv, value));
        }
        return Ok(Value::Real(f));
    }
    if let Ok(s) = value.extract::<String>() {
        return Ok(Value::Text(s));
    }
    Err(pyo3::exceptions::PyTypeError::new_err(format!(
        "'{name}': a value must be a bool, int, float or str, not {}",
        value.get_type().name()?
    )))
}

/// `numpy.bool_` (named `numpy.bool` since numpy 2).
fn is_numpy_bool(value: &Bound<'_, PyAny>) -> PyResult<bool> {
    let ty = value.get_type();
    let module = ty.module()?.to_string();
    let name = ty.name()?.to_string();
    Ok(module == "numpy" && (name == "bool_" || name == "bool"))
}

/// A value for a message: its `repr`, at most 40 characters (`10**1000` is not written out).
fn shown(value: &Bound<'_, PyAny>) -> String {
    let text = value
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".into());
    match text.chars().count() {
        n if n > 40 => format!(
            "{}... ({n} characters)",
            text.chars().take(24).collect::<String>()
        ),
        _ => text,
    }
}

/// The [`VariableError`] of a number that variable `sv` cannot take, saying what it takes: an
/// Integer or Enumeration a whole number in fmi2Integer's range narrowed by the declared min
/// and max (a float that is not whole, an int beyond the range).
fn refused(name: &str, sv: &ScalarVariable, value: &Bound<'_, PyAny>) -> PyErr {
    let int = sv.integer.as_ref().or(sv.enumeration.as_ref());
    let lo = int.and_then(|i| i.min).unwrap_or(i32::MIN);
    let hi = int.and_then(|i| i.max).unwrap_or(i32::MAX);
    let (a, give) = match sv.var_type() {
        Some(VarType::Integer) => ("an Integer", format!("a whole number from {lo} to {hi}")),
        Some(VarType::Enumeration) => (
            "an Enumeration",
            format!("a whole number from {lo} to {hi}"),
        ),
        Some(VarType::Boolean) => ("a Boolean", "True or False".to_string()),
        Some(VarType::String) => ("a String", "a str".to_string()),
        Some(VarType::Real) | None => ("a Real", "a float".to_string()),
    };
    VariableError::new_err(format!(
        "'{name}' = {}: variable '{}' is {a}; give {give}",
        shown(value),
        sv.name
    ))
}

/// A system with its FMUs, loaded once and reused by every run.
#[pyclass(module = "shipsim._native", name = "System")]
struct PySystem {
    system: System,
    fmus: Vec<Arc<Fmu>>,
}

impl PySystem {
    fn mds(&self) -> Vec<&ModelDescription> {
        self.fmus.iter().map(|f| &f.model_description).collect()
    }

    /// The run's isolation (`System.run(isolate=..., call_timeout=...)`), by the library's
    /// parser that `shipsim run --isolate` uses too ([`shipsim::isolate::options`]): `isolate`
    /// "all", "foreign" or instance names separated by commas, or a list of instance names; a
    /// call time limit in seconds. An instance that does not exist is a [`VariableError`], a
    /// value that cannot be used a `ValueError`; the messages are the CLI's.
    fn isolation(
        &self,
        isolate: Option<String>,
        instances: Option<Vec<String>>,
        call_timeout: Option<f64>,
    ) -> PyResult<shipsim::isolate::Isolation> {
        use shipsim::isolate::{IsolateMode, Isolation, IsolationError};
        let to_py = |e: IsolationError| match e {
            IsolationError::UnknownInstance { .. } => VariableError::new_err(e.to_string()),
            e => pyo3::exceptions::PyValueError::new_err(e.to_string()),
        };
        let mode = match (isolate, instances) {
            (None, None) => IsolateMode::None,
            (Some(v), None) => IsolateMode::parse(&v).map_err(to_py)?,
            (None, Some(names)) => IsolateMode::Instances(names),
            (Some(_), Some(_)) => {
                return Err(pyo3::exceptions::PyValueError::new_err(
                    "isolate: give a value or a list of instance names, not both",
                ))
            }
        };
        let names: Vec<&str> = self
            .system
            .instances
            .iter()
            .map(|i| i.name.as_str())
            .collect();
        Isolation::from_options(mode, call_timeout, &self.system.source, &names).map_err(to_py)
    }

    /// Checks `instance.variable` (or `instance.*` when `wildcard`), with "did you mean".
    fn check_name(&self, name: &str, wildcard: bool) -> PyResult<()> {
        self.variable(name, wildcard).map(|_| ())
    }

    /// The variable `instance.variable` names (None for `instance.*` when `wildcard`), or a
    /// [`VariableError`] with close names.
    fn variable(&self, name: &str, wildcard: bool) -> PyResult<Option<&ScalarVariable>> {
        let instances = || self.system.instances.iter().map(|i| i.name.as_str());
        let (inst, var) = match name.split_once('.') {
            Some(p) => p,
            None => {
                return Err(VariableError::new_err(format!(
                    "'{name}' is not instance.variable"
                )))
            }
        };
        let Some(i) = self.system.instances.iter().position(|s| s.name == inst) else {
            return Err(VariableError::new_err(format!(
                "'{name}': no instance '{inst}' in {}{}",
                self.system.source.display(),
                did_you_mean(inst, instances())
            )));
        };
        if wildcard && var == "*" {
            return Ok(None);
        }
        let md = &self.fmus[i].model_description;
        if let Some(v) = md.model_variables.variables.iter().find(|v| v.name == var) {
            return Ok(Some(v));
        }
        let names = md.model_variables.variables.iter().map(|v| v.name.as_str());
        Err(VariableError::new_err(format!(
            "'{name}': instance '{inst}' ({}) has no variable '{var}'{}",
            self.system.instances[i].fmu.display(),
            did_you_mean(var, names)
        )))
    }
}

/// The error of changing a System while a run of it is in progress in another thread (pyo3's
/// own is a bare "Already borrowed").
fn running(what: &str, system: &Bound<'_, PySystem>) -> PyErr {
    let source = system
        .try_borrow()
        .map(|s| s.system.source.display().to_string())
        .unwrap_or_default();
    ShipsimError::new_err(format!(
        "{what}: the System ({source}) is running in another thread; change it before or \
         after its runs (threads may run one System at the same time, each run on its own \
         instances), or load a System per thread"
    ))
}

#[pymethods]
impl PySystem {
    /// Reads a system file (native TOML or OSP XML) and loads its FMUs.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PySystem> {
        let system = System::load(&path).map_err(|e| py_err(py, e))?;
        let fmus = py
            .detach(|| run::load_fmus(&system))
            .map_err(|e| py_err(py, e))?;
        Ok(PySystem { system, fmus })
    }

    /// Sets a parameter or start value, like `--set instance.variable=value`. A System that
    /// is running in another thread is not changed: an error says so.
    fn set(slf: &Bound<'_, Self>, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let py = slf.py();
        let mut this = slf
            .try_borrow_mut()
            .map_err(|_| running(&format!("System.set('{name}')"), slf))?;
        let v = match this.variable(name, false)? {
            Some(sv) => to_value(name, sv, value)?,
            None => unreachable!("no wildcard"),
        };
        let r = VarRef::parse(name).expect("checked");
        this.system.set_value(r, v).map_err(|e| py_err(py, e))
    }

    /// The values set on the instances (from the file and `set`), as `instance.variable` ->
    /// value text.
    fn values(&self) -> Vec<(String, String)> {
        self.system
            .instances
            .iter()
            .flat_map(|i| {
                i.values
                    .iter()
                    .map(move |v| (format!("{}.{}", i.name, v.variable), v.value.to_string()))
            })
            .collect()
    }

    #[getter]
    fn source(&self) -> PathBuf {
        self.system.source.clone()
    }
    #[getter]
    fn start_time(&self) -> f64 {
        self.system.start_time
    }
    #[getter]
    fn stop_time(&self) -> Option<f64> {
        self.system.stop_time
    }
    #[getter]
    fn step_size(&self) -> f64 {
        self.system.step_size
    }
    /// Unit mismatches across connections are errors (true: native TOML files) or warnings
    /// (false: OSP files, as libcosim does not check units); `--strict-units` sets it.
    #[getter]
    fn strict_units(&self) -> bool {
        self.system.strict_units
    }
    #[setter]
    fn set_strict_units(slf: &Bound<'_, Self>, strict: bool) -> PyResult<()> {
        let mut this = slf
            .try_borrow_mut()
            .map_err(|_| running("System.strict_units", slf))?;
        this.system.strict_units = strict;
        Ok(())
    }
    #[getter]
    fn algorithm(&self) -> String {
        format!("{:?}", self.system.algorithm)
    }
    /// (instance name, FMU path) in system order.
    #[getter]
    fn instances(&self) -> Vec<(String, PathBuf)> {
        self.system
            .instances
            .iter()
            .map(|i| (i.name.clone(), i.fmu.clone()))
            .collect()
    }
    /// The connections as (from, to, gain, offset).
    #[getter]
    fn connections(&self) -> Vec<(String, String, f64, f64)> {
        self.system
            .connections
            .iter()
            .map(|c| (c.from.to_string(), c.to.to_string(), c.gain, c.offset))
            .collect()
    }

    /// Checks the system against its FMUs (as `shipsim check`); returns the warnings.
    fn check(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        let plan = self
            .system
            .validate(&self.mds())
            .map_err(|e| py_err(py, e))?;
        Ok(plan.warnings)
    }

    /// Runs the system and returns its recorded columns; see the Python `System.run`.
    #[pyo3(signature = (stop_time=None, variables=None, start_time=None, step_size=None, algorithm=None, verbose=false, isolate=None, isolate_instances=None, call_timeout=None, real_time_factor=None))]
    #[allow(clippy::too_many_arguments)]
    fn run<'py>(
        &self,
        py: Python<'py>,
        stop_time: Option<f64>,
        variables: Option<Vec<String>>,
        start_time: Option<f64>,
        step_size: Option<f64>,
        algorithm: Option<String>,
        verbose: bool,
        isolate: Option<String>,
        isolate_instances: Option<Vec<String>>,
        call_timeout: Option<f64>,
        real_time_factor: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let isolation = self.isolation(isolate, isolate_instances, call_timeout)?;
        let sys = self.configured(py, stop_time, variables, start_time, step_size, algorithm)?;
        let plan = sys.validate(&self.mds()).map_err(|e| py_err(py, e))?;
        let (opts, logs, interrupt) = run_options(verbose, isolation);
        if let Some(x) = real_time_factor {
            return self.run_paced(py, sys, plan, opts, logs, interrupt, x);
        }
        let mut rec = MemoryRecorder::new();
        let fmus = &self.fmus;
        let result = run_detached(
            py,
            &interrupt,
            |_| Ok(()),
            || {
                let begin = std::time::Instant::now();
                run::run_into(&plan, fmus, Some(&mut rec), &opts).map(|mut s| {
                    s.total_wall_time = begin.elapsed();
                    s
                })
            },
        );
        logs.emit(py)?;
        let summary = result?.map_err(|e| py_err(py, e))?;
        let out = rows_dict(py, &plan, &sys, &self.mds(), &rec)?;
        out.set_item("warnings", plan.warnings.clone())?;
        out.set_item("summary", summary_dict(py, &summary)?)?;
        Ok(out)
    }

    /// Starts a stepping session; see the Python `System.start`.
    #[pyo3(signature = (stop_time=None, variables=None, start_time=None, step_size=None, algorithm=None, verbose=false, isolate=None, isolate_instances=None, call_timeout=None, journal=None))]
    #[allow(clippy::too_many_arguments)]
    fn start(
        &self,
        py: Python<'_>,
        stop_time: Option<f64>,
        variables: Option<Vec<String>>,
        start_time: Option<f64>,
        step_size: Option<f64>,
        algorithm: Option<String>,
        verbose: bool,
        isolate: Option<String>,
        isolate_instances: Option<Vec<String>>,
        call_timeout: Option<f64>,
        journal: Option<Bound<'_, PyAny>>,
    ) -> PyResult<session::PySession> {
        // None: in memory; False: none; a path: also written to that file.
        let journal = match journal {
            None => shipsim::run::Journaling::Memory,
            Some(j) if j.is_instance_of::<pyo3::types::PyBool>() => match j.is_truthy()? {
                false => shipsim::run::Journaling::Off,
                true => shipsim::run::Journaling::Memory,
            },
            Some(j) => shipsim::run::Journaling::File(j.extract::<PathBuf>()?),
        };
        let isolation = self.isolation(isolate, isolate_instances, call_timeout)?;
        let sys = self.configured(py, stop_time, variables, start_time, step_size, algorithm)?;
        session::PySession::start(py, sys, self.fmus.clone(), verbose, isolation, journal)
    }
}

impl PySystem {
    /// `run` paced at `factor` times real time, through the runner of `shipsim run
    /// --real-time` ([`shipsim::realtime::run_system`]; no `[[io]]`, no journal): the same
    /// rows, and a summary with the lateness.
    #[allow(clippy::too_many_arguments)]
    fn run_paced<'py>(
        &self,
        py: Python<'py>,
        sys: System,
        plan: shipsim::system::Plan,
        opts: RunOptions,
        logs: Logs,
        interrupt: Arc<AtomicBool>,
        factor: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        use shipsim::realtime::{run_system, PacedRun, RealTimeOptions};
        let messages = Arc::new(Mutex::new(Vec::<String>::new()));
        let sink = messages.clone();
        let paced = PacedRun {
            run: opts,
            journal: shipsim::run::Journaling::Off,
            io: Vec::new(),
            rows: None,
            realtime: RealTimeOptions {
                factor: Some(factor),
                interrupt: Some(interrupt.clone()),
                log: Arc::new(move |m: &str| sink.lock().unwrap().push(m.to_string())),
                ..RealTimeOptions::default()
            },
        };
        let fmus = self.fmus.clone();
        let system = sys.clone();
        let result = run_detached(
            py,
            &interrupt,
            |_| Ok(()),
            || run_system(system, fmus, paced),
        );
        logs.emit(py)?;
        let (session, report) = result?.map_err(|e| py_err(py, e))?;
        let out = rows_dict(py, &plan, &sys, &self.mds(), session.rows())?;
        let mut warnings = plan.warnings.clone();
        warnings.extend(messages.lock().unwrap().drain(..));
        out.set_item("warnings", warnings)?;
        let d = PyDict::new(py);
        d.set_item("start_time", report.start_time)?;
        d.set_item("end_time", report.end_time)?;
        d.set_item("macro_steps", report.macro_steps)?;
        d.set_item("wall_time", report.wall.as_secs_f64())?;
        d.set_item("paced_factor", factor)?;
        d.set_item(
            "lateness_median",
            report.lateness.quantile(0.5).as_secs_f64(),
        )?;
        d.set_item("lateness_p99", report.lateness.quantile(0.99).as_secs_f64())?;
        d.set_item("lateness_max", report.lateness.max().as_secs_f64())?;
        d.set_item("overruns", report.overruns)?;
        d.set_item("rows", session.rows().time.len())?;
        out.set_item("summary", d)?;
        Ok(out)
    }
}

impl PySystem {
    /// A copy of the system with a run's options applied (`System.run` and `System.start`):
    /// the recorded variables (checked, with close names), the times, step size and algorithm;
    /// no output file.
    fn configured(
        &self,
        py: Python<'_>,
        stop_time: Option<f64>,
        variables: Option<Vec<String>>,
        start_time: Option<f64>,
        step_size: Option<f64>,
        algorithm: Option<String>,
    ) -> PyResult<System> {
        let mut sys = self.system.clone();
        if let Some(v) = &variables {
            for name in v {
                self.check_name(name, true)?;
            }
            sys.output.variables = Some(v.clone());
        }
        sys.output.file = None;
        sys.apply_stop_time(stop_time).map_err(|e| py_err(py, e))?;
        if let Some(t) = start_time {
            sys.start_time = t;
        }
        sys.apply_step_size(step_size).map_err(|e| py_err(py, e))?;
        if let Some(a) = algorithm {
            // The library's parser, as for system files and `shipsim run --algorithm`.
            sys.algorithm = a.parse().map_err(|e: shipsim::system::UnknownAlgorithm| {
                pyo3::exceptions::PyValueError::new_err(e.to_string())
            })?;
        }
        Ok(sys)
    }
}

/// The recorded rows as the Python layer reads them: `columns`, `types`, `units`, and `time`
/// and `data` as bytearrays of little-endian f64.
fn rows_dict<'py>(
    py: Python<'py>,
    plan: &shipsim::system::Plan,
    sys: &System,
    mds: &[&ModelDescription],
    rec: &MemoryRecorder,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let units: Vec<Option<String>> = plan
        .outputs
        .iter()
        .map(|o| {
            let md = mds[o.instance];
            let prefix = format!("{}.", sys.instances[o.instance].name);
            let name = o.header.strip_prefix(&prefix)?;
            let v = md
                .model_variables
                .variables
                .iter()
                .find(|v| v.name == name)?;
            md.real_unit(v).map(str::to_string)
        })
        .collect();
    out.set_item("units", units)?;
    out.set_item(
        "columns",
        rec.columns
            .iter()
            .map(|c| c.name.clone())
            .collect::<Vec<_>>(),
    )?;
    out.set_item(
        "types",
        rec.columns
            .iter()
            .map(|c| c.var_type.name())
            .collect::<Vec<_>>(),
    )?;
    out.set_item("time", le_bytes(py, &rec.time, f64::to_le_bytes)?)?;
    let data = PyList::empty(py);
    for col in &rec.data {
        data.append(le_bytes(py, col, f64::to_le_bytes)?)?;
    }
    out.set_item("data", data)?;
    Ok(out)
}

/// A bytearray of the values' little-endian bytes, written in place (numpy reads it without a
/// copy): `le` is `f64::to_le_bytes` or `i64::to_le_bytes`.
fn le_bytes<'py, T: Copy, const N: usize>(
    py: Python<'py>,
    v: &[T],
    le: fn(T) -> [u8; N],
) -> PyResult<Bound<'py, PyByteArray>> {
    PyByteArray::new_with(py, v.len() * N, |buf| {
        for (chunk, x) in buf.chunks_exact_mut(N).zip(v) {
            chunk.copy_from_slice(&le(*x));
        }
        Ok(())
    })
}

fn summary_dict<'py>(py: Python<'py>, s: &Summary) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("start_time", s.start_time)?;
    d.set_item("end_time", s.end_time)?;
    d.set_item("macro_steps", s.macro_steps)?;
    d.set_item("fmu_steps", s.fmu_steps)?;
    d.set_item("wall_time", s.wall_time.as_secs_f64())?;
    d.set_item("total_wall_time", s.total_wall_time.as_secs_f64())?;
    d.set_item("real_time_factor", s.real_time_factor())?;
    d.set_item("rows", s.rows)?;
    d.set_item("terminated_by", s.terminated_by.clone())?;
    Ok(d)
}

/// A table as (names, kinds, columns): Float and Int columns as bytearrays of f64/i64, Bool
/// and Text columns as lists.
fn table_dict<'py>(py: Python<'py>, t: &Table) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("names", t.names.clone())?;
    let kinds = PyList::empty(py);
    let cols = PyList::empty(py);
    for c in &t.columns {
        kinds.append(c.type_name())?;
        match c {
            ColumnData::Float(v) => cols.append(le_bytes(py, v, f64::to_le_bytes)?)?,
            ColumnData::Int(v) => cols.append(le_bytes(py, v, i64::to_le_bytes)?)?,
            ColumnData::Bool(v) => cols.append(v.clone())?,
            ColumnData::Text(v) => cols.append(v.clone())?,
        }
    }
    d.set_item("kinds", kinds)?;
    d.set_item("columns", cols)?;
    d.set_item("rows", t.rows())?;
    Ok(d)
}

/// Counts finished runs for the progress shown from the Python thread.
#[derive(Default)]
struct Count(AtomicUsize, AtomicUsize);

impl Observer for Count {
    fn finished(&self, _run: &Run, record: &RunRecord) {
        self.0.fetch_add(1, Ordering::Relaxed);
        if record.status.failed() {
            self.1.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// A campaign: its file, base system and runs.
#[pyclass(module = "shipsim._native", name = "Campaign")]
struct PyCampaign {
    campaign: Campaign,
}

/// An error of running or reading the results of a campaign: a mistake the campaign file makes
/// (a message that starts with "campaign ") is a [`SystemFileError`]; the rest as [`py_err`].
fn campaign_err(py: Python<'_>, e: Error) -> PyErr {
    match e {
        Error::Other(m) if m.starts_with("campaign ") => SystemFileError::new_err(m),
        e => py_err(py, e),
    }
}

/// An error of loading a campaign: reading a campaign file (or its base system) is a
/// [`SystemFileError`] unless an FMU is at fault; the rest as [`py_err`].
fn campaign_load_err(py: Python<'_>, e: Error) -> PyErr {
    match e {
        Error::Io { .. } | Error::Other(_) => SystemFileError::new_err(e.to_string()),
        e => py_err(py, e),
    }
}

#[pymethods]
impl PyCampaign {
    /// Reads a campaign file and its base system and expands the runs.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyCampaign> {
        let campaign = py
            .detach(|| Campaign::load(&path))
            .map_err(|e| campaign_load_err(py, e))?;
        Ok(PyCampaign { campaign })
    }

    #[getter]
    fn name(&self) -> String {
        self.campaign.spec.name.clone()
    }
    #[getter]
    fn description(&self) -> Option<String> {
        self.campaign.spec.description.clone()
    }
    #[getter]
    fn source(&self) -> PathBuf {
        self.campaign.spec.source.clone()
    }
    #[getter]
    fn base_hash(&self) -> String {
        self.campaign.base_hash.clone()
    }
    #[getter]
    fn fork_at(&self) -> Option<f64> {
        self.campaign.spec.fork_at
    }
    fn __len__(&self) -> usize {
        self.campaign.runs.len()
    }
    /// Every run's values (`instance.variable` -> value text), in run order.
    fn run_values(&self) -> Vec<Vec<(String, String)>> {
        self.campaign
            .runs
            .iter()
            .map(|r| {
                r.sets
                    .iter()
                    .map(|(k, v)| (k.clone(), v.to_string()))
                    .collect()
            })
            .collect()
    }

    /// Runs every run not done yet on `jobs` threads into the output folder; `progress(done,
    /// failed)` is called every 50 ms. Returns (outcome text, run table).
    #[pyo3(signature = (output, jobs=None, retry_failed=false, progress=None))]
    fn run<'py>(
        &self,
        py: Python<'py>,
        output: PathBuf,
        jobs: Option<i64>,
        retry_failed: bool,
        progress: Option<Bound<'py, PyAny>>,
    ) -> PyResult<(String, Bound<'py, PyDict>)> {
        // any integer is accepted here so that a wrong one gets a message, not an OverflowError
        let jobs = match jobs {
            Some(n) if n < 1 => {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "jobs = {n}: a campaign needs at least one job (jobs=N, N >= 1)"
                )))
            }
            Some(n) => Some(usize::try_from(n).unwrap_or(usize::MAX)),
            None => None,
        };
        let interrupt = Arc::new(AtomicBool::new(false));
        let logs = Logs::default();
        let count = Arc::new(Count::default());
        let opts = CampaignOptions {
            jobs,
            output: output.clone(),
            retry_failed,
            interrupt: Some(interrupt.clone()),
            log_sink: Some(logs.sink(false)),
            observer: Some(count.clone()),
            ..Default::default()
        };
        let campaign = &self.campaign;
        let poll = |_py: Python<'_>| match &progress {
            Some(p) => p
                .call1((
                    count.0.load(Ordering::Relaxed),
                    count.1.load(Ordering::Relaxed),
                ))
                .map(|_| ()),
            None => Ok(()),
        };
        let result = run_detached(py, &interrupt, poll, || execute::run(campaign, &opts));
        logs.emit(py)?;
        let outcome = result?.map_err(|e| campaign_err(py, e))?;
        if outcome.interrupted {
            return Err(PyKeyboardInterrupt::new_err(
                "interrupted: the finished runs are kept, run again to resume",
            ));
        }
        let table = remote::read_run_table(campaign, &output).map_err(|e| py_err(py, e))?;
        Ok((outcome.to_string(), table_dict(py, &table)?))
    }

    /// The run table of an output folder of this campaign (from its journal).
    fn table<'py>(&self, py: Python<'py>, output: PathBuf) -> PyResult<Bound<'py, PyDict>> {
        let t = remote::read_run_table(&self.campaign, &output).map_err(|e| py_err(py, e))?;
        table_dict(py, &t)
    }

    /// The derived table of an output folder of this campaign (from its journal); None when
    /// the campaign has no `[[derived]]` KPIs.
    fn derived_table<'py>(
        &self,
        py: Python<'py>,
        output: PathBuf,
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let t = remote::read_derived_table(&self.campaign, &output).map_err(|e| py_err(py, e))?;
        t.map(|t| table_dict(py, &t)).transpose()
    }

    /// Opens the output folder for recording results computed elsewhere (the Dask mode).
    #[pyo3(signature = (output, retry_failed=false))]
    fn collector(
        &self,
        py: Python<'_>,
        output: PathBuf,
        retry_failed: bool,
    ) -> PyResult<PyCollector> {
        let c =
            Collector::open(&self.campaign, &output, retry_failed).map_err(|e| py_err(py, e))?;
        Ok(PyCollector {
            campaign: self.campaign.clone(),
            collector: Some(c),
        })
    }
}

/// The client side of a distributed campaign ([`Collector`]).
#[pyclass(module = "shipsim._native", name = "Collector")]
struct PyCollector {
    campaign: Campaign,
    /// None once closed (the journal's lock released).
    collector: Option<Collector>,
}

impl PyCollector {
    fn get(&mut self) -> PyResult<&mut Collector> {
        self.collector
            .as_mut()
            .ok_or_else(|| ShipsimError::new_err("the collector is closed"))
    }
}

#[pymethods]
impl PyCollector {
    /// The runs not done yet in chunks of about `per_chunk` (warm-up groups kept whole).
    fn chunks(&mut self, py: Python<'_>, per_chunk: usize) -> PyResult<Vec<Vec<usize>>> {
        let campaign = self.campaign.clone();
        let c = self.get()?;
        c.chunks(&campaign, per_chunk).map_err(|e| py_err(py, e))
    }

    /// Records one finished run (a JSON record from `worker_run`). Returns (recorded, failed):
    /// recorded is false for a run already recorded by this collector.
    #[pyo3(signature = (record, series=None))]
    fn record(
        &mut self,
        py: Python<'_>,
        record: &str,
        series: Option<&[u8]>,
    ) -> PyResult<(bool, bool)> {
        let r: RunRecord = serde_json::from_str(record)
            .map_err(|e| ShipsimError::new_err(format!("not a run record from a worker: {e}")))?;
        let failed = r.status.failed();
        let campaign = self.campaign.clone();
        let recorded = self
            .get()?
            .record(&campaign, r, series)
            .map_err(|e| py_err(py, e))?;
        Ok((recorded, failed))
    }

    /// How many runs are not done yet.
    fn pending(&mut self) -> PyResult<usize> {
        let campaign = self.campaign.clone();
        Ok(self.get()?.pending(&campaign))
    }

    /// Writes the tables; returns (files, run table).
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<(Vec<PathBuf>, Bound<'py, PyDict>)> {
        let campaign = self.campaign.clone();
        let (files, table) = self.get()?.finish(&campaign).map_err(|e| py_err(py, e))?;
        Ok((files, table_dict(py, &table)?))
    }

    /// Releases the output folder (its journal lock).
    fn close(&mut self) {
        self.collector = None;
    }
}

/// The workers of this process, by campaign file and base hash: each loads its FMUs once.
static WORKERS: Mutex<Option<HashMap<WorkerKey, Arc<Worker>>>> = Mutex::new(None);

/// (campaign file, base hash): a worker is reused only for the same files.
type WorkerKey = (PathBuf, String);

fn worker_for(path: &std::path::Path, base_hash: &str) -> Result<Arc<Worker>, Error> {
    let key = (path.to_path_buf(), base_hash.to_string());
    let mut guard = WORKERS.lock().unwrap_or_else(|e| e.into_inner());
    let map = guard.get_or_insert_with(HashMap::new);
    if let Some(w) = map.get(&key) {
        return Ok(w.clone());
    }
    let campaign = Campaign::load(path)?;
    if campaign.base_hash != base_hash {
        return Err(Error::Other(format!(
            "campaign {}: this worker reads a base system or FMUs other than the client's \
             (hash {} here, {} on the client): the files must be the same on every worker",
            path.display(),
            campaign.base_hash,
            base_hash
        )));
    }
    let w = Arc::new(Worker::new(campaign)?);
    map.insert(key, w.clone());
    Ok(w)
}

/// Runs a chunk of a campaign's runs in this process (a Dask task): the campaign and its
/// FMUs are loaded on the first chunk and kept. Returns (JSON record, series bytes or None)
/// per run.
#[pyfunction]
#[pyo3(signature = (campaign, base_hash, runs, jobs=1))]
fn worker_run<'py>(
    py: Python<'py>,
    campaign: PathBuf,
    base_hash: String,
    runs: Vec<usize>,
    jobs: usize,
) -> PyResult<Vec<(String, Option<Bound<'py, PyBytes>>)>> {
    let interrupt = Arc::new(AtomicBool::new(false));
    let logs = Logs::default();
    let opts = CampaignOptions {
        jobs: Some(jobs.max(1)),
        interrupt: Some(interrupt.clone()),
        log_sink: Some(logs.sink(false)),
        ..Default::default()
    };
    let result = run_detached(
        py,
        &interrupt,
        |_| Ok(()),
        || worker_for(&campaign, &base_hash)?.run(&runs, &opts),
    );
    logs.emit(py)?;
    let finished = result?.map_err(|e| campaign_err(py, e))?;
    finished
        .into_iter()
        .map(|(r, series)| {
            let json = serde_json::to_string(&r).map_err(|e| {
                ShipsimError::new_err(format!("cannot encode run {}: {e}", r.index))
            })?;
            Ok((json, series.map(|b| PyBytes::new(py, &b))))
        })
        .collect()
}

/// Frees the workers of this process (the cache of [`worker_run`]): their FMUs are unloaded
/// and their unpack folders removed. A static is never dropped, so without this every Dask
/// worker process left its folders in `$TMPDIR`; `shipsim._dask` calls it at exit (`atexit`).
/// A chunk still running keeps its worker until it ends. Returns how many were freed.
#[pyfunction]
fn release_workers(py: Python<'_>) -> usize {
    py.detach(|| {
        let workers = WORKERS.lock().unwrap_or_else(|e| e.into_inner()).take();
        workers.map_or(0, |w| w.len())
    })
}

/// How many FMU shared libraries this process has loaded (each distinct FMU once per
/// System, Campaign or worker).
#[pyfunction]
fn fmu_load_count() -> usize {
    shipsim::fmu::load_count()
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("ShipsimError", py.get_type::<ShipsimError>())?;
    m.add("FmuError", py.get_type::<FmuError>())?;
    m.add("SystemFileError", py.get_type::<SystemFileError>())?;
    m.add("VariableError", py.get_type::<VariableError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("CheckpointError", py.get_type::<CheckpointError>())?;
    m.add("SessionError", py.get_type::<SessionError>())?;
    m.add_function(wrap_pyfunction!(inspect, m)?)?;
    m.add_function(wrap_pyfunction!(worker_run, m)?)?;
    m.add_function(wrap_pyfunction!(fmu_load_count, m)?)?;
    m.add_function(wrap_pyfunction!(release_workers, m)?)?;
    m.add_function(wrap_pyfunction!(fmu_host, m)?)?;
    m.add_class::<PySystem>()?;
    m.add_class::<PyCampaign>()?;
    m.add_class::<PyCollector>()?;
    m.add_class::<session::PySession>()?;
    m.add_class::<session::PyCheckpoint>()?;
    m.add_function(wrap_pyfunction!(session::replay, m)?)?;
    m.add_function(wrap_pyfunction!(analysis::loop_margins, m)?)?;
    m.add_function(wrap_pyfunction!(analysis::loop_grid, m)?)?;
    m.add_function(wrap_pyfunction!(analysis::loop_points, m)?)?;
    m.add_function(wrap_pyfunction!(analysis::frequency_response, m)?)?;
    m.add_function(wrap_pyfunction!(analysis::describing_function, m)?)?;
    // Isolated FMU instances (`isolate=`, `isolate = true`, campaigns' foreign FMUs) run in
    // processes of this interpreter: `python -m shipsim._fmu_host fmu-host FMU`.
    let executable: Option<PathBuf> = py.import("sys")?.getattr("executable")?.extract().ok();
    if let Some(exe) = executable.filter(|e| !e.as_os_str().is_empty()) {
        shipsim::isolate::set_host_command(exe, vec!["-m".into(), "shipsim._fmu_host".into()]);
    }
    Ok(())
}

/// The FMU host of an isolated instance (`shipsim._fmu_host`): serves the FMI calls of the
/// master on this process's stdin and stdout until the instance is freed; returns the exit
/// status (the caller ends the process with it).
#[pyfunction]
fn fmu_host(py: Python<'_>, fmu: PathBuf) -> i32 {
    py.detach(|| shipsim::isolate::host::serve(&fmu))
}
