//! `HeadingAutopilot` FMU: the loop-shaped DDG-51 heading autopilot [Taylor2000, sec. 5.2] of
//! `models::controllers::loop_shaped`, Tustin-discretised in the nondimensional time base, with
//! the +-30 deg command limit and the 90 deg track-change reference generator. No physics here.
//!
//! The design parameters default to the DDG-51 (466 ft, 22 kn); `preset` selects a named design
//! (`models::controllers::loop_shaped::presets`): 1 the DDG-51, 2 the container ship at 7 m/s.

use fmi2_export::FmuModel;
use models::controllers::loop_shaped::presets::HeadingPreset;
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
    /// The named design that replaces the design parameters (`Custom`: none).
    preset: HeadingPreset,
}

/// The nine design parameters of `design`, by variable name.
fn design_values(d: &HeadingDesign) -> [(&'static str, f64); 9] {
    let c = &d.common;
    [
        ("nomoto_k", c.nomoto_k),
        ("nomoto_t", c.nomoto_t),
        ("gear_pole", c.gear_pole),
        ("sample_step", c.sample_step),
        ("command_limit", c.limit),
        ("ship_length", c.length),
        ("ship_speed", c.speed),
        ("omega_n", d.omega_n),
        ("zeta", d.zeta),
    ]
}

impl HeadingAutopilotFmu {
    /// The design in use: the parameters' with `preset` = 0, else the preset's. A design
    /// parameter set to a value that is neither its default (the DDG-51's) nor the preset's
    /// conflicts with the preset and is refused, whatever the order of the sets.
    fn resolved_design(&self) -> Result<HeadingDesign, String> {
        let Some(preset) = self.preset.design() else {
            return Ok(self.design);
        };
        let default = HeadingDesign::default();
        let values = design_values(&self.design);
        let ours = design_values(&preset);
        let defaults = design_values(&default);
        for ((name, v), ((_, p), (_, d))) in values.iter().zip(ours.iter().zip(defaults.iter())) {
            if v != p && v != d {
                return Err(format!(
                    "preset = {} sets {name} = {p}, but {name} was set to {v}: \
                     set preset = 0 to give the design parameters one by one",
                    self.preset as i32
                ));
            }
        }
        Ok(preset)
    }
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
            preset: HeadingPreset::Custom,
        }
    }
}

fmi2_export::fmu! {
    HeadingAutopilotFmu => "HeadingAutopilot",
    description: "Loop-shaped DDG-51 heading autopilot (C = L/P, \
        L = wn^2/(s(s^2 + 2 zeta wn s + wn^2))), Tustin in t' = tU/L, +-30 deg command limit, \
        track-change reference generator. The design parameters default to the DDG-51 \
        (466 ft, 22 kn): for another ship set preset (2: container ship at 7 m/s) or all of them",
    experiment: (0.0, 600.0, 0.05),
    documentation: "documentation.html",
    variables: {
        tunable real "nomoto_k" (design.common.nomoto_k).min(0.0),
            "Nomoto K' of the design plant in t' = tU/L (eq. 5.26: 2.04, the DDG-51's; preset sets it)";
        tunable real "nomoto_t" (design.common.nomoto_t).min(0.0),
            "Nomoto T' in ship lengths (eq. 5.25: 1.9287, the DDG-51's; preset sets it)";
        tunable real "gear_pole" (design.common.gear_pole).min(0.0),
            "Steering-gear pole a of a/(s+a) in t' (eq. 5.28: 6, the DDG-51's; preset sets it)";
        tunable real "sample_step" (design.common.sample_step).min(0.0),
            "Largest internal Tustin step in ship lengths (t'); each communication step is split into equal samples not longer than this";
        tunable real "command_limit" ["rad"] (design.common.limit).min(0.0),
            "Rudder command limit (L2192-2199: 30 deg; container-ship preset: its 10 deg)";
        fixed real "ship_length" ["m"] (design.common.length).min(0.0),
            "Ship length L of the time base. Default: the DDG-51's 466 ft, not your ship's: set it with the other design parameters, or set preset";
        fixed real "ship_speed" ["m/s"] (design.common.speed).min(0.0),
            "Ship speed U of the time base. Default: the DDG-51's 22 kn, not your ship's: set it with the other design parameters, or set preset";
        tunable real "omega_n" (design.omega_n).min(0.0),
            "Target-loop natural frequency in t' (eqs. 5.32-5.34: sqrt(60))";
        tunable real "zeta" (design.zeta).min(0.0), "Target-loop damping (2)";
        fixed int "reference_mode"
            (reference => { 0: HeadingReference::External, 1: HeadingReference::TrackChange }),
            "0: heading_reference input; 1: track-change generator (turn by turn_angle at turn_rate from turn_start, leg_time, turn back), relative to the initial heading";
        fixed real "turn_angle" ["rad"] (track_change.angle),
            "Track change angle (negative: to port; [Taylor2000, sec. 4.8]: -90 deg)";
        fixed real "turn_rate" ["rad/s"] (track_change.turn_rate).min(0.0),
            "Heading-command rate during the turns (not given in [Taylor2000])";
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
        fixed int "preset" (preset => {
            0: HeadingPreset::Custom,
            1: HeadingPreset::Ddg51,
            2: HeadingPreset::ContainerShip,
        }),
            "Named design, replacing nomoto_k, nomoto_t, gear_pole, sample_step, command_limit, ship_length, ship_speed, omega_n, zeta: 0 none (those parameters; defaults DDG-51), 1 DDG-51 at 22 kn (= the defaults), 2 container ship (ContainerShip, L = 175 m) at 7 m/s with its own 1 s, 10 deg servo (K' = 2.921, T' = 4.360, a = 25, limit 10 deg)";
    }
}

impl FmuModel for HeadingAutopilotFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.design = self.resolved_design()?;
        let mut autopilot = HeadingAutopilot::new(self.design).map_err(|e| e.to_string())?;
        autopilot.reference = self.reference;
        autopilot.track_change = self.track_change;
        autopilot.start(self.heading, self.reference_input);
        self.autopilot = autopilot;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.design = self.resolved_design()?;
        self.autopilot
            .set_design(self.design)
            .map_err(|e| e.to_string())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.autopilot.step(self.heading, self.reference_input, h);
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        self.autopilot.internal_steps(h, each);
    }
}
