//! Validation: a [`System`] checked against the FMUs' model descriptions and resolved into a
//! [`Plan`].
//!
//! One `Checker` carries the system, the model descriptions, the instance index and the
//! errors and warnings found so far; each concern is a small method in its own file, run in
//! this order (which is also the order of the messages):
//!
//! 1. the time grid (this file),
//! 2. the instances and their start values (this file and `values.rs`),
//! 3. the connections, their types and units, and unconnected inputs (`connections.rs`),
//! 4. the events (`events.rs`),
//! 5. the recorded outputs (`outputs.rs`),
//! 6. the stepping order, algebraic loops and dropped last steps (`order.rs`),
//! 7. the FMUs themselves: GUIDs shared by different models (`guids.rs`) and variability the
//!    standard forbids (`variability.rs`), both warnings.
//!
//! Every error names the file, the line when known, the instance and the variable, with
//! close-name suggestions; all errors are returned together.

use super::{InstanceSpec, Plan, PlanInstance, System, VarRef};
use crate::error::{did_you_mean, Error, Result};
use crate::model_description::ModelDescription;
use crate::run::{LastStep, OffGrid};
use std::collections::HashMap;

mod connections;
mod couplings;
mod events;
mod guids;
mod order;
mod outputs;
mod values;
mod variability;

/// The base-step grid of a run.
struct Grid {
    /// Number of base steps: the run ends at t0 + n_steps*h.
    n_steps: u64,
    /// t0 + n_steps*h, or the stop time after a short last step.
    stop_on_grid: f64,
    /// A stop time off the grid and what the run does about it.
    off_grid: Option<OffGrid>,
}

/// The state of one validation: inputs, the instance index, and what was found.
struct Checker<'a> {
    sys: &'a System,
    mds: &'a [&'a ModelDescription],
    /// Instance name -> index (the first of duplicates is overwritten, as reported).
    index: HashMap<&'a str, usize>,
    errors: Vec<Error>,
    warnings: Vec<String>,
}

impl System {
    /// Checks the system against the FMUs' model descriptions (`mds[i]` belongs to
    /// `instances[i]`) and resolves it into a [`Plan`]. All errors are collected and returned
    /// together; each names the file, line, instance and variable, with close-name suggestions.
    pub fn validate(&self, mds: &[&ModelDescription]) -> Result<Plan> {
        assert_eq!(mds.len(), self.instances.len());
        let mut c = Checker {
            sys: self,
            mds,
            index: HashMap::new(),
            errors: Vec::new(),
            warnings: Vec::new(),
        };
        let grid = c.grid();
        c.instance_names();
        let instances = c.instances();
        let (connections, driven) = c.connections();
        c.unconnected_inputs(&driven);
        let events = c.events(&grid, &driven);
        let outputs = c.outputs();
        let order = c.order(&connections);
        c.step_multiples(grid.n_steps);
        c.shared_guids();
        c.invalid_variability();
        c.ineffective_couplings(&instances, &connections);
        if !c.errors.is_empty() {
            return Err(if c.errors.len() == 1 {
                c.errors.pop().unwrap()
            } else {
                Error::Many(c.errors)
            });
        }
        Ok(Plan {
            start_time: self.start_time,
            step_size: self.step_size,
            n_steps: grid.n_steps,
            stop_time: grid.stop_on_grid,
            off_grid: grid.off_grid,
            algorithm: self.algorithm,
            instances,
            order,
            connections,
            events,
            outputs,
            output_file: self.output.file.clone(),
            decimation: self.output.decimation.max(1),
            warnings: c.warnings,
        })
    }
}

impl<'a> Checker<'a> {
    fn err(&self, line: Option<usize>, msg: String) -> Error {
        Error::system(&self.sys.source, line, msg)
    }

    /// `file:line` (or `file`) for warnings.
    fn loc(&self, line: Option<usize>) -> String {
        let src = self.sys.source.display();
        match line {
            Some(l) => format!("{src}:{l}"),
            None => src.to_string(),
        }
    }

