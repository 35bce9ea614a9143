//! `cargo xtask fuzz --minutes N [--seed S] [--jobs J] [--no-files]`: a seeded fuzz run of every
//! FMU of target/fmu and of malformed files through shipsim, for N minutes (docs/fuzzing.md).
//! The fixed-seed suite of the same fuzzer is a step of `cargo xtask test` ([`suite`]).

use crate::{cargo, fmu, run, workspace_root};
use anyhow::{bail, Result};
use std::path::Path;
use std::process::Command;

/// Builds the FMUs, shipsim and the fuzz binary, then runs `fuzz run` with `args`.
pub fn main(args: &[String]) -> Result<()> {
    if !args.iter().any(|a| a == "--minutes") {
        bail!("usage: cargo xtask fuzz --minutes N [--seed S] [--jobs J] [--no-files]");
    }
    let root = workspace_root();
    let fmu_dir = fmu::build_fmus(&root)?;
    build(&root)?;
    run(Command::new(root.join("target/release/fuzz"))
        .current_dir(&root)
        .arg("run")
        .args(args)
        .arg("--fmu-dir")
        .arg(&fmu_dir))
}

fn build(root: &Path) -> Result<()> {
    run(cargo().current_dir(root).args([
        "build",
        "--release",
        "-p",
        "shipsim",
        "-p",
        "system-tests",
        "--bin",
        "shipsim",
        "--bin",
        "fuzz",
    ]))
}

/// The fixed-seed fuzz suite (`fuzz suite`): every FMU of `fmu_dir`, the binaries already built.
pub fn suite(root: &Path, fmu_dir: &Path) -> Result<()> {
    eprintln!("xtask: fuzz suite (fixed seeds; failures in target/fuzz/suite-failures.txt)");
    run(Command::new(root.join("target/release/fuzz"))
        .current_dir(root)
        .arg("suite")
        .arg("--fmu-dir")
        .arg(fmu_dir))
}
