//! The durable record of completed runs: `runs.jsonl` in the output folder, one JSON line per
//! finished run (successful or failed), appended as each run ends.
//!
//! Crash safety: a line is written with one `write` call on a file opened for appending, then
//! `fdatasync`ed before the run counts as done. A process killed during a write leaves at most
//! one partial last line; [`Journal::open`] drops it (truncating the file to its last complete
//! line), so that run is simply run again. A run is never written twice: a resumed campaign
//! skips every key already in the journal ([`Journal::done`]), and the journal is locked
//! (`flock`) while a campaign writes it, so two processes never run into one folder. Numbers round-trip exactly
//! (serde_json's `float_roundtrip`); non-finite KPI values are written as `null` and read back
//! as NaN.

use super::kpi::KpiValue;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Ran to its stop time.
    Ok,
    /// An FMU ended it early (fmi2Terminated); the KPIs cover the part that ran.
    Terminated,
    /// An FMU or validation error.
    Error,
    /// A recorded variable became NaN.
    Nan,
    /// The master panicked (a bug): the run is recorded, the campaign goes on.
    Panic,
    /// The run ended, but a window statistic is NaN or infinite (an empty window, an
    /// overflow): its value is not a result.
    NonFiniteKpi,
}

impl Status {
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Terminated => "terminated",
            Status::Error => "error",
            Status::Nan => "nan",
            Status::Panic => "panic",
            Status::NonFiniteKpi => "non_finite_kpi",
        }
    }

    pub fn failed(self) -> bool {
        !matches!(self, Status::Ok | Status::Terminated)
    }
}

/// A KPI value as written: a number, null (non-finite) or a verdict string.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum JsonKpi {
    Number(Option<f64>),
    Verdict(String),
}

impl From<&KpiValue> for JsonKpi {
    fn from(v: &KpiValue) -> JsonKpi {
        match v {
            KpiValue::Number(x) => JsonKpi::Number(x.is_finite().then_some(*x)),
            KpiValue::Verdict(s) => JsonKpi::Verdict(s.to_string()),
        }
    }
}

impl JsonKpi {
    pub fn number(&self) -> f64 {
        match self {
            JsonKpi::Number(x) => x.unwrap_or(f64::NAN),
            JsonKpi::Verdict(_) => f64::NAN,
        }
    }
}

/// One finished run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    pub index: usize,
    pub key: String,
    pub status: Status,
    pub message: String,
    pub kpis: Vec<JsonKpi>,
    /// Wall time of the run [s] (for a forked run: from the restored warm-up state).
    pub wall_time: f64,
}

impl RunRecord {
    /// The same run with the same outcome: index, key, status, message and KPI values (bit for
    /// bit, NaN equal to NaN); the wall time may differ.
    pub fn same_result(&self, other: &RunRecord) -> bool {
        let bits = |r: &RunRecord| -> Vec<Option<u64>> {
            r.kpis
                .iter()
                .map(|k| match k {
                    JsonKpi::Number(x) => Some(x.map_or(u64::MAX, f64::to_bits)),
                    JsonKpi::Verdict(_) => None,
                })
                .collect()
        };
        let verdicts = |r: &RunRecord| -> Vec<Option<String>> {
            r.kpis
                .iter()
                .map(|k| match k {
                    JsonKpi::Verdict(s) => Some(s.clone()),
                    JsonKpi::Number(_) => None,
                })
                .collect()
        };
        (self.index, &self.key, self.status, &self.message)
            == (other.index, &other.key, other.status, &other.message)
            && bits(self) == bits(other)
            && verdicts(self) == verdicts(other)
    }
}

/// The journal file, open for appending.
pub struct Journal {
    path: PathBuf,
    file: File,
    /// Completed runs by key (the last record of a key wins).
    records: HashMap<String, RunRecord>,
}

