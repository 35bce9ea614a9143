//! `shipsim._native.loop_margins`, `frequency_response` and `describing_function`: the loop
//! analysis of the library ([`shipsim::analysis`]) on a loaded System, with the GIL released
//! and Ctrl-C honoured as for a run. Results come back as table dicts ([`table_dict`]) and the
//! margins as numbers; with `output`, the tables and plots are written there too.

use super::{py_err, run_detached, run_options, table_dict, PySystem};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use shipsim::analysis::{self, Injection, LoopPoint, Options};
use std::path::PathBuf;

/// The measurement's options from Python's keywords.
#[allow(clippy::too_many_arguments)]
fn options(
    at: Option<f64>,
    frequencies: Option<Vec<f64>>,
    amplitude: Option<f64>,
    periods: Option<u32>,
    settle: Option<f64>,
    linearity: bool,
    jobs: Option<usize>,
) -> (
    Options,
    super::Logs,
    std::sync::Arc<std::sync::atomic::AtomicBool>,
) {
    let (run, logs, interrupt) = run_options(false, Default::default());
    let d = Options::default();
    let opts = Options {
        at,
        frequencies,
        amplitude: amplitude.unwrap_or(d.amplitude),
        periods: periods.unwrap_or(d.periods),
        settle,
        linearity,
        jobs,
        run,
    };
    (opts, logs, interrupt)
}

fn injection(input: &str) -> Injection {
    match input.contains("->") {
        true => Injection::Connection(input.to_string()),
        false => Injection::Input(input.to_string()),
    }
}

/// A measured point as plain numbers (a Dask task's result): ω, Re L, Im L, distortion, and
/// the linearity check's gain and phase change.
type PointTuple = (f64, f64, f64, f64, Option<f64>, Option<f64>);

fn to_tuple(p: &LoopPoint) -> PointTuple {
    (
        p.omega,
        p.l.re,
        p.l.im,
        p.distortion,
        p.gain_change_db,
        p.phase_change_deg,
    )
}

fn from_tuple(t: &PointTuple) -> LoopPoint {
    LoopPoint {
        omega: t.0,
        l: num_complex::Complex64::new(t.1, t.2),
        distortion: t.3,
        gain_change_db: t.4,
        phase_change_deg: t.5,
    }
}

/// The grid of a loop analysis (the given frequencies, or the default range for the step).
#[pyfunction]
#[pyo3(signature = (system, frequencies=None))]
pub fn loop_grid(
    py: Python<'_>,
    system: &PySystem,
    frequencies: Option<Vec<f64>>,
) -> PyResult<Vec<f64>> {
    let (opts, _, _) = options(None, frequencies, None, None, None, true, None);
    analysis::grid(&system.system, &opts).map_err(|e| py_err(py, e))
}

/// The loop's points at `chunk` of the grid, without refinement: a Dask worker's task.
#[pyfunction]
#[pyo3(signature = (system, connection, chunk, at=None, frequencies=None, amplitude=None, periods=None, settle=None, linearity=true, jobs=None))]
#[allow(clippy::too_many_arguments)]
pub fn loop_points(
    py: Python<'_>,
    system: &PySystem,
    connection: String,
    chunk: Vec<f64>,
    at: Option<f64>,
    frequencies: Option<Vec<f64>>,
    amplitude: Option<f64>,
    periods: Option<u32>,
    settle: Option<f64>,
    linearity: bool,
    jobs: Option<usize>,
) -> PyResult<Vec<PointTuple>> {
    let (opts, logs, interrupt) =
        options(at, frequencies, amplitude, periods, settle, linearity, jobs);
    let (sys, fmus) = (&system.system, &system.fmus);
    let result = run_detached(
        py,
        &interrupt,
        |_| Ok(()),
        || analysis::loop_points(sys, fmus, &connection, &chunk, &opts),
    );
    logs.emit(py)?;
    let points = result?.map_err(|e| py_err(py, e))?;
    Ok(points.iter().map(to_tuple).collect())
}

