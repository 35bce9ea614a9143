//! `RrsAutopilot` FMU: the rudder roll stabilization autopilot of van der Klugt (1987, source 003)
//! in `models::controllers::rrs` (roll LQ via the innovation process, closed-form course
//! controller, AGC, criterion adaptation, operator modes) as an FMI 2.0 co-simulation FMU. No
//! physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::controllers::rrs::{AgcTarget, RollMode, RrsAutopilot, RrsAutopilotParams, RrsInputs};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one autopilot instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RrsAutopilotFmu {
    p: RrsAutopilotParams,
    inputs: RrsInputs,
    ap: RrsAutopilot,
}

impl Default for RrsAutopilotFmu {
    fn default() -> Self {
        let p = RrsAutopilotParams::default();
        RrsAutopilotFmu {
            inputs: RrsInputs {
                speed: 11.0,
                ..RrsInputs::default()
            },
            ap: RrsAutopilot::new(p).expect("default parameters are valid"),
            p,
        }
    }
}

type V = Variable<RrsAutopilotFmu>;

static VARIABLES: [V; 55] = [
    V::boolean_parameter(
        "agc_enabled",
        true,
        "Automatic Gain Controller on (003 section 5.3)",
        |m| m.p.agc_enabled,
        |m, v| m.p.agc_enabled = v,
    ),
    V::integer_parameter(
        "agc_target",
        true,
        "1: A*(delta_psi + delta_phi) (literal Fig. 5.5); 2: delta_psi + A*delta_phi (default, course changes do not attenuate the course loop)",
        1,
        2,
        |m| match m.p.agc_target {
            AgcTarget::Total => 1,
            AgcTarget::RollOnly => 2,
        },
        |m, v| {
            m.p.agc_target = if v == 1 {
                AgcTarget::Total
            } else {
                AgcTarget::RollOnly
            }
        },
    ),
    V::integer_parameter(
        "roll_mode",
        true,
        "Roll stabilisation 0 OFF (gains computed, not applied: course only), 1 ON, 2 forced roll (inverted roll feedback) [operator]",
        0,
        2,
        |m| match m.p.roll_mode {
            RollMode::Off => 0,
            RollMode::On => 1,
            RollMode::Forced => 2,
        },
        |m, v| {
            m.p.roll_mode = match v {
                0 => RollMode::Off,
                2 => RollMode::Forced,
                _ => RollMode::On,
            }
        },
    ),
    V::boolean_parameter(
        "course_auto",
        true,
        "Automatic course control (false: manual, the wheel input is the course rudder)",
        |m| m.p.course_auto,
        |m, v| m.p.course_auto = v,
    ),
    V::boolean_parameter(
        "adaptation_enabled",
        true,
        "On-line criterion adaptation of q_phi (eqs. 6.27-6.28)",
        |m| m.p.adaptation.enabled,
        |m, v| m.p.adaptation.enabled = v,
    ),
    V::real_parameter(
        "lambda",
        None,
        true,
        "Course criterion weight lambda of J = E[psi^2]/lambda + E[delta^2] (1 accurate ... 10 economic)",
        |m| m.p.lambda,
        |m, v| m.p.lambda = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "angle_max",
        Some("rad"),
        true,
        "Allowed maximum rudder angle delta_max (operator; 003 RRS gear 22 deg)",
        |m| m.p.angle_max,
        |m, v| m.p.angle_max = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "rate_max",
        Some("rad/s"),
        true,
        "Maximum rudder rate of the steering machine for the AGC (003: 15 deg/s)",
        |m| m.p.rate_max,
        |m, v| m.p.rate_max = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "agc_memory_time",
        Some("s"),
        true,
        "AGC memory forgetting time constant [interpretation; thesis gives none]",
        |m| m.p.agc_memory_time,
        |m, v| m.p.agc_memory_time = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "q_phi_initial",
        None,
        true,
        "Roll weight q_phi (initial value when adaptation is on)",
        |m| m.p.adaptation.q_initial,
        |m, v| m.p.adaptation.q_initial = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "roll_q2",
        None,
        true,
        "Roll-rate weight q2 (realization: 0)",
        |m| m.p.roll_q2,
        |m, v| m.p.roll_q2 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "roll_q3",
        None,
        true,
        "v_delta weight q3 (realization: 0)",
        |m| m.p.roll_q3,
        |m, v| m.p.roll_q3 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "r",
        None,
        true,
        "Rudder weight r",
        |m| m.p.r,
        |m, v| m.p.r = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "alpha",
        Some("1/s"),
        true,
        "Adaptation speed alpha (q_phi moves at most alpha*q_max per second)",
        |m| m.p.adaptation.alpha,
        |m, v| m.p.adaptation.alpha = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "q_max",
        None,
        true,
        "Rule 3: upper limit q_phi(max)",
        |m| m.p.adaptation.q_max,
        |m, v| m.p.adaptation.q_max = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "q_operator",
        None,
        true,
        "Rule 10: operator limit q_phi0 (much/little roll reduction)",
        |m| m.p.adaptation.q_operator,
        |m, v| m.p.adaptation.q_operator = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "roll_variance_target",
        None,
        true,
        "Rule 7: target roll variance sigma_phi^2 [rad^2]",
        |m| m.p.adaptation.roll_variance_target,
        |m, v| m.p.adaptation.roll_variance_target = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "roll_variance_time",
        Some("s"),
        true,
        "Time constant of the roll-variance low-pass (Fig. 6.10)",
        |m| m.p.adaptation.roll_variance_time,
        |m, v| m.p.adaptation.roll_variance_time = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "heading_error_max",
        Some("rad"),
        true,
        "Rule 8: heading-error limit psi_max",
        |m| m.p.adaptation.heading_error_max,
        |m, v| m.p.adaptation.heading_error_max = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "rate_ratio_start",
        None,
        true,
        "Rule 2 breakpoint rho_0 (Delta q2 = 0 below, -1 at required rate = rate_max)",
        |m| m.p.adaptation.rate_ratio_start,
        |m, v| m.p.adaptation.rate_ratio_start = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "angle_ratio_start",
        None,
        true,
        "Rule 6 breakpoint (Delta q6 = 0 below this fraction of angle_max)",
        |m| m.p.adaptation.angle_ratio_start,
        |m, v| m.p.adaptation.angle_ratio_start = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "q_beta",
        None,
        true,
        "Rule 3 breakpoint beta (Delta q3 = 0 below beta*q_max)",
        |m| m.p.adaptation.q_beta,
        |m, v| m.p.adaptation.q_beta = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "min_speed",
        Some("m/s"),
        true,
        "Lowest speed used in the speed laws",
        |m| m.p.min_speed,
        |m, v| m.p.min_speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "max_substep",
        Some("s"),
        true,
        "Largest Euler sub-step of the innovation process",
        |m| m.p.max_substep,
        |m, v| m.p.max_substep = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "innovation_scale",
        None,
        true,
        "Time scaling l of the innovation process (L of eq. 3.15)",
        |m| m.p.innovation_scale,
        |m, v| m.p.innovation_scale = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "k_dp0",
        None,
        false,
        "Speed law k_dp = K_dp0 U^2 (Table 2.4: -0.0014)",
        |m| m.p.laws.k_dp0,
        |m, v| m.p.laws.k_dp0 = v,
    ),
    V::real_parameter(
        "k_dv0",
        None,
        false,
        "k_dv = K_dv0 U (0.01)",
        |m| m.p.laws.k_dv0,
        |m, v| m.p.laws.k_dv0 = v,
    ),
    V::real_parameter(
        "k_dr0",
        None,
        false,
        "k_dr = K_dr0 U (-0.0027)",
        |m| m.p.laws.k_dr0,
        |m, v| m.p.laws.k_dr0 = v,
    ),
    V::real_parameter(
        "k_vp0",
        None,
        false,
        "k_vp = K_vp0 U (0.21)",
        |m| m.p.laws.k_vp0,
        |m, v| m.p.laws.k_vp0 = v,
    ),
    V::real_parameter(
        "t_v0",
        Some("m"),
        false,
        "tau_v = T_v0 / U (78 m)",
        |m| m.p.laws.t_v0,
        |m, v| m.p.laws.t_v0 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "z_n0",
        None,
        false,
        "z_n = z_n0 + z_n1 U (0.064)",
        |m| m.p.laws.z_n0,
        |m, v| m.p.laws.z_n0 = v,
    ),
    V::real_parameter(
        "z_n1",
        None,
        false,
        "z_n1 (0.0038 s/m) [s/m]",
        |m| m.p.laws.z_n1,
        |m, v| m.p.laws.z_n1 = v,
    ),
    V::real_parameter(
        "k_vr0",
        None,
        false,
        "k_vr = K_vr0 (-0.46)",
        |m| m.p.laws.k_vr0,
        |m, v| m.p.laws.k_vr0 = v,
    ),
    V::real_parameter(
        "omega_n0",
        Some("rad/s"),
        false,
        "omega_n (0.63 rad/s)",
        |m| m.p.laws.omega_n0,
        |m, v| m.p.laws.omega_n0 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "t_r0",
        Some("m"),
        false,
        "tau_r = T_r0 / U (13 m)",
        |m| m.p.laws.t_r0,
        |m, v| m.p.laws.t_r0 = v,
    )
    .with_range(Some(0.0), None),
    V::real_input(
        "roll",
        Some("rad"),
        "Roll-filter estimate phi",
        |m| m.inputs.roll,
        |m, v| m.inputs.roll = v,
    ),
    V::real_input(
        "roll_rate",
        Some("rad/s"),
        "Roll-filter estimate d(phi)/dt",
        |m| m.inputs.roll_rate,
        |m, v| m.inputs.roll_rate = v,
    ),
    V::real_input(
        "sway_rudder",
        Some("m/s"),
        "Roll-filter estimate v_delta (sway velocity caused by the rudder)",
        |m| m.inputs.sway_rudder,
        |m, v| m.inputs.sway_rudder = v,
    ),
    V::real_input(
        "heading_error",
        Some("rad"),
        "Yaw-filter heading error psi - psi_ref",
        |m| m.inputs.heading_error,
        |m, v| m.inputs.heading_error = v,
    ),
    V::real_input(
        "yaw_rate",
        Some("rad/s"),
        "Yaw-filter rate of turn",
        |m| m.inputs.yaw_rate,
        |m, v| m.inputs.yaw_rate = v,
    ),
    V::real_input(
        "yaw_offset",
        Some("rad/s"),
        "Yaw-filter offset state x3 (constant yaw disturbance, rate-of-turn units)",
        |m| m.inputs.yaw_offset,
        |m, v| m.inputs.yaw_offset = v,
    ),
    V::real_input(
        "speed",
        Some("m/s"),
        "Speed-filter estimate U",
        |m| m.inputs.speed,
        |m, v| m.inputs.speed = v,
    ),
    V::real_input(
        "wheel",
        Some("rad"),
        "Manual steering wheel rudder (course_auto = false)",
        |m| m.inputs.wheel,
        |m, v| m.inputs.wheel = v,
    ),
    V::real_input(
        "rudder_angle",
        Some("rad"),
        "Measured rudder angle (criterion rule 6)",
        |m| m.inputs.rudder,
        |m, v| m.inputs.rudder = v,
    ),
    V::real_output(
        "rudder_command",
        Some("rad"),
        "Rudder set point delta_g to the steering machine (course + AGC-attenuated roll rudder, limited to angle_max)",
        |m| m.ap.outputs(&m.inputs).rudder_command,
    ),
    V::real_output(
        "roll_rudder",
        Some("rad"),
        "Roll-controller rudder delta_phi = -(k1 phi + k2 phi_dot + k3 v_delta) before the AGC (0 with RRS off)",
        |m| m.ap.outputs(&m.inputs).roll_rudder,
    ),
    V::real_output(
        "course_rudder",
        Some("rad"),
        "Course-controller rudder delta_psi (or the wheel in manual)",
        |m| m.ap.outputs(&m.inputs).course_rudder,
    ),
    V::real_output(
        "attenuation",
        None,
        "AGC attenuation A = rate_max / max(rate_max, |du/dt|, memory), 0 < A <= 1",
        |m| m.ap.outputs(&m.inputs).attenuation,
    ),
    V::real_output(
        "q_phi",
        None,
        "Current roll weight q_phi (criterion adaptation)",
        |m| m.ap.q_phi(),
    ),
    V::real_output(
        "roll_variance",
        None,
        "Low-passed roll variance estimate [rad^2]",
        |m| m.ap.roll_variance(),
    ),
    V::real_output(
        "roll_gain_1",
        None,
        "k1 (rad/rad) from the innovation process at the input speed",
        |m| m.ap.roll_gains(m.inputs.speed)[0],
    ),
    V::real_output(
        "roll_gain_2",
        Some("s"),
        "k2 (rad per rad/s)",
        |m| m.ap.roll_gains(m.inputs.speed)[1],
    ),
    V::real_output(
        "roll_gain_3",
        None,
        "k3 (rad per m/s) [s/m]",
        |m| m.ap.roll_gains(m.inputs.speed)[2],
    ),
    V::real_output(
        "course_gain_1",
        None,
        "Course k1 = sign(k_dr) sqrt(1/lambda)",
        |m| m.ap.course_gains(m.inputs.speed)[0],
    ),
    V::real_output(
        "course_gain_2",
        Some("s"),
        "Course k2 = (sqrt(1 + 2 tau_r k_dr k1) - 1)/k_dr",
        |m| m.ap.course_gains(m.inputs.speed)[1],
    ),
];

impl FmuModel for RrsAutopilotFmu {
    const MODEL_IDENTIFIER: &'static str = "RrsAutopilot";
    const DESCRIPTION: &'static str = "Rudder roll stabilization autopilot (van der Klugt 1987): \
        roll LQ by the innovation process, closed-form course controller, Automatic Gain \
        Controller, criterion adaptation, RRS on/off/forced and manual/automatic modes";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 600.0,
        step_size: 0.1,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.ap = RrsAutopilot::new(self.p).map_err(|e| e.to_string())?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.ap.set_params(self.p).map_err(|e| e.to_string())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.ap.step(&self.inputs, h);
        Ok(())
    }
}

export_fmu!(RrsAutopilotFmu);
