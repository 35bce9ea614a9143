//! The run table as Parquet: Float -> DOUBLE, Int -> INT64, Bool -> BOOLEAN, Text ->
//! BYTE_ARRAY annotated as a UTF-8 string; every column REQUIRED, one row group, Snappy
//! compression (pandas' default). pandas (pyarrow) and polars read these as float64, int64,
//! bool and string (Arrow Float64, Int64, Boolean, Utf8).
//!
//! This module uses the parquet crate's own column writer and reader, not its Arrow layer: the
//! `arrow` feature (arrow-array, -select, -ipc, -cmp and the Arrow reader/writer) measured
//! about 4 CPU-minutes of clean release build here, the crate without it about 1 minute.
//!
//! Reading takes any flat file whose columns have these types or close ones: FLOAT (widened),
//! INT32 and the unsigned integers (as Int; a UINT_64 above `i64::MAX` is an error), and
//! optional (nullable) columns. A null Float reads as NaN and a null Text as `""` (the
//! table's missing values); a null Int or Bool is an error naming the column and the row.
//! Files compressed with Snappy or not at all can be read; other codecs (zstd, gzip, ...) are
//! not built in.

use std::fs::File;
use std::panic::AssertUnwindSafe;
use std::path::Path;
use std::sync::Arc;

use parquet::basic::{Compression, ConvertedType, LogicalType, Repetition, Type as Physical};
use parquet::column::reader::{ColumnReader, ColumnReaderImpl};
use parquet::column::writer::ColumnWriter;
use parquet::data_type::{ByteArray, DataType};
use parquet::errors::ParquetError;
use parquet::file::properties::WriterProperties;
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::{ColumnDescriptor, Type};

use super::{write_atomic, ColumnData, Table};
use crate::error::{Error, Result};

impl Table {
    /// Writes the table as Parquet to `path`, atomically (see the [module](super) doc).
    pub fn write_parquet(&self, path: &Path) -> Result<()> {
        self.check(path)?;
        let fail = |e: ParquetError| Error::Other(format!("writing {}: {e}", path.display()));
        let schema = Arc::new(self.parquet_schema().map_err(fail)?);
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .build();
        write_atomic(path, |file| {
            let mut w = SerializedFileWriter::new(file, schema, Arc::new(props)).map_err(fail)?;
            if self.rows() > 0 {
                let mut group = w.next_row_group().map_err(fail)?;
                for column in &self.columns {
                    let mut c = group
                        .next_column()
                        .map_err(fail)?
                        .ok_or_else(|| fail(ParquetError::General("too few columns".into())))?;
                    write_column(c.untyped(), column).map_err(fail)?;
                    c.close().map_err(fail)?;
                }
                group.close().map_err(fail)?;
            }
            // Writes the footer and returns the file.
            w.into_inner().map_err(fail)
        })
    }

    /// Reads a Parquet table from `path` (see the module doc for the column types it takes).
    pub fn read_parquet(path: &Path) -> Result<Table> {
        let file =
            File::open(path).map_err(|e| Error::io(format!("reading {}", path.display()), e))?;
        // The parquet crate panics on some corrupt files rather than returning an error (seen
        // by flipping single bytes of a valid file: a dictionary-encoded page without its
        // dictionary); such a panic becomes this error, so that one bad file fails alone.
        std::panic::catch_unwind(AssertUnwindSafe(|| read_file(path, file))).unwrap_or_else(
            |panic| {
                let what = (panic.downcast_ref::<&str>().copied())
                    .or(panic.downcast_ref::<String>().map(String::as_str))
                    .unwrap_or("a panic");
                Err(Error::Other(format!(
                    "{}: not a readable Parquet file: the decoder failed: {what}",
                    path.display()
                )))
            },
        )
    }

    /// One REQUIRED leaf per column.
    fn parquet_schema(&self) -> parquet::errors::Result<Type> {
        let fields = self.names.iter().zip(&self.columns).map(|(name, column)| {
            let (physical, text) = match column {
                ColumnData::Float(_) => (Physical::DOUBLE, false),
                ColumnData::Int(_) => (Physical::INT64, false),
                ColumnData::Bool(_) => (Physical::BOOLEAN, false),
                ColumnData::Text(_) => (Physical::BYTE_ARRAY, true),
            };
            let mut field =
                Type::primitive_type_builder(name, physical).with_repetition(Repetition::REQUIRED);
            if text {
                field = field
                    .with_converted_type(ConvertedType::UTF8)
                    .with_logical_type(Some(LogicalType::String));
            }
            field.build().map(Arc::new)
        });
        Type::group_type_builder("schema")
            .with_fields(fields.collect::<parquet::errors::Result<_>>()?)
            .build()
    }
}

