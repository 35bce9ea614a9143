//! Master algorithms on the C test FMU: exact time grid, multi-rate, Jacobi vs Gauss-Seidel,
//! events, gain/offset, Integer/Boolean connections, logging, CLI run and Ctrl-C.
mod common;
use common::*;
use shipsim::log::LogRecord;
use shipsim::run::{run_system, Output, RunOptions};
use shipsim::system::System;
use std::process::Command;
use std::sync::{Arc, Mutex};

fn run_file(path: &std::path::Path, out: &std::path::Path) -> shipsim::run::Summary {
    let s = System::load(path).unwrap();
    run_system(&s, Output::File(out.to_path_buf()), &RunOptions::default())
        .unwrap()
        .1
}

/// Controller every 10 base steps, plant every base step; after 1e6 steps the grid is exact:
/// every communication point each FMU received equals t_k = (t0_ns + k h_ns)/1e9, libcosim's
/// nanosecond clock (computed in the FMU with its own integer step count), each step starts
/// exactly where the previous one ended (t + h), and the final time is exactly t_(1e6).
#[test]
fn multi_rate_time_grid_is_exact_after_a_million_steps() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let p = write_system(
        d.path(),
        "mr.toml",
        r#"
connections = ["ctrl.y -> plant.u", "plant.y -> ctrl.u"]
[simulation]
start_time = 0.3
stop_time = 1000.3
step_size = 0.001
[[instances]]
name = "plant"
fmu = "testfmu.fmu"
parameters = { base_step = 0.001, k = -0.5 }
[[instances]]
name = "ctrl"
fmu = "testfmu.fmu"
step_multiple = 10
parameters = { base_step = 0.001, k = 0.1 }
[output]
variables = ["plant.t_last", "plant.grid_error", "plant.steps", "ctrl.t_last", "ctrl.grid_error", "ctrl.steps"]
decimation = 100000
"#,
    );
    let out = d.path().join("mr.csv");
    let s = run_file(&p, &out);
    assert_eq!(s.macro_steps, 1_000_000);
    assert_eq!(s.fmu_steps, 1_100_000);
    let (h, rows) = read_csv(&out);
    assert_eq!(rows.len(), 11);
    let last = rows.last().unwrap();
    let t_ns = |k: u64| (300_000_000 + k * 1_000_000) as f64 / 1e9;
    let t_end = t_ns(1_000_000);
    assert_eq!(t_end, 1000.3);
    assert_eq!(last[0], t_end, "time column");
    assert_eq!(last[col(&h, "plant.t_last")], t_end);
    assert_eq!(last[col(&h, "ctrl.t_last")], t_end);
    assert_eq!(last[col(&h, "plant.grid_error")], 0.0);
    assert_eq!(last[col(&h, "ctrl.grid_error")], 0.0);
    assert_eq!(last[col(&h, "plant.steps")], 1_000_000.0);
    assert_eq!(last[col(&h, "ctrl.steps")], 100_000.0);
    for (j, r) in rows.iter().enumerate() {
        assert_eq!(r[0], t_ns(j as u64 * 100_000));
    }
}

const CHAIN: &str = r#"
connections = [{ from = "src.y", to = "dst.u", gain = GAIN, offset = OFFSET }]
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

fn chain(d: &std::path::Path, algo: &str, gain: f64, offset: f64) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = CHAIN
        .replace("ALGO", algo)
        .replace("GAIN", &format!("{gain:?}"))
        .replace("OFFSET", &format!("{offset:?}"));
    let p = write_system(d, &format!("chain_{algo}.toml"), &text);
    let out = d.join(format!("chain_{algo}.csv"));
    run_file(&p, &out);
    read_csv(&out)
}

