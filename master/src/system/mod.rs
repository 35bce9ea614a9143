//! The format-neutral co-simulation system: what a system file says, whatever format it came in.
//!
//! - [`System`] and its parts ([`InstanceSpec`], [`ConnectionSpec`], [`EventSpec`],
//!   [`OutputSpec`]) are what the readers in [`crate::format`] produce: names and values as
//!   written, with the file and line they came from.
//! - [`validate`] checks a system against the FMUs' model descriptions and resolves it into a
//!   [`Plan`] ([`plan`]): instance indices, value references, types and step indices, everything
//!   the master ([`crate::run`]) needs before the first step.
//!
//! This module depends on no reader: `format::toml` and `format::osp` depend on it.

use crate::error::{did_you_mean, Error, Result};
use crate::fmu::UnpackedFmu;
use std::path::PathBuf;

pub mod io;
pub mod last_step;
pub mod plan;
pub mod validate;

pub use last_step::{LastStep, OffGrid};
pub use plan::{Plan, PlanConnection, PlanEvent, PlanInstance, PlanOutput, StartValue};

/// Master algorithm (implemented in [`crate::run::algorithm`]).
///
/// Its names are read by [`str::parse`] ([`Algorithm::from_str`](std::str::FromStr)), the one
/// parser of the TOML `[simulation] algorithm`, `shipsim run --algorithm` and Python's
/// `System.run(algorithm=...)`. Case does not matter (`Jacobi`, `GAUSS-SEIDEL`):
///
/// - `jacobi`: [`Algorithm::Jacobi`];
/// - `gauss-seidel`, `gauss_seidel`, `gauss seidel`, `gaussseidel`, `seidel`:
///   [`Algorithm::GaussSeidel`].
///
/// Any other name is an [`UnknownAlgorithm`], whose message is the same everywhere.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Algorithm {
    /// All instances step in parallel from the outputs of the previous communication point.
    #[default]
    Jacobi,
    /// Instances step one after another in connection order, each using the newest outputs.
    GaussSeidel,
}

impl std::str::FromStr for Algorithm {
    type Err = UnknownAlgorithm;

    /// The names listed at [`Algorithm`], in any case.
    fn from_str(name: &str) -> std::result::Result<Algorithm, UnknownAlgorithm> {
        match name.to_lowercase().as_str() {
            "jacobi" => Ok(Algorithm::Jacobi),
            "gauss-seidel" | "gauss_seidel" | "gauss seidel" | "gaussseidel" | "seidel" => {
                Ok(Algorithm::GaussSeidel)
            }
            _ => Err(UnknownAlgorithm(name.to_string())),
        }
    }
}

/// A name that is not one of [`Algorithm`]'s; its message:
/// `unknown algorithm "NAME"; use "jacobi" or "gauss-seidel"`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownAlgorithm(pub String);

impl std::fmt::Display for UnknownAlgorithm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "unknown algorithm \"{}\"; use \"jacobi\" or \"gauss-seidel\"",
            self.0
        )
    }
}

impl std::error::Error for UnknownAlgorithm {}

/// The format of the file a [`System`] was read from (set by its reader in [`crate::format`]):
/// what validation and the run's checks need to know about the file, without knowing the
/// readers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// shipsim's native TOML (`format::toml`).
    Toml,
    /// OSP `OspSystemStructure.xml` (`format::osp`).
    Osp,
    /// SSP 1.0: an `.ssp` archive or a `.ssd` file (`format::ssp`).
    Ssp,
    /// One FMU run alone (`format::fmu`).
    Fmu,
}

/// A value given in a system file or on the command line.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
    /// Unparsed text (from `--set`), converted by the variable's type during validation; for
    /// a Real it may be a `pi` expression and carry a unit (`90deg`, `15 kn`, `pi/2`),
    /// converted to the variable's declared unit ([`crate::units`]). A `String` value on a
    /// Real variable (a TOML string) is read the same way.
    Text(String),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Real(v) => write!(f, "{v}"),
            Value::Integer(v) => write!(f, "{v}"),
            Value::Boolean(v) => write!(f, "{v}"),
            Value::String(v) => write!(f, "\"{v}\""),
            Value::Text(v) => write!(f, "{v}"),
        }
    }
}

