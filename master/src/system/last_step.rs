//! What a system file says about a stop time off the base-step grid ([`LastStep`]), and what a
//! validated run does about it ([`OffGrid`]).
//!
//! A stop time off the grid ends the run in one of two ways: at the last grid point before it
//! (the default, libcosim's way), or with a shorter last step to the stop time itself (FMPy's
//! way: `fmpy.simulation.simulateCS` sets the last communication point to the stop time when
//! the FMU declares canHandleVariableCommunicationStepSize, FMI 2.0, sec. 4.3.1). The master's
//! communication points ([`crate::run::TimeGrid`]) follow it.

/// What a run does when its stop time is off the base-step grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LastStep {
    /// Stop at the last grid point before the stop time (a warning says so).
    #[default]
    Drop,
    /// Take a shorter last step to the stop time. Every FMU must declare
    /// canHandleVariableCommunicationStepSize.
    Short,
}

impl LastStep {
    /// `"short"` or `"drop"` (the system file's `last_step` and the CLI's `--last-step`).
    pub fn parse(s: &str) -> Option<LastStep> {
        match s {
            "short" => Some(LastStep::Short),
            "drop" => Some(LastStep::Drop),
            _ => None,
        }
    }

    /// The name [`LastStep::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            LastStep::Short => "short",
            LastStep::Drop => "drop",
        }
    }
}

/// A stop time off the base-step grid, and what the run did about it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OffGrid {
    /// The stop time asked for.
    pub stop_time: f64,
    pub last_step: LastStep,
}