    fn inst_names(&self) -> impl Iterator<Item = &'a str> + Clone {
        self.sys.instances.iter().map(|i| i.name.as_str())
    }

    fn var_names(&self, i: usize) -> impl Iterator<Item = &'a str> + Clone {
        self.mds[i]
            .model_variables
            .variables
            .iter()
            .map(|v| v.name.as_str())
    }

    /// The time grid: a positive step, a stop after the start, at least one step. A stop time
    /// off the grid is a warning (the run ends at the last grid point before it), or with
    /// `last_step = "short"` one more, shorter step to it ([`Checker::short_last_step`]).
    fn grid(&mut self) -> Grid {
        let sys = self.sys;
        if !(sys.step_size > 0.0 && sys.step_size.is_finite()) {
            let e = self.err(
                None,
                format!(
                    "step_size = {}; it must be a positive number",
                    sys.step_size
                ),
            );
            self.errors.push(e);
        }
        let stop = sys.stop_time.unwrap_or(sys.start_time + 1.0);
        if !(stop > sys.start_time) {
            let e = self.err(
                None,
                format!(
                    "stop_time = {stop} must be greater than start_time = {}",
                    sys.start_time
                ),
            );
            self.errors.push(e);
        }
        let ratio = (stop - sys.start_time) / sys.step_size;
        let mut n_steps = if ratio.is_finite() && ratio > 0.0 {
            (ratio + 1e-9 * ratio.max(1.0)).floor() as u64
        } else {
            0
        };
        if n_steps == 0 && self.errors.is_empty() {
            let e = self.err(
                None,
                format!(
                    "the run from {} to {stop} is shorter than one step of {}",
                    sys.start_time, sys.step_size
                ),
            );
            self.errors.push(e);
            n_steps = 1;
        }
        let stop_on_grid = sys.start_time + n_steps as f64 * sys.step_size;
        let off =
            self.errors.is_empty() && (stop_on_grid - stop).abs() > 1e-9 * stop.abs().max(1.0);
        let grid = Grid {
            n_steps,
            stop_on_grid,
            off_grid: off.then_some(OffGrid {
                stop_time: stop,
                last_step: sys.last_step,
            }),
        };
        match (off, sys.last_step) {
            (false, _) => grid,
            (true, LastStep::Drop) => {
                self.warnings.push(format!(
                    "{}: stop_time {stop} is not on the base-step grid; the run ends at t = {stop_on_grid}",
                    self.loc(None)
                ));
                grid
            }
            (true, LastStep::Short) => self.short_last_step(grid, stop),
        }
    }

    /// `last_step = "short"` with a stop time off the grid: one more base step, ending at the
    /// stop time. Every instance takes it (the last step of a step multiple > 1 is shortened
    /// too, [`crate::run::TimeGrid::step_size`]), so every FMU must declare
    /// canHandleVariableCommunicationStepSize (FMI 2.0, sec. 4.3.1): an error names each one
    /// that does not.
    fn short_last_step(&mut self, grid: Grid, stop: f64) -> Grid {
        let sys = self.sys;
        for (i, inst) in sys.instances.iter().enumerate() {
            let var_step = self.mds[i]
                .co_simulation
                .as_ref()
                .is_some_and(|c| c.can_handle_variable_communication_step_size);
            if !var_step {
                let e = self.err(
                    inst.line,
                    format!(
                        "instance '{}': last_step = \"short\" needs a shorter last step to stop_time {stop} (off the base-step grid, the last grid point is t = {}), but FMU {} does not declare canHandleVariableCommunicationStepSize; use last_step = \"drop\" or a stop time on the grid",
                        inst.name,
                        grid.stop_on_grid,
                        fmu_file_name(inst)
                    ),
                );
                self.errors.push(e);
            }
        }
        Grid {
            n_steps: grid.n_steps + 1,
            stop_on_grid: stop,
            ..grid
        }
    }

    /// Instance names: non-empty, no dots or spaces, unique; at least one instance.
    fn instance_names(&mut self) {
        let sys = self.sys;
        for (i, inst) in sys.instances.iter().enumerate() {
            if inst.name.is_empty()
                || inst.name.contains('.')
                || inst.name.contains(char::is_whitespace)
            {
                let e = self.err(
                    inst.line,
                    format!(
                        "instance name '{}' must be non-empty, without dots or spaces",
                        inst.name
                    ),
                );
                self.errors.push(e);
            }
            if self.index.insert(inst.name.as_str(), i).is_some() {
                let e = self.err(
                    inst.line,
                    format!("instance '{}' is defined twice", inst.name),
                );
                self.errors.push(e);
            }
        }
        if sys.instances.is_empty() {
            let e = self.err(None, "the system has no instances".into());
            self.errors.push(e);
        }
    }

    /// Every instance with its checked start values.
    fn instances(&mut self) -> Vec<PlanInstance> {
        let sys = self.sys;
        sys.instances
            .iter()
            .enumerate()
            .map(|(i, inst)| PlanInstance {
                name: inst.name.clone(),
                step_multiple: inst.step_multiple,
                start_values: self.start_values(i, inst),
            })
            .collect()
    }

    /// Resolves `inst.var` to (instance index, variable index), with suggestions.
    fn resolve(&self, r: &VarRef, line: Option<usize>, what: &str) -> Result<(usize, usize)> {
        let Some(&i) = self.index.get(r.instance.as_str()) else {
            return Err(self.err(
                line,
                format!(
                    "{what} '{r}': no instance named '{}'{}",
                    r.instance,
                    did_you_mean(&r.instance, self.inst_names())
                ),
            ));
        };
        match self.mds[i]
            .model_variables
            .variables
            .iter()
            .position(|v| v.name == r.variable)
        {
            Some(v) => Ok((i, v)),
            None => Err(self.err(
                line,
                format!(
                    "{what} '{r}': instance '{}' (FMU {}) has no variable '{}'{}",
                    r.instance,
                    fmu_file_name(&self.sys.instances[i]),
                    r.variable,
                    did_you_mean(&r.variable, self.var_names(i))
                ),
            )),
        }
    }
}

fn fmu_file_name(inst: &InstanceSpec) -> String {
    inst.fmu
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default()
}
