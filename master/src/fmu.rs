//! FMU import: unzip into a private temporary directory, parse `modelDescription.xml`, check the
//! FMI version, co-simulation support and binary, load the shared library and resolve every FMI
//! 2.0 function once (FMI 2.0 section 2.1 "Application Programming Interface", section 4 for the
//! co-simulation functions; the archive layout is section 2.3 "FMU Distribution").

use crate::error::{Error, Result};
use crate::limits::{Limits, MAX_MODEL_DESCRIPTION};
use crate::model_description::{CoSimulation, ModelDescription, ScalarVariable};
use fmi2::*;
use libloading::os::unix::{Library, RTLD_GLOBAL, RTLD_LOCAL, RTLD_NOW};
use std::collections::HashMap;
use std::ffi::c_void;
use std::io::{Read, Write};
use std::os::unix::fs::{DirBuilderExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Platform folder inside `binaries/` (FMI 2.0 section 2.3).
pub const PLATFORM: &str = if cfg!(target_os = "macos") {
    "darwin64"
} else if cfg!(target_os = "windows") {
    "win64"
} else {
    "linux64"
};
const LIB_EXT: &str = if cfg!(target_os = "macos") {
    "dylib"
} else if cfg!(target_os = "windows") {
    "dll"
} else {
    "so"
};

pub type VR = fmi2ValueReference;

/// Every FMI 2.0 common and co-simulation function, resolved once at load (like FMPy, a missing
/// export makes the FMU unloadable). The table and its signatures are `fmi2`'s, shared with the
/// export layer.
pub(crate) type Api = Fmi2Functions;

/// Resolves all 34 functions of `lib`; the first missing one is reported by name.
unsafe fn resolve(lib: &Library) -> std::result::Result<Api, String> {
    Fmi2Functions::resolve(|name| {
        let c = format!("{name}\0");
        match lib.get::<*const c_void>(c.as_bytes()) {
            Ok(p) => Ok(*p),
            Err(_) => Ok(std::ptr::null()),
        }
    })
}

/// The loaded binary plus the unpacked directory it lives in. Instances keep it alive through
/// an `Arc`; field order makes the library unload before the directory is removed.
pub(crate) struct FmuLibrary {
    /// None for an FMU opened without its binary ([`Fmu::open_unloaded`]).
    pub api: Option<Api>,
    lib: Option<Library>,
    /// The binary runs on the process's Python runtime ([`python`]).
    pub python: bool,
    _dir: tempfile::TempDir,
}

impl Drop for FmuLibrary {
    fn drop(&mut self) {
        if let Some(lib) = self.lib.take() {
            drop(lib);
        }
    }
}

/// A loaded FMI 2.0 co-simulation FMU, ready to instantiate (see [`crate::instance`]).
pub struct Fmu {
    /// The `.fmu` file it came from.
    pub path: PathBuf,
    pub model_description: ModelDescription,
    /// Unpacked directory (private, removed when the last user drops).
    pub unpacked: PathBuf,
    pub(crate) lib: Arc<FmuLibrary>,
    index: HashMap<String, usize>,
    /// SHA-256 of the `.fmu` file, computed on first use ([`Fmu::archive_hash`]).
    archive_hash: std::sync::OnceLock<String>,
}

impl std::fmt::Debug for Fmu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fmu").field("path", &self.path).finish()
    }
}

/// Unpacks a zip archive (an FMU, or an SSP for the SSP reader) into a new temporary directory.
pub fn unpack_archive(path: &Path, unpack: &Unpack) -> Result<tempfile::TempDir> {
    unpack_into_temp(path, unpack, None)
}

/// [`unpack_archive`] for an FMU: the binaries of other platforms than [`PLATFORM`] are checked
/// like every entry but not written (an FMU with linux64 and win64 binaries unpacks its `.so`
/// only); their folders are, so that [`UnpackedFmu::platforms`] lists them.
fn unpack_fmu_archive(path: &Path, unpack: &Unpack) -> Result<tempfile::TempDir> {
    unpack_into_temp(path, unpack, Some(PLATFORM))
}

