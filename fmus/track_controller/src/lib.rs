//! `TrackController` FMU: the loop-shaped DDG-51 cross-track controller (source 000) of
//! `models::controllers::loop_shaped`, Tustin-discretised in the nondimensional time base, with
//! the +-30 deg command limit and the lateral-offset reference generator. No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::controllers::loop_shaped::{
    LateralOffset, TrackController, TrackDesign, TrackReference,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one autopilot instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TrackControllerFmu {
    d: TrackDesign,
    reference: TrackReference,
    lo: LateralOffset,
    cross_track: f64,
    reference_input: f64,
    tc: TrackController,
}

impl Default for TrackControllerFmu {
    fn default() -> Self {
        let d = TrackDesign::default();
        TrackControllerFmu {
            d,
            reference: TrackReference::External,
            lo: LateralOffset::default(),
            cross_track: 0.0,
            reference_input: 0.0,
            tc: TrackController::new(d).expect("default design is valid"),
        }
    }
}

type V = Variable<TrackControllerFmu>;

static VARIABLES: [V; 25] = [
    V::real_parameter(
        "nomoto_k",
        None,
        true,
        "Nomoto K' of the design plant in t' = tU/L (eq. 5.26: 2.04)",
        |m| m.d.common.nomoto_k,
        |m, v| m.d.common.nomoto_k = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "nomoto_t",
        None,
        true,
        "Nomoto T' in ship lengths (eq. 5.25: 1.9287)",
        |m| m.d.common.nomoto_t,
        |m, v| m.d.common.nomoto_t = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "gear_pole",
        None,
        true,
        "Steering-gear pole a of a/(s+a) in t' (eq. 5.28: 6)",
        |m| m.d.common.gear_pole,
        |m, v| m.d.common.gear_pole = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "sample_step",
        None,
        true,
        "Largest internal Tustin step in ship lengths (t'); each communication step is split into equal samples not longer than this",
        |m| m.d.common.sample_step,
        |m, v| m.d.common.sample_step = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "command_limit",
        Some("rad"),
        true,
        "Rudder command limit (L2192-2199: 30 deg)",
        |m| m.d.common.limit,
        |m, v| m.d.common.limit = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "ship_length",
        Some("m"),
        false,
        "Ship length L of the time base (DDG-51: 466 ft)",
        |m| m.d.common.length,
        |m, v| m.d.common.length = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "ship_speed",
        Some("m/s"),
        false,
        "Ship speed U of the time base (22 kn)",
        |m| m.d.common.speed,
        |m, v| m.d.common.speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "gain",
        None,
        true,
        "Controller gain of C_y = gain (s+z1)(s+z2)(s+z3)(s+z4)/((s+p1)(s+p2)(s+p3)(s+p4)) (L2641: 20)",
        |m| m.d.gain,
        |m, v| m.d.gain = v,
    ),
    V::real_parameter(
        "zero1",
        None,
        true,
        "Zero z1 in t' (0.5, 0.5, 6, 1000)",
        |m| m.d.zeros[0],
        |m, v| m.d.zeros[0] = v,
    ),
    V::real_parameter(
        "zero2",
        None,
        true,
        "Zero z2 in t' (0.5, 0.5, 6, 1000)",
        |m| m.d.zeros[1],
        |m, v| m.d.zeros[1] = v,
    ),
    V::real_parameter(
        "zero3",
        None,
        true,
        "Zero z3 in t' (0.5, 0.5, 6, 1000)",
        |m| m.d.zeros[2],
        |m, v| m.d.zeros[2] = v,
    ),
    V::real_parameter(
        "zero4",
        None,
        true,
        "Zero z4 in t' (0.5, 0.5, 6, 1000)",
        |m| m.d.zeros[3],
        |m, v| m.d.zeros[3] = v,
    ),
    V::real_parameter(
        "pole1",
        None,
        true,
        "Pole p1 in t' (11, 15, 30, 30)",
        |m| m.d.poles[0],
        |m, v| m.d.poles[0] = v,
    ),
    V::real_parameter(
        "pole2",
        None,
        true,
        "Pole p2 in t' (11, 15, 30, 30)",
        |m| m.d.poles[1],
        |m, v| m.d.poles[1] = v,
    ),
    V::real_parameter(
        "pole3",
        None,
        true,
        "Pole p3 in t' (11, 15, 30, 30)",
        |m| m.d.poles[2],
        |m, v| m.d.poles[2] = v,
    ),
    V::real_parameter(
        "pole4",
        None,
        true,
        "Pole p4 in t' (11, 15, 30, 30)",
        |m| m.d.poles[3],
        |m, v| m.d.poles[3] = v,
    ),
    V::integer_parameter(
        "reference_mode",
        false,
        "0: cross_track_reference input; 1: lateral-offset generator (offset from offset_start over offset_duration, cosine ramp; 0 = step)",
        0,
        1,
        |m| match m.reference {
            TrackReference::External => 0,
            TrackReference::LateralOffset => 1,
        },
        |m, v| {
            m.reference = if v == 1 {
                TrackReference::LateralOffset
            } else {
                TrackReference::External
            }
        },
    ),
    V::real_parameter(
        "offset",
        Some("m"),
        false,
        "Lateral offset of the generated manoeuvre",
        |m| m.lo.offset,
        |m, v| m.lo.offset = v,
    ),
    V::real_parameter(
        "offset_start",
        Some("s"),
        false,
        "Start of the offset manoeuvre after the start time",
        |m| m.lo.start,
        |m, v| m.lo.start = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "offset_duration",
        Some("s"),
        false,
        "Duration of the cosine ramp (0: a step)",
        |m| m.lo.duration,
        |m, v| m.lo.duration = v,
    )
    .with_range(Some(0.0), None),
    V::real_input(
        "cross_track",
        Some("m"),
        "Measured lateral position y relative to the track (positive to starboard)",
        |m| m.cross_track,
        |m, v| m.cross_track = v,
    ),
    V::real_input(
        "cross_track_reference",
        Some("m"),
        "Commanded lateral position (reference_mode = 0)",
        |m| m.reference_input,
        |m, v| m.reference_input = v,
    ),
    V::real_output(
        "rudder_command",
        Some("rad"),
        "Rudder command delta_c = sat(C_y(z)(y_ref - y)/L), held between samples",
        |m| m.tc.command(),
    ),
    V::real_output(
        "unlimited_command",
        Some("rad"),
        "Controller output before the command limit",
        |m| m.tc.unlimited_command(),
    ),
    V::real_output(
        "cross_track_reference_used",
        Some("m"),
        "Cross-track reference at the last sample",
        |m| m.tc.cross_track_reference(),
    ),
];

impl FmuModel for TrackControllerFmu {
    const MODEL_IDENTIFIER: &'static str = "TrackController";
    const DESCRIPTION: &'static str = "Loop-shaped DDG-51 cross-track controller \
        C_y = 20(s+0.5)^2(s+6)(s+1000)/((s+11)(s+15)(s+30)^2), Tustin in t' = tU/L, \
        +-30 deg command limit, lateral-offset reference generator";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 600.0,
        step_size: 0.05,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        let mut tc = TrackController::new(self.d).map_err(|e| e.to_string())?;
        tc.reference = self.reference;
        tc.lateral_offset = self.lo;
        tc.start(self.reference_input);
        self.tc = tc;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.tc.set_design(self.d).map_err(|e| e.to_string())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.tc.step(self.cross_track, self.reference_input, h);
        Ok(())
    }
}

export_fmu!(TrackControllerFmu);