/// A value after checking it against the variable type.
#[derive(Debug, Clone, PartialEq)]
pub enum TypedValue {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(String),
}

#[derive(Debug, Clone)]
pub struct ValueSpec {
    pub variable: String,
    pub value: Value,
    pub line: Option<usize>,
}

#[derive(Debug, Clone)]
pub struct InstanceSpec {
    pub name: String,
    /// Path to the .fmu, resolved against the system file's directory.
    pub fmu: PathBuf,
    pub step_multiple: u32,
    pub values: Vec<ValueSpec>,
    pub line: Option<usize>,
    /// Run this instance out of process whatever the run's isolation option (TOML
    /// `isolate = true`; [`crate::isolate`]): an FMU known to crash or hang.
    pub isolate: bool,
}

/// `instance.variable`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct VarRef {
    pub instance: String,
    pub variable: String,
}

impl std::fmt::Display for VarRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.instance, self.variable)
    }
}

impl VarRef {
    /// Splits at the first dot: instance names cannot contain dots, variable names may.
    pub fn parse(s: &str) -> Option<VarRef> {
        let (i, v) = s.trim().split_once('.')?;
        if i.is_empty() || v.is_empty() {
            return None;
        }
        Some(VarRef {
            instance: i.to_string(),
            variable: v.to_string(),
        })
    }
}

#[derive(Debug, Clone)]
pub struct ConnectionSpec {
    pub from: VarRef,
    pub to: VarRef,
    pub gain: f64,
    pub offset: f64,
    pub line: Option<usize>,
    /// OSP VariableConnection: the direction follows the variables' causalities.
    pub either_direction: bool,
    /// The gain converts between physically different quantities (e.g. a wave moment in N.m
    /// into a rudder-equivalent disturbance in rad): the unit check is skipped for it.
    pub convert: bool,
    /// A term of a summed input: every connection into the input says so, and the input gets
    /// the sum of their `gain*from + offset`, added in the order of [`System::connections`]
    /// (TOML `sum = true`; an OSP `Sum` function's inputs `in[0]`, `in[1]`, ...). Without it a
    /// second connection into an input is an error.
    pub sum: bool,
    /// A value mapping of an Integer, Enumeration or Boolean connection (SSP 1.0 mapping
    /// transformations); None passes values unchanged.
    pub mapping: Option<ValueMapping>,
}

/// A table that maps the values of a discrete connection: SSP 1.0
/// `IntegerMappingTransformation`, `EnumerationMappingTransformation` (by item values) and
/// `BooleanMappingTransformation` (`SystemStructureCommon.xsd`, `GTransformationChoice`).
/// Sorted by source, one entry per source; a value without an entry passes unchanged.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ValueMapping {
    /// Boolean (values 0/1; any nonzero source counts as 1) or Integer/Enumeration.
    pub boolean: bool,
    entries: Vec<(i32, i32)>,
}

impl ValueMapping {
    /// The table of (source, target) pairs; a source given twice is an error.
    pub fn new(boolean: bool, mut entries: Vec<(i32, i32)>) -> std::result::Result<Self, String> {
        entries.sort_by_key(|e| e.0);
        if let Some(w) = entries.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(format!("source value {} is mapped twice", w[0].0));
        }
        Ok(ValueMapping { boolean, entries })
    }

    /// The (source, target) pairs, by source.
    pub fn entries(&self) -> &[(i32, i32)] {
        &self.entries
    }

    /// The mapped value (a binary search; no allocation).
    #[inline]
    pub fn apply(&self, value: i32) -> i32 {
        let key = if self.boolean {
            i32::from(value != 0)
        } else {
            value
        };
        match self.entries.binary_search_by_key(&key, |e| e.0) {
            Ok(k) => self.entries[k].1,
            Err(_) => value,
        }
    }
}

#[derive(Debug, Clone)]
pub struct EventSpec {
    pub time: f64,
    pub target: VarRef,
    pub value: Value,
    pub line: Option<usize>,
}