fn unpack_into_temp(
    path: &Path,
    unpack: &Unpack,
    only_platform: Option<&str>,
) -> Result<tempfile::TempDir> {
    match crate::limits::regular(path) {
        Err(crate::limits::ReadError::NotRegular(what)) => {
            return Err(Error::fmu(
                path,
                format!("is {what}; an FMU is a zip archive (a .fmu file)"),
            ))
        }
        Err(crate::limits::ReadError::Io(e)) => {
            return Err(Error::fmu(path, format!("cannot open: {e}")))
        }
        _ => {}
    }
    let file =
        std::fs::File::open(path).map_err(|e| Error::fmu(path, format!("cannot open: {e}")))?;
    if file.metadata().is_ok_and(|m| m.is_dir()) {
        return Err(Error::fmu(
                path,
                "is a directory; an FMU is a zip archive (a .fmu file), an unpacked FMU folder cannot be used",
            ));
    }
    let declared = declared_entries(&file);
    let mut zip = zip::ZipArchive::new(file)
        .map_err(|e| Error::fmu(path, format!("not a valid FMU (zip) archive: {e}")))?;
    if declared.is_some_and(|n| n != zip.len() as u64) {
        return Err(Error::fmu(
                path,
                format!(
                    "cannot unpack the archive: it holds {} entries under {} names (a name appears twice; which copy is meant?); refused",
                    declared.unwrap_or(0),
                    zip.len()
                ),
            ));
    }
    let limits = &unpack.limits;
    if zip.len() as u64 > limits.max_files {
        return Err(Error::fmu(
                path,
                format!(
                    "the archive has {} entries, more than the limit of {}; if it is genuine, raise the limit (CLI --max-fmu-files, library Limits::max_files)",
                    zip.len(),
                    limits.max_files
                ),
            ));
    }
    let parent = unpack.parent.clone().unwrap_or_else(std::env::temp_dir);
    let dir = tempfile::Builder::new()
        .prefix("shipsim-fmu-")
        .permissions(std::fs::Permissions::from_mode(0o700))
        .tempdir_in(&parent)
        .map_err(|e| {
            Error::io(
                format!("creating a temporary directory in {}", parent.display()),
                e,
            )
        })?;
    Extraction {
        fmu: path,
        dir: dir.path(),
        unpack,
        only_platform,
        total: 0,
    }
    .all(&mut zip)?;
    Ok(dir)
}

/// Unpacks and parses an FMU without loading its binary (for `inspect` and validation).
pub struct UnpackedFmu {
    pub path: PathBuf,
    pub model_description: ModelDescription,
    pub dir: tempfile::TempDir,
}

/// How an FMU archive is unpacked ([`UnpackedFmu::open_with`], [`Fmu::load_with`]).
///
/// Every FMU gets its own directory `shipsim-fmu-*` (mode 0700) in `parent`; files are written
/// 0600 (0700 under `binaries/`), whatever modes the archive stores; directories 0700. Binaries
/// of other platforms than [`PLATFORM`] are checked but not written.
/// Symbolic links, absolute paths and `..` are refused, and so is an archive beyond
/// [`Limits`]. The directory is removed when the last user of the FMU drops it (also on an
/// error and while a panic unwinds); a process that wants to remove it on a signal too puts
/// `parent` (or `$TMPDIR`) in a directory of its own and removes that, as the CLI does.
#[derive(Clone, Debug, Default)]
pub struct Unpack {
    pub limits: Limits,
    /// Where the FMU's directory is created (default: the temporary directory, `$TMPDIR`).
    pub parent: Option<PathBuf>,
    /// Checked between entries and every 64 KiB of data: once set, unpacking stops with an
    /// error (the CLI's Ctrl-C flag).
    pub interrupt: Option<Arc<AtomicBool>>,
}

impl UnpackedFmu {
    /// [`UnpackedFmu::open_with`] with the default [`Unpack`] options.
    pub fn open(path: &Path) -> Result<UnpackedFmu> {
        UnpackedFmu::open_with(path, &Unpack::default())
    }

    /// Unpacks the archive (see [`Unpack`]) and parses its `modelDescription.xml`.
    pub fn open_with(path: &Path, unpack: &Unpack) -> Result<UnpackedFmu> {
        let dir = unpack_fmu_archive(path, unpack)?;
        let model_description = read_model_description(path, dir.path())?;
        Ok(UnpackedFmu {
            path: path.to_path_buf(),
            model_description,
            dir,
        })
    }

