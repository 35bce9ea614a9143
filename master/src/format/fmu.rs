//! An FMU run alone, as FMPy's `simulate_fmu` runs one: `shipsim run X.fmu` (issue 36,
//! item 10). The system has one instance, named by the FMU's model identifier, over the FMU's
//! `DefaultExperiment` (FMI 2.0 sec. 2.2.5), recording every output into `<identifier>.csv`
//! in the current folder. What the model description leaves out takes FMPy's defaults: start
//! 0 s, stop start + 1 s, step (stop - start) / 500. The choices are said in
//! [`System::notes`].

use crate::error::Result;
use crate::fmu::UnpackedFmu;
use crate::system::{Algorithm, Format, InstanceSpec, OutputSpec, System};
use std::path::{Path, PathBuf};

/// Whether `path` names an FMU archive (by its extension).
pub fn is_fmu_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("fmu"))
}

/// The system of one FMU: see the module documentation.
pub fn load(path: &Path) -> Result<System> {
    let fmu = UnpackedFmu::open(path)?;
    let id = fmu.check()?.model_identifier.clone();
    let exp = fmu
        .model_description
        .default_experiment
        .clone()
        .unwrap_or_default();
    let start = exp.start_time.unwrap_or(0.0);
    let stop = exp.stop_time.unwrap_or(start + 1.0);
    let step = exp.step_size.unwrap_or((stop - start) / 500.0);
    let from = |given: Option<f64>, default: &str| match given {
        Some(x) => format!("{x} s from its DefaultExperiment"),
        None => format!("{default} (FMPy's default; it has no DefaultExperiment value)"),
    };
    let csv = PathBuf::from(format!("{id}.csv"));
    let note = format!(
        "running the FMU {} alone as instance '{id}': start {}, stop {}, step {}, every output \
         to {} (-o, --stop-time, --step-size and --set {id}.VARIABLE=VALUE change them)",
        path.display(),
        from(exp.start_time, "0 s"),
        from(exp.stop_time, "start + 1 s"),
        from(exp.step_size, "(stop - start) / 500"),
        csv.display()
    );
    Ok(System {
        source: path.to_path_buf(),
        format: Format::Fmu,
        start_time: start,
        stop_time: Some(stop),
        step_size: step,
        algorithm: Algorithm::Jacobi,
        instances: vec![InstanceSpec {
            name: id,
            fmu: path.to_path_buf(),
            step_multiple: 1,
            values: Vec::new(),
            line: None,
            isolate: false,
        }],
        connections: Vec::new(),
        events: Vec::new(),
        output: OutputSpec {
            file: Some(csv),
            variables: None,
            decimation: 1,
        },
        strict_units: false,
        last_step: Default::default(),
        archive: None,
        notes: vec![note],
        io: Vec::new(),
    })
}
