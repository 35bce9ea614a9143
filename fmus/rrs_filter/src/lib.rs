//! `RrsFilter` FMU: the roll, yaw and adaptive speed filters of [Klugt1987, sec. 6.3]
//! (`models::observers::rrs_filter`). No physics here.

use fmi2_export::{passes, FmuModel};
use models::error::check_positive;
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

    /// Yaw parameters with τ_r, k_dr, k_vr, k_dv, τ_v from [Klugt1987, Table 2.4] at the design speed.
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
        check_positive("design_speed", self.design_speed)?;
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

fmi2_export::fmu! {
    RrsFilterFmu => "RrsFilter",
    description: "Roll filter (constant-heel rejection), yaw filter with \
        coloured measurement noise and adaptive noise intensity, adaptive speed filter \
        (van der Klugt 1987, App. E-F, sections 4.4-4.5, 5.5, 6.3)",
    experiment: (0.0, 300.0, 0.1),
    documentation: "documentation.html",
    variables: {
        fixed real "sample_time" ["s"] (sample_time).min(0.0),
            "Filter sample time T of the Euler discretisation ([Klugt1987, eqs. (6.1)-(6.4)]; not given in the thesis); a step h is ceil(h/T) samples";
        tunable real "design_speed" ["m/s"] (design_speed).min(0.0),
            "Ship speed at which the Table 2.4 control model (omega_n, z_n, k_dp, k_vp, k_dv, tau_v, tau_r, k_dr) is evaluated for the filters";
        tunable real "roll_q1" (roll_q[0]).min(0.0),
            "Roll filter q1 = E[w1^2]/E[v^2] (App. E; not given in the thesis)";
        tunable real "roll_q2" (roll_q[1]).min(0.0),
            "Roll filter q2 = E[w2^2]/E[v^2] of the heel-offset drift (App. E; k3 = sqrt(q2))";
        tunable real "yaw_a" (yaw.a).min(0.0),
            "Yaw filter a: tau_f = tau_r / a (reading of eq. 6.7 / L 3116 taken; cut-off a/tau_r rad/s)";
        tunable real "yaw_e_w1" (yaw.e_w1).min(0.0), "Yaw system-noise intensity E[w1^2] (realised: 0.1)";
        tunable real "yaw_e_w2" (yaw.e_w2).min(0.0),
            "Yaw bias-drift intensity E[w2^2] (realised: 0.001 E[w1^2])";
        tunable real "yaw_e_v" (yaw.e_v).min(0.0),
            "White heading measurement-noise intensity E[v^2] (realised: 0.01)";
        tunable real "yaw_e_w3" (yaw.e_w3).min(0.0),
            "High-frequency 'measurement' noise intensity E[w3^2]: fixed value, or start value when adaptive";
        tunable bool "yaw_adaptive" (yaw.adaptive),
            "Adapt E*[w3^2] = E_c / yaw_ec_divisor, E_c = E[z_hf^2]/E[z_lf^2] (eq. 5.12)";
        tunable real "yaw_ec_divisor" (yaw.ec_divisor).min(0.0),
            "Divisor of E_c: 1 as realised (L 3112), 7 as suggested in section 5.5.4 (L 2885)";
        tunable real "yaw_variance_time_constant" ["s"] (yaw.variance_time_constant).min(0.0),
            "Time constant of the low-pass filtered squares estimating E[z_hf^2], E[z_lf^2] (Fig. 5.13 lost; a parameter)";
        tunable bool "yaw_third_order" (yaw.third_order),
            "Include the noise-free rudder->sway submodel (k_vr x1) in the yaw filter (section 4.4.3); false: realised 2nd-order Nomoto model";
        tunable int "speed_adaptation" (speed.adaptation => {
                0: SpeedAdaptation::Constant, 1: SpeedAdaptation::Linear,
                2: SpeedAdaptation::Quadratic, 3: SpeedAdaptation::Switch,
            }),
            "Speed filter law: 0 C (constant), 1 L (realised), 2 Q (best in the study), 3 S (switch) (section 5.5.3)";
        tunable real "speed_c" (speed.c).min(0.0),
            "Speed filter threshold factor c: no adaptation while |e_z| <= c sigma_z (eq. 5.10)";
        tunable real "speed_sigma_z" ["m/s"] (speed.sigma_z).min(0.0),
            "A-priori standard deviation sigma_z of the speed prediction error (realised threshold c sigma_z = 2)";
        tunable real "speed_tau0" ["s"] (speed.tau0).min(0.0),
            "Speed filter time constant tau0 = sqrt(E[v^2]/E[w^2]) (study: 100 s)";
        tunable real "speed_tau_min" ["s"] (speed.tau_min).min(0.0),
            "Smallest speed filter time constant tau_f,min (Q_max = 100 Q: 10 s)";
        fixed real "initial_speed" ["m/s"] (initial_speed), "Initial speed estimate";
        input real "roll_measured" ["rad"] (inputs.roll),
            "Measured roll angle (may contain a constant heel)";
        input real "heading_measured" ["rad"] (inputs.heading), "Measured heading (or heading error)";
        input real "speed_measured" ["m/s"] (inputs.speed), "Measured ship speed";
        input real "roll_rudder" ["rad"] (inputs.roll_rudder),
            "Roll-controller output delta_phi (drives the roll filter, L 1935; not the measured rudder)";
        input real "course_rudder" ["rad"] (inputs.course_rudder),
            "Course-controller output delta_psi (drives the yaw filter, L 1939)";
        output real "roll_estimate" ["rad"] (|m| m.filter.roll.state()[0]),
            "Estimated roll angle, constant heel removed";
        output real "roll_rate_estimate" ["rad/s"] (|m| m.filter.roll.state()[1]), "Estimated roll rate";
        output real "heel_offset_estimate" ["rad"] (|m| m.filter.roll.state()[2]),
            "Estimated constant heel x_v";
        output real "rudder_sway_estimate" (|m| m.filter.roll.state()[3]),
            "Rudder-induced sway v_delta of the noise-free submodel (model scale, K_dv0 = 0.01)";
        output real "roll_innovation" ["rad"] (|m| m.filter.roll.innovation()),
            "Roll prediction error y - (phi_hat + x_v)";
        output real "heading_estimate" ["rad"] (|m| m.filter.yaw.state()[0]),
            "Estimated low-frequency heading";
        output real "yaw_rate_estimate" ["rad/s"] (|m| m.filter.yaw.state()[1]),
            "Estimated low-frequency rate of turn";
        output real "yaw_bias_estimate" ["rad/s"] (|m| m.filter.yaw.state()[2]),
            "Estimated yaw-moment bias x3 (rate-of-turn units)";
        output real "heading_hf_estimate" ["rad"] (|m| m.filter.yaw.state()[3]),
            "Estimated high-frequency heading component x4";
        output real "yaw_innovation" ["rad"] (|m| m.filter.yaw.innovation()),
            "Yaw prediction error z = y - (psi_hat - x4)";
        output real "yaw_e_w3_used" (|m| m.filter.yaw.e_w3()), "E*[w3^2] in use";
        output real "yaw_e_c" (|m| m.filter.yaw.e_c()), "E_c = E[z_hf^2]/E[z_lf^2] (eq. 5.12)";
        output real "yaw_k1" ["1/s"] (|m| m.filter.yaw.gains()[0]),
            "Yaw filter gain k1 (innovation process)";
        output real "yaw_k2" (|m| m.filter.yaw.gains()[1]), "Yaw filter gain k2";
        output real "yaw_k3" (|m| m.filter.yaw.gains()[2]), "Yaw filter gain k3";
        output real "yaw_k4" ["1/s"] (|m| m.filter.yaw.gains()[3]), "Yaw filter gain k4";
        output real "roll_k1" ["1/s"] (|m| m.filter.roll.gains()[0]), "Roll filter gain k1 (fixed)";
        output real "roll_k2" (|m| m.filter.roll.gains()[1]), "Roll filter gain k2";
        output real "roll_k3" ["1/s"] (|m| m.filter.roll.gains()[2]), "Roll filter gain k3 = sqrt(q2)";
        output real "speed_estimate" ["m/s"] (|m| m.filter.speed.estimate()), "Filtered speed U_hat";
        output real "speed_time_constant" ["s"] (|m| m.filter.speed.time_constant()),
            "Speed filter time constant tau_f of the last sample";
        output real "speed_innovation" ["m/s"] (|m| m.filter.speed.innovation()),
            "Speed prediction error e_z = U_meas - U_hat";
    }
}

impl FmuModel for RrsFilterFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.filter = self.build()?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        check_positive("design_speed", self.design_speed)?;
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

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let dt = self.filter.sample_time;
        each("sample_time", dt, passes(h, dt));
    }
}