    /// FMI version and co-simulation checks (FMI 2.0 sections 2.2.1 and 4.3.1).
    pub fn check(&self) -> Result<&CoSimulation> {
        let md = &self.model_description;
        if !is_fmi2_version(&md.fmi_version) {
            return Err(Error::fmu(
                &self.path,
                format!(
                    "fmiVersion is \"{}\"; this master imports FMI 2.0 only",
                    md.fmi_version
                ),
            ));
        }
        let Some(cs) = &md.co_simulation else {
            return Err(Error::fmu(
                &self.path,
                if md.model_exchange.is_some() {
                    "the FMU supports only Model Exchange; a <CoSimulation> element is required"
                } else {
                    "modelDescription.xml has no <CoSimulation> element"
                },
            ));
        };
        if let Some(name) = md.duplicate_variable_name() {
            return Err(Error::fmu(
                &self.path,
                format!("modelDescription.xml declares the variable '{name}' twice (FMI 2.0, sec. 2.2.7: names are unique)"),
            ));
        }
        for (i, v) in md.model_variables.variables.iter().enumerate() {
            if v.var_type().is_none() {
                return Err(Error::fmu(
                    &self.path,
                    format!(
                        "variable '{}' (index {}) has no Real/Integer/Boolean/String/Enumeration element",
                        v.name,
                        i + 1
                    ),
                ));
            }
        }
        Ok(cs)
    }

    /// The platforms the archive has binaries for: the folders of `binaries/`, sorted (FMI 2.0,
    /// sec. 2.4: linux64, win64, darwin64, ...). This master loads [`PLATFORM`]'s.
    pub fn platforms(&self) -> Vec<String> {
        let mut found: Vec<String> = std::fs::read_dir(self.dir.path().join("binaries"))
            .map(|rd| {
                rd.flatten()
                    .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        found.sort();
        found
    }

    /// `binaries/<platform>/<modelIdentifier>.<ext>`: a regular file inside the unpacked
    /// directory (the identifier is checked to be a file name, and the resolved path to lie
    /// inside the directory).
    pub fn binary_path(&self) -> Result<PathBuf> {
        let cs = self.check()?;
        check_model_identifier(&self.path, &cs.model_identifier)?;
        let p = self
            .dir
            .path()
            .join("binaries")
            .join(PLATFORM)
            .join(format!("{}.{}", cs.model_identifier, LIB_EXT));
        let regular = std::fs::symlink_metadata(&p).is_ok_and(|m| m.file_type().is_file());
        if !regular {
            let found = self.platforms();
            return Err(Error::fmu(
                &self.path,
                format!(
                    "missing binary binaries/{PLATFORM}/{}.{LIB_EXT} (platforms in the archive: {})",
                    cs.model_identifier,
                    if found.is_empty() {
                        "none".to_string()
                    } else {
                        found.join(", ")
                    }
                ),
            ));
        }
        let inside = match (p.canonicalize(), self.dir.path().canonicalize()) {
            (Ok(bin), Ok(dir)) => bin.starts_with(dir),
            _ => false,
        };
        if !inside {
            return Err(Error::fmu(
                &self.path,
                format!(
                    "binaries/{PLATFORM}/{}.{LIB_EXT} resolves outside the unpacked FMU; refused",
                    cs.model_identifier
                ),
            ));
        }
        Ok(p)
    }
}

/// `fmiVersion` of FMI 2.0: "2.0" (FMI 2.0, sec. 2.2.1), also "2.0.x" as some tools of the
/// 2.0.x maintenance releases write it.
fn is_fmi2_version(v: &str) -> bool {
    match v.strip_prefix("2.0") {
        Some("") => true,
        Some(rest) => rest
            .strip_prefix('.')
            .is_some_and(|r| !r.is_empty() && r.bytes().all(|b| b.is_ascii_digit())),
        None => false,
    }
}

/// `modelDescription.xml` at the root of the unpacked archive: a regular file (never followed
/// through a link), read up to [`MAX_MODEL_DESCRIPTION`] bytes, parsed.
fn read_model_description(fmu: &Path, dir: &Path) -> Result<ModelDescription> {
    let md_path = dir.join("modelDescription.xml");
    let err = |m: String| Error::fmu(fmu, m);
    match std::fs::symlink_metadata(&md_path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(err(
                "the archive has no modelDescription.xml at its root".into()
            ))
        }
        Err(e) => return Err(err(format!("cannot read modelDescription.xml: {e}"))),
        Ok(m) if !m.file_type().is_file() => {
            return Err(err("modelDescription.xml is not a regular file".into()))
        }
        Ok(_) => {}
    }
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW)
        .open(&md_path)
        .map_err(|e| err(format!("cannot read modelDescription.xml: {e}")))?;
    let xml = crate::limits::read_limited_from(file, MAX_MODEL_DESCRIPTION)
        .map_err(|e| err(format!("cannot read modelDescription.xml: {e}")))?;
    ModelDescription::parse(&xml).map_err(|e| {
        err(format!(
            "modelDescription.xml does not parse as an FMI 2.0 model description: {e}"
        ))
    })
}