/// src integrates u=1: src.y(t_k) = k h. dst integrates src.y.
/// Jacobi: dst sees src.y(t_k) over [t_k, t_k+1] -> dst.y(t_n) = h^2 n(n-1)/2.
/// Gauss-Seidel in connection order (src first): it sees src.y(t_k+1) -> h^2 n(n+1)/2.
#[test]
fn jacobi_and_gauss_seidel_differ_exactly_as_defined() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let h = 0.1;
    for (algo, shift) in [("jacobi", -1.0), ("gauss-seidel", 1.0)] {
        let (hd, rows) = chain(d.path(), algo, 1.0, 0.0);
        assert_eq!(rows.len(), 11);
        for (n, r) in rows.iter().enumerate() {
            let n = n as f64;
            assert!((r[col(&hd, "src.y")] - n * h).abs() < 1e-12);
            let expect = h * h * n * (n + shift) / 2.0;
            assert!(
                (r[col(&hd, "dst.y")] - expect).abs() < 1e-12,
                "{algo} n={n}: {} vs {expect}",
                r[col(&hd, "dst.y")]
            );
        }
    }
}

#[test]
fn gain_and_offset_apply_to_the_connection() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let (hd, rows) = chain(d.path(), "jacobi", 2.0, 0.5);
    for (n, r) in rows.iter().enumerate() {
        // Row n holds dst.y2 = k*u after the step from t_(n-1), whose input was set from
        // src.y(t_(n-1)) = (n-1) h (Jacobi): u = 2*src.y + 0.5.
        let u = 2.0 * (n.saturating_sub(1) as f64 * 0.1) + 0.5;
        assert!((r[col(&hd, "dst.y2")] - u).abs() < 1e-12, "n={n}");
    }
}

#[test]
fn events_integer_and_boolean_connections() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let p = write_system(
        d.path(),
        "ev.toml",
        r#"
connections = ["a.n_out -> b.n_in", "a.enabled_out -> b.enabled"]
[simulation]
stop_time = 1.0
step_size = 0.1
[[instances]]
name = "a"
fmu = "testfmu.fmu"
parameters = { n_in = 7, u = 1.0 }
[[instances]]
name = "b"
fmu = "testfmu.fmu"
parameters = { u = 1.0 }
[[events]]
time = 0.5
set = "a.u"
value = 3.0
[[events]]
time = 0.7
set = "a.enabled"
value = false
[output]
variables = ["a.*", "b.y", "b.n_out", "b.enabled_out"]
"#,
    );
    let out = d.path().join("ev.csv");
    run_file(&p, &out);
    let (h, rows) = read_csv(&out);
    let ay = col(&h, "a.y");
    // a.u = 1 for 5 steps, 3 for 2 steps, then integration disabled for 3 steps
    assert!((rows[5][ay] - 0.5).abs() < 1e-12);
    assert!((rows[7][ay] - 1.1).abs() < 1e-12);
    assert!((rows[10][ay] - 1.1).abs() < 1e-12);
    assert_eq!(rows[10][col(&h, "b.n_out")], 7.0);
    assert_eq!(
        rows[0][col(&h, "b.n_out")],
        7.0,
        "initial values propagate before the first step"
    );
    // a is disabled before its step from 0.7; b gets a.enabled_out = false at the next exchange
    // (t = 0.8), so its step from 0.8 is the first disabled one and row t = 0.9 shows it.
    assert_eq!(rows[8][col(&h, "a.enabled_out")], 0.0);
    assert_eq!(rows[8][col(&h, "b.enabled_out")], 1.0);
    assert_eq!(rows[9][col(&h, "b.enabled_out")], 0.0);
    let by = col(&h, "b.y");
    assert!(
        (rows[10][by] - 0.8).abs() < 1e-12,
        "b integrates u=1 for 8 steps: {}",
        rows[10][by]
    );
}

