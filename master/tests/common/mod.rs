//! Test helpers: build the C test FMU (tests/c/testfmu.c) with gcc and package it, in variants
//! that misbehave on purpose.
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

pub const GUID: &str = "{shipsim-test-fmu}";

/// tests/c/testfmu.xml with the GUID and fmiVersion filled in.
pub fn model_description(guid: &str, fmi_version: &str) -> String {
    include_str!("../c/testfmu.xml")
        .replace("FMI_VERSION", fmi_version)
        .replace("GUID", guid)
}

/// A C source of the test FMUs: `tests/c/<name>`.
pub fn c_source(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/c")
        .join(name)
}

/// Compiles the C source `src` (testfmu.c, or a file that includes it) into `dir/<tag>.so` with
/// extra defines.
pub fn compile(dir: &Path, tag: &str, src: &Path, defines: &[&str]) -> PathBuf {
    let out = dir.join(format!("{tag}.so"));
    let mut cmd = Command::new("gcc");
    cmd.args(["-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-o"])
        .arg(&out)
        .arg(src);
    for d in defines {
        cmd.arg(format!("-D{d}"));
    }
    cmd.arg("-lm");
    let st = cmd
        .status()
        .expect("gcc must be installed to build the test FMU");
    assert!(st.success(), "gcc failed for {tag}");
    out
}

/// Writes a zip with the given (name, bytes) entries.
pub fn zip_files(path: &Path, entries: &[(&str, Vec<u8>)]) {
    let f = std::fs::File::create(path).unwrap();
    let mut z = zip::ZipWriter::new(f);
    let opts = zip::write::SimpleFileOptions::default();
    for (name, data) in entries {
        z.start_file(*name, opts).unwrap();
        z.write_all(data).unwrap();
    }
    z.finish().unwrap();
}

pub struct Variant<'a> {
    pub defines: &'a [&'a str],
    pub md_guid: &'a str,
    pub fmi_version: &'a str,
    pub with_binary: bool,
    pub with_md: bool,
    pub md_override: Option<&'a str>,
}

impl Default for Variant<'_> {
    fn default() -> Self {
        Variant {
            defines: &[],
            md_guid: GUID,
            fmi_version: "2.0",
            with_binary: true,
            with_md: true,
            md_override: None,
        }
    }
}

/// Builds `dir/<name>.fmu`.
pub fn build_fmu(dir: &Path, name: &str, v: Variant) -> PathBuf {
    let mut entries: Vec<(&str, Vec<u8>)> = Vec::new();
    let md = match v.md_override {
        Some(s) => s.to_string(),
        None => model_description(v.md_guid, v.fmi_version),
    };
    if v.with_md {
        entries.push(("modelDescription.xml", md.into_bytes()));
    }
    if v.with_binary {
        let so = compile(dir, name, &c_source("testfmu.c"), v.defines);
        entries.push(("binaries/linux64/testfmu.so", std::fs::read(so).unwrap()));
    }
    entries.push(("resources/readme.txt", b"test".to_vec()));
    let p = dir.join(format!("{name}.fmu"));
    zip_files(&p, &entries);
    p
}

/// The standard test FMU.
pub fn test_fmu(dir: &Path) -> PathBuf {
    build_fmu(dir, "testfmu", Variant::default())
}

/// The standard test FMU in `dir` and `dir/sys.toml`: one instance `m` of it, u = 1, 0.2 s in
/// steps of 0.1 s (the base system of the small test campaigns).
pub fn tiny_system(dir: &Path) -> PathBuf {
    test_fmu(dir);
    write_system(
        dir,
        "sys.toml",
        "[simulation]\nstop_time = 0.2\nstep_size = 0.1\n[[instances]]\nname = \"m\"\n\
         fmu = \"testfmu.fmu\"\nparameters = { u = 1.0 }\n",
    )
}

/// Writes a system file into `dir` and returns its path.
pub fn write_system(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Reads a CSV into (header, rows of f64).
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|x| match x {
                    "true" => 1.0,
                    "false" => 0.0,
                    _ => x.parse::<f64>().unwrap(),
                })
                .collect()
        })
        .collect();
    (header, rows)
}

pub fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

