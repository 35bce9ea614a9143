//! Running a campaign: a work-stealing pool (rayon) over the runs still to do, each run with
//! its own instances of FMUs loaded once per process; each finished run appended to the
//! journal at once.
//!
//! A run fails alone: an FMU error, a NaN in a recorded variable or a panic is recorded in its
//! row (status and message) and the campaign goes on. An interrupt (Ctrl-C) stops the runs in
//! flight cleanly; they are not recorded, and the next start runs them again. A thread stuck
//! inside an FMU cannot be stopped from outside, so a wall-time limit per run needs the
//! out-of-process mode of the hardening issue; it is not offered here.
//!
//! With `fork_at = T`, the runs are grouped by their values of everything that cannot change
//! during a run (fixed and structural parameters, seeds, start values of states). Each group
//! runs its warm-up to T once; at T every FMU's state is serialized into a master checkpoint,
//! and each run of the group continues from it in fresh instances, with its own inputs and
//! tunable parameters set by events at T. A forked run is bit-identical to the cold run that
//! sets them by events at T ([`super::Campaign::fork_systems_for`]).

use super::design::Run;
use super::journal::{Journal, JsonKpi, RunRecord, Status};
use super::kpi::{missing_values, KpiRecorder, KpiValue};
use super::output;
use super::Campaign;
use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::isolate::Isolation;
use crate::log::LogSink;
use crate::model_description::ModelDescription;
use crate::run::{self, ColumnInfo, CsvRecorder, Recorder, Row, RunOptions};
use crate::system::System;
use rayon::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How to run a campaign.
#[derive(Clone, Default)]
pub struct CampaignOptions {
    /// Worker threads (default: every core).
    pub jobs: Option<usize>,
    /// Run only shard i of n (0-based): runs (or, with forks, warm-up groups) whose index is
    /// i modulo n.
    pub shard: Option<(usize, usize)>,
    /// The output folder (journal, tables, provenance, series).
    pub output: PathBuf,
    /// Show a progress bar.
    pub progress: bool,
    /// Run again the runs that failed before (default: a failed run counts as done).
    pub retry_failed: bool,
    pub interrupt: Option<Arc<AtomicBool>>,
    pub log_sink: Option<LogSink>,
    /// Told of every run as it starts and ends (progress in embedding applications).
    pub observer: Option<Arc<dyn Observer>>,
}

/// An observer of a campaign's runs, called from the worker threads.
pub trait Observer: Send + Sync {
    /// A run starts. Called inside the run's panic guard: a panic here fails that run only.
    fn started(&self, _run: &Run) {}
    /// A run finished and is in the journal.
    fn finished(&self, _run: &Run, _record: &RunRecord) {}
}

/// What a campaign run did.
#[derive(Debug, Clone, Default)]
pub struct CampaignOutcome {
    /// Runs in the campaign (all shards).
    pub total: usize,
    /// Runs of this shard.
    pub selected: usize,
    /// Runs of this shard found done in the journal and skipped.
    pub skipped: usize,
    /// Runs executed now, and how many of them failed.
    pub ran: usize,
    pub failed: usize,
    /// Of the runs done before (`skipped`), how many had failed (not run again without
    /// `retry_failed`).
    pub failed_before: usize,
    pub interrupted: bool,
    pub jobs: usize,
    /// Why the jobs were limited, if they were.
    pub jobs_note: Option<String>,
    pub wall: Duration,
    /// The slowest run executed now: (index, wall time [s]).
    pub slowest: Option<(usize, f64)>,
    /// The shard run (`--shard I/N`), if any.
    pub shard: Option<(usize, usize)>,
    /// With forks: the runs per warm-up group (of this shard).
    pub groups: Option<Vec<usize>>,
    pub files: Vec<PathBuf>,
    pub warnings: Vec<String>,
}

impl CampaignOutcome {
    pub fn runs_per_second(&self) -> f64 {
        self.ran as f64 / self.wall.as_secs_f64().max(1e-9)
    }
}

