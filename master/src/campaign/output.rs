//! The files of a campaign's output folder:
//!
//! - `campaign.json`: provenance: the campaign file (path and text), the base system's path
//!   and the hash of it and its FMUs, the tool version, the run count, the shard;
//! - `runs.jsonl`: the journal of finished runs ([`super::journal`]);
//! - `runs.csv`, `runs.parquet`: the run table, one row per finished run in index order:
//!   `run, point, replication, [arm,]` the factors, the derived seeds (named by their
//!   parameter), the KPIs, `status, message, wall_time, key`;
//! - `derived.csv`, `derived.parquet` (with derived KPIs): one row per design point and
//!   replication: `point, replication,` the factors and seeds, the derived KPIs, `status`;
//! - `series/run-NNNNNN.csv`: the decimated series of the runs the file asked for.

use super::derived::DerivedKpi;
use super::journal::{Journal, RunRecord};
use super::table::{ColumnData, Table};
use super::{Campaign, CampaignSpec, Design};
use crate::error::{Error, Result};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The file name of run `index`'s series in `series/`.
pub(super) fn series_name(index: usize) -> String {
    format!("run-{index:06}.csv")
}

/// The provenance sidecar.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Provenance {
    pub tool: String,
    pub version: String,
    pub campaign_file: PathBuf,
    pub campaign_text: String,
    pub system_file: PathBuf,
    /// SHA-256 over the base system file and its FMU files.
    pub base_hash: String,
    /// SHA-256 of the campaign text.
    pub campaign_hash: String,
    /// SHA-256 of the KPI definitions: a journal is only continued by the same KPIs.
    pub kpi_hash: String,
    pub runs: usize,
    pub shard: Option<(usize, usize)>,
}

impl Provenance {
    pub fn of(campaign: &Campaign, shard: Option<(usize, usize)>) -> Provenance {
        use sha2::{Digest, Sha256};
        Provenance {
            tool: "shipsim".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            campaign_file: campaign.spec.source.clone(),
            campaign_text: campaign.spec.text.clone(),
            system_file: campaign.spec.system.clone(),
            base_hash: campaign.base_hash.clone(),
            campaign_hash: super::design::hex(&Sha256::digest(campaign.spec.text.as_bytes())),
            kpi_hash: super::design::hex(&Sha256::digest(
                format!("{:?}", campaign.spec.kpis).as_bytes(),
            )),
            runs: campaign.runs.len(),
            shard,
        }
    }

    pub fn read(dir: &Path) -> Result<Provenance> {
        let path = dir.join("campaign.json");
        let text = crate::limits::read_text(
            &path,
            crate::limits::MAX_SYSTEM_FILE,
            "campaign provenance file",
        )?;
        serde_json::from_str(&text).map_err(|e| {
            Error::system(
                &path,
                Some(e.line()),
                format!("not a campaign sidecar: {e}"),
            )
        })
    }
}

/// Writes `campaign.json`, after checking that the journal beside it (if any) may be
/// continued: same base system and FMUs, same KPIs, same shard. A campaign file that changed
/// otherwise (more factors, points or replications) continues it: finished runs are found by
/// their keys.
pub fn check_or_write_provenance(
    campaign: &Campaign,
    dir: &Path,
    shard: Option<(usize, usize)>,
) -> Result<()> {
    let now = Provenance::of(campaign, shard);
    let path = dir.join("campaign.json");
    if path.exists() {
        let before = Provenance::read(dir)?;
        let what = if before.kpi_hash != now.kpi_hash {
            Some("the KPI definitions changed")
        } else if before.base_hash != now.base_hash {
            Some("the base system or one of its FMUs changed")
        } else if before.shard != now.shard {
            Some("it was run with another --shard")
        } else {
            None
        };
        if let Some(what) = what {
            return Err(Error::Other(format!(
                "{} holds the results of another campaign ({what} since {} was written); \
                 use another output folder (-o) or remove it",
                dir.display(),
                path.display()
            )));
        }
        if before == now {
            return Ok(());
        }
    }
    let text = serde_json::to_string_pretty(&now).expect("serializable");
    write_atomic(&path, text.as_bytes())
}

/// Writes `bytes` to `path` atomically ([`super::table::write_atomic`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    super::table::write_atomic(path, |mut file| {
        use std::io::Write;
        file.write_all(bytes)
            .map_err(|e| Error::io(format!("writing {}", path.display()), e))?;
        Ok(file)
    })
}