#[derive(Debug, Clone, Default)]
pub struct OutputSpec {
    pub file: Option<PathBuf>,
    /// `inst.var` or `inst.*`; None = every output variable of every instance.
    pub variables: Option<Vec<String>>,
    pub decimation: u32,
}

/// A co-simulation system, whatever file it came from.
#[derive(Debug, Clone)]
pub struct System {
    pub source: PathBuf,
    /// The format of [`System::source`].
    pub format: Format,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    pub step_size: f64,
    pub algorithm: Algorithm,
    pub instances: Vec<InstanceSpec>,
    pub connections: Vec<ConnectionSpec>,
    pub events: Vec<EventSpec>,
    pub output: OutputSpec,
    /// Units that do not match on a connection are an error (true) or a warning (false). The
    /// native TOML reader sets it (a connection between different quantities says
    /// `convert = true` there); the OSP reader does not, because libcosim runs OSP files
    /// without a unit check and third-party FMUs declare units loosely (`dimensionless` for an
    /// energy). `shipsim run/check --strict-units` sets it for any file.
    pub strict_units: bool,
    /// A stop time off the base-step grid: stop before it (the default) or take a short last
    /// step to it (TOML `[simulation] last_step`, `shipsim run --last-step`).
    pub last_step: LastStep,
    /// The unpacked SSP archive the FMU paths point into, kept as long as the system (set by
    /// the SSP reader for `.ssp` files).
    pub archive: Option<std::sync::Arc<tempfile::TempDir>>,
    /// What the reader chose for the user where the file does not say (`shipsim run` prints
    /// them): an FMU run alone names its time span and output file.
    pub notes: Vec<String>,
    /// The `[[io]]` channels of a native TOML file ([`io`]): used by a paced or I/O run
    /// ([`crate::realtime`]), ignored by every other.
    pub io: Vec<io::IoSpec>,
}

/// How a run whose file gives no step size (an SSD without a fixed-step master annotation:
/// SSP 1.0 defines none) is given one, the same words for every entry point.
const GIVE_STEP_SIZE: &str = "give the run a step size: shipsim run --step-size SECONDS, \
     System.run(step_size=SECONDS) in Python, or step_size = SECONDS in a campaign file";

/// The message for a system without a step size.
pub(crate) fn no_step_size() -> String {
    format!(
        "the file gives no step size (SSP 1.0 defines none; OSP's <osp:FixedStepAlgorithm \
         baseStepSize> or OMSimulator's <oms:FixedStepMaster stepSize> would); {GIVE_STEP_SIZE}"
    )
}

/// How a run whose file has no end time is given one, the same words for every entry point.
const GIVE_STOP_TIME: &str = "give the run a stop time: shipsim run --stop-time SECONDS, \
     System.run(stop_time=SECONDS) in Python, or stop_time = SECONDS in a campaign file";

impl System {
    /// The stop time of a run: the one its caller gives, if any (`shipsim run --stop-time`,
    /// Python's `System.run(stop_time=...)`, a campaign file's `stop_time`), replaces the
    /// file's; then the run must have one ([`System::require_stop_time`]). Every entry point
    /// of a run calls this, so that all of them accept and refuse the same files with the same
    /// message.
    pub fn apply_stop_time(&mut self, given: Option<f64>) -> Result<()> {
        if let Some(t) = given {
            self.stop_time = Some(t);
        }
        self.require_stop_time()
    }

    /// The step size of a run: the one its caller gives, if any (`shipsim run --step-size`,
    /// Python's `System.run(step_size=...)`, a campaign file's `step_size`), replaces the
    /// file's. A file that gives none (`step_size` NaN: an SSD without an OSP or OMSimulator
    /// fixed-step annotation) then needs one: an error naming the file and the three ways.
    pub fn apply_step_size(&mut self, given: Option<f64>) -> Result<()> {
        if let Some(h) = given {
            self.step_size = h;
        }
        if !self.step_size.is_nan() {
            return Ok(());
        }
        Err(Error::system(&self.source, None, no_step_size()))
    }

