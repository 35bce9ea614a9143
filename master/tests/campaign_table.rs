//! The run table's files (CSV, Parquet): round trips bit for bit, the exact text of CSV cells,
//! type inference, empty tables, bad files, atomic writes. `write_fixture` also writes the files
//! that tests/python/test_campaign_table.py reads with pandas and polars.
//!
//! Every expected value here is a literal; floats are compared by `f64::to_bits` (tolerance 0).
use std::path::{Path, PathBuf};

use shipsim::campaign::table::{ColumnData, Table};

/// Floats that printing and parsing get wrong most easily: signed zero, the smallest
/// subnormal, the largest finite value, whole numbers (`3.0` must stay Float), numbers whose
/// `{:?}` form has an exponent, NaN and the infinities.
const FLOATS: [f64; 12] = [
    0.1,
    -0.0,
    0.0,
    1e-300,
    3.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e16,
    5e-324,
    f64::MAX,
    -1.2345678901234567e-7,
];

/// Whole numbers only: a Float column that must not read back as Int.
const WHOLE: [f64; 12] = [
    3.0,
    -0.0,
    0.0,
    1e15,
    -2.0,
    42.0,
    7.0,
    8.0,
    9.0,
    10.0,
    9007199254740992.0,
    -1.0,
];

const TEXTS: [&str; 12] = [
    "plain",
    "comma, here",
    "quote \"q\" inside",
    "line\nbreak",
    "unicode: ø ψ 🚢",
    "",
    "  spaces  ",
    "crlf\r\nend",
    "\"",
    "true",
    "12",
    "x;y\tz",
];

fn table() -> Table {
    let mut t = Table::default();
    t.push("x", ColumnData::Float(FLOATS.to_vec()));
    t.push("whole", ColumnData::Float(WHOLE.to_vec()));
    t.push(
        "n",
        ColumnData::Int(vec![
            0,
            -1,
            i64::MAX,
            i64::MIN,
            42,
            7,
            8,
            9,
            10,
            11,
            12,
            -13,
        ]),
    );
    t.push(
        "ok",
        ColumnData::Bool(vec![
            true, false, true, true, false, false, true, false, true, false, true, false,
        ]),
    );
    t.push(
        "message, \"quoted\"",
        ColumnData::Text(TEXTS.iter().map(|s| s.to_string()).collect()),
    );
    t
}

/// Names, types and values equal, floats by their bits.
fn assert_same(got: &Table, want: &Table) {
    assert_eq!(got.names, want.names);
    assert_eq!(got.columns.len(), want.columns.len());
    for ((name, g), w) in got.names.iter().zip(&got.columns).zip(&want.columns) {
        match (g, w) {
            (ColumnData::Float(g), ColumnData::Float(w)) => {
                let g: Vec<u64> = g.iter().map(|x| x.to_bits()).collect();
                let w: Vec<u64> = w.iter().map(|x| x.to_bits()).collect();
                assert_eq!(g, w, "column '{name}' (bits)");
            }
            _ => assert_eq!(g, w, "column '{name}'"),
        }
    }
}

