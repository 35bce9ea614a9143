//! `TrackController` FMU: the loop-shaped DDG-51 cross-track controller [Taylor2000, sec. 5.3] of
//! `models::controllers::loop_shaped`, Tustin-discretised in the nondimensional time base, with
//! the +-30 deg command limit and the lateral-offset reference generator. No physics here.

use fmi2_export::FmuModel;
use models::controllers::loop_shaped::{
    LateralOffset, TrackController, TrackDesign, TrackReference,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one autopilot instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TrackControllerFmu {
    design: TrackDesign,
    reference: TrackReference,
    lateral_offset: LateralOffset,
    cross_track: f64,
    reference_input: f64,
    controller: TrackController,
}

impl Default for TrackControllerFmu {
    fn default() -> Self {
        let design = TrackDesign::default();
        TrackControllerFmu {
            design,
            reference: TrackReference::External,
            lateral_offset: LateralOffset::default(),
            cross_track: 0.0,
            reference_input: 0.0,
            controller: TrackController::new(design).expect("default design is valid"),
        }
    }
}

fmi2_export::fmu! {
    TrackControllerFmu => "TrackController",
    description: "Loop-shaped DDG-51 cross-track controller \
        C_y = 20(s+0.5)^2(s+6)(s+1000)/((s+11)(s+15)(s+30)^2), Tustin in t' = tU/L, \
        +-30 deg command limit, lateral-offset reference generator",
    experiment: (0.0, 600.0, 0.05),
    documentation: "documentation.html",
    variables: {
        loop_shaping_common!(design.common);
        tunable real "gain" (design.gain),
            "Controller gain of C_y = gain (s+z1)(s+z2)(s+z3)(s+z4)/((s+p1)(s+p2)(s+p3)(s+p4)) (L2641: 20)";
        tunable real "zero1" (design.zeros[0]), "Zero z1 in t' (0.5, 0.5, 6, 1000)";
        tunable real "zero2" (design.zeros[1]), "Zero z2 in t' (0.5, 0.5, 6, 1000)";
        tunable real "zero3" (design.zeros[2]), "Zero z3 in t' (0.5, 0.5, 6, 1000)";
        tunable real "zero4" (design.zeros[3]), "Zero z4 in t' (0.5, 0.5, 6, 1000)";
        tunable real "pole1" (design.poles[0]), "Pole p1 in t' (11, 15, 30, 30)";
        tunable real "pole2" (design.poles[1]), "Pole p2 in t' (11, 15, 30, 30)";
        tunable real "pole3" (design.poles[2]), "Pole p3 in t' (11, 15, 30, 30)";
        tunable real "pole4" (design.poles[3]), "Pole p4 in t' (11, 15, 30, 30)";
        fixed int "reference_mode"
            (reference => { 0: TrackReference::External, 1: TrackReference::LateralOffset }),
            "0: cross_track_reference input; 1: lateral-offset generator (offset from offset_start over offset_duration, cosine ramp; 0 = step)";
        fixed real "offset" ["m"] (lateral_offset.offset), "Lateral offset of the generated manoeuvre";
        fixed real "offset_start" ["s"] (lateral_offset.start).min(0.0),
            "Start of the offset manoeuvre after the start time";
        fixed real "offset_duration" ["s"] (lateral_offset.duration).min(0.0),
            "Duration of the cosine ramp (0: a step)";
        input real "cross_track" ["m"] (cross_track),
            "Measured lateral position y relative to the track (positive to starboard)";
        input real "cross_track_reference" ["m"] (reference_input),
            "Commanded lateral position (reference_mode = 0)";
        output real "rudder_command" ["rad"] (|m| m.controller.command()),
            "Rudder command delta_c = sat(C_y(z)(y_ref - y)/L), held between samples";
        output real "unlimited_command" ["rad"] (|m| m.controller.unlimited_command()),
            "Controller output before the command limit";
        output real "cross_track_reference_used" ["m"] (|m| m.controller.cross_track_reference()),
            "Cross-track reference at the last sample";
    }
}

impl FmuModel for TrackControllerFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        let mut controller = TrackController::new(self.design).map_err(|e| e.to_string())?;
        controller.reference = self.reference;
        controller.lateral_offset = self.lateral_offset;
        controller.start(self.reference_input);
        self.controller = controller;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.controller
            .set_design(self.design)
            .map_err(|e| e.to_string())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.controller
            .step(self.cross_track, self.reference_input, h);
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        self.controller.internal_steps(h, each);
    }
}
