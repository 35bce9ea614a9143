//! The fuzzer finds what it must find (issue 19, docs/fuzzing.md): a C FMU built with one planted
//! fault per variant (tests/fixtures/fuzz/Misbehave.c) is fuzzed by the `fuzz` binary, and each
//! fault is reported with its kind and the FMU's name: a segfault, an abort and an exit() as
//! crashes, a spinning fmi2DoStep as a hang over the per-call limit, NaN behind fmi2OK as a
//! non-finite output, a panic message on stderr as a panic. The same FMU without a fault gives
//! no failure at all, so every one of these is the fault's doing.

use std::path::{Path, PathBuf};
use std::process::Command;

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/fuzz");

/// Builds `dir/<name>.fmu` from Misbehave.c with the fault `fault` (see the C file).
fn build(dir: &Path, name: &str, fault: u32) -> PathBuf {
    let so = dir.join(format!("{name}.so"));
    let st = Command::new("gcc")
        .args([
            "-shared", "-fPIC", "-O1", "-std=c99", "-Wall", "-Wextra", "-Werror",
        ])
        .args(["-fvisibility=hidden", "-I"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/fmus/include"))
        .arg(format!("-DMODEL_ID={name}"))
        .arg(format!("-DFAULT={fault}"))
        .arg("-o")
        .arg(&so)
        .arg(Path::new(FIXTURE).join("Misbehave.c"))
        .arg("-lm")
        .status()
        .expect("gcc must be installed to build the fuzzer's test FMU");
    assert!(st.success(), "gcc failed for {name}");
    let xml = std::fs::read_to_string(Path::new(FIXTURE).join("Misbehave.xml"))
        .unwrap()
        .replace("MODEL_ID", name)
        .replace("FAULT", &fault.to_string());
    let fmu = dir.join(format!("{name}.fmu"));
    let mut z = zip::ZipWriter::new(std::fs::File::create(&fmu).unwrap());
    let opts = zip::write::SimpleFileOptions::default();
    use std::io::Write;
    z.start_file("modelDescription.xml", opts).unwrap();
    z.write_all(xml.as_bytes()).unwrap();
    z.start_file(format!("binaries/linux64/{name}.so"), opts)
        .unwrap();
    z.write_all(&std::fs::read(&so).unwrap()).unwrap();
    z.finish().unwrap();
    std::fs::remove_file(so).unwrap();
    fmu
}

/// Runs the fuzz binary; (exit status, the failure lines it wrote).
fn fuzz(args: &[&str], fmu_dir: &Path, out: &Path, file: &str) -> (i32, Vec<String>) {
    let o = Command::new(env!("CARGO_BIN_EXE_fuzz"))
        .args(args)
        .arg("--fmu-dir")
        .arg(fmu_dir)
        .arg("--out")
        .arg(out)
        .args(["--no-files", "--jobs", "2"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    let lines = std::fs::read_to_string(out.join(file))
        .unwrap_or_else(|e| panic!("{file}: {e}; stdout: {stdout}"))
        .lines()
        .filter(|l| !l.starts_with("    replay:"))
        .map(String::from)
        .collect();
    (o.status.code().unwrap_or(-1), lines)
}

fn of<'a>(lines: &'a [String], kind: &str, target: &str) -> Vec<&'a String> {
    lines
        .iter()
        .filter(|l| l.starts_with(&format!("{kind} ")) && l.contains(&format!(" target={target} ")))
        .collect()
}

#[test]
fn planted_crashes_nans_and_panics_are_found_and_the_clean_fmu_passes() {
    let tmp = tempfile::tempdir().unwrap();
    let fmus = tmp.path().join("fmus");
    std::fs::create_dir(&fmus).unwrap();
    for (name, fault) in [
        ("Clean", 0),
        ("Segv", 1),
        ("Nan", 3),
        ("Abort", 4),
        ("Panic", 5),
        ("Exit", 6),
    ] {
        build(&fmus, name, fault);
    }
    let (status, lines) = fuzz(
        &["suite"],
        &fmus,
        &tmp.path().join("out"),
        "suite-failures.txt",
    );
    assert_eq!(status, 1, "failures must fail the suite: {lines:#?}");
    assert!(
        lines.iter().all(|l| !l.contains(" target=Clean ")),
        "the clean FMU must give no failure: {lines:#?}"
    );
    let expect = [
        ("crash", "Segv", "killed by SIGSEGV"),
        ("crash", "Abort", "killed by SIGABRT"),
        ("crash", "Exit", "exited with status 0"),
        ("nonfinite", "Nan", "y = NaN"),
        (
            "panic",
            "Panic",
            "panicked at fmus/misbehave/src/lib.rs:1:1: / planted panic",
        ),
    ];
    for (kind, target, text) in expect {
        let found = of(&lines, kind, target);
        // Each unit that steps hits the fault; the suite goes on after each (several units).
        assert!(
            found.len() >= 3,
            "{kind} {target}: {found:#?}\nall: {lines:#?}"
        );
        assert!(
            found
                .iter()
                .all(|l| l.contains(text) && l.contains("doStep(")),
            "{kind} {target}: {found:#?}"
        );
    }
    // Every failure of a faulty FMU is of its fault's kind (a crash is not also a hang, say).
    for l in &lines {
        let target = l
            .split(" target=")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap();
        let kind = l.split(' ').next().unwrap();
        assert!(expect.iter().any(|e| e.0 == kind && e.1 == target), "{l}");
    }
}

#[test]
fn a_spinning_do_step_is_a_hang_of_that_call() {
    let tmp = tempfile::tempdir().unwrap();
    let fmus = tmp.path().join("fmus");
    std::fs::create_dir(&fmus).unwrap();
    build(&fmus, "Hang", 2);
    // Parameter unit 0: instantiate, set k, initialize, one step of 1 s (which spins).
    let (status, lines) = fuzz(
        &["replay", "param", "Hang", "19", "0"],
        &fmus,
        &tmp.path().join("out"),
        "replay-failures.txt",
    );
    assert_eq!(status, 1, "{lines:#?}");
    assert_eq!(lines.len(), 1, "{lines:#?}");
    assert!(
        lines[0].starts_with("hang case=param target=Hang seed=19 unit=0 | doStep(t=0,h=1,noPrior=0): still running after"),
        "{}",
        lines[0]
    );
}

/// A stand-in for shipsim that fails the way `mode` says on every check, run and inspect (and
/// writes a small OSP file for `export-osp`, which the fuzzer uses to make its OSP bases).
const FAKE_SHIPSIM: &str = r#"#!/bin/sh
if [ "$1" = export-osp ]; then
    mkdir -p "$(dirname "$4")"
    echo '<OspSystemStructure><Simulators><Simulator name="a" source="x/Clean.fmu" stepSize="0.1"/></Simulators></OspSystemStructure>' > "$4"
    exit 0
fi
case "$FUZZ_FAKE_MODE" in
    exit101) echo "error: boom" >&2; exit 101 ;;
    segv) kill -SEGV $$ ;;
    silent) exit 1 ;;
    panic) echo "thread 'main' panicked at master/src/main.rs:1:1:" >&2; exit 1 ;;
    *) echo "error: a clean refusal, naming the file" >&2; exit 1 ;;
