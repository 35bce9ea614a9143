//! `shipsim run SYSTEM --real-time` (`--real-time-factor X`), and any run of a system with
//! `[[io]]` channels: a stepping session paced to the wall clock and on the wire
//! ([`shipsim::realtime`]), its rows streamed to the CSV, every input it applied journaled
//! (`--journal FILE`, by default beside the output) so that `shipsim replay` gives the same CSV
//! bit for bit.

use clap::Args;
use shipsim::error::{Error, Result};
use shipsim::realtime::{self, PacedRun, RealTimeOptions};
use shipsim::run::{CsvRecorder, Journaling, OpenOnWrite, Recorder, RunOptions};
use shipsim::system::System;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Args, Default)]
pub struct RealTimeArgs {
    /// Pace the run to the wall clock: each macro step waits for its deadline (start +
    /// k*h); a late step is counted, never skipped. The summary gives the lateness.
    #[arg(long)]
    pub real_time: bool,
    /// Pace at X times real time (2: twice as fast; 0.5: half).
    #[arg(long, value_name = "X")]
    pub real_time_factor: Option<f64>,
    /// The journal of a paced or I/O run (every input applied; `shipsim replay FILE`
    /// replays it). Default: the output file with .jsonl.
    #[arg(long, value_name = "FILE")]
    pub journal: Option<PathBuf>,
    /// With a paced or I/O run: a checkpoint every T s of simulated time, written beside the
    /// journal as NAME-t.ckpt (`shipsim replay JOURNAL --from NAME-t.ckpt` replays from it).
    #[arg(long, value_name = "T")]
    pub checkpoint_every: Option<f64>,
    /// Ignore the system file's [[io]] channels.
    #[arg(long)]
    pub no_io: bool,
}

impl RealTimeArgs {
    /// Whether the run goes this way: paced, or with [[io]] channels.
    pub fn wanted(&self, sys: &System) -> bool {
        self.real_time || self.real_time_factor.is_some() || (!self.no_io && !sys.io.is_empty())
    }

    fn factor(&self) -> Result<Option<f64>> {
        match (self.real_time, self.real_time_factor) {
            (_, Some(x)) if !(x > 0.0 && x.is_finite()) => Err(Error::Other(format!(
                "--real-time-factor {x}: a positive number"
            ))),
            (_, Some(x)) => Ok(Some(x)),
            (true, None) => Ok(Some(1.0)),
            (false, None) => Ok(None),
        }
    }
}

/// What else the run command says.
pub struct Context {
    pub output: Option<PathBuf>,
    pub run: RunOptions,
    pub unpack: shipsim::fmu::Unpack,
    pub quiet: bool,
}

/// Runs `sys` in real time (see the module documentation).
pub fn run(sys: System, args: &RealTimeArgs, cx: Context) -> Result<()> {
    let factor = args.factor()?;
    let fmus = shipsim::run::load_fmus_with(&sys, &cx.unpack, &cx.run.isolation)?;
    let journal = args
        .journal
        .clone()
        .or_else(|| cx.output.as_ref().map(|o| o.with_extension("jsonl")));
    let io = match args.no_io {
        true => Vec::new(),
        false => sys.io.clone(),
    };
    if let Some(j) = &journal {
        if let Some(dir) = j.parent().filter(|d| !d.as_os_str().is_empty()) {
            let _ = std::fs::create_dir_all(dir);
        }
    }
    let rows: Option<Box<dyn Recorder + Send>> = match &cx.output {
        Some(out) => Some(Box::new(CsvRecorder::new(csv_file(out)?))),
        None => None,
    };
    let rt = RealTimeOptions {
        factor,
        interrupt: cx.run.interrupt.clone(),
        checkpoint_every: args.checkpoint_every.map(|t| {
            let base = journal
                .clone()
                .or(cx.output.clone())
                .unwrap_or_else(|| "session".into());
            (t, base)
        }),
        log: Arc::new(|m: &str| eprintln!("{m}")),
        ..RealTimeOptions::default()
    };
    let paced = PacedRun {
        run: cx.run.clone(),
        journal: journal.clone().map_or(Journaling::Off, Journaling::File),
        io,
        rows,
        realtime: rt,
    };
    let (_, report) = realtime::run_system(sys, fmus, paced)?;
    if !cx.quiet {
        eprintln!("{report}");
        if let Some(o) = &cx.output {
            eprintln!("rows written to {}", o.display());
        }
        if let Some(j) = &journal {
            eprintln!(
                "journal written to {} (shipsim replay {} gives the same CSV)",
                j.display(),
                j.display()
            );
        }
        for c in &report.checkpoints {
            eprintln!("checkpoint written to {}", c.display());
        }
    }
    Ok(())
}

/// The CSV output, its folder created, buffered, the file created on the first row: a run
/// that fails before its instances are initialized leaves the last run's file as it was (as
/// `shipsim run` does, issue 36).
fn csv_file(out: &std::path::Path) -> Result<OpenOnWrite> {
    let p = shipsim::output_path::writable(out)?;
    if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io(format!("cannot create output folder {}", dir.display()), e))?;
    }
    Ok(OpenOnWrite::new(p))
}
