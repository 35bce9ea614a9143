//! `HeadingAutopilot` FMU: the loop-shaped DDG-51 heading autopilot [Taylor2000, sec. 5.2] of
//! `models::controllers::loop_shaped`, Tustin-discretised in the nondimensional time base, with
//! the +-30 deg command limit and the 90 deg track-change reference generator. No physics here.

use fmi2_export::FmuModel;
use models::controllers::loop_shaped::{
    HeadingAutopilot, HeadingDesign, HeadingReference, TrackChange,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one autopilot instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct HeadingAutopilotFmu {
    design: HeadingDesign,
    reference: HeadingReference,
    track_change: TrackChange,
    heading: f64,
    reference_input: f64,
    autopilot: HeadingAutopilot,
}

impl Default for HeadingAutopilotFmu {
    fn default() -> Self {
        let design = HeadingDesign::default();
        HeadingAutopilotFmu {
            design,
            reference: HeadingReference::External,
            track_change: TrackChange::default(),
            heading: 0.0,
            reference_input: 0.0,
            autopilot: HeadingAutopilot::new(design).expect("default design is valid"),
        }
    }
}

fmi2_export::fmu! {
    HeadingAutopilotFmu => "HeadingAutopilot",
    description: "Loop-shaped DDG-51 heading autopilot (C = L/P, \
        L = wn^2/(s(s^2 + 2 zeta wn s + wn^2))), Tustin in t' = tU/L, +-30 deg command limit, \
        track-change reference generator",
    experiment: (0.0, 600.0, 0.05),
    documentation: "documentation.html",
    variables: {
        loop_shaping_common!(design.common);
        tunable real "omega_n" (design.omega_n).min(0.0),
            "Target-loop natural frequency in t' (eqs. 5.32-5.34: sqrt(60))";
        tunable real "zeta" (design.zeta).min(0.0), "Target-loop damping (2)";
        fixed int "reference_mode"
            (reference => { 0: HeadingReference::External, 1: HeadingReference::TrackChange }),
            "0: heading_reference input; 1: track-change generator (turn by turn_angle at turn_rate from turn_start, leg_time, turn back), relative to the initial heading";
        fixed real "turn_angle" ["rad"] (track_change.angle),
            "Track change angle (negative: to port; 000 section 4.8: -90 deg)";
        fixed real "turn_rate" ["rad/s"] (track_change.turn_rate).min(0.0),
            "Heading-command rate during the turns (not given in 000)";
        fixed real "leg_time" ["s"] (track_change.leg).min(0.0), "Time on the new leg before turning back";
        fixed real "turn_start" ["s"] (track_change.start).min(0.0),
            "Start of the first turn after the start time";
        input real "heading" ["rad"] (heading), "Measured heading psi";
        input real "heading_reference" ["rad"] (reference_input),
            "Commanded heading (reference_mode = 0)";
        output real "rudder_command" ["rad"] (|m| m.autopilot.command()),
            "Rudder command delta_c = sat(C(z)(psi_ref - psi)), held between samples";
        output real "unlimited_command" ["rad"] (|m| m.autopilot.unlimited_command()),
            "Controller output before the command limit";
        output real "heading_reference_used" ["rad"] (|m| m.autopilot.heading_reference()),
            "Heading reference at the last sample";
    }
}

impl FmuModel for HeadingAutopilotFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        let mut autopilot = HeadingAutopilot::new(self.design).map_err(|e| e.to_string())?;
        autopilot.reference = self.reference;
        autopilot.track_change = self.track_change;
        autopilot.start(self.heading, self.reference_input);
        self.autopilot = autopilot;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.autopilot
            .set_design(self.design)
            .map_err(|e| e.to_string())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.autopilot.step(self.heading, self.reference_input, h);
        Ok(())
    }
}
