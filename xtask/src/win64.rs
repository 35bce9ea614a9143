//! The win64 binaries of the FMUs: `x86_64-pc-windows-gnu`, linked by MinGW-w64.
//!
//! Two toolchains can build them, tried in this order:
//! * **rustup**: the target installed beside the toolchain that runs xtask
//!   (`rustup target add x86_64-pc-windows-gnu`), and MinGW-w64's linker
//!   (`x86_64-w64-mingw32-gcc`). This is the set-up of a normal developer machine.
//! * **Debian**: where rustup cannot reach its servers (this project's CI), Debian bookworm's
//!   own Rust (`apt-get install rustc-web cargo-web rust-web-src gcc-mingw-w64-x86-64`, rustc
//!   1.85, or 1.96 from bookworm-security) builds the standard library for the target from its
//!   source (`-Zbuild-std`, allowed on a stable compiler by `RUSTC_BOOTSTRAP=1`). The two startup objects a windows-gnu link
//!   needs (`rsbegin.o`, `rsend.o`, normally shipped with the target's standard library) are
//!   compiled here from the same source. The FMU crates and their dependencies therefore build
//!   with that rustc, 1.85 at the oldest (the workspace's `rust-version` is for the master and is
//!   ignored here).
//!
//! Either way the build has a target directory of its own (`target/win64`): two compilers
//! sharing `target/` would rebuild each other's crates. The DLLs are stripped of symbols
//! (`-C strip=symbols`); only the FMI functions are exported.

use crate::cargo;
use anyhow::{bail, Context, Result};
use object::Object;
use std::path::{Path, PathBuf};
use std::process::Command;

pub const TARGET: &str = "x86_64-pc-windows-gnu";
const LINKER: &str = "x86_64-w64-mingw32-gcc";
/// The one line that says how to get what builds the win64 binaries.
pub const INSTALL: &str = "`rustup target add x86_64-pc-windows-gnu` and MinGW-w64 \
    (`apt-get install gcc-mingw-w64-x86-64`), or, without rustup's servers, Debian's Rust: \
    `apt-get install rustc-web cargo-web rust-web-src gcc-mingw-w64-x86-64`";

/// A toolchain that builds win64 FMU binaries.
pub enum Toolchain {
    /// rustup's target beside the running toolchain.
    Rustup,
    /// Debian's rustc and cargo with the standard library's source (`sysroot` = `/usr`).
    Debian {
        rustc: PathBuf,
        cargo: PathBuf,
        library: PathBuf,
    },
}

impl Toolchain {
    /// The toolchain found on this machine, or why there is none.
    pub fn find() -> std::result::Result<Toolchain, String> {
        if !on_path(LINKER) {
            return Err(format!("no MinGW-w64 linker ({LINKER})"));
        }
        if target_installed(Path::new("rustc")) {
            return Ok(Toolchain::Rustup);
        }
        let (rustc, cargo) = (
            PathBuf::from("/usr/bin/rustc"),
            PathBuf::from("/usr/bin/cargo"),
        );
        if let Some(sysroot) = sysroot(&rustc) {
            let library = sysroot.join("lib/rustlib/src/rust/library");
            if cargo.exists() && library.join("Cargo.lock").exists() {
                return Ok(Toolchain::Debian {
                    rustc,
                    cargo,
                    library,
                });
            }
        }
        Err(format!(
            "rustc has no {TARGET} target and no Debian Rust with the standard library's source"
        ))
    }

    pub fn describe(&self) -> String {
        match self {
            Toolchain::Rustup => format!("rustup's {TARGET} target, linked by {LINKER}"),
            Toolchain::Debian { rustc, .. } => format!(
                "{} ({}) with -Zbuild-std, linked by {LINKER}",
                rustc.display(),
                version(rustc).unwrap_or_else(|| "unknown version".into())
            ),
        }
    }

