//! `RrsAutopilot` FMU: the rudder roll stabilization autopilot of [Klugt1987]
//! in `models::controllers::rrs` (roll LQ via the innovation process, closed-form course
//! controller, AGC, criterion adaptation, operator modes) as an FMI 2.0 co-simulation FMU. No
//! physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::controllers::rrs::{
    AgcTarget, RollMode, RrsAutopilot, RrsAutopilotParams, RrsInputs, RrsOutputs,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one autopilot instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RrsAutopilotFmu {
    params: RrsAutopilotParams,
    inputs: RrsInputs,
    autopilot: RrsAutopilot,
    /// `autopilot.outputs(&inputs)`, computed once wherever the autopilot or its inputs change
    /// (initialize, parameters_changed, calculate_outputs, do_step) instead of in each of the
    /// four getters that read it; `None` (after a deserialized restore) means compute it. Not
    /// part of the state.
    #[serde(skip)]
    outputs: Option<RrsOutputs>,
}

impl RrsAutopilotFmu {
    fn out(&self) -> RrsOutputs {
        self.outputs
            .unwrap_or_else(|| self.autopilot.outputs(&self.inputs))
    }

    fn keep_outputs(&mut self) {
        self.outputs = Some(self.autopilot.outputs(&self.inputs));
    }
}

impl Default for RrsAutopilotFmu {
    fn default() -> Self {
        let params = RrsAutopilotParams::default();
        RrsAutopilotFmu {
            inputs: RrsInputs {
                speed: 11.0,
                ..RrsInputs::default()
            },
            autopilot: RrsAutopilot::new(params).expect("default parameters are valid"),
            params,
            outputs: None,
        }
    }
}

