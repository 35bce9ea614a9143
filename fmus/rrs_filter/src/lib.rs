//! `RrsFilter` FMU: van der Klugt's roll, yaw and adaptive speed filters
//! (`models::observers::rrs_filter`). No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::observers::rrs_filter::{
    RollFilter, RollFilterParams, RrsFilter, RrsFilterInputs, SpeedAdaptation, SpeedFilter,
    SpeedFilterParams, YawFilterParams,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and filters of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RrsFilterFmu {
    sample_time: f64,
    design_speed: f64,
    roll_q: [f64; 2],
    yaw: YawFilterParams,
    speed: SpeedFilterParams,
    initial_speed: f64,
    inputs: RrsFilterInputs,
    filter: RrsFilter,
}

impl RrsFilterFmu {
    fn roll_params(&self) -> RollFilterParams {
        RollFilterParams::table_2_4(self.design_speed, self.roll_q[0], self.roll_q[1])
    }

    /// Yaw parameters with τ_r, k_dr, k_vr, k_dv, τ_v from Table 2.4 at the design speed.
    fn yaw_params(&self) -> YawFilterParams {
        let base = YawFilterParams::realised(self.design_speed);
        YawFilterParams {
            tau_r: base.tau_r,
            k_dr: base.k_dr,
            k_vr: base.k_vr,
            k_dv: base.k_dv,
            tau_v: base.tau_v,
            ..self.yaw
        }
    }

    fn build(&self) -> Result<RrsFilter, String> {
        if !(self.design_speed > 0.0) {
            return Err(format!("design_speed = {} must be > 0", self.design_speed));
        }
        RrsFilter::new(
            self.roll_params(),
            self.yaw_params(),
            self.speed,
            self.sample_time,
            self.initial_speed,
        )
    }
}

impl Default for RrsFilterFmu {
    fn default() -> Self {
        let mut m = RrsFilterFmu {
            sample_time: 0.1,
            design_speed: 11.0,
            roll_q: [10.0, 0.001],
            yaw: YawFilterParams::realised(11.0),
            speed: SpeedFilterParams::realised(),
            initial_speed: 11.0,
            inputs: RrsFilterInputs::default(),
            filter: RrsFilter::new(
                RollFilterParams::table_2_4(11.0, 10.0, 0.001),
                YawFilterParams::realised(11.0),
                SpeedFilterParams::realised(),
                0.1,
                11.0,
            )
            .expect("preset"),
        };
        m.inputs.speed = m.initial_speed;
        m
    }
}

type V = Variable<RrsFilterFmu>;