impl std::fmt::Display for CampaignOutcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let shard = match self.shard {
            Some((i, n)) => format!(" of shard {i}/{n}"),
            None => String::new(),
        };
        write!(
            f,
            "{} of {} runs{shard} ran ({} failed), {} were done before; {:.1} s, {:.2} runs/s on {} job(s)",
            self.ran,
            self.selected,
            self.failed,
            self.skipped,
            self.wall.as_secs_f64(),
            self.runs_per_second(),
            self.jobs
        )?;
        if self.failed_before > 0 {
            write!(
                f,
                "\n{} of the runs done before had failed (--retry-failed runs them again)",
                self.failed_before
            )?;
        }
        if let Some(note) = &self.jobs_note {
            write!(f, " ({note})")?;
        }
        if let Some((i, t)) = self.slowest {
            write!(f, "\nslowest run: {i} ({t:.3} s)")?;
        }
        if let Some(g) = &self.groups {
            let (lo, hi) = (g.iter().min().unwrap_or(&0), g.iter().max().unwrap_or(&0));
            write!(f, "\nwarm-up groups: {} ({lo}..={hi} runs each)", g.len())?;
        }
        if self.interrupted {
            write!(
                f,
                "\ninterrupted: the runs in flight were not recorded and will run again"
            )?;
        }
        for p in &self.files {
            write!(f, "\nwrote {}", p.display())?;
        }
        Ok(())
    }
}

/// The shared state of the workers.
struct Context<'a> {
    campaign: &'a Campaign,
    fmus: Vec<Arc<Fmu>>,
    run_opts: RunOptions,
    sink: Mutex<Sink>,
    progress: Option<indicatif::ProgressBar>,
    failed: AtomicUsize,
    /// Runs finished (recorded) by this call.
    done: AtomicUsize,
    slowest: Mutex<Option<(usize, f64)>>,
    interrupted: AtomicBool,
    series_dir: PathBuf,
    observer: Option<Arc<dyn Observer>>,
}

impl Context<'_> {
    fn mds(&self) -> Vec<&ModelDescription> {
        self.fmus.iter().map(|f| &f.model_description).collect()
    }

    fn stop(&self) -> bool {
        self.run_opts
            .interrupt
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// Records a finished run (journal, progress, slowest); an interrupted one is not.
    fn finish(&self, run: &Run, result: Outcome) -> Result<()> {
        let (status, message, kpis, wall) = match result {
            Outcome::Interrupted => {
                self.interrupted.store(true, Ordering::Relaxed);
                return Ok(());
            }
            Outcome::Done {
                status,
                message,
                kpis,
                wall,
            } => (status, message, kpis, wall),
        };
        self.done.fetch_add(1, Ordering::Relaxed);
        if status.failed() {
            self.failed.fetch_add(1, Ordering::Relaxed);
        }
        {
            let mut s = self.slowest.lock().unwrap_or_else(|e| e.into_inner());
            if s.is_none_or(|(_, t)| wall > t) {
                *s = Some((run.index, wall));
            }
        }
        let record = RunRecord {
            index: run.index,
            key: run.key.clone(),
            status,
            message,
            kpis: kpis.iter().map(JsonKpi::from).collect(),
            wall_time: wall,
        };
        if let Some(o) = &self.observer {
            o.finished(run, &record);
        }
        self.sink
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .put(record)?;
        if let Some(p) = &self.progress {
            p.inc(1);
            p.set_message(format!("{} failed", self.failed.load(Ordering::Relaxed)));
        }
        Ok(())
    }
}

/// Where finished runs go: the journal of the output folder (a local campaign), or a list
/// handed back to the caller (a chunk run by a worker for a client that records it,
/// [`super::remote`]).
pub(super) enum Sink {
    Journal(Journal),
    Collect(Vec<RunRecord>),
}

