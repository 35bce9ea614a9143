//! The `shipsim` command line: `run`, `check`, `inspect`, `export-osp`, `export-ssp`, `plot`,
//! `campaign`.
mod cli;

use clap::{Parser, Subcommand};
use shipsim::error::Error;
use shipsim::fmu::{Unpack, UnpackedFmu};
use shipsim::limits::Limits;
use shipsim::run::{
    checkpoint_step, prepare_with, resume, run, Checkpoint, CheckpointRequest, Output, RunOptions,
    Sampling,
};
use shipsim::system::{Algorithm, System};
use std::io::IsTerminal;
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "shipsim",
    version,
    about = "FMI 2.0 co-simulation master for ship-control systems"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// How `shipsim run --profile` prints the profile.
#[derive(Clone, Copy, clap::ValueEnum)]
enum ProfileFormat {
    /// A table on stderr after the summary.
    Table,
    /// One JSON line on stdout: the summary's figures and the profile.
    Json,
}

#[derive(Subcommand)]
enum Command {
    /// Run a system (native .toml or OSP OspSystemStructure.xml).
    Run {
        /// The system file.
        system: PathBuf,
        /// Override the stop time [s].
        #[arg(long)]
        stop_time: Option<f64>,
        /// Override the base step size [s] (an SSD without an OSP or OMSimulator fixed-step
        /// annotation gives none).
        #[arg(long)]
        step_size: Option<f64>,
        /// CSV output file (overrides the system's output.file).
        #[arg(long, short)]
        output: Option<PathBuf>,
        /// Record nothing and write no CSV, even if the system has an [output] section (to
        /// measure speed without the CSV's cost).
        #[arg(long, conflicts_with = "output")]
        no_output: bool,
        /// Time the step loop per instance (fmi2DoStep, get/set) and the master's own work, on
        /// 1 in 127 macro steps; print a table after the summary (stderr), or with
        /// --profile=json one JSON line of the summary and profile on stdout.
        #[arg(long, value_enum, num_args = 0..=1, require_equals = true, default_missing_value = "table", value_name = "FORMAT")]
        profile: Option<ProfileFormat>,
        /// With --profile: time 1 in N macro steps instead of 1 in 127 (1 = every step, which
        /// catches work done on few steps at about 10 % overhead; else choose a prime).
        #[arg(long, value_name = "N", requires = "profile", value_parser = clap::value_parser!(u64).range(1..))]
        profile_every: Option<u64>,
        /// Set a parameter or start value: --set instance.variable=value (repeatable).
        #[arg(long = "set", value_name = "INST.VAR=VALUE")]
        set: Vec<String>,
        /// Override the algorithm: jacobi or gauss-seidel (any case; gauss_seidel, gaussseidel
        /// and seidel name Gauss-Seidel too, as in system files).
        #[arg(long)]
        algorithm: Option<String>,
        /// Make a unit mismatch on a connection an error in any system file (an OSP
        /// OspSystemStructure.xml only warns, as libcosim runs it; the native TOML always errs).
        #[arg(long)]
        strict_units: bool,
        /// A stop time off the base-step grid: `drop` stops at the last grid point before it
        /// (the default), `short` takes a shorter last step to it (every FMU must declare
        /// canHandleVariableCommunicationStepSize). Overrides the system's `last_step`.
        #[arg(long, value_name = "short|drop", value_parser = ["short", "drop"])]
        last_step: Option<String>,
        /// Show all FMU log messages and switch FMU debug logging on.
        #[arg(long, short)]
        verbose: bool,
        /// No progress bar and no summary.
        #[arg(long, short)]
        quiet: bool,
        /// Write a checkpoint to FILE when the run passes t = T (a base-step point strictly
        /// inside the run) and go on to the end.
        #[arg(long, num_args = 2, value_names = ["T", "FILE"])]
        checkpoint_at: Option<Vec<String>>,
        /// Continue from a checkpoint of this system (same instances, FMU files, connections,
        /// time grid, fixed parameters and events before it; a new value of a tunable
        /// parameter or input, by --set or in the file, applies at the checkpoint's time); the
        /// output has the rows from the checkpoint's time on.
        #[arg(long, value_name = "FILE")]
        resume: Option<PathBuf>,
        #[command(flatten)]
        limits: LimitArgs,
        /// Run FMU instances in their own processes, so that a crash, exit() or hang of an FMU
        /// is an error naming it and every completed step is kept: all of them (--isolate),
        /// those of FMUs not built by this project (--isolate=foreign) or the named ones
        /// (--isolate=NAME,NAME; each an instance of the system). See docs/isolation.md.
        #[arg(long, num_args = 0..=1, require_equals = true, default_missing_value = "all", value_name = "all|foreign|NAMES")]
        isolate: Option<String>,
        /// The longest wall time of one FMI call [s]: an isolated instance's process is then
        /// killed and the run fails naming the call; in process, shipsim exits with a message.
        /// Default: no limit.
        #[arg(long, value_name = "SECONDS")]
        call_timeout: Option<f64>,
        #[command(flatten)]
        realtime: cli::realtime::RealTimeArgs,
    },
    /// Host one isolated FMU instance for a master (internal: started by `run --isolate`).
    #[command(hide = true)]
    FmuHost { fmu: PathBuf },
    /// Validate a system without running it: everything `run` checks before the first step
    /// (names, types, units, declared ranges, connections, events, outputs).
    Check {
        /// The system file (native .toml or OSP OspSystemStructure.xml).
        system: PathBuf,
        /// Set a parameter or start value, as `run --set` does: --set instance.variable=value
        /// (repeatable; a value may carry a unit: 90deg, "15 kn", pi/2).
        #[arg(long = "set", value_name = "INST.VAR=VALUE")]
        set: Vec<String>,
        /// Make a unit mismatch on a connection an error in any system file (an OSP
        /// OspSystemStructure.xml only warns, as libcosim runs it; the native TOML always errs).
        #[arg(long)]
        strict_units: bool,
        #[command(flatten)]
        limits: LimitArgs,
    },
    /// Show an FMU's variables by causality (type, start, unit and display unit, range,
    /// description) and capabilities, or with --doc its documentation.
    Inspect {
        /// The .fmu file.
        fmu: PathBuf,
        /// Print the FMU's documentation/index.html as plain text instead (conventions such as
        /// angle origins and the meaning of gains are documented there).
        #[arg(long)]
        doc: bool,
        /// With --doc: copy the FMU's documentation/ folder (the HTML page and its files) into
        /// DIR instead, to open index.html in a browser.
        #[arg(long, value_name = "DIR", requires = "doc")]
        html: Option<PathBuf>,
        #[command(flatten)]
        limits: LimitArgs,
    },
    /// Statistics of a recorded CSV per column over a time window: mean, variance, std, RMS,
    /// min, max and max |x|.
    Stats(cli::stats::StatsArgs),
    /// Plot recorded columns of one CSV, or of several overlaid, against time (and x-y tracks
    /// with equal axes) into a PNG.
    Plot(PlotArgs),
    /// Loop analysis through the FMUs: margins at a broken connection (--break), frequency
    /// responses (--input, --output) and describing functions (--amplitudes).
    Loop(cli::loop_cmd::LoopArgs),
    /// Replay the journal of a stepping session (Python's `System.start(journal=...)`):
    /// the same rows as the session, bit for bit, as a CSV.
    Replay(cli::replay::ReplayArgs),
    /// Campaigns: many runs over factors, seeds and arms, one KPI row per run.
    Campaign {
        #[command(subcommand)]
        command: cli::campaign::CampaignCommand,
    },
    /// Write an OSP OspSystemStructure.xml for a native system file (runs in libcosim).
    ExportOsp {
        system: PathBuf,
        /// Output file (default: NAME/OspSystemStructure.xml in the current folder, NAME the
        /// system file's name: a folder libcosim's `cosim run NAME` reads).
        #[arg(long, short)]
        output: Option<PathBuf>,
    },
    /// Write an SSP 1.0 archive (.ssp: SystemStructure.ssd, the FMUs, the parameters as .ssv)
    /// for a system; what SSP cannot express (events, summed inputs, ...) is an error.
    ExportSsp {
        system: PathBuf,
        /// Output file (default: NAME.ssp in the current folder, NAME the system file's name).
        #[arg(long, short)]
        output: Option<PathBuf>,
    },
}

