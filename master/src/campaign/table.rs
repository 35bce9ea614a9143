//! The run table of a campaign: named, typed columns of equal length, and its files.
//!
//! A failed run's KPIs are NaN (Float columns have no other missing value); Text columns use
//! the empty string.
//!
//! Files ([`Table::write`], [`Table::read`], chosen by extension):
//!
//! - **Parquet** (`.parquet`, [`parquet_io`]): Float -> DOUBLE, Int -> INT64, Bool -> BOOLEAN,
//!   Text -> UTF-8 string (Arrow's Float64, Int64, Boolean, Utf8 in pandas and polars),
//!   Snappy-compressed. Keeps every value bit for bit (NaN payloads too) and every column's
//!   type, also for a table without rows.
//! - **CSV** (`.csv`, [`csv_io`]): a header row, fields quoted only when needed (RFC 4180,
//!   sec. 2). Floats keep their bits (except a NaN's sign and payload) and their type; see
//!   [`csv_io`] for what CSV cannot keep.
//!
//! Both load straight into pandas and polars (`tests/python/test_campaign_table.py`). Writes are
//! atomic: the file is written as `<path>.tmp`, synced, then renamed over `path`, so a crash
//! leaves the old file or the new one, never half a table.

pub mod csv_io;
pub mod parquet_io;

use std::fs::File;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// One column's values.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnData {
    Float(Vec<f64>),
    Int(Vec<i64>),
    Bool(Vec<bool>),
    Text(Vec<String>),
}

impl ColumnData {
    pub fn len(&self) -> usize {
        match self {
            ColumnData::Float(v) => v.len(),
            ColumnData::Int(v) => v.len(),
            ColumnData::Bool(v) => v.len(),
            ColumnData::Text(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The type's name, for messages: `Float`, `Int`, `Bool` or `Text`.
    pub fn type_name(&self) -> &'static str {
        match self {
            ColumnData::Float(_) => "Float",
            ColumnData::Int(_) => "Int",
            ColumnData::Bool(_) => "Bool",
            ColumnData::Text(_) => "Text",
        }
    }

    /// Row `i` as a number (Int as f64, Bool as 0/1, Text parsed or NaN).
    pub fn number(&self, i: usize) -> f64 {
        match self {
            ColumnData::Float(v) => v[i],
            ColumnData::Int(v) => v[i] as f64,
            ColumnData::Bool(v) => v[i] as i32 as f64,
            ColumnData::Text(v) => v[i].parse().unwrap_or(f64::NAN),
        }
    }
}

/// Named columns of equal length.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    pub names: Vec<String>,
    pub columns: Vec<ColumnData>,
}

impl Table {
    /// Rows (the length of the first column; 0 without columns).
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, ColumnData::len)
    }

    /// Adds a column (its length must equal the table's when it has columns).
    pub fn push(&mut self, name: impl Into<String>, data: ColumnData) {
        debug_assert!(self.columns.is_empty() || data.len() == self.rows());
        self.names.push(name.into());
        self.columns.push(data);
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Option<&ColumnData> {
        let j = self.names.iter().position(|n| n == name)?;
        Some(&self.columns[j])
    }

    /// Checks the shape: one name per column and columns of equal length. `path` names the file
    /// being written, for the message.
    pub fn check(&self, path: &Path) -> Result<()> {
        if self.names.len() != self.columns.len() {
            return Err(Error::Other(format!(
                "{}: cannot write the table: {} names for {} columns",
                path.display(),
                self.names.len(),
                self.columns.len()
            )));
        }
        let rows = self.rows();
        for (name, column) in self.names.iter().zip(&self.columns) {
            if column.len() != rows {
                return Err(Error::Other(format!(
                    "{}: cannot write the table: column '{name}' has {} rows, the first column {rows}",
                    path.display(),
                    column.len()
                )));
            }
        }
        Ok(())
    }

    /// Writes the table as CSV or Parquet, by the extension of `path` (`.csv`, `.parquet`).
    pub fn write(&self, path: &Path) -> Result<()> {
        match Format::of(path)? {
            Format::Csv => self.write_csv(path),
            Format::Parquet => self.write_parquet(path),
        }
    }

    /// Reads a table from CSV or Parquet, by the extension of `path` (`.csv`, `.parquet`).
    pub fn read(path: &Path) -> Result<Table> {
        match Format::of(path)? {
            Format::Csv => Table::read_csv(path),
            Format::Parquet => Table::read_parquet(path),
        }
    }
}

/// The file formats, by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Csv,
    Parquet,
}

impl Format {
    fn of(path: &Path) -> Result<Format> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ext.eq_ignore_ascii_case("csv") {
            Ok(Format::Csv)
        } else if ext.eq_ignore_ascii_case("parquet") || ext.eq_ignore_ascii_case("pq") {
            Ok(Format::Parquet)
        } else {
            Err(Error::Other(format!(
                "{}: unknown table format '.{ext}' (use .csv or .parquet)",
                path.display()
            )))
        }
    }
}

/// `<path>.tmp`: the file a write goes to before it is renamed over `path`.
fn tmp_path(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(".tmp");
    PathBuf::from(s)
}

/// Writes `path` atomically: `write` fills `<path>.tmp` and returns the file, which is synced
/// to disk and renamed over `path` (a rename within a directory is atomic on POSIX file
/// systems). On any error the temporary file is removed and `path` is left as it was.
pub(crate) fn write_atomic(path: &Path, write: impl FnOnce(File) -> Result<File>) -> Result<()> {
    let path = &crate::output_path::writable(path)?;
    let tmp = tmp_path(path);
    let result = File::create(&tmp)
        .map_err(|e| Error::io(format!("creating {}", tmp.display()), e))
        .and_then(write)
        .and_then(|file| {
            file.sync_all()
                .map_err(|e| Error::io(format!("syncing {}", tmp.display()), e))
        })
        .and_then(|()| {
            std::fs::rename(&tmp, path).map_err(|e| {
                Error::io(
                    format!("renaming {} to {}", tmp.display(), path.display()),
                    e,
                )
            })
        });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
        return result;
    }
    // Make the rename itself durable (best effort: not every platform can open a directory).
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}
