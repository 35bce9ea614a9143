//! `PassiveObserver` FMU: the nonlinear passive DP observer of [Fossen1999] with wave filtering and
//! bias estimation (`models::observers::passive_observer`). No physics here.

use fmi2_export::{passes, FmuModel};
use models::observers::passive_observer::{Injection, PassiveObserver, PassiveObserverParams};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and observer of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PassiveObserverFmu {
    params: PassiveObserverParams,
    initial_estimate: [f64; 3],
    measured: [f64; 3],
    thrust: [f64; 3],
    observer: PassiveObserver,
}

impl Default for PassiveObserverFmu {
    fn default() -> Self {
        let params = PassiveObserverParams::northern_clipper();
        PassiveObserverFmu {
            observer: PassiveObserver::new(params.clone(), [0.0; 3]).expect("preset"),
            params,
            initial_estimate: [0.0; 3],
            measured: [0.0; 3],
            thrust: [0.0; 3],
        }
    }
}

fmi2_export::fmu! {
    PassiveObserverFmu => "PassiveObserver",
    description: "Nonlinear passive observer for dynamic positioning with \
        wave filtering and bias estimation (Fossen & Strand 1999), Northern Clipper preset",
    experiment: (0.0, 1000.0, 1.0),
    documentation: "documentation.html",
    variables: {
        fixed real "mass_surge" ["kg"] (params.m[0][0]).min(0.0),
            "M11 of the observer model (Northern Clipper eq. 56; SI)";
        fixed real "mass_sway" ["kg"] (params.m[1][1]).min(0.0),
            "M22 of the observer model (Northern Clipper eq. 56; SI)";
        fixed real "inertia_yaw" (params.m[2][2]).min(0.0),
            "M33 of the observer model (Northern Clipper eq. 56; SI)";
        fixed real "damping_surge" (params.d[0][0]), "D11 of the observer model (eq. 57; SI)";
        fixed real "damping_sway" (params.d[1][1]), "D22 of the observer model (eq. 57; SI)";
        fixed real "damping_sway_yaw" (params.d[1][2]), "D23 of the observer model (eq. 57; SI)";
        fixed real "damping_yaw_sway" (params.d[2][1]), "D32 of the observer model (eq. 57; SI)";
        fixed real "damping_yaw" (params.d[2][2]), "D33 of the observer model (eq. 57; SI)";
        tunable real "bias_time_constant_surge" ["s"] (params.t_bias[0]).min(0.0),
            "Bias time constant T (surge; eq. 58: 1000 s)";
        tunable real "bias_time_constant_sway" ["s"] (params.t_bias[1]).min(0.0),
            "Bias time constant T (sway; eq. 58: 1000 s)";
        tunable real "bias_time_constant_yaw" ["s"] (params.t_bias[2]).min(0.0),
            "Bias time constant T (yaw; eq. 58: 1000 s)";
        tunable real "wave_frequency_surge" ["rad/s"] (params.omega0[0]).min(0.0),
            "Dominant wave (encounter) frequency omega0 (surge; 0.8976 rad/s = 7 s); tunable for gain scheduling (Remark 2)";
        tunable real "wave_frequency_sway" ["rad/s"] (params.omega0[1]).min(0.0),
            "Dominant wave (encounter) frequency omega0 (sway; 0.8976 rad/s = 7 s); tunable for gain scheduling (Remark 2)";
        tunable real "wave_frequency_yaw" ["rad/s"] (params.omega0[2]).min(0.0),
            "Dominant wave (encounter) frequency omega0 (yaw; 0.8976 rad/s = 7 s); tunable for gain scheduling (Remark 2)";
        tunable real "wave_damping_surge" (params.zeta[0]).min(0.0),
            "Relative damping zeta of the WF model (surge; 0.1)";
        tunable real "wave_damping_sway" (params.zeta[1]).min(0.0),
            "Relative damping zeta of the WF model (sway; 0.1)";
        tunable real "wave_damping_yaw" (params.zeta[2]).min(0.0),
            "Relative damping zeta of the WF model (yaw; 0.1)";
        tunable real "notch_damping_surge" (params.zeta_n[0]).min(0.0), "Notch damping zeta_n (surge; 1.0)";
        tunable real "notch_damping_sway" (params.zeta_n[1]).min(0.0), "Notch damping zeta_n (sway; 1.0)";
        tunable real "notch_damping_yaw" (params.zeta_n[2]).min(0.0), "Notch damping zeta_n (yaw; 1.0)";
        tunable real "cutoff_frequency_surge" ["rad/s"] (params.omega_c[0]).min(0.0),
            "Filter cut-off omega_c (surge; 1.1 rad/s); K2 = omega_c";
        tunable real "cutoff_frequency_sway" ["rad/s"] (params.omega_c[1]).min(0.0),
            "Filter cut-off omega_c (sway; 1.1 rad/s); K2 = omega_c";
        tunable real "cutoff_frequency_yaw" ["rad/s"] (params.omega_c[2]).min(0.0),
            "Filter cut-off omega_c (yaw; 1.1 rad/s); K2 = omega_c";
        tunable real "kappa_surge" (params.kappa[0]).min(0.0),
            "Velocity injection gain kappa (surge; 0.1, 0.1, 0.01)";
        tunable real "kappa_sway" (params.kappa[1]).min(0.0),
            "Velocity injection gain kappa (sway; 0.1, 0.1, 0.01)";
        tunable real "kappa_yaw" (params.kappa[2]).min(0.0),
            "Velocity injection gain kappa (yaw; 0.1, 0.1, 0.01)";
        tunable real "lambda_surge" (params.lambda[0]).min(0.0),
            "Bias injection gain lambda (surge; Lambda = 0.1 K: 0.01, 0.01, 0.001)";
        tunable real "lambda_sway" (params.lambda[1]).min(0.0),
            "Bias injection gain lambda (sway; Lambda = 0.1 K: 0.01, 0.01, 0.001)";
        tunable real "lambda_yaw" (params.lambda[2]).min(0.0),
            "Bias injection gain lambda (yaw; Lambda = 0.1 K: 0.01, 0.01, 0.001)";
        tunable real "gamma" (params.gamma).min(0.0), "Lyapunov scaling gamma (1)";
        tunable int "injection" (params.injection => { 1: Injection::Literal, 2: Injection::MassNormalised }),
            "1: eq. 25 literally with SI M, D (bias in N, N.m; the paper's gains then give almost no velocity/bias injection); 2: injection as an acceleration, bias state in m/s2 (normalised-model reading, default)";
        fixed real "max_substep" ["s"] (params.max_substep).min(0.0), "Largest RK4 sub-step";
        fixed real "initial_north" ["m"] (initial_estimate[0]), "Initial LF position/heading estimate";
        fixed real "initial_east" ["m"] (initial_estimate[1]), "Initial LF position/heading estimate";
        fixed real "initial_heading" ["rad"] (initial_estimate[2]), "Initial LF position/heading estimate";
        input real "north_measured" ["m"] (measured[0]), "Measured north position y1 = x + WF motion (DGPS)";
        input real "east_measured" ["m"] (measured[1]), "Measured east position y2";
        input real "heading_measured" ["rad"] (measured[2]), "Measured heading y3 (gyrocompass)";
        input real "tau_surge" ["N"] (thrust[0]), "Commanded thrust surge (body frame)";
        input real "tau_sway" ["N"] (thrust[1]), "Commanded thrust sway (body frame)";
        input real "tau_yaw" ["N.m"] (thrust[2]), "Commanded thrust yaw (body frame)";
        output real "north_estimate" ["m"] (|m| m.observer.eta()[0]),
            "LF estimate eta_hat (wave-frequency motion removed)";
        output real "east_estimate" ["m"] (|m| m.observer.eta()[1]),
            "LF estimate eta_hat (wave-frequency motion removed)";
        output real "heading_estimate" ["rad"] (|m| m.observer.eta()[2]),
            "LF estimate eta_hat (wave-frequency motion removed)";
        output real "surge_velocity_estimate" ["m/s"] (|m| m.observer.nu()[0]),
            "LF velocity estimate nu_hat (body)";
        output real "sway_velocity_estimate" ["m/s"] (|m| m.observer.nu()[1]),
            "LF velocity estimate nu_hat (body)";
        output real "yaw_rate_estimate" ["rad/s"] (|m| m.observer.nu()[2]),
            "LF velocity estimate nu_hat (body)";
        output real "north_wf_estimate" ["m"] (|m| m.observer.eta_w()[0]),
            "Wave-frequency motion estimate eta_w_hat = xi2_hat";
        output real "east_wf_estimate" ["m"] (|m| m.observer.eta_w()[1]),
            "Wave-frequency motion estimate eta_w_hat = xi2_hat";
        output real "heading_wf_estimate" ["rad"] (|m| m.observer.eta_w()[2]),
            "Wave-frequency motion estimate eta_w_hat = xi2_hat";
        output real "bias_north_estimate" ["N"] (|m| m.observer.bias_force()[0]),
            "Earth-fixed bias force estimate (J M J^T b_hat when mass-normalised)";
        output real "bias_east_estimate" ["N"] (|m| m.observer.bias_force()[1]),
            "Earth-fixed bias force estimate (J M J^T b_hat when mass-normalised)";
        output real "bias_yaw_estimate" ["N.m"] (|m| m.observer.bias_force()[2]),
            "Earth-fixed bias force estimate (J M J^T b_hat when mass-normalised)";
        output real "innovation_north" ["m"] (|m| m.observer.innovation()[0]), "Innovation y - y_hat";
        output real "innovation_east" ["m"] (|m| m.observer.innovation()[1]), "Innovation y - y_hat";
        output real "innovation_heading" ["rad"] (|m| m.observer.innovation()[2]), "Innovation y - y_hat";
        output real "k1_surge" (|m| m.observer.gains().0[0]),
            "Notch gain k1 = -2 (zeta_n - zeta) omega_c / omega0 (eq. 45; -2.2059 for the paper's set)";
        output real "k2_surge" ["rad/s"] (|m| m.observer.gains().1[0]),
            "Notch gain k2 = 2 omega0 (zeta_n - zeta) (eq. 46; 1.6157)";
    }
}

impl FmuModel for PassiveObserverFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.observer = PassiveObserver::new(self.params.clone(), self.initial_estimate)?;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.observer.set_params(self.params.clone())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.observer.step(self.measured, self.thrust, h);
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let max_substep = self.observer.params().max_substep;
        each("max_substep", max_substep, passes(h, max_substep));
    }
}
