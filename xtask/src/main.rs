//! `cargo xtask <task>`: the project's build, packaging and test entry points.
//!
//! * `build-fmus`: builds every FMU crate (packages with `[package.metadata.fmu]`) in release mode
//!   in one cargo invocation and writes `target/fmu/<ModelIdentifier>.fmu`.
//! * `test`: Rust tests, FMUs, a Python venv under `target/venv` with FMPy and libcosimpy, and
//!   the Python checks in `tests/python`.
//! * `demo`: the default coupled system (see README).

mod fmu;

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("build-fmus") => fmu::build_fmus(&workspace_root()).map(|_| ()),
        Some("test") => test(&args[1..]),
        Some("demo") => demo(),
        Some("bench") => bench(&args[1..]),
        Some("report") => report(),
        _ => {
            eprintln!(
                "usage: cargo xtask <task>\n\n\
                 tasks:\n  \
                 build-fmus   build every FMU into target/fmu/<ModelIdentifier>.fmu\n  \
                 test         run every test: Rust, FMU packaging, FMPy and libcosim checks\n  \
                 demo         run the default coupled system\n  \
                 report       run every coupled system and write the validation report (target/report)\n  \
                 bench        master overhead per FMU-step: shipsim vs libcosim vs FMPy (master/bench)"
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
    run(Command::new(&python)
        .args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
            "-r",
        ])
        .arg(&req))?;
    std::fs::write(&stamp, req_text)?;
    Ok(python)
}

fn test(extra: &[String]) -> Result<()> {
    let root = workspace_root();
    let started = std::time::Instant::now();
    let fmu_dir = fmu::build_fmus(&root)?;
    // The binaries first: system tests run the release master and the reference generator.
    run(cargo().current_dir(&root).args([
        "build",
        "--release",
        "--workspace",
        "--exclude",
        "xtask",
        "--bins",
    ]))?;
    eprintln!("xtask: Rust tests (release, sharing the FMU build)");
    run(cargo()
        .current_dir(&root)
        .args(["test", "--release", "--workspace", "--exclude", "xtask"])
        .args(extra)
        .env("SHIPSIM_FMU_DIR", &fmu_dir))?;
    let python = ensure_venv(&root)?;
    eprintln!("xtask: Python checks (FMPy, libcosim) in tests/python");
    let bin = root.join("target/release");
    run(Command::new(&python)
        .current_dir(&root)
        .args(["-m", "pytest", "-q", "tests/python"])
        .env("SHIPSIM_FMU_DIR", &fmu_dir)
        .env("SHIPSIM_BIN", bin.join("shipsim"))
        .env("SHIPSIM_REFERENCE_BIN", bin.join("model-reference")))?;
    eprintln!(
        "xtask: all tests passed in {:.0} s",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Runs every study of tests/src/studies and writes target/report/README.md with figures.
fn report() -> Result<()> {
    let root = workspace_root();
    let fmu_dir = fmu::build_fmus(&root)?;
    run(cargo().current_dir(&root).args([
        "build",
        "--release",
        "-p",
        "system-tests",
        "--bin",
        "report",
    ]))?;
    run(Command::new(root.join("target/release/report"))
        .current_dir(&root)
        .arg(root.join("target/report"))
        .env("SHIPSIM_FMU_DIR", fmu_dir))
}

/// Runs master/bench/bench_master.py in the project venv (extra arguments are passed on).
fn bench(extra: &[String]) -> Result<()> {
    let root = workspace_root();
    run(cargo()
        .current_dir(&root)
        .args(["build", "--release", "-p", "shipsim", "--bins"]))?;
    let python = ensure_venv(&root)?;
    run(Command::new(python)
        .current_dir(&root)
        .arg("master/bench/bench_master.py")
        .args(extra)
        .env("SHIPSIM_BIN", root.join("target/release/shipsim")))
}

/// The built-in default system: currently the steering-gear classification manoeuvre
/// (systems/steering_gear_classification.toml) run by the shipsim master; it becomes the rudder
/// roll stabilization system when the hull, disturbance, observer and controller FMUs land.
fn demo() -> Result<()> {
    let root = workspace_root();
    fmu::build_fmus(&root)?;
    run(cargo()
        .current_dir(&root)
        .args(["build", "--release", "-p", "shipsim", "--bins"]))?;
    let out_dir = root.join("target/demo");
    std::fs::create_dir_all(&out_dir)?;
    let system = root.join("systems/steering_gear_classification.toml");
    run(Command::new(root.join("target/release/shipsim"))
        .current_dir(&root)
        .arg("run")
        .arg(&system))?;
    let csv = out_dir.join("steering_gear_classification.csv");
    let text =
        std::fs::read_to_string(&csv).with_context(|| format!("reading {}", csv.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let col = |name: &str| header.iter().position(|h| *h == name);
    let target = 35f64.to_radians();
    println!();
    println!(
        "Hard over 35 deg port -> 35 deg starboard at t = 5 s (van der Klugt 1987, section 2.3)"
    );
    println!(
        "{:<6} {:>16} {:>20} {:>20}",
        "gear", "max rate [deg/s]", "to within 0.1 deg [s]", "rate-limited [s]"
    );
    for gear in ["slow", "rrs"] {
        let (Some(a), Some(r), Some(s)) = (
            col(&format!("{gear}.rudder_angle")),
            col(&format!("{gear}.rudder_rate")),
            col(&format!("{gear}.rate_saturated_time")),
        ) else {
            bail!("{} lacks the {gear} columns", csv.display());
        };
        let max_rate = rows.iter().map(|row| row[r].abs()).fold(0.0, f64::max);
        let arrival = rows
            .iter()
            .find(|row| (row[a] - target).abs() < 0.1f64.to_radians())
            .map(|row| row[0] - 5.0);
        let sat = rows.last().map(|row| row[s]).unwrap_or(f64::NAN);
        println!(
            "{gear:<6} {:>16.2} {:>20} {:>20.2}",
            max_rate.to_degrees(),
            arrival.map_or("not reached".to_string(), |t| format!("{t:.2}")),
            sat
        );
    }
    println!("(classification rule: 70 deg within 30 s, i.e. 2.5 deg/s suffices)");
    let png = out_dir.join("steering_gear_classification.png");
    run(Command::new(root.join("target/release/shipsim"))
        .arg("plot")
        .arg(&csv)
        .args([
            "--panel",
            "rudder angle [deg]=slow.rudder_angle,rrs.rudder_angle",
            "--panel",
            "rudder rate [deg/s]=slow.rudder_rate,rrs.rudder_rate",
            "--scale",
            "57.29577951308232",
            "--title",
            "Hard over 35 deg port to 35 deg starboard: 2.5 deg/s vs 15 deg/s gear",
            "-o",
        ])
        .arg(&png))?;
    println!("results: {} and {}", csv.display(), png.display());
    Ok(())
}