/// The number of entries the zip's end-of-central-directory record declares (APPNOTE.TXT
/// 4.3.16), or `None` when it cannot be read or the archive is zip64. The `zip` crate indexes
/// entries by name, so an archive that holds a name twice shows fewer entries than this.
fn declared_entries(file: &std::fs::File) -> Option<u64> {
    use std::os::unix::fs::FileExt;
    let len = file.metadata().ok()?.len();
    let tail_len = len.min(22 + 65_535);
    let mut tail = vec![0u8; tail_len as usize];
    file.read_exact_at(&mut tail, len - tail_len).ok()?;
    let at = tail
        .windows(4)
        .rposition(|w| w == [0x50, 0x4b, 0x05, 0x06])
        .filter(|&i| i + 22 <= tail.len())?;
    let n = u16::from_le_bytes([tail[at + 10], tail[at + 11]]);
    (n != 0xFFFF).then_some(u64::from(n))
}

/// Unpacking one archive into its private directory under [`Unpack`]'s rules.
struct Extraction<'a> {
    fmu: &'a Path,
    dir: &'a Path,
    unpack: &'a Unpack,
    /// `Some(platform)`: files under `binaries/<other platform>/` are not written.
    only_platform: Option<&'a str>,
    /// Bytes written so far.
    total: u64,
}