fn error_of(r: shipsim::Result<Table>) -> String {
    match r {
        Ok(t) => panic!("expected an error, read {t:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn csv_round_trip_keeps_bits_and_types() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("runs.csv");
    table().write_csv(&p).unwrap();
    assert_same(&Table::read_csv(&p).unwrap(), &table());
    assert_same(&Table::read(&p).unwrap(), &table());
}

#[test]
fn parquet_round_trip_keeps_bits_and_types() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("runs.parquet");
    table().write_parquet(&p).unwrap();
    assert_same(&Table::read_parquet(&p).unwrap(), &table());
    assert_same(&Table::read(&p).unwrap(), &table());
}

#[test]
fn parquet_keeps_nan_payloads_and_signs() {
    // A negative NaN and two NaNs with payloads, beside 0.0 and -0.0 (a dictionary encoder that
    // compared floats by value would merge those).
    let bits = [
        0x7ff8_0000_0000_0000_u64,
        0xfff8_0000_0000_0000,
        0x7ff8_0000_0000_0001,
        0x7ff0_0000_dead_beef,
        0x0000_0000_0000_0000,
        0x8000_0000_0000_0000,
        0x0000_0000_0000_0000,
        0x8000_0000_0000_0000,
    ];
    let mut t = Table::default();
    t.push(
        "x",
        ColumnData::Float(bits.iter().map(|&b| f64::from_bits(b)).collect()),
    );
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("nan.parquet");
    t.write_parquet(&p).unwrap();
    let Some(ColumnData::Float(back)) = Table::read_parquet(&p).unwrap().column("x").cloned()
    else {
        panic!("x is not a Float column");
    };
    let back: Vec<u64> = back.iter().map(|x| x.to_bits()).collect();
    assert_eq!(back, bits);
}

#[test]
fn parquet_round_trip_of_many_rows_and_distinct_values() {
    // 100 000 rows: past the writer's default page and dictionary sizes, so the plain-encoding
    // fallback is exercised too. The values are 1/(i+1) and i*i.
    let n = 100_000;
    let mut t = Table::default();
    t.push(
        "inv",
        ColumnData::Float((0..n).map(|i| 1.0 / (i as f64 + 1.0)).collect()),
    );
    t.push("sq", ColumnData::Int((0..n).map(|i| i * i).collect()));
    t.push(
        "label",
        ColumnData::Text((0..n).map(|i| format!("run-{i}")).collect()),
    );
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("big.parquet");
    t.write_parquet(&p).unwrap();
    assert_same(&Table::read_parquet(&p).unwrap(), &t);
    let q = d.path().join("big.csv");
    t.write_csv(&q).unwrap();
    assert_same(&Table::read_csv(&q).unwrap(), &t);
}

#[test]
fn csv_cells_are_written_in_the_documented_form() {
    let mut t = Table::default();
    t.push(
        "x",
        ColumnData::Float(vec![
            3.0,
            -0.0,
            0.1,
            1e-300,
            1e16,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ]),
    );
    t.push("n", ColumnData::Int(vec![3, -7, 0, 1, 2, 3, 4, 5]));
    t.push(
        "b",
        ColumnData::Bool(vec![true, false, true, true, true, true, true, false]),
    );
    t.push(
        "s",
        ColumnData::Text(
            [
                "a,b",
                "say \"hi\"",
                "two\nlines",
                "plain",
                "",
                "ø",
                " ",
                "x",
            ]
            .map(String::from)
            .to_vec(),
        ),
    );
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("cells.csv");
    t.write_csv(&p).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    assert_eq!(
        text,
        "x,n,b,s\n\
         3.0,3,true,\"a,b\"\n\
         -0.0,-7,false,\"say \"\"hi\"\"\"\n\
         0.1,0,true,\"two\nlines\"\n\
         1e-300,1,true,plain\n\
         1e16,2,true,\n\
         NaN,3,true,ø\n\
         inf,4,true, \n\
         -inf,5,false,x\n"
    );
}

#[test]
fn csv_infers_column_types_from_cells() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("foreign.csv");
    std::fs::write(
        &p,
        "int,float,mixed,bool,text,blank\n\
         1,1.5,1,true,x,\n\
         -2,NaN,2.5,FALSE,1,\n\
         +3,-inf,3,True,2,\n",
    )
    .unwrap();
    let t = Table::read_csv(&p).unwrap();
    let want = [
        ColumnData::Int(vec![1, -2, 3]),
        ColumnData::Float(vec![1.5, f64::NAN, f64::NEG_INFINITY]),
        ColumnData::Float(vec![1.0, 2.5, 3.0]),
        ColumnData::Bool(vec![true, false, true]),
        ColumnData::Text(vec!["x".into(), "1".into(), "2".into()]),
        ColumnData::Text(vec![String::new(); 3]),
    ];
    let mut expected = Table::default();
    for (name, c) in ["int", "float", "mixed", "bool", "text", "blank"]
        .iter()
        .zip(want)
    {
        expected.push(*name, c);
    }
    assert_same(&t, &expected);
}

#[test]
fn a_single_text_column_of_empty_strings_survives_csv() {
    // Each record is one empty field: written as `""` so that it is not an empty line.
    let mut t = Table::default();
    t.push("only", ColumnData::Text(vec![String::new(); 3]));
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("empty_cells.csv");
    t.write_csv(&p).unwrap();
    assert_same(&Table::read_csv(&p).unwrap(), &t);
}

