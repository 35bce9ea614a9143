//! FMUs that share a GUID: two different FMU files whose model descriptions differ but whose
//! `guid` is the same. The GUID is meant to identify one model description (FMI 2.0, sec.
//! 2.2.1); libcosim caches unpacked FMUs by it and would run the first model for both. shipsim
//! runs each file's own model, so this is a warning, for the systems that go on to libcosim
//! (`export-osp`).

use super::Checker;
use crate::model_description::ModelDescription;
use std::path::PathBuf;

/// The same model, as far as an importer that trusts the GUID can tell: name, identifier and
/// variables (names and value references).
fn same_model(a: &ModelDescription, b: &ModelDescription) -> bool {
    let id = |m: &ModelDescription| m.co_simulation.as_ref().map(|c| c.model_identifier.clone());
    let vars = |m: &ModelDescription| {
        m.model_variables
            .variables
            .iter()
            .map(|v| (v.name.clone(), v.value_reference))
            .collect::<Vec<_>>()
    };
    a.model_name == b.model_name && id(a) == id(b) && vars(a) == vars(b)
}

impl Checker<'_> {
    /// A warning for every pair of FMU files with the same GUID and different models.
    pub(super) fn shared_guids(&mut self) {
        // (file, model description) of each distinct FMU file, in instance order.
        let mut files: Vec<(PathBuf, &ModelDescription)> = Vec::new();
        for (inst, md) in self.sys.instances.iter().zip(self.mds) {
            let file = inst.fmu.canonicalize().unwrap_or_else(|_| inst.fmu.clone());
            if !files.iter().any(|(f, _)| *f == file) {
                files.push((file, md));
            }
        }
        for (k, (fa, a)) in files.iter().enumerate() {
            for (fb, b) in &files[k + 1..] {
                if a.guid == b.guid && !same_model(a, b) {
                    self.warnings.push(format!(
                        "{}: FMUs {} (model '{}') and {} (model '{}') share the GUID {}; libcosim \
                         caches FMUs by GUID and would run one model for both (shipsim runs each)",
                        self.loc(None),
                        fa.display(),
                        a.model_name,
                        fb.display(),
                        b.model_name,
                        a.guid
                    ));
                }
            }
        }
    }
}
