//! A campaign whose runs execute in other processes: the Python package's distributed mode,
//! where Dask workers run chunks of runs and the client records them.
//!
//! The split keeps one writer per output folder, as on one machine:
//!
//! - the client opens the output folder with a [`Collector`] (provenance checked or written,
//!   journal open and locked), asks it for the runs still to do in chunks
//!   ([`Collector::chunks`]; a warm-up group of a forked campaign is never split), hands the
//!   chunks out, records each result as it arrives ([`Collector::record`]: journal append,
//!   synced; a result that arrives twice is recorded once) and writes the tables at the end
//!   ([`Collector::finish`]);
//! - a worker process holds a [`Worker`]: the campaign and its FMUs, loaded once per process,
//!   and runs chunks into records ([`Worker::run`]), with the series files, if the campaign
//!   asks for any, handed back as bytes.
//!
//! So a worker lost mid-chunk costs only that chunk, which the engine runs again elsewhere,
//! and resume works as on one machine: the journal says which runs are done. The worker checks
//! that it sees the same campaign as the client (the run keys hash the base system file and
//! every FMU file), so a worker with other files on its shared path fails loudly.

use super::execute::{self, CampaignOptions};
use super::journal::{Journal, RunRecord};
use super::table::Table;
use super::{output, Campaign, Run};
use crate::error::{Error, Result};
use crate::fmu::{Fmu, UnpackedFmu};
use crate::model_description::ModelDescription;
use crate::run;
use rayon::prelude::*;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The client's side: the output folder, opened by the one process that records.
pub struct Collector {
    dir: PathBuf,
    journal: Journal,
    retry_failed: bool,
    /// Keys recorded by this collector (a result that arrives twice is recorded once).
    recorded: HashSet<String>,
}

impl Collector {
    /// Opens (or creates) the output folder of `campaign`: checks or writes the provenance
    /// and opens the journal, which stays locked while the collector lives.
    pub fn open(campaign: &Campaign, dir: &Path, retry_failed: bool) -> Result<Collector> {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io(format!("cannot create output folder {}", dir.display()), e))?;
        // the folder's lock (the journal's) before anything is written into it
        let journal = Journal::open(dir, output::kpi_columns(&campaign.spec).len())?;
        output::check_or_write_provenance(campaign, dir, None)?;
        Ok(Collector {
            dir: dir.to_path_buf(),
            journal,
            retry_failed,
            recorded: HashSet::new(),
        })
    }

    /// How many runs are not done yet.
    pub fn pending(&self, campaign: &Campaign) -> usize {
        self.todo(campaign).len()
    }

    /// The runs not done yet, by index (every run's key is computed, in parallel).
    fn todo(&self, campaign: &Campaign) -> Vec<usize> {
        (0..campaign.runs.len())
            .into_par_iter()
            .filter(|&i| self.to_do(&campaign.runs.run(i)))
            .collect()
    }

    /// Not in the journal (or failed there, with `retry_failed`), and not recorded since.
    fn to_do(&self, run: &Run) -> bool {
        execute::to_do(&self.journal, run, self.retry_failed) && !self.recorded.contains(&run.key)
    }

    /// The runs not done yet, as chunks of about `per_chunk` runs in index order. The runs of
    /// a warm-up group (`fork_at`) stay in one chunk, so that each warm-up runs once.
    pub fn chunks(&self, campaign: &Campaign, per_chunk: usize) -> Result<Vec<Vec<usize>>> {
        let todo = self.todo(campaign);
        // Grouping needs the model descriptions only when the campaign forks (which variables
        // are tunable); they are read without loading the binaries.
        let unpacked = match campaign.spec.fork_at {
            Some(_) => campaign
                .system
                .instances
                .iter()
                .map(|i| UnpackedFmu::open(&i.fmu))
                .collect::<Result<Vec<_>>>()?,
            None => Vec::new(),
        };
        let mds: Vec<&ModelDescription> = unpacked.iter().map(|u| &u.model_description).collect();
        let units = execute::work_units(campaign, &mds, &todo)?;
        let mut chunks: Vec<Vec<usize>> = Vec::new();
        for unit in units {
            match chunks.last_mut() {
                Some(c) if c.len() + unit.len() <= per_chunk.max(1) => c.extend(unit),
                _ => chunks.push(unit),
            }
        }
        Ok(chunks)
    }

    /// Records a finished run from a worker (and its series file, if it has one): appended to
    /// the journal and synced. Returns false, recording nothing, for a run already recorded
    /// by this collector (a chunk that ran twice). A record whose key is not the run's key in
    /// this campaign is refused: the worker saw other files.
    pub fn record(
        &mut self,
        campaign: &Campaign,
        record: RunRecord,
        series: Option<&[u8]>,
    ) -> Result<bool> {
        let expected = campaign.runs.get(record.index).map(|r| r.key);
        if expected.as_deref() != Some(record.key.as_str()) {
            return Err(Error::Other(format!(
                "campaign {}: a worker returned run {} with key {}, but this campaign's run {} \
                 has key {}: the worker reads a different campaign, base system or FMU (the \
                 files must be the same on every worker)",
                campaign.spec.source.display(),
                record.index,
                record.key,
                record.index,
                expected.as_deref().unwrap_or("(none)")
            )));
        }
        if !self.recorded.insert(record.key.clone()) {
            return Ok(false);
        }
        if let Some(bytes) = series {
            let dir = self.dir.join("series");
            std::fs::create_dir_all(&dir)
                .map_err(|e| Error::io(format!("cannot create {}", dir.display()), e))?;
            output::write_atomic(&dir.join(output::series_name(record.index)), bytes)?;
        }
        self.journal.append(record)?;
        Ok(true)
    }

    /// Writes the run table and the derived table from the journal; returns the files and
    /// the run table.
    pub fn finish(&self, campaign: &Campaign) -> Result<(Vec<PathBuf>, Table)> {
        let files = output::write_tables(
            &campaign.spec,
            &campaign.runs,
            &self.journal,
            &self.dir,
            output::Stop(None),
        )?;
        Ok((files, run_table(campaign, &self.journal)))
    }
}

