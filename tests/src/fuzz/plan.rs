//! What a run runs: the fixed suite of `cargo xtask test` and the seeded rounds of
//! `cargo xtask fuzz --minutes N`.

use super::files::Family;
use super::runner::{Target, Task};
use super::units::{param_cases, Kind};

/// The suite's seed (the number): fixed, so CI runs the same cases every time.
pub const SUITE_SEED: u64 = 19;

/// Random call sequences per FMU in the suite (x [`super::units::CALLS_PER_UNIT`] calls: 24 FMUs give
/// 28,800 calls).
pub const SUITE_CALL_UNITS: u64 = 30;
/// Mutated states per FMU in the suite (24 FMUs give 1,032).
pub const SUITE_STATE_UNITS: u64 = 43;
/// Malformed files per family in the suite.
pub const SUITE_FILE_UNITS: u64 = 60;

/// Splits `units` into tasks of at most `chunk` units (so that two workers share the load).
fn chunks(
    units: std::ops::Range<u64>,
    chunk: u64,
    mut task: impl FnMut(std::ops::Range<u64>) -> Task,
) -> Vec<Task> {
    let mut out = Vec::new();
    let mut a = units.start;
    while a < units.end {
        let b = (a + chunk).min(units.end);
        out.push(task(a..b));
        a = b;
    }
    out
}

/// One round: `calls` call units and `states` state units per FMU, the parameter units
/// `params` (None: every fixed case of each FMU), and `files` units per file family.
pub fn round(
    targets: &[Target],
    seed: u64,
    calls: u64,
    states: u64,
    params: Option<u64>,
    files: u64,
) -> Vec<Task> {
    let mut tasks = Vec::new();
    for (i, t) in targets.iter().enumerate() {
        let fmu = |kind, units| Task::Fmu {
            kind,
            target: i,
            seed,
            units,
        };
        tasks.extend(chunks(0..calls, 6, |u| fmu(Kind::Calls, u)));
        tasks.extend(chunks(0..states, 22, |u| fmu(Kind::State, u)));
        let fixed = param_cases(&super::ffi::Model::new(&t.unpacked.md)).len() as u64;
        let range = match params {
            None => 0..fixed,
            // Past the fixed cases, a parameter unit draws a random parameter and value.
            Some(n) => fixed..fixed + n,
        };
        tasks.extend(chunks(range, 40, |u| fmu(Kind::Param, u)));
    }
    for family in [Family::Toml, Family::Osp, Family::Md] {
        tasks.extend(chunks(0..files, 10, |u| Task::File {
            family,
            seed,
            units: u,
        }));
    }
    tasks
}

/// The suite of `cargo xtask test`.
pub fn suite(targets: &[Target], files: bool) -> Vec<Task> {
    round(
        targets,
        SUITE_SEED,
        SUITE_CALL_UNITS,
        SUITE_STATE_UNITS,
        None,
        if files { SUITE_FILE_UNITS } else { 0 },
    )
}

/// Round `r` of a long run from `seed`: the first round holds every fixed parameter case.
pub fn long_round(targets: &[Target], seed: u64, r: u64, files: bool) -> Vec<Task> {
    round(
        targets,
        seed.wrapping_add(r),
        SUITE_CALL_UNITS,
        SUITE_STATE_UNITS,
        if r == 0 { None } else { Some(20) },
        if files { 20 } else { 0 },
    )
}