/// Directory of our built FMUs: $SHIPSIM_FMU_DIR or <workspace>/target/fmu.
pub fn fmu_dir() -> PathBuf {
    std::env::var_os("SHIPSIM_FMU_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/fmu"))
}

/// Path of one of our FMUs; fails (never skips) when it has not been built.
pub fn our_fmu(model_identifier: &str) -> PathBuf {
    let p = fmu_dir().join(format!("{model_identifier}.fmu"));
    assert!(
        p.is_file(),
        "{} is missing: run `cargo xtask build-fmus` first",
        p.display()
    );
    p
}

/// A system file with its FMUs loaded and validated: (plan, FMUs).
pub fn load_plan(
    path: &Path,
) -> shipsim::Result<(
    shipsim::system::Plan,
    Vec<std::sync::Arc<shipsim::fmu::Fmu>>,
)> {
    let sys = shipsim::system::System::load(path)?;
    let fmus = shipsim::run::load_fmus(&sys)?;
    let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
    Ok((sys.validate(&mds)?, fmus))
}

/// Runs a system file, recording every output in memory.
pub fn run_memory(path: &Path) -> shipsim::run::MemoryRecorder {
    let (plan, fmus) = load_plan(path).unwrap();
    let mut memory = shipsim::run::MemoryRecorder::new();
    let opts = shipsim::run::RunOptions::default();
    shipsim::run::run_into(&plan, &fmus, Some(&mut memory), &opts).unwrap();
    memory
}

/// The bits of each value, for exact comparisons.
pub fn bits(xs: &[f64]) -> Vec<u64> {
    xs.iter().map(|x| x.to_bits()).collect()
}

/// systems/rrs.toml pointing at $SHIPSIM_FMU_DIR, written into `dir`.
pub fn rrs_file(dir: &Path) -> PathBuf {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../systems/rrs.toml"))
            .unwrap();
    let fmu_dir = our_fmu("RrsShip").parent().unwrap().to_path_buf();
    let text = text.replace("../target/fmu/", &format!("{}/", fmu_dir.display()));
    write_system(dir, "rrs.toml", &text)
}

/// `shipsim ARGS` in `dir`, killed after 60 s (a write into a FIFO would block forever):
/// (success, stderr).
pub fn shipsim_in(dir: &Path, args: &[&str]) -> (bool, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .current_dir(dir)
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // read stderr while waiting: a long message would fill the pipe and block the child
    let mut pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = std::io::Read::read_to_string(&mut pipe, &mut text);
        text
    });
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > std::time::Duration::from_secs(60) {
            let _ = child.kill();
            panic!("shipsim {args:?} did not end in 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let status = child.wait().unwrap();
    (status.success(), reader.join().unwrap())
}

/// `sys` with one more event: `target` set to `value` at `time`.
pub fn with_event(
    sys: &shipsim::system::System,
    time: f64,
    target: &str,
    value: shipsim::system::Value,
) -> shipsim::system::System {
    let mut s = sys.clone();
    s.events.push(shipsim::system::EventSpec {
        time,
        target: shipsim::system::VarRef::parse(target).unwrap(),
        value,
        line: None,
    });
    s
}

/// Every recorded row as bit patterns: [time, column...].
pub fn rows(m: &shipsim::run::MemoryRecorder) -> Vec<Vec<u64>> {
    (0..m.time.len())
        .map(|i| {
            std::iter::once(m.time[i].to_bits())
                .chain(m.data.iter().map(|c| c[i].to_bits()))
                .collect()
        })
        .collect()
}

/// `systems/<name>` with our FMUs from $SHIPSIM_FMU_DIR, stopping at `stop_time`, no output
/// file (the checkpoint, session and loop-analysis tests).
pub fn our_system(
    name: &str,
    stop_time: f64,
    algorithm: shipsim::system::Algorithm,
) -> shipsim::system::System {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../systems")
        .join(name);
    let mut sys = shipsim::system::System::load(&path).unwrap();
    for inst in &mut sys.instances {
        let stem = inst.fmu.file_stem().unwrap().to_string_lossy().into_owned();
        inst.fmu = our_fmu(&stem);
    }
    sys.stop_time = Some(stop_time);
    sys.algorithm = algorithm;
    sys.output.file = None;
    sys
}
