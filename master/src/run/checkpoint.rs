//! A master-level checkpoint: a run at communication point t_k, complete enough to continue it
//! in fresh instances, bit for bit as if it had never stopped.
//!
//! A [`Checkpoint`] holds every instance's FMU state, serialized by the FMU itself (FMI 2.0,
//! sec. 2.1.8: `fmi2GetFMUstate`, `fmi2SerializeFMUstate`; the FMU must declare
//! canGetAndSetFMUstate and canSerializeFMUstate), and the exchange's [`Values`] at t_k: the
//! outputs published at the last communication point. The FMU states alone do not suffice:
//! under Jacobi an instance with a step multiple above 1 may already be past t_k while the
//! others still read the outputs it published before.
//!
//! The checkpoint is taken after the outputs of t_k are published and before the events of
//! step k, so a run continued from it ([`super::resume_into`]) applies the events at k and later
//! as usual: a warm-up run to t_k followed by runs that change a parameter at t_k (campaign
//! forks) gives what a cold run with that change as an event at t_k gives.
//!
//! Its [`Fingerprint`] says which run it belongs to: the instances, their FMUs' GUIDs and
//! archive hashes, the time grid, the algorithm and stepping order, the exchanged and recorded
//! variables, the connections' gains, offsets and mappings, the start values and the events
//! before it. A checkpoint is refused by a plan whose fingerprint differs, naming the
//! difference, with one exception: events at the checkpoint's step and later are what a fork
//! changes, and [`Checkpoint::adopt`] turns a new start value of a tunable parameter or input
//! into such an event ([`settings`]). The file format is in [`file`].

use super::exchange::Values;
use super::slot::Slot;
use super::time_grid::TimeGrid;
use crate::error::{Error, Result};
use crate::fmu::{Fmu, VR};
use crate::instance::Stepping;
use crate::system::{Algorithm, Plan};
use std::sync::Arc;

mod file;
mod settings;

pub use settings::{Coupling, Setting};

/// A run at communication point t_`step` (see the module documentation).
#[derive(Debug, Clone)]
pub struct Checkpoint {
    /// The base step k: the run continues with step k (its events included).
    pub step: u64,
    /// t_k.
    pub time: f64,
    /// The exchange's values at t_k.
    pub values: Values,
    /// Every instance's serialized FMU state, in plan order.
    pub states: Vec<InstanceState>,
    pub fingerprint: Fingerprint,
}

/// One instance's FMU state, in the FMU's own serialization.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InstanceState {
    pub name: String,
    pub bytes: Vec<u8>,
}

/// What identifies the system a checkpoint belongs to.
#[derive(Debug, Clone, PartialEq)]
pub struct Fingerprint {
    pub start_time: f64,
    pub step_size: f64,
    pub n_steps: u64,
    pub algorithm: Algorithm,
    pub instances: Vec<InstanceId>,
    /// The stepping order (Gauss-Seidel: connection order).
    pub order: Vec<u32>,
    /// The variables the exchange reads (connection sources, then recorded outputs), which
    /// lay out [`Values`].
    pub observed: Vec<ObservedId>,
    /// The connections' destinations and transformations, in plan order.
    pub couplings: Vec<Coupling>,
    /// The start values set, by instance.
    pub starts: Vec<Setting>,
    /// Every event of the plan; those before the checkpoint's step must agree.
    pub events: Vec<Setting>,
}

/// An instance, its FMU and its rate.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InstanceId {
    pub name: String,
    pub guid: String,
    /// SHA-256 of the `.fmu` file ([`Fmu::archive_hash`]).
    pub fmu_hash: String,
    pub step_multiple: u32,
}

/// A variable the exchange reads: instance index, type code, value reference, and a label
/// for messages (the connection or the column header).
#[derive(Debug, Clone)]
pub struct ObservedId {
    pub instance: u32,
    pub kind: u8,
    pub vr: VR,
    pub label: String,
}

impl PartialEq for ObservedId {
    /// The label only names it.
    fn eq(&self, o: &Self) -> bool {
        (self.instance, self.kind, self.vr) == (o.instance, o.kind, o.vr)
    }
}

/// A type code of the file format, stable across releases.
fn kind_code(t: crate::model_description::VarType) -> u8 {
    use crate::model_description::VarType as T;
    match t {
        T::Real => 0,
        T::Integer => 1,
        T::Boolean => 2,
        T::String => 3,
        T::Enumeration => 4,
    }
}

