//! What a checkpoint's system set and coupled, besides its structure: the connections'
//! transformations, the start values and the events before the checkpoint (issue 38, item 3).
//! Each changes the result, so a resume under different ones would continue a run that never
//! happened; they are compared at resume, and the difference is named.
//!
//! One difference is meant rather than mistaken: a new value for a tunable parameter or an
//! input (`shipsim run --resume cp.bin --set autopilot.k=2`). [`Checkpoint::adopt`] turns it
//! into an event at the checkpoint's time, so that the resumed run is the cold run with that
//! change at T, as a campaign fork is. A fixed parameter cannot change after initialization,
//! so a new value for one is refused.

use super::{Checkpoint, Fingerprint};
use crate::fmu::{Fmu, VR};
use crate::system::{Plan, PlanEvent, TypedValue, ValueMapping};
use std::collections::BTreeMap;
use std::sync::Arc;

/// A value set on an instance: a start value, or an event at `step`.
#[derive(Debug, Clone)]
pub struct Setting {
    pub instance: u32,
    pub vr: VR,
    /// `instance.variable`, for messages.
    pub label: String,
    pub value: TypedValue,
    /// The event's base step (0 for a start value).
    pub step: u64,
}

/// A connection's destination and transformation (its source is in
/// [`Fingerprint::observed`], at the same index).
#[derive(Debug, Clone)]
pub struct Coupling {
    pub label: String,
    pub to_instance: u32,
    pub to_vr: VR,
    pub gain: f64,
    pub offset: f64,
    /// A term of a summed input.
    pub sum: bool,
    /// A value mapping: (Boolean?, (source, target) pairs).
    pub mapping: Option<(bool, Vec<(i32, i32)>)>,
}

/// Bitwise equality: a resume reproduces a run bit for bit, so -0.0 is not 0.0.
fn same_value(a: &TypedValue, b: &TypedValue) -> bool {
    match (a, b) {
        (TypedValue::Real(x), TypedValue::Real(y)) => x.to_bits() == y.to_bits(),
        _ => a == b,
    }
}

/// A value as a user writes it.
pub fn show(v: &TypedValue) -> String {
    match v {
        TypedValue::Real(x) => format!("{x}"),
        TypedValue::Integer(i) => format!("{i}"),
        TypedValue::Boolean(b) => format!("{b}"),
        TypedValue::String(s) => format!("{s:?}"),
    }
}

impl PartialEq for Setting {
    /// The label only names it.
    fn eq(&self, o: &Self) -> bool {
        (self.instance, self.vr, self.step) == (o.instance, o.vr, o.step)
            && same_value(&self.value, &o.value)
    }
}

impl PartialEq for Coupling {
    fn eq(&self, o: &Self) -> bool {
        (self.to_instance, self.to_vr, self.sum, &self.mapping)
            == (o.to_instance, o.to_vr, o.sum, &o.mapping)
            && self.gain.to_bits() == o.gain.to_bits()
            && self.offset.to_bits() == o.offset.to_bits()
    }
}

impl Coupling {
    /// "label (gain g, offset o, summed, mapped)", for messages.
    fn describe(&self) -> String {
        let mut s = format!("{} (gain {}, offset {}", self.label, self.gain, self.offset);
        if self.sum {
            s.push_str(", summed");
        }
        if let Some((_, pairs)) = &self.mapping {
            let p: Vec<String> = pairs.iter().map(|(a, b)| format!("{a}->{b}")).collect();
            s.push_str(&format!(", mapping {}", p.join(" ")));
        }
        s + ")"
    }
}

/// The couplings, start values and events of `plan`.
pub fn of_plan(plan: &Plan) -> (Vec<Coupling>, Vec<Setting>, Vec<Setting>) {
    let couplings = plan
        .connections
        .iter()
        .map(|c| Coupling {
            label: c.name.clone(),
            to_instance: c.to_instance as u32,
            to_vr: c.to_vr,
            gain: c.gain,
            offset: c.offset,
            sum: c.sum,
            mapping: c.mapping.as_ref().map(mapping_pairs),
        })
        .collect();
    let starts = plan
        .instances
        .iter()
        .enumerate()
        .flat_map(|(i, pi)| {
            pi.start_values.iter().map(move |s| Setting {
                instance: i as u32,
                vr: s.vr,
                label: format!("{}.{}", pi.name, s.variable),
                value: s.value.clone(),
                step: 0,
            })
        })
        .collect();
    let events = plan
        .events
        .iter()
        .map(|e| Setting {
            instance: e.instance as u32,
            vr: e.vr,
            label: e.name.clone(),
            value: e.value.clone(),
            step: e.step,
        })
        .collect();
    (couplings, starts, events)
}

fn mapping_pairs(m: &ValueMapping) -> (bool, Vec<(i32, i32)>) {
    (m.boolean, m.entries().to_vec())
}

/// Start values by (instance, value reference), the last one winning as when applied.
fn by_variable(starts: &[Setting]) -> BTreeMap<(u32, VR), &Setting> {
    starts.iter().map(|s| ((s.instance, s.vr), s)).collect()
}

