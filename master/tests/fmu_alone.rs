//! `shipsim run X.fmu` (issue 36, item 10): one FMU run alone over its DefaultExperiment, as
//! FMPy's `simulate_fmu` runs one, recording every output into `<identifier>.csv` in the
//! current folder. Before, the FMU was read as a TOML system file ("not UTF-8 text").
mod common;
use common::*;

/// The FMU alone gives the bytes of the equivalent one-instance system file.
#[test]
fn an_fmu_runs_alone_like_its_one_instance_system() {
    let d = tempfile::tempdir().unwrap();
    let fmu = our_fmu("SteeringGear");
    let (ok, err) = shipsim_in(
        d.path(),
        &[
            "run",
            fmu.to_str().unwrap(),
            "--set",
            "SteeringGear.rudder_command=0.1",
        ],
    );
    assert!(ok, "{err}");
    assert!(
        err.contains("note: running the FMU")
            && err.contains("alone as instance 'SteeringGear': start 0 s from its DefaultExperiment, stop 30 s from its DefaultExperiment, step 0.01 s from its DefaultExperiment, every output to SteeringGear.csv")
            && err.contains("3001 rows written to SteeringGear.csv"),
        "{err}"
    );
    let sys = write_system(
        d.path(),
        "one.toml",
        &format!(
            "[simulation]\nstop_time = 30.0\nstep_size = 0.01\n[[instances]]\nname = \"SteeringGear\"\n\
             fmu = \"{}\"\nparameters = {{ rudder_command = 0.1 }}\n[output]\nfile = \"one.csv\"\n",
            fmu.display()
        ),
    );
    let (ok, err) = shipsim_in(d.path(), &["run", sys.to_str().unwrap(), "-q"]);
    assert!(ok, "{err}");
    let alone = std::fs::read_to_string(d.path().join("SteeringGear.csv")).unwrap();
    assert_eq!(
        alone,
        std::fs::read_to_string(d.path().join("one.csv")).unwrap()
    );
    assert_eq!(alone.lines().count(), 1 + 3001);
    assert!(
        alone.starts_with("time,SteeringGear.rudder_angle,"),
        "{alone}"
    );
    // --stop-time, --step-size and -o change them; `check` reads the FMU the same way.
    let (ok, err) = shipsim_in(
        d.path(),
        &[
            "run",
            fmu.to_str().unwrap(),
            "--stop-time",
            "2",
            "--step-size",
            "0.5",
            "-o",
            "short.csv",
            "-q",
        ],
    );
    assert!(ok, "{err}");
    let short = std::fs::read_to_string(d.path().join("short.csv")).unwrap();
    let times: Vec<&str> = short
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(times, ["0", "0.5", "1", "1.5", "2"]);
    let (ok, err) = shipsim_in(d.path(), &["check", fmu.to_str().unwrap()]);
    assert!(ok, "{err}");
}

/// Without a DefaultExperiment: FMPy's defaults (stop start + 1 s, step (stop - start)/500),
/// said in the note.
#[test]
fn without_a_default_experiment_fmpys_defaults_apply() {
    let d = tempfile::tempdir().unwrap();
    let md = model_description("{shipsim-test-fmu}", "2.0").replace(
        "<DefaultExperiment startTime=\"0\" stopTime=\"1\" stepSize=\"0.01\"/>",
        "",
    );
    let fmu = build_fmu(
        d.path(),
        "testfmu",
        Variant {
            md_override: Some(&md),
            ..Default::default()
        },
    );
    let (ok, err) = shipsim_in(d.path(), &["run", fmu.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        err.contains("start 0 s (FMPy's default; it has no DefaultExperiment value), stop start + 1 s (FMPy's default")
            && err.contains("step (stop - start) / 500 (FMPy's default")
            && err.contains("501 rows written to testfmu.csv"),
        "{err}"
    );
}