impl Fingerprint {
    /// The fingerprint of a plan run with `fmus` (`fmus[i]` for `plan.instances[i]`); an
    /// FMU file that cannot be read again for its hash is an error.
    pub fn of(plan: &Plan, fmus: &[Arc<Fmu>]) -> Result<Fingerprint> {
        let sources = plan.connections.iter().map(|c| ObservedId {
            instance: c.from_instance as u32,
            kind: kind_code(c.var_type),
            vr: c.from_vr,
            label: c.name.clone(),
        });
        let outputs = plan.outputs.iter().map(|o| ObservedId {
            instance: o.instance as u32,
            kind: kind_code(o.var_type),
            vr: o.vr,
            label: o.header.clone(),
        });
        let (couplings, starts, events) = settings::of_plan(plan);
        Ok(Fingerprint {
            start_time: plan.start_time,
            step_size: plan.step_size,
            n_steps: plan.n_steps,
            algorithm: plan.algorithm,
            instances: plan
                .instances
                .iter()
                .zip(fmus)
                .map(|(pi, f)| {
                    Ok(InstanceId {
                        name: pi.name.clone(),
                        guid: f.guid().to_string(),
                        fmu_hash: f.archive_hash()?.to_string(),
                        step_multiple: pi.step_multiple,
                    })
                })
                .collect::<Result<_>>()?,
            order: plan.order.iter().map(|&i| i as u32).collect(),
            observed: sources.chain(outputs).collect(),
            couplings,
            starts,
            events,
        })
    }

    /// The first difference between the system of checkpoint `self` and `here`, said for a
    /// user, or None.
    pub fn difference(&self, here: &Fingerprint) -> Option<String> {
        let names = |f: &Fingerprint| {
            let n: Vec<&str> = f.instances.iter().map(|i| i.name.as_str()).collect();
            n.join(", ")
        };
        if self.instances.len() != here.instances.len() {
            return Some(format!(
                "{} instances ({}) in the checkpoint, {} ({}) in this system",
                self.instances.len(),
                names(self),
                here.instances.len(),
                names(here)
            ));
        }
        for (i, (a, b)) in self.instances.iter().zip(&here.instances).enumerate() {
            if a.name != b.name {
                return Some(format!(
                    "instance {} is '{}' in the checkpoint, '{}' in this system",
                    i + 1,
                    a.name,
                    b.name
                ));
            }
            if a.guid != b.guid {
                return Some(format!(
                    "instance '{}': FMU GUID \"{}\" in the checkpoint, \"{}\" in this system (a different FMU)",
                    a.name, a.guid, b.guid
                ));
            }
            if a.fmu_hash != b.fmu_hash {
                return Some(format!(
                    "instance '{}': the FMU file has SHA-256 {} in the checkpoint, {} in this system (another build of the FMU)",
                    a.name, a.fmu_hash, b.fmu_hash
                ));
            }
            if a.step_multiple != b.step_multiple {
                return Some(format!(
                    "instance '{}': step_multiple {} in the checkpoint, {} in this system",
                    a.name, a.step_multiple, b.step_multiple
                ));
            }
        }
        self.grid_difference(here)
            .or_else(|| self.exchange_difference(here))
            .or_else(|| self.settings_difference(here))
    }

    /// Time grid and algorithm.
    fn grid_difference(&self, here: &Fingerprint) -> Option<String> {
        let differ = |a: f64, b: f64| a.to_bits() != b.to_bits();
        if differ(self.start_time, here.start_time) {
            return Some(format!(
                "start_time {} s in the checkpoint, {} s in this system",
                self.start_time, here.start_time
            ));
        }
        if differ(self.step_size, here.step_size) {
            return Some(format!(
                "step_size {} s in the checkpoint, {} s in this system",
                self.step_size, here.step_size
            ));
        }
        if self.n_steps != here.n_steps {
            return Some(format!(
                "{} base steps (stop at t = {} s) in the checkpoint, {} (t = {} s) in this system",
                self.n_steps,
                self.grid().at(self.n_steps),
                here.n_steps,
                here.grid().at(here.n_steps)
            ));
        }
        if self.algorithm != here.algorithm {
            return Some(format!(
                "algorithm {:?} in the checkpoint, {:?} in this system",
                self.algorithm, here.algorithm
            ));
        }
        None
    }

    /// Stepping order and exchanged variables.
    fn exchange_difference(&self, here: &Fingerprint) -> Option<String> {
        if self.order != here.order {
            let show = |f: &Fingerprint| {
                let n: Vec<&str> = f
                    .order
                    .iter()
                    .map(|&i| f.instances[i as usize].name.as_str())
                    .collect();
                n.join(", ")
            };
            return Some(format!(
                "stepping order ({}) in the checkpoint, ({}) in this system",
                show(self),
                show(here)
            ));
        }
        if let Some(i) = (0..self.observed.len().min(here.observed.len()))
            .find(|&i| self.observed[i] != here.observed[i])
        {
            return Some(format!(
                "connection or recorded output {} is '{}' in the checkpoint, '{}' in this system",
                i + 1,
                self.observed[i].label,
                here.observed[i].label
            ));
        }
        if self.observed.len() != here.observed.len() {
            return Some(format!(
                "{} connections and recorded outputs in the checkpoint, {} in this system",
                self.observed.len(),
                here.observed.len()
            ));
        }
        None
    }

    /// The run's time grid.
    pub fn grid(&self) -> TimeGrid {
        TimeGrid::new(self.start_time, self.step_size, self.n_steps)
    }