impl Sink {
    fn put(&mut self, record: RunRecord) -> Result<()> {
        match self {
            Sink::Journal(j) => j.append(record),
            Sink::Collect(v) => {
                v.push(record);
                Ok(())
            }
        }
    }
}

/// How one run ended.
enum Outcome {
    Done {
        status: Status,
        message: String,
        kpis: Vec<KpiValue>,
        /// Wall time of the run [s].
        wall: f64,
    },
    Interrupted,
}

/// Records the KPIs and, for the runs that asked for it, the decimated series.
struct RunRecorders<'a> {
    kpis: KpiRecorder<'a>,
    series: Option<(CsvRecorder, u64, u64)>,
}

impl Recorder for RunRecorders<'_> {
    fn start(&mut self, columns: &[ColumnInfo], expected_rows: u64) -> Result<()> {
        self.kpis.start(columns, expected_rows)?;
        if let Some((csv, _, _)) = &mut self.series {
            csv.start(columns, expected_rows)?;
        }
        Ok(())
    }

    fn record(&mut self, time: f64, row: &Row<'_>) -> Result<()> {
        self.kpis.record(time, row)?;
        if let Some((csv, every, n)) = &mut self.series {
            if *n % *every == 0 {
                csv.record(time, row)?;
            }
            *n += 1;
        }
        Ok(())
    }

    fn finish(&mut self) -> Result<()> {
        self.kpis.finish()?;
        if let Some((csv, _, _)) = &mut self.series {
            csv.finish()?;
        }
        Ok(())
    }
}

/// How a run's execution ends: the master's result and the recorders.
/// "KPI 'x' is NaN (...)" for the first window statistic that is not finite.
fn non_finite_stat(specs: &[super::kpi::KpiSpec], values: &[KpiValue]) -> Option<String> {
    let mut at = 0;
    for k in specs {
        let columns = k.columns();
        if let (super::kpi::KpiSpec::Stat { .. }, Some(KpiValue::Number(x))) = (k, values.get(at)) {
            if !x.is_finite() {
                return Some(format!(
                    "KPI '{}' is {x}: its window holds no sample of the run, or the statistic \
                     overflowed",
                    columns[0]
                ));
            }
        }
        at += columns.len();
    }
    None
}

fn classify(
    result: std::thread::Result<Result<run::Summary>>,
    recorders: &RunRecorders<'_>,
    specs: &[super::kpi::KpiSpec],
    wall: f64,
) -> Outcome {
    let failed = |status, message: String| Outcome::Done {
        status,
        message,
        kpis: missing_values(specs),
        wall,
    };
    match result {
        Ok(Ok(summary)) => {
            let (status, message) = match summary.terminated_by {
                Some(m) => (Status::Terminated, m),
                None => (Status::Ok, String::new()),
            };
            let kpis = recorders.kpis.values();
            let (status, message) = match non_finite_stat(specs, &kpis) {
                Some(m) => (Status::NonFiniteKpi, m),
                None => (status, message),
            };
            Outcome::Done {
                status,
                message,
                kpis,
                wall,
            }
        }
        Ok(Err(Error::Interrupted { .. })) => Outcome::Interrupted,
        Ok(Err(e)) if recorders.kpis.nan().is_some() => failed(Status::Nan, e.to_string()),
        Ok(Err(e)) => failed(Status::Error, e.to_string()),
        Err(panic) => {
            let m = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "a panic without a message".into());
            failed(Status::Panic, format!("panic: {m}"))
        }
    }
}