fmi2_export::fmu! {
    RrsAutopilotFmu => "RrsAutopilot",
    description: "Rudder roll stabilization autopilot (van der Klugt 1987): \
        roll LQ by the innovation process, closed-form course controller, Automatic Gain \
        Controller, criterion adaptation, RRS on/off/forced and manual/automatic modes",
    experiment: (0.0, 600.0, 0.1),
    documentation: "documentation.html",
    variables: {
        tunable bool "agc_enabled" (params.agc_enabled),
            "Automatic Gain Controller on ([Klugt1987, sec. 5.3])";
        tunable int "agc_target" (params.agc_target => { 1: AgcTarget::Total, 2: AgcTarget::RollOnly }),
            "1: A*(delta_psi + delta_phi) (literal Fig. 5.5); 2: delta_psi + A*delta_phi (default, course changes do not attenuate the course loop)";
        tunable int "roll_mode" (params.roll_mode => { 0: RollMode::Off, 1: RollMode::On, 2: RollMode::Forced }),
            "Roll stabilisation 0 OFF (gains computed, not applied: course only), 1 ON, 2 forced roll (inverted roll feedback) [operator]";
        tunable bool "course_auto" (params.course_auto),
            "Automatic course control (false: manual, the wheel input is the course rudder)";
        tunable bool "adaptation_enabled" (params.adaptation.enabled),
            "On-line criterion adaptation of q_phi (eqs. 6.27-6.28)";
        tunable real "lambda" (params.lambda).min(0.0),
            "Course criterion weight lambda of J = E[psi^2]/lambda + E[delta^2] (1 accurate ... 10 economic)";
        tunable real "angle_max" ["rad"] (params.angle_max).min(0.0),
            "Allowed maximum rudder angle delta_max (operator; the RRS gear of [Klugt1987]: 22 deg)";
        tunable real "rate_max" ["rad/s"] (params.rate_max).min(0.0),
            "Maximum rudder rate of the steering machine for the AGC ([Klugt1987]: 15 deg/s)";
        tunable real "agc_memory_time" ["s"] (params.agc_memory_time).min(0.0),
            "AGC memory forgetting time constant [interpretation; thesis gives none]";
        tunable real "q_phi_initial" (params.adaptation.q_initial).min(0.0),
            "Roll weight q_phi (initial value when adaptation is on)";
        tunable real "roll_q2" (params.roll_q2).min(0.0), "Roll-rate weight q2 (realization: 0)";
        tunable real "roll_q3" (params.roll_q3).min(0.0), "v_delta weight q3 (realization: 0)";
        tunable real "r" (params.r).min(0.0), "Rudder weight r";
        tunable real "alpha" ["1/s"] (params.adaptation.alpha).min(0.0),
            "Adaptation speed alpha (q_phi moves at most alpha*q_max per second)";
        tunable real "q_max" (params.adaptation.q_max).min(0.0), "Rule 3: upper limit q_phi(max)";
        tunable real "q_operator" (params.adaptation.q_operator).min(0.0),
            "Rule 10: operator limit q_phi0 (much/little roll reduction)";
        tunable real "roll_variance_target" (params.adaptation.roll_variance_target).min(0.0),
            "Rule 7: target roll variance sigma_phi^2 [rad^2]";
        tunable real "roll_variance_time" ["s"] (params.adaptation.roll_variance_time).min(0.0),
            "Time constant of the roll-variance low-pass (Fig. 6.10)";
        tunable real "heading_error_max" ["rad"] (params.adaptation.heading_error_max).min(0.0),
            "Rule 8: heading-error limit psi_max";
        tunable real "rate_ratio_start" (params.adaptation.rate_ratio_start).min(0.0),
            "Rule 2 breakpoint rho_0 (Delta q2 = 0 below, -1 at required rate = rate_max)";
        tunable real "angle_ratio_start" (params.adaptation.angle_ratio_start).min(0.0),
            "Rule 6 breakpoint (Delta q6 = 0 below this fraction of angle_max)";
        tunable real "q_beta" (params.adaptation.q_beta).min(0.0),
            "Rule 3 breakpoint beta (Delta q3 = 0 below beta*q_max)";
        tunable real "min_speed" ["m/s"] (params.min_speed).min(0.0),
            "Lowest speed used in the speed laws";
        tunable real "max_substep" ["s"] (params.max_substep).min(0.0),
            "Largest Euler sub-step of the innovation process";
        tunable real "innovation_scale" (params.innovation_scale).min(0.0),
            "Time scaling l of the innovation process (L of eq. 3.15)";
        fixed real "k_dp0" (params.laws.k_dp0), "Speed law k_dp = K_dp0 U^2 (Table 2.4: -0.0014)";
        fixed real "k_dv0" (params.laws.k_dv0), "k_dv = K_dv0 U (0.01)";
        fixed real "k_dr0" (params.laws.k_dr0), "k_dr = K_dr0 U (-0.0027)";
        fixed real "k_vp0" (params.laws.k_vp0), "k_vp = K_vp0 U (0.21)";
        // min 1 m: T_v0 = 0 gives a NaN rudder command, T_v0 <= 0.1 m NaN roll gains within
        // 2 s (issue 19); 1 m is 1.3 % of Table 2.4's 78 m.
        fixed real "t_v0" ["m"] (params.laws.t_v0).min(1.0), "tau_v = T_v0 / U (78 m)";
        fixed real "z_n0" (params.laws.z_n0), "z_n = z_n0 + z_n1 U (0.064)";
        fixed real "z_n1" (params.laws.z_n1), "z_n1 (0.0038 s/m) [s/m]";
        fixed real "k_vr0" (params.laws.k_vr0), "k_vr = K_vr0 (-0.46)";
        fixed real "omega_n0" ["rad/s"] (params.laws.omega_n0).min(0.0), "omega_n (0.63 rad/s)";
        fixed real "t_r0" ["m"] (params.laws.t_r0).min(0.0), "tau_r = T_r0 / U (13 m)";
        input real "roll" ["rad"] (inputs.roll), "Roll-filter estimate phi";
        input real "roll_rate" ["rad/s"] (inputs.roll_rate), "Roll-filter estimate d(phi)/dt";
        input real "sway_rudder" ["m/s"] (inputs.sway_rudder),
            "Roll-filter estimate v_delta (sway velocity caused by the rudder)";
        input real "heading_error" ["rad"] (inputs.heading_error),
            "Yaw-filter heading error psi - psi_ref";
        input real "yaw_rate" ["rad/s"] (inputs.yaw_rate), "Yaw-filter rate of turn";
        input real "yaw_offset" ["rad/s"] (inputs.yaw_offset),
            "Yaw-filter offset state x3 (constant yaw disturbance, rate-of-turn units)";
        input real "speed" ["m/s"] (inputs.speed), "Speed-filter estimate U";
        input real "wheel" ["rad"] (inputs.wheel),
            "Manual steering wheel rudder (course_auto = false)";
        input real "rudder_angle" ["rad"] (inputs.rudder),
            "Measured rudder angle (criterion rule 6)";
        output real "rudder_command" ["rad"] (|m| m.out().rudder_command),
            "Rudder set point delta_g to the steering machine (course + AGC-attenuated roll rudder, limited to angle_max)";
        output real "roll_rudder" ["rad"] (|m| m.out().roll_rudder),
            "Roll-controller rudder delta_phi = -(k1 phi + k2 phi_dot + k3 v_delta) before the AGC (0 with RRS off)";
        output real "course_rudder" ["rad"] (|m| m.out().course_rudder),
            "Course-controller rudder delta_psi (or the wheel in manual)";
        output real "attenuation" (|m| m.out().attenuation),
            "AGC attenuation A = rate_max / max(rate_max, |du/dt|, memory), 0 < A <= 1";
        output real "q_phi" (|m| m.autopilot.q_phi()), "Current roll weight q_phi (criterion adaptation)";
        output real "roll_variance" (|m| m.autopilot.roll_variance()),
            "Low-passed roll variance estimate [rad^2]";
        output real "roll_gain_1" (|m| m.autopilot.roll_gains(m.inputs.speed)[0]),
            "k1 (rad/rad) from the innovation process at the input speed";
        output real "roll_gain_2" ["s"] (|m| m.autopilot.roll_gains(m.inputs.speed)[1]),
            "k2 (rad per rad/s)";
        output real "roll_gain_3" (|m| m.autopilot.roll_gains(m.inputs.speed)[2]),
            "k3 (rad per m/s) [s/m]";
        output real "course_gain_1" (|m| m.autopilot.course_gains(m.inputs.speed)[0]),
            "Course k1 = sign(k_dr) sqrt(1/lambda)";
        output real "course_gain_2" ["s"] (|m| m.autopilot.course_gains(m.inputs.speed)[1]),
            "Course k2 = (sqrt(1 + 2 tau_r k_dr k1) - 1)/k_dr";
    }
}

