//! `cargo xtask artifacts`: captures every output a refactor must leave byte-identical, and
//! compares two captures.
//!
//! A refactor of the FMU crates (or of the master, the models, the studies) is meant to change
//! no result. This task writes the observable outputs of one commit into a folder:
//!
//! * `fmu/<ModelIdentifier>/modelDescription.xml` and `fmu/<ModelIdentifier>/documentation/index.html`
//!   of every FMU crate, taken from `target/fmu/<ModelIdentifier>.fmu` (the GUID is a hash of the
//!   XML, so it is kept and must stay identical too);
//! * `csv/<name>.csv`: `shipsim run systems/<name>.toml` of every system file;
//! * `report/`: the validation report, exactly as `cargo xtask report DIR` writes it.
//!
//! Usage:
//!
//! ```text
//! git checkout <old>; cargo xtask artifacts target/artifacts/before
//! git checkout <new>; cargo xtask artifacts target/artifacts/after
//! cargo xtask artifacts --compare target/artifacts/before target/artifacts/after
//! ```
//!
//! A relative DIR is taken from the workspace root (as for `cargo xtask report`). DIR is wiped
//! first, but only when it holds the marker file [`MARKER`] this task writes (or is empty);
//! any other existing folder is refused. `--compare A B` requires every file of either tree to
//! exist in both and be byte-for-byte identical; it prints one line per differing or missing file
//! and a summary, and fails when anything differs.

use crate::{cargo, fmu, run, workspace_root};
use anyhow::{bail, Context, Result};
use std::collections::BTreeSet;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Written into every artifacts folder; only folders holding it are ever wiped. Not compared.
const MARKER: &str = ".shipsim-artifacts";

/// `cargo xtask artifacts DIR` or `cargo xtask artifacts --compare A B`.
pub fn main(args: &[String]) -> Result<()> {
    let root = workspace_root();
    match args {
        [flag, a, b] if flag == "--compare" => compare(&root.join(a), &root.join(b)),
        [dir] if !dir.starts_with('-') => capture(&root, &root.join(dir)),
        _ => bail!("usage: cargo xtask artifacts DIR | cargo xtask artifacts --compare A B"),
    }
}

