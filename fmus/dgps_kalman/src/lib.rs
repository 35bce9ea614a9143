//! `DgpsKalman` FMU: the 4-state DGPS position/velocity Kalman filter of [Artyszuk2003, sec. 2]
//! (`models::observers::dgps_kalman`). No physics here.

use fmi2_export::{passes, FmuModel};
use models::observers::dgps_kalman::{DgpsKalman, DgpsKalmanParams};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and filter of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DgpsKalmanFmu {
    params: DgpsKalmanParams,
    initial_estimate: [f64; 4],
    measured: [f64; 2],
    heading: f64,
    /// Current speed [m/s] and the direction it flows toward [rad] [Artyszuk2003, sec. 1].
    current: [f64; 2],
    filter: DgpsKalman,
}

impl Default for DgpsKalmanFmu {
    fn default() -> Self {
        DgpsKalmanFmu {
            params: DgpsKalmanParams::default(),
            initial_estimate: [0.0; 4],
            measured: [0.0; 2],
            heading: 0.0,
            current: [0.0; 2],
            filter: DgpsKalman::new(DgpsKalmanParams::default(), [0.0; 4]).expect("preset"),
        }
    }
}

/// The inputs of the water-related outputs.
const WATER: &[&str] = &["heading", "current_speed", "current_direction"];

impl DgpsKalmanFmu {
    /// Water-related body velocity [surge, sway] (current-corrected).
    fn through_water(&self) -> [f64; 2] {
        let [speed, direction] = self.current;
        self.filter
            .body_velocity_through_water(self.heading, speed, direction)
    }
}

fmi2_export::fmu! {
    DgpsKalmanFmu => "DgpsKalman",
    description: "4-state DGPS position/velocity Kalman filter with speed \
        over ground and drift-angle outputs (Artyszuk)",
    experiment: (0.0, 600.0, 1.0),
    documentation: "documentation.html",
    variables: {
        fixed real "time_step" ["s"] (params.dt).min(0.0),
            "Filter time-update step dt ([Artyszuk2003]: 1 s); a communication step h is ceil(h/dt) cycles";
        fixed real "process_noise_level" (params.sp).min(0.0),
            "S_p, spectral amplitude of the PV random-walk model (m2/s3 implied; 0.001 low, 0.01 optimal, 0.1 high)";
        fixed real "measurement_variance" ["m2"] (params.r).min(0.0),
            "R per axis ([Artyszuk2003]: 4 m2, i.e. 2 m DGPS standard deviation)";
        fixed bool "full_recursion" (params.full_recursion),
            "true: time-varying Kalman recursion from P0 = p0 I; false: the steady-state form of eq. 5 (the paper's results)";
        fixed real "initial_covariance" (params.p0).min(0.0), "p0 of P0 = p0 I for the full recursion";
        fixed real "initial_velocity_north" ["m/s"] (initial_estimate[0]), "Initial v_NS estimate";
        fixed real "initial_velocity_east" ["m/s"] (initial_estimate[1]), "Initial v_EW estimate";
        fixed real "initial_north" ["m"] (initial_estimate[2]), "Initial north position estimate";
        fixed real "initial_east" ["m"] (initial_estimate[3]), "Initial east position estimate";
        input real "north_measured" ["m"] (measured[0]), "DGPS north position fix";
        input real "east_measured" ["m"] (measured[1]), "DGPS east position fix";
        input real "heading" ["rad"] (heading), "Gyro heading psi (for the drift angle, eq. 7)";
        output real "velocity_north_estimate" ["m/s"] (|m| m.filter.estimate()[0]).depends_on(&[]),
            "Estimated v_NS";
        output real "velocity_east_estimate" ["m/s"] (|m| m.filter.estimate()[1]).depends_on(&[]),
            "Estimated v_EW";
        output real "north_estimate" ["m"] (|m| m.filter.estimate()[2]).depends_on(&[]),
            "Estimated north position";
        output real "east_estimate" ["m"] (|m| m.filter.estimate()[3]).depends_on(&[]),
            "Estimated east position";
        output real "speed_over_ground" ["m/s"] (|m| m.filter.speed_over_ground()).depends_on(&[]),
            "v_xy = sqrt(v_NS^2 + v_EW^2) (eq. 6)";
        output real "course_over_ground" ["rad"] (|m| m.filter.course_over_ground()).depends_on(&[]),
            "atan2(v_EW, v_NS)";
        output real "drift_angle" ["rad"] (|m| m.filter.drift_angle(m.heading)).depends_on(&["heading"]),
            "beta_A = psi - atan2(v_EW, v_NS), wrapped (eq. 7); overestimated in turns by the filter lag";
        output real "gain_velocity" ["1/s"] (|m| m.filter.steady_gain()[(0, 0)]).depends_on(&[]),
            "Steady-state velocity gain k_v of K_inf (S_p = 0.01: 0.042688)";
        output real "gain_position" (|m| m.filter.steady_gain()[(2, 0)]).depends_on(&[]),
            "Steady-state position gain k_p of K_inf (S_p = 0.01: 0.271106)";
        input real "current_speed" ["m/s"] (current[0]),
            "Sea-current speed |v_c| for the ground-to-water correction ([Artyszuk2003, sec. 1])";
        input real "current_direction" ["rad"] (current[1]),
            "Direction the current flows toward, gamma_c (0: a north current moving the ship north)";
        output real "surge_velocity_ground" ["m/s"] (|m| m.filter.body_velocity_over_ground(m.heading)[0])
            .depends_on(&["heading"]),
            "Ground-related body velocity v_x = D^T(psi) [v_NS, v_EW] (surge)";
        output real "sway_velocity_ground" ["m/s"] (|m| m.filter.body_velocity_over_ground(m.heading)[1])
            .depends_on(&["heading"]),
            "Ground-related body velocity v_y (sway, to starboard)";
        output real "surge_velocity_water" ["m/s"] (|m| m.through_water()[0]).depends_on(WATER),
            "Water-related surge v_x - [D^T(psi) v_c]_x (current correction, [Artyszuk2003, sec. 1])";
        output real "sway_velocity_water" ["m/s"] (|m| m.through_water()[1]).depends_on(WATER),
            "Water-related sway v_y - [D^T(psi) v_c]_y";
        output real "drift_angle_water" ["rad"]
            (|m| m.filter.drift_angle_through_water(m.heading, m.current[0], m.current[1]))
            .depends_on(WATER),
            "Water-related drift angle atan2(-v_y_water, v_x_water) ([Artyszuk2003, sec. 1])";
    }
}

impl FmuModel for DgpsKalmanFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.filter = DgpsKalman::new(self.params, self.initial_estimate)?;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.filter.step(self.measured[0], self.measured[1], h);
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let dt = self.filter.params().dt;
        each("time_step", dt, passes(h, dt));
    }
}