    /// The end-time rule of a run: an OSP file may leave out `<EndTime>` (libcosim then runs
    /// until it is stopped) and an SSD `DefaultExperiment@stopTime`; shipsim needs an end. A
    /// system read from such a file whose stop time was not set since is an error naming the
    /// file, instead of the one-second run that the validation's default stop time
    /// (start + 1 s) would give. A TOML file without `stop_time` keeps that default.
    /// `shipsim check` and Python's `System.check` validate without this rule: they run
    /// nothing.
    pub fn require_stop_time(&self) -> Result<()> {
        let missing = match (self.stop_time, self.format) {
            (Some(_), _) | (None, Format::Toml | Format::Fmu) => return Ok(()),
            (None, Format::Osp) => "<EndTime>",
            (None, Format::Ssp) => "<DefaultExperiment stopTime=\"...\">",
        };
        Err(Error::system(
            &self.source,
            None,
            format!("the file has no {missing}; {GIVE_STOP_TIME}"),
        ))
    }

    /// The instance's FMU file exists (an error naming the file, line and instance if not).
    pub fn require_fmu(&self, inst: &InstanceSpec) -> Result<()> {
        if inst.fmu.exists() {
            return Ok(());
        }
        Err(Error::system(
            &self.source,
            inst.line,
            format!(
                "instance '{}': FMU file '{}' not found",
                inst.name,
                inst.fmu.display()
            ),
        ))
    }

    /// Every instance's FMU unpacked, with its model description read (binaries not loaded).
    pub fn unpack_fmus(&self) -> Result<Vec<UnpackedFmu>> {
        self.instances
            .iter()
            .map(|inst| {
                self.require_fmu(inst)?;
                UnpackedFmu::open(&inst.fmu)
            })
            .collect()
    }

    /// Applies `--set inst.var=value` overrides (they replace values from the file). The value
    /// is kept as text and checked against the variable (type, unit, declared range) when the
    /// system is validated.
    pub fn apply_overrides(&mut self, sets: &[String]) -> Result<()> {
        for s in sets {
            let parsed = s
                .split_once('=')
                .and_then(|(l, r)| Some((VarRef::parse(l)?, r)));
            let Some((r, rhs)) = parsed else {
                return Err(Error::Other(format!(
                    "--set {s}: expected instance.variable=value"
                )));
            };
            self.set_value(r, Value::Text(rhs.trim().to_string()))
                .map_err(|e| Error::Other(format!("--set {s}: {e}")))?;
        }
        Ok(())
    }

    /// Sets a start value of an instance's variable, replacing one from the file (the value
    /// is checked against the variable when the system is validated).
    pub fn set_value(&mut self, r: VarRef, value: Value) -> Result<()> {
        let Some(i) = self.instances.iter().position(|i| i.name == r.instance) else {
            let names = self.instances.iter().map(|i| i.name.as_str());
            return Err(Error::Other(format!(
                "no instance '{}'{}",
                r.instance,
                did_you_mean(&r.instance, names)
            )));
        };
        let inst = &mut self.instances[i];
        inst.values.retain(|v| v.variable != r.variable);
        inst.values.push(ValueSpec {
            variable: r.variable,
            value,
            line: None,
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::Algorithm;

    #[test]
    fn algorithm_names_in_any_case_and_one_message_for_the_rest() {
        for name in ["jacobi", "Jacobi", "JACOBI"] {
            assert_eq!(name.parse(), Ok(Algorithm::Jacobi));
        }
        for name in [
            "gauss-seidel",
            "gauss_seidel",
            "gauss seidel",
            "gaussseidel",
            "seidel",
            "Gauss-Seidel",
            "GAUSS_SEIDEL",
            "Seidel",
        ] {
            assert_eq!(name.parse(), Ok(Algorithm::GaussSeidel), "{name}");
        }
        for name in ["", " jacobi", "gauss--seidel", "gauss", "rk4"] {
            assert_eq!(
                name.parse::<Algorithm>().unwrap_err().to_string(),
                format!("unknown algorithm \"{name}\"; use \"jacobi\" or \"gauss-seidel\"")
            );
        }
    }
}