impl Context<'_> {
    fn recorders(&self, run: &Run) -> Result<RunRecorders<'_>> {
        let series = match &self.campaign.spec.series {
            Some(s) if s.runs.contains(&(run.index as u64)) => {
                let path = crate::output_path::writable(
                    &self.series_dir.join(super::output::series_name(run.index)),
                )?;
                std::fs::create_dir_all(&self.series_dir).map_err(|e| {
                    Error::io(format!("cannot create {}", self.series_dir.display()), e)
                })?;
                let f = std::fs::File::create(&path)
                    .map_err(|e| Error::io(format!("cannot create {}", path.display()), e))?;
                let w: Box<dyn std::io::Write> = Box::new(std::io::BufWriter::new(f));
                Some((CsvRecorder::new(w), s.decimation as u64, 0))
            }
            _ => None,
        };
        Ok(RunRecorders {
            kpis: KpiRecorder::new(&self.campaign.spec.kpis),
            series,
        })
    }

    /// A cold run: validate the run's system and run it.
    fn cold(&self, run: &Run) -> Outcome {
        self.execute(run, |rec| {
            let system = self.campaign.system_for(run)?;
            let plan = system.validate(&self.mds())?;
            run::run_into(&plan, &self.fmus, Some(rec), &self.run_opts)
        })
    }

    /// A run's execution with a panic caught and the outcome classified.
    fn execute(
        &self,
        run: &Run,
        body: impl FnOnce(&mut dyn Recorder) -> Result<run::Summary>,
    ) -> Outcome {
        let begin = Instant::now();
        let mut recorders = match self.recorders(run) {
            Ok(r) => r,
            Err(e) => {
                return Outcome::Done {
                    status: Status::Error,
                    message: e.to_string(),
                    kpis: missing_values(&self.campaign.spec.kpis),
                    wall: 0.0,
                }
            }
        };
        let result = catch_unwind(AssertUnwindSafe(|| {
            if let Some(o) = &self.observer {
                o.started(run);
            }
            body(&mut recorders)
        }));
        let wall = begin.elapsed().as_secs_f64();
        classify(result, &recorders, &self.campaign.spec.kpis, wall)
    }
}

/// Runs the campaign's runs of this shard that are not done yet. See the module documentation.
pub fn run(campaign: &Campaign, opts: &CampaignOptions) -> Result<CampaignOutcome> {
    let begin = Instant::now();
    at_least_one_job(opts.jobs)?;
    let fmus = run::load_fmus_with(
        &campaign.system,
        &crate::fmu::Unpack::default(),
        &foreign_isolation(),
    )?;
    validate_first_runs(campaign, &fmus)?;
    let dir = &opts.output;
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::io(format!("cannot create output folder {}", dir.display()), e))?;
    // The folder's lock first (the journal holds it): a second process on the folder is refused
    // before it writes anything, campaign.json included.
    let journal = Journal::open(dir, output::kpi_columns(&campaign.spec).len())?;
    output::check_or_write_provenance(campaign, dir, opts.shard)?;
    let (jobs, jobs_note) = jobs_for(&fmus, opts.jobs, campaign.runs.len())?;
    let mut outcome = CampaignOutcome {
        total: campaign.runs.len(),
        jobs,
        jobs_note,
        shard: opts.shard,
        ..Default::default()
    };
    let mds: Vec<&ModelDescription> = fmus.iter().map(|f| &f.model_description).collect();
    let fork = fork_plan(campaign, &mds)?;
    let selected = select(campaign, fork.as_ref(), opts.shard);
    outcome.selected = selected.len();
    // Each selected run's state in the journal (None: not done; Some(failed)), its key made once.
    let state: Vec<(usize, Option<bool>)> = selected
        .into_par_iter()
        .map(|i| {
            let done = journal.done(&campaign.runs.run(i).key);
            (i, done.map(|r| r.status.failed()))
        })
        .collect();
    let retry = opts.retry_failed;
    let todo: Vec<usize> = state
        .iter()
        .filter(|(_, s)| s.is_none() || (retry && *s == Some(true)))
        .map(|&(i, _)| i)
        .collect();
    outcome.skipped = outcome.selected - todo.len();
    outcome.failed_before = state
        .iter()
        .filter(|(_, s)| !retry && *s == Some(true))
        .count();
    drop(state);
    let ctx = Context {
        progress: opts.progress.then(|| progress_bar(todo.len())),
        observer: opts.observer.clone(),
        ..Context::new(
            campaign,
            fmus,
            opts,
            Sink::Journal(journal),
            dir.join("series"),
        )
    };
    let stopped_before = ctx.stop();
    outcome.groups = execute_all(&ctx, fork.as_ref(), &todo, jobs)?;
    outcome.ran = ctx.done.load(Ordering::Relaxed);
    outcome.interrupted = ctx.interrupted.load(Ordering::Relaxed) || ctx.stop();
    let stopped_runs = outcome.interrupted && !stopped_before;
    outcome.failed = ctx.failed.load(Ordering::Relaxed);
    outcome.slowest = *ctx.slowest.lock().unwrap_or_else(|e| e.into_inner());
    let Sink::Journal(journal) = ctx.sink.into_inner().unwrap_or_else(|e| e.into_inner()) else {
        unreachable!("a local campaign records into its journal")
    };
    // A signal during the runs stopped them, and the tables of the finished runs are written on
    // the way out (a second signal exits at once); a first signal before the runs, or during
    // this phase, stops it.
    let stop = output::Stop(opts.interrupt.as_deref().filter(|_| !stopped_runs));
    outcome.files = match output::write_tables(&campaign.spec, &campaign.runs, &journal, dir, stop)
    {
        Err(Error::Interrupted { .. }) => {
            outcome.interrupted = true;
            Vec::new()
        }
        other => other?,
    };
    outcome.wall = begin.elapsed();
    Ok(outcome)
}

