//! The session journal: every value set from outside a stepping session, with what identifies
//! the system, so that the session replays offline bit for bit (`shipsim replay`,
//! `System.replay` in Python, [`super::Session::replay`]).
//!
//! The file is JSON Lines. The first line is the [`JournalHeader`]: the system file and its
//! SHA-256, every instance's FMU and its SHA-256, the values set on the instances before the
//! start (the file's and those set since, typed), and the run's options (times, step size,
//! algorithm, recorded variables, decimation). Each further line is a [`Record`]:
//!
//! - `{"record":"set","step":k,"time":t,"variable":"inst.var","value":{"Real":x}}`: a value
//!   set at t_k, as the FMU takes it (a value given with a unit is converted; a Real is
//!   written with every bit, serde_json's float round trip);
//! - `{"record":"checkpoint","id":n,"step":k}` and `{"record":"restore","id":n,"step":k}`:
//!   a checkpoint taken, and the session rewound to it (the values set after it are dropped
//!   from the history);
//! - `{"record":"end","step":k}`: the session closed at t_k.
//!
//! The file is buffered and flushed at each checkpoint, restore and end, when the session is
//! dropped, and by a real-time run at most once a wall second ([`crate::realtime`]); a session without an end record (its process died) replays to the
//! step of its last record.

use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::system::{LastStep, PlanEvent, System, TypedValue, Value, VarRef};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;

const FORMAT: &str = "shipsim-session-journal";
const VERSION: u32 = 1;

/// A value as the journal writes it, typed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum JournalValue {
    Real(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
    /// Text a user gave (`--set`, a unit), read by the variable's type as written.
    Text(String),
}

impl From<&Value> for JournalValue {
    fn from(v: &Value) -> JournalValue {
        match v {
            Value::Real(x) => JournalValue::Real(*x),
            Value::Integer(x) => JournalValue::Integer(*x),
            Value::Boolean(x) => JournalValue::Boolean(*x),
            Value::String(x) => JournalValue::String(x.clone()),
            Value::Text(x) => JournalValue::Text(x.clone()),
        }
    }
}

impl From<&TypedValue> for JournalValue {
    fn from(v: &TypedValue) -> JournalValue {
        match v {
            TypedValue::Real(x) => JournalValue::Real(*x),
            TypedValue::Integer(x) => JournalValue::Integer(i64::from(*x)),
            TypedValue::Boolean(x) => JournalValue::Boolean(*x),
            TypedValue::String(x) => JournalValue::String(x.clone()),
        }
    }
}

impl From<JournalValue> for Value {
    fn from(v: JournalValue) -> Value {
        match v {
            JournalValue::Real(x) => Value::Real(x),
            JournalValue::Integer(x) => Value::Integer(x),
            JournalValue::Boolean(x) => Value::Boolean(x),
            JournalValue::String(x) => Value::String(x),
            JournalValue::Text(x) => Value::Text(x),
        }
    }
}

/// An instance and its FMU, by content.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FmuId {
    pub instance: String,
    pub fmu: PathBuf,
    pub sha256: String,
}

/// A value set on an instance before the start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StartSetting {
    pub variable: String,
    pub value: JournalValue,
}

/// The journal's first line: the system and the run's options.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct JournalHeader {
    pub format: String,
    pub version: u32,
    pub system: PathBuf,
    pub system_sha256: String,
    pub fmus: Vec<FmuId>,
    pub values: Vec<StartSetting>,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    pub step_size: f64,
    pub algorithm: String,
    pub last_step: String,
    pub variables: Option<Vec<String>>,
    pub decimation: u32,
}

impl JournalHeader {
    /// The header of a session of `system` run with `fmus` (`fmus[i]` for instance i).
    pub fn of(system: &System, fmus: &[Arc<Fmu>]) -> Result<JournalHeader> {
        let source = system
            .source
            .canonicalize()
            .unwrap_or_else(|_| system.source.clone());
        let system_sha256 = match source.is_file() {
            true => crate::digest::file_sha256(&source)?,
            false => String::new(),
        };
        let fmus = system
            .instances
            .iter()
            .zip(fmus)
            .map(|(inst, f)| {
                Ok(FmuId {
                    instance: inst.name.clone(),
                    fmu: inst.fmu.canonicalize().unwrap_or_else(|_| inst.fmu.clone()),
                    sha256: f.archive_hash()?.to_string(),
                })
            })
            .collect::<Result<_>>()?;
        let values = system
            .instances
            .iter()
            .flat_map(|i| {
                i.values.iter().map(move |v| StartSetting {
                    variable: format!("{}.{}", i.name, v.variable),
                    value: JournalValue::from(&v.value),
                })
            })
            .collect();
        Ok(JournalHeader {
            format: FORMAT.into(),
            version: VERSION,
            system: source,
            system_sha256,
            fmus,
            values,
            start_time: system.start_time,
            stop_time: system.stop_time,
            step_size: system.step_size,
            algorithm: format!("{:?}", system.algorithm),
            last_step: match system.last_step {
                LastStep::Drop => "drop".into(),
                LastStep::Short => "short".into(),
            },
            variables: system.output.variables.clone(),
            decimation: system.output.decimation,
        })
    }
}