impl FmuModel for RrsAutopilotFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.outputs = None;
        self.autopilot = RrsAutopilot::new(self.params).map_err(|e| e.to_string())?;
        self.keep_outputs();
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        let changed = self.autopilot.set_params(self.params);
        self.keep_outputs();
        changed.map_err(|e| e.to_string())
    }

    fn calculate_outputs(&mut self) {
        self.keep_outputs();
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.autopilot.step(&self.inputs, h);
        self.keep_outputs();
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let max_substep = self.autopilot.params.max_substep;
        each("max_substep", max_substep, passes(h, max_substep));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fmi2_export::testing::real_of as output;
    use models::math::{cos, sin};

    /// The four outputs read from the kept outputs equal `RrsAutopilot::outputs` for the
    /// current inputs bit for bit: before the first sample (where they follow the inputs, kept
    /// by `calculate_outputs`), after each step, after a parameter change, and when nothing is
    /// kept (a deserialized state).
    #[test]
    fn outputs_from_the_kept_outputs_equal_the_model() {
        let mut m = RrsAutopilotFmu::default();
        m.initialize(0.0).unwrap();
        let check = |m: &RrsAutopilotFmu, at: &str| {
            let o = m.autopilot.outputs(&m.inputs);
            for (name, want) in [
                ("rudder_command", o.rudder_command),
                ("roll_rudder", o.roll_rudder),
                ("course_rudder", o.course_rudder),
                ("attenuation", o.attenuation),
            ] {
                assert_eq!(output(m, name).to_bits(), want.to_bits(), "{name} {at}");
            }
            let mut restored = m.clone();
            restored.outputs = None;
            for name in [
                "rudder_command",
                "roll_rudder",
                "course_rudder",
                "attenuation",
            ] {
                assert_eq!(
                    output(&restored, name).to_bits(),
                    output(m, name).to_bits(),
                    "{name} {at}, restored"
                );
            }
        };
        check(&m, "initialized");
        // before the first sample the outputs are the control law at the current inputs
        m.inputs.roll = 0.05;
        m.inputs.heading_error = -0.02;
        m.calculate_outputs();
        check(&m, "inputs set");
        // (the roll gains start at 0: the innovation process starts from P = 0)
        assert!(m.out().course_rudder != 0.0 && m.out().rudder_command != 0.0);
        let mut commands = Vec::new();
        for k in 0..300 {
            let t = 0.1 * k as f64;
            m.inputs.roll = 0.1 * sin(0.63 * t);
            m.inputs.roll_rate = 0.063 * cos(0.63 * t);
            m.inputs.heading_error = 0.02 * sin(0.05 * t);
            m.calculate_outputs();
            check(&m, &format!("step {k}, inputs set"));
            m.do_step(t, 0.1).unwrap();
            check(&m, &format!("step {k}"));
            commands.push(m.out().rudder_command);
            if k == 150 {
                m.params.angle_max = 0.2;
                m.parameters_changed().unwrap();
                check(&m, "angle_max changed");
            }
        }
        // the held outputs change from sample to sample, the roll rudder among them
        assert!(commands.windows(2).filter(|w| w[0] != w[1]).count() > 250);
        assert!(m.out().roll_rudder != 0.0);
    }
}
