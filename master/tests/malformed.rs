//! Every malformed input gives an error naming the file, instance, variable or value; never a
//! panic. Test FMUs are compiled from tests/c/testfmu.c at test time.
mod common;
use common::*;
use shipsim::run::{run_system, Output, RunOptions};
use shipsim::system::System;
use shipsim::{Error, Fmu};
use std::process::Command;

fn load_err(p: &std::path::Path) -> String {
    match Fmu::load(p) {
        Ok(_) => panic!("{} loaded but should not", p.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn non_zip_file() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("notazip.fmu");
    std::fs::write(&p, "hello").unwrap();
    let e = load_err(&p);
    assert!(
        e.contains("notazip.fmu") && e.contains("not a valid FMU (zip) archive"),
        "{e}"
    );
}

#[test]
fn missing_file() {
    let e = load_err(std::path::Path::new("/nonexistent/x.fmu"));
    assert!(
        e.contains("/nonexistent/x.fmu") && e.contains("cannot open"),
        "{e}"
    );
}

#[test]
fn zip_without_model_description() {
    let d = tempfile::tempdir().unwrap();
    let p = build_fmu(
        d.path(),
        "nomd",
        Variant {
            with_md: false,
            ..Default::default()
        },
    );
    let e = load_err(&p);
    assert!(
        e.contains("nomd.fmu") && e.contains("no modelDescription.xml"),
        "{e}"
    );
}

#[test]
fn xml_that_does_not_parse() {
    let d = tempfile::tempdir().unwrap();
    let p = build_fmu(
        d.path(),
        "badxml",
        Variant {
            md_override: Some("<fmiModelDescription fmiVersion=\"2.0\" <<"),
            ..Default::default()
        },
    );
    let e = load_err(&p);
    assert!(
        e.contains("badxml.fmu") && e.contains("does not parse"),
        "{e}"
    );
    // Well-formed XML that lacks required attributes is also a parse error, not a panic.
    let p = build_fmu(
        d.path(),
        "noguid",
        Variant {
            md_override: Some("<fmiModelDescription fmiVersion=\"2.0\" modelName=\"x\"/>"),
            ..Default::default()
        },
    );
    let e = load_err(&p);
    assert!(e.contains("noguid.fmu") && e.contains("guid"), "{e}");
}

#[test]
fn wrong_fmi_version_and_model_exchange_only() {
    let d = tempfile::tempdir().unwrap();
    let p = build_fmu(
        d.path(),
        "fmi3",
        Variant {
            fmi_version: "3.0",
            with_binary: false,
            ..Default::default()
        },
    );
    let e = load_err(&p);
    assert!(e.contains("fmiVersion is \"3.0\""), "{e}");
    let md = model_description(GUID, "2.0").replace(
        "<CoSimulation modelIdentifier=\"testfmu\" canHandleVariableCommunicationStepSize=\"true\"/>",
        "<ModelExchange modelIdentifier=\"testfmu\"/>",
    );
    let p = build_fmu(
        d.path(),
        "me",
        Variant {
            md_override: Some(&md),
            with_binary: false,
            ..Default::default()
        },
    );
    let e = load_err(&p);
    assert!(
        e.contains("me.fmu") && e.contains("only Model Exchange"),
        "{e}"
    );
}

#[test]
fn missing_binary() {
    let d = tempfile::tempdir().unwrap();
    let p = build_fmu(
        d.path(),
        "nobin",
        Variant {
            with_binary: false,
            ..Default::default()
        },
    );
    let e = load_err(&p);
    assert!(
        e.contains("nobin.fmu") && e.contains("missing binary binaries/linux64/testfmu.so"),
        "{e}"
    );
}

/// An FMU built for other platforms only (a Windows-only FMU, say) is refused with the platforms
/// it has, and `inspect` lists them.
#[test]
fn other_platforms_only() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("winonly.fmu");
    common::zip_files(
        &p,
        &[
            (
                "modelDescription.xml",
                common::model_description(common::GUID, "2.0").into_bytes(),
            ),
            ("binaries/win64/testfmu.dll", b"MZ".to_vec()),
            ("binaries/darwin64/testfmu.dylib", b"\xcf\xfa".to_vec()),
        ],
    );
    let e = load_err(&p);
    assert!(
        e.contains("winonly.fmu")
            && e.contains(
                "missing binary binaries/linux64/testfmu.so (platforms in the archive: \
                 darwin64, win64)"
            ),
        "{e}"
    );
    let text = shipsim::inspect::inspect(&p, &Default::default()).unwrap();
    assert!(text.contains("platforms      darwin64, win64\n"), "{text}");
}

/// An FMU with binaries for several platforms unpacks this platform's only (the others are checked
/// like every entry, and their folders kept so that `platforms` lists them), and runs.
#[test]
fn other_platforms_are_not_unpacked() {
    let d = tempfile::tempdir().unwrap();
    let so = compile(d.path(), "multi", &c_source("testfmu.c"), &[]);
    let p = d.path().join("multi.fmu");
    zip_files(
        &p,
        &[
            (
                "modelDescription.xml",
                model_description(GUID, "2.0").into_bytes(),
            ),
            ("binaries/linux64/testfmu.so", std::fs::read(so).unwrap()),
            ("binaries/win64/testfmu.dll", vec![b'M'; 1 << 20]),
        ],
    );
    let u = shipsim::fmu::UnpackedFmu::open(&p).unwrap();
    assert_eq!(u.platforms(), ["linux64", "win64"]);
    assert!(u.dir.path().join("binaries/linux64/testfmu.so").is_file());
    assert!(u.dir.path().join("binaries/win64").is_dir());
    assert!(!u.dir.path().join("binaries/win64/testfmu.dll").exists());
    assert!(Fmu::load(&p).is_ok());
}

#[test]
fn missing_fmi2_symbol() {
    let d = tempfile::tempdir().unwrap();
    let p = build_fmu(
        d.path(),
        "nocancel",
        Variant {
            defines: &["OMIT_CANCEL_STEP"],
            ..Default::default()
        },
    );
    let e = load_err(&p);
    assert!(
        e.contains("nocancel.fmu") && e.contains("does not export 'fmi2CancelStep'"),
        "{e}"
    );
}

#[test]
fn wrong_guid() {
    let d = tempfile::tempdir().unwrap();
    let p = build_fmu(
        d.path(),
        "wrongguid",
        Variant {
            md_guid: "{another-guid}",
            ..Default::default()
        },
    );
    let fmu = Fmu::load(&p).unwrap();
    let e = match fmu.instantiate("inst1", false, shipsim::log::stderr_sink(false)) {
        Ok(_) => panic!("instantiated with a wrong GUID"),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains("wrongguid.fmu")
            && e.contains("inst1")
            && e.contains("fmi2Instantiate returned NULL"),
        "{e}"
    );
    assert!(
        e.contains("{another-guid}") && e.contains("Wrong GUID"),
        "the FMU's log line is in the error: {e}"
    );
}

#[test]
fn do_step_error_names_instance_time_and_status() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let sys = write_system(
        d.path(),
        "fail.toml",
        r#"
[simulation]
stop_time = 1.0
step_size = 0.1
[[instances]]
name = "good"
fmu = "testfmu.fmu"
[[instances]]
name = "bad"
fmu = "testfmu.fmu"
parameters = { fail_at_step = 3 }
"#,
    );
    let s = System::load(&sys).unwrap();
    let out = d.path().join("out.csv");
    let e = run_system(&s, Output::File(out.clone()), &RunOptions::default()).unwrap_err();
    match &e {
        Error::Fmi {
            instance,
            function,
            status,
            time,
            log,
        } => {
            assert_eq!(instance, "bad");
            assert_eq!(*function, "fmi2DoStep");
            assert_eq!(*status, fmi2::fmi2Error);
            assert!((time.unwrap() - 0.3).abs() < 1e-12, "{time:?}");
            assert!(
                log.iter().any(|l| l.contains("failing at step 3")),
                "{log:?}"
            );
        }
        other => panic!("unexpected error {other}"),
    }
    let msg = e.to_string();
    assert!(
        msg.contains("instance 'bad': fmi2DoStep returned fmi2Error at t = 0.3"),
        "{msg}"
    );
}