impl Journal {
    /// Opens (or creates) `dir/runs.jsonl` of a campaign with `kpis` KPI columns, reading the
    /// runs already done and dropping a partial last line. A line that is not a run record of
    /// this campaign (another number of KPI values) is an error naming the file and line; so is
    /// a run recorded twice with different results, unless the first failed (a retry, which
    /// replaces it). A run recorded twice with the same results is kept once.
    pub fn open(dir: &Path, kpis: usize) -> Result<Journal> {
        let path = crate::output_path::writable(&dir.join("runs.jsonl"))?;
        let io = |what: &str, e| Error::io(format!("{what} {}", path.display()), e);
        let mut file = OpenOptions::new()
            .read(true)
            .append(true)
            .create(true)
            .open(&path)
            .map_err(|e| io("cannot open the run journal", e))?;
        // One process at a time per output folder: a second `campaign run` on the same folder
        // would run the same runs and write them twice. The lock goes with the process (also
        // on SIGKILL). It is flock's, held by this open file: a second open in another thread
        // of the same process (two Python threads running one Campaign) is refused too.
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(Error::Other(format!(
                    "{} is in use: a campaign is running into {} (in another process, or in \
                     another thread of this one); wait for it to end, or give another output \
                     folder",
                    path.display(),
                    dir.display()
                )))
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(io("cannot lock", e)),
        }
        let mut text = Vec::new();
        file.read_to_end(&mut text)
            .map_err(|e| io("cannot read the run journal", e))?;
        let complete = text.iter().rposition(|b| *b == b'\n').map_or(0, |p| p + 1);
        if complete < text.len() {
            file.set_len(complete as u64)
                .map_err(|e| io("cannot drop the partial last line of", e))?;
            file.seek(SeekFrom::End(0))
                .map_err(|e| io("cannot seek in", e))?;
        }
        let mut records: HashMap<String, RunRecord> = HashMap::new();
        let mut lines: HashMap<String, usize> = HashMap::new();
        for (n, line) in text[..complete].split(|b| *b == b'\n').enumerate() {
            if line.is_empty() {
                continue;
            }
            let at = |m: String| Error::system(&path, Some(n + 1), m);
            let r: RunRecord =
                serde_json::from_slice(line).map_err(|e| at(format!("not a run record: {e}")))?;
            if r.kpis.len() != kpis {
                return Err(at(format!(
                    "the record of run {} has {} KPI values where the campaign has {kpis}: \
                     not a journal of this campaign",
                    r.index,
                    r.kpis.len()
                )));
            }
            match records.get(&r.key) {
                Some(old) if old.status.failed() => {}
                Some(old) if old.same_result(&r) => continue,
                Some(_) => {
                    return Err(at(format!(
                        "run {} (key {}) is recorded twice with different results, on lines \
                         {} and {}; remove the wrong line",
                        r.index,
                        r.key,
                        lines[&r.key],
                        n + 1
                    )))
                }
                None => {}
            }
            lines.insert(r.key.clone(), n + 1);
            records.insert(r.key.clone(), r);
        }
        Ok(Journal {
            path,
            file,
            records,
        })
    }

    /// The record of a run already done, by key.
    pub fn done(&self, key: &str) -> Option<&RunRecord> {
        self.records.get(key)
    }

    pub fn records(&self) -> impl Iterator<Item = &RunRecord> {
        self.records.values()
    }

    /// Appends a finished run durably (written and synced before it returns).
    pub fn append(&mut self, r: RunRecord) -> Result<()> {
        let mut line = serde_json::to_vec(&r)
            .map_err(|e| Error::Other(format!("cannot encode run {}: {e}", r.index)))?;
        line.push(b'\n');
        let io = |e| Error::io(format!("cannot append to {}", self.path.display()), e);
        self.file.write_all(&line).map_err(io)?;
        self.file.sync_data().map_err(io)?;
        self.records.insert(r.key.clone(), r);
        Ok(())
    }
}