esac
"#;

#[test]
fn malformed_file_cases_judge_shipsims_exit() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let fmus = tmp.path().join("fmus");
    std::fs::create_dir(&fmus).unwrap();
    build(&fmus, "Clean", 0);
    let fake = tmp.path().join("shipsim");
    std::fs::write(&fake, FAKE_SHIPSIM).unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    for (mode, kind, text) in [
        ("exit101", "exit101", "error: boom"),
        ("segv", "crash", "killed by SIGSEGV"),
        ("silent", "nomessage", "exited with status 1"),
        ("panic", "panic", "panicked at master/src/main.rs"),
        ("refuse", "", ""),
    ] {
        let out = tmp.path().join(mode);
        let o = Command::new(env!("CARGO_BIN_EXE_fuzz"))
            .args(["suite", "--only", "toml,osp,md", "--jobs", "2", "--fmu-dir"])
            .arg(&fmus)
            .arg("--shipsim")
            .arg(&fake)
            .arg("--out")
            .arg(&out)
            .env("FUZZ_FAKE_MODE", mode)
            .output()
            .unwrap();
        let text_out = String::from_utf8_lossy(&o.stdout);
        let lines: Vec<String> = std::fs::read_to_string(out.join("suite-failures.txt"))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with("    replay:"))
            .map(String::from)
            .collect();
        if kind.is_empty() {
            // An error exit with a message is what a malformed file must give.
            assert_eq!(o.status.code(), Some(0), "{mode}: {text_out}\n{lines:#?}");
            assert!(lines.is_empty(), "{mode}: {lines:#?}");
            continue;
        }
        assert_eq!(o.status.code(), Some(1), "{mode}: {text_out}");
        // Every case of every family fails, at its first command, as the fake does.
        assert_eq!(lines.len(), 180, "{mode}: {text_out}");
        for family in ["toml", "osp", "md"] {
            let n = lines
                .iter()
                .filter(|l| l.starts_with(&format!("{kind} case={family} ")) && l.contains(text))
                .count();
            assert_eq!(n, 60, "{mode} {family}: {lines:#?}");
        }
    }
}
