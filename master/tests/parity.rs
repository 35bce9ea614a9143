//! One rule for every entry point (issue 29): the end-time rule of OSP and SSP files, the
//! algorithm names and the isolation options are accepted and refused alike, with the same
//! messages, by `shipsim run`, by system files and by campaigns (`shipsim campaign run` and the
//! library's `Campaign::load`). tests/python/test_python_parity.py checks Python's
//! `System.run` and `Campaign` against the same strings (and the CLI again, side by side).

mod common;

use common::*;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The end of the end-time message, the same for every entry point.
const GIVE: &str = "give the run a stop time: shipsim run --stop-time SECONDS, \
                    System.run(stop_time=SECONDS) in Python, or stop_time = SECONDS in a campaign file";

fn shipsim(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `shipsim ARGS` fails with exactly `error: MESSAGE` on stderr.
fn refused(args: &[&str], message: &str) {
    let o = shipsim(args);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
    assert_eq!(stderr(&o), format!("error: {message}\n"), "{args:?}");
}

/// `shipsim ARGS` succeeds.
fn accepted(args: &[&str]) {
    let o = shipsim(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
}

/// A campaign file beside `system` (one run, the final value of `variable`), without or with
/// a stop time.
fn campaign(dir: &Path, name: &str, system: &Path, variable: &str, stop: Option<f64>) -> PathBuf {
    let stop = stop
        .map(|t| format!("stop_time = {t:?}\n"))
        .unwrap_or_default();
    let text = format!(
        "system = \"{}\"\n{stop}[[kpis]]\nname = \"last\"\nvariable = \"{variable}\"\nstat = \"final\"\n",
        system.file_name().unwrap().to_str().unwrap()
    );
    write_system(dir, name, &text)
}

/// The KPI `last` of run 0 of a campaign's output folder (runs.csv).
fn last_kpi(out: &Path) -> f64 {
    let (header, rows) = {
        let text = std::fs::read_to_string(out.join("runs.csv")).unwrap();
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        let rows: Vec<Vec<String>> = lines
            .map(|l| l.split(',').map(String::from).collect())
            .collect();
        (header, rows)
    };
    let j = header.iter().position(|h| h == "last").unwrap();
    rows[0][j].parse().unwrap()
}

const OSP_WITHOUT_END: &str = r#"<OspSystemStructure version="0.1"><BaseStepSize>0.1</BaseStepSize><Simulators>
<Simulator name="a" source="testfmu.fmu"/></Simulators></OspSystemStructure>"#;

const SSD_WITHOUT_STOP: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations" name="one" version="1.0">
  <ssd:System name="root">
    <ssd:Elements>
      <ssd:Component name="a" source="testfmu.fmu"/>
    </ssd:Elements>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="0.1"/></osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"#;

/// An OSP file without `<EndTime>` and an SSD without `stopTime`: `shipsim run` and a campaign
/// (the CLI's and the library's) refuse them with the same message, and run them when given a
/// stop time (`--stop-time`, the campaign's `stop_time`). Campaigns used to run them for 1 s.
#[test]
fn a_file_without_an_end_time_is_refused_alike_by_run_and_campaign() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    test_fmu(dir);
    for (name, text, missing) in [
        ("OspSystemStructure.xml", OSP_WITHOUT_END, "<EndTime>"),
        (
            "SystemStructure.ssd",
            SSD_WITHOUT_STOP,
            "<DefaultExperiment stopTime=\"...\">",
        ),
    ] {
        let sys = write_system(dir, name, text);
        let message = format!("{}: the file has no {missing}; {GIVE}", sys.display());
        refused(&["run", s(&sys), "-q"], &message);
        accepted(&["run", s(&sys), "-q", "--stop-time", "0.3"]);

        let c = campaign(dir, "c.toml", &sys, "a.y", None);
        let out = dir.join("out");
        refused(&["campaign", "run", s(&c), "-q", "-o", s(&out)], &message);
        let e = shipsim::campaign::Campaign::load(&c).unwrap_err();
        assert_eq!(e.to_string(), message);

        let c = campaign(dir, "c_stop.toml", &sys, "a.t_last", Some(0.3));
        let out = dir.join(format!("out_{name}"));
        accepted(&["campaign", "run", s(&c), "-q", "-o", s(&out)]);
        assert!((last_kpi(&out) - 0.3).abs() < 1e-12);
    }
}

/// src integrates u = 1 and dst integrates src.y: at t = 1 s (10 steps of 0.1 s) dst.y is
/// 0.45 under Jacobi and 0.55 under Gauss-Seidel (tests/run.rs derives both).
const CHAIN: &str = r#"connections = [{ from = "src.y", to = "dst.u" }]
[simulation]
stop_time = 1.0
step_size = 0.1
algorithm = "ALGO"
[[instances]]
name = "dst"
fmu = "testfmu.fmu"
[[instances]]
name = "src"
fmu = "testfmu.fmu"
parameters = { u = 1.0 }
"#;

/// The line of `algorithm = ` in [`CHAIN`].
const ALGORITHM_LINE: usize = 5;

/// Every spelling, and the final dst.y of the chain it gives.
const SPELLINGS: [(&str, f64); 11] = [
    ("jacobi", 0.45),
    ("Jacobi", 0.45),
    ("JACOBI", 0.45),
    ("gauss-seidel", 0.55),
    ("gauss_seidel", 0.55),
    ("gauss seidel", 0.55),
    ("gaussseidel", 0.55),
    ("seidel", 0.55),
    ("Gauss-Seidel", 0.55),
    ("GAUSS_SEIDEL", 0.55),
    ("SEIDEL", 0.55),
];

/// The final dst.y of a CSV written by `shipsim run`.
fn final_dst(csv: &Path) -> f64 {
    let (header, rows) = read_csv(csv);
    let j = header.iter().position(|h| h == "dst.y").unwrap();
    rows.last().unwrap()[j]
}

/// The same names select the same algorithm in `shipsim run --algorithm`, in a system file's
/// `algorithm` (run by `shipsim run` and by a campaign), and any other name is refused with
/// one message. (`--algorithm seidel` and `gauss_seidel` in a file were refused before, and
/// each entry point had its own message.)
#[test]
fn algorithm_names_are_the_same_for_run_system_files_and_campaigns() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    test_fmu(dir);
    let base = write_system(dir, "chain.toml", &CHAIN.replace("ALGO", "jacobi"));
    for (i, (name, dst)) in SPELLINGS.iter().enumerate() {
        let csv = dir.join(format!("cli_{i}.csv"));
        accepted(&["run", s(&base), "-q", "--algorithm", name, "-o", s(&csv)]);
        assert!((final_dst(&csv) - dst).abs() < 1e-12, "--algorithm {name}");

        let sys = write_system(
            dir,
            &format!("chain_{i}.toml"),
            &CHAIN.replace("ALGO", name),
        );
        let csv = dir.join(format!("file_{i}.csv"));
        accepted(&["run", s(&sys), "-q", "-o", s(&csv)]);
        assert!((final_dst(&csv) - dst).abs() < 1e-12, "algorithm = {name}");

        let c = campaign(dir, &format!("c_{i}.toml"), &sys, "dst.y", None);
        let out = dir.join(format!("out_{i}"));
        accepted(&["campaign", "run", s(&c), "-q", "-o", s(&out)]);
        assert!((last_kpi(&out) - dst).abs() < 1e-12, "campaign, {name}");
    }
    for name in ["rk4", "gauss--seidel", " jacobi"] {
        let message = format!("unknown algorithm \"{name}\"; use \"jacobi\" or \"gauss-seidel\"");
        refused(
            &["run", s(&base), "-q", &format!("--algorithm={name}")],
            &message,
        );
        let sys = write_system(dir, "bad.toml", &CHAIN.replace("ALGO", name));
        let in_file = format!("{}:{ALGORITHM_LINE}: {message}", sys.display());
        refused(&["run", s(&sys), "-q"], &in_file);
        let c = campaign(dir, "c_bad.toml", &sys, "dst.y", None);
        refused(
            &[
                "campaign",
                "run",
                s(&c),
                "-q",
                "-o",
                s(&dir.join("out_bad")),
            ],
            &format!("campaign {}: base system: {in_file}", c.display()),
        );
    }
}