/// The KPI column names of the campaign, in row order.
pub fn kpi_columns(spec: &CampaignSpec) -> Vec<String> {
    spec.kpis.iter().flat_map(|k| k.columns()).collect()
}

/// The finished runs of the campaign in index order, by index (records of other campaigns'
/// keys are left out). Every run's key is computed (in parallel); none is kept.
///
/// Runs are matched by key, not by index: a campaign extended with more points or
/// replications keeps its finished runs (their keys do not change), under new indices.
pub fn finished<'a>(runs: &Design, journal: &'a Journal) -> Vec<(usize, &'a RunRecord)> {
    finished_until(runs, journal, Stop(None)).expect("never stopped")
}

/// [`finished`], given up when `stop` is set.
fn finished_until<'a>(
    runs: &Design,
    journal: &'a Journal,
    stop: Stop,
) -> Result<Vec<(usize, &'a RunRecord)>> {
    if journal.records().next().is_none() {
        return Ok(Vec::new());
    }
    let found = (0..runs.len()).into_par_iter().map(|i| {
        stop.check()?;
        Ok(journal.done(&runs.run(i).key).map(|r| (i, r)))
    });
    Ok(found
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect())
}

/// The interrupt flag of the table phase (the first SIGINT or SIGTERM): checked between
/// tables and inside the long loops, so that the phase after the runs stops as promptly as a
/// run does (issue 38, item 11). The journal has every finished run; the next `campaign run`
/// writes the tables.
#[derive(Clone, Copy)]
pub struct Stop<'a>(pub Option<&'a std::sync::atomic::AtomicBool>);

impl Stop<'_> {
    fn check(self) -> Result<()> {
        match self.0 {
            Some(f) if f.load(std::sync::atomic::Ordering::Relaxed) => {
                Err(Error::Interrupted { time: f64::NAN })
            }
            _ => Ok(()),
        }
    }
}

/// The run table of the finished runs.
pub fn run_table(spec: &CampaignSpec, runs: &Design, finished: &[(usize, &RunRecord)]) -> Table {
    let done: Vec<&RunRecord> = finished.iter().map(|f| f.1).collect();
    let places: Vec<(usize, u32, usize)> = finished.iter().map(|f| runs.place(f.0)).collect();
    let mut t = Table::default();
    let int = |f: &dyn Fn(usize) -> i64| ColumnData::Int((0..done.len()).map(f).collect());
    t.push("run", int(&|k| finished[k].0 as i64));
    t.push("point", int(&|k| places[k].0 as i64));
    t.push("replication", int(&|k| places[k].1 as i64));
    if !spec.arms.is_empty() {
        let arm = places.iter().map(|p| spec.arms[p.2].name.clone()).collect();
        t.push("arm", ColumnData::Text(arm));
    }
    for (j, f) in spec.factors.iter().enumerate() {
        let values = places.iter().map(|p| runs.factor(p.0, j)).collect();
        t.push(&f.name, ColumnData::Float(values));
    }
    for (j, s) in spec.replications.seeds.iter().enumerate() {
        let seeds = places.par_iter().map(|p| runs.seed(p.1, j)).collect();
        t.push(s, ColumnData::Int(seeds));
    }
    drop(places);
    let mut j = 0;
    for k in &spec.kpis {
        for (c, name) in k.columns().into_iter().enumerate() {
            let data = if k.is_verdict(c) {
                ColumnData::Text(done.iter().map(|r| verdict(&r.kpis[j])).collect())
            } else {
                ColumnData::Float(done.iter().map(|r| r.kpis[j].number()).collect())
            };
            t.push(name, data);
            j += 1;
        }
    }
    let text =
        |f: &dyn Fn(&RunRecord) -> String| ColumnData::Text(done.iter().map(|r| f(r)).collect());
    t.push("status", text(&|r| r.status.name().to_string()));
    t.push("message", text(&|r| r.message.clone()));
    t.push(
        "wall_time",
        ColumnData::Float(done.iter().map(|r| r.wall_time).collect()),
    );
    t.push("key", text(&|r| r.key.clone()));
    t
}

fn verdict(v: &super::journal::JsonKpi) -> String {
    match v {
        super::journal::JsonKpi::Verdict(s) => s.clone(),
        super::journal::JsonKpi::Number(_) => String::new(),
    }
}

