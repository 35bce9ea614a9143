//! Building and packaging the FMUs.
//!
//! Every workspace package with `[package.metadata.fmu] model-identifier = "X"` is an FMU crate
//! (a `cdylib` that invokes `fmi2_export::export_fmu!`). All of them are built in one
//! `cargo build --release` so they share one build of the workspace. For each, the shared library
//! is loaded once to obtain the generated `modelDescription.xml` and `documentation/index.html`
//! (this also proves the library loads), its exported symbols and dynamic dependencies are
//! checked, and `target/fmu/X.fmu` is written with fixed timestamps (reproducible archives).
//!
//! Every archive carries `binaries/linux64/X.so` and, where a toolchain for it is installed
//! (win64.rs), `binaries/win64/X.dll`, built from the same sources in a second cargo build.

use crate::win64::{self, Toolchain};
use crate::{cargo, run};
use anyhow::{bail, Context, Result};
use object::read::elf::{Dyn, ElfFile64, FileHeader};
use object::{Object, ObjectSymbol};
use serde::Deserialize;
use std::ffi::c_void;
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(Deserialize)]
struct Metadata {
    packages: Vec<Package>,
    workspace_members: Vec<String>,
}

#[derive(Deserialize)]
struct Package {
    id: String,
    name: String,
    targets: Vec<Target>,
    metadata: Option<serde_json::Value>,
}

#[derive(Deserialize)]
struct Target {
    name: String,
    crate_types: Vec<String>,
}

/// An FMU crate of the workspace.
pub struct FmuCrate {
    pub package: String,
    pub lib_name: String,
    pub model_identifier: String,
    /// `example = true`: an example FMU (examples/), packaged into `target/fmu-examples/`.
    pub example: bool,
}

