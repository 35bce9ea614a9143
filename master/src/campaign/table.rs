//! The run table of a campaign: named, typed columns of equal length.
//!
//! A failed run's KPIs are NaN (Float columns have no other missing value); Text columns use
//! the empty string.

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
}
