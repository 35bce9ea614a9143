//! The run table as Parquet, through Arrow: Float -> Float64, Int -> Int64, Bool -> Boolean,
//! Text -> Utf8, every column non-nullable, one row group, Snappy compression (what pandas
//! and pyarrow write by default).
//!
//! Reading takes any file whose columns have these types or close ones: Float32 (widened),
//! Int8..Int32 and UInt8..UInt64 (as Int; a UInt64 above `i64::MAX` is an error), LargeUtf8
//! and Utf8View. A null Float reads as NaN and a null Text as `""` (the table's missing
//! values); a null Int or Bool is an error naming the column and the row. Files compressed
//! with Snappy or not at all can be read; other codecs (zstd, gzip, ...) are not built in.

use std::fs::File;
use std::path::Path;
use std::sync::Arc;

use arrow_array::cast::AsArray;
use arrow_array::types::{
    Float32Type, Float64Type, Int16Type, Int32Type, Int64Type, Int8Type, UInt16Type, UInt32Type,
    UInt64Type, UInt8Type,
};
use arrow_array::{
    Array, ArrayRef, ArrowPrimitiveType, BooleanArray, Float64Array, Int64Array, RecordBatch,
    RecordBatchOptions, StringArray,
};
use arrow_schema::{DataType, Field, Schema};
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::arrow::ArrowWriter;
use parquet::basic::Compression;
use parquet::file::properties::WriterProperties;

use super::{write_atomic, ColumnData, Table};
use crate::error::{Error, Result};

impl Table {
    /// Writes the table as Parquet to `path`, atomically (see the [module](super) doc).
    pub fn write_parquet(&self, path: &Path) -> Result<()> {
        self.check(path)?;
        let fail =
            |e: &dyn std::fmt::Display| Error::Other(format!("writing {}: {e}", path.display()));
        let batch = self.record_batch().map_err(|e| fail(&e))?;
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .build();
        write_atomic(path, |file| {
            let mut w =
                ArrowWriter::try_new(file, batch.schema(), Some(props)).map_err(|e| fail(&e))?;
            if batch.num_rows() > 0 {
                w.write(&batch).map_err(|e| fail(&e))?;
            }
            // Writes the footer and returns the file.
            w.into_inner().map_err(|e| fail(&e))
        })
    }

    /// Reads a Parquet table from `path` (see the module doc for the column types it takes).
    pub fn read_parquet(path: &Path) -> Result<Table> {
        let file =
            File::open(path).map_err(|e| Error::io(format!("reading {}", path.display()), e))?;
        let unreadable = |e: &dyn std::fmt::Display| {
            Error::Other(format!(
                "{}: not a readable Parquet file: {e}",
                path.display()
            ))
        };
        let builder = ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| unreadable(&e))?;
        let mut table = Table::default();
        for field in builder.schema().fields() {
            let column = empty_column(field.data_type()).ok_or_else(|| {
                Error::Other(format!(
                    "{}: column '{}' has type {}, which a run table cannot hold \
                     (Float64, Int64, Boolean or Utf8)",
                    path.display(),
                    field.name(),
                    field.data_type()
                ))
            })?;
            table.push(field.name().clone(), column);
        }
        let mut first_row = 0;
        for batch in builder.build().map_err(|e| unreadable(&e))? {
            let batch = batch.map_err(|e| unreadable(&e))?;
            for ((name, column), array) in table
                .names
                .iter()
                .zip(&mut table.columns)
                .zip(batch.columns())
            {
                append(column, array.as_ref()).map_err(|(row, what)| {
                    Error::Other(format!(
                        "{}: column '{name}', row {}: {what}",
                        path.display(),
                        first_row + row
                    ))
                })?;
            }
            first_row += batch.num_rows();
        }
        Ok(table)
    }

    /// The table as one Arrow record batch (the row count is explicit, for a table without
    /// columns).
    fn record_batch(&self) -> Result<RecordBatch, arrow_schema::ArrowError> {
        let fields: Vec<Field> = self
            .names
            .iter()
            .zip(&self.columns)
            .map(|(name, column)| {
                let data_type = match column {
                    ColumnData::Float(_) => DataType::Float64,
                    ColumnData::Int(_) => DataType::Int64,
                    ColumnData::Bool(_) => DataType::Boolean,
                    ColumnData::Text(_) => DataType::Utf8,
                };
                Field::new(name, data_type, false)
            })
            .collect();
        let arrays: Vec<ArrayRef> = self
            .columns
            .iter()
            .map(|column| -> ArrayRef {
                match column {
                    ColumnData::Float(v) => Arc::new(Float64Array::from(v.clone())),
                    ColumnData::Int(v) => Arc::new(Int64Array::from(v.clone())),
                    ColumnData::Bool(v) => Arc::new(BooleanArray::from(v.clone())),
                    ColumnData::Text(v) => Arc::new(StringArray::from_iter_values(v)),
                }
            })
            .collect();
        let options = RecordBatchOptions::new().with_row_count(Some(self.rows()));
        RecordBatch::try_new_with_options(Arc::new(Schema::new(fields)), arrays, &options)
    }
}

