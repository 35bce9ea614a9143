//! The registered coupled-system studies (see [`crate::study`]). Each module runs system files
//! from `systems/` and returns a [`Report`](crate::study::Report).
//!
//! To add a study: a module with `pub fn run(env: &Env) -> Result<Report, String>`, one entry
//! in [`STUDIES`], and one `#[test]` line in `tests/tests/studies.rs`.

use crate::study::{Env, Report};

pub mod autopilot;
pub mod autopilot_robustness;
pub mod container_ship_seaway;
pub mod dgps_trial;
pub mod dp_observer;
pub mod loop_analysis;
mod path_common;
pub mod path_control;
pub mod path_estimation;
pub mod rrs;
pub mod rrs_polar;
pub mod steering_gear;

/// A study: id (also its output folder under `target/studies/`), function.
pub type Study = (&'static str, fn(&Env) -> Result<Report, String>);

pub const STUDIES: &[Study] = &[
    ("steering_gear", steering_gear::run),
    ("dp_observer", dp_observer::run),
    ("dgps_trial", dgps_trial::run),
    ("rrs", rrs::run),
    ("path_control", path_control::run),
    ("autopilot", autopilot::run),
    ("path_estimation", path_estimation::run),
    ("container_ship_seaway", container_ship_seaway::run),
    ("loop_analysis", loop_analysis::run),
];

/// Studies in the report only (`cargo xtask report`): campaigns too long for the test suite,
/// which runs reduced versions of them.
pub const REPORT_ONLY: &[Study] = &[
    ("rrs_polar", rrs_polar::run),
    ("autopilot_robustness", autopilot_robustness::run),
];

/// Runs the study `id` in `target/studies/<id>/`.
pub fn run(id: &str) -> Result<Report, String> {
    let (_, f) = STUDIES
        .iter()
        .chain(REPORT_ONLY)
        .find(|s| s.0 == id)
        .ok_or_else(|| format!("no study {id:?}"))?;
    let env = Env::new(&format!("studies/{id}"))?;
    f(&env)
}
