//! FMU import: unzip into a private temporary directory, parse `modelDescription.xml`, check the
//! FMI version, co-simulation support and binary, load the shared library and resolve every FMI
//! 2.0 function once (FMI 2.0 section 2.1 "Application Programming Interface", section 4 for the
//! co-simulation functions; the archive layout is section 2.3 "FMU Distribution").

use crate::error::{Error, Result};
use crate::model_description::{CoSimulation, ModelDescription, ScalarVariable};
use fmi2::*;
use libloading::os::unix::{Library, RTLD_GLOBAL, RTLD_LOCAL, RTLD_NOW};
use std::collections::HashMap;
use std::ffi::c_void;
use std::path::{Path, PathBuf};
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
}

impl std::fmt::Debug for Fmu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fmu").field("path", &self.path).finish()
    }
}

/// Unpacks and parses an FMU without loading its binary (for `inspect` and validation).
pub struct UnpackedFmu {
    pub path: PathBuf,
    pub model_description: ModelDescription,
    pub dir: tempfile::TempDir,
}

impl UnpackedFmu {
    pub fn open(path: &Path) -> Result<UnpackedFmu> {
        let file =
            std::fs::File::open(path).map_err(|e| Error::fmu(path, format!("cannot open: {e}")))?;
        let mut zip = zip::ZipArchive::new(file)
            .map_err(|e| Error::fmu(path, format!("not a valid FMU (zip) archive: {e}")))?;
        let dir = tempfile::Builder::new()
            .prefix("shipsim-fmu-")
            .tempdir()
            .map_err(|e| Error::io("creating a temporary directory", e))?;
        zip.extract(dir.path())
            .map_err(|e| Error::fmu(path, format!("cannot unpack the archive: {e}")))?;
        let md_path = dir.path().join("modelDescription.xml");
        let xml = std::fs::read_to_string(&md_path).map_err(|e| {
            Error::fmu(
                path,
                if e.kind() == std::io::ErrorKind::NotFound {
                    "the archive has no modelDescription.xml at its root".to_string()
                } else {
                    format!("cannot read modelDescription.xml: {e}")
                },
            )
        })?;
        let model_description = ModelDescription::parse(&xml).map_err(|e| {
            Error::fmu(
                path,
                format!("modelDescription.xml does not parse as an FMI 2.0 model description: {e}"),
            )
        })?;
        Ok(UnpackedFmu {
            path: path.to_path_buf(),
            model_description,
            dir,
        })
    }

    /// FMI version and co-simulation checks (FMI 2.0 sections 2.2.1 and 4.3.1).
    pub fn check(&self) -> Result<&CoSimulation> {
        let md = &self.model_description;
        if !md.fmi_version.starts_with("2.") {
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

    pub fn binary_path(&self) -> Result<PathBuf> {
        let cs = self.check()?;
        let p = self
            .dir
            .path()
            .join("binaries")
            .join(PLATFORM)
            .join(format!("{}.{}", cs.model_identifier, LIB_EXT));
        if !p.is_file() {
            let mut found = Vec::new();
            if let Ok(rd) = std::fs::read_dir(self.dir.path().join("binaries")) {
                for e in rd.flatten() {
                    found.push(e.file_name().to_string_lossy().into_owned());
                }
            }
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
        Ok(p)
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
    /// Unpacks, parses, checks and loads an FMU.
    pub fn load(path: impl AsRef<Path>) -> Result<Fmu> {
        let path = path.as_ref();
        LOADS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let unpacked = UnpackedFmu::open(path)?;
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
                _dir: unpacked.dir,
            }),
            index,
        })
    }

    /// Unpacks, parses and checks an FMU (its binary must be there) without loading the binary:
    /// its instances run in FMU host processes ([`crate::isolate`]), so a crash in the binary's
    /// initializers cannot take this process down.
    pub fn open_unloaded(path: impl AsRef<Path>) -> Result<Fmu> {
        let path = path.as_ref();
        let unpacked = UnpackedFmu::open(path)?;
        unpacked.binary_path()?;
        let index = unpacked.model_description.variable_index();
        Ok(Fmu {
            path: path.to_path_buf(),
            model_description: unpacked.model_description,
            unpacked: unpacked.dir.path().to_path_buf(),
            lib: Arc::new(FmuLibrary {
                api: None,
                lib: None,
                _dir: unpacked.dir,
            }),
            index,
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

    /// Loads libpython globally once per process; returns the library path or why it failed.
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
            return Ok("(already in the process)".into());
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
        Ok(libpath.display().to_string())
    }
}
