//! The step loop: macro steps from t_k (t_0, or a checkpoint's) to t_n with an [`Algorithm`],
//! recording, progress and interruption. A run may stop at a communication point between two
//! calls of [`Stepper::advance`] (to take a checkpoint) and go on. Nothing in it allocates on
//! the success path. A profiled run times a sample of the macro steps ([`super::profile`]).

use super::algorithm::{Algorithm, MacroStep};
use super::exchange::{Column, Values};
use super::profile::{Accumulator, Lap, Off, Probe};
use super::progress::Progress;
use super::recorder::{Recorder, Row};
use super::slot::{Slot, StepCount};
use super::time_grid::TimeGrid;
use crate::error::{Error, Result};
use crate::instance::Stepping;
use crate::system::PlanEvent;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Where recorded rows go, and which.
pub struct Recording<'r> {
    pub recorder: &'r mut dyn Recorder,
    pub columns: &'r [Column],
    /// A row every `decimation` base steps (and at the last point).
    pub decimation: u64,
    pub rows: u64,
}

impl Recording<'_> {
    #[inline]
    pub fn row(&mut self, t: f64, values: &Values) -> Result<()> {
        self.rows += 1;
        self.recorder.record(t, &Row::new(self.columns, values))
    }
}

/// A run at communication point t_k, ready to step: at its first point, or at a checkpoint's
/// ([`super::checkpoint`]).
pub struct Stepper<'a> {
    pub(super) grid: TimeGrid,
    pub(super) events: &'a [PlanEvent],
    pub(super) slots: Vec<Slot<Stepping>>,
    pub(super) values: Values,
    pub(super) recording: Option<Recording<'a>>,
    pub(super) progress: Option<Progress>,
    pub(super) interrupt: Option<&'a AtomicBool>,
    /// The next base step: the run is at t_k.
    pub(super) k: u64,
    pub(super) count: StepCount,
    /// Wall time spent stepping so far.
    pub(super) wall: Duration,
    /// The sums of a profiled run ([`super::RunOptions::profile`]).
    pub(super) profile: Option<Accumulator>,
}

/// How the step loop ended.
pub struct LoopEnd {
    /// The base step the run ended at (t_n, or earlier if an instance ended it).
    pub steps: u64,
    pub count: StepCount,
    /// Wall time of the loop.
    pub wall: Duration,
}

impl Stepper<'_> {
    /// Steps until t_`until` (at most the end of the run), or until an instance ends the run or
    /// the interrupt flag is set (then the recorder is finished and the error is
    /// [`Error::Interrupted`]). The events of step k are applied at k, from any starting k.
    /// With a profile, the sampled steps are timed ([`super::profile`]).
    pub fn advance<A: Algorithm>(&mut self, algorithm: &A, until: u64) -> Result<()> {
        let start = Instant::now();
        let grid = self.grid;
        let until = until.min(grid.n_steps());
        let mut count = std::mem::take(&mut self.count);
        let mut profile = self.profile.take();
        let mut k = self.k;
        let mut next_event = self.events.partition_point(|e| e.step < k);
        // The next sampled step (none without a profile): one comparison per step.
        let mut next_sample = profile.as_ref().map_or(u64::MAX, |a| a.sampling.next(k));
        let mut steps = || -> Result<()> {
            while k < until && count.terminated_by.is_none() {
                let (next_event, count) = (&mut next_event, &mut count);
                match profile.as_mut().filter(|_| k == next_sample) {
                    Some(acc) => {
                        let mut timer = acc.start();
                        self.macro_step(algorithm, k, &grid, next_event, count, &mut timer)?;
                        timer.lap(Lap::Master);
                        next_sample += acc.sampling.every.max(1);
                    }
                    None => self.macro_step(algorithm, k, &grid, next_event, count, &mut Off)?,
                }
                k += 1;
            }
            Ok(())
        };
        let result = steps();
        // Also on an error: an interrupted stepping session stays at t_k, where it stopped,
        // with its count ([`super::Session`]).
        self.k = k;
        self.count = count;
        self.profile = profile;
        self.wall += start.elapsed();
        result
    }

    /// Macro step k (with the next event's index and the count): the interruption check, the
    /// step's events, the algorithm's step, the row at t_(k+1) (every `decimation` steps, at
    /// t_n and at an early end) and the progress bar.
    #[inline(always)]
    fn macro_step<A: Algorithm, P: Probe>(
        &mut self,
        algorithm: &A,
        k: u64,
        grid: &TimeGrid,
        next_event: &mut usize,
        count: &mut StepCount,
        probe: &mut P,
    ) -> Result<()> {
        let t = grid.at(k);
        if self.interrupted() {
            return Err(self.interrupt_at(t));
        }
        let first = *next_event;
        while *next_event < self.events.len() && self.events[*next_event].step == k {
            *next_event += 1;
        }
        let step = MacroStep {
            k,
            t,
            events: &self.events[first..*next_event],
        };
        algorithm.step(&step, grid, &mut self.slots, &mut self.values, count, probe)?;
        let k = k + 1;
        let ended = count.terminated_by.is_some();
        if let Some(r) = self.recording.as_mut() {
            if k % r.decimation == 0 || k == grid.n_steps() || ended {
                r.row(grid.at(k), &self.values)?;
            }
        }
        if let Some(p) = &self.progress {
            p.update(k, grid);
        }
        Ok(())
    }

    /// An instance ended the run early (fmi2Discard + fmi2Terminated).
    pub fn ended(&self) -> bool {
        self.count.terminated_by.is_some()
    }

    /// Ends stepping: the progress bar and the recorder are finished.
    pub fn finish(&mut self) -> Result<LoopEnd> {
        if let Some(p) = &self.progress {
            p.finish();
        }
        if let Some(r) = self.recording.as_mut() {
            r.recorder.finish()?;
        }
        Ok(LoopEnd {
            steps: self.k,
            count: std::mem::take(&mut self.count),
            wall: self.wall,
        })
    }

    #[inline]
    fn interrupted(&self) -> bool {
        self.interrupt
            .map(|f| f.load(Ordering::Relaxed))
            .unwrap_or(false)
    }

    /// Finishes the recorder (the rows so far are kept) and leaves the bar where it stopped.
    fn interrupt_at(&mut self, time: f64) -> Error {
        if let Some(r) = self.recording.as_mut() {
            if let Err(e) = r.recorder.finish() {
                return e;
            }
        }
        if let Some(p) = &self.progress {
            p.abandon();
        }
        Error::Interrupted { time }
    }
}