fn check_err(text: &str) -> String {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let p = write_system(d.path(), "sys.toml", text);
    let s = match System::load(&p) {
        Ok(s) => s,
        Err(e) => return e.to_string(),
    };
    let u = shipsim::fmu::UnpackedFmu::open(&d.path().join("testfmu.fmu")).unwrap();
    let mds: Vec<_> = s.instances.iter().map(|_| &u.model_description).collect();
    match s.validate(&mds) {
        Ok(_) => panic!("validation passed:\n{text}"),
        Err(e) => e.to_string(),
    }
}

const HEAD: &str = r#"
[simulation]
stop_time = 1.0
step_size = 0.1
[[instances]]
name = "plant"
fmu = "testfmu.fmu"
[[instances]]
name = "ctrl"
fmu = "testfmu.fmu"
"#;

#[test]
fn unknown_instance_and_variable_names_get_suggestions() {
    let e = check_err(&format!("connections = [\"plnat.y -> ctrl.u\"]\n{HEAD}"));
    assert!(
        e.contains("sys.toml:1:")
            && e.contains("no instance named 'plnat'")
            && e.contains("did you mean 'plant'"),
        "{e}"
    );
    let e = check_err(&format!("connections = [\"plant.yy -> ctrl.u\"]\n{HEAD}"));
    assert!(
        e.contains("instance 'plant'") && e.contains("no variable 'yy'") && e.contains("'y'"),
        "{e}"
    );
    let e = check_err(&format!("{HEAD}parameters = {{ kk = 2.0 }}\n"));
    assert!(
        e.contains("instance 'ctrl': no variable 'kk' to set to 2")
            && e.contains("did you mean 'k'"),
        "{e}"
    );
}

