//! `cargo xtask <task>`: the project's build, packaging and test entry points.
//!
//! * `build-fmus`: builds every FMU crate (packages with `[package.metadata.fmu]`) in release mode
//!   in one cargo invocation and writes `target/fmu/<ModelIdentifier>.fmu`.
//! * `test`: Rust tests, FMUs, a Python venv under `target/venv` with FMPy and libcosimpy, and
//!   the Python checks in `tests/python`.
//! * `demo`: the default coupled system (see README).
//! * `wheel`: the `shipsim` Python package (python/) as a wheel under target/wheels/.
//! * `export-osp`: every system file of systems/ as target/osp/<name>/OspSystemStructure.xml
//!   (+ scenario.json for its events) for libcosim / cosim-cli.
//! * `export-ssp`: every system file of systems/ that SSP 1.0 can express as target/ssp/<name>.ssp.
//! * `fuzz --minutes N [--seed S]`: seeded fuzzing of every FMU and of malformed files
//!   (docs/fuzzing.md); its fixed-seed suite is a step of `test`.
//! * `artifacts DIR` / `artifacts --compare A B`: captures the model descriptions, documentation,
//!   system CSVs and report of a commit and compares two captures byte for byte (see artifacts.rs).
//! * `lint`: the lint step of `test`: the master's layers (layers.rs), rustfmt, clippy.

mod artifacts;
mod fmu;
mod fuzz;
mod layers;
mod win64;

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("build-fmus") => fmu::build_fmus_task(&workspace_root(), &args[1..]),
        Some("test") => test(&args[1..]),
        Some("demo") => demo(),
        Some("bench") => bench(&args[1..]),
        Some("report") => report(args.get(1).map(String::as_str)),
        Some("export-osp") => export_osp(),
        Some("export-ssp") => export_ssp(),
        Some("wheel") => wheel(),
        Some("artifacts") => artifacts::main(&args[1..]),
        Some("lint") => lint(&workspace_root()),
        Some("fuzz") => fuzz::main(&args[1..]),
        _ => {
            eprintln!(
                "usage: cargo xtask <task>\n\n\
                 tasks:\n  \
                 build-fmus [--platforms linux64[,win64]]  build every FMU into target/fmu/<ModelIdentifier>.fmu\n  \
                 test         run every test: Rust, FMU packaging, FMPy and libcosim checks\n  \
                 demo         run the default coupled system\n  \
                 wheel        build the shipsim Python package (python/) as a wheel in target/wheels\n  \
                 report [DIR] run every coupled system and write the validation report (target/report)\n  \
                 export-osp   every system of systems/ as target/osp/<name>/OspSystemStructure.xml for libcosim\n  \
                 export-ssp   every system of systems/ that SSP 1.0 can express as target/ssp/<name>.ssp\n  \
                 bench        master overhead vs libcosim and FMPy, every system's speed and profile, campaigns (docs/bench.md)\n  \
                 fuzz --minutes N [--seed S]  seeded FMI and file fuzzing for N minutes (target/fuzz)\n  \
                 artifacts DIR          FMU model descriptions, system CSVs and report into DIR\n  \
                 artifacts --compare A B  byte-compare two artifact folders (refactor check)\n  \
                 lint         the master's layers (no import cycle, no file over 1,000 lines), rustfmt, clippy"
            );
            std::process::exit(2);
        }
    };
    if let Err(e) = result {
        eprintln!("xtask: error: {e:#}");
        std::process::exit(1);
    }
}

/// The workspace root (parent of this crate's manifest directory).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

/// Runs a command, streaming its output; fails with the command line on a non-zero exit.
pub fn run(cmd: &mut Command) -> Result<()> {
    let status = cmd
        .status()
        .with_context(|| format!("could not start {cmd:?}"))?;
    if !status.success() {
        bail!("{cmd:?} failed with {status}");
    }
    Ok(())
}

