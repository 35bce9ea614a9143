//! `PathWlsEstimator` FMU: the moving-window Weighted Least-Squares parameter estimator of
//! Parsons & Cuong (1980, source 004, section 4) in `models::controllers::wls`, estimating
//! f22, f23, f25, f32, f33, f35 of the Tokyo Maru and the window means of N′, Y′ from the
//! measured states, the rudder angle and the control-loop filter's estimate at the window start;
//! its f outputs feed the PathController's estimate inputs. No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::controllers::path::UpdateDecision;
use models::controllers::wls::{WlsEstimator, WlsSchedule, WlsSettings};
use models::hull::tokyo_maru::TokyoMaruCoefficients;
use models::observers::path_model::states_prime;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one estimator instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PathWlsFmu {
    schedule: WlsSchedule,
    initial_depth_ratio: f64,
    gamma_depth_ratio: f64,
    /// Table 9 PSDs r_jj of ψ′, r′, β′, η′; W = diag(1/r_jj).
    r: [f64; 4],
    max_evaluations: i32,
    ship_length: f64,
    ship_speed: f64,
    /// Measured ψ [rad], r [rad/s], β [rad], η [m]; rudder δ [rad].
    z: [f64; 4],
    rudder: f64,
    /// Filter estimate ψ̂, r̂, β̂, η̂ (SI).
    xhat: [f64; 4],
    start_time: f64,
    est: WlsEstimator,
}

impl PathWlsFmu {
    fn settings(&self) -> WlsSettings {
        let g = TokyoMaruCoefficients::at_depth_ratio(self.gamma_depth_ratio);
        WlsSettings {
            dt: 0.005,
            gamma: [g.g21, g.g22, g.g31, g.g32],
            weight: self.r.map(|r| 1.0 / r),
            max_evaluations: self.max_evaluations.max(0) as usize,
        }
    }

    fn initial_estimate(&self) -> [f64; 8] {
        initial_estimate(self.initial_depth_ratio)
    }

    fn prime(&self, v: &[f64; 4]) -> [f64; 4] {
        states_prime(v, self.ship_length, self.ship_speed)
    }

    fn p(&self, i: usize) -> f64 {
        self.est.estimate()[i]
    }
}

/// The Table 2 coefficients at H/T = `depth_ratio` with N′ = Y′ = 0.
fn initial_estimate(depth_ratio: f64) -> [f64; 8] {
    let c = TokyoMaruCoefficients::at_depth_ratio(depth_ratio);
    [c.f22, c.f23, c.f25, c.f32, c.f33, c.f35, 0.0, 0.0]
}

impl Default for PathWlsFmu {
    fn default() -> Self {
        let schedule = WlsSchedule {
            window_start: 3.45,
            window_length: 2.5,
            update_cycle: 6.0,
        };
        // WlsSettings::default() is what settings() gives for the parameter defaults below
        // (gammas at H/T = 1.89, Table 9 weights, 2000 evaluations); initialize rebuilds it.
        PathWlsFmu {
            schedule,
            initial_depth_ratio: 1.89,
            gamma_depth_ratio: 1.89,
            r: [1.2976e-9, 7.7215e-10, 8.2777e-10, 5.0651e-9],
            max_evaluations: 2000,
            ship_length: models::hull::tokyo_maru::L,
            ship_speed: models::hull::tokyo_maru::U,
            z: [0.0; 4],
            rudder: 0.0,
            xhat: [0.0; 4],
            start_time: 0.0,
            est: WlsEstimator::new(WlsSettings::default(), schedule, initial_estimate(1.89))
                .expect("default settings are valid"),
        }
    }
}

type V = Variable<PathWlsFmu>;

fn decision_code(d: UpdateDecision) -> f64 {
    match d {
        UpdateDecision::None => 0.0,
        UpdateDecision::F23F25 => 1.0,
        UpdateDecision::All => 2.0,
    }
}