/// The derived table: one row per design point and replication with any finished run.
pub fn derived_table(
    spec: &CampaignSpec,
    runs: &Design,
    finished: &[(usize, &RunRecord)],
) -> Result<Option<Table>> {
    derived_table_until(spec, runs, finished, Stop(None))
}

fn derived_table_until(
    spec: &CampaignSpec,
    runs: &Design,
    finished: &[(usize, &RunRecord)],
    stop: Stop,
) -> Result<Option<Table>> {
    if spec.derived.is_empty() {
        return Ok(None);
    }
    let kpis = DerivedKpi::compile(spec, &kpi_columns(spec))?;
    let arms = spec.arms.len().max(1);
    // Per (point, replication): the record of each arm.
    type Cell<'a> = ((usize, u32), Vec<Option<&'a RunRecord>>);
    let mut cells: std::collections::BTreeMap<(usize, u32), Vec<Option<&RunRecord>>> =
        Default::default();
    for (i, rec) in finished {
        let (point, replication, arm) = runs.place(*i);
        cells
            .entry((point, replication))
            .or_insert_with(|| vec![None; arms])[arm] = Some(rec);
    }
    let rows: Vec<Cell> = cells.into_iter().collect();
    let mut t = Table::default();
    t.push(
        "point",
        ColumnData::Int(rows.iter().map(|c| c.0 .0 as i64).collect()),
    );
    t.push(
        "replication",
        ColumnData::Int(rows.iter().map(|c| c.0 .1 as i64).collect()),
    );
    for (j, f) in spec.factors.iter().enumerate() {
        let values = rows.iter().map(|c| runs.factor(c.0 .0, j)).collect();
        t.push(&f.name, ColumnData::Float(values));
    }
    for (j, s) in spec.replications.seeds.iter().enumerate() {
        let seeds = rows.par_iter().map(|c| runs.seed(c.0 .1, j)).collect();
        t.push(s, ColumnData::Int(seeds));
    }
    // values[row][arm][kpi column]
    let n_kpis = kpi_columns(spec).len();
    let values: Vec<Vec<Vec<f64>>> = rows
        .iter()
        .map(|(_, recs)| {
            recs.iter()
                .map(|r| match r {
                    Some(r) if !r.status.failed() => r.kpis.iter().map(|k| k.number()).collect(),
                    _ => vec![f64::NAN; n_kpis],
                })
                .collect()
        })
        .collect();
    let derived: Vec<Vec<f64>> = kpis
        .iter()
        .map(|d| {
            let column = values.chunks(4096).map(|rows| {
                stop.check()?;
                Ok(rows.iter().map(|v| d.eval(v)).collect::<Vec<f64>>())
            });
            Ok(column.collect::<Result<Vec<_>>>()?.concat())
        })
        .collect::<Result<_>>()?;
    for (d, column) in kpis.iter().zip(&derived) {
        t.push(&d.name, ColumnData::Float(column.clone()));
    }
    let status = rows
        .iter()
        .enumerate()
        .map(|(i, (_, recs))| {
            if recs.iter().any(Option::is_none) {
                "incomplete".to_string()
            } else if recs.iter().any(|r| r.is_some_and(|r| r.status.failed())) {
                "failed".to_string()
            } else if derived.iter().any(|c| !c[i].is_finite()) {
                // x[on] / 0 and the like: a value that is not a result
                "non_finite".to_string()
            } else {
                "ok".to_string()
            }
        })
        .collect();
    t.push("status", ColumnData::Text(status));
    Ok(Some(t))
}

/// Writes the run table and the derived table (CSV and Parquet) from the journal.
/// Stops with [`Error::Interrupted`] when `stop` is set ([`Stop`]); each file is written
/// whole or not at all.
pub fn write_tables(
    spec: &CampaignSpec,
    runs: &Design,
    journal: &Journal,
    dir: &Path,
    stop: Stop,
) -> Result<Vec<PathBuf>> {
    let done = finished_until(runs, journal, stop)?;
    let mut files = Vec::new();
    let mut write = |name: &str, t: &Table| -> Result<()> {
        let csv = dir.join(format!("{name}.csv"));
        let parquet = dir.join(format!("{name}.parquet"));
        stop.check()?;
        t.write_csv(&csv)?;
        stop.check()?;
        t.write_parquet(&parquet)?;
        files.push(csv);
        files.push(parquet);
        Ok(())
    };
    write("runs", &run_table(spec, runs, &done))?;
    if let Some(t) = derived_table_until(spec, runs, &done, stop)? {
        write("derived", &t)?;
    }
    Ok(files)
}