    /// Indices into `instances` (a file's order must name them).
    fn check_indices(&self) -> std::result::Result<(), String> {
        let n = self.instances.len();
        if let Some(i) = self.order.iter().find(|&&i| i as usize >= n) {
            return Err(format!("stepping order names instance {i} of {n}"));
        }
        if let Some(o) = self.observed.iter().find(|o| o.instance as usize >= n) {
            return Err(format!(
                "variable '{}' names instance {} of {n}",
                o.label, o.instance
            ));
        }
        if let Some(c) = self.couplings.iter().find(|c| c.to_instance as usize >= n) {
            return Err(format!(
                "connection '{}' names instance {} of {n}",
                c.label, c.to_instance
            ));
        }
        let mut set = self.starts.iter().chain(&self.events);
        if let Some(s) = set.find(|s| s.instance as usize >= n) {
            return Err(format!(
                "'{}' names instance {} of {n}",
                s.label, s.instance
            ));
        }
        if self.couplings.len() > self.observed.len() {
            return Err(format!(
                "{} connections but {} exchanged variables",
                self.couplings.len(),
                self.observed.len()
            ));
        }
        Ok(())
    }
}

impl Checkpoint {
    /// The run at t_`step`: every instance's serialized state and the exchange's values.
    pub fn capture(
        fingerprint: Fingerprint,
        step: u64,
        slots: &mut [Slot<Stepping>],
        values: &Values,
    ) -> Result<Checkpoint> {
        let states = slots
            .iter_mut()
            .map(|s| {
                Ok(InstanceState {
                    name: s.inst.name().to_string(),
                    bytes: s.inst.serialize_state()?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Checkpoint {
            step,
            time: fingerprint.grid().at(step),
            values: values.clone(),
            states,
            fingerprint,
        })
    }

    /// The checkpoint belongs to the system of `plan` (run with `fmus`), else an error naming
    /// the first difference.
    pub fn check_plan(&self, plan: &Plan, fmus: &[Arc<Fmu>]) -> Result<()> {
        self.check(&Fingerprint::of(plan, fmus)?)
    }

    /// The checkpoint belongs to the system of fingerprint `here` and is consistent in itself.
    pub fn check(&self, here: &Fingerprint) -> Result<()> {
        let at = format!("the checkpoint at t = {} s (step {})", self.time, self.step);
        let differs = self
            .fingerprint
            .difference(here)
            .or_else(|| self.fingerprint.past_events_difference(here, self.step));
        if let Some(d) = differs {
            return Err(Error::Other(format!(
                "{at} is from a different system: {d}"
            )));
        }
        self.consistency()
            .map_err(|m| Error::Other(format!("{at} is inconsistent: {m}")))
    }

    /// Step, time and states agree with the fingerprint.
    fn consistency(&self) -> std::result::Result<(), String> {
        let fp = &self.fingerprint;
        if self.step >= fp.n_steps {
            return Err(format!("the run has only {} base steps", fp.n_steps));
        }
        let t = fp.grid().at(self.step);
        if t.to_bits() != self.time.to_bits() {
            return Err(format!("step {} is at t = {t} s", self.step));
        }
        if self.states.len() != fp.instances.len() {
            return Err(format!(
                "{} instance states for {} instances",
                self.states.len(),
                fp.instances.len()
            ));
        }
        for (s, i) in self.states.iter().zip(&fp.instances) {
            if s.name != i.name {
                return Err(format!(
                    "the state of '{}' where '{}' belongs",
                    s.name, i.name
                ));
            }
        }
        fp.check_indices()
    }

    /// Restores every instance's state and the exchange's values. `values` must have the
    /// layout of the checkpoint's exchange (the fingerprints agree, [`Self::check`]).
    pub fn restore(&self, slots: &mut [Slot<Stepping>], values: &mut Values) -> Result<()> {
        let lengths = |v: &Values| [v.real.len(), v.integer.len(), v.boolean.len()];
        if lengths(&self.values) != lengths(values) || self.states.len() != slots.len() {
            return Err(Error::Other(format!(
                "the checkpoint at t = {} s holds {:?} Real/Integer/Boolean values and {} states; this run exchanges {:?} values between {} instances",
                self.time,
                lengths(&self.values),
                self.states.len(),
                lengths(values),
                slots.len()
            )));
        }
        for (slot, state) in slots.iter_mut().zip(&self.states) {
            slot.inst.restore_state(&state.bytes)?;
        }
        values.real.copy_from_slice(&self.values.real);
        values.integer.copy_from_slice(&self.values.integer);
        values.boolean.copy_from_slice(&self.values.boolean);
        Ok(())
    }
}

/// The base step of time `t` for a checkpoint of `plan`: a communication point t0 + k*h
/// strictly inside the run (the rule of event times, within 1e-6 of a step).
pub fn checkpoint_step(plan: &Plan, t: f64) -> Result<u64> {
    let kf = (t - plan.start_time) / plan.step_size;
    let k = kf.round();
    if !(k >= 1.0) || (kf - k).abs() > 1e-6 || k >= plan.n_steps as f64 {
        return Err(Error::Other(format!(
            "checkpoint time {t} s: it must be a base-step point t0 + k*h (h = {} s) strictly between the start {} s and the end {} s",
            plan.step_size, plan.start_time, plan.stop_time
        )));
    }
    Ok(k as u64)
}
