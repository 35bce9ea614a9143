//! Pure-Rust model loops: a coupled system of `systems/` run directly on the `models` crate, with
//! the master's exchange order and no FMI (issue 16). A loop is the limit the FMU system is
//! measured against: the same computation, bit for bit, without the master, the FMI calls and
//! the export layer in between.
//!
//! To be the same computation a loop does what the master does (`master/src/run/`) and what
//! each FMU wrapper (`fmus/<name>/src/lib.rs`) does between the FMI calls:
//! - **grid**: t_k and the step sizes of [`shipsim::run::TimeGrid`], the master's own type; the
//!   number of base steps as the validator computes it ([`n_steps`]);
//! - **initialization**: the wrapper's start values and parameter mapping, then the master's
//!   initial exchange (as many rounds as instances; in each, every instance rebuilds its model
//!   from its parameters and inputs, as `fmi2GetReal` in Initialization Mode does after a set,
//!   then every input is set), then `initialize` once more (`fmi2ExitInitializationMode`);
//! - **Jacobi** (shipsim's `run/algorithm.rs`, `Jacobi`): every input of the instances due at k
//!   from the outputs published at t_k, then every due instance steps, then the outputs of the
//!   instances whose step ends at t_(k+1) (every instance at the last point) are published;
//! - **connections**: the master's `gain·x + offset` ([`link`]).
//!
//! Nothing in a loop's macro step allocates (`tests/tests/model_loop_no_alloc.rs`).
//!
//! Loops: [`rrs`] runs `systems/rrs.toml`; [`container_ship`] runs
//! `systems/container_ship_seaway_autopilot.toml` (summed inputs).

// `k % m == 0` reads as the master's rate rule (`Slot::steps_at`).
#![allow(unknown_lints, clippy::manual_is_multiple_of)]

pub mod container_ship;
mod disturbances;
pub mod rrs;

use shipsim::run::write_real;
use std::io::Write;
use std::time::Duration;

/// What a loop run did.
#[derive(Clone, Copy, Debug)]
pub struct LoopSummary {
    /// t_n, the last communication point.
    pub stop_time: f64,
    pub macro_steps: u64,
    /// Wall time of the step loop only (construction and initialization excluded, as in the
    /// master's `Summary::wall_time`), recording included.
    pub wall: Duration,
}

/// The number of base steps of a run from `t0` to `stop` with base step `h`, as the master's
/// validator computes it (`master/src/system/validate/mod.rs`, `Checker::grid`): the run ends
/// at the last grid point not after `stop` (up to a relative 1e-9).
pub fn n_steps(t0: f64, stop: f64, h: f64) -> Result<u64, String> {
    let ratio = (stop - t0) / h;
    let n = if ratio.is_finite() && ratio > 0.0 {
        (ratio + 1e-9 * ratio.max(1.0)).floor() as u64
    } else {
        0
    };
    if n == 0 {
        return Err(format!(
            "the run from {t0} to {stop} is shorter than one step of {h}"
        ));
    }
    Ok(n)
}

/// The gain and offset of every connection of the looped systems: the defaults.
/// `convert = true` only skips the master's unit check; it changes no arithmetic.
const GAIN: f64 = 1.0;
const OFFSET: f64 = 0.0;

/// A connection of the system file: the master sets `gain·x + offset` on the input
/// (`master/src/run/exchange.rs`, `Kind::map` of Real), with [`GAIN`] and [`OFFSET`]: the value
/// arrives unchanged, except that −0 becomes +0.
#[inline(always)]
pub fn link(x: f64) -> f64 {
    GAIN * x + OFFSET
}

/// Recorded rows written as `shipsim run` writes them (`shipsim::run::CsvRecorder`): the header
/// `time,<columns>`, then per row the time and the values in Rust's shortest round-trip form.
/// A write error is kept and returned by [`CsvWriter::finish`], so that [`CsvWriter::row`] can
/// be called from a loop's `record` callback.
pub struct CsvWriter<W: Write> {
    out: W,
    error: Option<std::io::Error>,
}

impl<W: Write> CsvWriter<W> {
    /// Writes the header.
    pub fn new(mut out: W, columns: &[&str]) -> std::io::Result<CsvWriter<W>> {
        writeln!(out, "time,{}", columns.join(","))?;
        Ok(CsvWriter { out, error: None })
    }

    /// One row (nothing after a write error).
    pub fn row(&mut self, time: f64, values: &[f64]) {
        if self.error.is_none() {
            if let Err(e) = self.write_row(time, values) {
                self.error = Some(e);
            }
        }
    }

    /// One line, numbers as `shipsim run` writes them ([`write_real`]).
    fn write_row(&mut self, time: f64, values: &[f64]) -> std::io::Result<()> {
        write_real(&mut self.out, time)?;
        for x in values {
            self.out.write_all(b",")?;
            write_real(&mut self.out, *x)?;
        }
        self.out.write_all(b"\n")
    }

    /// Flushes; the first write error, if any.
    pub fn finish(mut self) -> std::io::Result<()> {
        match self.error.take() {
            Some(e) => Err(e),
            None => self.out.flush(),
        }
    }
}