/// Lists the FMU crates from `cargo metadata`.
pub fn fmu_crates(root: &Path) -> Result<Vec<FmuCrate>> {
    let out = cargo()
        .current_dir(root)
        .args(["metadata", "--format-version", "1", "--no-deps"])
        .output()
        .context("running cargo metadata")?;
    if !out.status.success() {
        bail!(
            "cargo metadata failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let meta: Metadata = serde_json::from_slice(&out.stdout).context("parsing cargo metadata")?;
    let mut crates = Vec::new();
    for p in meta
        .packages
        .iter()
        .filter(|p| meta.workspace_members.contains(&p.id))
    {
        let fmu = p.metadata.as_ref().and_then(|m| m.get("fmu"));
        let Some(id) = fmu
            .and_then(|f| f.get("model-identifier"))
            .and_then(|v| v.as_str())
        else {
            continue;
        };
        let example = fmu
            .and_then(|f| f.get("example"))
            .and_then(|v| v.as_bool())
            .unwrap_or(false);
        let lib = p
            .targets
            .iter()
            .find(|t| t.crate_types.iter().any(|c| c == "cdylib"))
            .with_context(|| format!("FMU package {} has no cdylib target", p.name))?;
        crates.push(FmuCrate {
            package: p.name.clone(),
            lib_name: lib.name.clone(),
            model_identifier: id.to_string(),
            example,
        });
    }
    crates.sort_by(|a, b| a.model_identifier.cmp(&b.model_identifier));
    Ok(crates)
}

unsafe extern "C" fn append(out: *mut c_void, data: *const u8, len: usize) {
    let v = &mut *(out as *mut Vec<u8>);
    v.extend_from_slice(std::slice::from_raw_parts(data, len));
}

type Generator =
    unsafe extern "C" fn(*mut c_void, unsafe extern "C" fn(*mut c_void, *const u8, usize));

/// Calls a generator entry point of the FMU library.
fn generated_text(lib: &libloading::Library, symbol: &[u8]) -> Result<String> {
    let mut buf: Vec<u8> = Vec::new();
    // SAFETY: the symbol is emitted by `export_fmu!` with exactly this signature.
    unsafe {
        let f: libloading::Symbol<Generator> = lib
            .get(symbol)
            .with_context(|| format!("symbol {}", String::from_utf8_lossy(symbol)))?;
        f(&mut buf as *mut Vec<u8> as *mut c_void, append);
    }
    String::from_utf8(buf).context("generated text is not UTF-8")
}

/// Shared libraries an FMU binary may depend on (glibc, libm, libgcc_s, the loader).
const ALLOWED_NEEDED: [&str; 6] = [
    "libc.so.6",
    "libm.so.6",
    "libgcc_s.so.1",
    "ld-linux-x86-64.so.2",
    "libpthread.so.0",
    "libdl.so.2",
];

/// Checks the exported FMI symbols and the dynamic dependencies of a built FMU binary.
fn check_binary(path: &Path) -> Result<()> {
    let data = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let elf = ElfFile64::<object::Endianness>::parse(&*data)
        .with_context(|| format!("{} is not a 64-bit ELF file", path.display()))?;
    let exported: std::collections::HashSet<&str> = elf
        .dynamic_symbols()
        .filter(|s| s.is_definition())
        .filter_map(|s| s.name().ok())
        .collect();
    let missing: Vec<&str> = fmi2::FUNCTION_NAMES
        .iter()
        .copied()
        .filter(|n| !exported.contains(n))
        .collect();
    if !missing.is_empty() {
        bail!("{} does not export {}", path.display(), missing.join(", "));
    }
    let endian = elf.endian();
    let header = elf.elf_header();
    let mut needed = Vec::new();
    if let Some((dynamic, link)) = header
        .sections(endian, &*data)
        .ok()
        .and_then(|s| s.dynamic(endian, &*data).ok().flatten())
    {
        let sections = header.sections(endian, &*data)?;
        let strings = sections.strings(endian, &*data, link)?;
        for d in dynamic {
            if d.d_tag(endian) as u32 == object::elf::DT_NEEDED {
                let name = strings
                    .get(d.d_val(endian) as u32)
                    .map_err(|_| anyhow::anyhow!("bad DT_NEEDED entry"))?;
                needed.push(String::from_utf8_lossy(name).into_owned());
            }
        }
    }
    let extra: Vec<&String> = needed
        .iter()
        .filter(|n| !ALLOWED_NEEDED.contains(&n.as_str()))
        .collect();
    if !extra.is_empty() {
        bail!(
            "{} depends on {:?}; an FMU may only need {:?}",
            path.display(),
            extra,
            ALLOWED_NEEDED
        );
    }
    Ok(())
}

/// Writes one `.fmu` archive (with a win64 binary when `dll` is given).
fn write_fmu(
    out: &Path,
    id: &str,
    xml: &str,
    so: &Path,
    dll: Option<&Path>,
    html: &str,
) -> Result<()> {
    use zip::write::SimpleFileOptions;
    let file = std::fs::File::create(out).with_context(|| format!("creating {}", out.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let opts = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    zip.start_file("modelDescription.xml", opts)?;
    zip.write_all(xml.as_bytes())?;
    zip.start_file(
        format!("binaries/linux64/{id}.so"),
        opts.unix_permissions(0o755),
    )?;
    zip.write_all(&std::fs::read(so)?)?;
    if let Some(dll) = dll {
        zip.start_file(
            format!("binaries/win64/{id}.dll"),
            opts.unix_permissions(0o755),
        )?;
        zip.write_all(&std::fs::read(dll)?)?;
    }
    zip.start_file("documentation/index.html", opts)?;
    zip.write_all(html.as_bytes())?;
    zip.finish()?;
    Ok(())
}

/// Whether `build-fmus` writes win64 binaries.
#[derive(Clone, Copy, PartialEq, Debug)]
pub enum Win64 {
    /// linux64 only (`--platforms linux64`).
    Skip,
    /// Where a toolchain is installed; otherwise say so once, with the install line.
    IfAvailable,
    /// A missing toolchain is an error (`CI=true`, `--platforms linux64,win64`).
    Required,
}

impl Win64 {
    /// `Required` under `CI=true`, else `IfAvailable`.
    pub fn from_env() -> Win64 {
        if crate::ci() {
            Win64::Required
        } else {
            Win64::IfAvailable
        }
    }

    /// `--platforms LIST`: `linux64` or `linux64,win64` (any order).
    pub fn parse_platforms(list: &str) -> Result<Win64> {
        let mut names: Vec<&str> = list.split(',').map(str::trim).collect();
        names.sort_unstable();
        match names.as_slice() {
            ["linux64"] => Ok(Win64::Skip),
            ["linux64", "win64"] => Ok(Win64::Required),
            _ => bail!("--platforms {list:?}: expected linux64 or linux64,win64"),
        }
    }
}

/// `cargo xtask build-fmus [--platforms linux64[,win64]]`.
pub fn build_fmus_task(root: &Path, args: &[String]) -> Result<()> {
    let win64 = match args {
        [] => Win64::from_env(),
        [flag, list] if flag == "--platforms" => Win64::parse_platforms(list)?,
        _ => bail!("usage: cargo xtask build-fmus [--platforms linux64|linux64,win64]"),
    };
    build_fmus_for(root, win64).map(|_| ())
}

/// Builds and packages every FMU, with win64 binaries as [`Win64::from_env`] says; returns the
/// output folder `target/fmu` (example FMUs go to `target/fmu-examples`).
pub fn build_fmus(root: &Path) -> Result<PathBuf> {
    build_fmus_for(root, Win64::from_env())
}

fn build_fmus_for(root: &Path, win64: Win64) -> Result<PathBuf> {
    let crates = fmu_crates(root)?;
    if crates.is_empty() {
        bail!("no FMU crates found (packages with [package.metadata.fmu])");
    }
    // In a target folder of their own: `cargo test --workspace` resolves the shared crates'
    // features with the dev-dependencies (serde on fmi2, libc's extra_traits, ...), and in
    // target/ the FMU crates' library units would be rebuilt by each command in turn, so
    // `cargo xtask demo` after `cargo xtask test` recompiled all 25 (issue 36, item 4).
    let build_dir = root.join("target/fmu-build");
    let mut cmd = cargo();
    cmd.current_dir(root)
        .env("CARGO_TARGET_DIR", &build_dir)
        .args(["build", "--release", "--lib"]);
    for c in &crates {
        cmd.args(["-p", &c.package]);
    }
    run(&mut cmd)?;
    let windows = build_win64(root, &crates, win64)?;
    let out_dir = root.join("target/fmu");
    package(
        &crates,
        &build_dir.join("release"),
        windows.as_deref(),
        &out_dir,
        &root.join("target/fmu-examples"),
    )?;
    Ok(out_dir)
}

/// Builds the win64 binaries in `target/win64`; returns the folder that holds the DLLs, or
/// `None` when they are not built.
fn build_win64(root: &Path, crates: &[FmuCrate], win64: Win64) -> Result<Option<PathBuf>> {
    if win64 == Win64::Skip {
        return Ok(None);
    }
    let toolchain = match Toolchain::find() {
        Ok(t) => t,
        Err(why) if win64 == Win64::Required => bail!(
            "the win64 FMU binaries cannot be built: {why}; install {}",
            win64::INSTALL
        ),
        Err(why) => {
            eprintln!(
                "xtask: FMUs with linux64 binaries only ({why}); for win64 binaries install {}",
                win64::INSTALL
            );
            return Ok(None);
        }
    };
    eprintln!("xtask: win64 binaries with {}", toolchain.describe());
    let target = root.join("target/win64");
    let packages: Vec<&str> = crates.iter().map(|c| c.package.as_str()).collect();
    run(toolchain
        .build_command(&target, &packages)?
        .current_dir(root))?;
    Ok(Some(target.join(win64::TARGET).join("release")))
}

/// A variant of some FMUs for a measurement: the FMUs whose model identifiers are `only`, built
/// with `--cfg <cfg>` in a target directory of their own (`target/variants/<cfg>`, so the
/// normal build is untouched) and packaged into its `fmu/` folder, which is returned.
pub fn build_fmu_variant(root: &Path, cfg: &str, only: &[&str]) -> Result<PathBuf> {
    let crates: Vec<FmuCrate> = fmu_crates(root)?
        .into_iter()
        .filter(|c| only.contains(&c.model_identifier.as_str()))
        .collect();
    if crates.len() != only.len() {
        bail!("FMU variant {cfg}: not every one of {only:?} is an FMU crate");
    }
    let target = root.join("target/variants").join(cfg);
    let flags = match std::env::var("RUSTFLAGS") {
        Ok(f) if !f.trim().is_empty() => format!("{f} --cfg {cfg}"),
        _ => format!("--cfg {cfg}"),
    };
    let mut cmd = cargo();
    cmd.current_dir(root)
        .env("CARGO_TARGET_DIR", &target)
        .env("RUSTFLAGS", flags)
        .args(["build", "--release", "--lib"]);
    for c in &crates {
        cmd.args(["-p", &c.package]);
    }
    run(&mut cmd)?;
    let out_dir = target.join("fmu");
    package(&crates, &target.join("release"), None, &out_dir, &out_dir)?;
    Ok(out_dir)
}

/// Packages built FMU libraries (in `release`, and the win64 DLLs in `windows` if given) as
/// `.fmu` archives: into `out_dir`, or `examples_dir` for example FMUs.
fn package(
    crates: &[FmuCrate],
    release: &Path,
    windows: Option<&Path>,
    out_dir: &Path,
    examples_dir: &Path,
) -> Result<()> {
    std::fs::create_dir_all(out_dir)?;
    std::fs::create_dir_all(examples_dir)?;
    for c in crates {
        let so = release.join(format!("lib{}.so", c.lib_name));
        check_binary(&so)?;
        // SAFETY: our own FMU library; loading runs no initialisers beyond Rust's std.
        let lib = unsafe { libloading::Library::new(&so) }
            .with_context(|| format!("loading {}", so.display()))?;
        let xml = generated_text(&lib, b"shipfmu_model_description")?;
        let html = generated_text(&lib, b"shipfmu_documentation_html")?;
        let dll = windows.map(|w| w.join(format!("{}.dll", c.lib_name)));
        if let Some(dll) = &dll {
            win64::check_dll(dll)?;
        }
        let dir = if c.example { examples_dir } else { out_dir };
        let fmu = dir.join(format!("{}.fmu", c.model_identifier));
        write_fmu(&fmu, &c.model_identifier, &xml, &so, dll.as_deref(), &html)?;
        eprintln!("xtask: wrote {}", fmu.display());
    }
    Ok(())
}