/// `CI=true` (or 1): what a test needs and lacks is a failure, not a skipped check.
pub fn ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v.eq_ignore_ascii_case("true") || v == "1")
}

pub fn cargo() -> Command {
    Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
}

/// Creates (or refreshes, when requirements.txt changed) the venv under target/venv.
fn ensure_venv(root: &Path) -> Result<PathBuf> {
    let venv = root.join("target/venv");
    let python = venv.join("bin/python");
    let req = root.join("tests/python/requirements.txt");
    let req_text =
        std::fs::read_to_string(&req).with_context(|| format!("reading {}", req.display()))?;
    let stamp = venv.join(".requirements.txt");
    if python.exists() && std::fs::read_to_string(&stamp).ok().as_deref() == Some(req_text.as_str())
    {
        return Ok(python);
    }
    if !python.exists() {
        eprintln!("xtask: creating the Python venv {}", venv.display());
        run(Command::new("python3").args(["-m", "venv"]).arg(&venv))?;
    }
    eprintln!("xtask: installing tests/python/requirements.txt into the venv");
    run(pip_install(&python).arg("-r").arg(&req))?;
    std::fs::write(&stamp, req_text)?;
    Ok(python)
}

/// `PATH` with the venv's `bin/` first (maturin's PEP 517 backend runs its `maturin` binary
/// from there when pip does not isolate the build).
fn venv_path(python: &Path) -> std::ffi::OsString {
    let bin = python.parent().expect("the venv's bin/").to_path_buf();
    let mut paths = vec![bin];
    if let Some(p) = std::env::var_os("PATH") {
        paths.extend(std::env::split_paths(&p));
    }
    std::env::join_paths(paths).expect("PATH entries without ':'")
}

/// Builds the `shipsim` Python package (python/, maturin, release) and installs it into the
/// venv, without build isolation: maturin comes from requirements.txt, and the Rust build
/// shares target/ with the workspace (a rebuild of an unchanged tree takes seconds).
fn install_python_package(root: &Path, python: &Path) -> Result<()> {
    eprintln!("xtask: building and installing the shipsim Python package (python/) into the venv");
    run(pip_install(python)
        .current_dir(root)
        .args([
            "--no-build-isolation",
            "--force-reinstall",
            "--no-deps",
            "./python",
        ])
        .env("PATH", venv_path(python)))
}

/// `python -m pip install --quiet` (arguments to follow).
fn pip_install(python: &Path) -> Command {
    let mut cmd = Command::new(python);
    cmd.args([
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
    ]);
    cmd
}

/// `cargo xtask wheel`: the Python package as a wheel (abi3: one wheel for CPython >= 3.9).
fn wheel() -> Result<()> {
    let root = workspace_root();
    let python = ensure_venv(&root)?;
    let out = root.join("target/wheels");
    run(Command::new(python.with_file_name("maturin"))
        .current_dir(&root)
        .args(["build", "--release", "-m", "python/Cargo.toml", "-o"])
        .arg(&out)
        .env("PATH", venv_path(&python)))?;
    eprintln!(
        "xtask: wheel in {}; install it with `pip install {}/shipsim-*.whl`",
        out.display(),
        out.display()
    );
    Ok(())
}