/// The run table of the runs in `journal`: what `runs.parquet` holds.
pub fn run_table(campaign: &Campaign, journal: &Journal) -> Table {
    let done = output::finished(&campaign.runs, journal);
    output::run_table(&campaign.spec, &campaign.runs, &done)
}

/// The run table of a campaign's output folder (from its journal).
pub fn read_run_table(campaign: &Campaign, dir: &Path) -> Result<Table> {
    let kpis = output::kpi_columns(&campaign.spec).len();
    Ok(run_table(campaign, &Journal::open(dir, kpis)?))
}

/// The derived table of a campaign's output folder (from its journal): what `derived.parquet`
/// holds, None when the campaign has no `[[derived]]` KPIs.
pub fn read_derived_table(campaign: &Campaign, dir: &Path) -> Result<Option<Table>> {
    let kpis = output::kpi_columns(&campaign.spec).len();
    let journal = Journal::open(dir, kpis)?;
    let done = output::finished(&campaign.runs, &journal);
    output::derived_table(&campaign.spec, &campaign.runs, &done)
}

/// A worker's side: the campaign and its FMUs, each loaded once for the life of the worker.
pub struct Worker {
    pub campaign: Campaign,
    fmus: Vec<Arc<Fmu>>,
}

/// A finished run from a worker, with its series file's bytes if the campaign records one.
pub type Finished = (RunRecord, Option<Vec<u8>>);

impl Worker {
    /// Loads the campaign's FMUs.
    pub fn new(campaign: Campaign) -> Result<Worker> {
        let fmus = run::load_fmus(&campaign.system)?;
        Ok(Worker { campaign, fmus })
    }

    /// Runs the given runs (by index) and returns their records, in completion order. A run
    /// that fails is a record with its status, as on one machine; an interrupt
    /// (`opts.interrupt`) ends the chunk with [`Error::Interrupted`].
    pub fn run(&self, indices: &[usize], opts: &CampaignOptions) -> Result<Vec<Finished>> {
        let series = tempfile::Builder::new()
            .prefix("shipsim-series-")
            .tempdir()
            .map_err(|e| Error::io("cannot create a folder for the series files", e))?;
        let records = execute::run_collect(
            &self.campaign,
            &self.fmus,
            indices,
            opts,
            series.path().into(),
        )?;
        records
            .into_iter()
            .map(|r| {
                let path = series.path().join(output::series_name(r.index));
                let bytes = match path.exists() {
                    true => Some(
                        std::fs::read(&path)
                            .map_err(|e| Error::io(format!("cannot read {}", path.display()), e))?,
                    ),
                    false => None,
                };
                Ok((r, bytes))
            })
            .collect()
    }
}
