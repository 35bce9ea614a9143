//! Loop analysis of a coupled system, measured through its FMUs: frequency responses between
//! two points, the loop transfer function and stability margins at a broken connection, and
//! describing functions of nonlinear elements (docs/loop-analysis.md).
//!
//! Every measurement is a set of forks of one run: the system is run (or not) to the operating
//! point T and checkpointed ([`crate::run::Session::checkpoint`]); each frequency (and
//! amplitude) is then a session resumed from that state ([`crate::run::Session::resume`]) in
//! which a sinusoid d_k = A sin(ω (t_k − T)) rides on an input (as events at every step) or on a
//! connection (as its offset), and the recorded signals are correlated with e^{-jω(t_k − T)}
//! over a whole number of periods after a settling time ([`fork`]). Forks run in parallel on
//! a rayon pool.
//!
//! - [`frequency_response`]: Y/D for each output, D the injected sinusoid's phasor;
//! - [`loop_margins`]: L = −R/U at the break, R the returned signal (the connection's source as
//!   the connection reads it), U = g·R + D what is sent; gain and phase margins, crossover,
//!   delay margin and sensitivity peak, with the crossings refined by more forks ([`margins`]);
//! - [`describing_function`]: Y/D at one frequency over a range of amplitudes.

use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::run::{Checkpoint, Journaling, RunOptions, Session, SessionOptions};
use crate::system::System;
use num_complex::Complex64;
use std::sync::Arc;

mod bode;
mod fork;
mod margins;
mod output;

pub use margins::{Crossing, Margins};
pub use output::{
    describing_table, loop_table, response_table, write_describing, write_margins, write_response,
    Written,
};

/// Where the sinusoid is injected.
#[derive(Debug, Clone)]
pub enum Injection {
    /// An input or tunable parameter `instance.variable`: u_k = u0 + d_k, u0 its value at T.
    Input(String),
    /// A Real connection `a.y -> b.u`: b.u = g·a.y + c + d_k.
    Connection(String),
}

/// How to measure (the defaults are documented in docs/loop-analysis.md).
#[derive(Clone)]
pub struct Options {
    /// The operating point [s]: a communication point; None = the start, after initialization.
    pub at: Option<f64>,
    /// The frequencies [rad/s]; each is snapped to a whole number of periods on the grid.
    /// None = 20 log-spaced from 0.001 to 0.3 times the Nyquist frequency π/h.
    pub frequencies: Option<Vec<f64>>,
    /// The sinusoid's amplitude, in the unit of the input or connection.
    pub amplitude: f64,
    /// Periods in the correlation window (at least; more where one period is under 50 steps).
    pub periods: u32,
    /// Settling time [s] before the window; None = 3 periods.
    pub settle: Option<f64>,
    /// Measure each frequency again at twice the amplitude and report the change (linearity).
    pub linearity: bool,
    /// Parallel forks (None = every core).
    pub jobs: Option<usize>,
    pub run: RunOptions,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            at: None,
            frequencies: None,
            amplitude: 0.01,
            periods: 4,
            settle: None,
            linearity: true,
            jobs: None,
            run: RunOptions::default(),
        }
    }
}

/// One measured frequency of a response: per output, the ratio and the output's distortion.
#[derive(Debug, Clone)]
pub struct ResponsePoint {
    /// The snapped frequency [rad/s].
    pub omega: f64,
    pub outputs: Vec<OutputResponse>,
}

#[derive(Debug, Clone)]
pub struct OutputResponse {
    pub name: String,
    /// Y/D.
    pub ratio: Complex64,
    /// sqrt(Σ_{n=2..5} |Y_n|²)/|Y_1|: the output's harmonic distortion.
    pub distortion: f64,
    /// At twice the amplitude: 20 log10 |ratio(2A)/ratio(A)| and the phase change [deg].
    pub gain_change_db: Option<f64>,
    pub phase_change_deg: Option<f64>,
}

/// One measured point of a loop at a break.
#[derive(Debug, Clone)]
pub struct LoopPoint {
    pub omega: f64,
    /// L = −R/U.
    pub l: Complex64,
    /// The returned signal's harmonic distortion.
    pub distortion: f64,
    pub gain_change_db: Option<f64>,
    pub phase_change_deg: Option<f64>,
}

/// One amplitude of a describing function.
#[derive(Debug, Clone)]
pub struct DescribingPoint {
    pub amplitude: f64,
    pub omega: f64,
    pub outputs: Vec<OutputResponse>,
}

