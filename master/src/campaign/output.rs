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
use super::{Campaign, CampaignSpec, Run};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
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

/// The finished runs of the campaign in index order (records of other campaigns' keys are
/// left out).
///
/// Runs are matched by key, not by index: a campaign extended with more points or
/// replications keeps its finished runs (their keys do not change), under new indices.
pub fn finished<'a>(
    runs: &'a [Run],
    records: impl Iterator<Item = &'a RunRecord>,
) -> Vec<(&'a Run, &'a RunRecord)> {
    let by_key: HashMap<&str, &RunRecord> = records.map(|r| (r.key.as_str(), r)).collect();
    runs.iter()
        .filter_map(|r| Some((r, *by_key.get(r.key.as_str())?)))
        .collect()
}

/// The run table of the finished runs.
pub fn run_table(spec: &CampaignSpec, finished: &[(&Run, &RunRecord)]) -> Table {
    let runs: Vec<&Run> = finished.iter().map(|f| f.0).collect();
    let done: Vec<&RunRecord> = finished.iter().map(|f| f.1).collect();
    let mut t = Table::default();
    let int = |f: &dyn Fn(&Run) -> i64| ColumnData::Int(runs.iter().map(|r| f(r)).collect());
    t.push("run", int(&|r| r.index as i64));
    t.push("point", int(&|r| r.point as i64));
    t.push("replication", int(&|r| r.replication as i64));
    if !spec.arms.is_empty() {
        let arm = runs.iter().map(|r| spec.arms[r.arm].name.clone()).collect();
        t.push("arm", ColumnData::Text(arm));
    }
    for (j, f) in spec.factors.iter().enumerate() {
        t.push(
            &f.name,
            ColumnData::Float(runs.iter().map(|r| r.factors[j]).collect()),
        );
    }
    for (j, s) in spec.replications.seeds.iter().enumerate() {
        t.push(
            s,
            ColumnData::Int(runs.iter().map(|r| r.seeds[j]).collect()),
        );
    }
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
    finished: &[(&Run, &RunRecord)],
) -> Result<Option<Table>> {
    if spec.derived.is_empty() {
        return Ok(None);
    }
    let kpis = DerivedKpi::compile(spec, &kpi_columns(spec))?;
    let arms = spec.arms.len().max(1);
    // Per (point, replication): any run of the cell (it carries the factors and seeds), and
    // the record of each arm.
    type Cell<'a> = (&'a Run, Vec<Option<&'a RunRecord>>);
    let mut cells: std::collections::BTreeMap<(usize, u32), Cell> = Default::default();
    for (run, rec) in finished {
        cells
            .entry((run.point, run.replication))
            .or_insert_with(|| (run, vec![None; arms]))
            .1[run.arm] = Some(rec);
    }
    let rows: Vec<&Cell> = cells.values().collect();
    let mut t = Table::default();
    t.push(
        "point",
        ColumnData::Int(rows.iter().map(|c| c.0.point as i64).collect()),
    );
    t.push(
        "replication",
        ColumnData::Int(rows.iter().map(|c| c.0.replication as i64).collect()),
    );
    for (j, f) in spec.factors.iter().enumerate() {
        t.push(
            &f.name,
            ColumnData::Float(rows.iter().map(|c| c.0.factors[j]).collect()),
        );
    }
    for (j, s) in spec.replications.seeds.iter().enumerate() {
        t.push(
            s,
            ColumnData::Int(rows.iter().map(|c| c.0.seeds[j]).collect()),
        );
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
        .map(|d| values.iter().map(|v| d.eval(v)).collect())
        .collect();
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
pub fn write_tables(
    spec: &CampaignSpec,
    runs: &[Run],
    journal: &Journal,
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    let done = finished(runs, journal.records());
    let mut files = Vec::new();
    let mut write = |name: &str, t: &Table| -> Result<()> {
        let csv = dir.join(format!("{name}.csv"));
        let parquet = dir.join(format!("{name}.parquet"));
        t.write_csv(&csv)?;
        t.write_parquet(&parquet)?;
        files.push(csv);
        files.push(parquet);
        Ok(())
    };
    write("runs", &run_table(spec, &done))?;
    if let Some(t) = derived_table(spec, &done)? {
        write("derived", &t)?;
    }
    Ok(files)
}
