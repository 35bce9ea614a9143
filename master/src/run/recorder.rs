//! Recorders: observers of a run that receive the recorded variables at every recorded
//! communication point (every `decimation` base steps, the last point, and the point where an
//! FMU ended the run).
//!
//! A [`Recorder`] is told the columns once ([`Recorder::start`]), gets one [`Row`] per
//! recorded point ([`Recorder::record`]) and is finished once ([`Recorder::finish`]). The
//! master does not care what it does with them: [`CsvRecorder`] writes the CSV file of
//! `shipsim run`, [`MemoryRecorder`] keeps the columns as vectors (for the Python package and
//! for tests), and a statistics accumulator only needs to implement the same three methods.
//! `record` is called from the step loop, which allocates nothing: a recorder reserves what it
//! needs in `start` (it is told the number of rows to expect).

use super::exchange::{Column, Values};
use crate::error::{Error, Result};
use crate::model_description::VarType;
use std::io::Write;

/// One recorded column: `instance.variable` and its type (Real, Integer or Boolean).
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnInfo {
    pub name: String,
    pub var_type: VarType,
}

/// One recorded value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sample {
    Real(f64),
    Integer(i32),
    Boolean(bool),
}

impl Sample {
    /// The value as a number (a Boolean is 0 or 1).
    pub fn as_f64(self) -> f64 {
        match self {
            Sample::Real(x) => x,
            Sample::Integer(i) => i as f64,
            Sample::Boolean(b) => b as i32 as f64,
        }
    }
}

/// The recorded variables at one communication point, in column order. Borrowed from the
/// exchange for the duration of [`Recorder::record`].
pub struct Row<'a> {
    columns: &'a [Column],
    values: &'a Values,
}

impl<'a> Row<'a> {
    pub(crate) fn new(columns: &'a [Column], values: &'a Values) -> Row<'a> {
        Row { columns, values }
    }

    pub fn len(&self) -> usize {
        self.columns.len()
    }

    pub fn is_empty(&self) -> bool {
        self.columns.is_empty()
    }

    /// Column `j`.
    #[inline]
    pub fn get(&self, j: usize) -> Sample {
        match self.columns[j] {
            Column::Real(i) => Sample::Real(self.values.real[i]),
            Column::Integer(i) => Sample::Integer(self.values.integer[i]),
            Column::Boolean(i) => Sample::Boolean(self.values.boolean[i] != 0),
        }
    }

    pub fn iter(&self) -> impl Iterator<Item = Sample> + '_ {
        (0..self.len()).map(|j| self.get(j))
    }
}

/// An observer of a run's recorded variables.
pub trait Recorder {
    /// Called once, before the first row, with the columns and the number of rows the run
    /// will record if it runs to its end.
    fn start(&mut self, columns: &[ColumnInfo], expected_rows: u64) -> Result<()>;
    /// One row at communication point `time`. Called from the step loop: no allocation.
    fn record(&mut self, time: f64, row: &Row<'_>) -> Result<()>;
    /// Called once after the last row, also when the run was interrupted.
    fn finish(&mut self) -> Result<()> {
        Ok(())
    }
}

/// The CSV file of `shipsim run`: header `time,instance.variable,...`, one line per row.
/// Numbers are written in Rust's shortest round-trip form, so values survive the file exactly;
/// Booleans are written 0 or 1.
pub struct CsvRecorder {
    out: Box<dyn Write>,
}

impl CsvRecorder {
    pub fn new(out: Box<dyn Write>) -> CsvRecorder {
        CsvRecorder { out }
    }
}

fn write_error(e: std::io::Error) -> Error {
    Error::io("writing the output file", e)
}

impl Recorder for CsvRecorder {
    fn start(&mut self, columns: &[ColumnInfo], _expected_rows: u64) -> Result<()> {
        let mut header = String::from("time");
        for c in columns {
            header.push(',');
            header.push_str(&c.name);
        }
        header.push('\n');
        self.out
            .write_all(header.as_bytes())
            .map_err(|e| Error::io("writing the output header", e))
    }

    #[inline]
    fn record(&mut self, time: f64, row: &Row<'_>) -> Result<()> {
        write!(self.out, "{time}").map_err(write_error)?;
        for v in row.iter() {
            match v {
                Sample::Real(x) => write!(self.out, ",{x}"),
                Sample::Integer(i) => write!(self.out, ",{i}"),
                Sample::Boolean(b) => write!(self.out, ",{}", b as i32),
            }
            .map_err(write_error)?;
        }
        self.out.write_all(b"\n").map_err(write_error)
    }

    fn finish(&mut self) -> Result<()> {
        self.out.flush().map_err(write_error)
    }
}

/// The recorded columns kept in memory, each as a vector of numbers (Integer and Boolean
/// columns as 0/1 and whole numbers), with the time vector.
#[derive(Debug, Clone, Default)]
pub struct MemoryRecorder {
    pub columns: Vec<ColumnInfo>,
    pub time: Vec<f64>,
    /// `data[j]` is column `j`.
    pub data: Vec<Vec<f64>>,
}

impl MemoryRecorder {
    pub fn new() -> MemoryRecorder {
        MemoryRecorder::default()
    }

    /// The column named `instance.variable`.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        let j = self.columns.iter().position(|c| c.name == name)?;
        Some(&self.data[j])
    }
}

impl Recorder for MemoryRecorder {
    /// Reserves every row up front, so that recording allocates nothing; a run too long to
    /// keep in memory is an error here, before the first step.
    fn start(&mut self, columns: &[ColumnInfo], expected_rows: u64) -> Result<()> {
        let too_long = || {
            Error::Other(format!(
                "cannot keep {expected_rows} rows of {} columns in memory; record fewer \
                 points (output decimation) or write a file",
                columns.len() + 1
            ))
        };
        let rows = usize::try_from(expected_rows).map_err(|_| too_long())?;
        self.columns = columns.to_vec();
        self.time = Vec::new();
        self.data = columns.iter().map(|_| Vec::new()).collect();
        for v in std::iter::once(&mut self.time).chain(self.data.iter_mut()) {
            v.try_reserve_exact(rows).map_err(|_| too_long())?;
        }
        Ok(())
    }

    #[inline]
    fn record(&mut self, time: f64, row: &Row<'_>) -> Result<()> {
        self.time.push(time);
        for (column, v) in self.data.iter_mut().zip(row.iter()) {
            column.push(v.as_f64());
        }
        Ok(())
    }
}