fn test(extra: &[String]) -> Result<()> {
    let root = workspace_root();
    let started = std::time::Instant::now();
    let fmu_dir = fmu::build_fmus(&root)?;
    // The binaries first: system tests run the release master and the reference generator.
    build_binaries(&root)?;
    lint(&root)?;
    eprintln!("xtask: Rust tests (release, sharing the FMU build)");
    run(cargo()
        .current_dir(&root)
        .args(["test", "--release", "--workspace", "--exclude", "xtask"])
        .args(extra)
        .env("SHIPSIM_FMU_DIR", &fmu_dir))?;
    fuzz::suite(&root, &fmu_dir)?;
    let python = ensure_venv(&root)?;
    install_python_package(&root, &python)?;
    eprintln!("xtask: Python checks (FMPy, libcosim, the shipsim package) in tests/python");
    let bin = root.join("target/release");
    run(Command::new(&python)
        .current_dir(&root)
        .args(["-m", "pytest", "-q", "-rs", "tests/python"])
        .env("SHIPSIM_FMU_DIR", &fmu_dir)
        .env("SHIPSIM_BIN", bin.join("shipsim"))
        .env("SHIPSIM_REFERENCE_BIN", bin.join("model-reference")))?;
    eprintln!(
        "xtask: all tests passed in {:.0} s",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The master's seams (no import cycle, no file over 1,000 lines: layers.rs), formatting
/// (rustfmt, whole workspace) and the master's function-length rule: no function in
/// `master/src` over 100 lines (`master/clippy.toml`), so that each concern stays readable in
/// one screen.
fn lint(root: &Path) -> Result<()> {
    eprintln!("xtask: no import cycle and no file over 1,000 lines in master/src");
    layers::check(root)?;
    for (tool, component) in [("fmt", "rustfmt"), ("clippy", "clippy")] {
        let found = cargo().args([tool, "--version"]).output();
        if !found.map(|o| o.status.success()).unwrap_or(false) {
            bail!(
                "cargo {tool} is not installed; install it with `rustup component add {component}`"
            );
        }
    }
    eprintln!("xtask: rustfmt check of the workspace");
    run(cargo()
        .current_dir(root)
        .args(["fmt", "--all", "--", "--check"]))
    .context("code is not formatted: run `cargo fmt --all`")?;
    eprintln!("xtask: clippy disallowed_methods on models/ and the FMU crates (one libm: models/src/math.rs)");
    let mut clippy = cargo();
    clippy
        .current_dir(root)
        .args(["clippy", "--release", "--lib", "-p", "ship-models"]);
    for c in fmu::fmu_crates(root)? {
        clippy.args(["-p", &c.package]);
    }
    run(clippy.args([
        "--",
        "-A",
        "clippy::all",
        "-D",
        "clippy::disallowed_methods",
    ]))?;
    eprintln!("xtask: clippy too_many_lines (100) on master/src");
    run(cargo().current_dir(root).args([
        "clippy",
        "--release",
        "-p",
        "shipsim",
        "--lib",
        "--bins",
        "--",
        "-D",
        "clippy::too_many_lines",
    ]))
}

/// Runs every study of tests/src/studies and writes `<dir>/README.md` with figures (default
/// target/report; `cargo xtask report docs/report` refreshes the copy the README links).
fn report(dir: Option<&str>) -> Result<()> {
    let root = workspace_root();
    let fmu_dir = fmu::build_fmus(&root)?;
    build_report(&root)?;
    write_report(&root, &fmu_dir, &root.join(dir.unwrap_or("target/report")))
}

/// Builds the release `report` binary of system-tests.
pub fn build_report(root: &Path) -> Result<()> {
    build_tests_bin(root, "report")
}

/// Builds one release binary of system-tests (tests/src/bin).
fn build_tests_bin(root: &Path, name: &str) -> Result<()> {
    run(cargo()
        .current_dir(root)
        .args(["build", "--release", "-p", "system-tests", "--bin", name]))
}

/// Runs the (built) report binary with the FMUs of `fmu_dir`, writing the report into `out`.
pub fn write_report(root: &Path, fmu_dir: &Path, out: &Path) -> Result<()> {
    run(Command::new(root.join("target/release/report"))
        .current_dir(root)
        .arg(out)
        .env("SHIPSIM_FMU_DIR", fmu_dir))
}

/// Builds the FMUs and shipsim, then exports every systems/*.toml with `shipsim export-osp` to
/// target/osp/<name>/OspSystemStructure.xml (FMU paths relative to it, into target/fmu).
fn export_osp() -> Result<()> {
    let root = workspace_root();
    fmu::build_fmus(&root)?;
    run(cargo()
        .current_dir(&root)
        .args(["build", "--release", "-p", "shipsim", "--bins"]))?;
    let systems = system_files(&root)?;
    for sys in &systems {
        let name = sys.file_stem().and_then(|s| s.to_str()).unwrap_or("system");
        let out = root
            .join("target/osp")
            .join(name)
            .join("OspSystemStructure.xml");
        run(Command::new(root.join("target/release/shipsim"))
            .current_dir(&root)
            .arg("export-osp")
            .arg(sys)
            .arg("-o")
            .arg(&out))?;
    }
    eprintln!(
        "xtask: {} systems exported under {}; run one with `cosim run target/osp/<name>` or \
         libcosimpy's CosimExecution.from_osp_config_file",
        systems.len(),
        root.join("target/osp").display()
    );
    Ok(())
}

/// The system files of systems/ (`*.toml`), sorted.
fn system_files(root: &Path) -> Result<Vec<PathBuf>> {
    let mut systems: Vec<PathBuf> = std::fs::read_dir(root.join("systems"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    systems.sort();
    Ok(systems)
}

/// Builds the FMUs and shipsim, then exports every systems/*.toml with `shipsim export-ssp` to
/// target/ssp/<name>.ssp. A system that SSP 1.0 cannot express (shipsim refuses it, naming
/// what) is listed at the end and does not fail the task.
fn export_ssp() -> Result<()> {
    let root = workspace_root();
    fmu::build_fmus(&root)?;
    run(cargo()
        .current_dir(&root)
        .args(["build", "--release", "-p", "shipsim", "--bins"]))?;
    let mut refused = Vec::new();
    let systems = system_files(&root)?;
    for sys in &systems {
        let name = sys.file_stem().and_then(|s| s.to_str()).unwrap_or("system");
        let out = root.join("target/ssp").join(format!("{name}.ssp"));
        // a refused system leaves no archive from an earlier export behind
        let _ = std::fs::remove_file(&out);
        let status = Command::new(root.join("target/release/shipsim"))
            .current_dir(&root)
            .arg("export-ssp")
            .arg(sys)
            .arg("-o")
            .arg(&out)
            .status()
            .context("could not start target/release/shipsim")?;
        if !status.success() {
            refused.push(name.to_string());
        }
    }
    eprintln!(
        "xtask: {} of {} systems exported under {}; run one with libcosimpy's \
         CosimExecution.from_ssp_file or `shipsim run target/ssp/<name>.ssp`",
        systems.len() - refused.len(),
        systems.len(),
        root.join("target/ssp").display()
    );
    if !refused.is_empty() {
        eprintln!(
            "xtask: not exportable to SSP 1.0 (the errors above say why): {}",
            refused.join(", ")
        );
    }
    Ok(())
}

/// `cargo xtask bench`: master overhead against libcosim and FMPy (bench_master.py, extra
/// arguments are passed on to it), every system's speed and per-instance profile with the
/// pure-Rust RRS model loop (bench_systems.py), campaign throughput, fixed cost and warm-up
/// forks (bench_campaign.py), the Python package's overhead over the CLI (bench_python.py),
/// the cost of stepping a session from Python (bench_session.py), a loop analysis's time
/// (bench_loop.py), the lateness of paced real-time runs (bench_realtime.py),
/// the cost of crash isolation (bench_isolated.py), and what checks compiled into the FMUs
/// cost: the RRS system against a variant of its FMUs built without per-call logging
/// (bench_variants.py); printed, and written to docs/bench.md (committed).
/// `cargo xtask bench --only variants` runs and prints that section alone.
fn bench(extra: &[String]) -> Result<()> {
    let only = match extra {
        [flag, section, ..] if flag == "--only" => match section.as_str() {
            "variants" => Some("variants"),
            other => bail!("cargo xtask bench --only: unknown section {other:?} (known: variants)"),
        },
        _ => None,
    };
    let root = workspace_root();
    fmu::build_fmus(&root)?;
    run(cargo()
        .current_dir(&root)
        .args(["build", "--release", "-p", "shipsim", "--bins"]))?;
    build_tests_bin(&root, "rrs-model-loop")?;
    let rrs = [
        "RrsShip",
        "SteeringGear",
        "Waves",
        "Wind",
        "Sensors",
        "RrsFilter",
        "RrsAutopilot",
    ];
    let no_call_log = fmu::build_fmu_variant(&root, "shipsim_no_call_log", &rrs)?;
    let no_output_check = fmu::build_fmu_variant(&root, "shipsim_no_output_check", &rrs)?;
    let platform_libm = fmu::build_fmu_variant(&root, "shipsim_platform_libm", &rrs)?;
    let python = ensure_venv(&root)?;
    install_python_package(&root, &python)?;
    let script = |name: &str, args: &[String]| -> Result<String> {
        let mut cmd = Command::new(&python);
        cmd.current_dir(&root)
            .arg(format!("master/bench/{name}"))
            .args(args)
            .env("SHIPSIM_BIN", root.join("target/release/shipsim"))
            .env(
                "SHIPSIM_MODEL_LOOP_BIN",
                root.join("target/release/rrs-model-loop"),
            )
            .stderr(std::process::Stdio::inherit());
        let out = cmd.output()?;
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        print!("{text}");
        if !out.status.success() {
            bail!("master/bench/{name} failed with {}", out.status);
        }
        Ok(text)
    };
    let variants = || {
        script(
            "bench_variants.py",
            &[
                format!("shipsim_no_call_log={}", no_call_log.display()),
                format!("shipsim_no_output_check={}", no_output_check.display()),
                format!("shipsim_platform_libm={}", platform_libm.display()),
            ],
        )
    };
    if only == Some("variants") {
        // One section, printed only: docs/bench.md is written by the whole bench.
        return variants().map(drop);
    }
    let master = script("bench_master.py", extra)?;
    let systems = script("bench_systems.py", &[])?;
    let campaigns = script("bench_campaign.py", &[])?;
    let python_pkg = script("bench_python.py", &[])?;
    let session = script("bench_session.py", &[])?;
    let loops = script("bench_loop.py", &[])?;
    let realtime = script("bench_realtime.py", &[])?;
    let isolated = script("bench_isolated.py", &[])?;
    let events = script("bench_events.py", &[])?;
    let variants = variants()?;
    let doc = format!(
        "# Benchmarks\n\nWritten by `cargo xtask bench` (do not edit by hand). Ratios are \
         measured in one run on one machine; absolute times depend on it.\n\n\
         ## Master overhead per FMU-step (master/bench/bench_master.py)\n\n```text\n{master}```\n\n\
         {systems}\n{campaigns}\n{python_pkg}\n{session}\n{loops}\n{realtime}\n{isolated}\n{events}\n{variants}"
    );
    std::fs::write(root.join("docs/bench.md"), doc)?;
    println!("wrote docs/bench.md");
    Ok(())
}

/// The built-in default system: rudder roll stabilization (systems/rrs.toml) with RRS off and
/// on, through the shipsim master; a table on stdout, CSVs and a plot in target/demo/.
/// Every binary of the workspace, release. `demo` and `test` build them with this one command,
/// so that they share one feature resolution and one build: `-p system-tests --bin demo`
/// resolved the FMU crates' features differently and recompiled all 25 of them after a test
/// (issue 36, item 4).
fn build_binaries(root: &Path) -> Result<()> {
    run(cargo().current_dir(root).args([
        "build",
        "--release",
        "--workspace",
        "--exclude",
        "xtask",
        "--bins",
    ]))
}

fn demo() -> Result<()> {
    let root = workspace_root();
    let fmu_dir = fmu::build_fmus(&root)?;
    build_binaries(&root)?;
    run(Command::new(root.join("target/release/demo"))
        .current_dir(&root)
        .env("SHIPSIM_FMU_DIR", fmu_dir))
}