#[test]
fn empty_tables() {
    let d = tempfile::tempdir().unwrap();
    // No columns: an empty CSV file; a Parquet file with an empty schema.
    for name in ["none.csv", "none.parquet"] {
        let p = d.path().join(name);
        Table::default().write(&p).unwrap();
        assert_eq!(Table::read(&p).unwrap(), Table::default(), "{name}");
    }
    assert_eq!(std::fs::read(d.path().join("none.csv")).unwrap(), b"");
    // Columns without rows: Parquet keeps the types; CSV keeps the names and reads Text.
    let mut t = Table::default();
    t.push("x", ColumnData::Float(vec![]));
    t.push("n", ColumnData::Int(vec![]));
    t.push("ok", ColumnData::Bool(vec![]));
    t.push("s", ColumnData::Text(vec![]));
    let p = d.path().join("rows0.parquet");
    t.write_parquet(&p).unwrap();
    assert_same(&Table::read_parquet(&p).unwrap(), &t);
    let p = d.path().join("rows0.csv");
    t.write_csv(&p).unwrap();
    assert_eq!(std::fs::read_to_string(&p).unwrap(), "x,n,ok,s\n");
    let back = Table::read_csv(&p).unwrap();
    assert_eq!(back.names, ["x", "n", "ok", "s"]);
    assert_eq!(back.columns, vec![ColumnData::Text(vec![]); 4]);
}

#[test]
fn truncated_and_garbage_files_give_errors_naming_the_file() {
    let d = tempfile::tempdir().unwrap();
    let pq = d.path().join("runs.parquet");
    table().write_parquet(&pq).unwrap();
    let bytes = std::fs::read(&pq).unwrap();
    for (name, content) in [
        ("half.parquet", &bytes[..bytes.len() / 2]),
        ("tail_cut.parquet", &bytes[..bytes.len() - 1]),
        ("head_only.parquet", &bytes[..4]),
        ("empty.parquet", &b""[..]),
        ("text.parquet", &b"x,n\n1,2\n"[..]),
    ] {
        let p = d.path().join(name);
        std::fs::write(&p, content).unwrap();
        let e = error_of(Table::read_parquet(&p));
        assert!(
            e.contains(&p.display().to_string()) && e.contains("not a readable Parquet file"),
            "{name}: {e}"
        );
    }

    let csv = d.path().join("runs.csv");
    table().write_csv(&csv).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    // Cut after the first field of the record of 1e-300: that record has 1 field of 5.
    let start = text.find("\n1e-300,").unwrap();
    let p = d.path().join("cut.csv");
    std::fs::write(&p, &text[..start + "\n1e-300".len()]).unwrap();
    let e = error_of(Table::read_csv(&p));
    assert!(
        e.contains(&p.display().to_string()) && e.contains("found record with 1 field"),
        "{e}"
    );
    // A binary file (the Parquet bytes) is not UTF-8.
    let p = d.path().join("binary.csv");
    std::fs::write(&p, &bytes).unwrap();
    let e = error_of(Table::read_csv(&p));
    assert!(
        e.contains(&p.display().to_string()) && e.contains("UTF-8"),
        "{e}"
    );
    // Missing files.
    for name in ["missing.csv", "missing.parquet"] {
        let p = d.path().join(name);
        let e = error_of(Table::read(&p));
        assert!(e.contains(&format!("reading {}", p.display())), "{e}");
    }
}

#[test]
fn parquet_with_any_single_byte_flipped_reads_or_fails_naming_the_file() {
    // Every byte of a small file, flipped in turn: the read returns the table, other values or
    // an error naming the file; a panic inside the parquet crate must not escape.
    let mut t = Table::default();
    t.push("x", ColumnData::Float(vec![1.0, 2.5, f64::NAN, 4.0]));
    t.push("n", ColumnData::Int(vec![1, 2, 3, 4]));
    t.push("ok", ColumnData::Bool(vec![true, false, true, true]));
    t.push(
        "s",
        ColumnData::Text(["a", "bb", "", "ccc"].map(String::from).to_vec()),
    );
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("good.parquet");
    t.write_parquet(&p).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    let q = d.path().join("flipped.parquet");
    let mut failed = 0;
    for i in 0..bytes.len() {
        let mut b = bytes.clone();
        b[i] ^= 0xff;
        std::fs::write(&q, &b).unwrap();
        if let Err(e) = Table::read_parquet(&q) {
            let e = e.to_string();
            assert!(
                e.starts_with(&format!("{}: ", q.display())),
                "byte {i}: {e}"
            );
            failed += 1;
        }
    }
    // Most flips break the file (the footer, the page headers, the magic numbers).
    assert!(failed > bytes.len() / 4, "{failed} of {}", bytes.len());
}

#[test]
fn unknown_extensions_are_refused_by_name() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("runs.xlsx");
    let e = table().write(&p).unwrap_err().to_string();
    assert!(
        e.contains("runs.xlsx") && e.contains(".csv or .parquet"),
        "{e}"
    );
    assert!(!p.exists());
    let e = error_of(Table::read(&p));
    assert!(e.contains("runs.xlsx"), "{e}");
}