/// Validates the system of the first run of each arm (of the campaign, when it has no arms)
/// against the FMUs, as `shipsim check` validates a system, before anything runs or is
/// written. When every one fails, the mistake is one that every run would make (an unknown KPI
/// or seed variable, a campaign-wide value out of its variable's range, a stop time that cannot
/// be): one error instead of a campaign of failed runs. A mistake of some arms or values only
/// fails those runs, which are recorded.
fn validate_first_runs(campaign: &Campaign, fmus: &[Arc<Fmu>]) -> Result<()> {
    let mds: Vec<&ModelDescription> = fmus.iter().map(|f| &f.model_description).collect();
    let mut first_error = None;
    for arm in 0..campaign.spec.arms.len().max(1) {
        // the first run of an arm is the arm's index (point 0, replication 0)
        let Some(run) = campaign.runs.get(arm) else {
            continue;
        };
        match campaign
            .system_for(&run)
            .and_then(|s| s.validate(&mds).map(drop))
        {
            Ok(()) => return Ok(()),
            Err(e) if first_error.is_none() => first_error = Some((run.index, e)),
            Err(_) => {}
        }
    }
    match first_error {
        None => Ok(()),
        Some((index, e)) => Err(Error::Other(format!(
            "campaign {}: run {index} cannot run, and no run would (the first run of every arm \
             fails the same checks): {e}",
            campaign.spec.source.display(),
        ))),
    }
}

/// Whether a run still has to run: not in the journal, or failed there and retried.
pub(super) fn to_do(journal: &Journal, run: &Run, retry_failed: bool) -> bool {
    match journal.done(&run.key) {
        Some(rec) => retry_failed && rec.status.failed(),
        None => true,
    }
}

/// The isolation of a campaign's runs: the instances of FMUs not built by this project run in
/// their own processes ([`crate::isolate`]), so one that crashes, exits or hangs fails its run
/// only. Our FMUs run in process (their calls are tested and fuzzed, and in process is faster).
/// Without a command to host them (the library in another program that set none with
/// [`crate::isolate::set_host_command`], and no `$SHIPSIM_FMU_HOST`), every FMU runs in
/// process. The Python package sets one, so campaigns from Python and on Dask workers isolate
/// foreign FMUs too.
fn foreign_isolation() -> Isolation {
    let iso = Isolation::foreign();
    match iso.host_command() {
        Ok(_) => iso,
        Err(_) => Isolation::default(),
    }
}