/// The system ready for forks: its plan's stop time covers the longest fork, and the state at
/// the operating point (None when it is the start: forks start fresh).
pub(crate) struct Base {
    system: System,
    fmus: Vec<Arc<Fmu>>,
    checkpoint: Option<Checkpoint>,
    /// The operating point's time.
    time: f64,
    h: f64,
    run: RunOptions,
}

impl Base {
    /// A session at the operating point, recording `variables` at every step.
    fn session(&self) -> Result<Session> {
        let (system, fmus, run) = (self.system.clone(), self.fmus.clone(), self.run.clone());
        match &self.checkpoint {
            Some(cp) => Session::resume(system, fmus, cp, run),
            None => {
                let opts = SessionOptions {
                    run,
                    journal: Journaling::Off,
                };
                Session::start(system, fmus, opts)
            }
        }
    }
}

/// `system` prepared for forks of at most `max_steps` macro steps from the operating point,
/// recording `variables` at every step.
fn prepare(
    system: &System,
    fmus: &[Arc<Fmu>],
    variables: Vec<String>,
    max_steps: u64,
    opts: &Options,
) -> Result<Base> {
    let mut sys = system.clone();
    let h = sys.step_size;
    let t0 = sys.start_time;
    let at = opts.at.unwrap_or(t0);
    let kf = (at - t0) / h;
    let step = kf.round();
    if !(step >= 0.0) || (kf - step).abs() > 1e-6 {
        return Err(Error::Other(format!(
            "--at {at}: the operating point must be a communication point t0 + k*h (t0 = {t0} s, h = {h} s)"
        )));
    }
    let step = step as u64;
    sys.stop_time = Some(t0 + (step + max_steps + 1) as f64 * h);
    sys.output.file = None;
    sys.output.variables = Some(variables);
    sys.output.decimation = 1;
    let run = opts.run.clone();
    let mut base = Base {
        system: sys,
        fmus: fmus.to_vec(),
        checkpoint: None,
        time: at,
        h,
        run,
    };
    if step > 0 {
        let mut warm = base.session()?;
        warm.step(step)?;
        base.time = warm.time();
        base.checkpoint = Some(warm.checkpoint()?.checkpoint);
        warm.close()?;
    }
    Ok(base)
}

/// The frequencies of a measurement: given, or the default range.
fn frequencies(opts: &Options, h: f64) -> Result<Vec<f64>> {
    let nyquist = std::f64::consts::PI / h;
    let list = match &opts.frequencies {
        Some(f) => f.clone(),
        None => log_space(1e-3 * nyquist, 0.3 * nyquist, 20),
    };
    if list.is_empty() {
        return Err(Error::Other("no frequencies to measure".into()));
    }
    if let Some(w) = list.iter().find(|w| !(**w > 0.0 && **w < nyquist)) {
        return Err(Error::Other(format!(
            "frequency {w} rad/s: it must be positive and below the Nyquist frequency pi/h = {nyquist} rad/s of the step h = {h} s"
        )));
    }
    Ok(list)
}

/// `n` frequencies log-spaced from `lo` to `hi` (both included).
pub fn log_space(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![lo],
        _ => (0..n)
            .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
            .collect(),
    }
}

/// Runs `work` on a pool of `jobs` threads (None: every core).
fn pool<T: Send>(jobs: Option<usize>, work: impl FnOnce() -> T + Send) -> Result<T> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(j) = jobs {
        b = b.num_threads(j.max(1));
    }
    let pool = b
        .build()
        .map_err(|e| Error::Other(format!("cannot start the analysis's threads: {e}")))?;
    Ok(pool.install(work))
}

/// The frequency response from `input` to each of `outputs` (`instance.variable`) of `system`
/// run with `fmus`, at the frequencies of `opts`.
pub fn frequency_response(
    system: &System,
    fmus: &[Arc<Fmu>],
    input: &Injection,
    outputs: &[String],
    opts: &Options,
) -> Result<Vec<ResponsePoint>> {
    let freqs = frequencies(opts, system.step_size)?;
    let plan = fork::Plan::new(system, fmus, input, outputs, opts)?;
    let max = freqs
        .iter()
        .map(|w| plan.length(*w).total())
        .max()
        .unwrap_or(0);
    let base = prepare(system, fmus, plan.variables(), max, opts)?;
    let twice = if opts.linearity { 2.0 } else { 1.0 };
    let work = fork::Work::new(&plan, &base, twice * opts.amplitude)?;
    pool(opts.jobs, || {
        work.responses(&freqs, opts.amplitude, opts.linearity)
    })?
}

