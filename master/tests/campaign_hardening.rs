//! A campaign file or folder cannot be turned against its user (issue 38): names that would
//! clash in the run tables, a second process on a running folder, journal lines that do not
//! match the campaign, and absurd job counts are refused with clear errors.
mod common;

use shipsim::campaign::CampaignSpec;
use std::path::Path;

fn load_err(dir: &Path, text: &str) -> String {
    let p = dir.join("c.toml");
    std::fs::write(&p, text).unwrap();
    match CampaignSpec::load(&p) {
        Ok(_) => panic!("loaded:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn factor_seed_and_kpi_names_cannot_be_table_columns_or_each_other() {
    let d = tempfile::tempdir().unwrap();
    let base = "system = \"sys.toml\"\n";
    // a factor named like a table column, with its line
    let e = load_err(
        d.path(),
        &format!("{base}[[factors]]\nname = \"run\"\nvariable = \"m.k\"\nvalues = [1, 2]\n"),
    );
    assert!(
        e.contains("c.toml:2:") && e.contains("factor name 'run' is a column of the run tables"),
        "{e}"
    );
    // a KPI named like one
    let e = load_err(
        d.path(),
        &format!("{base}[[kpis]]\nname = \"status\"\nvariable = \"m.y\"\nstat = \"mean\"\n"),
    );
    assert!(
        e.contains("c.toml:2:") && e.contains("kpi name 'status' is a column"),
        "{e}"
    );
    // a KPI named like a factor
    let e = load_err(
        d.path(),
        &format!(
            "{base}[[factors]]\nname = \"k\"\nvariable = \"m.k\"\nvalues = [1, 2]\n\
             [[kpis]]\nname = \"k\"\nvariable = \"m.y\"\nstat = \"mean\"\n"
        ),
    );
    assert!(
        e.contains("kpi 'k' has the name of a factor: the run tables would have two columns 'k'"),
        "{e}"
    );
    // a derived KPI named like a table column
    let e = load_err(
        d.path(),
        &format!(
            "{base}[[kpis]]\nname = \"y\"\nvariable = \"m.y\"\nstat = \"mean\"\n\
             [[derived]]\nname = \"key\"\nexpr = \"y * 2\"\n"
        ),
    );
    assert!(e.contains("derived kpi name 'key' is a column"), "{e}");
}

/// A campaign of the C test FMU in `dir`: `sys.toml` and `NAME.toml` with the factor values.
fn tiny_campaign(dir: &Path, name: &str, values: &str) -> std::path::PathBuf {
    common::tiny_system(dir);
    common::write_system(
        dir,
        &format!("{name}.toml"),
        &format!(
            "system = \"sys.toml\"\n[[factors]]\nvariable = \"m.k\"\nvalues = {values}\n\
             [[kpis]]\nname = \"y_mean\"\nvariable = \"m.y\"\nstat = \"mean\"\n"
        ),
    )
}

#[test]
fn a_refused_second_process_writes_nothing_into_the_folder() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1, 2]");
    let (ok, err) = common::shipsim_in(d.path(), &["campaign", "run", "a.toml", "-o", "out", "-q"]);
    assert!(ok, "{err}");
    let provenance = std::fs::read(d.path().join("out/campaign.json")).unwrap();
    // another process holds the folder (a campaign running into it)
    let held = std::fs::OpenOptions::new()
        .read(true)
        .append(true)
        .open(d.path().join("out/runs.jsonl"))
        .unwrap();
    held.lock().unwrap();
    tiny_campaign(d.path(), "b", "[1, 2, 3]");
    let (ok, err) = common::shipsim_in(d.path(), &["campaign", "run", "b.toml", "-o", "out", "-q"]);
    assert!(
        !ok && err.contains("is in use: a campaign is running into out (in another process"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(d.path().join("out/campaign.json")).unwrap(),
        provenance,
        "campaign.json was rewritten by the refused run"
    );
}

#[test]
fn jobs_are_at_least_one_and_at_most_the_runs_and_four_per_core() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1, 2, 3]");
    let (ok, err) = common::shipsim_in(
        d.path(),
        &["campaign", "run", "a.toml", "-o", "zero", "-j", "0"],
    );
    assert!(
        !ok && err.contains("jobs = 0: a campaign needs at least one job"),
        "{err}"
    );
    assert!(!d.path().join("zero/campaign.json").exists());
    // a million threads were started before: now three runs take three jobs
    let start = std::time::Instant::now();
    let (ok, err) = common::shipsim_in(
        d.path(),
        &["campaign", "run", "a.toml", "-o", "many", "-j", "1000000"],
    );
    assert!(ok, "{err}");
    assert!(
        err.contains("on 3 job(s) (1000000 jobs asked, at most"),
        "{err}"
    );
    assert!(start.elapsed() < std::time::Duration::from_secs(30));
}

