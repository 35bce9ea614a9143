//! Campaigns: many runs of one system over factors, seeds and arms, one KPI row per run.
//!
//! A campaign file ([`spec`]) names a base system and says what to vary and what to measure.
//! [`Campaign::load`] reads it, reads the base system and lays out the runs ([`design`]: each
//! run is made from its index when it is needed).
//! [`execute::run`] runs them on a work-stealing pool, each with its own FMU
//! instances (every FMU library loaded once per process), computing the KPIs on the fly
//! ([`kpi`], [`manoeuvre`]) and appending each finished run durably to the journal
//! ([`journal`]), from which the run table and the derived table ([`derived`]) are written
//! ([`output`], [`table`]). With `fork_at`, runs that share everything fixed at
//! initialization share one warm-up to `fork_at` and continue from its checkpoint.
//! [`remote`] splits the same work between worker processes that run chunks of runs and one
//! client that records them (the Python package's Dask mode).

use crate::error::{Error, Result};
use crate::model_description::ModelDescription;
use crate::system::{EventSpec, OutputSpec, System, Value, VarRef};
use sha2::{Digest, Sha256};
use std::path::Path;

pub mod derived;
pub mod design;
pub mod execute;
pub mod journal;
pub mod kpi;
pub mod manoeuvre;
pub mod merge;
pub mod output;
pub mod plot;
pub mod remote;
pub mod spec;
pub mod table;

pub use design::{Design, Run};
pub use execute::{CampaignOptions, CampaignOutcome};
pub use spec::CampaignSpec;

/// A campaign: its file, its base system and its runs.
#[derive(Debug, Clone)]
pub struct Campaign {
    pub spec: CampaignSpec,
    /// The base system, with the campaign's stop time and the recorded KPI variables.
    pub system: System,
    /// SHA-256 of the base system file and of every FMU file it uses.
    pub base_hash: String,
    /// The runs, each made from its index when asked for.
    pub runs: Design,
}

/// SHA-256 of a file's bytes, hex.
pub fn file_hash(path: &Path) -> Result<String> {
    crate::digest::file_sha256(path)
}

/// Every KPI window holds part of the run: a window that starts after the stop time gives every
/// run a NaN statistic.
fn windows_fit(spec: &CampaignSpec, system: &System) -> Result<()> {
    let Some(stop) = system.stop_time else {
        return Ok(());
    };
    for k in &spec.kpis {
        if let kpi::KpiSpec::Stat { name, window, .. } = k {
            if window.0 > stop {
                return Err(Error::Other(format!(
                    "campaign {}: kpi '{name}': its window [{}, {}] starts after the run ends \
                     (stop time {stop} s), so it would hold no sample",
                    spec.source.display(),
                    window.0,
                    window.1
                )));
            }
        }
    }
    Ok(())
}

impl Campaign {
    /// Reads a campaign file and its base system, and lays out the runs.
    pub fn load(path: &Path) -> Result<Campaign> {
        Campaign::from_spec(CampaignSpec::load(path)?)
    }

    /// A checked campaign file with its base system read from the file it names.
    pub fn from_spec(spec: CampaignSpec) -> Result<Campaign> {
        let system = System::load(&spec.system).map_err(|e| {
            Error::Other(format!(
                "campaign {}: base system: {e}",
                spec.source.display()
            ))
        })?;
        Campaign::new(spec, system)
    }

