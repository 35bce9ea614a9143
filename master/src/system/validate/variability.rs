//! Variability the standard forbids: only Real variables can be `continuous` (FMI 2.0, sec.
//! 2.2.7, the `variability` attribute). FMPy's validation refuses such an FMU; shipsim runs it
//! (the variable is exchanged through its type's functions either way) and warns once per FMU
//! file.

use super::Checker;
use crate::model_description::{VarType, Variability};
use std::path::Path;

impl Checker<'_> {
    /// A warning for every non-Real variable declared `continuous`, once per FMU file.
    pub(super) fn invalid_variability(&mut self) {
        let mut seen: Vec<&Path> = Vec::new();
        for (inst, md) in self.sys.instances.iter().zip(self.mds) {
            if seen.contains(&inst.fmu.as_path()) {
                continue;
            }
            seen.push(&inst.fmu);
            let bad: Vec<String> = md
                .model_variables
                .variables
                .iter()
                .filter(|v| v.variability == Variability::Continuous)
                .filter_map(|v| match v.var_type() {
                    Some(VarType::Real) | None => None,
                    Some(t) => Some(format!("'{}' ({t})", v.name)),
                })
                .collect();
            if !bad.is_empty() {
                self.warnings.push(format!(
                    "{}: FMU {} declares {} continuous; FMI 2.0 allows variability=\"continuous\" \
                     only for Real variables (sec. 2.2.7); it runs as declared",
                    self.loc(inst.line),
                    inst.fmu.display(),
                    bad.join(", ")
                ));
            }
        }
    }
}