impl Fingerprint {
    /// The first difference in connections' transformations or start values.
    pub(super) fn settings_difference(&self, here: &Fingerprint) -> Option<String> {
        if let Some((a, b)) = self
            .couplings
            .iter()
            .zip(&here.couplings)
            .find(|(a, b)| a != b)
        {
            return Some(format!(
                "connection {} in the checkpoint, {} in this system",
                a.describe(),
                b.describe()
            ));
        }
        if self.couplings.len() != here.couplings.len() {
            return Some(format!(
                "{} connections in the checkpoint, {} in this system",
                self.couplings.len(),
                here.couplings.len()
            ));
        }
        let (mine, theirs) = (by_variable(&self.starts), by_variable(&here.starts));
        for key in mine.keys().chain(theirs.keys()) {
            let (a, b) = (mine.get(key), theirs.get(key));
            if a.zip(b)
                .is_some_and(|(a, b)| same_value(&a.value, &b.value))
            {
                continue;
            }
            let label = a.or(b).map(|s| s.label.as_str()).unwrap_or_default();
            let value = |s: Option<&&Setting>| match s {
                Some(s) => show(&s.value),
                None => "not set".into(),
            };
            return Some(format!(
                "{label} is {} in the checkpoint, {} in this system (a resume continues the \
                 checkpoint's run: a fixed parameter cannot change after initialization, and \
                 `shipsim run --resume` applies a new value of a tunable parameter or input \
                 as an event at the checkpoint's time)",
                value(a),
                value(b)
            ));
        }
        None
    }

    /// The first difference in the events before base step `k` (the ones that made the run
    /// the checkpoint holds).
    pub(super) fn past_events_difference(&self, here: &Fingerprint, k: u64) -> Option<String> {
        let past = |f: &Fingerprint| -> Vec<Setting> {
            f.events.iter().filter(|e| e.step < k).cloned().collect()
        };
        let (a, b) = (past(self), past(here));
        let at = |e: &Setting| {
            format!(
                "{} = {} at t = {} s",
                e.label,
                show(&e.value),
                self.grid().at(e.step)
            )
        };
        let before = self.grid().at(k);
        if let Some((x, y)) = a.iter().zip(&b).find(|(x, y)| x != y) {
            return Some(format!(
                "an event before t = {before} s is {} in the checkpoint, {} in this system",
                at(x),
                at(y)
            ));
        }
        (a.len() != b.len()).then(|| {
            format!(
                "{} event(s) before t = {before} s in the checkpoint, {} in this system",
                a.len(),
                b.len()
            )
        })
    }
}

impl Checkpoint {
    /// Makes `plan` resume this checkpoint with its new values of tunable parameters and
    /// inputs: each start value that differs from the checkpoint's (or that the checkpoint's
    /// system did not set), on a variable that may change during a run (FMI 2.0 sec. 4.2.4),
    /// becomes an event at the checkpoint's step, before the plan's own events there, and the
    /// start value goes back to the checkpoint's. Returns a note per value moved. Other
    /// differences are left for [`Checkpoint::check`] to name (a fixed parameter cannot
    /// change after initialization). Does nothing when the instances differ.
    pub fn adopt(&self, plan: &mut Plan, fmus: &[Arc<Fmu>]) -> Vec<String> {
        let mine = self.fingerprint.instances.iter().map(|i| i.name.as_str());
        if !mine.eq(plan.instances.iter().map(|i| i.name.as_str())) {
            return Vec::new();
        }
        let theirs = by_variable(&self.fingerprint.starts);
        let mut moved = Vec::new();
        for (i, (pi, fmu)) in plan.instances.iter_mut().zip(fmus).enumerate() {
            let name = pi.name.clone();
            pi.start_values.retain_mut(|s| {
                let old = theirs.get(&(i as u32, s.vr)).map(|o| &o.value);
                let changeable = || {
                    fmu.variable(&s.variable)
                        .is_some_and(|v| v.settable_in_step_mode())
                };
                if old.is_some_and(|o| same_value(o, &s.value)) || !changeable() {
                    return true;
                }
                let event = PlanEvent {
                    step: self.step,
                    instance: i,
                    vr: s.vr,
                    value: s.value.clone(),
                    name: format!("{name}.{}", s.variable),
                };
                let was = old.map_or("no value set".into(), show);
                moved.push((event, was));
                match old {
                    Some(o) => {
                        s.value = o.clone();
                        true
                    }
                    None => false,
                }
            });
        }
        let notes = moved
            .iter()
            .map(|(e, was)| {
                format!(
                    "{} = {}: applied at t = {} s, the checkpoint's time, as an event (the checkpoint's run had {was})",
                    e.name,
                    show(&e.value),
                    self.time
                )
            })
            .collect();
        let at = plan.events.partition_point(|e| e.step < self.step);
        plan.events
            .splice(at..at, moved.into_iter().map(|(e, _)| e));
        notes
    }
}
