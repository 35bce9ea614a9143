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

use super::{InstanceSpec, LastStep, OffGrid, Plan, PlanInstance, System, VarRef};
use crate::error::{did_you_mean, Error, Result};
use crate::model_description::ModelDescription;
use std::collections::HashMap;

mod connections;
mod couplings;
mod events;
mod guids;
mod order;
mod outputs;
mod values;
mod variability;

/// The most base steps a run may have: 2^53, up to which every step index k is an exact
/// double, so that t0 + k*h names distinct, ordered steps.
pub const MAX_STEPS: u64 = 1 << 53;

/// A run of more base steps than this (10^9) gets a warning that says how many.
pub const WARN_STEPS: u64 = 1_000_000_000;

/// A number for a message: plain when that is short (`0.01`, `3600`), else with an exponent
/// (`1e300`, `5e-324`), never hundreds of digits.
fn short(x: f64) -> String {
    let a = x.abs();
    match a != 0.0 && a.is_finite() && !(1e-6..1e15).contains(&a) {
        true => format!("{x:e}"),
        false => format!("{x}"),
    }
}

/// The base-step grid of a run.
struct Grid {
    /// The times and step make a grid; when not (an error was reported), `n_steps` is a
    /// stand-in of one step that lets the other checks go on, and no check compares with it.
    ok: bool,
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
        c.step_multiple_range(&grid);
        if grid.ok {
            c.step_multiples(grid.n_steps);
        }
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

    /// The time grid: finite times, a positive finite step, a stop after the start, at least
    /// one step and at most [`MAX_STEPS`] (more than [`WARN_STEPS`] is a warning that says
    /// how many). A stop time off the grid is a warning (the run ends at the last grid point
    /// before it), or with `last_step = "short"` one more, shorter step to it
    /// ([`Checker::short_last_step`]). Numbers in messages are short ([`short`]).
    fn grid(&mut self) -> Grid {
        let sys = self.sys;
        let (t0, h) = (sys.start_time, sys.step_size);
        let stop = sys.stop_time.unwrap_or(t0 + 1.0);
        let fail = |c: &mut Self, m: String| {
            let e = c.err(None, m);
            c.errors.push(e);
        };
        if h.is_nan() {
            fail(self, super::no_step_size());
        } else if !(h > 0.0 && h.is_finite()) {
            fail(
                self,
                format!("step_size = {}; it must be a positive number", short(h)),
            );
        }
        if !t0.is_finite() {
            fail(
                self,
                format!("start_time = {}; it must be a finite number", short(t0)),
            );
        } else if !stop.is_finite() {
            fail(
                self,
                format!("stop_time = {}; it must be a finite number", short(stop)),
            );
        } else if !(stop > t0) {
            fail(
                self,
                format!(
                    "stop_time = {} must be greater than start_time = {}",
                    short(stop),
                    short(t0)
                ),
            );
        }
        let ratio = (stop - t0) / h;
        let mut n_steps = 0;
        if self.errors.is_empty() {
            match self.step_count(t0, stop, h, ratio) {
                Ok(n) => n_steps = n,
                Err(m) => fail(self, m),
            }
        }
        let ok = n_steps > 0;
        if !ok {
            // An error was reported; a grid of one step lets the other checks go on.
            n_steps = 1;
        }
        let stop_on_grid = t0 + n_steps as f64 * h;
        let off =
            self.errors.is_empty() && (stop_on_grid - stop).abs() > 1e-9 * stop.abs().max(1.0);
        let grid = Grid {
            ok,
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

    /// The number of base steps from t0 to stop (finite, stop > t0, h > 0): at least one,
    /// at most [`MAX_STEPS`], each long enough to move the time at t0 and at stop; more
    /// than [`WARN_STEPS`] is a warning.
    fn step_count(
        &mut self,
        t0: f64,
        stop: f64,
        h: f64,
        ratio: f64,
    ) -> std::result::Result<u64, String> {
        let run = format!("the run from {} to {}", short(t0), short(stop));
        if !(ratio < MAX_STEPS as f64) {
            return Err(format!(
                "{run} has {} steps of {} s, more than the {} a run can count exactly (t = t0 + k*h); use a larger step_size or a shorter run",
                short(ratio.floor()),
                short(h),
                short(MAX_STEPS as f64)
            ));
        }
        if t0 + h == t0 || stop - h == stop {
            return Err(format!(
                "{run}: a step of {} s does not change the time at t = {} (below the resolution of a double there); use a larger step_size",
                short(h),
                short(if t0 + h == t0 { t0 } else { stop })
            ));
        }
        // A ratio a rounding below a whole number (0.3 / 0.1 = 2.9999999999999996) counts
        // as that number: a relative 1e-9, at most 1e-3 of a step (uncapped, 1e10 steps
        // gained 10 more).
        let n = (ratio + (1e-9 * ratio.max(1.0)).min(1e-3)).floor() as u64;
        if n == 0 {
            return Err(format!("{run} is shorter than one step of {}", short(h)));
        }
        if n > WARN_STEPS {
            self.warnings.push(format!(
                "{}: {run} has {n} macro steps of {} s; it may take long (Ctrl-C stops it cleanly)",
                self.loc(None),
                short(h),
            ));
        }
        Ok(n)
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

    /// Every instance steps every m base steps with 1 <= m <= the run's steps: a reader that
    /// makes m from a step size (OSP `stepSize` / `BaseStepSize`) gives 0 for NaN and the
    /// largest u32 for an infinite or huge one, and an instance whose step is longer than the
    /// run would never step. Without a grid (a stop time that is negative, not a number or
    /// too far: its own error) only m = 0 is reported, not every step multiple above 1.
    fn step_multiple_range(&mut self, grid: &Grid) {
        let sys = self.sys;
        for inst in &sys.instances {
            let m = inst.step_multiple;
            if m == 0 || (grid.ok && u64::from(m) > grid.n_steps) {
                let step = f64::from(m) * sys.step_size;
                let e = self.err(
                    inst.line,
                    format!(
                        "instance '{}': step_multiple = {m} (a step of {} s); it must be a whole number of base steps from 1 to the run's {} (a step size that is not a number, infinite, or longer than the run?)",
                        inst.name,
                        short(step),
                        grid.n_steps
                    ),
                );
                self.errors.push(e);
            }
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
                isolate: inst.isolate,
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