impl Extraction<'_> {
    fn err(&self, m: String) -> Error {
        Error::fmu(self.fmu, m)
    }

    fn interrupted(&self) -> bool {
        self.unpack
            .interrupt
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    fn all<R: Read + std::io::Seek>(&mut self, zip: &mut zip::ZipArchive<R>) -> Result<()> {
        for i in 0..zip.len() {
            if self.interrupted() {
                return Err(self.err("unpacking interrupted".into()));
            }
            let entry = zip
                .by_index(i)
                .map_err(|e| self.err(format!("cannot unpack the archive: {e}")))?;
            self.entry(entry)?;
        }
        Ok(())
    }

    /// One entry: a directory (created 0700) or a file (written 0600, 0700 under
    /// `binaries/`), never a link, never outside the directory, never past the limits.
    fn entry<R: Read>(&mut self, mut entry: zip::read::ZipFile<'_, R>) -> Result<()> {
        let name = entry.name().to_string();
        let Some(rel) = entry.enclosed_name() else {
            return Err(self.err(format!(
                "cannot unpack the archive: entry '{name}' is an absolute path or leaves the archive ('..'); refused"
            )));
        };
        if entry.is_symlink() {
            return Err(self.err(format!(
                "cannot unpack the archive: entry '{name}' is a symbolic link; links are refused (one could point outside the FMU)"
            )));
        }
        let out = self.dir.join(&rel);
        if entry.is_dir() {
            return self.create_dirs(&out);
        }
        if let Some(parent) = out.parent() {
            self.create_dirs(parent)?;
        }
        if self.other_platform(&rel) {
            return Ok(());
        }
        let limit = self.entry_limit(&name, entry.size(), entry.compressed_size())?;
        let mode = if rel.starts_with("binaries") {
            0o700
        } else {
            0o600
        };
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(mode)
            .custom_flags(libc::O_NOFOLLOW)
            .open(&out)
            .map_err(|e| match e.kind() {
                std::io::ErrorKind::AlreadyExists => self.err(format!(
                    "cannot unpack the archive: entry '{name}' appears twice (or clashes with a directory); refused"
                )),
                _ => self.err(format!("cannot unpack '{name}': {e}")),
            })?;
        let mut buf = vec![0u8; 64 << 10];
        let mut written = 0u64;
        loop {
            if self.interrupted() {
                return Err(self.err("unpacking interrupted".into()));
            }
            let n = entry
                .read(&mut buf)
                .map_err(|e| self.err(format!("cannot unpack '{name}': {e}")))?;
            if n == 0 {
                return Ok(());
            }
            written += n as u64;
            self.total += n as u64;
            if written > limit {
                return Err(self.over_limit(&name, written, entry.compressed_size()));
            }
            file.write_all(&buf[..n])
                .map_err(|e| self.err(format!("cannot unpack '{name}': {e}")))?;
        }
    }

    /// A file under `binaries/<platform>/` of another platform than the one unpacked for.
    fn other_platform(&self, rel: &Path) -> bool {
        let mut parts = rel.components();
        match (self.only_platform, parts.next(), parts.next(), parts.next()) {
            (Some(ours), Some(b), Some(p), Some(_)) => {
                b.as_os_str() == "binaries" && p.as_os_str() != ours
            }
            _ => false,
        }
    }

    /// Directories inside the unpacked directory, 0700.
    fn create_dirs(&self, dir: &Path) -> Result<()> {
        std::fs::DirBuilder::new()
            .recursive(true)
            .mode(0o700)
            .create(dir)
            .map_err(|e| self.err(format!("cannot unpack the archive: {}: {e}", dir.display())))
    }

    /// The most bytes the entry may unpack to: what is left of the size limit, and for an
    /// entry beyond [`Limits::RATIO_EXEMPT`] the ratio limit. Refused at once when the sizes
    /// the archive declares already break a limit.
    fn entry_limit(&self, name: &str, size: u64, compressed: u64) -> Result<u64> {
        let l = &self.unpack.limits;
        let by_ratio = l
            .max_ratio
            .saturating_mul(compressed.max(1))
            .max(Limits::RATIO_EXEMPT);
        let by_size = l.max_size.saturating_sub(self.total);
        let limit = by_ratio.min(by_size);
        if size > limit {
            return Err(self.over_limit(name, size, compressed));
        }
        Ok(limit)
    }

    /// The error for an entry that unpacks (or declares it unpacks) to `size` bytes, past a
    /// limit.
    fn over_limit(&self, name: &str, size: u64, compressed: u64) -> Error {
        let l = &self.unpack.limits;
        let hs = crate::limits::human_bytes;
        if size > Limits::RATIO_EXEMPT && size > l.max_ratio.saturating_mul(compressed.max(1)) {
            self.err(format!(
                "entry '{name}' unpacks to more than {} times its compressed size of {} bytes, the limit on the compression ratio (a zip bomb?); if the archive is genuine, raise the limit (CLI --max-fmu-ratio, library Limits::max_ratio)",
                l.max_ratio, compressed
            ))
        } else {
            self.err(format!(
                "unpacking entry '{name}' takes the archive past {}, the limit on the unpacked size of one FMU; if it is genuine, raise the limit (CLI --max-fmu-size, library Limits::max_size)",
                hs(l.max_size)
            ))
        }
    }
}

/// A `modelIdentifier` names the binary `binaries/<platform>/<modelIdentifier>.<ext>` (FMI 2.0,
/// sec. 2.3) and is "a short class name according to C-syntax" (FMI 2.0, sec. 4.3.1): a file
/// name, never a path. Separators, `..`, control characters and an empty name are refused.
fn check_model_identifier(fmu: &Path, id: &str) -> Result<()> {
    let bad = id.is_empty()
        || id == "."
        || id == ".."
        || id.contains(['/', '\\'])
        || id.chars().any(char::is_control);
    match bad {
        true => Err(Error::fmu(
            fmu,
            format!(
                "modelIdentifier {id:?} is not a file name (FMI 2.0, sec. 4.3.1: a C identifier); refused"
            ),
        )),
        false => Ok(()),
    }
}

/// Shared libraries loaded by [`Fmu::load`] in this process (a statistic: campaigns and
/// workers load each FMU once and make every run's instances from it).
static LOADS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// How many FMU shared libraries [`Fmu::load`] has loaded in this process so far.
pub fn load_count() -> usize {
    LOADS.load(std::sync::atomic::Ordering::Relaxed)
}

impl Fmu {
    /// Unpacks, parses, checks and loads an FMU (default [`Unpack`] options).
    pub fn load(path: impl AsRef<Path>) -> Result<Fmu> {
        Fmu::load_with(path, &Unpack::default())
    }

