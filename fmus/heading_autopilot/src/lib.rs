//! `HeadingAutopilot` FMU: the loop-shaped DDG-51 heading autopilot (source 000) of
//! `models::controllers::loop_shaped`, Tustin-discretised in the nondimensional time base, with
//! the +-30 deg command limit and the 90 deg track-change reference generator. No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::controllers::loop_shaped::{
    HeadingAutopilot, HeadingDesign, HeadingReference, TrackChange,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one autopilot instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct HeadingAutopilotFmu {
    d: HeadingDesign,
    reference: HeadingReference,
    tc: TrackChange,
    heading: f64,
    reference_input: f64,
    ap: HeadingAutopilot,
}

impl Default for HeadingAutopilotFmu {
    fn default() -> Self {
        let d = HeadingDesign::default();
        HeadingAutopilotFmu {
            d,
            reference: HeadingReference::External,
            tc: TrackChange::default(),
            heading: 0.0,
            reference_input: 0.0,
            ap: HeadingAutopilot::new(d).expect("default design is valid"),
        }
    }
}

type V = Variable<HeadingAutopilotFmu>;

static VARIABLES: [V; 19] = [
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
        "omega_n",
        None,
        true,
        "Target-loop natural frequency in t' (eqs. 5.32-5.34: sqrt(60))",
        |m| m.d.omega_n,
        |m, v| m.d.omega_n = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "zeta",
        None,
        true,
        "Target-loop damping (2)",
        |m| m.d.zeta,
        |m, v| m.d.zeta = v,
    )
    .with_range(Some(0.0), None),
    V::integer_parameter(
        "reference_mode",
        false,
        "0: heading_reference input; 1: track-change generator (turn by turn_angle at turn_rate from turn_start, leg_time, turn back), relative to the initial heading",
        0,
        1,
        |m| match m.reference {
            HeadingReference::External => 0,
            HeadingReference::TrackChange => 1,
        },
        |m, v| {
            m.reference = if v == 1 {
                HeadingReference::TrackChange
            } else {
                HeadingReference::External
            }
        },
    ),
    V::real_parameter(
        "turn_angle",
        Some("rad"),
        false,
        "Track change angle (negative: to port; 000 section 4.8: -90 deg)",
        |m| m.tc.angle,
        |m, v| m.tc.angle = v,
    ),
    V::real_parameter(
        "turn_rate",
        Some("rad/s"),
        false,
        "Heading-command rate during the turns (not given in 000)",
        |m| m.tc.turn_rate,
        |m, v| m.tc.turn_rate = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "leg_time",
        Some("s"),
        false,
        "Time on the new leg before turning back",
        |m| m.tc.leg,
        |m, v| m.tc.leg = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "turn_start",
        Some("s"),
        false,
        "Start of the first turn after the start time",
        |m| m.tc.start,
        |m, v| m.tc.start = v,
    )
    .with_range(Some(0.0), None),
    V::real_input(
        "heading",
        Some("rad"),
        "Measured heading psi",
        |m| m.heading,
        |m, v| m.heading = v,
    ),
    V::real_input(
        "heading_reference",
        Some("rad"),
        "Commanded heading (reference_mode = 0)",
        |m| m.reference_input,
        |m, v| m.reference_input = v,
    ),
    V::real_output(
        "rudder_command",
        Some("rad"),
        "Rudder command delta_c = sat(C(z)(psi_ref - psi)), held between samples",
        |m| m.ap.command(),
    ),
    V::real_output(
        "unlimited_command",
        Some("rad"),
        "Controller output before the command limit",
        |m| m.ap.unlimited_command(),
    ),
    V::real_output(
        "heading_reference_used",
        Some("rad"),
        "Heading reference at the last sample",
        |m| m.ap.heading_reference(),
    ),
];

impl FmuModel for HeadingAutopilotFmu {
    const MODEL_IDENTIFIER: &'static str = "HeadingAutopilot";
    const DESCRIPTION: &'static str = "Loop-shaped DDG-51 heading autopilot (C = L/P, \
        L = wn^2/(s(s^2 + 2 zeta wn s + wn^2))), Tustin in t' = tU/L, +-30 deg command limit, \
        track-change reference generator";
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
        let mut ap = HeadingAutopilot::new(self.d).map_err(|e| e.to_string())?;
        ap.reference = self.reference;
        ap.track_change = self.tc;
        ap.start(self.heading, self.reference_input);
        self.ap = ap;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.ap.set_design(self.d).map_err(|e| e.to_string())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.ap.step(self.heading, self.reference_input, h);
        Ok(())
    }
}

export_fmu!(HeadingAutopilotFmu);