#[test]
fn type_and_causality_mismatch() {
    let e = check_err(&format!(
        "connections = [\"plant.steps -> ctrl.u\"]\n{HEAD}"
    ));
    assert!(
        e.contains("type mismatch")
            && e.contains("'plant.steps' is Integer")
            && e.contains("'ctrl.u' is Real"),
        "{e}"
    );
    let e = check_err(&format!("connections = [\"plant.y -> ctrl.y2\"]\n{HEAD}"));
    assert!(
        e.contains("causality mismatch") && e.contains("target 'ctrl.y2' is output"),
        "{e}"
    );
    let e = check_err(&format!("connections = [\"plant.u -> ctrl.u\"]\n{HEAD}"));
    assert!(
        e.contains("causality mismatch") && e.contains("source 'plant.u' is input"),
        "{e}"
    );
    let e = check_err(&format!("connections = [\"plant.y -> ctrl.k\"]\n{HEAD}"));
    assert!(e.contains("target 'ctrl.k' is parameter"), "{e}");
    let e = check_err(&format!("{HEAD}parameters = {{ k = true }}\n"));
    assert!(
        e.contains("variable 'k'") && e.contains("value true does not fit a Real variable"),
        "{e}"
    );
    let e = check_err(&format!("{HEAD}parameters = {{ y = 1.0 }}\n"));
    assert!(
        e.contains("variable 'y'") && e.contains("cannot be set"),
        "{e}"
    );
}

#[test]
fn input_driven_twice_and_units() {
    let e = check_err(&format!(
        "connections = [\"plant.y -> ctrl.u\", \"plant.t_last -> ctrl.u\"]\n{HEAD}"
    ));
    assert!(e.contains("input 'ctrl.u' is driven twice"), "{e}");
    assert!(
        e.contains("incompatible units: 'plant.t_last' is in s but 'ctrl.u' is in m"),
        "{e}"
    );
}

#[test]
fn syntax_errors_name_the_line() {
    let e = check_err("[simulation]\nstop_time = 1.0\nstep_size = 0.1\n[[instances]]\nname = \"a\"\nfmu = \"testfmu.fmu\"\nstep_multiple = 0\n");
    assert!(
        e.contains("sys.toml:4") && e.contains("step_multiple = 0"),
        "{e}"
    );
    let e = check_err("[simulation]\nstop_time = 1.0\nstepsize = 0.1\n");
    assert!(e.contains("sys.toml:3") && e.contains("stepsize"), "{e}");
    let e = check_err(&format!("{HEAD}[simulation2]\n"));
    assert!(e.contains("sys.toml:11"), "{e}");
    let e = check_err(&format!("connections = [\"plant.y => ctrl.u\"]\n{HEAD}"));
    assert!(
        e.contains("must read \"instance.output -> instance.input\""),
        "{e}"
    );
}