/// The worker threads to use (every core by default), and why they were limited: an FMU in
/// process that can be instantiated only once per process allows one (isolated, each instance
/// has a process of its own).
fn at_least_one_job(jobs: Option<usize>) -> Result<()> {
    if jobs == Some(0) {
        return Err(Error::Other(
            "jobs = 0: a campaign needs at least one job (-j N, Python jobs=N, N >= 1)".into(),
        ));
    }
    Ok(())
}

/// At most this many jobs per core: a run is CPU-bound, so more threads only add switching.
pub const JOBS_PER_CORE: usize = 4;

/// The number of jobs (threads) for `runs` runs: `jobs` (default: one per core), never 0,
/// never more than the runs nor [`JOBS_PER_CORE`] per core, and 1 for an FMU that can be
/// instantiated once per process; with a note when it is not what was asked.
fn jobs_for(
    fmus: &[Arc<Fmu>],
    jobs: Option<usize>,
    runs: usize,
) -> Result<(usize, Option<String>)> {
    at_least_one_job(jobs)?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let most = JOBS_PER_CORE * cores;
    let asked = jobs.unwrap_or_else(rayon::current_num_threads);
    let mut note = (asked > most).then(|| {
        format!("{asked} jobs asked, at most {most}: {JOBS_PER_CORE} per core on {cores} cores")
    });
    let jobs = asked.min(most).min(runs.max(1));
    let once = fmus
        .iter()
        .find(|f| f.is_loaded() && f.co_simulation().can_be_instantiated_only_once_per_process);
    if let (Some(f), true) = (once, jobs > 1) {
        note = Some(format!(
            "{} declares canBeInstantiatedOnlyOncePerProcess: one job (it is built by this project, so it runs in process)",
            f.path.display()
        ));
        return Ok((1, note));
    }
    Ok((jobs, note))
}

impl<'a> Context<'a> {
    /// The workers' state for `campaign` with its loaded FMUs, recording into `sink`; no
    /// progress bar and no observer.
    fn new(
        campaign: &'a Campaign,
        fmus: Vec<Arc<Fmu>>,
        opts: &CampaignOptions,
        sink: Sink,
        series_dir: PathBuf,
    ) -> Context<'a> {
        Context {
            campaign,
            fmus,
            run_opts: RunOptions {
                interrupt: opts.interrupt.clone(),
                log_sink: opts.log_sink.clone(),
                isolation: foreign_isolation(),
                ..Default::default()
            },
            sink: Mutex::new(sink),
            progress: None,
            failed: Default::default(),
            done: Default::default(),
            slowest: Mutex::new(None),
            interrupted: AtomicBool::new(false),
            series_dir,
            observer: None,
        }
    }
}

/// Runs `todo` on a pool of `jobs` threads: each run cold, or with forks each warm-up group
/// once and its runs from the checkpoint (returns the group sizes then).
fn execute_all(
    ctx: &Context,
    fork: Option<&Fork>,
    todo: &[usize],
    jobs: usize,
) -> Result<Option<Vec<usize>>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| Error::Other(format!("cannot start {jobs} worker threads: {e}")))?;
    let errors: Mutex<Vec<Error>> = Mutex::new(Vec::new());
    let keep = |r: Result<()>| {
        if let Err(e) = r {
            errors.lock().unwrap_or_else(|e| e.into_inner()).push(e);
        }
    };
    let groups = pool.install(|| match fork {
        None => {
            todo.par_iter().for_each(|&i| {
                if !ctx.stop() {
                    let run = ctx.campaign.runs.run(i);
                    keep(ctx.finish(&run, ctx.cold(&run)));
                }
            });
            None
        }
        Some(fork) => {
            let groups = fork.groups_of(todo);
            groups.par_iter().for_each(|g| keep(fork.run_group(ctx, g)));
            Some(groups.iter().map(Vec::len).collect())
        }
    });
    if let Some(p) = &ctx.progress {
        p.finish();
    }
    match errors.into_inner().unwrap_or_else(|e| e.into_inner()).pop() {
        Some(e) => Err(e),
        None => Ok(groups),
    }
}

