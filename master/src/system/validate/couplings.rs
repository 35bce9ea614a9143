//! Couplings that have no effect. An FMU may declare, per output, the parameter that scales it
//! (a `<Coupling output=".." gain=".."/>` of the tool "shipsim" in `<VendorAnnotations>`,
//! FMI 2.0, sec. 2.2.6; our FMUs write it from the `fmu!` table's `.gated_by(..)`). A connected
//! output whose gain is 0 (the system's value, or else the start value) carries only zeros:
//! a warning, since the run is valid but the connection does nothing.

use super::Checker;
use crate::system::plan::{PlanConnection, PlanInstance};
use crate::system::TypedValue;

impl Checker<'_> {
    /// A warning for every connected output whose declared gain parameter is 0.
    pub(super) fn ineffective_couplings(
        &mut self,
        instances: &[PlanInstance],
        connections: &[PlanConnection],
    ) {
        for (i, (inst, md)) in self.sys.instances.iter().zip(self.mds).enumerate() {
            for coupling in md.couplings() {
                let vars = &md.model_variables.variables;
                let find = |name: &str| vars.iter().find(|v| v.name == name);
                let (Some(output), Some(gain)) = (find(&coupling.output), find(&coupling.gain))
                else {
                    continue;
                };
                let set = instances.get(i).and_then(|p| {
                    p.start_values
                        .iter()
                        .rev()
                        .find(|s| s.variable == gain.name)
                });
                let value = match set.map(|s| &s.value) {
                    Some(TypedValue::Real(x)) => Some(*x),
                    Some(TypedValue::Integer(k)) => Some(f64::from(*k)),
                    Some(_) => None,
                    None => gain
                        .real
                        .as_ref()
                        .and_then(|r| r.start)
                        .or_else(|| gain.integer.as_ref().and_then(|r| r.start.map(f64::from))),
                };
                if value != Some(0.0) {
                    continue;
                }
                let targets: Vec<&str> = connections
                    .iter()
                    .filter(|c| c.from_instance == i && c.from_vr == output.value_reference)
                    .map(|c| c.name.as_str())
                    .collect();
                if targets.is_empty() {
                    continue;
                }
                self.warnings.push(format!(
                    "{}: '{}.{}' is connected ({}) but its gain '{}.{}' is 0{}, so the \
                     connection carries only zeros; set {} (shipsim inspect --doc {} says how)",
                    self.loc(inst.line),
                    inst.name,
                    output.name,
                    targets.join(", "),
                    inst.name,
                    gain.name,
                    if set.is_some() { "" } else { " (its default)" },
                    gain.name,
                    inst.fmu.display(),
                ));
            }
        }
    }
}