/// Limits on unpacking FMU archives ([`Limits`]; their defaults in brackets).
#[derive(clap::Args)]
struct LimitArgs {
    /// Refuse an FMU archive that unpacks to more than SIZE in total: bytes, or with K, M, G
    /// or T (powers of 1024) [default: 1G].
    #[arg(long, value_name = "SIZE", value_parser = parse_size_arg)]
    max_fmu_size: Option<u64>,
    /// Refuse an FMU archive of more than N entries [default: 10000].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    max_fmu_files: Option<u64>,
    /// Refuse an FMU archive with an entry of more than 1 MiB that unpacks to more than R
    /// times its compressed size (a zip bomb) [default: 200].
    #[arg(long, value_name = "R", value_parser = clap::value_parser!(u64).range(1..))]
    max_fmu_ratio: Option<u64>,
}

fn parse_size_arg(s: &str) -> Result<u64, String> {
    shipsim::limits::parse_size(s)
}

impl LimitArgs {
    fn limits(&self) -> Limits {
        let d = Limits::default();
        Limits {
            max_size: self.max_fmu_size.unwrap_or(d.max_size),
            max_files: self.max_fmu_files.unwrap_or(d.max_files),
            max_ratio: self.max_fmu_ratio.unwrap_or(d.max_ratio),
        }
    }
}