/// One line after the header.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "record", rename_all = "lowercase")]
pub enum Record {
    Set {
        step: u64,
        time: f64,
        variable: String,
        value: JournalValue,
    },
    Checkpoint {
        id: u64,
        step: u64,
    },
    Restore {
        id: u64,
        step: u64,
    },
    End {
        step: u64,
    },
}

impl Record {
    fn step(&self) -> u64 {
        match self {
            Record::Set { step, .. }
            | Record::Checkpoint { step, .. }
            | Record::Restore { step, .. }
            | Record::End { step } => *step,
        }
    }
}

/// Where a session keeps its journal.
#[derive(Debug, Clone, Default, PartialEq)]
pub enum Journaling {
    /// In memory (`journal_text`, `save`), the default.
    #[default]
    Memory,
    /// In memory and streamed to this file as the session goes.
    File(PathBuf),
    /// Not at all: nothing to replay, and memory stays flat however many values are set (a
    /// reinforcement-learning loop of millions of steps).
    Off,
}

/// A session's journal: in memory, and streamed to a file when one is given.
pub struct Journal {
    pub header: JournalHeader,
    pub records: Vec<Record>,
    file: Option<(PathBuf, BufWriter<std::fs::File>)>,
    off: bool,
}

fn json<T: Serialize>(v: &T) -> String {
    serde_json::to_string(v).expect("journal records serialize")
}

impl Journal {
    /// A journal with its header, written to a file if `mode` says so (created, or truncated).
    pub fn new(header: JournalHeader, mode: &Journaling) -> Result<Journal> {
        let file = match mode {
            Journaling::Memory | Journaling::Off => None,
            Journaling::File(p) => {
                let p = crate::output_path::writable(p)?;
                if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
                    std::fs::create_dir_all(dir).map_err(|e| {
                        Error::io(format!("cannot create folder {}", dir.display()), e)
                    })?;
                }
                let f = std::fs::File::create(&p).map_err(|e| {
                    Error::io(format!("cannot create the journal {}", p.display()), e)
                })?;
                Some((p, BufWriter::new(f)))
            }
        };
        let mut j = Journal {
            header,
            records: Vec::new(),
            file,
            off: *mode == Journaling::Off,
        };
        let line = json(&j.header);
        j.write_line(&line)?;
        Ok(j)
    }

    /// The session keeps no journal ([`Journaling::Off`]).
    pub fn is_off(&self) -> bool {
        self.off
    }

    /// The file the journal is written to.
    pub fn path(&self) -> Option<&Path> {
        self.file.as_ref().map(|(p, _)| p.as_path())
    }

    fn write_line(&mut self, line: &str) -> Result<()> {
        if let Some((p, w)) = &mut self.file {
            writeln!(w, "{line}")
                .map_err(|e| Error::io(format!("cannot write the journal {}", p.display()), e))?;
        }
        Ok(())
    }

    fn add(&mut self, r: Record, flush: bool) -> Result<()> {
        if self.off {
            return Ok(());
        }
        let line = json(&r);
        self.records.push(r);
        self.write_line(&line)?;
        if flush {
            self.flush()?;
        }
        Ok(())
    }

    pub fn set(&mut self, step: u64, time: f64, e: &PlanEvent) -> Result<()> {
        let r = Record::Set {
            step,
            time,
            variable: e.name.clone(),
            value: JournalValue::from(&e.value),
        };
        self.add(r, false)
    }
    pub fn checkpoint(&mut self, id: u64, step: u64) -> Result<()> {
        self.add(Record::Checkpoint { id, step }, true)
    }
    pub fn restore(&mut self, id: u64, step: u64) -> Result<()> {
        self.add(Record::Restore { id, step }, true)
    }
    pub fn end(&mut self, step: u64) -> Result<()> {
        self.add(Record::End { step }, true)
    }

    pub fn flush(&mut self) -> Result<()> {
        if let Some((p, w)) = &mut self.file {
            w.flush()
                .map_err(|e| Error::io(format!("cannot write the journal {}", p.display()), e))?;
        }
        Ok(())
    }

    /// The whole journal as JSON Lines (header, then records).
    pub fn to_text(&self) -> String {
        let mut s = json(&self.header);
        s.push('\n');
        for r in &self.records {
            s.push_str(&json(r));
            s.push('\n');
        }
        s
    }

    /// Writes the whole journal to `path`.
    pub fn save(&self, path: &Path) -> Result<()> {
        let p = crate::output_path::writable(path)?;
        std::fs::write(&p, self.to_text())
            .map_err(|e| Error::io(format!("cannot write the journal {}", p.display()), e))
    }
}

/// The end record of a session at base step `step`, as a line.
pub fn end_line(step: u64) -> String {
    json(&Record::End { step }) + "\n"
}

