//! The fixed-step master: runs a validated [`Plan`] with loaded FMUs.
//!
//! A run goes through these files in order:
//!
//! 1. [`exchange`]: the plan's connections and recorded outputs resolved into per-instance
//!    typed ports and one shared value store;
//! 2. [`recorder`]: the observer that receives the recorded rows (CSV file, memory, ...);
//! 3. [`initialize`]: instantiation, start values, initialization with the initial exchange;
//! 4. [`stepping`]: the step loop, generic over the [`algorithm`] (Jacobi or Gauss-Seidel),
//!    on the communication points of [`time_grid`], each instance a [`slot`];
//! 5. termination of every instance (here), so that a failing fmi2Terminate is reported.
//!
//! A run can stop at a communication point and hand back a [`Checkpoint`]
//! ([`run_to_checkpoint`]), write one on passing a step and go on ([`RunOptions::checkpoint`]),
//! or start from one in fresh instances ([`resume_into`]); [`checkpoint`] says what it holds.
//!
//! Clean termination holds on every path: an instance dropped on an error or an interrupt is
//! terminated and freed ([`crate::instance`]). The step loop allocates nothing.
//!
//! The library installs no process-wide state (no signal handler, no logger): a caller that
//! wants Ctrl-C to stop a run sets [`RunOptions::interrupt`] from its own handler, as the CLI
//! does. FMU log messages go to [`RunOptions::log_sink`] (default: stderr, warnings and worse).

use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::isolate::{IsolateMode, Isolation};
use crate::log::LogSink;
use crate::model_description::ModelDescription;
use crate::slave::CallMonitor;
use crate::system::{Algorithm as AlgorithmChoice, LastStep, OffGrid, Plan, System};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

mod algorithm;
mod checkpoint;
mod exchange;
mod initialize;
mod profile;
mod progress;
mod recorder;
mod session;
mod slot;
mod stepping;
mod time_grid;

use algorithm::{Algorithm, GaussSeidel, Jacobi};
use checkpoint::Fingerprint;
pub use checkpoint::{checkpoint_step, Checkpoint};
use exchange::Exchange;
pub use profile::{Profile, Sampling};
pub use recorder::{
    write_real, ColumnInfo, CsvRecorder, MemoryRecorder, OpenOnWrite, Recorder, Row, Sample,
};
pub use session::{
    Journal, JournalHeader, Journaling, Replay, Session, SessionCheckpoint, SessionOptions, Set,
    State,
};
use stepping::{Recording, Stepper};
pub use time_grid::TimeGrid;

/// How to run.
#[derive(Clone, Default)]
pub struct RunOptions {
    /// FMU log messages below fmi2Warning are shown too, and loggingOn is passed to the FMUs.
    pub verbose: bool,
    /// Show a progress bar (the CLI enables it only when stderr is a terminal).
    pub progress: bool,
    /// Set to true (e.g. by Ctrl-C) to stop the run cleanly.
    pub interrupt: Option<Arc<AtomicBool>>,
    pub log_sink: Option<LogSink>,
    /// Write a checkpoint on passing a base step and continue ([`run_into`], [`resume_into`]).
    pub checkpoint: Option<CheckpointRequest>,
    /// Time where the step loop goes per instance, on these steps ([`Summary::profile`],
    /// [`profile`]).
    pub profile: Option<Sampling>,
    /// Which instances run in their own processes ([`crate::isolate`]); the FMUs must be
    /// loaded for it ([`load_fmus_with`]).
    pub isolation: Isolation,
    /// Where in-process instances note the call in progress (for a caller's exit hook or
    /// watchdog, [`crate::slave::CallMonitor`]).
    pub monitor: Option<Arc<CallMonitor>>,
}

