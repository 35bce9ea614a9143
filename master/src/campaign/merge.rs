//! `shipsim campaign merge`: the output folders of a campaign's shards (or of interrupted
//! attempts) combined into one folder, with the tables and the derived KPIs recomputed, and a
//! report of the runs that are missing.

use super::journal::{Journal, RunRecord};
use super::output::{self, write_atomic, Provenance};
use super::{CampaignSpec, Design};
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// What a merge found.
#[derive(Debug, Clone)]
pub struct MergeReport {
    /// Runs in the campaign.
    pub total: usize,
    /// Finished runs found.
    pub found: usize,
    /// Runs found in more than one input folder (kept once: a successful record first).
    pub duplicates: usize,
    /// Runs the output folder had already (merging them again is a no-op).
    pub present: usize,
    /// Indices of the runs no input has.
    pub missing: Vec<usize>,
    pub files: Vec<PathBuf>,
}

impl std::fmt::Display for MergeReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of {} runs found ({} in several inputs, {} already in the output folder)",
            self.found, self.total, self.duplicates, self.present
        )?;
        if !self.missing.is_empty() {
            let shown: Vec<String> = self
                .missing
                .iter()
                .take(20)
                .map(|i| i.to_string())
                .collect();
            write!(
                f,
                "\nmissing {} run(s): {}{}",
                self.missing.len(),
                shown.join(", "),
                if self.missing.len() > 20 { ", ..." } else { "" }
            )?;
        }
        for p in &self.files {
            write!(f, "\nwrote {}", p.display())?;
        }
        Ok(())
    }
}

/// Merges the output folders `inputs` of one campaign into `out`.
pub fn merge(inputs: &[PathBuf], out: &Path) -> Result<MergeReport> {
    let Some(first) = inputs.first() else {
        return Err(Error::Other(
            "campaign merge: give the output folders to merge".into(),
        ));
    };
    let prov = Provenance::read(first)?;
    // the KPIs of every input are the first's (their hashes are compared below)
    let kpis = output::kpi_columns(&CampaignSpec::parse(
        &prov.campaign_file,
        &prov.campaign_text,
    )?)
    .len();
    let mut records: HashMap<String, RunRecord> = HashMap::new();
    let mut duplicates = 0;
    // An output folder that holds a campaign already must hold this one.
    let earlier = out.join("campaign.json").exists().then_some(out);
    for dir in earlier
        .into_iter()
        .chain(inputs.iter().map(PathBuf::as_path))
    {
        let p = Provenance::read(dir)?;
        if (p.base_hash.as_str(), p.kpi_hash.as_str())
            != (prov.base_hash.as_str(), prov.kpi_hash.as_str())
        {
            return Err(Error::Other(format!(
                "campaign merge: {} is from another campaign than {} (other base system, FMUs or KPIs)",
                dir.display(),
                first.display()
            )));
        }
        if !dir.join("runs.jsonl").exists() || Some(dir) == earlier {
            continue;
        }
        for r in Journal::open(dir, kpis)?.records() {
            match records.get(&r.key) {
                Some(old) => {
                    duplicates += 1;
                    if old.status.failed() && !r.status.failed() {
                        records.insert(r.key.clone(), r.clone());
                    }
                }
                None => {
                    records.insert(r.key.clone(), r.clone());
                }
            }
        }
    }
    // The campaign as the newest input (or the output folder) describes it: its runs, keyed
    // like the journals.
    let newest = earlier
        .into_iter()
        .chain(inputs.iter().map(PathBuf::as_path))
        .map(Provenance::read)
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .max_by_key(|p| p.runs)
        .expect("one input");
    let spec = CampaignSpec::parse(&newest.campaign_file, &newest.campaign_text)?;
    let runs = Design::new(&spec, &newest.base_hash)?;
    std::fs::create_dir_all(out)
        .map_err(|e| Error::io(format!("cannot create {}", out.display()), e))?;
    let mut merged_prov = newest.clone();
    merged_prov.shard = None;
    let text = serde_json::to_string_pretty(&merged_prov).expect("serializable");
    // the output folder's lock before anything is written into it
    let mut journal = Journal::open(out, kpis)?;
    write_atomic(&out.join("campaign.json"), text.as_bytes())?;
    let (mut found, mut present) = (0, 0);
    let mut missing = Vec::new();
    for run in runs.iter() {
        let new = records.get(&run.key);
        // what the folder has stands, unless it failed and an input has the run done
        let kept = journal
            .done(&run.key)
            .is_some_and(|h| !h.status.failed() || new.is_none_or(|n| n.status.failed()));
        match (kept, new) {
            (true, _) => {
                found += 1;
                present += 1;
            }
            (false, Some(r)) => {
                found += 1;
                journal.append(r.clone())?;
            }
            (false, None) => missing.push(run.index),
        }
    }
    let files = output::write_tables(&spec, &runs, &journal, out, output::Stop(None))?;
    Ok(MergeReport {
        total: runs.len(),
        found,
        duplicates,
        present,
        missing,
        files,
    })
}