/// The loop transfer function at the connection `connection` (`a.y -> b.u`) and its margins.
pub fn loop_margins(
    system: &System,
    fmus: &[Arc<Fmu>],
    connection: &str,
    opts: &Options,
) -> Result<(Vec<LoopPoint>, Margins)> {
    let freqs = frequencies(opts, system.step_size)?;
    let (plan, base) = loop_base(system, fmus, connection, &freqs, opts)?;
    let work = fork::Work::new(&plan, &base, 2.0 * opts.amplitude)?;
    pool(opts.jobs, || margins::measure(&work, &freqs, opts))?
}

/// The frequencies an analysis with `opts` measures on its grid: given, or the default range
/// for the system's step (what a caller that splits the grid into chunks splits).
pub fn grid(system: &System, opts: &Options) -> Result<Vec<f64>> {
    frequencies(opts, system.step_size)
}

/// The loop's points at `chunk`, a part of the grid of `opts` (no refinement): what a Dask
/// worker measures. The system is prepared for the whole grid, so that every chunk's forks are
/// the forks of [`loop_margins`], bit for bit.
pub fn loop_points(
    system: &System,
    fmus: &[Arc<Fmu>],
    connection: &str,
    chunk: &[f64],
    opts: &Options,
) -> Result<Vec<LoopPoint>> {
    let freqs = frequencies(opts, system.step_size)?;
    let (plan, base) = loop_base(system, fmus, connection, &freqs, opts)?;
    let work = fork::Work::new(&plan, &base, 2.0 * opts.amplitude)?;
    pool(opts.jobs, || {
        work.loop_points(chunk, opts.amplitude, opts.linearity)
    })?
}

/// [`loop_margins`] from grid points measured elsewhere ([`loop_points`]): the crossings are
/// refined here.
pub fn loop_margins_from(
    system: &System,
    fmus: &[Arc<Fmu>],
    connection: &str,
    grid_points: Vec<LoopPoint>,
    opts: &Options,
) -> Result<(Vec<LoopPoint>, Margins)> {
    let freqs = frequencies(opts, system.step_size)?;
    let (plan, base) = loop_base(system, fmus, connection, &freqs, opts)?;
    let work = fork::Work::new(&plan, &base, 2.0 * opts.amplitude)?;
    pool(opts.jobs, || margins::refine_all(&work, grid_points, opts))?
}

/// The plan and prepared system of a loop analysis over `freqs` (its stop time covers the
/// fork of the lowest frequency).
fn loop_base(
    system: &System,
    fmus: &[Arc<Fmu>],
    connection: &str,
    freqs: &[f64],
    opts: &Options,
) -> Result<(fork::Plan, Base)> {
    let injection = Injection::Connection(connection.to_string());
    let plan = fork::Plan::new(system, fmus, &injection, &[], opts)?;
    let lowest = freqs.iter().copied().fold(f64::INFINITY, f64::min);
    let max = plan.length(lowest).total();
    let base = prepare(system, fmus, plan.variables(), max, opts)?;
    Ok((plan, base))
}

/// The describing function from `input` to `output` at `omega` over `amplitudes`.
pub fn describing_function(
    system: &System,
    fmus: &[Arc<Fmu>],
    input: &Injection,
    output: &str,
    omega: f64,
    amplitudes: &[f64],
    opts: &Options,
) -> Result<Vec<DescribingPoint>> {
    frequencies(
        &Options {
            frequencies: Some(vec![omega]),
            ..opts.clone()
        },
        system.step_size,
    )?;
    if amplitudes.is_empty() || amplitudes.iter().any(|a| !(*a > 0.0) || !a.is_finite()) {
        return Err(Error::Other(
            "describing function: give one or more positive amplitudes".into(),
        ));
    }
    let outputs = [output.to_string()];
    let plan = fork::Plan::new(system, fmus, input, &outputs, opts)?;
    let base = prepare(
        system,
        fmus,
        plan.variables(),
        plan.length(omega).total(),
        opts,
    )?;
    let largest = amplitudes.iter().copied().fold(0.0, f64::max);
    let work = fork::Work::new(&plan, &base, largest)?;
    pool(opts.jobs, || work.describing(omega, amplitudes))?
}
