//! Loading an FMU binary for fuzzing, and what the fuzzer knows of its variables.
//!
//! This is a test tool that must make calls the master's importer never makes (illegal call
//! sequences, NULL arrays, foreign and freed FMU states), so it loads the shared library itself
//! with `libloading` and calls the raw function table of `fmi2` (FFI outside the importer,
//! confined to the fuzzer). The archive is unpacked and its model description parsed by the
//! master's [`shipsim::fmu::UnpackedFmu`].

use fmi2::*;
use shipsim::model_description::{ModelDescription, ScalarVariable, VarType};
use std::cell::RefCell;
use std::ffi::{c_char, c_int, c_void, CString};
use std::path::{Path, PathBuf};

/// One variable as the fuzzer draws from it.
#[derive(Clone, Debug)]
pub struct Var {
    pub name: String,
    pub vr: u32,
    pub ty: VarType,
    pub causality: Causality,
    pub variability: Variability,
    /// Declared range (Real, Integer, Enumeration); infinite when not declared.
    pub min: f64,
    pub max: f64,
    pub start: Option<f64>,
    pub settable_instantiated: bool,
}

impl Var {
    fn new(v: &ScalarVariable) -> Option<Var> {
        let ty = v.var_type()?;
        let (min, max, start) = if let Some(r) = &v.real {
            (r.min, r.max, r.start)
        } else if let Some(i) = v.integer.as_ref().or(v.enumeration.as_ref()) {
            (
                i.min.map(f64::from),
                i.max.map(f64::from),
                i.start.map(f64::from),
            )
        } else if let Some(b) = &v.boolean {
            (
                Some(0.0),
                Some(1.0),
                b.start.map(|b| f64::from(u8::from(b))),
            )
        } else {
            (None, None, None)
        };
        let (lo, hi) = match ty {
            VarType::Real => (f64::NEG_INFINITY, f64::INFINITY),
            _ => (f64::from(i32::MIN), f64::from(i32::MAX)),
        };
        Some(Var {
            name: v.name.clone(),
            vr: v.value_reference,
            ty,
            causality: v.causality,
            variability: v.variability,
            min: min.unwrap_or(lo),
            max: max.unwrap_or(hi),
            start,
            settable_instantiated: v.settable_in_instantiated(),
        })
    }

    /// A parameter that may be given a value before initialization.
    pub fn is_parameter(&self) -> bool {
        self.causality == Causality::Parameter
            && matches!(self.variability, Variability::Fixed | Variability::Tunable)
    }
}

/// The variables of one FMU by base type (Enumerations with Integers: they share
/// fmi2Get/SetInteger, FMI 2.0 sec. 2.2.7).
#[derive(Clone, Debug, Default)]
pub struct Model {
    pub name: String,
    pub guid: String,
    pub real: Vec<Var>,
    pub integer: Vec<Var>,
    pub boolean: Vec<Var>,
    pub string: Vec<Var>,
    /// Value references of the Real outputs: checked for finiteness after every fmi2OK.
    pub real_outputs: Vec<u32>,
    pub default_step: f64,
}

impl Model {
    pub fn new(md: &ModelDescription) -> Model {
        let mut m = Model {
            name: md
                .co_simulation
                .as_ref()
                .map_or(md.model_name.clone(), |c| c.model_identifier.clone()),
            guid: md.guid.clone(),
            default_step: md
                .default_experiment
                .as_ref()
                .and_then(|d| d.step_size)
                .filter(|h| h.is_finite() && *h > 0.0)
                .unwrap_or(0.1),
            ..Model::default()
        };
        for v in md.model_variables.variables.iter().filter_map(Var::new) {
            if v.ty == VarType::Real && v.causality == Causality::Output {
                m.real_outputs.push(v.vr);
            }
            match v.ty {
                VarType::Real => m.real.push(v),
                VarType::Integer | VarType::Enumeration => m.integer.push(v),
                VarType::Boolean => m.boolean.push(v),
                VarType::String => m.string.push(v),
            }
        }
        m
    }

    pub fn of(&self, ty: VarType) -> &[Var] {
        match ty {
            VarType::Real => &self.real,
            VarType::Integer | VarType::Enumeration => &self.integer,
            VarType::Boolean => &self.boolean,
            VarType::String => &self.string,
        }
    }

    /// Every parameter of a numeric or Boolean type.
    pub fn parameters(&self) -> impl Iterator<Item = &Var> {
        self.real
            .iter()
            .chain(&self.integer)
            .chain(&self.boolean)
            .filter(|v| v.is_parameter())
    }
}

