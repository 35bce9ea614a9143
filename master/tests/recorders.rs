//! Recorders are interchangeable observers of a run: the in-memory recorder holds exactly what
//! the CSV file holds, a user-written recorder (here a statistics accumulator) sees the same
//! rows, and both algorithms feed them alike.
mod common;
use common::*;
use shipsim::model_description::VarType;
use shipsim::run::{
    prepare, run, run_into, ColumnInfo, MemoryRecorder, Output, Recorder, Row, RunOptions,
};
use shipsim::system::System;

const SYSTEM: &str = r#"
connections = ["a.n_out -> b.n_in", "a.enabled_out -> b.enabled", { from = "a.y", to = "b.u", gain = 0.5, offset = 0.25 }]
[simulation]
stop_time = 1.0
step_size = 0.1
algorithm = "ALGO"
[[instances]]
name = "a"
fmu = "testfmu.fmu"
parameters = { n_in = 7, u = 1.0 }
[[instances]]
name = "b"
fmu = "testfmu.fmu"
step_multiple = 3
[[events]]
time = 0.7
set = "a.enabled"
value = false
[output]
variables = ["a.y", "a.enabled_out", "b.y", "b.n_out", "b.enabled_out"]
decimation = 2
"#;

/// Per column: the number of rows, the last value, and the largest value.
#[derive(Default)]
struct Stats {
    names: Vec<String>,
    rows: usize,
    last: Vec<f64>,
    max: Vec<f64>,
    finished: bool,
}

impl Recorder for Stats {
    fn start(&mut self, columns: &[ColumnInfo], _rows: u64) -> shipsim::Result<()> {
        self.names = columns.iter().map(|c| c.name.clone()).collect();
        self.last = vec![f64::NAN; columns.len()];
        self.max = vec![f64::NEG_INFINITY; columns.len()];
        Ok(())
    }
    fn record(&mut self, _time: f64, row: &Row<'_>) -> shipsim::Result<()> {
        self.rows += 1;
        for (j, v) in row.iter().enumerate() {
            self.last[j] = v.as_f64();
            self.max[j] = self.max[j].max(v.as_f64());
        }
        Ok(())
    }
    fn finish(&mut self) -> shipsim::Result<()> {
        self.finished = true;
        Ok(())
    }
}

#[test]
fn memory_and_statistics_recorders_see_exactly_the_csv_rows() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    for algo in ["jacobi", "gauss-seidel"] {
        let p = write_system(d.path(), "r.toml", &SYSTEM.replace("ALGO", algo));
        let (plan, fmus) = prepare(&System::load(&p).unwrap()).unwrap();
        let csv = d.path().join(format!("{algo}.csv"));
        let s_csv = run(
            &plan,
            &fmus,
            Output::File(csv.clone()),
            &RunOptions::default(),
        )
        .unwrap();
        let mut mem = MemoryRecorder::new();
        let s_mem = run_into(&plan, &fmus, Some(&mut mem), &RunOptions::default()).unwrap();
        let mut stats = Stats::default();
        run_into(&plan, &fmus, Some(&mut stats), &RunOptions::default()).unwrap();

        let (header, rows) = read_csv(&csv);
        // t = 0, 0.2, ..., 1.0: decimation 2 over 10 steps.
        assert_eq!(rows.len(), 6, "{algo}");
        assert_eq!((s_csv.rows, s_mem.rows), (6, 6), "{algo}");
        assert_eq!(mem.time, rows.iter().map(|r| r[0]).collect::<Vec<_>>());
        assert_eq!(mem.columns.len() + 1, header.len());
        for (j, c) in mem.columns.iter().enumerate() {
            assert_eq!(c.name, header[j + 1]);
            let from_csv: Vec<f64> = rows.iter().map(|r| r[j + 1]).collect();
            assert_eq!(mem.data[j], from_csv, "{algo}: column {}", c.name);
            assert_eq!(mem.column(&c.name), Some(&from_csv[..]));
        }
        let types: Vec<VarType> = mem.columns.iter().map(|c| c.var_type).collect();
        use VarType::*;
        assert_eq!(types, [Real, Boolean, Real, Integer, Boolean]);
        // the values themselves: b.n_out follows a.n_in = 7, a.enabled_out drops at t = 0.7
        assert_eq!(mem.column("b.n_out").unwrap(), [7.0; 6]);
        assert_eq!(
            mem.column("a.enabled_out").unwrap(),
            [1.0, 1.0, 1.0, 1.0, 0.0, 0.0]
        );
        assert_eq!(stats.rows, 6);
        assert!(stats.finished);
        assert_eq!(stats.names, header[1..]);
        for (j, name) in stats.names.iter().enumerate() {
            let col = mem.column(name).unwrap();
            assert_eq!(stats.last[j], *col.last().unwrap());
            assert_eq!(
                stats.max[j],
                col.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            );
        }
    }
}

#[test]
fn a_memory_recorder_too_long_for_memory_is_an_error_before_the_first_step() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let p = write_system(
        d.path(),
        "long.toml",
        r#"
[simulation]
stop_time = 1e9
step_size = 1e-6
[[instances]]
name = "a"
fmu = "testfmu.fmu"
"#,
    );
    let (plan, fmus) = prepare(&System::load(&p).unwrap()).unwrap();
    let mut mem = MemoryRecorder::new();
    let e = run_into(&plan, &fmus, Some(&mut mem), &RunOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("cannot keep 1000000000000001 rows"), "{msg}");
    assert!(msg.contains("rows of 8 columns in memory"), "{msg}");
}

/// A variable named and also matched by `inst.*`, or named twice, is one column, at its first
/// place. Before, it was recorded once per match (the header had `a.y` twice).
#[test]
fn a_variable_matched_twice_is_recorded_once() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let text = SYSTEM.replace("ALGO", "jacobi").replace(
        r#"variables = ["a.y", "a.enabled_out", "b.y", "b.n_out", "b.enabled_out"]"#,
        r#"variables = ["a.y", "b.y", "a.*", "b.y", "a.y"]"#,
    );
    let p = write_system(d.path(), "r.toml", &text);
    let (plan, fmus) = prepare(&System::load(&p).unwrap()).unwrap();
    let mut mem = MemoryRecorder::new();
    run_into(&plan, &fmus, Some(&mut mem), &RunOptions::default()).unwrap();
    let names: Vec<&str> = mem.columns.iter().map(|c| c.name.as_str()).collect();
    // a.* is y, t_last, grid_error, y2, steps, n_out, enabled_out (the test FMU's outputs, in
    // its model description's order); a.y and b.y keep their first places.
    assert_eq!(
        names,
        [
            "a.y",
            "b.y",
            "a.t_last",
            "a.grid_error",
            "a.y2",
            "a.steps",
            "a.n_out",
            "a.enabled_out"
        ]
    );
}