    /// Unpacks (see [`Unpack`]), parses, checks and loads an FMU.
    pub fn load_with(path: impl AsRef<Path>, unpack: &Unpack) -> Result<Fmu> {
        let path = path.as_ref();
        LOADS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let unpacked = UnpackedFmu::open_with(path, unpack)?;
        let cs = unpacked.check()?.clone();
        let bin = unpacked.binary_path()?;
        let (lib, uses_python) = open_binary(path, &unpacked, &cs, &bin)?;
        let api = unsafe { resolve(&lib) }.map_err(|m| Error::fmu(path, m))?;
        // fmi2GetVersion must be "2.0" (FMI 2.0 section 2.1.4).
        let version = unsafe { lossy_str((api.fmi2GetVersion)()) };
        if !version.starts_with("2.") {
            return Err(Error::fmu(
                path,
                format!("fmi2GetVersion() returned \"{version}\", expected \"2.0\""),
            ));
        }
        let unpacked_dir = unpacked.dir.path().to_path_buf();
        let md = unpacked.model_description;
        // The Python runtime must never be unloaded under an embedded interpreter: keep such
        // libraries loaded for the life of the process.
        let lib = if uses_python {
            std::mem::forget(lib);
            None
        } else {
            Some(lib)
        };
        let index = md.variable_index();
        Ok(Fmu {
            path: path.to_path_buf(),
            model_description: md,
            unpacked: unpacked_dir,
            lib: Arc::new(FmuLibrary {
                api: Some(api),
                lib,
                python: uses_python,
                _dir: unpacked.dir,
            }),
            index,
            archive_hash: Default::default(),
        })
    }

    /// Unpacks, parses and checks an FMU (its binary must be there) without loading the binary:
    /// its instances run in FMU host processes ([`crate::isolate`]), so a crash in the binary's
    /// initializers cannot take this process down.
    pub fn open_unloaded(path: impl AsRef<Path>, unpack: &Unpack) -> Result<Fmu> {
        let path = path.as_ref();
        let unpacked = UnpackedFmu::open_with(path, unpack)?;
        unpacked.binary_path()?;
        let index = unpacked.model_description.variable_index();
        Ok(Fmu {
            path: path.to_path_buf(),
            model_description: unpacked.model_description,
            unpacked: unpacked.dir.path().to_path_buf(),
            lib: Arc::new(FmuLibrary {
                api: None,
                lib: None,
                python: false,
                _dir: unpacked.dir,
            }),
            index,
            archive_hash: Default::default(),
        })
    }

    /// The binary is loaded in this process (not so after [`Fmu::open_unloaded`]).
    pub fn is_loaded(&self) -> bool {
        self.lib.api.is_some()
    }

    pub fn co_simulation(&self) -> &CoSimulation {
        self.model_description
            .co_simulation
            .as_ref()
            .expect("checked at load")
    }

    pub fn guid(&self) -> &str {
        &self.model_description.guid
    }

    /// SHA-256 (hex) of the `.fmu` file, read on the first call: it tells two builds of an FMU
    /// apart where the GUID does not (a checkpoint's fingerprint). The file is read again
    /// after loading, so one replaced in between is hashed as it is now.
    pub fn archive_hash(&self) -> Result<&str> {
        if let Some(h) = self.archive_hash.get() {
            return Ok(h);
        }
        let h = crate::digest::file_sha256(&self.path)?;
        Ok(self.archive_hash.get_or_init(|| h))
    }

    pub fn variable(&self, name: &str) -> Option<&ScalarVariable> {
        self.index
            .get(name)
            .map(|&i| &self.model_description.model_variables.variables[i])
    }

    pub fn variable_index(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }

    pub fn variables(&self) -> &[ScalarVariable] {
        &self.model_description.model_variables.variables
    }

    /// `file:///…/resources` URI of the unpacked resources folder (FMI 2.0 section 2.1.5:
    /// fmuResourceLocation is a URI, RFC 3986).
    pub fn resource_uri(&self) -> String {
        let p = self.unpacked.join("resources");
        let s = p.to_string_lossy();
        let mut out = String::from("file://");
        for b in s.bytes() {
            match b {
                b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'/' | b'-' | b'_' | b'.' | b'~' => {
                    out.push(b as char)
                }
                _ => out.push_str(&format!("%{b:02X}")),
            }
        }
        out
    }
}