fn read_file(path: &Path, file: File) -> Result<Table> {
    let unreadable = |what: String| {
        Error::Other(format!(
            "{}: not a readable Parquet file: {what}",
            path.display()
        ))
    };
    let size = file.metadata().map(|m| m.len()).unwrap_or(0);
    let reader = SerializedFileReader::new(file).map_err(|e| unreadable(e.to_string()))?;
    let meta = reader.metadata();
    let schema = meta.file_metadata().schema_descr();
    let mut table = Table::default();
    // A flat schema: root field j is leaf column j.
    for (j, field) in schema.root_schema().get_fields().iter().enumerate() {
        let column = (field.is_primitive() && j < schema.num_columns())
            .then(|| empty_column(&schema.column(j)))
            .flatten()
            .ok_or_else(|| {
                Error::Other(format!(
                    "{}: column '{}' is {}, which a run table cannot hold \
                     (DOUBLE, INT64, BOOLEAN or a UTF-8 string, not repeated)",
                    path.display(),
                    field.name(),
                    describe(field)
                ))
            })?;
        table.push(field.name(), column);
    }
    let mut first_row = 0;
    for g in 0..meta.num_row_groups() {
        let group_meta = meta.row_group(g);
        let rows = usize::try_from(group_meta.num_rows())
            .map_err(|_| unreadable(format!("row group {g} has a negative row count")))?;
        let group = reader
            .get_row_group(g)
            .map_err(|e| unreadable(e.to_string()))?;
        for (j, (name, column)) in table.names.iter().zip(&mut table.columns).enumerate() {
            // The bounds the crate asserts (a panic) before it reads a chunk.
            let chunk = group_meta.column(j);
            let start = chunk
                .dictionary_page_offset()
                .unwrap_or(chunk.data_page_offset());
            let len = chunk.compressed_size();
            if start < 0 || len < 0 || start.saturating_add(len) as u64 > size {
                return Err(unreadable(format!(
                    "column '{name}', row group {g}: bytes {start} + {len} lie outside the \
                     file of {size} bytes"
                )));
            }
            let descr = schema.column(j);
            let read = group
                .get_column_reader(j)
                .map_err(Bad::Decode)
                .and_then(|r| append(column, r, rows, &descr));
            read.map_err(|bad| match bad {
                Bad::Decode(e) => unreadable(format!("column '{name}': {e}")),
                Bad::Value(row, what) => Error::Other(format!(
                    "{}: column '{name}', row {}: {what}",
                    path.display(),
                    first_row + row
                )),
            })?;
        }
        first_row += rows;
    }
    Ok(table)
}

fn write_column(w: &mut ColumnWriter<'_>, column: &ColumnData) -> parquet::errors::Result<()> {
    let written = match (w, column) {
        (ColumnWriter::DoubleColumnWriter(w), ColumnData::Float(v)) => w.write_batch(v, None, None),
        (ColumnWriter::Int64ColumnWriter(w), ColumnData::Int(v)) => w.write_batch(v, None, None),
        (ColumnWriter::BoolColumnWriter(w), ColumnData::Bool(v)) => w.write_batch(v, None, None),
        (ColumnWriter::ByteArrayColumnWriter(w), ColumnData::Text(v)) => {
            let bytes: Vec<ByteArray> = v.iter().map(|s| ByteArray::from(s.as_bytes())).collect();
            w.write_batch(&bytes, None, None)
        }
        _ => Err(ParquetError::General(
            "a column writer of another type than its column".into(),
        )),
    };
    written.map(|_| ())
}

/// The empty column for a Parquet leaf, or None for a type a run table cannot hold.
fn empty_column(c: &ColumnDescriptor) -> Option<ColumnData> {
    use ConvertedType as C;
    if c.max_rep_level() > 0 || c.max_def_level() > 1 {
        return None;
    }
    let logical = c.logical_type_ref();
    let integer = matches!(logical, None | Some(LogicalType::Integer(_)))
        && matches!(
            c.converted_type(),
            C::NONE
                | C::INT_8
                | C::INT_16
                | C::INT_32
                | C::INT_64
                | C::UINT_8
                | C::UINT_16
                | C::UINT_32
                | C::UINT_64
        );
    let string = matches!(logical, Some(LogicalType::String)) || c.converted_type() == C::UTF8;
    Some(match c.physical_type() {
        Physical::DOUBLE | Physical::FLOAT if logical.is_none() => ColumnData::Float(Vec::new()),
        Physical::INT32 | Physical::INT64 if integer => ColumnData::Int(Vec::new()),
        Physical::BOOLEAN if logical.is_none() => ColumnData::Bool(Vec::new()),
        Physical::BYTE_ARRAY if string => ColumnData::Text(Vec::new()),
        _ => return None,
    })
}

/// Whether an integer leaf holds unsigned values (stored in the signed physical type).
fn unsigned(c: &ColumnDescriptor) -> bool {
    use ConvertedType as C;
    matches!(
        c.converted_type(),
        C::UINT_8 | C::UINT_16 | C::UINT_32 | C::UINT_64
    ) || matches!(c.logical_type_ref(), Some(LogicalType::Integer(t)) if !t.is_signed)
}

