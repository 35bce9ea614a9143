//! Master algorithms: how the instances of a macro step exchange values and step.
//!
//! An [`Algorithm`] does two things: one round of the initial exchange (instances in
//! Initialization Mode, repeated once per instance so that initial values propagate along
//! chains, as libcosim does), and one macro step from t_k to t_(k+1). The step loop
//! ([`super::stepping`]) is generic over it, so the choice costs nothing per step.
//!
//! - [`Jacobi`]: every instance that steps at k takes its inputs from the outputs published at
//!   the last communication point; an instance's outputs are published when its own step ends
//!   (k + m_i), so slow instances do not leak future values into fast ones (libcosim's
//!   fixed_step_algorithm with decimation factors).
//! - [`GaussSeidel`]: instances step one after another in connection order, each reading the
//!   newest outputs (already at t_(k+1) for those stepped earlier in the same macro step).
//!
//! A macro step takes a [`Probe`]: a profiled run times its sampled steps through it
//! ([`super::profile`]), lapping after each FMI call or batch; every other step passes
//! [`super::profile::Off`], which compiles to nothing.
//!
//! To add one, implement the trait here, add a variant to [`crate::system::Algorithm`] (and
//! its name to its `FromStr`, the one parser of the system files, the CLI and Python), and
//! dispatch to it in [`super::run_into`].

use super::exchange::Values;
use super::profile::{Lap, Probe};
use super::slot::{Slot, StepCount};
use super::time_grid::TimeGrid;
use crate::error::Result;
use crate::instance::{Readable, Stepping};
use crate::system::PlanEvent;

/// One macro step of the run: k, t_k, and the events applied at it.
pub struct MacroStep<'a> {
    pub k: u64,
    pub t: f64,
    pub events: &'a [PlanEvent],
}

/// A fixed-step master algorithm.
pub trait Algorithm {
    /// One round of exchange between instances in Initialization Mode.
    fn initial_exchange<S: Readable>(
        &self,
        slots: &mut [Slot<S>],
        values: &mut Values,
    ) -> Result<()>;

    /// Sets inputs, applies the step's events, steps the instances due at k, and publishes
    /// their outputs into `values`. `probe` laps after each FMI call or batch, attributing the
    /// time since the last lap ([`Lap`]), and at the start (the master's work before).
    fn step<P: Probe>(
        &self,
        step: &MacroStep,
        grid: &TimeGrid,
        slots: &mut [Slot<Stepping>],
        values: &mut Values,
        count: &mut StepCount,
        probe: &mut P,
    ) -> Result<()>;
}

/// All instances from the previous communication point's outputs.
pub struct Jacobi;

impl Algorithm for Jacobi {
    fn initial_exchange<S: Readable>(
        &self,
        slots: &mut [Slot<S>],
        values: &mut Values,
    ) -> Result<()> {
        for s in slots.iter_mut() {
            s.get_outputs(values)?;
        }
        for s in slots.iter_mut() {
            s.set_inputs(values)?;
        }
        Ok(())
    }

    #[inline]
    fn step<P: Probe>(
        &self,
        step: &MacroStep,
        grid: &TimeGrid,
        slots: &mut [Slot<Stepping>],
        values: &mut Values,
        count: &mut StepCount,
        probe: &mut P,
    ) -> Result<()> {
        let k = step.k;
        probe.lap(Lap::Master);
        // Inputs, events and step of one instance after another: `values` changes only when
        // the outputs are published below, so every instance sees the same calls, with the same
        // values, as with all inputs first and all steps after (one pass over the slots).
        for (i, s) in slots.iter_mut().enumerate() {
            let due = s.steps_at(k);
            if due {
                s.set_inputs(values)?;
                probe.lap(Lap::Exchange(i));
            }
            if !step.events.is_empty() {
                apply_events(s, i, step, probe)?;
            }
            if due {
                s.do_step(k, step.t, grid, count)?;
                probe.lap(Lap::DoStep(i));
            }
        }
        for (i, s) in slots.iter_mut().enumerate() {
            if s.steps_at(k + 1) || k + 1 == grid.n_steps() {
                s.get_outputs(values)?;
                probe.lap(Lap::Exchange(i));
            }
        }
        Ok(())
    }
}

/// One instance after another in `order`, each from the newest outputs.
pub struct GaussSeidel<'a> {
    pub order: &'a [usize],
}

impl Algorithm for GaussSeidel<'_> {
    fn initial_exchange<S: Readable>(
        &self,
        slots: &mut [Slot<S>],
        values: &mut Values,
    ) -> Result<()> {
        for &i in self.order {
            slots[i].set_inputs(values)?;
            slots[i].get_outputs(values)?;
        }
        Ok(())
    }

    #[inline]
    fn step<P: Probe>(
        &self,
        step: &MacroStep,
        grid: &TimeGrid,
        slots: &mut [Slot<Stepping>],
        values: &mut Values,
        count: &mut StepCount,
        probe: &mut P,
    ) -> Result<()> {
        let k = step.k;
        probe.lap(Lap::Master);
        for &i in self.order {
            let s = &mut slots[i];
            if s.steps_at(k) {
                s.set_inputs(values)?;
                probe.lap(Lap::Exchange(i));
            }
            if !step.events.is_empty() {
                apply_events(s, i, step, probe)?;
            }
            if s.steps_at(k) {
                s.do_step(k, step.t, grid, count)?;
                probe.lap(Lap::DoStep(i));
                s.get_outputs(values)?;
                probe.lap(Lap::Exchange(i));
            }
        }
        Ok(())
    }
}

/// Applies the step's events of instance `i` to its slot, in their order (FMI 2.0: inputs and
/// tunable parameters). Out of line: most macro steps have no events.
#[inline(never)]
fn apply_events<P: Probe>(
    s: &mut Slot<Stepping>,
    i: usize,
    step: &MacroStep,
    probe: &mut P,
) -> Result<()> {
    for e in step.events.iter().filter(|e| e.instance == i) {
        s.apply(e, step.t)?;
        probe.lap(Lap::Exchange(i));
    }
    Ok(())
}
