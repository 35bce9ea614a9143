//! `shipsim check` refuses what `run` refuses: values outside a variable's declared min/max
//! (which our FMUs' fmi2SetReal/fmi2SetInteger refuse during the run), and constants, with a
//! message naming instance, variable, value and range; `run` refuses them the same way before
//! any FMU is instantiated.

mod common;

use common::our_fmu;
use shipsim::model_description::ModelDescription;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Waves and the RRS autopilot, unconnected (the autopilot's inputs keep their start values).
fn system(dir: &Path) -> PathBuf {
    let (waves, autopilot) = (our_fmu("Waves"), our_fmu("RrsAutopilot"));
    let text = format!(
        "[simulation]\nstop_time = 1.0\nstep_size = 0.1\n\n\
         [[instances]]\nname = \"waves\"\nfmu = \"{}\"\n\n\
         [[instances]]\nname = \"autopilot\"\nfmu = \"{}\"\n",
        waves.display(),
        autopilot.display()
    );
    let p = dir.join("sys.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn shipsim(args: &[&str], system: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .args(args)
        .arg(system)
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn check_and_run_refuse_values_outside_the_declared_range() {
    let dir = tempfile::tempdir().unwrap();
    let sys = system(dir.path());
    let csv = dir.path().join("out.csv");
    let csv_arg = csv.to_str().unwrap();
    // (set, the range the FMU declares: RrsAutopilot roll_mode 0..2, Waves H_s 0..30 m)
    let cases = [
        (
            "waves.significant_wave_height=-10 ft",
            "value -10 ft (= -3.048 m) is outside the declared range [0, 30]",
        ),
        (
            "autopilot.roll_mode=5",
            "value 5 is outside the declared range [0, 2]",
        ),
        (
            "autopilot.roll_mode=-1",
            "value -1 is outside the declared range [0, 2]",
        ),
        (
            "waves.significant_wave_height=-3",
            "value -3 is outside the declared range [0, 30]",
        ),
        (
            "waves.significant_wave_height=31 m",
            "value 31 m is outside the declared range [0, 30]",
        ),
    ];
    for (set, message) in cases {
        let (inst, var) = set.split_once('=').unwrap().0.split_once('.').unwrap();
        let named = format!("instance '{inst}', variable '{var}'");
        for (cmd, extra) in [
            (&["check"][..], vec!["--set", set]),
            (&["run", "-q"][..], vec!["--set", set, "-o", csv_arg]),
        ] {
            let out = shipsim(cmd, &sys, &extra);
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(!out.status.success(), "{cmd:?} {set} passed");
            assert!(
                err.contains(message) && err.contains(&named),
                "{cmd:?} {set}: {err}"
            );
            assert!(err.contains(&format!("--set {set}")), "{err}");
            // Refused in validation, not by the FMU's fmi2SetXXX during the run.
            assert!(!err.contains("fmi2Set"), "{err}");
            assert!(!csv.exists(), "run wrote a CSV");
        }
    }
    // The ends of the ranges are accepted.
    for set in [
        "autopilot.roll_mode=0",
        "autopilot.roll_mode=2",
        "waves.significant_wave_height=0",
        "waves.significant_wave_height=30",
    ] {
        let out = shipsim(&["check"], &sys, &["--set", set]);
        assert!(
            out.status.success(),
            "{set}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn check_help_describes_its_arguments() {
    let out = Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .args(["check", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("<SYSTEM>  The system file"), "{help}");
    assert!(
        help.contains("--set <INST.VAR=VALUE>  Set a parameter"),
        "{help}"
    );
}

const XML: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="M" guid="{strict}">
  <CoSimulation modelIdentifier="M"/>
  <ModelVariables>
    <ScalarVariable name="g" valueReference="0" causality="local" variability="constant"><Real start="9.81"/></ScalarVariable>
    <ScalarVariable name="u" valueReference="1" causality="input"><Real start="0" min="-1" max="1"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="2" causality="output"><Real/></ScalarVariable>
    <ScalarVariable name="n" valueReference="3" causality="parameter" variability="tunable"><Integer start="1" min="1"/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>"#;

fn validate(text: &str) -> Result<(), String> {
    let text = format!(
        "[simulation]\nstop_time = 1.0\nstep_size = 0.1\n\n[[instances]]\nname = \"m\"\nfmu = \"M.fmu\"\n{text}"
    );
    let sys = shipsim::format::toml::parse(Path::new("sys.toml"), &text).unwrap();
    let md = ModelDescription::parse(XML).unwrap();
    sys.validate(&[&md]).map(|_| ()).map_err(|e| e.to_string())
}

#[test]
fn constants_are_named_as_constants() {
    let e = validate("parameters = { g = 10.0 }").unwrap_err();
    assert!(
        e.contains("sys.toml:8") && e.contains("variable 'g': it is a constant"),
        "{e}"
    );
    assert!(!e.contains("initial="), "{e}");
    let e = validate("[[events]]\ntime = 0.5\nset = \"m.g\"\nvalue = 1.0\n").unwrap_err();
    assert!(e.contains("'m.g' is a constant"), "{e}");
    // An output that is not constant still gets the causality/initial message.
    let e = validate("parameters = { y = 1.0 }").unwrap_err();
    assert!(e.contains("initial=calculated"), "{e}");
}

#[test]
fn event_values_and_one_sided_ranges_are_checked() {
    let ev = |v: &str| format!("[[events]]\ntime = 0.5\nset = \"m.u\"\nvalue = {v}\n");
    assert!(validate(&ev("1.0")).is_ok());
    let e = validate(&ev("1.5")).unwrap_err();
    assert!(
        e.contains("event at t = 0.5") && e.contains("[-1, 1]"),
        "{e}"
    );
    // NaN is refused, with or without a range (our FMUs' fmi2SetReal refuses it too).
    assert!(validate(&ev("nan"))
        .unwrap_err()
        .contains("value NaN is not a number"));
    let e = validate("parameters = { u = \"nan\" }").unwrap_err();
    assert!(
        e.contains("sys.toml:8") && e.contains("is not a number"),
        "{e}"
    );
    // min only: the open side is shown as inf.
    let e = validate("parameters = { n = 0 }").unwrap_err();
    assert!(
        e.contains("value 0 is outside the declared range [1, inf]"),
        "{e}"
    );
    assert!(validate("parameters = { n = 2147483647 }").is_ok());
}