#[test]
fn journal_lines_that_do_not_match_the_campaign_are_errors_naming_the_line() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1, 2]");
    let (ok, err) = common::shipsim_in(d.path(), &["campaign", "run", "a.toml", "-o", "out", "-q"]);
    assert!(ok, "{err}");
    let journal = d.path().join("out/runs.jsonl");
    let good = std::fs::read_to_string(&journal).unwrap();
    let first = good.lines().next().unwrap().to_string();
    let record: serde_json::Value = serde_json::from_str(&first).unwrap();
    let with = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut r = record.clone();
        f(&mut r);
        format!("{good}{r}\n")
    };
    // a record with fewer KPI values than the campaign defines (it panicked: index out of bounds)
    std::fs::write(&journal, with(&|r| r["kpis"] = serde_json::json!([]))).unwrap();
    for args in [
        &["campaign", "run", "a.toml", "-o", "out", "-q"][..],
        &["campaign", "merge", "out", "-o", "merged"][..],
    ] {
        let (ok, err) = common::shipsim_in(d.path(), args);
        assert!(!ok, "{args:?}");
        assert!(
            err.contains("runs.jsonl:3: the record of run ")
                && err.contains(" has 0 KPI values where the campaign has 1"),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    // the same run twice with another result: an error, not "the last line wins"
    std::fs::write(&journal, with(&|r| r["kpis"] = serde_json::json!([123.0]))).unwrap();
    let (ok, err) = common::shipsim_in(d.path(), &["campaign", "run", "a.toml", "-o", "out", "-q"]);
    assert!(
        !ok && err.contains("is recorded twice with different results, on lines 1 and 3"),
        "{err}"
    );
    // the same run twice with the same result (another wall time): kept once
    std::fs::write(&journal, with(&|r| r["wall_time"] = serde_json::json!(9.5))).unwrap();
    let (ok, err) = common::shipsim_in(d.path(), &["campaign", "run", "a.toml", "-o", "out"]);
    assert!(ok && err.contains("2 were done before"), "{err}");
}

#[test]
fn a_mistake_every_run_would_make_is_one_error_before_anything_runs() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1, 2]");
    // an unknown KPI variable: every run was recorded as an error, and the exit status was 0
    std::fs::write(
        d.path().join("bad.toml"),
        "system = \"sys.toml\"\n[[factors]]\nvariable = \"m.k\"\nvalues = [1, 2]\n\
         [[kpis]]\nname = \"y_mean\"\nvariable = \"m.nope\"\nstat = \"mean\"\n",
    )
    .unwrap();
    let (ok, err) = common::shipsim_in(
        d.path(),
        &["campaign", "run", "bad.toml", "-o", "out", "-q"],
    );
    assert!(!ok, "{err}");
    assert!(
        err.contains("run 0 cannot run, and no run would") && err.contains("nope"),
        "{err}"
    );
    assert!(
        !d.path().join("out").exists(),
        "the output folder was created"
    );
}

#[test]
fn derived_expressions_are_bounded_and_checked_at_load() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1, 2]");
    let base = std::fs::read_to_string(d.path().join("a.toml")).unwrap();
    // 2^2^...^2 with 100,000 operators took a minute to parse, after every run had run
    let long = vec!["2"; 100_000].join("^");
    std::fs::write(
        d.path().join("long.toml"),
        format!("{base}[[derived]]\nname = \"big\"\nexpr = \"y_mean * {long}\"\n"),
    )
    .unwrap();
    let start = std::time::Instant::now();
    let (ok, err) = common::shipsim_in(
        d.path(),
        &["campaign", "run", "long.toml", "-o", "out", "-q"],
    );
    assert!(
        !ok && err.contains("characters, more than the 1000 a derived expression may have"),
        "{err}"
    );
    assert!(start.elapsed() < std::time::Duration::from_secs(10));
    assert!(!d.path().join("out").exists());
    // an unknown KPI in a derived expression is found before the runs, not after them
    std::fs::write(
        d.path().join("typo.toml"),
        format!("{base}[[derived]]\nname = \"twice\"\nexpr = \"2 * y_maen\"\n"),
    )
    .unwrap();
    let (ok, err) = common::shipsim_in(
        d.path(),
        &["campaign", "run", "typo.toml", "-o", "out", "-q"],
    );
    assert!(!ok && err.contains("no KPI 'y_maen'"), "{err}");
    assert!(!d.path().join("out").exists());
    // an unknown function is named, with the functions there are (it was exmex's "wlog a
    // number/variable cannot be on the right of a closing parenthesis, left: sqr; right: (")
    std::fs::write(
        d.path().join("fn.toml"),
        format!("{base}[[derived]]\nname = \"root\"\nexpr = \"2 * sqr(y_mean)\"\n"),
    )
    .unwrap();
    let (ok, err) =
        common::shipsim_in(d.path(), &["campaign", "run", "fn.toml", "-o", "out", "-q"]);
    assert!(
        !ok && err.contains(
            "derived kpi 'root' = \"2 * sqr(y_mean)\": unknown function 'sqr' (did you mean 'sqrt'"
        ) && err.contains("; the functions are abs, acos, acosh, asin, ")
            && err.contains(", sqrt, tan, tanh, trunc (and the operators + - * / ^)"),
        "{err}"
    );
    assert!(!d.path().join("out").exists());
}

