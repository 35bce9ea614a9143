//! Crash isolation: FMU instances run out of process, one `shipsim fmu-host` child process per
//! instance, in the spirit of OSP's proxy-fmu (which spawns one process per instance and
//! forwards the FMI calls over RPC). A segfault, `abort()`, `exit()` or hang of the FMU then ends
//! the child, not the master: the master reports an error naming the instance, the FMI call and
//! the simulation time, and the run ends through its normal error path (the recorder keeps every
//! row up to the last completed step).
//!
//! - [`protocol`]: the frames on the two pipes (one FMI call per request, log messages and one
//!   reply back);
//! - [`client`]: the master's end, [`Client`], the out-of-process [`crate::slave::Slave`]
//!   (preallocated buffers: a step allocates nothing);
//! - [`host`]: the child's end, `shipsim fmu-host FMU`, which loads the FMU with the same
//!   importer ([`crate::fmu`]) and serves each request through the in-process slave
//!   ([`crate::slave::InProcess`]), so that the FMU is called the same way in both;
//! - [`options`]: the run's isolation options as the CLI and Python give them, one parser.
//!
//! docs/isolation.md is the user's guide.

mod client;
pub mod host;
pub mod options;
mod protocol;

use crate::error::{Error, Result};
use crate::model_description::ModelDescription;
use std::ffi::OsString;
use std::path::PathBuf;
use std::sync::OnceLock;
use std::time::Duration;

pub use client::Client;
pub use options::IsolationError;

/// Which instances of a run are isolated.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum IsolateMode {
    /// Every instance in process (the default).
    #[default]
    None,
    /// Every instance in its own process.
    All,
    /// The instances of FMUs not built by this project ([`is_ours`]).
    Foreign,
    /// The named instances.
    Instances(Vec<String>),
}

/// Out-of-process options of a run ([`crate::run::RunOptions::isolation`]).
#[derive(Clone, Debug, Default)]
pub struct Isolation {
    pub mode: IsolateMode,
    /// The longest wall time one FMI call of an isolated instance may take; the child is killed
    /// after it and the run fails naming the call. None: no limit (Ctrl-C still stops a hung
    /// child).
    pub call_timeout: Option<Duration>,
    /// The `shipsim` executable that hosts the FMUs; default: `$SHIPSIM_FMU_HOST`, else this
    /// executable if it is `shipsim`.
    pub host: Option<PathBuf>,
}

/// The generationTool of the FMUs this project builds (fmus/export/src/xml.rs).
const OUR_GENERATION_TOOL: &str = "ship-control fmi2-export ";

/// The FMU was built by this project's export layer (its generationTool says so). Its
/// functions are checked by our tests and fuzzing; any other FMU is foreign.
pub fn is_ours(md: &ModelDescription) -> bool {
    md.generation_tool
        .as_deref()
        .is_some_and(|t| t.starts_with(OUR_GENERATION_TOOL))
}

impl Isolation {
    /// Isolation for the instances of foreign FMUs ([`is_ours`]).
    pub fn foreign() -> Isolation {
        Isolation {
            mode: IsolateMode::Foreign,
            ..Default::default()
        }
    }

    /// Instance `name` of an FMU with model description `md` runs out of process.
    pub fn applies(&self, name: &str, md: &ModelDescription) -> bool {
        match &self.mode {
            IsolateMode::None => false,
            IsolateMode::All => true,
            IsolateMode::Foreign => !is_ours(md),
            IsolateMode::Instances(names) => names.iter().any(|n| n == name),
        }
    }

    /// The command that hosts FMUs, run as `PROGRAM ARGS... fmu-host FMU`:
    /// [`Isolation::host`], `$SHIPSIM_FMU_HOST`, this executable when it is `shipsim`, or the
    /// command the embedding program set ([`set_host_command`]: the Python package's
    /// interpreter with `-m shipsim._fmu_host`).
    pub fn host_command(&self) -> Result<(PathBuf, Vec<OsString>)> {
        if let Some(h) = &self.host {
            return Ok((h.clone(), Vec::new()));
        }
        if let Some(h) = std::env::var_os("SHIPSIM_FMU_HOST") {
            return Ok((PathBuf::from(h), Vec::new()));
        }
        let exe = std::env::current_exe().ok();
        let is_shipsim = exe
            .as_ref()
            .and_then(|e| e.file_name())
            .is_some_and(|n| n == "shipsim");
        match (exe, HOST_COMMAND.get()) {
            (Some(e), _) if is_shipsim => Ok((e, Vec::new())),
            (_, Some((program, args))) => Ok((program.clone(), args.clone())),
            _ => Err(Error::Other(
                "isolated FMU instances run in `shipsim fmu-host` processes, and this process is not shipsim: set SHIPSIM_FMU_HOST to the shipsim executable".into(),
            )),
        }
    }
}

/// The host command of a program that embeds the library ([`set_host_command`]).
static HOST_COMMAND: OnceLock<(PathBuf, Vec<OsString>)> = OnceLock::new();

/// Sets, once per process, the command that hosts isolated FMUs in a program that is not
/// `shipsim` (`PROGRAM ARGS... fmu-host FMU` must call [`host::serve`] for FMU and exit with its
/// status). The Python package sets its interpreter with `-m shipsim._fmu_host`, so that runs
/// and campaigns from Python, Dask workers included, isolate FMUs as the command line does.
/// A second call is ignored.
pub fn set_host_command(program: PathBuf, args: Vec<OsString>) {
    let _ = HOST_COMMAND.set((program, args));
}
