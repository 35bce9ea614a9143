//! The run table as CSV: a header row of names, then one record per row, fields quoted only
//! when they hold a comma, a quote or a line break (RFC 4180, sec. 2; lines end in `\n`).
//!
//! Cells:
//!
//! - **Float**: Rust's shortest round-trip form with a decimal point or an exponent (`{:?}` of
//!   `f64`: `3.0`, `-0.0`, `0.1`, `1e-300`, `1e16`), so that a value reads back to the same bits
//!   and a whole number is not mistaken for an Int; `NaN`, `inf` and `-inf` for the others.
//! - **Int**: the integer. **Bool**: `true`/`false`. **Text**: the string.
//!
//! Reading infers each column's type from its cells: all integers -> Int; all numbers
//! (including `NaN`, `inf`) -> Float; all `true`/`false` (any case) -> Bool; else Text. A
//! column without rows is Text.
//!
//! What CSV cannot keep (Parquet keeps all of it): a NaN's sign and payload (every NaN reads
//! back as `f64::NAN`); the type of a Text column whose every cell reads as a number or a
//! bool (`["1", "2"]` reads back as Int); the types of a table without rows.

use std::fs::File;
use std::path::Path;

use super::{write_atomic, ColumnData, Table};
use crate::error::{Error, Result};

impl Table {
    /// Writes the table as CSV to `path`, atomically (see the [module](super) doc). A table
    /// without columns is an empty file.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        self.check(path)?;
        write_atomic(path, |file| {
            let mut w = csv::Writer::from_writer(file);
            let fail = |e: csv::Error| Error::Other(format!("writing {}: {e}", path.display()));
            if !self.columns.is_empty() {
                w.write_record(&self.names).map_err(fail)?;
            }
            let mut record = vec![String::new(); self.columns.len()];
            for i in 0..self.rows() {
                for (cell, column) in record.iter_mut().zip(&self.columns) {
                    cell.clear();
                    format_cell(cell, column, i);
                }
                w.write_record(&record).map_err(fail)?;
            }
            w.into_inner()
                .map_err(|e| Error::io(format!("writing {}", path.display()), e.into_error()))
        })
    }

    /// Reads a CSV table from `path`, inferring each column's type (see the module doc). An
    /// empty file is a table without columns.
    pub fn read_csv(path: &Path) -> Result<Table> {
        let file =
            File::open(path).map_err(|e| Error::io(format!("reading {}", path.display()), e))?;
        let fail = |e: csv::Error| {
            Error::Other(format!("{}: not a readable CSV table: {e}", path.display()))
        };
        let mut reader = csv::ReaderBuilder::new().from_reader(file);
        let names: Vec<String> = reader
            .headers()
            .map_err(fail)?
            .iter()
            .map(str::to_owned)
            .collect();
        let mut cells: Vec<Vec<String>> = vec![Vec::new(); names.len()];
        let mut record = csv::StringRecord::new();
        // The reader checks that every record has as many fields as the header.
        while reader.read_record(&mut record).map_err(fail)? {
            for (column, field) in cells.iter_mut().zip(record.iter()) {
                column.push(field.to_owned());
            }
        }
        let columns = cells.into_iter().map(infer).collect();
        Ok(Table { names, columns })
    }
}

/// Appends row `i` of `column` to `cell` in the form described in the module doc.
fn format_cell(cell: &mut String, column: &ColumnData, i: usize) {
    use std::fmt::Write;
    // Writing into a String cannot fail.
    let _ = match column {
        ColumnData::Float(v) => write!(cell, "{}", FloatCell(v[i])),
        ColumnData::Int(v) => write!(cell, "{}", v[i]),
        ColumnData::Bool(v) => write!(cell, "{}", v[i]),
        ColumnData::Text(v) => write!(cell, "{}", v[i]),
    };
}

/// A Float cell: `{:?}` keeps a decimal point or an exponent on every finite value (`3.0`,
/// `1e16`), where `{}` writes `3` and `10000000000000000`, which would read back as Int.
struct FloatCell(f64);

impl std::fmt::Display for FloatCell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        if x.is_nan() {
            f.write_str("NaN")
        } else if x.is_infinite() {
            f.write_str(if x > 0.0 { "inf" } else { "-inf" })
        } else {
            write!(f, "{x:?}")
        }
    }
}

/// The column of these cells, by the first type that reads them all.
fn infer(cells: Vec<String>) -> ColumnData {
    if cells.is_empty() {
        return ColumnData::Text(cells);
    }
    if let Some(v) = parse_all(&cells, |s| s.parse::<i64>().ok()) {
        return ColumnData::Int(v);
    }
    if let Some(v) = parse_all(&cells, |s| s.parse::<f64>().ok()) {
        return ColumnData::Float(v);
    }
    if let Some(v) = parse_all(&cells, parse_bool) {
        return ColumnData::Bool(v);
    }
    ColumnData::Text(cells)
}

fn parse_all<T>(cells: &[String], parse: impl Fn(&str) -> Option<T>) -> Option<Vec<T>> {
    cells.iter().map(|s| parse(s)).collect()
}

fn parse_bool(s: &str) -> Option<bool> {
    if s.eq_ignore_ascii_case("true") {
        Some(true)
    } else if s.eq_ignore_ascii_case("false") {
        Some(false)
    } else {
        None
    }
}
