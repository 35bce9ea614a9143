//! Events: a value set at a base-step point during the run, on an input or tunable parameter.

use super::connections::Driven;
use super::values::convert;
use super::{Checker, Grid};
use crate::system::{EventSpec, PlanEvent};

impl Checker<'_> {
    /// Every event checked and resolved, sorted by step (stable: same-step events keep their
    /// order in the file).
    pub(super) fn events(&mut self, grid: &Grid, driven: &Driven) -> Vec<PlanEvent> {
        let mut events: Vec<PlanEvent> = self
            .sys
            .events
            .iter()
            .filter_map(|e| self.event(e, grid, driven))
            .collect();
        events.sort_by_key(|e| e.step);
        events
    }

    fn event(&mut self, e: &EventSpec, grid: &Grid, driven: &Driven) -> Option<PlanEvent> {
        let (i, vi) = self
            .resolve(&e.target, e.line, "event")
            .map_err(|err| self.errors.push(err))
            .ok()?;
        let sv = &self.mds[i].model_variables.variables[vi];
        if sv.variability == crate::model_description::Variability::Constant {
            let err = self.err(
                e.line,
                format!(
                    "event at t = {}: '{}' is a constant and cannot be set (value {})",
                    e.time, e.target, e.value
                ),
            );
            self.errors.push(err);
            return None;
        }
        if !sv.settable_in_step_mode() {
            let err = self.err(e.line, format!(
                "event at t = {}: '{}' is {} {}; only inputs and tunable parameters can change during a run",
                e.time, e.target, sv.variability, sv.causality));
            self.errors.push(err);
            return None;
        }
        let tv = match convert(&e.value, self.mds[i], sv) {
            Ok(v) => v,
            Err(m) => {
                let err = self.err(
                    e.line,
                    format!("event at t = {}, '{}': {m}", e.time, e.target),
                );
                self.errors.push(err);
                return None;
            }
        };
        let sys = self.sys;
        let kf = (e.time - sys.start_time) / sys.step_size;
        let k = kf.round();
        if !(k >= 0.0) || (kf - k).abs() > 1e-6 || k as u64 >= grid.n_steps {
            let err = self.err(
                e.line,
                format!(
                "event at t = {} for '{}': the time must be a base-step point t0 + k*h in [{}, {})",
                e.time, e.target, sys.start_time, grid.stop_on_grid),
            );
            self.errors.push(err);
            return None;
        }
        if driven.contains_key(&(i, vi)) {
            self.warnings.push(format!("{}: event sets '{}', which a connection also drives; the connection overrides it at the next exchange", self.loc(e.line), e.target));
        }
        Some(PlanEvent {
            step: k as u64,
            instance: i,
            vr: sv.value_reference,
            value: tv,
            name: e.target.to_string(),
        })
    }
}

impl super::System {
    /// One value set from outside a running system, at time `e.time`, in a run of `n_steps`
    /// base steps ending at `stop` (a stepping session's `set`, [`crate::run::Session::set`]), checked and resolved as an
    /// event at t_step of the system file would be: the same name, type, unit, range and
    /// causality rules, and the same messages. A connected input is accepted (the connection
    /// drives it again at the next exchange, as for an event).
    pub fn resolve_event(
        &self,
        mds: &[&crate::model_description::ModelDescription],
        e: &EventSpec,
        n_steps: u64,
        stop: f64,
    ) -> crate::error::Result<PlanEvent> {
        let mut c = Checker {
            sys: self,
            mds,
            index: self
                .instances
                .iter()
                .enumerate()
                .map(|(i, inst)| (inst.name.as_str(), i))
                .collect(),
            errors: Vec::new(),
            warnings: Vec::new(),
        };
        let grid = Grid {
            ok: true,
            n_steps,
            stop_on_grid: stop,
            off_grid: None,
        };
        match c.event(e, &grid, &Driven::new()) {
            Some(ev) => Ok(ev),
            None => Err(c.errors.pop().unwrap_or_else(|| {
                crate::error::Error::Other(format!("'{}' cannot be set", e.target))
            })),
        }
    }
}