#[test]
fn events_are_checked() {
    let e = check_err(&format!(
        "{HEAD}[[events]]\ntime = 0.25\nset = \"ctrl.u\"\nvalue = 1.0\n"
    ));
    assert!(
        e.contains("event at t = 0.25") && e.contains("base-step point"),
        "{e}"
    );
    let e = check_err(&format!(
        "{HEAD}[[events]]\ntime = 0.2\nset = \"ctrl.k\"\nvalue = 1.0\n"
    ));
    assert!(e.contains("'ctrl.k' is fixed parameter"), "{e}");
}

#[test]
fn algebraic_loop_is_noted_under_gauss_seidel() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let text = HEAD.replace(
        "step_size = 0.1",
        "step_size = 0.1\nalgorithm = \"gauss-seidel\"",
    );
    // y2 depends directly on u in both: plant.y2 -> ctrl.u, ctrl.y2 -> plant.u is a loop;
    // km -> m gets a conversion warning too.
    let p = write_system(
        d.path(),
        "loop.toml",
        &format!("connections = [\"plant.y2 -> ctrl.u\", \"ctrl.y2 -> plant.u\"]\n{text}"),
    );
    let s = System::load(&p).unwrap();
    let u = shipsim::fmu::UnpackedFmu::open(&d.path().join("testfmu.fmu")).unwrap();
    let plan = s
        .validate(&[&u.model_description, &u.model_description])
        .unwrap();
    let w = plan.warnings.join("\n");
    assert!(
        w.contains("algebraic loop under Gauss-Seidel: plant.y2 -> ctrl.u, ctrl.y2 -> plant.u"),
        "{w}"
    );
    assert!(
        w.contains("from km to m without conversion; set gain = 1000"),
        "{w}"
    );
    // No loop through state outputs (y does not depend on u).
    let p = write_system(
        d.path(),
        "noloop.toml",
        &format!("connections = [\"plant.y -> ctrl.u\", \"ctrl.y -> plant.u\"]\n{text}"),
    );
    let plan = System::load(&p)
        .unwrap()
        .validate(&[&u.model_description, &u.model_description])
        .unwrap();
    assert!(
        !plan.warnings.join("\n").contains("algebraic loop"),
        "{:?}",
        plan.warnings
    );
}

#[test]
fn osp_file_errors() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let p = write_system(
        d.path(),
        "bad.xml",
        "<OspSystemStructure version=\"0.1\"><Simulators>",
    );
    let e = System::load(&p).unwrap_err().to_string();
    assert!(
        e.contains("bad.xml") && e.contains("not a valid OspSystemStructure.xml"),
        "{e}"
    );
    let p = write_system(
        d.path(),
        "step.xml",
        r#"<OspSystemStructure version="0.1"><BaseStepSize>0.1</BaseStepSize><Simulators>
<Simulator name="a" source="testfmu.fmu" stepSize="0.25"/></Simulators></OspSystemStructure>"#,
    );
    let e = System::load(&p).unwrap_err().to_string();
    assert!(
        e.contains("step.xml:2")
            && e.contains("simulator 'a': stepSize 0.25 is not a positive integer multiple"),
        "{e}"
    );
}

/// The CLI reports errors with exit code 1 and never panics.
#[test]
fn cli_errors_do_not_panic() {
    let d = tempfile::tempdir().unwrap();
    let bin = env!("CARGO_BIN_EXE_shipsim");
    let junk = d.path().join("junk.fmu");
    std::fs::write(&junk, [0u8, 1, 2, 3]).unwrap();
    let sys = write_system(
        d.path(),
        "sys.toml",
        &format!("connections = [\"plant.y -> ctrl.u\"]\n{HEAD}"),
    );
    let missing = write_system(d.path(), "missing.toml", "[simulation]\nstop_time=1.0\nstep_size=0.1\n[[instances]]\nname=\"a\"\nfmu=\"nothere.fmu\"\n");
    for args in [
        vec!["inspect".to_string(), junk.display().to_string()],
        vec!["run".into(), sys.display().to_string()],
        vec!["check".into(), missing.display().to_string()],
        vec!["run".into(), missing.display().to_string()],
        vec!["run".into(), "/nonexistent.toml".into()],
    ] {
        let out = Command::new(bin).args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
    let out = Command::new(bin)
        .args(["check", missing.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("missing.toml:4")
            && err.contains("instance 'a': FMU file")
            && err.contains("nothere.fmu' not found"),
        "{err}"
    );
}