/// Runs the given runs (by index) into a list instead of a journal: a chunk of a campaign
/// whose results another process records ([`super::remote`]). Series files go to
/// `series_dir`. An interrupt ends it with [`Error::Interrupted`] (nothing is returned, the
/// client runs the chunk again).
pub(super) fn run_collect(
    campaign: &Campaign,
    fmus: &[Arc<Fmu>],
    indices: &[usize],
    opts: &CampaignOptions,
    series_dir: PathBuf,
) -> Result<Vec<RunRecord>> {
    if let Some(i) = indices.iter().find(|&&i| i >= campaign.runs.len()) {
        return Err(Error::Other(format!(
            "campaign {}: no run {i} (it has {})",
            campaign.spec.source.display(),
            campaign.runs.len()
        )));
    }
    let (jobs, _) = jobs_for(fmus, opts.jobs, indices.len())?;
    let mds: Vec<&ModelDescription> = fmus.iter().map(|f| &f.model_description).collect();
    let fork = fork_plan(campaign, &mds)?;
    let ctx = Context {
        observer: opts.observer.clone(),
        ..Context::new(
            campaign,
            fmus.to_vec(),
            opts,
            Sink::Collect(Vec::new()),
            series_dir,
        )
    };
    execute_all(&ctx, fork.as_ref(), indices, jobs)?;
    if ctx.interrupted.load(Ordering::Relaxed) || ctx.stop() {
        return Err(Error::Interrupted { time: f64::NAN });
    }
    match ctx.sink.into_inner().unwrap_or_else(|e| e.into_inner()) {
        Sink::Collect(records) => Ok(records),
        Sink::Journal(_) => unreachable!("a chunk collects its records"),
    }
}

/// The runs by warm-up group (a forked campaign) or one by one: the units of work that keep
/// a group's warm-up in one place, in index order.
pub(super) fn work_units(
    campaign: &Campaign,
    mds: &[&ModelDescription],
    todo: &[usize],
) -> Result<Vec<Vec<usize>>> {
    Ok(match fork_plan(campaign, mds)? {
        Some(f) => f.groups_of(todo),
        None => todo.iter().map(|&i| vec![i]).collect(),
    })
}

fn progress_bar(n: usize) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(n as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} runs, {msg}, {per_sec}, ETA {eta}",
        )
        .expect("valid template"),
    );
    bar.set_message("0 failed");
    bar
}

/// The runs of shard i of n: by run index, or with forks by warm-up group (so a group's
/// warm-up runs once, in one shard).
fn select(campaign: &Campaign, fork: Option<&Fork>, shard: Option<(usize, usize)>) -> Vec<usize> {
    let all = 0..campaign.runs.len();
    match (shard, fork) {
        (None, _) => all.collect(),
        (Some((i, n)), None) => all.filter(|r| r % n == i).collect(),
        (Some((i, n)), Some(f)) => all.filter(|r| f.group[*r] % n == i).collect(),
    }
}

/// The warm-up groups of a forked campaign.
struct Fork {
    at: f64,
    /// `group[run]`: the run's warm-up group, numbered in order of first appearance.
    group: Vec<usize>,
    /// The set variables (`instance.variable`) that can change during a run (inputs and
    /// tunable parameters): set by events at the fork, the others before the warm-up.
    changeable: std::collections::HashSet<String>,
}

