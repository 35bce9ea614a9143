//! `shipsim`: an FMI 2.0 co-simulation master for ship-control systems.
//!
//! The crate in layers, each depending only on those above it (docs/ARCHITECTURE.md walks a run
//! through them; `cargo xtask lint` refuses an import cycle):
//!
//! - **Foundations**: [`error`] (errors that name file, line, instance, variable and value),
//!   [`limits`] (bounded reads, unpacking limits), [`units`] (SI units, typed user values),
//!   [`log`] (FMU log records and sinks).
//! - **Importer**: [`fmu`] unzips an FMU, reads its model description and resolves every symbol
//!   once; [`model_description`] is the typed `modelDescription.xml`.
//! - **FMU calls**: [`slave`] is the one interface to an FMU instance (the FMI calls the master
//!   makes) and its in-process implementation, the only FFI besides the loader; [`isolate`] is
//!   the out-of-process implementation (a `shipsim fmu-host` child per instance, served by the
//!   in-process one); [`instance`] is a slave instance whose FMI lifecycle is enforced by types.
//! - **System**: [`system`] is the format-neutral system and its validation into a
//!   [`system::Plan`]; [`format`](mod@format) holds the file formats that read into it (native
//!   TOML, OSP `OspSystemStructure.xml`, SSP 1.0) and write out of it (OSP, SSP).
//! - **Master**: [`run`] executes a plan: exchange, recorders, Jacobi and Gauss-Seidel, the
//!   step loop, checkpoints.
//! - **Campaigns**: [`campaign`] runs a system many times over factors, seeds and arms (each
//!   run through [`run`]), with KPIs, durable journals, run tables and plots.
//! - **Tools**: [`inspect`] (an FMU summary), [`results`] (the reader of recorded CSVs),
//!   [`plot`] (PNG plots of them).
//!
//! Entry functions are named by one rule: `f` is the common form; `f_with` takes the options
//! `f` leaves at their defaults (`load_with`, `load_fmus_with`, `prepare_with`); `f_into`
//! records into any [`run::Recorder`] (`run_into`, `resume_into`).
//!
//! The library holds no process-wide state (no signal handlers, no global logger): it is
//! loaded into other processes (Python, Dask workers). The `shipsim` binary (`main.rs`) is the
//! command line and installs those itself.
//!
//! Tests: `master/tests/*.rs` (a C test FMU compiled at test time, our FMUs from
//! `$SHIPSIM_FMU_DIR`), `tests/python/test_master_*.py` (PythonFMU, crane-fmu, libcosim);
//! benchmark: `master/bench/bench_master.py`.

// `k % m == 0` reads as the time-grid rule; `is_multiple_of` needs a newer Rust than our MSRV.
#![allow(unknown_lints, clippy::manual_is_multiple_of)]
// `!(x > 0.0)` is the check that also rejects NaN, which `x <= 0.0` would let through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod analysis;
pub mod campaign;
pub mod digest;
pub mod error;
pub mod fmu;
pub mod format;
pub mod inspect;
pub mod instance;
pub mod isolate;
pub mod limits;
pub mod log;
pub mod model_description;
pub mod output_path;
pub mod plot;
pub mod realtime;
pub mod results;
pub mod run;
pub mod slave;
pub mod system;
pub mod units;

pub use error::{Error, Result};
pub use fmu::Fmu;
