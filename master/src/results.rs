//! The reader of recorded results: the CSV files that `shipsim run` writes (the CSV recorder of
//! [`crate::run`]), read back as columns of numbers for `shipsim plot`, `shipsim stats` and the
//! studies of the test suite.
//!
//! Not to be confused with a campaign's run table ([`crate::campaign::table::Table`]: typed
//! columns, one row per run, in CSV or Parquet).

use crate::error::{Error, Result};
use std::path::Path;

/// A recorded CSV: header names and columns of numbers.
#[derive(Clone, Debug)]
pub struct ResultsTable {
    pub names: Vec<String>,
    pub columns: Vec<Vec<f64>>,
    /// Columns of text (recorded String variables), left out of `names` and `columns`.
    pub text: Vec<String>,
}

/// A CSV field as a number (`true`/`false` as 1/0).
fn number(field: &str) -> Option<f64> {
    match field.trim() {
        "true" | "True" => Some(1.0),
        "false" | "False" => Some(0.0),
        f => f.parse().ok(),
    }
}

impl ResultsTable {
    /// Reads a CSV written by the recorder (first column time, header `instance.variable`;
    /// fields quoted as RFC 4180 says, read by the `csv` crate). Booleans (`true`/`false`) read
    /// as 1/0. A column whose first value is not a number is text (a recorded String
    /// variable): it is listed in `text` and left out; a later value that is not a number in
    /// a number column is an error naming the line and column.
    pub fn read(path: &Path) -> Result<ResultsTable> {
        let bad = |line: u64, e: String| Error::Other(format!("{}:{line}: {e}", path.display()));
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .from_path(path)
            .map_err(|e| Error::Other(format!("cannot read {}: {e}", path.display())))?;
        let mut records = reader.records();
        let header = records
            .next()
            .ok_or_else(|| Error::Other(format!("{}: empty CSV file", path.display())))?
            .map_err(|e| bad(1, e.to_string()))?;
        let all: Vec<String> = header.iter().map(|s| s.trim().to_string()).collect();
        let mut numeric: Option<Vec<bool>> = None;
        let mut columns = vec![Vec::new(); all.len()];
        for record in records {
            let record =
                record.map_err(|e| bad(e.position().map_or(0, |p| p.line()), e.to_string()))?;
            let line = record.position().map_or(0, |p| p.line());
            if record.iter().all(|f| f.trim().is_empty()) {
                continue;
            }
            if record.len() != all.len() {
                let e = format!("{} values, header has {}", record.len(), all.len());
                return Err(bad(line, e));
            }
            let numeric =
                numeric.get_or_insert_with(|| record.iter().map(|f| number(f).is_some()).collect());
            for (c, field) in record.iter().enumerate().filter(|(c, _)| numeric[*c]) {
                let v = number(field).ok_or_else(|| {
                    let e = format!("column {:?}: {:?} is not a number", all[c], field.trim());
                    bad(line, e)
                })?;
                columns[c].push(v);
            }
        }
        let numeric = numeric.unwrap_or_else(|| vec![true; all.len()]);
        let (mut names, mut text, mut kept) = (Vec::new(), Vec::new(), Vec::new());
        for ((name, column), is_number) in all.into_iter().zip(columns).zip(numeric) {
            match is_number {
                true => {
                    names.push(name);
                    kept.push(column);
                }
                false => text.push(name),
            }
        }
        Ok(ResultsTable {
            names,
            columns: kept,
            text,
        })
    }

    /// The column named `name`; the error lists the available columns.
    pub fn column(&self, name: &str) -> Result<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
            .ok_or_else(|| match self.text.iter().any(|t| t == name) {
                true => Error::Other(format!("column {name:?} is text (a String variable)")),
                false => Error::Other(format!(
                    "no column {name:?}; columns: {}",
                    self.names.join(", ")
                )),
            })
    }

    /// The first column (time).
    pub fn time(&self) -> &[f64] {
        self.columns.first().map(Vec::as_slice).unwrap_or(&[])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_numbers_booleans_and_text_columns() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("r.csv");
        std::fs::write(&csv, "time,g.a,g.flag\n0,1.5,true\n0.1,2.5,false\n").unwrap();
        let t = ResultsTable::read(&csv).unwrap();
        assert_eq!(t.time(), &[0.0, 0.1]);
        assert_eq!(t.column("g.a").unwrap(), &[1.5, 2.5]);
        assert_eq!(t.column("g.flag").unwrap(), &[1.0, 0.0]);
        assert!(t
            .column("g.b")
            .unwrap_err()
            .to_string()
            .contains("columns: time, g.a"));
        // a column that starts with text is text (a String variable), left out of the numbers
        std::fs::write(&csv, "time,x\n0,abc\n").unwrap();
        let t = ResultsTable::read(&csv).unwrap();
        assert_eq!(
            (t.names, t.text),
            (vec!["time".to_string()], vec!["x".to_string()])
        );
        // text later in a number column is an error naming the line and column
        std::fs::write(&csv, "time,x\n0,1\n0.1,abc\n").unwrap();
        let e = ResultsTable::read(&csv).unwrap_err().to_string();
        assert!(
            e.contains("r.csv:3: column \"x\": \"abc\" is not a number"),
            "{e}"
        );
    }
}