/// "INT32 (DATE)", "BYTE_ARRAY", "a group", "a repeated INT64": a field's type, for messages.
fn describe(field: &Type) -> String {
    let info = field.get_basic_info();
    if !field.is_primitive() {
        return "a group".to_owned();
    }
    let repeated = if info.repetition() == Repetition::REPEATED {
        "a repeated "
    } else {
        ""
    };
    match info.logical_type_ref() {
        Some(l) => format!("{repeated}{} ({l:?})", field.get_physical_type()),
        None if info.converted_type() != ConvertedType::NONE => format!(
            "{repeated}{} ({})",
            field.get_physical_type(),
            info.converted_type()
        ),
        None => format!("{repeated}{}", field.get_physical_type()),
    }
}

/// Why a column chunk cannot be read: the file is broken, or a value does not fit the table
/// (its row within the row group and what is wrong).
enum Bad {
    Decode(ParquetError),
    Value(usize, String),
}

/// Appends a row group's chunk to the column that [`empty_column`] made for its leaf.
fn append(
    column: &mut ColumnData,
    r: ColumnReader,
    rows: usize,
    descr: &ColumnDescriptor,
) -> Result<(), Bad> {
    let (optional, unsigned) = (descr.max_def_level() > 0, unsigned(descr));
    let too_big = |x: u64| format!("{x} does not fit a 64-bit integer");
    match (column, r) {
        (ColumnData::Float(v), ColumnReader::DoubleColumnReader(mut r)) => {
            fill(v, read(&mut r, rows, optional)?, Some(f64::NAN), Ok)
        }
        (ColumnData::Float(v), ColumnReader::FloatColumnReader(mut r)) => {
            fill(v, read(&mut r, rows, optional)?, Some(f64::NAN), |x| {
                Ok(f64::from(x))
            })
        }
        (ColumnData::Int(v), ColumnReader::Int64ColumnReader(mut r)) => {
            // An unsigned value is stored in the bits of an i64.
            let convert = |x: i64| match unsigned {
                true => i64::try_from(x as u64).map_err(|_| too_big(x as u64)),
                false => Ok(x),
            };
            fill(v, read(&mut r, rows, optional)?, None, convert)
        }
        (ColumnData::Int(v), ColumnReader::Int32ColumnReader(mut r)) => {
            let convert = |x: i32| match unsigned {
                true => Ok(i64::from(x as u32)),
                false => Ok(i64::from(x)),
            };
            fill(v, read(&mut r, rows, optional)?, None, convert)
        }
        (ColumnData::Bool(v), ColumnReader::BoolColumnReader(mut r)) => {
            fill(v, read(&mut r, rows, optional)?, None, Ok)
        }
        (ColumnData::Text(v), ColumnReader::ByteArrayColumnReader(mut r)) => {
            let convert = |b: ByteArray| {
                b.as_utf8()
                    .map(str::to_owned)
                    .map_err(|_| "not valid UTF-8".to_owned())
            };
            fill(
                v,
                read(&mut r, rows, optional)?,
                Some(String::new()),
                convert,
            )
        }
        (column, _) => Err(Bad::Decode(ParquetError::General(format!(
            "a chunk of another physical type than the {} column",
            column.type_name()
        )))),
    }
}

/// A chunk's values (non-null only) and, for an optional column, its definition levels.
struct Chunk<T> {
    values: Vec<T>,
    levels: Option<Vec<i16>>,
}

/// Reads `rows` records of a flat column.
fn read<T: DataType>(
    r: &mut ColumnReaderImpl<T>,
    rows: usize,
    optional: bool,
) -> Result<Chunk<T::T>, Bad> {
    let mut chunk = Chunk {
        values: Vec::with_capacity(rows),
        levels: optional.then(|| Vec::with_capacity(rows)),
    };
    let mut done = 0;
    while done < rows {
        let (records, _, _) = r
            .read_records(rows - done, chunk.levels.as_mut(), None, &mut chunk.values)
            .map_err(Bad::Decode)?;
        if records == 0 {
            let what = format!("the chunk ends after {done} of {rows} rows");
            return Err(Bad::Decode(ParquetError::General(what)));
        }
        done += records;
    }
    Ok(chunk)
}

/// Appends a chunk's values, converted, with `null` (or an error without one) for nulls.
fn fill<T, U: Clone>(
    out: &mut Vec<U>,
    chunk: Chunk<T>,
    null: Option<U>,
    convert: impl Fn(T) -> Result<U, String>,
) -> Result<(), Bad> {
    let count = chunk.values.len();
    let mut values = chunk.values.into_iter();
    let mut next = |row: usize| {
        let x = values.next().ok_or_else(|| {
            Bad::Decode(ParquetError::General(
                "fewer values than the definition levels say".into(),
            ))
        })?;
        convert(x).map_err(|what| Bad::Value(row, what))
    };
    match chunk.levels {
        None => {
            out.reserve(count);
            for row in 0..count {
                out.push(next(row)?);
            }
        }
        Some(levels) => {
            out.reserve(levels.len());
            for (row, level) in levels.into_iter().enumerate() {
                if level > 0 {
                    out.push(next(row)?);
                } else {
                    let null = null.clone();
                    out.push(null.ok_or_else(|| Bad::Value(row, "null value".into()))?);
                }
            }
        }
    }
    Ok(())
}