    /// A checked campaign file with its base system given (e.g. with the FMU paths pointed
    /// elsewhere): records the KPI variables, hashes the system file and FMUs, lays out the runs.
    pub fn new(spec: CampaignSpec, mut system: System) -> Result<Campaign> {
        system.apply_stop_time(spec.stop_time)?;
        system.apply_step_size(spec.step_size)?;
        // derived expressions are checked now, not after every run has run
        derived::DerivedKpi::compile(&spec, &output::kpi_columns(&spec))?;
        windows_fit(&spec, &system)?;
        let mut variables: Vec<String> = Vec::new();
        let series = spec.series.iter().flat_map(|s| s.variables.iter().cloned());
        for v in spec
            .kpis
            .iter()
            .flat_map(|k| k.variables())
            .map(str::to_string)
            .chain(series)
        {
            if !variables.contains(&v) {
                variables.push(v);
            }
        }
        system.output = OutputSpec {
            file: None,
            variables: Some(variables),
            decimation: 1,
        };
        let mut h = Sha256::new();
        h.update(file_hash(&spec.system)?.as_bytes());
        for inst in &system.instances {
            system.require_fmu(inst)?;
            h.update(file_hash(&inst.fmu)?.as_bytes());
        }
        let base_hash = design::hex(&h.finalize());
        if let Some(t) = spec.fork_at {
            if let Some(k) = spec.kpis.iter().find(|k| k.start() < t) {
                return Err(Error::Other(format!(
                    "campaign {}: kpi '{}' starts before fork_at = {t} s; runs that fork share \
                     everything before it, so windows must start at or after it",
                    spec.source.display(),
                    k.name()
                )));
            }
        }
        let runs = Design::new(&spec, &base_hash)?;
        Ok(Campaign {
            spec,
            system,
            base_hash,
            runs,
        })
    }

    /// The cold system of a run: the base system with the run's values as start values.
    pub fn system_for(&self, run: &Run) -> Result<System> {
        let mut s = self.system.clone();
        set_start_values(&mut s, &run.sets)?;
        Ok(s)
    }

    /// The systems of a forked run, given which variables can change during a run:
    /// (the warm-up system, shared by every run of the run's group: the base system with the
    /// run's values of everything else as start values; the run itself: the warm-up system
    /// with the run's values of the changeable variables set by events at `fork_at`).
    /// The run is, by construction, the cold run that applies the change by events at T.
    pub fn fork_systems_for(
        &self,
        run: &Run,
        fork_at: f64,
        changeable: &dyn Fn(&VarRef) -> bool,
    ) -> Result<(System, System)> {
        let (late, early): (Vec<_>, Vec<_>) = design::effective_sets(&run.sets)
            .into_iter()
            .partition(|(v, _)| VarRef::parse(v).is_some_and(|r| changeable(&r)));
        let mut warm_up = self.system.clone();
        set_start_values(&mut warm_up, &early)?;
        let mut member = warm_up.clone();
        for (v, value) in late {
            member.events.push(EventSpec {
                time: fork_at,
                target: VarRef::parse(&v).expect("checked"),
                value,
                line: None,
            });
        }
        Ok((warm_up, member))
    }

    /// The key of the warm-up group of a run: a hash of its values of everything that cannot
    /// change during a run.
    pub fn group_key(&self, run: &Run, changeable: &dyn Fn(&VarRef) -> bool) -> String {
        let mut h = Sha256::new();
        for (v, value) in design::effective_sets(&run.sets) {
            if !VarRef::parse(&v).is_some_and(|r| changeable(&r)) {
                h.update(format!("{v}={value}\n").as_bytes());
            }
        }
        design::hex(&h.finalize())
    }
}

/// Whether `r` names an input or tunable parameter (settable during a run, FMI 2.0 sec. 4.2.4)
/// of an instance of `system` with model descriptions `mds`.
pub fn changeable_in(system: &System, mds: &[&ModelDescription], r: &VarRef) -> bool {
    let Some(i) = system.instances.iter().position(|s| s.name == r.instance) else {
        return false;
    };
    mds[i]
        .model_variables
        .variables
        .iter()
        .find(|v| v.name == r.variable)
        .is_some_and(|v| v.settable_in_step_mode())
}

/// Sets values as start values, like `--set` (later values win).
fn set_start_values(system: &mut System, sets: &[(String, Value)]) -> Result<()> {
    for (v, value) in sets {
        let r = VarRef::parse(v)
            .ok_or_else(|| Error::Other(format!("'{v}' is not instance.variable")))?;
        system.set_value(r, value.clone()).map_err(|e| {
            Error::Other(format!(
                "campaign sets '{v}' in {}: {e}",
                system.source.display()
            ))
        })?;
    }
    Ok(())
}