/// `shipsim run --isolate` and `--call-timeout` take the values Python's `System.run(isolate=,
/// call_timeout=)` takes (the library's parser), with the same messages; every isolated run
/// gives the in-process run's bytes. (Campaigns have no isolation option: they always isolate
/// foreign FMUs.) An unknown instance name and an empty value isolated nothing before.
#[test]
fn isolation_options_are_those_of_python() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    test_fmu(dir);
    let sys = write_system(dir, "chain.toml", &CHAIN.replace("ALGO", "jacobi"));
    let inside = dir.join("inside.csv");
    accepted(&["run", s(&sys), "-q", "-o", s(&inside)]);
    let inside = std::fs::read(&inside).unwrap();
    for (i, option) in [
        "--isolate",
        "--isolate=all",
        "--isolate=foreign",
        "--isolate=src",
        "--isolate=src,dst",
        "--isolate= dst , src,",
    ]
    .iter()
    .enumerate()
    {
        let csv = dir.join(format!("iso_{i}.csv"));
        accepted(&[
            "run",
            s(&sys),
            "-q",
            option,
            "--call-timeout=30",
            "-o",
            s(&csv),
        ]);
        assert_eq!(std::fs::read(&csv).unwrap(), inside, "{option}");
    }
    let f = sys.display();
    for (option, message) in [
        (
            "--isolate=",
            "isolate \"\": give all, foreign or instance names separated by commas".to_string(),
        ),
        (
            "--isolate= , ",
            "isolate \" , \": give all, foreign or instance names separated by commas".into(),
        ),
        (
            "--isolate=srcc",
            format!("isolate: no instance 'srcc' in {f} (did you mean 'src'?)"),
        ),
        (
            "--isolate=src,bogus",
            format!("isolate: no instance 'bogus' in {f}"),
        ),
        (
            "--call-timeout=-1",
            "call timeout -1: give a positive number of seconds (at most 1e9)".into(),
        ),
        (
            "--call-timeout=0",
            "call timeout 0: give a positive number of seconds (at most 1e9)".into(),
        ),
        (
            "--call-timeout=2e9",
            "call timeout 2000000000: give a positive number of seconds (at most 1e9)".into(),
        ),
    ] {
        refused(&["run", s(&sys), "-q", option], &message);
    }
}
