//! Instantiation and initialization of every instance (FMI 2.0 section 4.2.4):
//!
//! fmi2Instantiate -> fmi2SetXXX (variables settable in "Instantiated") -> fmi2SetupExperiment
//! -> fmi2EnterInitializationMode -> fmi2SetXXX (settable in "InitializationMode") -> exchange
//! of connected values, repeated once per instance so initial values propagate along chains
//! (as libcosim does) -> fmi2ExitInitializationMode -> outputs read at t_0.
//!
//! Each phase runs over all instances before the next begins. On an error the instances made
//! so far are dropped, which frees them, terminating only those in Step Mode (FMI 2.0, sec.
//! 4.2.4: no fmi2Terminate in Initialization Mode; [`crate::instance`]).
//!
//! An instance that [`RunOptions::isolation`] names is instantiated in its own process
//! ([`crate::isolate`]); the rest of the run does not see the difference.

use super::algorithm::Algorithm;
use super::exchange::{Ports, Values};
use super::slot::{set_value, Slot};
use super::RunOptions;
use crate::error::{Error, Result};
use crate::fmu::Fmu;
use crate::instance::{Backend, Instance, Stepping};
use crate::log::stderr_sink;
use crate::system::{Plan, PlanInstance};
use std::sync::Arc;

/// Every instance of `plan` at its first communication point, with its outputs in `values`.
pub fn initialize<A: Algorithm>(
    algorithm: &A,
    plan: &Plan,
    fmus: &[Arc<Fmu>],
    ports: Vec<Ports>,
    values: &mut Values,
    opts: &RunOptions,
) -> Result<Vec<Slot<Stepping>>> {
    let sink = opts
        .log_sink
        .clone()
        .unwrap_or_else(|| stderr_sink(opts.verbose));
    let mut instantiated = Vec::with_capacity(plan.instances.len());
    for ((pi, fmu), ports) in plan.instances.iter().zip(fmus).zip(ports) {
        let isolated = pi.isolate || opts.isolation.applies(&pi.name, &fmu.model_description);
        let backend = Backend {
            isolate: isolated.then_some(&opts.isolation),
            interrupt: opts.interrupt.clone(),
            monitor: opts.monitor.clone(),
        };
        let mut inst = fmu.instantiate_on(&pi.name, opts.verbose, sink.clone(), backend)?;
        apply_start_values(&mut inst, pi, true)?;
        instantiated.push(Slot {
            inst,
            ports,
            step_multiple: pi.step_multiple as u64,
            var_step: fmu
                .co_simulation()
                .can_handle_variable_communication_step_size,
            do_steps: 0,
        });
    }
    let mut initializing = Vec::with_capacity(instantiated.len());
    for (slot, pi) in instantiated.into_iter().zip(&plan.instances) {
        let mut slot = slot.enter_initialization_mode(plan.start_time, plan.stop_time)?;
        apply_start_values(&mut slot.inst, pi, false)?;
        initializing.push(slot);
    }
    if !plan.connections.is_empty() {
        for _ in 0..initializing.len() {
            algorithm.initial_exchange(&mut initializing, values)?;
        }
    }
    let mut slots = initializing
        .into_iter()
        .map(Slot::exit_initialization_mode)
        .collect::<Result<Vec<_>>>()?;
    for s in slots.iter_mut() {
        s.get_outputs(values)?;
    }
    Ok(slots)
}

/// The instance's start values of one phase: before initialization (settable in
/// "Instantiated") or during it.
fn apply_start_values<S>(
    inst: &mut Instance<S>,
    pi: &PlanInstance,
    before_init: bool,
) -> Result<()> {
    for sv in pi
        .start_values
        .iter()
        .filter(|s| s.before_init == before_init)
    {
        set_value(inst, sv.vr, &sv.value).map_err(|e| ctx_err(e, &pi.name, &sv.variable))?;
    }
    Ok(())
}

/// An FMI error while setting a start value, with the variable it was for.
fn ctx_err(e: Error, instance: &str, variable: &str) -> Error {
    match e {
        Error::Fmi {
            instance: _,
            function,
            status,
            time,
            log,
        } => Error::Other(format!(
            "{} (setting '{instance}.{variable}')",
            Error::Fmi {
                instance: instance.to_string(),
                function,
                status,
                time,
                log
            }
        )),
        e => e,
    }
}
