//! A slot: one instance of the run with its ports and its step rate, carried through the FMI
//! lifecycle (its type state follows the instance's, [`crate::instance`]).

use super::exchange::{Ports, Values};
use super::time_grid::TimeGrid;
use crate::error::{Error, Result};
use crate::fmu::VR;
use crate::instance::{Initializing, Instance, Instantiated, Readable, StepOutcome, Stepping};
use crate::system::{PlanEvent, TypedValue};

/// One instance of the run.
pub struct Slot<S> {
    pub inst: Instance<S>,
    pub ports: Ports,
    /// Steps at every k divisible by this (its step multiple).
    pub step_multiple: u64,
    /// The FMU can take a shorter last step (canHandleVariableCommunicationStepSize).
    pub var_step: bool,
    /// fmi2DoStep calls of this instance so far in this run (from a resumed checkpoint: since
    /// the resume).
    pub do_steps: u64,
}

impl<S> Slot<S> {
    /// Writes the connected inputs from `values`.
    #[inline(always)]
    pub fn set_inputs(&mut self, values: &Values) -> Result<()> {
        self.ports.set_inputs(&mut self.inst, values)
    }

    /// Applies an event's value (FMI 2.0: inputs and tunable parameters, in step mode).
    pub fn apply(&mut self, e: &PlanEvent, t: f64) -> Result<()> {
        set_value(&mut self.inst, e.vr, &e.value)
            .map_err(|err| Error::Other(format!("event at t = {t} setting '{}': {err}", e.name)))
    }

    /// Steps at base step k (the rate rule of [`super::time_grid`]). A step multiple that is a
    /// power of two (1, 2, 4, ...: every system so far) is tested with a mask instead of a
    /// division (the algorithms ask twice per instance and macro step).
    #[inline(always)]
    pub fn steps_at(&self, k: u64) -> bool {
        let m = self.step_multiple;
        let mask = m.wrapping_sub(1);
        if m & mask == 0 {
            k & mask == 0
        } else {
            k % m == 0
        }
    }
}

impl<S: Readable> Slot<S> {
    /// Reads the observed variables into `values`.
    #[inline(always)]
    pub fn get_outputs(&mut self, values: &mut Values) -> Result<()> {
        self.ports.get_outputs(&mut self.inst, values)
    }
}

impl Slot<Instantiated> {
    /// `fmi2SetupExperiment` + `fmi2EnterInitializationMode`.
    pub fn enter_initialization_mode(self, t0: f64, stop: f64) -> Result<Slot<Initializing>> {
        let inst = self.inst.enter_initialization_mode(None, t0, Some(stop))?;
        Ok(Slot {
            inst,
            ports: self.ports,
            step_multiple: self.step_multiple,
            var_step: self.var_step,
            do_steps: self.do_steps,
        })
    }
}

impl Slot<Initializing> {
    /// `fmi2ExitInitializationMode`: the instance is at its first communication point.
    pub fn exit_initialization_mode(self) -> Result<Slot<Stepping>> {
        Ok(Slot {
            inst: self.inst.exit_initialization_mode()?,
            ports: self.ports,
            step_multiple: self.step_multiple,
            var_step: self.var_step,
            do_steps: self.do_steps,
        })
    }
}

/// How a macro step ended for the run.
#[derive(Debug, Default)]
pub struct StepCount {
    /// fmi2DoStep calls so far.
    pub fmu_steps: u64,
    /// Set when an instance ended the simulation early (fmi2Discard + fmi2Terminated).
    pub terminated_by: Option<String>,
}

impl Slot<Stepping> {
    /// `fmi2DoStep` from t_k = `t` over the slot's step (the last step may be shortened or
    /// dropped, [`TimeGrid::step_size`]); an early end by the FMU is noted in `count`.
    #[inline(always)]
    pub fn do_step(
        &mut self,
        k: u64,
        t: f64,
        grid: &TimeGrid,
        count: &mut StepCount,
    ) -> Result<()> {
        let Some(h) = grid.step_size(k, self.step_multiple, grid.n_steps(), self.var_step) else {
            return Ok(());
        };
        count.fmu_steps += 1;
        self.do_steps += 1;
        match self.inst.do_step(t, h)? {
            StepOutcome::Ok => Ok(()),
            StepOutcome::Terminated {
                last_successful_time,
            } => {
                self.ended(last_successful_time, count);
                Ok(())
            }
        }
    }

    /// The FMU ended the simulation early at `last_successful_time`: noted in `count`.
    #[cold]
    #[inline(never)]
    fn ended(&self, last_successful_time: f64, count: &mut StepCount) {
        count.terminated_by = Some(format!(
            "instance '{}' ended the simulation at t = {last_successful_time} s (fmi2Discard, fmi2Terminated)",
            self.inst.name()
        ));
    }
}

/// fmi2SetXxx of one typed value.
pub fn set_value<S>(inst: &mut Instance<S>, vr: VR, v: &TypedValue) -> Result<()> {
    match v {
        TypedValue::Real(x) => inst.set_real(&[vr], &[*x]),
        TypedValue::Integer(x) => inst.set_integer(&[vr], &[*x]),
        TypedValue::Boolean(x) => inst.set_boolean(&[vr], &[*x as i32]),
        TypedValue::String(s) => inst.set_string(&[vr], &[s.as_str()]),
    }
}