/// The process-wide state of the command line (the library has none): the flag the first
/// SIGINT, SIGTERM or SIGHUP sets, and a private temporary directory.
struct Session {
    /// Set by the first signal: a run stops cleanly at its next step, an FMU being unpacked
    /// stops at its next entry. A second signal removes [`Session::tmp`] and exits at once
    /// (status 130): for an FMU that hangs in a call.
    interrupt: Arc<AtomicBool>,
    /// `$TMPDIR/shipsim-*` (mode 0700). `TMPDIR` is pointed into it, so every FMU the process
    /// unpacks (and every temporary file of the process and of its children) lies inside.
    /// Removed when `main` returns, while a panic unwinds out of it, and by the signal
    /// handler before it exits.
    tmp: Option<tempfile::TempDir>,
}

impl Session {
    /// Creates the directory (first, while the process has one thread: `TMPDIR` is set
    /// here) and installs the signal handler.
    fn start() -> Session {
        let tmp = tempfile::Builder::new()
            .prefix("shipsim-")
            .permissions(std::fs::Permissions::from_mode(0o700))
            .tempdir()
            .ok();
        if let Some(t) = &tmp {
            std::env::set_var("TMPDIR", t.path());
        }
        let interrupt = Arc::new(AtomicBool::new(false));
        let (flag, dir) = (
            interrupt.clone(),
            tmp.as_ref().map(|t| t.path().to_path_buf()),
        );
        let _ = ctrlc::set_handler(move || {
            if flag.swap(true, Ordering::SeqCst) {
                if let Some(d) = &dir {
                    remove_tree(d);
                }
                std::process::exit(130);
            }
        });
        Session { interrupt, tmp }
    }

    /// How FMUs are unpacked: into [`Session::tmp`], under `limits`, stopped by a signal.
    fn unpack(&self, limits: &LimitArgs) -> Unpack {
        Unpack {
            limits: limits.limits(),
            parent: self.tmp.as_ref().map(|t| t.path().to_path_buf()),
            interrupt: Some(self.interrupt.clone()),
        }
    }
}