/// Loads an FMU's binary (RTLD_NOW | RTLD_LOCAL); returns it and whether it runs on the Python
/// runtime [`python`] provides. That runtime is loaded first when the FMU declares
/// needsExecutionTool="true" (PythonFMU's default), and also when the binary fails to load
/// for want of a CPython symbol (`undefined symbol: _Py_NoneStruct`): PythonFMU's
/// `--no-external-tool` builds the same binary but declares needsExecutionTool="false", and
/// FMPy and libcosim (when run from Python) only run it because their process already holds
/// libpython. The load is then retried once.
fn open_binary(
    path: &Path,
    unpacked: &UnpackedFmu,
    cs: &CoSimulation,
    bin: &Path,
) -> Result<(Library, bool)> {
    let tool = || {
        unpacked
            .model_description
            .generation_tool
            .as_deref()
            .unwrap_or("unknown tool")
            .to_string()
    };
    if cs.needs_execution_tool {
        if let Err(msg) = python::ensure_runtime() {
            return Err(Error::fmu(
                path,
                format!("the FMU declares needsExecutionTool=\"true\" (generated by '{}') and needs a Python runtime in the process: {msg}", tool()),
            ));
        }
    }
    let name = bin.file_name().unwrap().to_string_lossy();
    // SAFETY: loading a foreign library runs its initializers; that is what importing means.
    let open = || unsafe { Library::open(Some(bin), RTLD_NOW | RTLD_LOCAL) };
    match open() {
        Ok(lib) => Ok((lib, cs.needs_execution_tool)),
        Err(e) if !cs.needs_execution_tool && python::missing_symbol(&e.to_string()) => {
            if let Err(msg) = python::ensure_runtime() {
                return Err(Error::fmu(
                    path,
                    format!("binaries/{PLATFORM}/{name} calls the Python C API ({e}; generated by '{}'), and no Python runtime could be loaded: {msg}", tool()),
                ));
            }
            open().map(|lib| (lib, true)).map_err(|e| {
                Error::fmu(path, format!("cannot load binaries/{PLATFORM}/{name} with the Python runtime loaded: {e}"))
            })
        }
        Err(e) => Err(Error::fmu(
            path,
            format!("cannot load binaries/{PLATFORM}/{name}: {e}"),
        )),
    }
}

/// Hosting PythonFMU-style FMUs (`needsExecutionTool="true"`, or built with
/// `--no-external-tool`, [`open_binary`]): their binaries call the CPython C API but do not link
/// libpython, expecting the host process to provide it. We load the shared libpython of the
/// chosen Python ([`python::python_executable`]) globally (RTLD_GLOBAL) before the FMU, and
/// point the embedded interpreter at that Python's module path so the FMU can import
/// `pythonfmu` and its own packages from there. One Python serves every such FMU of the process.
pub mod python {
    use super::*;
    use std::process::Command;
    use std::sync::OnceLock;

    static RUNTIME: OnceLock<std::result::Result<String, String>> = OnceLock::new();

    /// The Python whose runtime (libpython) and packages (`sys.path`) a PythonFMU runs on:
    /// `$SHIPSIM_PYTHON`, else `$VIRTUAL_ENV/bin/python3` (an activated virtual environment),
    /// else `python3` on PATH. It must be a Python with a shared libpython (`--enable-shared`;
    /// distribution and venv Pythons are) that has the FMU's imports installed (`pythonfmu`
    /// and whatever the slave imports). When the host is itself a Python process (the `shipsim`
    /// package), the runtime already there is used and none is loaded.
    pub fn python_executable() -> PathBuf {
        if let Some(p) = std::env::var_os("SHIPSIM_PYTHON") {
            return PathBuf::from(p);
        }
        if let Some(v) = std::env::var_os("VIRTUAL_ENV") {
            let p = PathBuf::from(v).join("bin").join("python3");
            if p.is_file() {
                return p;
            }
        }
        PathBuf::from("python3")
    }

    /// The dynamic loader's message names a missing CPython symbol (`undefined symbol:
    /// _Py_NoneStruct`, `undefined symbol: PyLong_FromLong`): the binary expects the host to
    /// provide libpython.
    pub fn missing_symbol(dlerror: &str) -> bool {
        dlerror
            .split("undefined symbol: ")
            .nth(1)
            .is_some_and(|sym| sym.starts_with("Py") || sym.starts_with("_Py"))
    }

    /// Loads libpython globally once per process; returns which Python (its version, executable
    /// and library) or why it failed.
    pub fn ensure_runtime() -> std::result::Result<String, String> {
        RUNTIME.get_or_init(load).clone()
    }

