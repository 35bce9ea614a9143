//! `shipsim replay JOURNAL [-o FILE.csv]`: replays the journal of a stepping session (Python's
//! `System.start(journal=...)`, [`shipsim::run::Session::replay`]) and writes its rows as
//! `shipsim run` writes a CSV, bit for bit the session's. With `--from CHECKPOINT` (a paced
//! run's `--checkpoint-every`) it replays from that checkpoint's time on
//! ([`shipsim::run::Session::replay_from`]): the rows are the full replay's tail, bit for bit.

use clap::Args;
use shipsim::error::{Error, Result};
use shipsim::model_description::VarType;
use shipsim::run::{write_real, MemoryRecorder, RunOptions, Session};
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

#[derive(Args)]
pub struct ReplayArgs {
    /// The session's journal (JSON Lines).
    pub journal: PathBuf,
    /// The CSV to write (default: the journal's name with .csv, beside it).
    #[arg(long, short)]
    pub output: Option<PathBuf>,
    /// Replay from this checkpoint of the session (written by `shipsim run --checkpoint-every`):
    /// the rows from its time on.
    #[arg(long, value_name = "CHECKPOINT")]
    pub from: Option<PathBuf>,
}

pub fn run(args: &ReplayArgs, interrupt: Arc<AtomicBool>) -> Result<()> {
    let opts = RunOptions {
        interrupt: Some(interrupt),
        ..Default::default()
    };
    let mut session = match &args.from {
        None => Session::replay(&args.journal, opts)?,
        Some(cp) => Session::replay_from(&args.journal, cp, opts)?,
    };
    for w in session.warnings() {
        eprintln!("warning: {w}");
    }
    let out = args
        .output
        .clone()
        .unwrap_or_else(|| args.journal.with_extension("csv"));
    let path = shipsim::output_path::writable(&out)?;
    let io = |e| Error::io(format!("cannot write {}", path.display()), e);
    let mut w = std::io::BufWriter::new(std::fs::File::create(&path).map_err(io)?);
    write_rows(&mut w, session.rows()).map_err(io)?;
    w.flush().map_err(io)?;
    let from = match session.rows().time.first() {
        Some(t) if args.from.is_some() => format!(" from t = {t} s"),
        _ => String::new(),
    };
    eprintln!(
        "replayed {}{from} to t = {} s: {} rows written to {}",
        args.journal.display(),
        session.time(),
        session.rows().time.len(),
        path.display()
    );
    session.close()
}

/// The rows as `shipsim run` writes them: the header, then `time` and each column by its type.
fn write_rows(w: &mut impl Write, m: &MemoryRecorder) -> std::io::Result<()> {
    let mut header = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    let names = std::iter::once("time").chain(m.columns.iter().map(|c| c.name.as_str()));
    header.write_record(names).map_err(std::io::Error::other)?;
    w.write_all(
        &header
            .into_inner()
            .map_err(|e| std::io::Error::other(e.to_string()))?,
    )?;
    for (i, t) in m.time.iter().enumerate() {
        write_real(w, *t)?;
        for (c, col) in m.columns.iter().zip(&m.data) {
            let x = col[i];
            match c.var_type {
                VarType::Real => w.write_all(b",").and_then(|()| write_real(w, x))?,
                _ => write!(w, ",{}", x as i64)?,
            }
        }
        w.write_all(b"\n")?;
    }
    Ok(())
}