#[test]
fn fmu_log_messages_reach_the_sink_with_instance_and_category() {
    let d = tempfile::tempdir().unwrap();
    build_fmu(
        d.path(),
        "logging",
        Variant {
            defines: &["LOG_EVERY_STEP"],
            ..Default::default()
        },
    );
    let p = write_system(
        d.path(),
        "log.toml",
        "[simulation]\nstop_time = 0.3\nstep_size = 0.1\n[[instances]]\nname = \"talker\"\nfmu = \"logging.fmu\"\n",
    );
    let seen: Arc<Mutex<Vec<LogRecord>>> = Arc::default();
    let s2 = seen.clone();
    let opts = RunOptions {
        log_sink: Some(Arc::new(move |r: &LogRecord| {
            s2.lock().unwrap().push(r.clone())
        })),
        ..Default::default()
    };
    run_system(&System::load(&p).unwrap(), Output::None, &opts).unwrap();
    let seen = seen.lock().unwrap();
    assert_eq!(seen.len(), 3);
    assert_eq!(seen[2].instance, "talker");
    assert_eq!(seen[2].category, "logAll");
    assert_eq!(seen[2].status, fmi2::fmi2OK);
    assert_eq!(seen[2].message, "step 2 at t = 0.2");
}

#[test]
fn cli_run_set_stop_time_check_inspect() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let text = CHAIN
        .replace("ALGO", "jacobi")
        .replace("GAIN", "1.0")
        .replace("OFFSET", "0.0");
    let p = write_system(d.path(), "c.toml", &text);
    let bin = env!("CARGO_BIN_EXE_shipsim");
    let out = d.path().join("c.csv");
    let o = Command::new(bin)
        .args([
            "run",
            p.to_str().unwrap(),
            "--stop-time",
            "0.5",
            "--set",
            "src.u=2",
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("5 macro steps, 10 FMU steps") && err.contains("real-time factor"),
        "{err}"
    );
    let (h, rows) = read_csv(&out);
    assert_eq!(rows.len(), 6);
    assert!((rows[5][col(&h, "src.y")] - 1.0).abs() < 1e-12);
    let o = Command::new(bin)
        .args(["check", p.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("OK (2 instances, 1 connections"));
    let o = Command::new(bin)
        .args(["run", p.to_str().unwrap(), "--set", "src.uu=2"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("no variable 'uu'") && err.contains("did you mean 'u'"),
        "{err}"
    );
    let o = Command::new(bin)
        .args(["inspect", d.path().join("testfmu.fmu").to_str().unwrap()])
        .output()
        .unwrap();
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(
        s.contains("{shipsim-test-fmu}")
            && s.contains("fail_at_step")
            && s.contains("canHandleVariableCommunicationStepSize   true"),
        "{s}"
    );
}

/// Ctrl-C stops the run cleanly: exit code 130, the CSV rows so far are flushed.
#[test]
fn ctrl_c_terminates_cleanly() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let p = write_system(
        d.path(),
        "long.toml",
        "[simulation]\nstop_time = 1e9\nstep_size = 0.001\n[[instances]]\nname = \"a\"\nfmu = \"testfmu.fmu\"\n[output]\nvariables = [\"a.y\"]\ndecimation = 1000\n",
    );
    let out = d.path().join("long.csv");
    let child = Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .args(["run", p.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let st = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted at t = "), "{err}");
    let (h, rows) = read_csv(&out);
    assert_eq!(h, vec!["time", "a.y"]);
    assert!(rows.len() > 1);
}

/// fmi2Discard with fmi2Terminated = true ends the run early at that communication point
/// (FMI 2.0 section 4.2.3); the summary says which instance and when; rows stop there.
#[test]
fn fmu_that_terminates_early_ends_the_run_cleanly() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let p = write_system(
        d.path(),
        "term.toml",
        "[simulation]\nstop_time = 1.0\nstep_size = 0.1\n[[instances]]\nname = \"a\"\nfmu = \"testfmu.fmu\"\n[[instances]]\nname = \"quitter\"\nfmu = \"testfmu.fmu\"\nparameters = { terminate_at_step = 4 }\n",
    );
    let out = d.path().join("term.csv");
    let s = run_file(&p, &out);
    assert_eq!(s.macro_steps, 5);
    let msg = s.terminated_by.unwrap();
    assert!(
        msg.contains("instance 'quitter' ended the simulation at t = 0.4"),
        "{msg}"
    );
    let (_, rows) = read_csv(&out);
    assert_eq!(rows.len(), 6);
    assert_eq!(rows.last().unwrap()[0], 0.5);
}