/// Where and when a run writes its checkpoint.
#[derive(Clone, Debug)]
pub struct CheckpointRequest {
    /// The base step k: the checkpoint is the run at t_k ([`checkpoint_step`] finds k for a time).
    pub step: u64,
    pub file: PathBuf,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct Summary {
    pub macro_steps: u64,
    /// Sum over instances of fmi2DoStep calls.
    pub fmu_steps: u64,
    pub start_time: f64,
    pub end_time: f64,
    /// Wall time of the step loop only (after initialization).
    pub wall_time: Duration,
    /// Wall time including loading, instantiation and initialization.
    pub total_wall_time: Duration,
    pub rows: u64,
    /// Set when an FMU ended the simulation early (fmi2Discard + fmi2Terminated).
    pub terminated_by: Option<String>,
    pub output_file: Option<PathBuf>,
    /// Set when the stop time asked for was off the base-step grid: the run stopped before it
    /// or took a short last step to it (`Display` says which).
    pub off_grid: Option<OffGrid>,
    /// With [`RunOptions::profile`]: where the step loop's time went (not part of `Display`).
    pub profile: Option<Profile>,
}

impl Summary {
    pub fn real_time_factor(&self) -> f64 {
        (self.end_time - self.start_time) / self.wall_time.as_secs_f64().max(1e-12)
    }
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let w = self.wall_time.as_secs_f64();
        let early = match self.terminated_by {
            Some(_) => " (ended early)",
            None => "",
        };
        writeln!(
            f,
            "simulated {} s .. {} s{early}: {} macro steps, {} FMU steps",
            self.start_time, self.end_time, self.macro_steps, self.fmu_steps
        )?;
        write!(
            f,
            "wall time {:.3} s (step loop), {:.3} s total; real-time factor {:.1}; {:.3} us per macro step, {:.3} us per FMU step",
            w,
            self.total_wall_time.as_secs_f64(),
            self.real_time_factor(),
            w * 1e6 / self.macro_steps.max(1) as f64,
            w * 1e6 / self.fmu_steps.max(1) as f64
        )?;
        if let Some(o) = &self.off_grid {
            write!(f, "\n{}", off_grid_line(o))?;
        }
        if let Some(t) = &self.terminated_by {
            // The instance's time is its own last successful time (FMI 2.0, sec. 4.2.3), which
            // lies in its last step; the master ends that macro step for the other instances
            // and stops at the step's end, t_(k+1): the end of the run and its last row. With
            // a step multiple, or an FMU that reports the end of its step, the two differ.
            write!(
                f,
                "\n{t}; the master stopped at the end of that macro step, at t = {} s (its last communication point)",
                self.end_time
            )?;
        }
        if let Some(p) = &self.output_file {
            write!(f, "\n{} rows written to {}", self.rows, p.display())?;
        }
        Ok(())
    }
}

/// The summary's line on a stop time off the base-step grid: which [`LastStep`] was done.
fn off_grid_line(o: &OffGrid) -> String {
    let stop = o.stop_time;
    match o.last_step {
        LastStep::Short => format!(
            "stop time {stop} s is off the base-step grid: the last step was shortened to end at it (last_step = \"short\")"
        ),
        LastStep::Drop => format!(
            "stop time {stop} s is off the base-step grid: the run stopped before it, at the last grid point (last_step = \"drop\"; last_step = \"short\" or --last-step short takes a shorter last step to it)"
        ),
    }
}

/// Loads each distinct FMU once (instances of the same file share one loaded library).
pub fn load_fmus(system: &System) -> Result<Vec<Arc<Fmu>>> {
    load_fmus_with(
        system,
        &crate::fmu::Unpack::default(),
        &Isolation::default(),
    )
}

/// [`load_fmus`] with the archives unpacked under `unpack` (limits, directory, interrupt), for
/// a run with `isolation`: an FMU whose instances all run in their own processes is opened
/// without loading its binary here ([`Fmu::open_unloaded`]).
pub fn load_fmus_with(
    system: &System,
    unpack: &crate::fmu::Unpack,
    isolation: &Isolation,
) -> Result<Vec<Arc<Fmu>>> {
    let mut cache: HashMap<PathBuf, Arc<Fmu>> = HashMap::new();
    let mut out = Vec::new();
    let key_of = |inst: &crate::system::InstanceSpec| {
        inst.fmu.canonicalize().unwrap_or_else(|_| inst.fmu.clone())
    };
    // The files with an instance that is not isolated by name (`--isolate=NAMES`) or by the
    // system file (`isolate = true`).
    let by_name: &[String] = match &isolation.mode {
        IsolateMode::Instances(names) => names,
        _ => &[],
    };
    // A set: systems of 20,000 instances are loaded in one go.
    let named_in_process: std::collections::HashSet<PathBuf> = match &isolation.mode {
        IsolateMode::None | IsolateMode::Instances(_) => system
            .instances
            .iter()
            .filter(|i| !i.isolate && !by_name.contains(&i.name))
            .map(key_of)
            .collect(),
        _ => Default::default(),
    };
    for inst in &system.instances {
        let key = key_of(inst);
        let fmu = match cache.get(&key) {
            Some(f) => {
                if f.is_loaded() && f.co_simulation().can_be_instantiated_only_once_per_process {
                    return Err(Error::fmu(
                        &inst.fmu,
                        format!(
                            "instance '{}': the FMU declares canBeInstantiatedOnlyOncePerProcess=\"true\" and is already used by another instance",
                            inst.name
                        ),
                    ));
                }
                f.clone()
            }
            None => {
                system.require_fmu(inst)?;
                let unloaded = match &isolation.mode {
                    IsolateMode::None | IsolateMode::Instances(_) => {
                        !named_in_process.contains(&key)
                    }
                    _ => true,
                };
                let opened = match unloaded {
                    true => Fmu::open_unloaded(&inst.fmu, unpack).and_then(|f| {
                        match isolation.mode == IsolateMode::Foreign
                            && crate::isolate::is_ours(&f.model_description)
                        {
                            true => Fmu::load_with(&inst.fmu, unpack),
                            false => Ok(f),
                        }
                    }),
                    false => Fmu::load_with(&inst.fmu, unpack),
                };
                let f = Arc::new(opened.map_err(|e| match e {
                    Error::Fmu { path, message } => Error::Fmu {
                        path,
                        message: format!("(instance '{}') {message}", inst.name),
                    },
                    e => e,
                })?);
                cache.insert(key, f.clone());
                f
            }
        };
        out.push(fmu);
    }
    Ok(out)
}