static VARIABLES: [V; 36] = [
    // ---- parameters (0..12)
    V::real_parameter(
        "window_start",
        None,
        false,
        "Start of the first data window in ship lengths t' = (t - t0) U/L (S11: 3.45, a window \
         of 2.5 L ending 0.05 L before the update at t' = 6)",
        |m| m.schedule.window_start,
        |m, v| m.schedule.window_start = v,
    ),
    V::real_parameter(
        "window_length",
        None,
        false,
        "Data window LW in ship lengths (2.5; one sample per communication step)",
        |m| m.schedule.window_length,
        |m, v| m.schedule.window_length = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "update_cycle",
        None,
        false,
        "Update cycle LU in ship lengths: a window every LU from window_start (5, 6 or 6.25)",
        |m| m.schedule.update_cycle,
        |m, v| m.schedule.update_cycle = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "initial_depth_ratio",
        None,
        false,
        "H/T whose Table 2 coefficients start the first search (1.89; 1e300: deep water); N', Y' start at 0",
        |m| m.initial_depth_ratio,
        |m, v| m.initial_depth_ratio = v,
    )
    .with_range(Some(1.0), None),
    V::real_parameter(
        "gamma_depth_ratio",
        None,
        false,
        "H/T of the fixed gamma~_ij of the model eq. 75 (1.89)",
        |m| m.gamma_depth_ratio,
        |m, v| m.gamma_depth_ratio = v,
    )
    .with_range(Some(1.0), None),
    V::real_parameter(
        "r_heading",
        None,
        false,
        "PSD r_jj of psi' for the weight W = R^-1 of eq. 77 (Table 9: 1.2976e-9)",
        |m| m.r[0],
        |m, v| m.r[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "r_yaw_rate",
        None,
        false,
        "PSD r_jj of r' (Table 9: 7.7215e-10)",
        |m| m.r[1],
        |m, v| m.r[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "r_drift_angle",
        None,
        false,
        "PSD r_jj of beta' (Table 9: 8.2777e-10)",
        |m| m.r[2],
        |m, v| m.r[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "r_cross_track",
        None,
        false,
        "PSD r_jj of eta' (Table 9: 5.0651e-9)",
        |m| m.r[3],
        |m, v| m.r[3] = v,
    )
    .with_range(Some(0.0), None),
    V::integer_parameter(
        "max_evaluations",
        false,
        "Largest number of cost evaluations per fit (Levenberg-Marquardt with a forward-difference Jacobian)",
        10,
        1_000_000,
        |m| m.max_evaluations,
        |m, v| m.max_evaluations = v,
    ),
    V::real_parameter(
        "ship_length",
        Some("m"),
        false,
        "Ship length L of the prime system (290 m)",
        |m| m.ship_length,
        |m, v| m.ship_length = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "ship_speed",
        Some("m/s"),
        false,
        "Ship speed U of the prime system (12 kn)",
        |m| m.ship_speed,
        |m, v| m.ship_speed = v,
    )
    .with_range(Some(0.0), None),
    // ---- inputs (12..21)
    V::real_input(
        "heading",
        Some("rad"),
        "Measured heading psi relative to the track direction",
        |m| m.z[0],
        |m, v| m.z[0] = v,
    ),
    V::real_input(
        "yaw_rate",
        Some("rad/s"),
        "Measured yaw rate r",
        |m| m.z[1],
        |m, v| m.z[1] = v,
    ),
    V::real_input(
        "drift_angle",
        Some("rad"),
        "Measured drift angle beta (Doppler sonar, v = -U beta)",
        |m| m.z[2],
        |m, v| m.z[2] = v,
    ),
    V::real_input(
        "cross_track",
        Some("m"),
        "Measured lateral offset eta",
        |m| m.z[3],
        |m, v| m.z[3] = v,
    ),
    V::real_input(
        "rudder_angle",
        Some("rad"),
        "Rudder angle delta (known exactly), sampled with the states",
        |m| m.rudder,
        |m, v| m.rudder = v,
    ),
    V::real_input(
        "heading_estimate",
        Some("rad"),
        "Control-loop filter estimate of psi (its value at the window start is the model's initial state)",
        |m| m.xhat[0],
        |m, v| m.xhat[0] = v,
    ),
    V::real_input(
        "yaw_rate_estimate",
        Some("rad/s"),
        "Filter estimate of r",
        |m| m.xhat[1],
        |m, v| m.xhat[1] = v,
    ),
    V::real_input(
        "drift_angle_estimate",
        Some("rad"),
        "Filter estimate of beta",
        |m| m.xhat[2],
        |m, v| m.xhat[2] = v,
    ),
    V::real_input(
        "cross_track_estimate",
        Some("m"),
        "Filter estimate of eta",
        |m| m.xhat[3],
        |m, v| m.xhat[3] = v,
    ),
    // ---- outputs (21..39)
    V::real_output("f22_estimate", None, "Estimate of f22 (last fit)", |m| {
        m.p(0)
    }),
    V::real_output("f23_estimate", None, "Estimate of f23 (last fit)", |m| {
        m.p(1)
    }),
    V::real_output("f25_estimate", None, "Estimate of f25 (last fit)", |m| {
        m.p(2)
    }),
    V::real_output("f32_estimate", None, "Estimate of f32 (last fit)", |m| {
        m.p(3)
    }),
    V::real_output("f33_estimate", None, "Estimate of f33 (last fit)", |m| {
        m.p(4)
    }),
    V::real_output("f35_estimate", None, "Estimate of f35 (last fit)", |m| {
        m.p(5)
    }),
    V::real_output(
        "yaw_moment_prime_estimate",
        None,
        "p7: window mean of N' = 2N/(rho L^3 U^2) seen through the fixed gamma~ (a by-product)",
        |m| m.p(6),
    ),
    V::real_output(
        "sway_force_prime_estimate",
        None,
        "p8: window mean of Y' = 2Y/(rho L^2 U^2) seen through the fixed gamma~ (a by-product)",
        |m| m.p(7),
    ),
    V::boolean_output(
        "estimate_valid",
        "f23 and f25 estimates within their Table 10 ranges (the controller would update)",
        |m| m.est.decision() != UpdateDecision::None,
    ),
    V::real_output(
        "validity",
        None,
        "Table 10 branch of the estimate: 0 no update (f23 or f25 out of range), 1 f23/f25 only, 2 all",
        |m| decision_code(m.est.decision()),
    ),
    V::real_output(
        "evaluations",
        None,
        "Cost evaluations of the last fit (Levenberg-Marquardt; the report's DUD counts differ)",
        |m| m.est.evaluations() as f64,
    ),
    V::real_output(
        "final_cost",
        None,
        "Cost J of eq. 77 at the last fit's minimum, W = R^-1 (dimensionless)",
        |m| m.est.cost(),
    ),
    V::real_output(
        "residual_sum_of_squares",
        None,
        "Sum over the window of |z'_k - x_m,k|^2 at the last fit's minimum (W = I, no 1/2: the scale of the report's printed J)",
        |m| m.est.sum_of_squares(),
    ),
    V::real_output(
        "updates",
        None,
        "Number of fits since the start",
        |m| m.est.updates() as f64,
    ),
    V::boolean_output(
        "loading",
        "A data window is being loaded",
        |m| m.est.loading(),
    ),
];

impl FmuModel for PathWlsFmu {
    const MODEL_IDENTIFIER: &'static str = "PathWlsEstimator";
    const DESCRIPTION: &'static str = "Moving-window Weighted Least-Squares estimator of the \
        Tokyo Maru path model (Parsons & Cuong 1980, section 4): f22, f23, f25, f32, f33, f35 \
        and the window means of N', Y' for the PathController's partial adaptation";
    /// The outputs change only in a step (at the end of a window).
    const DIRECT_FEEDTHROUGH: bool = false;
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 940.0,
        step_size: 0.2349,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        if !(self.ship_length > 0.0 && self.ship_speed > 0.0) {
            return Err(format!(
                "ship_length = {} and ship_speed = {} must be > 0",
                self.ship_length, self.ship_speed
            ));
        }
        for (i, r) in self.r.iter().enumerate() {
            if !(*r > 0.0 && r.is_finite()) {
                let n = ["r_heading", "r_yaw_rate", "r_drift_angle", "r_cross_track"][i];
                return Err(format!("parameter {n} = {r} must be > 0"));
            }
        }
        self.start_time = start_time;
        self.est = WlsEstimator::new(self.settings(), self.schedule, self.initial_estimate())
            .map_err(|e| e.to_string())?;
        Ok(())
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        // one sample per communication step, at its start
        let ul = self.ship_speed / self.ship_length;
        let (tp, dt) = ((t - self.start_time) * ul, h * ul);
        let (z, xhat) = (self.prime(&self.z), self.prime(&self.xhat));
        self.est
            .sample(tp, dt, z, self.rudder, xhat)
            .map(|_| ())
            .map_err(|e| format!("WLS fit at t = {t} s: {e}"))
    }
}

export_fmu!(PathWlsFmu);