/// The empty column that holds an Arrow type, or None for a type a run table cannot hold.
fn empty_column(data_type: &DataType) -> Option<ColumnData> {
    use DataType as D;
    Some(match data_type {
        D::Float64 | D::Float32 => ColumnData::Float(Vec::new()),
        D::Int8 | D::Int16 | D::Int32 | D::Int64 => ColumnData::Int(Vec::new()),
        D::UInt8 | D::UInt16 | D::UInt32 | D::UInt64 => ColumnData::Int(Vec::new()),
        D::Boolean => ColumnData::Bool(Vec::new()),
        D::Utf8 | D::LargeUtf8 | D::Utf8View => ColumnData::Text(Vec::new()),
        _ => return None,
    })
}

/// A failed value: its row within the batch and what is wrong.
type Bad = (usize, String);

/// Appends an Arrow array to the column that [`empty_column`] made for its type.
fn append(column: &mut ColumnData, array: &dyn Array) -> Result<(), Bad> {
    use DataType as D;
    match (column, array.data_type()) {
        (ColumnData::Float(v), D::Float64) => {
            primitive::<Float64Type, _>(v, array, Some(f64::NAN), Some)
        }
        (ColumnData::Float(v), D::Float32) => {
            primitive::<Float32Type, _>(v, array, Some(f64::NAN), |x| Some(f64::from(x)))
        }
        (ColumnData::Int(v), D::Int64) => primitive::<Int64Type, _>(v, array, None, Some),
        (ColumnData::Int(v), D::Int32) => integer::<Int32Type>(v, array),
        (ColumnData::Int(v), D::Int16) => integer::<Int16Type>(v, array),
        (ColumnData::Int(v), D::Int8) => integer::<Int8Type>(v, array),
        (ColumnData::Int(v), D::UInt64) => integer::<UInt64Type>(v, array),
        (ColumnData::Int(v), D::UInt32) => integer::<UInt32Type>(v, array),
        (ColumnData::Int(v), D::UInt16) => integer::<UInt16Type>(v, array),
        (ColumnData::Int(v), D::UInt8) => integer::<UInt8Type>(v, array),
        (ColumnData::Bool(v), D::Boolean) => {
            let a = array.as_boolean_opt().ok_or_else(mismatch)?;
            values(
                v,
                a.len(),
                |i| (!a.is_null(i)).then(|| Ok(a.value(i))),
                None,
            )
        }
        (ColumnData::Text(v), D::Utf8) => {
            let a = array.as_string_opt::<i32>().ok_or_else(mismatch)?;
            v.extend(a.iter().map(|s| s.unwrap_or_default().to_owned()));
            Ok(())
        }
        (ColumnData::Text(v), D::LargeUtf8) => {
            let a = array.as_string_opt::<i64>().ok_or_else(mismatch)?;
            v.extend(a.iter().map(|s| s.unwrap_or_default().to_owned()));
            Ok(())
        }
        (ColumnData::Text(v), D::Utf8View) => {
            let a = array.as_string_view_opt().ok_or_else(mismatch)?;
            v.extend(a.iter().map(|s| s.unwrap_or_default().to_owned()));
            Ok(())
        }
        (column, t) => Err((
            0,
            format!("type {t} in a batch, {} in the schema", column.type_name()),
        )),
    }
}

fn mismatch() -> Bad {
    (0, "the array does not have its declared type".to_owned())
}

/// Appends `len` values: `get(i)` is None for a null (replaced by `null`, or an error without
/// one), or the value or why it cannot be held.
fn values<U>(
    out: &mut Vec<U>,
    len: usize,
    get: impl Fn(usize) -> Option<Result<U, String>>,
    null: Option<U>,
) -> Result<(), Bad>
where
    U: Copy,
{
    out.reserve(len);
    for i in 0..len {
        match get(i) {
            Some(Ok(x)) => out.push(x),
            Some(Err(what)) => return Err((i, what)),
            None => out.push(null.ok_or((i, "null value".to_owned()))?),
        }
    }
    Ok(())
}

fn primitive<T: ArrowPrimitiveType, U: Copy>(
    out: &mut Vec<U>,
    array: &dyn Array,
    null: Option<U>,
    convert: impl Fn(T::Native) -> Option<U>,
) -> Result<(), Bad> {
    let a = array.as_primitive_opt::<T>().ok_or_else(mismatch)?;
    let get = |i| {
        (!a.is_null(i)).then(|| {
            let x = a.value(i);
            convert(x).ok_or_else(|| format!("{x:?} does not fit a 64-bit integer"))
        })
    };
    values(out, a.len(), get, null)
}

fn integer<T>(out: &mut Vec<i64>, array: &dyn Array) -> Result<(), Bad>
where
    T: ArrowPrimitiveType,
    T::Native: TryInto<i64>,
{
    primitive::<T, i64>(out, array, None, |x| x.try_into().ok())
}