/// Files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn writes_replace_whole_files_and_a_failed_write_changes_nothing() {
    let d = tempfile::tempdir().unwrap();
    let mut small = Table::default();
    small.push("a", ColumnData::Int(vec![1]));
    let mut ragged = table();
    ragged.columns[3] = ColumnData::Bool(vec![true]);
    for name in ["runs.csv", "runs.parquet"] {
        let p = d.path().join(name);
        table().write(&p).unwrap();
        small.write(&p).unwrap();
        assert_eq!(Table::read(&p).unwrap(), small, "{name}");
        let before = std::fs::read(&p).unwrap();
        let e = ragged.write(&p).unwrap_err().to_string();
        assert!(
            e.contains(name) && e.contains("column 'ok' has 1 rows, the first column 12"),
            "{e}"
        );
        assert_eq!(std::fs::read(&p).unwrap(), before, "{name}");
    }
    // A stale temporary file from a crash is overwritten, and none is left behind.
    std::fs::write(d.path().join("runs.csv.tmp"), "half a ta").unwrap();
    table().write_csv(&d.path().join("runs.csv")).unwrap();
    assert_eq!(listing(d.path()), ["runs.csv", "runs.parquet"]);
    // A directory that does not exist: an error naming the temporary file, nothing written.
    let p = d.path().join("no_such_dir").join("runs.parquet");
    let e = table().write(&p).unwrap_err().to_string();
    assert!(e.contains(&format!("creating {}.tmp", p.display())), "{e}");
    let mut mismatched = small.clone();
    mismatched.names.push("extra".into());
    let e = mismatched
        .write(&d.path().join("m.csv"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("m.csv") && e.contains("2 names for 1 columns"),
        "{e}"
    );
    assert_eq!(listing(d.path()), ["runs.csv", "runs.parquet"]);
}

