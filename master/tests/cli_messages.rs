//! What `shipsim run` says about its output and its end (issue 18, points 5, 9 and 10): a run
//! that writes nothing says so, an existing output file is named before it is replaced, an OSP
//! file without `<EndTime>` needs `--stop-time`, the summary of a run an FMU ended early names
//! both the FMU's time and the master's, and a tiny value is a short CSV field.

mod common;

use common::*;
use std::path::Path;
use std::process::{Command, Output};

fn shipsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

const ONE: &str = "[simulation]\nstop_time = 0.5\nstep_size = 0.1\n[[instances]]\nname = \"a\"\nfmu = \"testfmu.fmu\"\n";

/// Without -o and without [output], one line says that nothing is written and how to ask for
/// a file; -q silences it, and --no-output (asked for) does not print it.
#[test]
fn a_run_without_output_says_so() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let sys = write_system(d.path(), "one.toml", ONE);
    let o = shipsim(&["run", path(&sys)]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let notes: Vec<&str> = err.lines().filter(|l| l.contains("no output")).collect();
    assert_eq!(
        notes,
        ["no output requested, nothing will be written: pass -o FILE.csv or add [output] file = \"FILE.csv\" to the system file"],
        "{err}"
    );
    for quiet in [&["-q"][..], &["--no-output"][..]] {
        let o = shipsim(&[&["run", path(&sys)][..], quiet].concat());
        assert!(
            o.status.success() && !stderr(&o).contains("no output"),
            "{quiet:?}: {}",
            stderr(&o)
        );
    }
    // With -o nothing is said about it.
    let csv = d.path().join("out.csv");
    let o = shipsim(&["run", path(&sys), "-o", path(&csv)]);
    assert!(o.status.success() && !stderr(&o).contains("no output") && csv.is_file());
}

/// The second run into the same file says "overwriting FILE" (once); the first does not, nor
/// does a quiet run.
#[test]
fn overwriting_an_output_file_is_said() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let csv = d.path().join("demo/out.csv");
    let sys = write_system(
        d.path(),
        "one.toml",
        &format!("{ONE}[output]\nfile = \"{}\"\n", csv.display()),
    );
    let first = shipsim(&["run", path(&sys)]);
    assert!(
        first.status.success() && !stderr(&first).contains("overwriting"),
        "{}",
        stderr(&first)
    );
    let second = shipsim(&["run", path(&sys)]);
    let err = stderr(&second);
    let lines: Vec<&str> = err.lines().filter(|l| l.contains("overwriting")).collect();
    assert_eq!(lines, [format!("overwriting {}", csv.display())], "{err}");
    let quiet = shipsim(&["run", path(&sys), "-q"]);
    assert!(
        quiet.status.success() && stderr(&quiet).is_empty(),
        "{}",
        stderr(&quiet)
    );
}

/// An OSP file without <EndTime> used to run for 1 s without a word; now it is an error naming
/// the file and --stop-time, and with --stop-time it runs to that time.
#[test]
fn an_osp_file_without_end_time_needs_stop_time() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let xml = write_system(
        d.path(),
        "OspSystemStructure.xml",
        r#"<OspSystemStructure version="0.1"><BaseStepSize>0.1</BaseStepSize><Simulators>
<Simulator name="a" source="testfmu.fmu"/></Simulators></OspSystemStructure>"#,
    );
    let o = shipsim(&["run", path(&xml), "-q"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(&format!("error: {}", xml.display()))
            && err.contains("no <EndTime>")
            && err.contains("--stop-time"),
        "{err}"
    );
    let csv = d.path().join("osp.csv");
    let o = shipsim(&[
        "run",
        path(&xml),
        "-q",
        "--stop-time",
        "0.3",
        "-o",
        path(&csv),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, rows) = read_csv(&csv);
    let times: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(times, [0.0, 0.1, 0.2, 0.3]);
}

/// A multi-rate instance (5 base steps per doStep) ends the run in its step from t = 0.5 s;
/// the master stops at the end of that macro step, t = 0.6 s, which is the last row. The
/// summary says both, and that the run ended early. (The old summary said "simulated 0 s ..
/// 0.6 s" next to "ended the simulation at t = 0.5 s" with nothing joining them.)
#[test]
fn the_summary_of_an_early_end_names_both_times() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let sys = write_system(
        d.path(),
        "term.toml",
        "[simulation]\nstop_time = 2.0\nstep_size = 0.1\n[[instances]]\nname = \"a\"\nfmu = \"testfmu.fmu\"\n\
         [[instances]]\nname = \"slow\"\nfmu = \"testfmu.fmu\"\nstep_multiple = 5\nparameters = { terminate_at_step = 1 }\n",
    );
    let csv = d.path().join("term.csv");
    let o = shipsim(&["run", path(&sys), "-o", path(&csv)]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let (_, rows) = read_csv(&csv);
    assert_eq!(rows.last().unwrap()[0], 0.6);
    assert!(
        err.contains("simulated 0 s .. 0.6 s (ended early): 6 macro steps"),
        "{err}"
    );
    assert!(
        err.contains(
            "instance 'slow' ended the simulation at t = 0.5 s (fmi2Discard, fmi2Terminated); \
             the master stopped at the end of that macro step, at t = 0.6 s (its last communication point)"
        ),
        "{err}"
    );
}

/// DBL_MIN recorded: the field is its shortest round-trip digits with an exponent (23
/// characters), not 326 characters of decimal; it parses back to DBL_MIN.
#[test]
fn a_tiny_value_is_a_short_csv_field() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let sys = write_system(
        d.path(),
        "tiny.toml",
        "[simulation]\nstop_time = 0.2\nstep_size = 0.1\n[[instances]]\nname = \"a\"\nfmu = \"testfmu.fmu\"\n\
         parameters = { k = 2.2250738585072014e-308, u = 1.0 }\n[output]\nvariables = [\"a.y2\", \"a.u\"]\n",
    );
    let csv = d.path().join("tiny.csv");
    let o = shipsim(&["run", path(&sys), "-q", "-o", path(&csv)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(
        text,
        "time,a.y2,a.u\n0,2.2250738585072014e-308,1\n0.1,2.2250738585072014e-308,1\n0.2,2.2250738585072014e-308,1\n"
    );
    let field = text.lines().nth(1).unwrap().split(',').nth(1).unwrap();
    assert_eq!(field.parse::<f64>().unwrap(), f64::MIN_POSITIVE);
}