/// A journal read back for a replay.
pub struct Replay {
    pub path: PathBuf,
    pub header: JournalHeader,
    pub records: Vec<Record>,
}

impl Replay {
    /// Reads a journal file; a line that does not parse is an error naming the file and line.
    pub fn read(path: &Path) -> Result<Replay> {
        let bad = |line: usize, m: String| {
            Error::system(
                path,
                Some(line),
                format!("not a shipsim session journal: {m}"),
            )
        };
        let text = crate::limits::read_text(path, 1 << 30, "session journal")?;
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let Some((_, first)) = lines.next() else {
            return Err(bad(1, "the file is empty".into()));
        };
        let header: JournalHeader =
            serde_json::from_str(first).map_err(|e| bad(1, e.to_string()))?;
        if header.format != FORMAT || header.version != VERSION {
            return Err(bad(
                1,
                format!(
                    "format \"{}\" version {} (this shipsim reads \"{FORMAT}\" version {VERSION})",
                    header.format, header.version
                ),
            ));
        }
        let records = lines
            .map(|(i, l)| serde_json::from_str(l).map_err(|e| bad(i + 1, e.to_string())))
            .collect::<Result<Vec<Record>>>()?;
        Ok(Replay {
            path: path.to_path_buf(),
            header,
            records,
        })
    }

    /// The step the session ended at: its end record, else its last record's step.
    pub fn end_step(&self) -> u64 {
        let end = self.records.iter().rev().find_map(|r| match r {
            Record::End { step } => Some(*step),
            _ => None,
        });
        end.unwrap_or_else(|| self.records.iter().map(Record::step).max().unwrap_or(0))
    }

    /// The values set in the session's final history, in order: (step, variable, value).
    /// A restore drops the values set since its checkpoint was taken.
    pub fn sets(&self) -> Vec<(u64, String, Value)> {
        let mut history: Vec<(u64, String, JournalValue)> = Vec::new();
        let mut branches: HashMap<u64, Vec<(u64, String, JournalValue)>> = HashMap::new();
        for r in &self.records {
            match r {
                Record::Set {
                    step,
                    variable,
                    value,
                    ..
                } => history.push((*step, variable.clone(), value.clone())),
                Record::Checkpoint { id, .. } => {
                    branches.insert(*id, history.clone());
                }
                Record::Restore { id, .. } => {
                    if let Some(h) = branches.get(id) {
                        history = h.clone();
                    }
                }
                Record::End { .. } => {}
            }
        }
        history
            .into_iter()
            .map(|(s, n, v)| (s, n, Value::from(v)))
            .collect()
    }

    /// The journal's system, checked against the hashes it gives, with its start values and
    /// options, and its FMUs loaded for `run`'s isolation.
    pub fn system(&self, run: &crate::run::RunOptions) -> Result<(System, Vec<Arc<Fmu>>)> {
        let h = &self.header;
        let mut system = System::load(&h.system)?;
        let differs = |what: String| {
            Error::Other(format!(
                "cannot replay {}: {what}; the journal belongs to another version of the system",
                self.path.display()
            ))
        };
        if !h.system_sha256.is_empty() {
            let now = crate::digest::file_sha256(&h.system)?;
            if now != h.system_sha256 {
                return Err(differs(format!(
                    "{} has SHA-256 {now}, the journal's has {}",
                    h.system.display(),
                    h.system_sha256
                )));
            }
        }
        for s in &h.values {
            let r = VarRef::parse(&s.variable)
                .ok_or_else(|| differs(format!("'{}' is not instance.variable", s.variable)))?;
            system.set_value(r, Value::from(s.value.clone()))?;
        }
        system.start_time = h.start_time;
        system.stop_time = h.stop_time;
        system.step_size = h.step_size;
        system.algorithm = h
            .algorithm
            .parse()
            .map_err(|e: crate::system::UnknownAlgorithm| differs(e.to_string()))?;
        system.last_step = LastStep::parse(&h.last_step)
            .ok_or_else(|| differs(format!("last_step \"{}\"", h.last_step)))?;
        system.output.variables = h.variables.clone();
        system.output.decimation = h.decimation;
        system.output.file = None;
        let fmus =
            super::super::load_fmus_with(&system, &crate::fmu::Unpack::default(), &run.isolation)?;
        let names: Vec<&str> = system.instances.iter().map(|i| i.name.as_str()).collect();
        let journal: Vec<&str> = h.fmus.iter().map(|f| f.instance.as_str()).collect();
        if names != journal {
            return Err(differs(format!(
                "instances ({}) in the system, ({}) in the journal",
                names.join(", "),
                journal.join(", ")
            )));
        }
        for (id, f) in h.fmus.iter().zip(&fmus) {
            let now = f.archive_hash()?;
            if now != id.sha256 {
                return Err(differs(format!(
                    "instance '{}': the FMU {} has SHA-256 {now}, the journal's has {}",
                    id.instance,
                    f.path.display(),
                    id.sha256
                )));
            }
        }
        Ok((system, fmus))
    }
}