/// Removes a directory tree that another thread may still be writing into (an FMU being
/// unpacked): a few attempts.
fn remove_tree(dir: &Path) {
    for _ in 0..5 {
        if std::fs::remove_dir_all(dir).is_ok() || !dir.exists() {
            return;
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Command::FmuHost { fmu } = &cli.command {
        return ExitCode::from(shipsim::isolate::host::serve(fmu) as u8);
    }
    let session = Session::start();
    let result = dispatch(cli.command, &session);
    let interrupted = session.interrupt.load(Ordering::SeqCst);
    drop(session);
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Error::Interrupted { time }) if time.is_nan() => {
            eprintln!("interrupted; finished runs are kept, run the same command again to resume");
            ExitCode::from(130)
        }
        Err(Error::Interrupted { time }) => {
            eprintln!(
                "interrupted at t = {time} s; instances terminated and freed, output flushed"
            );
            ExitCode::from(130)
        }
        Err(Error::RunsFailed(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(2)
        }
        Err(e) if interrupted => {
            eprintln!("interrupted: {e}");
            ExitCode::from(130)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn dispatch(cmd: Command, session: &Session) -> shipsim::Result<()> {
    match cmd {
        Command::Plot(args) => plot(args),
        Command::Inspect {
            fmu,
            doc,
            html,
            limits,
        } => inspect(&fmu, doc, html.as_deref(), &session.unpack(&limits)),
        Command::Check {
            system,
            set,
            strict_units,
            limits,
        } => check(&system, &set, strict_units, &session.unpack(&limits)),
        Command::Run {
            system,
            stop_time,
            step_size,
            output,
            no_output,
            profile,
            profile_every,
            set,
            algorithm,
            strict_units,
            last_step,
            verbose,
            quiet,
            checkpoint_at,
            resume,
            limits,
            isolate,
            call_timeout,
            realtime,
        } => {
            let checkpoints = Checkpoints {
                at: checkpoint_at.map(parse_checkpoint_at).transpose()?,
                resume,
            };
            let mut sys = System::load(&system)?;
            sys.apply_overrides(&set)?;
            sys.apply_stop_time(stop_time)?;
            sys.apply_step_size(step_size)?;
            if let Some(a) = algorithm {
                sys.algorithm = a
                    .parse::<Algorithm>()
                    .map_err(|e| Error::Other(e.to_string()))?;
            }
            sys.strict_units |= strict_units;
            if let Some(l) = last_step
                .as_deref()
                .and_then(shipsim::system::LastStep::parse)
            {
                sys.last_step = l;
            }
            let flags = RunFlags {
                output,
                no_output,
                profile: profile.map(|f| (f, profile_every)),
                verbose,
                quiet,
                isolation: cli::isolate::isolation(isolate.as_deref(), call_timeout, &sys)?,
            };
            if realtime.wanted(&sys) {
                return run_real_time(sys, &realtime, &flags, &checkpoints, session, &limits);
            }
            run_cli(&sys, &flags, checkpoints, session, &limits)
        }
        Command::ExportOsp { system, output } => export_osp(&system, output),
        Command::ExportSsp { system, output } => export_ssp(&system, output),
        Command::Campaign { command } => {
            cli::campaign::dispatch(command, || session.interrupt.clone())
        }
        Command::Stats(args) => cli::stats::run(&args),
        Command::Loop(args) => cli::loop_cmd::run(&args, session.interrupt.clone()),
        Command::Replay(args) => cli::replay::run(&args, session.interrupt.clone()),
        Command::FmuHost { .. } => Ok(()),
    }
}

/// `shipsim inspect [--doc [--html DIR]]`.
fn inspect(fmu: &Path, doc: bool, html: Option<&Path>, unpack: &Unpack) -> shipsim::Result<()> {
    match (doc, html) {
        (false, _) => print!("{}", shipsim::inspect::inspect(fmu, unpack)?),
        (true, None) => print!("{}", shipsim::inspect::doc_text(fmu, unpack)?),
        (true, Some(dir)) => {
            let files = shipsim::inspect::extract_doc(fmu, dir, unpack)?;
            let index = dir.join("index.html");
            match index.is_file() {
                true => println!("wrote {} files; open {}", files.len(), index.display()),
                false => println!("wrote {} files into {}", files.len(), dir.display()),
            }
        }
    }
    Ok(())
}

/// The arguments of `shipsim plot`.
#[derive(clap::Args)]
struct PlotArgs {
    /// The CSV files written by `shipsim run`; several are overlaid, each column once per
    /// file (see --label).
    #[arg(required = true, num_args = 1..)]
    csv: Vec<PathBuf>,
    /// A time panel: "Y LABEL=COL[*F],COL[*F],..." (repeatable; panels stack vertically).
    /// COL*F multiplies that column by F, e.g. "roll [deg]=ship.roll*57.29578".
    #[arg(long = "panel", value_name = "LABEL=COL[*F][,COL...]")]
    panels: Vec<String>,
    /// An x-y panel with equal scales on both axes, e.g. a track: "ship.y,ship.x" draws
    /// north (x) up over east (y) (repeatable; below the time panels).
    #[arg(long = "xy", value_name = "XCOL[*F],YCOL[*F]")]
    xy: Vec<String>,
    /// Factor applied to every column that has no *F of its own.
    #[arg(long, default_value_t = 1.0)]
    scale: f64,
    /// Names of the CSV files in the legends, in order (default: the file names).
    #[arg(long, value_delimiter = ',', value_name = "NAME,NAME...")]
    label: Vec<String>,
    /// Only the rows with T0 <= t <= T1 [s]; either may be left out ("200:", ":600").
    #[arg(long, value_name = "T0:T1", allow_hyphen_values = true)]
    window: Option<String>,
    /// Figure title (default: the CSV file, or the files' labels joined by "vs").
    #[arg(long)]
    title: Option<String>,
    /// PNG output file.
    #[arg(long, short)]
    output: PathBuf,
}

/// `shipsim plot`: one time panel per --panel and one x-y panel per --xy, each series once per
/// CSV file.
fn plot(a: PlotArgs) -> shipsim::Result<()> {
    use shipsim::plot::{parse_window, plot_figure, Request};
    use shipsim::results::ResultsTable;
    let (csvs, output) = (a.csv.as_slice(), a.output.as_path());
    if a.panels.is_empty() && a.xy.is_empty() {
        return Err(Error::Other("nothing to plot: give --panel or --xy".into()));
    }
    if !a.label.is_empty() && a.label.len() != csvs.len() {
        return Err(Error::Other(format!(
            "--label has {} names for {} CSV files",
            a.label.len(),
            csvs.len()
        )));
    }
    let mut files = Vec::new();
    for (i, csv) in csvs.iter().enumerate() {
        let name = match a.label.get(i) {
            Some(l) => l.clone(),
            None => csv
                .file_name()
                .unwrap_or(csv.as_os_str())
                .to_string_lossy()
                .into_owned(),
        };
        files.push((name, ResultsTable::read(csv)?));
    }
    let request = Request {
        files: &files,
        panels: &a.panels,
        tracks: &a.xy,
        scale: a.scale,
        window: a.window.as_deref().map(parse_window).transpose()?,
    };
    let (panels, tracks) = request.figure()?;
    let title = a.title.unwrap_or_else(|| {
        let names: Vec<&str> = files.iter().map(|(name, _)| name.as_str()).collect();
        match csvs {
            [one] => one.display().to_string(),
            _ => names.join(" vs "),
        }
    });
    plot_figure(output, &title, &panels, &tracks)?;
    println!("wrote {}", output.display());
    Ok(())
}

fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}

/// `shipsim check`: the system validated against the FMUs' model descriptions (binaries are
/// not loaded).
fn check(
    system: &Path,
    set: &[String],
    strict_units: bool,
    unpack: &Unpack,
) -> shipsim::Result<()> {
    let mut sys = System::load(system)?;
    sys.apply_overrides(set)?;
    sys.strict_units |= strict_units;
    let mut unpacked = Vec::new();
    for inst in &sys.instances {
        sys.require_fmu(inst)?;
        let u = UnpackedFmu::open_with(&inst.fmu, unpack)?;
        u.binary_path()?;
        unpacked.push(u);
    }
    let mds: Vec<_> = unpacked.iter().map(|u| &u.model_description).collect();
    let plan = sys.validate(&mds)?;
    print_warnings(&plan.warnings);
    println!(
        "{}: OK ({} instances, {} connections, {} events, {} recorded variables, {} steps of {} s, {:?})",
        system.display(),
        plan.instances.len(),
        plan.connections.len(),
        plan.events.len(),
        plan.outputs.len(),
        plan.n_steps,
        plan.step_size,
        plan.algorithm
    );
    Ok(())
}

/// `shipsim run --checkpoint-at T FILE` and `--resume FILE`.
struct Checkpoints {
    at: Option<(f64, PathBuf)>,
    resume: Option<PathBuf>,
}

/// `--checkpoint-at T FILE` (clap gives exactly two values).
fn parse_checkpoint_at(v: Vec<String>) -> shipsim::Result<(f64, PathBuf)> {
    let [t, file] = <[String; 2]>::try_from(v)
        .map_err(|_| Error::Other("--checkpoint-at: expected T FILE".into()))?;
    let time = t.trim().parse::<f64>().ok().filter(|x| x.is_finite());
    let time = time.ok_or_else(|| {
        Error::Other(format!(
            "--checkpoint-at {t} {file}: T must be a time in seconds"
        ))
    })?;
    Ok((time, PathBuf::from(file)))
}

/// The flags of `shipsim run` that shape the run and what it prints.
struct RunFlags {
    output: Option<PathBuf>,
    no_output: bool,
    /// The format, and 1 in how many macro steps to time (default [`Sampling::default`]).
    profile: Option<(ProfileFormat, Option<u64>)>,
    verbose: bool,
    quiet: bool,
    isolation: shipsim::isolate::Isolation,
}

/// `shipsim run`: Ctrl-C stops the run cleanly (a second one exits at once); warnings, then
/// the run, then its summary on stderr (and the profile, if asked for: a table on stderr or
/// JSON on stdout).
fn run_cli(
    sys: &System,
    flags: &RunFlags,
    checkpoints: Checkpoints,
    session: &Session,
    limits: &LimitArgs,
) -> shipsim::Result<()> {
    let begin = Instant::now();
    let (verbose, quiet) = (flags.verbose, flags.quiet);
    let out_file = match flags.no_output {
        true => None,
        false => flags.output.clone().or_else(|| sys.output.file.clone()),
    };
    let out = match &out_file {
        Some(p) => Output::File(p.clone()),
        None => Output::None,
    };
    for (what, file) in [
        ("output file", out_file.as_deref()),
        (
            "checkpoint file",
            checkpoints.at.as_ref().map(|(_, f)| f.as_path()),
        ),
    ] {
        if let Some(f) = file {
            refuse_input(sys, what, f)?;
        }
    }
    let mut opts = RunOptions {
        verbose,
        progress: !quiet && std::io::stderr().is_terminal(),
        interrupt: Some(session.interrupt.clone()),
        log_sink: None,
        checkpoint: None,
        profile: flags.profile.map(|(_, every)| match every {
            Some(every) => Sampling { every },
            None => Sampling::default(),
        }),
        isolation: flags.isolation.clone(),
        // An FMU in process that calls exit() or hangs is named (cli/isolate.rs).
        monitor: Some(cli::isolate::guard(flags.isolation.call_timeout)),
    };
    let (mut plan, fmus) = prepare_with(sys, &session.unpack(limits), &flags.isolation)?;
    print_warnings(&plan.warnings);
    if !quiet {
        sys.notes.iter().for_each(|n| eprintln!("note: {n}"));
    }
    if !quiet && !flags.no_output {
        output_note(sys, out_file.as_deref());
    }
    if let Some((t, file)) = &checkpoints.at {
        let step = checkpoint_step(&plan, *t)
            .map_err(|e| Error::Other(format!("--checkpoint-at: {e}")))?;
        opts.checkpoint = Some(CheckpointRequest {
            step,
            file: file.clone(),
        });
    }
    let mut summary = match &checkpoints.resume {
        None => run(&plan, &fmus, out, &opts)?,
        Some(file) => {
            let cp = Checkpoint::read(file)?;
            for note in cp.adopt(&mut plan, &fmus) {
                eprintln!("note: {note}");
            }
            cp.check_plan(&plan, &fmus).map_err(|e| Error::Checkpoint {
                file: file.clone(),
                message: e.to_string(),
            })?;
            resume(&plan, &fmus, &cp, out, &opts)?
        }
    };
    summary.total_wall_time = begin.elapsed();
    if !quiet {
        if let Some((t, file)) = &checkpoints.at {
            eprintln!("checkpoint at t = {t} s written to {}", file.display());
        }
        eprintln!("{summary}");
    }
    match (flags.profile, &summary.profile) {
        (Some((ProfileFormat::Table, _)), Some(p)) => eprintln!("{p}"),
        (Some((ProfileFormat::Json, _)), Some(p)) => println!("{}", run_json(sys, &summary, p)),
        _ => {}
    }
    Ok(())
}

/// `shipsim run` paced or with `[[io]]` ([`cli::realtime`]): the flags it cannot take are
/// refused.
fn run_real_time(
    sys: System,
    args: &cli::realtime::RealTimeArgs,
    flags: &RunFlags,
    checkpoints: &Checkpoints,
    session: &Session,
    limits: &LimitArgs,
) -> shipsim::Result<()> {
    if flags.profile.is_some() || checkpoints.at.is_some() || checkpoints.resume.is_some() {
        return Err(Error::Other(
            "a paced or I/O run takes neither --profile, --checkpoint-at nor --resume (use --checkpoint-every T)".into(),
        ));
    }
    let output = match flags.no_output {
        true => None,
        false => flags.output.clone().or_else(|| sys.output.file.clone()),
    };
    if let Some(f) = &output {
        refuse_input(&sys, "output file", f)?;
    }
    if !flags.quiet {
        sys.notes.iter().for_each(|n| eprintln!("note: {n}"));
    }
    let cx = cli::realtime::Context {
        output,
        run: RunOptions {
            verbose: flags.verbose,
            interrupt: Some(session.interrupt.clone()),
            isolation: flags.isolation.clone(),
            monitor: Some(cli::isolate::guard(flags.isolation.call_timeout)),
            ..Default::default()
        },
        unpack: session.unpack(limits),
        quiet: flags.quiet,
    };
    cli::realtime::run(sys, args, cx)
}

/// A file the run writes (`what`: "output file") must not be one it reads: the system file or
/// an instance's FMU (the same file, also through another path or a hard link).
fn refuse_input(sys: &System, what: &str, file: &Path) -> shipsim::Result<()> {
    let Ok(target) = std::fs::metadata(file) else {
        return Ok(());
    };
    let same = |p: &Path| {
        std::fs::metadata(p).is_ok_and(|m| m.dev() == target.dev() && m.ino() == target.ino())
    };
    let input = match sys.instances.iter().find(|i| same(&i.fmu)) {
        _ if same(&sys.source) => format!("the system file {}", sys.source.display()),
        Some(i) => format!("the FMU {} of instance '{}'", i.fmu.display(), i.name),
        None => return Ok(()),
    };
    Err(Error::Other(format!(
        "the {what} {} is {input}; refusing to overwrite it (choose another file)",
        file.display()
    )))
}

/// One line on stderr about the output before a run: that nothing will be written and how to
/// ask for a file, or that an existing file is about to be replaced (the system files of the
/// repository all write into target/demo/, so consecutive runs replace each other's CSVs).
fn output_note(sys: &System, file: Option<&Path>) {
    match file {
        Some(f) if f.exists() => eprintln!("overwriting {}", f.display()),
        Some(_) => {}
        None => {
            let how = match sys.format == shipsim::system::Format::Osp {
                true => "pass -o FILE.csv",
                false => "pass -o FILE.csv or add [output] file = \"FILE.csv\" to the system file",
            };
            eprintln!("no output requested, nothing will be written: {how}");
        }
    }
}

/// `--profile=json`: the summary's figures and the profile, one line.
fn run_json(
    sys: &System,
    s: &shipsim::run::Summary,
    p: &shipsim::run::Profile,
) -> serde_json::Value {
    serde_json::json!({
        "system": sys.source.display().to_string(),
        "start_time": s.start_time,
        "end_time": s.end_time,
        "macro_steps": s.macro_steps,
        "fmu_steps": s.fmu_steps,
        "wall_s": s.wall_time.as_secs_f64(),
        "total_wall_s": s.total_wall_time.as_secs_f64(),
        "real_time_factor": s.real_time_factor(),
        "us_per_macro_step": s.wall_time.as_secs_f64() * 1e6 / s.macro_steps.max(1) as f64,
        "rows": s.rows,
        "terminated_by": s.terminated_by,
        "profile": p.to_json(),
    })
}

/// `shipsim export-osp`: OspSystemStructure.xml (and scenario.json for events).
fn export_osp(system: &Path, output: Option<PathBuf>) -> shipsim::Result<()> {
    let sys = System::load(system)?;
    let out = output.unwrap_or_else(|| export_name(system, "").join("OspSystemStructure.xml"));
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io(format!("cannot create folder {}", dir.display()), e))?;
    }
    let warnings = shipsim::format::osp::write(&sys, &out)?;
    print_warnings(&warnings);
    eprintln!("wrote {}", out.display());
    Ok(())
}

/// The default name of an export of `system`: its file name without the extension, plus
/// `extension`, in the current folder (never beside the system file, which may be in the
/// source tree; issue 36, item 6).
fn export_name(system: &Path, extension: &str) -> PathBuf {
    let stem = system.file_stem().map(|s| s.to_string_lossy().into_owned());
    PathBuf::from(format!(
        "{}{extension}",
        stem.unwrap_or_else(|| "system".into())
    ))
}

/// `shipsim export-ssp`: an SSP 1.0 archive (SystemStructure.ssd, the FMUs, the parameters).
fn export_ssp(system: &Path, output: Option<PathBuf>) -> shipsim::Result<()> {
    let sys = System::load(system)?;
    let out = output.unwrap_or_else(|| export_name(system, ".ssp"));
    let warnings = shipsim::format::ssp::write::write(&sys, &out)?;
    print_warnings(&warnings);
    eprintln!("wrote {}", out.display());
    Ok(())
}