    /// `cargo build --release --lib --target x86_64-pc-windows-gnu -p ...` in `target_dir`.
    pub fn build_command(&self, target_dir: &Path, packages: &[&str]) -> Result<Command> {
        let mut flags = vec!["-C".to_string(), "strip=symbols".to_string()];
        let mut after = Vec::new();
        let mut cmd = match self {
            Toolchain::Rustup => cargo(),
            Toolchain::Debian {
                rustc,
                cargo,
                library,
            } => {
                // one folder per compiler: an upgraded rustc compiles its own startup objects
                let release = version(rustc).unwrap_or_default();
                let release = release.split_whitespace().nth(1).unwrap_or("unknown");
                let objects =
                    startup_objects(rustc, library, &target_dir.join("rtstartup").join(release))?;
                flags.extend(["-L".to_string(), format!("native={}", objects.display())]);
                let mut cmd = Command::new(cargo);
                cmd.env("RUSTC", rustc)
                    .env("RUSTC_BOOTSTRAP", "1")
                    .env_remove("RUSTUP_TOOLCHAIN")
                    .env_remove("RUSTDOC")
                    .arg("-Zbuild-std=std,panic_unwind");
                after.push("--ignore-rust-version");
                cmd
            }
        };
        if let Ok(extra) = std::env::var("RUSTFLAGS") {
            flags.extend(extra.split_whitespace().map(String::from));
        }
        cmd.env("CARGO_TARGET_DIR", target_dir)
            .env("RUSTFLAGS", flags.join(" "))
            .args(["build", "--release", "--lib", "--target", TARGET])
            .args(after);
        for p in packages {
            cmd.args(["-p", p]);
        }
        Ok(cmd)
    }
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(program).is_file()))
}

fn sysroot(rustc: &Path) -> Option<PathBuf> {
    let out = Command::new(rustc)
        .args(["--print", "sysroot"])
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| PathBuf::from(String::from_utf8_lossy(&out.stdout).trim()))
}

fn version(rustc: &Path) -> Option<String> {
    let out = Command::new(rustc).arg("--version").output().ok()?;
    Some(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The target's standard library is installed beside `rustc`'s host one.
fn target_installed(rustc: &Path) -> bool {
    sysroot(rustc).is_some_and(|s| s.join("lib/rustlib").join(TARGET).join("lib").is_dir())
}

/// Compiles `rsbegin.o` and `rsend.o` from the standard library's source into `dir` (once).
fn startup_objects(rustc: &Path, library: &Path, dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    for name in ["rsbegin", "rsend"] {
        let object = dir.join(format!("{name}.o"));
        if object.exists() {
            continue;
        }
        let source = library.join("rtstartup").join(format!("{name}.rs"));
        crate::run(
            Command::new(rustc)
                .env("RUSTC_BOOTSTRAP", "1")
                .args(["--target", TARGET, "--emit=obj", "-C", "panic=abort", "-C"])
                .arg("opt-level=3")
                .arg("-o")
                .arg(&object)
                .arg(&source),
        )
        .with_context(|| format!("compiling {}", source.display()))?;
    }
    Ok(dir.to_path_buf())
}

/// The DLLs a win64 FMU binary may import: Windows' own (what Rust's std and `getrandom` use).
/// No MinGW runtime DLL: an FMU must load on a bare Windows.
pub const ALLOWED_IMPORTS: [&str; 9] = [
    "kernel32.dll",
    "advapi32.dll",
    "bcrypt.dll",
    "bcryptprimitives.dll",
    "msvcrt.dll",
    "ntdll.dll",
    "userenv.dll",
    "ws2_32.dll",
    "api-ms-win-core-synch-l1-2-0.dll",
];

/// Checks a win64 FMU binary: a PE32+ DLL exporting every FMI 2.0 function and importing only
/// [`ALLOWED_IMPORTS`].
pub fn check_dll(path: &Path) -> Result<()> {
    let data = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let pe = object::read::pe::PeFile64::parse(&*data)
        .with_context(|| format!("{} is not a 64-bit PE file", path.display()))?;
    let exported: std::collections::HashSet<String> = pe
        .exports()?
        .iter()
        .map(|e| String::from_utf8_lossy(e.name()).into_owned())
        .collect();
    let missing: Vec<&str> = fmi2::FUNCTION_NAMES
        .iter()
        .copied()
        .filter(|n| !exported.contains(*n))
        .collect();
    if !missing.is_empty() {
        bail!("{} does not export {}", path.display(), missing.join(", "));
    }
    let mut extra: Vec<String> = pe
        .imports()?
        .iter()
        .map(|i| String::from_utf8_lossy(i.library()).to_ascii_lowercase())
        .filter(|l| !ALLOWED_IMPORTS.contains(&l.as_str()))
        .collect();
    extra.sort();
    extra.dedup();
    if !extra.is_empty() {
        bail!(
            "{} imports {:?}; a win64 FMU may only import {:?}",
            path.display(),
            extra,
            ALLOWED_IMPORTS
        );
    }
    if pe.symbols().next().is_some() {
        bail!("{} is not stripped of its symbols", path.display());
    }
    Ok(())
}