/// One column chunk for [`write_raw`]: the non-null values, and the definition levels of an
/// optional column (1 = a value, 0 = null).
enum Chunk {
    F32(Vec<f32>, Option<Vec<i16>>),
    F64(Vec<f64>, Option<Vec<i16>>),
    I32(Vec<i32>, Option<Vec<i16>>),
    I64(Vec<i64>, Option<Vec<i16>>),
    Bytes(Vec<&'static [u8]>, Option<Vec<i16>>),
}

/// Writes a Parquet file as another writer might: the schema in Parquet's message syntax, and
/// one list of column chunks per row group.
fn write_raw(path: &Path, message: &str, groups: Vec<Vec<Chunk>>) {
    use parquet::column::writer::ColumnWriter as W;
    let schema = std::sync::Arc::new(parquet::schema::parser::parse_message_type(message).unwrap());
    let file = std::fs::File::create(path).unwrap();
    let mut w =
        parquet::file::writer::SerializedFileWriter::new(file, schema, Default::default()).unwrap();
    for chunks in groups {
        let mut group = w.next_row_group().unwrap();
        for chunk in chunks {
            let mut c = group.next_column().unwrap().unwrap();
            match (c.untyped(), chunk) {
                (W::FloatColumnWriter(w), Chunk::F32(v, l)) => {
                    w.write_batch(&v, l.as_deref(), None)
                }
                (W::DoubleColumnWriter(w), Chunk::F64(v, l)) => {
                    w.write_batch(&v, l.as_deref(), None)
                }
                (W::Int32ColumnWriter(w), Chunk::I32(v, l)) => {
                    w.write_batch(&v, l.as_deref(), None)
                }
                (W::Int64ColumnWriter(w), Chunk::I64(v, l)) => {
                    w.write_batch(&v, l.as_deref(), None)
                }
                (W::ByteArrayColumnWriter(w), Chunk::Bytes(v, l)) => {
                    let v: Vec<parquet::data_type::ByteArray> =
                        v.into_iter().map(Into::into).collect();
                    w.write_batch(&v, l.as_deref(), None)
                }
                _ => panic!("chunk of another type than its column"),
            }
            .unwrap();
            c.close().unwrap();
        }
        group.close().unwrap();
    }
    w.close().unwrap();
}

#[test]
fn parquet_from_other_writers_reads_close_types_and_nulls() {
    use Chunk::*;
    let d = tempfile::tempdir().unwrap();
    // Two row groups; nullable float, string and double; INT32; unsigned 64 and 32 bits (an
    // unsigned value is stored in the bits of the signed type: -1 is u32::MAX).
    let p = d.path().join("close.parquet");
    write_raw(
        &p,
        "message m { optional float f32; required int32 i32; \
         required int64 u64 (INTEGER(64,false)); optional binary s (STRING); \
         optional double f64; required int32 u32 (INTEGER(32,false)); }",
        vec![
            vec![
                F32(vec![0.5], Some(vec![1, 0])),
                I32(vec![-3, 4], None),
                I64(vec![0, 1 << 40], None),
                Bytes(vec!["é".as_bytes()], Some(vec![0, 1])),
                F64(vec![-0.0], Some(vec![0, 1])),
                I32(vec![-1, 7], None),
            ],
            vec![
                F32(vec![1.25], Some(vec![1])),
                I32(vec![7], None),
                I64(vec![5], None),
                Bytes(vec![b"x"], Some(vec![1])),
                F64(vec![2.5], Some(vec![1])),
                I32(vec![3], None),
            ],
        ],
    );
    let t = Table::read_parquet(&p).unwrap();
    let mut want = Table::default();
    want.push("f32", ColumnData::Float(vec![0.5, f64::NAN, 1.25]));
    want.push("i32", ColumnData::Int(vec![-3, 4, 7]));
    want.push("u64", ColumnData::Int(vec![0, 1 << 40, 5]));
    want.push(
        "s",
        ColumnData::Text(vec![String::new(), "é".into(), "x".into()]),
    );
    want.push("f64", ColumnData::Float(vec![f64::NAN, -0.0, 2.5]));
    want.push("u32", ColumnData::Int(vec![4294967295, 7, 3]));
    assert_same(&t, &want);

    // Errors name the file, the column and the row counted over all row groups.
    let p = d.path().join("null_int.parquet");
    write_raw(
        &p,
        "message m { optional int32 seed; }",
        vec![
            vec![I32(vec![1], Some(vec![1]))],
            vec![I32(vec![2], Some(vec![1, 0]))],
        ],
    );
    let e = error_of(Table::read_parquet(&p));
    assert!(
        e.contains(&format!(
            "{}: column 'seed', row 2: null value",
            p.display()
        )),
        "{e}"
    );
    let p = d.path().join("big_u64.parquet");
    write_raw(
        &p,
        "message m { required int64 seed (INTEGER(64,false)); }",
        vec![vec![I64(vec![1, -1], None)]],
    );
    let e = error_of(Table::read_parquet(&p));
    assert!(
        e.contains("column 'seed', row 1: 18446744073709551615 does not fit"),
        "{e}"
    );
    let p = d.path().join("bad_utf8.parquet");
    write_raw(
        &p,
        "message m { required binary s (STRING); }",
        vec![vec![Bytes(vec![b"ok", b"\xff"], None)]],
    );
    let e = error_of(Table::read_parquet(&p));
    assert!(e.contains("column 's', row 1: not valid UTF-8"), "{e}");

    // Types a run table cannot hold.
    for (message, what) in [
        ("required int32 day (DATE);", "column 'day' is INT32 (Date)"),
        ("required binary b;", "column 'b' is BYTE_ARRAY,"),
        ("repeated int64 r;", "column 'r' is a repeated INT64"),
        (
            "required group g { required int32 a; }",
            "column 'g' is a group",
        ),
    ] {
        let p = d.path().join("type.parquet");
        write_raw(&p, &format!("message m {{ {message} }}"), vec![]);
        let e = error_of(Table::read_parquet(&p));
        assert!(
            e.contains(&p.display().to_string()) && e.contains(what),
            "{message}: {e}"
        );
    }
}

/// Writes `table.csv`, `table.parquet` and `rows0.parquet` (the columns of the table without
/// rows) for tests/python/test_campaign_table.py, into $SHIPSIM_TABLE_FIXTURE_DIR (set by
/// that test) or `<target>/tmp/campaign-table-fixture`, and checks them here too.
#[test]
fn write_fixture() {
    let dir = std::env::var_os("SHIPSIM_TABLE_FIXTURE_DIR").map_or_else(
        || Path::new(env!("CARGO_TARGET_TMPDIR")).join("campaign-table-fixture"),
        PathBuf::from,
    );
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["table.csv", "table.parquet"] {
        let p = dir.join(name);
        table().write(&p).unwrap();
        assert_same(&Table::read(&p).unwrap(), &table());
    }
    let mut rows0 = table();
    for c in &mut rows0.columns {
        match c {
            ColumnData::Float(v) => v.clear(),
            ColumnData::Int(v) => v.clear(),
            ColumnData::Bool(v) => v.clear(),
            ColumnData::Text(v) => v.clear(),
        }
    }
    let p = dir.join("rows0.parquet");
    rows0.write_parquet(&p).unwrap();
    assert_same(&Table::read_parquet(&p).unwrap(), &rows0);
}