/// An unpacked FMU: its directory (kept by the parent for the whole run) and its model.
pub struct Unpacked {
    pub fmu: PathBuf,
    pub dir: PathBuf,
    pub binary: PathBuf,
    pub md: ModelDescription,
    _keep: Option<tempfile::TempDir>,
}

impl Unpacked {
    /// Unpacks `fmu` with the master's reader (parent side).
    pub fn open(fmu: &Path) -> Result<Unpacked, String> {
        let u = shipsim::fmu::UnpackedFmu::open(fmu).map_err(|e| e.to_string())?;
        let binary = u.binary_path().map_err(|e| e.to_string())?;
        Ok(Unpacked {
            fmu: fmu.to_path_buf(),
            dir: u.dir.path().to_path_buf(),
            binary,
            md: u.model_description,
            _keep: Some(u.dir),
        })
    }

    /// An FMU the parent unpacked into `dir` (child side).
    pub fn at(dir: &Path) -> Result<Unpacked, String> {
        let xml = std::fs::read_to_string(dir.join("modelDescription.xml"))
            .map_err(|e| format!("{}: {e}", dir.display()))?;
        let md = ModelDescription::parse(&xml).map_err(|e| e.to_string())?;
        let id = md
            .co_simulation
            .as_ref()
            .ok_or("no <CoSimulation>")?
            .model_identifier
            .clone();
        Ok(Unpacked {
            fmu: dir.to_path_buf(),
            dir: dir.to_path_buf(),
            binary: dir.join(format!("binaries/{}/{id}.so", shipsim::fmu::PLATFORM)),
            md,
            _keep: None,
        })
    }
}

/// A loaded binary with its function table.
pub struct Loaded {
    pub api: Fmi2Functions,
    pub model: Model,
    pub guid: CString,
    pub resources: CString,
    _lib: libloading::Library,
}

impl Loaded {
    pub fn load(u: &Unpacked) -> Result<Loaded, String> {
        // SAFETY: loading the FMU's binary runs its initializers; that is what is fuzzed.
        let lib = unsafe { libloading::Library::new(&u.binary) }
            .map_err(|e| format!("{}: {e}", u.binary.display()))?;
        // SAFETY: the symbols are the FMI 2.0 functions of that name (FMI 2.0 sec. 2.1).
        let api = unsafe {
            Fmi2Functions::resolve(|name| {
                Ok(lib
                    .get::<*const c_void>(name.as_bytes())
                    .map(|p| *p)
                    .unwrap_or(std::ptr::null()))
            })
        }?;
        let res = format!("file://{}/resources", u.dir.display());
        Ok(Loaded {
            api,
            model: Model::new(&u.md),
            guid: CString::new(u.md.guid.clone()).map_err(|e| e.to_string())?,
            resources: CString::new(res).map_err(|e| e.to_string())?,
            _lib: lib,
        })
    }
}

thread_local! {
    /// The last message the FMU logged (shown with a failure).
    pub static LAST_LOG: RefCell<String> = const { RefCell::new(String::new()) };
}

unsafe extern "C" fn sink(
    _ctx: *mut c_void,
    _instance: *const c_char,
    status: c_int,
    _category: *const c_char,
    message: *const c_char,
) {
    let text = lossy_str(message);
    LAST_LOG.with(|l| {
        let mut l = l.borrow_mut();
        l.clear();
        l.push_str(status_name(status));
        l.push_str(": ");
        l.extend(text.chars().take(300));
    });
}

unsafe extern "C" fn alloc(n: usize, size: usize) -> *mut c_void {
    libc::calloc(n, size)
}

unsafe extern "C" fn dealloc(p: *mut c_void) {
    libc::free(p)
}

/// The callbacks every instance gets (leaked once: they outlive every instance). `null_logger`
/// gives the variant without a logger, which fmi2Instantiate must refuse.
pub fn callbacks(null_logger: bool) -> *const fmi2CallbackFunctions {
    static PTRS: std::sync::OnceLock<[usize; 2]> = std::sync::OnceLock::new();
    let p = PTRS.get_or_init(|| {
        let target = Box::leak(Box::new(LogTarget {
            sink: Some(sink),
            ctx: std::ptr::null_mut(),
        }));
        let env = target as *mut LogTarget as *mut c_void;
        let make = |logger| {
            Box::leak(Box::new(fmi2CallbackFunctions {
                logger,
                allocateMemory: Some(alloc),
                freeMemory: Some(dealloc),
                stepFinished: None,
                componentEnvironment: env,
            })) as *const fmi2CallbackFunctions as usize
        };
        [make(logger_proxy()), make(None)]
    });
    p[usize::from(null_logger)] as *const fmi2CallbackFunctions
}
