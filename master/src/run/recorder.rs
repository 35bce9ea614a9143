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

/// One recorded value (a String borrowed from the exchange).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sample<'a> {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(&'a str),
}

impl Sample<'_> {
    /// The value as a number (a Boolean is 0 or 1; a String is not a number: NaN).
    pub fn as_f64(self) -> f64 {
        match self {
            Sample::Real(x) => x,
            Sample::Integer(i) => i as f64,
            Sample::Boolean(b) => b as i32 as f64,
            Sample::String(_) => f64::NAN,
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
    pub fn get(&self, j: usize) -> Sample<'a> {
        match self.columns[j] {
            Column::Real(i) => Sample::Real(self.values.real[i]),
            Column::Integer(i) => Sample::Integer(self.values.integer[i]),
            Column::Boolean(i) => Sample::Boolean(self.values.boolean[i] != 0),
            Column::String(i) => Sample::String(&self.values.string[i]),
        }
    }

    pub fn iter(&self) -> impl Iterator<Item = Sample<'a>> + '_ {
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
/// Header fields are quoted as RFC 4180 says (by the `csv` crate: a name with a comma, a
/// quote or a line break is enclosed in quotes, its quotes doubled), so a name never shifts
/// the columns. Numbers are written in Rust's shortest round-trip digits, so values survive
/// the file exactly ([`write_real`]: plain decimal, with an exponent for very small and very
/// large magnitudes); Booleans are written 0 or 1; Strings as they are, or quoted as RFC 4180
/// says when they hold a comma, a quote or a line break ([`write_text`]).
///
/// The output is flushed at least once a second of wall time ([`FlushClock`]), so a process
/// killed by a crashing FMU loses at most about the last second of rows.
///
/// The writer is any `Write` (by default a boxed one); a stepping session that streams its rows
/// ([`super::Session::record_into`]) needs one that is `Send`.
pub struct CsvRecorder<W: Write = Box<dyn Write>> {
    out: W,
    clock: FlushClock,
}

impl<W: Write> CsvRecorder<W> {
    pub fn new(out: W) -> CsvRecorder<W> {
        CsvRecorder {
            out,
            clock: FlushClock::new(std::time::Duration::from_secs(1)),
        }
    }
}

/// A file created (truncated) on the first write, buffered: a recorder that is never written
/// to leaves what is at the path alone.
pub struct OpenOnWrite {
    path: std::path::PathBuf,
    file: Option<std::io::BufWriter<std::fs::File>>,
}

impl OpenOnWrite {
    pub fn new(path: std::path::PathBuf) -> OpenOnWrite {
        OpenOnWrite { path, file: None }
    }

    fn file(&mut self) -> std::io::Result<&mut std::io::BufWriter<std::fs::File>> {
        if self.file.is_none() {
            let f = std::fs::File::create(&self.path).map_err(|e| {
                std::io::Error::new(
                    e.kind(),
                    format!("cannot create output file {}: {e}", self.path.display()),
                )
            })?;
            self.file = Some(std::io::BufWriter::with_capacity(1 << 16, f));
        }
        Ok(self.file.as_mut().expect("opened above"))
    }
}

impl Write for OpenOnWrite {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.file()?.write(buf)
    }
    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.file()?.write_all(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.file {
            Some(f) => f.flush(),
            None => Ok(()),
        }
    }
}

/// When to flush a stream of rows: when `period` of wall time has passed since the last
/// flush. The clock is read only every `every` rows, a number that adapts so that the reads
/// are between about 10 ms and 100 ms of wall time apart (it doubles when they come faster,
/// halves when slower): a fast run reads the clock once in up to 4,096 rows, a slow one at
/// every row. No allocation.
pub struct FlushClock {
    period: std::time::Duration,
    last_flush: std::time::Instant,
    last_check: std::time::Instant,
    every: u32,
    rows: u32,
}

impl FlushClock {
    pub fn new(period: std::time::Duration) -> FlushClock {
        let now = std::time::Instant::now();
        FlushClock {
            period,
            last_flush: now,
            last_check: now,
            every: 1,
            rows: 0,
        }
    }

    /// Counts one row; true when the stream is due to be flushed.
    #[inline]
    pub fn row(&mut self) -> bool {
        self.rows += 1;
        if self.rows < self.every {
            return false;
        }
        self.rows = 0;
        self.check(std::time::Instant::now())
    }

    #[cold]
    fn check(&mut self, now: std::time::Instant) -> bool {
        let since = now.duration_since(self.last_check);
        self.last_check = now;
        if since < std::time::Duration::from_millis(10) && self.every < 4096 {
            self.every *= 2;
        } else if since > std::time::Duration::from_millis(100) && self.every > 1 {
            self.every /= 2;
        }
        let due = now.duration_since(self.last_flush) >= self.period;
        if due {
            self.last_flush = now;
        }
        due
    }
}

/// Below this magnitude (and above zero) a number is written with an exponent.
const EXP_BELOW: f64 = 1e-6;
/// From this magnitude on a number is written with an exponent.
const EXP_FROM: f64 = 1e21;

/// Writes `x` in its shortest round-trip digits: as plain decimal (`{}`: `0.25`, `-1500`)
/// when 1e-6 <= |x| < 1e21 or x is 0, NaN or infinite, else with an exponent (`{:e}`:
/// `2.2250738585072014e-308`, `1e21`). Both forms parse back to the same `f64`. The
/// thresholds are those of ECMAScript's Number::toString (ECMA-262, sec. 6.1.6.1.20): inside
/// them the decimal form is at most 25 characters, outside them the exponent form is shorter
/// (`DBL_MIN` in decimal is 326 characters). Values in between keep the decimal form the
/// recorder always wrote, so such fields of existing CSVs do not change.
#[inline]
pub fn write_real(out: &mut impl Write, x: f64) -> std::io::Result<()> {
    let a = x.abs();
    if (a < EXP_BELOW && a != 0.0) || (a >= EXP_FROM && a.is_finite()) {
        write!(out, "{x:e}")
    } else {
        write!(out, "{x}")
    }
}

/// Writes a text field of a CSV row as RFC 4180 says (sec. 2, rules 6 and 7): as it is, or, when
/// it holds a comma, a double quote or a line break, enclosed in double quotes with each of its
/// quotes doubled. No allocation.
pub fn write_text(out: &mut impl Write, t: &str) -> std::io::Result<()> {
    if !t.contains([',', '"', '\n', '\r']) {
        return out.write_all(t.as_bytes());
    }
    out.write_all(b"\"")?;
    let mut parts = t.split('"');
    if let Some(first) = parts.next() {
        out.write_all(first.as_bytes())?;
    }
    for part in parts {
        out.write_all(b"\"\"")?;
        out.write_all(part.as_bytes())?;
    }
    out.write_all(b"\"")
}

fn write_error(e: std::io::Error) -> Error {
    Error::io("writing the output file", e)
}

impl<W: Write> Recorder for CsvRecorder<W> {
    fn start(&mut self, columns: &[ColumnInfo], _expected_rows: u64) -> Result<()> {
        let header_error = |e| Error::io("writing the output header", e);
        let mut w = csv::WriterBuilder::new()
            .terminator(csv::Terminator::Any(b'\n'))
            .from_writer(Vec::new());
        let names = std::iter::once("time").chain(columns.iter().map(|c| c.name.as_str()));
        w.write_record(names)
            .map_err(|e| header_error(std::io::Error::other(e)))?;
        let header = w
            .into_inner()
            .map_err(|e| header_error(std::io::Error::other(e.to_string())))?;
        self.out.write_all(&header).map_err(header_error)?;
        self.out.flush().map_err(header_error)
    }

    #[inline]
    fn record(&mut self, time: f64, row: &Row<'_>) -> Result<()> {
        write_real(&mut self.out, time).map_err(write_error)?;
        for v in row.iter() {
            match v {
                Sample::Real(x) => self
                    .out
                    .write_all(b",")
                    .and_then(|()| write_real(&mut self.out, x)),
                Sample::Integer(i) => write!(self.out, ",{i}"),
                Sample::Boolean(b) => write!(self.out, ",{}", b as i32),
                Sample::String(t) => self
                    .out
                    .write_all(b",")
                    .and_then(|()| write_text(&mut self.out, t)),
            }
            .map_err(write_error)?;
        }
        self.out.write_all(b"\n").map_err(write_error)?;
        if self.clock.row() {
            self.out.flush().map_err(write_error)?;
        }
        Ok(())
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
        if let Some(c) = columns.iter().find(|c| c.var_type == VarType::String) {
            return Err(Error::Other(format!(
                "'{}' is a String variable: String variables are recorded into CSV files \
                 (shipsim run -o FILE), not in memory (Python, campaigns)",
                c.name
            )));
        }
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

#[cfg(test)]
mod tests {
    use super::{write_real, write_text};

    /// RFC 4180 text fields, the expected bytes written out by hand.
    #[test]
    fn text_fields_are_quoted_only_when_needed() {
        let field = |t: &str| {
            let mut b = Vec::new();
            write_text(&mut b, t).unwrap();
            String::from_utf8(b).unwrap()
        };
        assert_eq!(field("plain text"), "plain text");
        assert_eq!(field(""), "");
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(field("\"\""), "\"\"\"\"\"\"");
        assert_eq!(field("two\nlines"), "\"two\nlines\"");
        assert_eq!(field("cr\r"), "\"cr\r\"");
    }

    fn text(x: f64) -> String {
        let mut b = Vec::new();
        write_real(&mut b, x).unwrap();
        String::from_utf8(b).unwrap()
    }

    /// The forms chosen at and around the thresholds, written out by hand.
    #[test]
    fn decimal_inside_exponent_outside() {
        assert_eq!(text(f64::MIN_POSITIVE), "2.2250738585072014e-308");
        assert_eq!(text(-5e-324), "-5e-324");
        assert_eq!(text(9.99e-7), "9.99e-7");
        assert_eq!(text(1e-6), "0.000001");
        assert_eq!(text(-1.25e-5), "-0.0000125");
        assert_eq!(text(0.1 + 0.2), "0.30000000000000004");
        assert_eq!(text(-1500.0), "-1500");
        assert_eq!(text(999999999999999900000.0), "999999999999999900000");
        assert_eq!(text(1e21), "1e21");
        assert_eq!(text(f64::MAX), "1.7976931348623157e308");
        assert_eq!(text(0.0), "0");
        assert_eq!(text(-0.0), "-0");
        assert_eq!(text(f64::NAN), "NaN");
        assert_eq!(text(f64::NEG_INFINITY), "-inf");
    }

    /// Every written value parses back to the same bits (NaN to a NaN), and no field is longer
    /// than 25 characters: 200,000 bit patterns spread over the whole range of f64 (a fixed
    /// xorshift sequence), plus the powers of ten around the thresholds.
    #[test]
    fn round_trips_and_stays_short() {
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut values: Vec<f64> = (0..200_000)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                f64::from_bits(state)
            })
            .collect();
        for e in -330..330 {
            let p: f64 = format!("1e{e}").parse().unwrap();
            values.extend([p, -p, p.next_up(), p.next_down()]);
        }
        for x in values {
            let t = text(x);
            let back: f64 = t.parse().unwrap();
            assert!(
                back.to_bits() == x.to_bits() || (x.is_nan() && back.is_nan()),
                "{x:e} written as {t}"
            );
            assert!(
                t.len() <= 25,
                "{x:e} written as {t} ({} characters)",
                t.len()
            );
        }
    }
}