/// The loop at `connection` and its margins; see the Python `System.loop_margins`. With
/// `grid`, the grid's points were measured elsewhere (Dask) and only the crossings are
/// refined here.
#[pyfunction]
#[pyo3(signature = (system, connection, at=None, frequencies=None, amplitude=None, periods=None, settle=None, linearity=true, jobs=None, output=None, grid=None))]
#[allow(clippy::too_many_arguments)]
pub fn loop_margins<'py>(
    py: Python<'py>,
    system: &PySystem,
    connection: String,
    at: Option<f64>,
    frequencies: Option<Vec<f64>>,
    amplitude: Option<f64>,
    periods: Option<u32>,
    settle: Option<f64>,
    linearity: bool,
    jobs: Option<usize>,
    output: Option<PathBuf>,
    grid: Option<Vec<PointTuple>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (opts, logs, interrupt) =
        options(at, frequencies, amplitude, periods, settle, linearity, jobs);
    let (sys, fmus) = (&system.system, &system.fmus);
    let result = run_detached(
        py,
        &interrupt,
        |_| Ok(()),
        || {
            let (points, m) = match &grid {
                Some(g) => {
                    let points = g.iter().map(from_tuple).collect();
                    analysis::loop_margins_from(sys, fmus, &connection, points, &opts)?
                }
                None => analysis::loop_margins(sys, fmus, &connection, &opts)?,
            };
            let written = match &output {
                Some(dir) => Some(analysis::write_margins(dir, &points, &m, &connection)?),
                None => None,
            };
            Ok((points, m, written))
        },
    );
    logs.emit(py)?;
    let (points, m, written) = result?.map_err(|e| py_err(py, e))?;
    let d = PyDict::new(py);
    d.set_item("connection", &connection)?;
    d.set_item("gain_margin_db", m.gain_margin_db)?;
    d.set_item("gain_margin_rad_s", m.gain_margin_rad_s)?;
    d.set_item("phase_margin_deg", m.phase_margin_deg)?;
    d.set_item("crossover_rad_s", m.crossover_rad_s)?;
    d.set_item("delay_margin_s", m.delay_margin_s)?;
    d.set_item("sensitivity_peak", m.sensitivity_peak)?;
    d.set_item("sensitivity_peak_rad_s", m.sensitivity_peak_rad_s)?;
    let pairs =
        |c: &[analysis::Crossing]| c.iter().map(|c| (c.omega, c.margin)).collect::<Vec<_>>();
    d.set_item("gain_crossovers", pairs(&m.gain_crossovers))?;
    d.set_item("phase_crossovers", pairs(&m.phase_crossovers))?;
    d.set_item("table", table_dict(py, &analysis::loop_table(&points))?)?;
    set_files(&d, written)?;
    Ok(d)
}

fn set_files(d: &Bound<'_, PyDict>, written: Option<analysis::Written>) -> PyResult<()> {
    if let Some(w) = written {
        d.set_item("table_path", w.table)?;
        d.set_item("parquet_path", w.parquet)?;
        d.set_item("plots", w.plots)?;
    }
    Ok(())
}

/// The frequency response from `input` to `outputs`; see the Python `System.frequency_response`.
#[pyfunction]
#[pyo3(signature = (system, input, outputs, at=None, frequencies=None, amplitude=None, periods=None, settle=None, linearity=true, jobs=None, output=None))]
#[allow(clippy::too_many_arguments)]
pub fn frequency_response<'py>(
    py: Python<'py>,
    system: &PySystem,
    input: String,
    outputs: Vec<String>,
    at: Option<f64>,
    frequencies: Option<Vec<f64>>,
    amplitude: Option<f64>,
    periods: Option<u32>,
    settle: Option<f64>,
    linearity: bool,
    jobs: Option<usize>,
    output: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    for name in &outputs {
        system.check_name(name, false)?;
    }
    let (opts, logs, interrupt) =
        options(at, frequencies, amplitude, periods, settle, linearity, jobs);
    let (sys, fmus) = (&system.system, &system.fmus);
    let inj = injection(&input);
    let result = run_detached(
        py,
        &interrupt,
        |_| Ok(()),
        || {
            let points = analysis::frequency_response(sys, fmus, &inj, &outputs, &opts)?;
            let written = match &output {
                Some(dir) => Some(analysis::write_response(
                    dir,
                    &points,
                    &format!("response to {input}"),
                )?),
                None => None,
            };
            Ok((points, written))
        },
    );
    logs.emit(py)?;
    let (points, written) = result?.map_err(|e| py_err(py, e))?;
    let d = PyDict::new(py);
    d.set_item("table", table_dict(py, &analysis::response_table(&points))?)?;
    set_files(&d, written)?;
    Ok(d)
}

/// The describing function from `input` to `output`; see the Python
/// `System.describing_function`.
#[pyfunction]
#[pyo3(signature = (system, input, output, frequency, amplitudes, at=None, periods=None, settle=None, jobs=None, directory=None))]
#[allow(clippy::too_many_arguments)]
pub fn describing_function<'py>(
    py: Python<'py>,
    system: &PySystem,
    input: String,
    output: String,
    frequency: f64,
    amplitudes: Vec<f64>,
    at: Option<f64>,
    periods: Option<u32>,
    settle: Option<f64>,
    jobs: Option<usize>,
    directory: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    system.check_name(&output, false)?;
    let (opts, logs, interrupt) = options(at, None, None, periods, settle, false, jobs);
    let (sys, fmus) = (&system.system, &system.fmus);
    let inj = injection(&input);
    let result = run_detached(
        py,
        &interrupt,
        |_| Ok(()),
        || {
            let points = analysis::describing_function(
                sys,
                fmus,
                &inj,
                &output,
                frequency,
                &amplitudes,
                &opts,
            )?;
            let written = match &directory {
                Some(dir) => Some(analysis::write_describing(
                    dir,
                    &points,
                    &format!("describing function {input} -> {output}"),
                )?),
                None => None,
            };
            Ok((points, written))
        },
    );
    logs.emit(py)?;
    let (points, written) = result?.map_err(|e| py_err(py, e))?;
    let d = PyDict::new(py);
    d.set_item(
        "table",
        table_dict(py, &analysis::describing_table(&points))?,
    )?;
    set_files(&d, written)?;
    Ok(d)
}