    const PROBE: &str = "import sys, sysconfig, os\n\
print(sysconfig.get_config_var('LIBDIR') or '')\n\
print(sysconfig.get_config_var('INSTSONAME') or '')\n\
print(sysconfig.get_config_var('LDLIBRARY') or '')\n\
print(sys.base_prefix)\n\
print(os.pathsep.join(p for p in sys.path if p))\n\
print(sysconfig.get_config_var('Py_ENABLE_SHARED'))\n\
print(sys.version.split()[0])\n";

    fn load() -> std::result::Result<String, String> {
        // Already present (e.g. the host is itself a Python process)?
        let this = Library::this();
        if unsafe { this.get::<*const c_void>(b"Py_IsInitialized\0") }.is_ok() {
            return Ok("the Python of this process".into());
        }
        let exe = python_executable();
        let out = Command::new(&exe).arg("-c").arg(PROBE).output().map_err(|e| {
            format!(
                "no suitable Python found: cannot run '{}' ({e}); install Python 3 with a shared libpython and the FMU's Python packages, or set SHIPSIM_PYTHON",
                exe.display()
            )
        })?;
        if !out.status.success() {
            return Err(format!(
                "'{}' failed: {}",
                exe.display(),
                String::from_utf8_lossy(&out.stderr)
            ));
        }
        let text = String::from_utf8_lossy(&out.stdout);
        let lines: Vec<&str> = text.lines().collect();
        if lines.len() < 7 {
            return Err(format!("unexpected output from '{}'", exe.display()));
        }
        let (libdir, soname, ldlib, base_prefix, syspath, _shared, version) = (
            lines[0], lines[1], lines[2], lines[3], lines[4], lines[5], lines[6],
        );
        let mut candidates = Vec::new();
        for name in [soname, ldlib] {
            if name.is_empty() || name.ends_with(".a") {
                continue;
            }
            candidates.push(Path::new(libdir).join(name));
            candidates.push(Path::new(base_prefix).join("lib").join(name));
        }
        let Some(libpath) = candidates.iter().find(|p| p.is_file()) else {
            return Err(format!(
                "Python {version} at '{}' has no shared libpython (looked for {}); use a Python built with --enable-shared or set SHIPSIM_PYTHON",
                exe.display(),
                candidates.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
            ));
        };
        // The embedded interpreter finds its standard library and packages through these
        // variables (set once, before any thread exists that could read the environment).
        if std::env::var_os("PYTHONHOME").is_none() {
            std::env::set_var("PYTHONHOME", base_prefix);
        }
        let mut pp = syspath.to_string();
        if let Some(old) = std::env::var_os("PYTHONPATH") {
            let old = old.to_string_lossy();
            if !old.is_empty() {
                pp = format!("{old}:{pp}");
            }
        }
        std::env::set_var("PYTHONPATH", pp);
        let lib = unsafe { Library::open(Some(libpath), RTLD_NOW | RTLD_GLOBAL) }
            .map_err(|e| format!("cannot load {}: {e}", libpath.display()))?;
        // Initialize the interpreter here, once, and release the GIL. PythonFMU binaries then
        // find it initialized: they take the GIL per call and never finalize it, so several
        // Python FMUs can share the process and exit does not run Py_Finalize twice.
        unsafe {
            let is_init = lib
                .get::<unsafe extern "C" fn() -> std::ffi::c_int>(b"Py_IsInitialized\0")
                .map_err(|e| format!("{}: {e}", libpath.display()))?;
            if is_init() == 0 {
                let init = lib
                    .get::<unsafe extern "C" fn(std::ffi::c_int)>(b"Py_InitializeEx\0")
                    .map_err(|e| format!("{}: {e}", libpath.display()))?;
                let save = lib
                    .get::<unsafe extern "C" fn() -> *mut c_void>(b"PyEval_SaveThread\0")
                    .map_err(|e| format!("{}: {e}", libpath.display()))?;
                // 0: do not install Python's signal handlers (Ctrl-C stays ours).
                init(0);
                if is_init() == 0 {
                    return Err(format!(
                        "Python {version} from {} failed to initialize (PYTHONHOME={base_prefix})",
                        libpath.display()
                    ));
                }
                save();
            }
        }
        std::mem::forget(lib);
        Ok(format!(
            "Python {version} at '{}' ({})",
            exe.display(),
            libpath.display()
        ))
    }
}