/// Column `name` of a CSV table.
fn csv_column(path: &Path, name: &str) -> Vec<String> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let at = r.headers().unwrap().iter().position(|h| h == name).unwrap();
    r.records().map(|x| x.unwrap()[at].to_string()).collect()
}

#[test]
fn non_finite_kpis_are_not_recorded_as_ok() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1, 2]");
    let base = std::fs::read_to_string(d.path().join("a.toml")).unwrap();
    // a window after the run's end: refused when the campaign is loaded
    std::fs::write(
        d.path().join("late.toml"),
        format!("{base}[[kpis]]\nname = \"late\"\nvariable = \"m.y\"\nstat = \"max\"\nwindow = [5, 10]\n"),
    )
    .unwrap();
    let (ok, err) = common::shipsim_in(
        d.path(),
        &["campaign", "run", "late.toml", "-o", "late", "-q"],
    );
    assert!(
        !ok && err.contains("kpi 'late': its window [5, 10] starts after the run ends"),
        "{err}"
    );
    // a window between two samples holds none (NaN), a derived x / 0 is infinite
    std::fs::write(
        d.path().join("gap.toml"),
        format!(
            "{base}[[kpis]]\nname = \"gap\"\nvariable = \"m.y\"\nstat = \"max\"\n\
             window = [0.13, 0.14]\n[[derived]]\nname = \"ratio\"\nexpr = \"y_mean / 0\"\n"
        ),
    )
    .unwrap();
    let (ok, err) = common::shipsim_in(
        d.path(),
        &["campaign", "run", "gap.toml", "-o", "gap", "-q"],
    );
    // runs that are not ok make the exit status non-zero (2), after the tables are written
    assert!(!ok && err.contains("error: 2 of 2 runs failed"), "{err}");
    let status = csv_column(&d.path().join("gap/runs.csv"), "status");
    assert_eq!(status, ["non_finite_kpi", "non_finite_kpi"]);
    let message = csv_column(&d.path().join("gap/runs.csv"), "message");
    assert!(message[0].starts_with("KPI 'gap' is NaN"), "{message:?}");
    std::fs::write(
        d.path().join("inf.toml"),
        format!("{base}[[derived]]\nname = \"ratio\"\nexpr = \"y_mean / 0\"\n"),
    )
    .unwrap();
    let (ok, err) = common::shipsim_in(
        d.path(),
        &["campaign", "run", "inf.toml", "-o", "inf", "-q"],
    );
    assert!(ok, "{err}");
    assert_eq!(
        csv_column(&d.path().join("inf/derived.csv"), "status"),
        ["non_finite", "non_finite"]
    );
}

/// The summary names a shard only when there is one (issue 36, item 11: it said "20 of 20 runs
/// in this shard ran" without --shard).
#[test]
fn the_summary_names_the_shard_only_with_one() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1, 2, 3, 4]");
    let (ok, err) = common::shipsim_in(d.path(), &["campaign", "run", "a.toml", "-o", "all"]);
    assert!(ok && err.contains("4 of 4 runs ran (0 failed)"), "{err}");
    assert!(!err.contains("shard"), "{err}");
    let (ok, err) = common::shipsim_in(
        d.path(),
        &["campaign", "run", "a.toml", "-o", "half", "--shard", "0/2"],
    );
    assert!(
        ok && err.contains("2 of 2 runs of shard 0/2 ran (0 failed)"),
        "{err}"
    );
}