/// Builds the FMUs, shipsim and the report binary, then writes every artifact into `dir`.
fn capture(root: &Path, dir: &Path) -> Result<()> {
    let started = std::time::Instant::now();
    // Build everything before touching `dir`, so that a failed build leaves it as it was.
    let fmu_dir = fmu::build_fmus(root)?;
    run(cargo()
        .current_dir(root)
        .args(["build", "--release", "-p", "shipsim", "--bins"]))?;
    crate::build_report(root)?;
    prepare_dir(dir)?;

    // Only the FMUs of the current crates: target/fmu may still hold archives of crates that
    // were renamed or removed, which would hide their absence. Example FMUs (examples/, packaged
    // into target/fmu-examples) are documentation, not product artifacts.
    let crates = fmu::fmu_crates(root)?;
    for c in crates.iter().filter(|c| !c.example) {
        let id = &c.model_identifier;
        let archive = fmu_dir.join(format!("{id}.fmu"));
        let file = std::fs::File::open(&archive)
            .with_context(|| format!("opening {}", archive.display()))?;
        let mut zip =
            zip::ZipArchive::new(file).with_context(|| format!("reading {}", archive.display()))?;
        let out = dir.join("fmu").join(id);
        // Compared as written: the exporter writes no generationDateAndTime, and the tool version
        // in generationTool is the workspace version (also in the text the GUID hashes).
        let xml = zip_entry(&mut zip, "modelDescription.xml", &archive)?;
        write(&out.join("modelDescription.xml"), &xml)?;
        let html = zip_entry(&mut zip, "documentation/index.html", &archive)?;
        write(&out.join("documentation/index.html"), &html)?;
    }

    // Every system writes exactly one CSV (its [output] file, which `-o` overrides; the master
    // writes nothing else), so `-o` puts it into DIR/csv instead of target/demo.
    let shipsim = root.join("target/release/shipsim");
    let systems = system_names(root)?;
    std::fs::create_dir_all(dir.join("csv"))?;
    for name in &systems {
        eprintln!("xtask: running systems/{name}.toml");
        run(Command::new(&shipsim)
            .current_dir(root)
            .arg("run")
            .arg(format!("systems/{name}.toml"))
            .arg("-o")
            .arg(dir.join("csv").join(format!("{name}.csv")))
            .arg("-q"))?;
    }

    crate::write_report(root, &fmu_dir, &dir.join("report"))?;
    eprintln!(
        "xtask: artifacts of {} FMUs and {} systems and the report written to {} in {:.0} s",
        crates.len(),
        systems.len(),
        dir.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

fn zip_entry(
    zip: &mut zip::ZipArchive<std::fs::File>,
    name: &str,
    archive: &Path,
) -> Result<Vec<u8>> {
    let mut entry = zip
        .by_name(name)
        .with_context(|| format!("{} has no {name}", archive.display()))?;
    let mut data = Vec::new();
    entry.read_to_end(&mut data)?;
    Ok(data)
}

fn write(path: &Path, data: &[u8]) -> Result<()> {
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::write(path, data).with_context(|| format!("writing {}", path.display()))
}

/// The names of systems/*.toml, sorted.
fn system_names(root: &Path) -> Result<Vec<String>> {
    let mut names: Vec<String> = std::fs::read_dir(root.join("systems"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .filter_map(|p| p.file_stem().and_then(|s| s.to_str()).map(String::from))
        .collect();
    names.sort();
    Ok(names)
}

/// Wipes `dir` if it is an earlier capture (holds [`MARKER`]) or empty, refuses otherwise, and
/// recreates it with the marker.
fn prepare_dir(dir: &Path) -> Result<()> {
    if dir.exists() {
        let empty = std::fs::read_dir(dir)
            .with_context(|| format!("reading {}", dir.display()))?
            .next()
            .is_none();
        if !empty && !dir.join(MARKER).is_file() {
            bail!(
                "{} exists and was not written by `cargo xtask artifacts` (no {MARKER}); \
                 refusing to wipe it",
                dir.display()
            );
        }
        std::fs::remove_dir_all(dir).with_context(|| format!("removing {}", dir.display()))?;
    }
    write(
        &dir.join(MARKER),
        b"Written by `cargo xtask artifacts`; this folder is wiped by its next run.\n",
    )
}

/// Every file under `dir` except the marker, as paths relative to `dir`.
fn files(dir: &Path) -> Result<BTreeSet<PathBuf>> {
    fn walk(base: &Path, dir: &Path, out: &mut BTreeSet<PathBuf>) -> Result<()> {
        for e in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
            let path = e?.path();
            if path.is_dir() {
                walk(base, &path, out)?;
            } else {
                let rel = path.strip_prefix(base)?.to_path_buf();
                if rel != Path::new(MARKER) {
                    out.insert(rel);
                }
            }
        }
        Ok(())
    }
    if !dir.join(MARKER).is_file() {
        bail!(
            "{} is not a `cargo xtask artifacts` folder (no {MARKER})",
            dir.display()
        );
    }
    let mut out = BTreeSet::new();
    walk(dir, dir, &mut out)?;
    Ok(out)
}

/// Compares two captures byte for byte.
fn compare(a: &Path, b: &Path) -> Result<()> {
    let in_a = files(a)?;
    let in_b = files(b)?;
    let all: BTreeSet<&PathBuf> = in_a.iter().chain(&in_b).collect();
    let (mut xml, mut html, mut csv, mut report) = (0, 0, 0, 0);
    let mut differ = 0;
    for rel in all {
        let name = rel.to_string_lossy();
        if name.starts_with("fmu/") && name.ends_with("/modelDescription.xml") {
            xml += 1;
        } else if name.starts_with("fmu/") && name.ends_with("/documentation/index.html") {
            html += 1;
        } else if name.starts_with("csv/") {
            csv += 1;
        } else if name.starts_with("report/") {
            report += 1;
        }
        let line = match (in_a.contains(rel), in_b.contains(rel)) {
            (true, false) => Some(format!("only in {}: {name}", a.display())),
            (false, true) => Some(format!("only in {}: {name}", b.display())),
            _ => {
                let x = std::fs::read(a.join(rel))?;
                let y = std::fs::read(b.join(rel))?;
                (x != y).then(|| {
                    let at = x.iter().zip(&y).take_while(|(p, q)| p == q).count();
                    let line = 1 + x[..at].iter().filter(|&&c| c == b'\n').count();
                    format!(
                        "differs: {name} (first at byte {at}, line {line}; {} vs {} bytes)",
                        x.len(),
                        y.len()
                    )
                })
            }
        };
        if let Some(line) = line {
            println!("{line}");
            differ += 1;
        }
    }
    let verdict = if differ == 0 {
        "identical".to_string()
    } else {
        format!("{differ} differ")
    };
    println!(
        "artifacts: {xml} model descriptions, {html} documentation pages, {csv} CSVs, \
         {report} report files: {verdict}"
    );
    if differ > 0 {
        bail!(
            "{differ} files differ between {} and {}",
            a.display(),
            b.display()
        );
    }
    Ok(())
}
