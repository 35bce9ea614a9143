//! Recorded outputs: `inst.var`, `inst.*` (every output of an instance), or by default every
//! output of every instance. A String variable is recorded when it is named (`inst.var`), not by
//! `inst.*` or the default, whose columns stay numbers.

use super::Checker;
use crate::error::did_you_mean;
use crate::model_description::{Causality, VarType};
use crate::system::{PlanOutput, VarRef};
use std::collections::HashSet;

impl Checker<'_> {
    /// The recorded columns, in the order the system lists them, each variable once: a variable
    /// both named and matched by `inst.*` (or named twice) keeps its first column.
    pub(super) fn outputs(&mut self) -> Vec<PlanOutput> {
        let mut outputs = Vec::new();
        let sys = self.sys;
        match &sys.output.variables {
            None => {
                for i in 0..sys.instances.len() {
                    self.all_outputs(i, &mut outputs);
                }
            }
            Some(list) => {
                for s in list {
                    self.output(s, &mut outputs);
                }
            }
        }
        let mut seen = HashSet::with_capacity(outputs.len());
        outputs.retain(|o| seen.insert((o.instance, o.vr, o.var_type)));
        outputs
    }

    /// One entry of the output list.
    fn output(&mut self, s: &str, outputs: &mut Vec<PlanOutput>) {
        if let Some(inst) = s.strip_suffix(".*") {
            match self.index.get(inst) {
                Some(&i) => self.all_outputs(i, outputs),
                None => {
                    let e = self.err(
                        None,
                        format!(
                            "output '{s}': no instance named '{inst}'{}",
                            did_you_mean(inst, self.inst_names())
                        ),
                    );
                    self.errors.push(e);
                }
            }
            return;
        }
        let Some(r) = VarRef::parse(s) else {
            let e = self.err(
                None,
                format!("output '{s}' must be written instance.variable or instance.*"),
            );
            self.errors.push(e);
            return;
        };
        match self.resolve(&r, None, "output") {
            Ok((i, vi)) => self.push_output(i, vi, outputs, true),
            Err(e) => self.errors.push(e),
        }
    }

    /// Every output variable of instance `i`.
    fn all_outputs(&self, i: usize, outputs: &mut Vec<PlanOutput>) {
        for (vi, v) in self.mds[i].model_variables.variables.iter().enumerate() {
            if v.causality == Causality::Output {
                self.push_output(i, vi, outputs, false);
            }
        }
    }

    /// Variable `vi` of instance `i` as a recorded output; a String only when `strings` (it is
    /// named, not matched by `instance.*`).
    fn push_output(&self, i: usize, vi: usize, outputs: &mut Vec<PlanOutput>, strings: bool) {
        let sv = &self.mds[i].model_variables.variables[vi];
        let t = sv.var_type().unwrap();
        if t != VarType::String || strings {
            outputs.push(PlanOutput {
                instance: i,
                vr: sv.value_reference,
                var_type: if t == VarType::Enumeration {
                    VarType::Integer
                } else {
                    t
                },
                header: format!("{}.{}", self.sys.instances[i].name, sv.name),
            });
        }
    }
}