/// Where rows go.
pub enum Output {
    None,
    File(PathBuf),
    Writer(Box<dyn Write>),
}

/// Runs a validated plan with loaded FMUs (`fmus[i]` for `plan.instances[i]`), recording into
/// a CSV file or writer.
pub fn run(plan: &Plan, fmus: &[Arc<Fmu>], output: Output, opts: &RunOptions) -> Result<Summary> {
    into_csv(output, |rec| run_into(plan, fmus, rec, opts))
}

/// [`resume_into`] recording into a CSV file or writer: the rows from the checkpoint's time on.
pub fn resume(
    plan: &Plan,
    fmus: &[Arc<Fmu>],
    cp: &Checkpoint,
    output: Output,
    opts: &RunOptions,
) -> Result<Summary> {
    into_csv(output, |rec| resume_into(plan, fmus, cp, rec, opts))
}

/// Runs `f` with a CSV recorder on `output` (or none); the summary names the file.
fn into_csv(
    output: Output,
    f: impl FnOnce(Option<&mut dyn Recorder>) -> Result<Summary>,
) -> Result<Summary> {
    let (writer, path): (Option<Box<dyn Write>>, Option<PathBuf>) = match output {
        Output::None => (None, None),
        Output::File(p) => (Some(create_output_file(&p)?), Some(p)),
        Output::Writer(w) => (Some(w), None),
    };
    let mut csv = writer.map(CsvRecorder::new);
    let mut summary = f(csv.as_mut().map(|r| r as &mut dyn Recorder))?;
    summary.output_file = path;
    Ok(summary)
}

/// The output file, checked and with its folder created, but opened (and so truncated) only
/// when the run writes into it: a run that fails before its instances are initialized leaves
/// the file of the last run as it was (issue 36, item 1). Buffered.
fn create_output_file(p: &std::path::Path) -> Result<Box<dyn Write>> {
    let p = crate::output_path::writable(p)?;
    if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io(format!("cannot create output folder {}", dir.display()), e))?;
    }
    Ok(Box::new(recorder::OpenOnWrite::new(p)))
}

/// Runs a validated plan with loaded FMUs, recording into any [`Recorder`] (or none). With
/// [`RunOptions::checkpoint`] it writes a checkpoint on passing that step and goes on.
pub fn run_into(
    plan: &Plan,
    fmus: &[Arc<Fmu>],
    recorder: Option<&mut dyn Recorder>,
    opts: &RunOptions,
) -> Result<Summary> {
    let course = Course {
        resume: None,
        checkpoint: write_request(opts),
    };
    Ok(dispatch(plan, fmus, recorder, opts, course)?.0)
}

/// Runs a plan from t_0 to t_`at_step` and returns the checkpoint there: the state at that
/// communication point after its outputs are published, before the events of step `at_step`.
/// The recorder gets the rows a full run records up to and including t_`at_step`. The
/// instances are terminated and freed. [`RunOptions::checkpoint`] is not used.
pub fn run_to_checkpoint(
    plan: &Plan,
    fmus: &[Arc<Fmu>],
    at_step: u64,
    recorder: Option<&mut dyn Recorder>,
    opts: &RunOptions,
) -> Result<Checkpoint> {
    let course = Course {
        resume: None,
        checkpoint: Some((at_step, Then::Return)),
    };
    dispatch(plan, fmus, recorder, opts, course)?
        .1
        .ok_or_else(|| Error::Other(format!("no checkpoint taken at step {at_step}")))
}