static VARIABLES: [V; 46] = [
    V::real_parameter(
        "sample_time",
        Some("s"),
        false,
        "Filter sample time T of the Euler discretisation (003 eqs. 6.1-6.4; not given in the thesis); a step h is ceil(h/T) samples",
        |m| m.sample_time,
        |m, v| m.sample_time = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "design_speed",
        Some("m/s"),
        true,
        "Ship speed at which the Table 2.4 control model (omega_n, z_n, k_dp, k_vp, k_dv, tau_v, tau_r, k_dr) is evaluated for the filters",
        |m| m.design_speed,
        |m, v| m.design_speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "roll_q1",
        None,
        true,
        "Roll filter q1 = E[w1^2]/E[v^2] (App. E; not given in the thesis)",
        |m| m.roll_q[0],
        |m, v| m.roll_q[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "roll_q2",
        None,
        true,
        "Roll filter q2 = E[w2^2]/E[v^2] of the heel-offset drift (App. E; k3 = sqrt(q2))",
        |m| m.roll_q[1],
        |m, v| m.roll_q[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "yaw_a",
        None,
        true,
        "Yaw filter a: tau_f = tau_r / a (reading of eq. 6.7 / L 3116 taken; cut-off a/tau_r rad/s)",
        |m| m.yaw.a,
        |m, v| m.yaw.a = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "yaw_e_w1",
        None,
        true,
        "Yaw system-noise intensity E[w1^2] (realised: 0.1)",
        |m| m.yaw.e_w1,
        |m, v| m.yaw.e_w1 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "yaw_e_w2",
        None,
        true,
        "Yaw bias-drift intensity E[w2^2] (realised: 0.001 E[w1^2])",
        |m| m.yaw.e_w2,
        |m, v| m.yaw.e_w2 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "yaw_e_v",
        None,
        true,
        "White heading measurement-noise intensity E[v^2] (realised: 0.01)",
        |m| m.yaw.e_v,
        |m, v| m.yaw.e_v = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "yaw_e_w3",
        None,
        true,
        "High-frequency 'measurement' noise intensity E[w3^2]: fixed value, or start value when adaptive",
        |m| m.yaw.e_w3,
        |m, v| m.yaw.e_w3 = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "yaw_adaptive",
        true,
        "Adapt E*[w3^2] = E_c / yaw_ec_divisor, E_c = E[z_hf^2]/E[z_lf^2] (eq. 5.12)",
        |m| m.yaw.adaptive,
        |m, v| m.yaw.adaptive = v,
    ),
    V::real_parameter(
        "yaw_ec_divisor",
        None,
        true,
        "Divisor of E_c: 1 as realised (L 3112), 7 as suggested in section 5.5.4 (L 2885)",
        |m| m.yaw.ec_divisor,
        |m, v| m.yaw.ec_divisor = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "yaw_variance_time_constant",
        Some("s"),
        true,
        "Time constant of the low-pass filtered squares estimating E[z_hf^2], E[z_lf^2] (Fig. 5.13 lost; a parameter)",
        |m| m.yaw.variance_time_constant,
        |m, v| m.yaw.variance_time_constant = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "yaw_third_order",
        true,
        "Include the noise-free rudder->sway submodel (k_vr x1) in the yaw filter (section 4.4.3); false: realised 2nd-order Nomoto model",
        |m| m.yaw.third_order,
        |m, v| m.yaw.third_order = v,
    ),
    V::integer_parameter(
        "speed_adaptation",
        true,
        "Speed filter law: 0 C (constant), 1 L (realised), 2 Q (best in the study), 3 S (switch) (section 5.5.3)",
        0,
        3,
        |m| m.speed.adaptation.index(),
        |m, v| m.speed.adaptation = SpeedAdaptation::from_index(v).unwrap_or(SpeedAdaptation::Linear),
    ),
    V::real_parameter(
        "speed_c",
        None,
        true,
        "Speed filter threshold factor c: no adaptation while |e_z| <= c sigma_z (eq. 5.10)",
        |m| m.speed.c,
        |m, v| m.speed.c = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "speed_sigma_z",
        Some("m/s"),
        true,
        "A-priori standard deviation sigma_z of the speed prediction error (realised threshold c sigma_z = 2)",
        |m| m.speed.sigma_z,
        |m, v| m.speed.sigma_z = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "speed_tau0",
        Some("s"),
        true,
        "Speed filter time constant tau0 = sqrt(E[v^2]/E[w^2]) (study: 100 s)",
        |m| m.speed.tau0,
        |m, v| m.speed.tau0 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "speed_tau_min",
        Some("s"),
        true,
        "Smallest speed filter time constant tau_f,min (Q_max = 100 Q: 10 s)",
        |m| m.speed.tau_min,
        |m, v| m.speed.tau_min = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "initial_speed",
        Some("m/s"),
        false,
        "Initial speed estimate",
        |m| m.initial_speed,
        |m, v| m.initial_speed = v,
    ),
    V::real_input(
        "roll_measured",
        Some("rad"),
        "Measured roll angle (may contain a constant heel)",
        |m| m.inputs.roll,
        |m, v| m.inputs.roll = v,
    ),
    V::real_input(
        "heading_measured",
        Some("rad"),
        "Measured heading (or heading error)",
        |m| m.inputs.heading,
        |m, v| m.inputs.heading = v,
    ),
    V::real_input(
        "speed_measured",
        Some("m/s"),
        "Measured ship speed",
        |m| m.inputs.speed,
        |m, v| m.inputs.speed = v,
    ),
    V::real_input(
        "roll_rudder",
        Some("rad"),
        "Roll-controller output delta_phi (drives the roll filter, L 1935; not the measured rudder)",
        |m| m.inputs.roll_rudder,
        |m, v| m.inputs.roll_rudder = v,
    ),
    V::real_input(
        "course_rudder",
        Some("rad"),
        "Course-controller output delta_psi (drives the yaw filter, L 1939)",
        |m| m.inputs.course_rudder,
        |m, v| m.inputs.course_rudder = v,
    ),
    V::real_output(
        "roll_estimate",
        Some("rad"),
        "Estimated roll angle, constant heel removed",
        |m| m.filter.roll.state()[0],
    ),
    V::real_output(
        "roll_rate_estimate",
        Some("rad/s"),
        "Estimated roll rate",
        |m| m.filter.roll.state()[1],
    ),
    V::real_output(
        "heel_offset_estimate",
        Some("rad"),
        "Estimated constant heel x_v",
        |m| m.filter.roll.state()[2],
    ),
    V::real_output(
        "rudder_sway_estimate",
        None,
        "Rudder-induced sway v_delta of the noise-free submodel (model scale, K_dv0 = 0.01)",
        |m| m.filter.roll.state()[3],
    ),
    V::real_output(
        "roll_innovation",
        Some("rad"),
        "Roll prediction error y - (phi_hat + x_v)",
        |m| m.filter.roll.innovation(),
    ),
    V::real_output(
        "heading_estimate",
        Some("rad"),
        "Estimated low-frequency heading",
        |m| m.filter.yaw.state()[0],
    ),
    V::real_output(
        "yaw_rate_estimate",
        Some("rad/s"),
        "Estimated low-frequency rate of turn",
        |m| m.filter.yaw.state()[1],
    ),
    V::real_output(
        "yaw_bias_estimate",
        Some("rad/s"),
        "Estimated yaw-moment bias x3 (rate-of-turn units)",
        |m| m.filter.yaw.state()[2],
    ),
    V::real_output(
        "heading_hf_estimate",
        Some("rad"),
        "Estimated high-frequency heading component x4",
        |m| m.filter.yaw.state()[3],
    ),
    V::real_output(
        "yaw_innovation",
        Some("rad"),
        "Yaw prediction error z = y - (psi_hat - x4)",
        |m| m.filter.yaw.innovation(),
    ),
    V::real_output(
        "yaw_e_w3_used",
        None,
        "E*[w3^2] in use",
        |m| m.filter.yaw.e_w3(),
    ),
    V::real_output(
        "yaw_e_c",
        None,
        "E_c = E[z_hf^2]/E[z_lf^2] (eq. 5.12)",
        |m| m.filter.yaw.e_c(),
    ),
    V::real_output(
        "yaw_k1",
        Some("1/s"),
        "Yaw filter gain k1 (innovation process)",
        |m| m.filter.yaw.gains()[0],
    ),
    V::real_output(
        "yaw_k2",
        None,
        "Yaw filter gain k2",
        |m| m.filter.yaw.gains()[1],
    ),
    V::real_output(
        "yaw_k3",
        None,
        "Yaw filter gain k3",
        |m| m.filter.yaw.gains()[2],
    ),
    V::real_output(
        "yaw_k4",
        Some("1/s"),
        "Yaw filter gain k4",
        |m| m.filter.yaw.gains()[3],
    ),
    V::real_output(
        "roll_k1",
        Some("1/s"),
        "Roll filter gain k1 (fixed)",
        |m| m.filter.roll.gains()[0],
    ),
    V::real_output(
        "roll_k2",
        None,
        "Roll filter gain k2",
        |m| m.filter.roll.gains()[1],
    ),
    V::real_output(
        "roll_k3",
        Some("1/s"),
        "Roll filter gain k3 = sqrt(q2)",
        |m| m.filter.roll.gains()[2],
    ),
    V::real_output(
        "speed_estimate",
        Some("m/s"),
        "Filtered speed U_hat",
        |m| m.filter.speed.estimate(),
    ),
    V::real_output(
        "speed_time_constant",
        Some("s"),
        "Speed filter time constant tau_f of the last sample",
        |m| m.filter.speed.time_constant(),
    ),
    V::real_output(
        "speed_innovation",
        Some("m/s"),
        "Speed prediction error e_z = U_meas - U_hat",
        |m| m.filter.speed.innovation(),
    ),
];

impl FmuModel for RrsFilterFmu {
    const MODEL_IDENTIFIER: &'static str = "RrsFilter";
    const DESCRIPTION: &'static str = "Roll filter (constant-heel rejection), yaw filter with \
        coloured measurement noise and adaptive noise intensity, adaptive speed filter \
        (van der Klugt 1987, App. E-F, sections 4.4-4.5, 5.5, 6.3)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 300.0,
        step_size: 0.1,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.filter = self.build()?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        if !(self.design_speed > 0.0) {
            return Err(format!("design_speed = {} must be > 0", self.design_speed));
        }
        let roll_params = self.roll_params();
        if roll_params != *self.filter.roll.params() {
            let mut roll = RollFilter::new(roll_params)?;
            roll.set_state(self.filter.roll.state());
            self.filter.roll = roll;
        }
        self.filter.yaw.set_params(self.yaw_params())?;
        if self.speed != self.filter.speed.params {
            let mut s = SpeedFilter::new(self.speed, self.filter.speed.estimate())?;
            s.set_estimate(self.filter.speed.estimate());
            self.filter.speed = s;
        }
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.filter.step(&self.inputs, h);
        Ok(())
    }
}

export_fmu!(RrsFilterFmu);