/// A campaign whose runs fail exits with status 2, after writing its tables (issue 38, item 7:
/// the exit status was 0); running it again (the failed runs count as done) says so again.
#[test]
fn failed_runs_make_the_exit_status_2() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1, 1e300]");
    // u k = 1e600 overflows: the second run's KPI is infinite (status non_finite_kpi)
    let sys = std::fs::read_to_string(d.path().join("sys.toml")).unwrap();
    common::write_system(d.path(), "sys.toml", &sys.replace("u = 1.0", "u = 1e300"));
    let run = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
            .current_dir(d.path())
            .args(["campaign", "run", "a.toml", "-o", "out"])
            .args(extra)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (code, err) = run(&[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("2 of 2 runs ran (1 failed)")
            && err.contains("error: 1 of 2 runs failed (status and message in runs.csv; --retry-failed runs them again)"),
        "{err}"
    );
    let table = std::fs::read_to_string(d.path().join("out/runs.csv")).unwrap();
    assert!(table.contains(",non_finite_kpi,"), "{table}");
    let (code, err) = run(&[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("2 were done before") && err.contains("1 of the runs done before had failed"),
        "{err}"
    );
    // Without failures: 0.
    tiny_campaign(d.path(), "b", "[1, 2]");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .current_dir(d.path())
        .args(["campaign", "run", "b.toml", "-o", "out_b", "-q"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
}

/// The first SIGTERM stops the phase after the runs (finding the finished runs, the tables,
/// the derived KPIs) as promptly as it stops a run, with status 130 and the journal kept
/// (issue 38, item 11: the phase ignored it, and `timeout` needed a SIGKILL). The journal of
/// 300,000 finished runs is written here, so the campaign has only that phase to do.
#[test]
fn sigterm_stops_the_table_phase() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1]");
    let text = "system = \"sys.toml\"\n[[factors]]\nvariable = \"m.k\"\nlinspace = [1, 2, 150000]\n\
                [[arms]]\nname = \"lo\"\nset = { \"m.u\" = 1.0 }\n[[arms]]\nname = \"hi\"\nset = { \"m.u\" = 2.0 }\n\
                [[kpis]]\nname = \"y_mean\"\nvariable = \"m.y\"\nstat = \"mean\"\n\
                [[derived]]\nname = \"r\"\nexpr = \"(y_mean[hi] + 1) / (y_mean[lo] + 1) * 2 - 1\"\n";
    let file = d.path().join("big.toml");
    std::fs::write(&file, text).unwrap();
    let c = shipsim::campaign::Campaign::load(&file).unwrap();
    let out = d.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let mut journal = String::new();
    for i in 0..c.runs.len() {
        let key = c.runs.run(i).key;
        journal.push_str(&format!(
            "{{\"index\":{i},\"key\":\"{key}\",\"status\":\"ok\",\"message\":\"\",\"kpis\":[{}],\"wall_time\":0.001}}\n",
            i as f64 * 1e-6
        ));
    }
    std::fs::write(out.join("runs.jsonl"), &journal).unwrap();
    let run = || {
        std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
            .current_dir(d.path())
            .args(["campaign", "run", "big.toml", "-o", "out", "-q"])
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    // Undisturbed, the phase takes this long and writes the tables.
    let begin = std::time::Instant::now();
    let done = run().wait_with_output().unwrap();
    let whole = begin.elapsed();
    assert!(done.status.success(), "{done:?}");
    assert!(out.join("derived.parquet").exists());
    for f in ["runs.csv", "runs.parquet", "derived.csv", "derived.parquet"] {
        std::fs::remove_file(out.join(f)).unwrap();
    }
    // SIGTERM at a third of it: the process ends soon after, interrupted, without tables.
    let child = run();
    std::thread::sleep(whole / 3);
    let at = std::time::Instant::now();
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let stopped = child.wait_with_output().unwrap();
    let after = at.elapsed();
    let err = String::from_utf8_lossy(&stopped.stderr);
    assert_eq!(stopped.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    assert!(
        after < whole / 2,
        "stopped {after:?} after SIGTERM; the whole phase takes {whole:?}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("runs.jsonl")).unwrap(),
        journal
    );
}

/// `campaign show --runs | head` ends quietly with status 0 when the reader stops early (it
/// panicked with "failed printing to stdout: Broken pipe").
#[test]
fn campaign_show_into_a_closed_pipe_is_quiet() {
    let d = tempfile::tempdir().unwrap();
    tiny_campaign(d.path(), "a", "[1]");
    std::fs::write(
        d.path().join("big.toml"),
        "system = \"sys.toml\"\n[[factors]]\nvariable = \"m.k\"\nlinspace = [1, 2, 100000]\n\
         [[kpis]]\nname = \"y_mean\"\nvariable = \"m.y\"\nstat = \"mean\"\n",
    )
    .unwrap();
    let out = std::process::Command::new("bash")
        .current_dir(d.path())
        .arg("-c")
        .arg(format!(
            "set -o pipefail; '{}' campaign show --runs big.toml | head -3",
            env!("CARGO_BIN_EXE_shipsim")
        ))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.is_empty(), "{err}");
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 3);
}