/// Continues a run from a checkpoint of the same system (else an error naming what differs,
/// [`Checkpoint::check`]): fresh instances are instantiated and initialized as in a normal run,
/// then every instance's state and the exchange's values are restored, and the step loop goes
/// on from step `cp.step` to the end, applying the plan's events at that step and later. The
/// recorder gets the row at t_`cp.step` first, then the rows a full run records after it. The
/// plan may differ from the checkpoint's in its start values and events (a fork).
pub fn resume_into(
    plan: &Plan,
    fmus: &[Arc<Fmu>],
    cp: &Checkpoint,
    recorder: Option<&mut dyn Recorder>,
    opts: &RunOptions,
) -> Result<Summary> {
    let course = Course {
        resume: Some(cp),
        checkpoint: write_request(opts),
    };
    Ok(dispatch(plan, fmus, recorder, opts, course)?.0)
}

/// Where a run starts and whether it takes a checkpoint.
struct Course<'c> {
    /// Start from this checkpoint instead of t_0.
    resume: Option<&'c Checkpoint>,
    /// Take a checkpoint on passing this step.
    checkpoint: Option<(u64, Then<'c>)>,
}

/// What to do with a checkpoint taken.
#[derive(Clone, Copy)]
enum Then<'c> {
    /// Stop the run and return it.
    Return,
    /// Write it and go on.
    Write(&'c Path),
}

fn write_request(opts: &RunOptions) -> Option<(u64, Then<'_>)> {
    opts.checkpoint
        .as_ref()
        .map(|c| (c.step, Then::Write(c.file.as_path())))
}

fn dispatch(
    plan: &Plan,
    fmus: &[Arc<Fmu>],
    recorder: Option<&mut dyn Recorder>,
    opts: &RunOptions,
    course: Course,
) -> Result<(Summary, Option<Checkpoint>)> {
    match plan.algorithm {
        AlgorithmChoice::Jacobi => execute(&Jacobi, plan, fmus, recorder, opts, course),
        AlgorithmChoice::GaussSeidel => {
            let gs = GaussSeidel { order: &plan.order };
            execute(&gs, plan, fmus, recorder, opts, course)
        }
    }
}

/// The rows a run records from t_`from` to t_`to`: the first, every `decimation` steps, and
/// t_n.
fn expected_rows(plan: &Plan, from: u64, to: u64) -> u64 {
    let dec = plan.decimation as u64;
    (to / dec - from / dec)
        .saturating_add(1)
        .saturating_add(u64::from(to == plan.n_steps && plan.n_steps % dec != 0))
}

/// The recording of a run from step `from` to `to`, its recorder started.
fn start_recording<'r>(
    plan: &Plan,
    recorder: &'r mut dyn Recorder,
    columns: &'r [exchange::Column],
    from: u64,
    to: u64,
) -> Result<Recording<'r>> {
    let infos: Vec<ColumnInfo> = plan
        .outputs
        .iter()
        .map(|o| ColumnInfo {
            name: o.header.clone(),
            var_type: o.var_type,
        })
        .collect();
    recorder.start(&infos, expected_rows(plan, from, to))?;
    Ok(Recording {
        recorder,
        columns,
        decimation: plan.decimation as u64,
        rows: 0,
    })
}

/// The first step of a run on `course` and the step where it stops, checked before the run:
/// the FMUs can save their states, the checkpoint's fingerprint matches, the requested step
/// lies in the run.
fn course_steps(
    plan: &Plan,
    fmus: &[Arc<Fmu>],
    fp: Option<&Fingerprint>,
    course: &Course,
) -> Result<(u64, u64)> {
    if fp.is_some() {
        for (pi, fmu) in plan.instances.iter().zip(fmus) {
            fmu.require_state_support(&pi.name)?;
        }
    }
    let first = match (course.resume, fp) {
        (Some(cp), Some(fp)) => {
            cp.check(fp)?;
            cp.step
        }
        _ => 0,
    };
    let stop = match course.checkpoint {
        Some((at, then)) => {
            if at < first || at >= plan.n_steps {
                let grid = TimeGrid::of(plan);
                return Err(Error::Other(format!(
                    "checkpoint at step {at}: it must lie in the run, from step {first} (t = {} s) to before the end at step {} (t = {} s)",
                    grid.at(first),
                    plan.n_steps,
                    grid.at(plan.n_steps)
                )));
            }
            match then {
                Then::Return => at,
                Then::Write(_) => plan.n_steps,
            }
        }
        None => plan.n_steps,
    };
    Ok((first, stop))
}