/// Groups the runs when the campaign forks, after checking every FMU can save its state.
fn fork_plan(campaign: &Campaign, mds: &[&ModelDescription]) -> Result<Option<Fork>> {
    let Some(at) = campaign.spec.fork_at else {
        return Ok(None);
    };
    for (inst, md) in campaign.system.instances.iter().zip(mds) {
        let cs = md.co_simulation.as_ref();
        if !cs.is_some_and(|c| c.can_get_and_set_fmu_state && c.can_serialize_fmu_state) {
            return Err(Error::fmu(
                &inst.fmu,
                format!(
                    "instance '{}': fork_at needs canGetAndSetFMUstate and canSerializeFMUstate, which this FMU does not declare",
                    inst.name
                ),
            ));
        }
    }
    let changeable: std::collections::HashSet<String> = campaign
        .runs
        .variables()
        .filter(|v| {
            crate::system::VarRef::parse(v)
                .is_some_and(|r| super::changeable_in(&campaign.system, mds, &r))
        })
        .map(str::to_string)
        .collect();
    let fork = Fork {
        at,
        group: Vec::new(),
        changeable,
    };
    let mut keys: std::collections::HashMap<String, usize> = Default::default();
    let group = campaign
        .runs
        .iter()
        .map(|r| {
            let n = keys.len();
            *keys
                .entry(campaign.group_key(&r, &|v| fork.is_changeable(v)))
                .or_insert(n)
        })
        .collect();
    Ok(Some(Fork { group, ..fork }))
}

impl Fork {
    fn is_changeable(&self, r: &crate::system::VarRef) -> bool {
        self.changeable.contains(&r.to_string())
    }

    /// (The warm-up system of the run's group, the run's own system.)
    fn systems(&self, campaign: &Campaign, run: &Run) -> Result<(System, System)> {
        campaign.fork_systems_for(run, self.at, &|v| self.is_changeable(v))
    }

    /// The runs to do, by warm-up group.
    fn groups_of(&self, todo: &[usize]) -> Vec<Vec<usize>> {
        let mut by: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
        for &i in todo {
            by.entry(self.group[i]).or_default().push(i);
        }
        by.into_values().collect()
    }

    /// One group: its warm-up to T, then every run from the checkpoint.
    fn run_group(&self, ctx: &Context, runs: &[usize]) -> Result<()> {
        if ctx.stop() {
            return Ok(());
        }
        let design = &ctx.campaign.runs;
        let warm_up = || -> Result<run::Checkpoint> {
            let (system, _) = self.systems(ctx.campaign, &design.run(runs[0]))?;
            let plan = system.validate(&ctx.mds())?;
            let k = run::checkpoint_step(&plan, self.at)
                .map_err(|e| Error::Other(format!("fork_at: {e}")))?;
            run::run_to_checkpoint(&plan, &ctx.fmus, k, None, &ctx.run_opts)
        };
        let cp = match catch_unwind(AssertUnwindSafe(warm_up)) {
            Ok(Ok(cp)) => Arc::new(cp),
            Ok(Err(Error::Interrupted { .. })) => return Ok(()),
            failed => {
                // The warm-up failed: every run of the group fails with its message.
                let message = match failed {
                    Ok(Err(e)) => format!("warm-up: {e}"),
                    _ => "warm-up: panic".into(),
                };
                for &i in runs {
                    let done = Outcome::Done {
                        status: Status::Error,
                        message: message.clone(),
                        kpis: missing_values(&ctx.campaign.spec.kpis),
                        wall: 0.0,
                    };
                    ctx.finish(&design.run(i), done)?;
                }
                return Ok(());
            }
        };
        runs.par_iter().try_for_each(|&i| {
            if ctx.stop() {
                return Ok(());
            }
            let r = design.run(i);
            let outcome = ctx.execute(&r, |rec| {
                let plan = self.systems(ctx.campaign, &r)?.1.validate(&ctx.mds())?;
                run::resume_into(&plan, &ctx.fmus, &cp, Some(rec), &ctx.run_opts)
            });
            ctx.finish(&r, outcome)
        })
    }
}