fn execute<A: Algorithm>(
    algorithm: &A,
    plan: &Plan,
    fmus: &[Arc<Fmu>],
    recorder: Option<&mut dyn Recorder>,
    opts: &RunOptions,
    course: Course,
) -> Result<(Summary, Option<Checkpoint>)> {
    let begin = Instant::now();
    let fingerprint = (course.resume.is_some() || course.checkpoint.is_some())
        .then(|| Fingerprint::of(plan, fmus))
        .transpose()?;
    let (first, stop) = course_steps(plan, fmus, fingerprint.as_ref(), &course)?;
    let Exchange {
        ports,
        mut values,
        columns,
    } = Exchange::build(plan);
    let mut slots = initialize::initialize(algorithm, plan, fmus, ports, &mut values, opts)?;
    // After the instances are initialized: a run that fails before has recorded nothing.
    let mut recording = match recorder {
        Some(r) => Some(start_recording(plan, r, &columns, first, stop)?),
        None => None,
    };
    if let Some(cp) = course.resume {
        cp.restore(&mut slots, &mut values)?;
    }
    let grid = TimeGrid::of(plan);
    let start_time = match first {
        0 => plan.start_time,
        k => grid.at(k),
    };
    if let Some(r) = recording.as_mut() {
        r.row(start_time, &values)?;
    }
    let mut stepper = Stepper {
        grid,
        events: &plan.events,
        slots,
        values,
        recording,
        progress: progress::Progress::new(opts.progress, plan.n_steps),
        interrupt: opts.interrupt.as_deref(),
        k: first,
        count: Default::default(),
        wall: Duration::ZERO,
        profile: opts
            .profile
            .map(|s| profile::Accumulator::new(plan.instances.len(), s)),
    };
    let mut taken = None;
    if let (Some((at, then)), Some(fp)) = (course.checkpoint, fingerprint) {
        stepper.advance(algorithm, at)?;
        if stepper.ended() {
            let end = stepper.finish()?;
            return Err(Error::Other(format!(
                "no checkpoint at t = {} s: {}",
                grid.at(at),
                end.count.terminated_by.unwrap_or_default()
            )));
        }
        let cp = Checkpoint::capture(fp, at, &mut stepper.slots, &stepper.values)?;
        match then {
            Then::Return => taken = Some(cp),
            Then::Write(path) => cp.write(path)?,
        }
    }
    stepper.advance(algorithm, stop)?;
    let end = stepper.finish()?;
    let rows = stepper.recording.as_ref().map(|r| r.rows).unwrap_or(0);
    let profile = stepper.profile.as_ref().map(|acc| {
        let names = plan.instances.iter().map(|pi| pi.name.clone());
        let calls = stepper.slots.iter().map(|s| s.do_steps);
        Profile::new(acc, names.zip(calls), end.steps - first, end.wall)
    });
    // Terminate explicitly so that a failing fmi2Terminate is reported.
    for s in stepper.slots {
        s.inst.terminate()?;
    }
    let summary = Summary {
        profile,
        macro_steps: end.steps - first,
        fmu_steps: end.count.fmu_steps,
        start_time,
        end_time: grid.at(end.steps),
        wall_time: end.wall,
        total_wall_time: begin.elapsed(),
        rows,
        terminated_by: end.count.terminated_by,
        output_file: None,
        off_grid: plan.off_grid,
    };
    Ok((summary, taken))
}

/// Loads a system's FMUs and validates it against their model descriptions. The plan's
/// warnings are for the caller to show.
pub fn prepare(system: &System) -> Result<(Plan, Vec<Arc<Fmu>>)> {
    prepare_with(
        system,
        &crate::fmu::Unpack::default(),
        &Isolation::default(),
    )
}

/// [`prepare`] with the archives unpacked under `unpack` (limits, directory, interrupt), for a
/// run with `isolation` ([`load_fmus_with`]).
pub fn prepare_with(
    system: &System,
    unpack: &crate::fmu::Unpack,
    isolation: &Isolation,
) -> Result<(Plan, Vec<Arc<Fmu>>)> {
    let fmus = load_fmus_with(system, unpack, isolation)?;
    let mds: Vec<&ModelDescription> = fmus.iter().map(|f| &f.model_description).collect();
    let plan = system.validate(&mds)?;
    Ok((plan, fmus))
}

/// Validates a system, loads its FMUs and runs it ([`prepare`] then [`run`]). The plan's
/// warnings are returned in it, not printed.
pub fn run_system(system: &System, output: Output, opts: &RunOptions) -> Result<(Plan, Summary)> {
    let begin = Instant::now();
    let (plan, fmus) = prepare(system)?;
    let mut summary = run(&plan, &fmus, output, opts)?;
    summary.total_wall_time = begin.elapsed();
    Ok((plan, summary))
}
