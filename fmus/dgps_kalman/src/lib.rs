//! `DgpsKalman` FMU: Artyszuk's 4-state DGPS position/velocity Kalman filter
//! (`models::observers::dgps_kalman`). No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::observers::dgps_kalman::{DgpsKalman, DgpsKalmanParams};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and filter of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DgpsKalmanFmu {
    params: DgpsKalmanParams,
    x0: [f64; 4],
    z: [f64; 2],
    heading: f64,
    /// Current speed [m/s] and the direction it flows toward [rad] (§2.1).
    current: [f64; 2],
    filter: DgpsKalman,
}

impl Default for DgpsKalmanFmu {
    fn default() -> Self {
        DgpsKalmanFmu {
            params: DgpsKalmanParams::default(),
            x0: [0.0; 4],
            z: [0.0; 2],
            heading: 0.0,
            current: [0.0; 2],
            filter: DgpsKalman::new(DgpsKalmanParams::default(), [0.0; 4]).expect("preset"),
        }
    }
}

type V = Variable<DgpsKalmanFmu>;

static VARIABLES: [V; 28] = [
    V::real_parameter(
        "time_step",
        Some("s"),
        false,
        "Filter time-update step dt (002: 1 s); a communication step h is ceil(h/dt) cycles",
        |m| m.params.dt,
        |m, v| m.params.dt = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "process_noise_level",
        None,
        false,
        "S_p, spectral amplitude of the PV random-walk model (m2/s3 implied; 0.001 low, 0.01 optimal, 0.1 high)",
        |m| m.params.sp,
        |m, v| m.params.sp = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "measurement_variance",
        Some("m2"),
        false,
        "R per axis (002: 4 m2, i.e. 2 m DGPS standard deviation)",
        |m| m.params.r,
        |m, v| m.params.r = v,
    )
    .with_range(Some(0.0), None),
    V::boolean_parameter(
        "full_recursion",
        false,
        "true: time-varying Kalman recursion from P0 = p0 I; false: the steady-state form of eq. 5 (the paper's results)",
        |m| m.params.full_recursion,
        |m, v| m.params.full_recursion = v,
    ),
    V::real_parameter(
        "initial_covariance",
        None,
        false,
        "p0 of P0 = p0 I for the full recursion",
        |m| m.params.p0,
        |m, v| m.params.p0 = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "initial_velocity_north",
        Some("m/s"),
        false,
        "Initial v_NS estimate",
        |m| m.x0[0],
        |m, v| m.x0[0] = v,
    ),
    V::real_parameter(
        "initial_velocity_east",
        Some("m/s"),
        false,
        "Initial v_EW estimate",
        |m| m.x0[1],
        |m, v| m.x0[1] = v,
    ),
    V::real_parameter(
        "initial_north",
        Some("m"),
        false,
        "Initial north position estimate",
        |m| m.x0[2],
        |m, v| m.x0[2] = v,
    ),
    V::real_parameter(
        "initial_east",
        Some("m"),
        false,
        "Initial east position estimate",
        |m| m.x0[3],
        |m, v| m.x0[3] = v,
    ),
    V::real_input(
        "north_measured",
        Some("m"),
        "DGPS north position fix",
        |m| m.z[0],
        |m, v| m.z[0] = v,
    ),
    V::real_input(
        "east_measured",
        Some("m"),
        "DGPS east position fix",
        |m| m.z[1],
        |m, v| m.z[1] = v,
    ),
    V::real_input(
        "heading",
        Some("rad"),
        "Gyro heading psi (for the drift angle, eq. 7)",
        |m| m.heading,
        |m, v| m.heading = v,
    ),
    V::real_output(
        "velocity_north_estimate",
        Some("m/s"),
        "Estimated v_NS",
        |m| m.filter.estimate()[0],
    )
    .depends_on(&[]),
    V::real_output(
        "velocity_east_estimate",
        Some("m/s"),
        "Estimated v_EW",
        |m| m.filter.estimate()[1],
    )
    .depends_on(&[]),
    V::real_output(
        "north_estimate",
        Some("m"),
        "Estimated north position",
        |m| m.filter.estimate()[2],
    )
    .depends_on(&[]),
    V::real_output(
        "east_estimate",
        Some("m"),
        "Estimated east position",
        |m| m.filter.estimate()[3],
    )
    .depends_on(&[]),
    V::real_output(
        "speed_over_ground",
        Some("m/s"),
        "v_xy = sqrt(v_NS^2 + v_EW^2) (eq. 6)",
        |m| m.filter.speed_over_ground(),
    )
    .depends_on(&[]),
    V::real_output(
        "course_over_ground",
        Some("rad"),
        "atan2(v_EW, v_NS)",
        |m| m.filter.course_over_ground(),
    )
    .depends_on(&[]),
    V::real_output(
        "drift_angle",
        Some("rad"),
        "beta_A = psi - atan2(v_EW, v_NS), wrapped (eq. 7); overestimated in turns by the filter lag",
        |m| m.filter.drift_angle(m.heading),
    )
    .depends_on(&["heading"]),
    V::real_output(
        "gain_velocity",
        Some("1/s"),
        "Steady-state velocity gain k_v of K_inf (S_p = 0.01: 0.042688)",
        |m| m.filter.steady_gain()[(0, 0)],
    )
    .depends_on(&[]),
    V::real_output(
        "gain_position",
        None,
        "Steady-state position gain k_p of K_inf (S_p = 0.01: 0.271106)",
        |m| m.filter.steady_gain()[(2, 0)],
    )
    .depends_on(&[]),
    V::real_input(
        "current_speed",
        Some("m/s"),
        "Sea-current speed |v_c| for the ground-to-water correction (section 1 of 002)",
        |m| m.current[0],
        |m, v| m.current[0] = v,
    ),
    V::real_input(
        "current_direction",
        Some("rad"),
        "Direction the current flows toward, gamma_c (0: a north current moving the ship north)",
        |m| m.current[1],
        |m, v| m.current[1] = v,
    ),
    V::real_output(
        "surge_velocity_ground",
        Some("m/s"),
        "Ground-related body velocity v_x = D^T(psi) [v_NS, v_EW] (surge)",
        |m| m.filter.body_velocity_over_ground(m.heading)[0],
    )
    .depends_on(&["heading"]),
    V::real_output(
        "sway_velocity_ground",
        Some("m/s"),
        "Ground-related body velocity v_y (sway, to starboard)",
        |m| m.filter.body_velocity_over_ground(m.heading)[1],
    )
    .depends_on(&["heading"]),
    V::real_output(
        "surge_velocity_water",
        Some("m/s"),
        "Water-related surge v_x - [D^T(psi) v_c]_x (current correction, 002 line 34)",
        |m| m.filter.body_velocity_through_water(m.heading, m.current[0], m.current[1])[0],
    )
    .depends_on(&["heading", "current_speed", "current_direction"]),
    V::real_output(
        "sway_velocity_water",
        Some("m/s"),
        "Water-related sway v_y - [D^T(psi) v_c]_y",
        |m| m.filter.body_velocity_through_water(m.heading, m.current[0], m.current[1])[1],
    )
    .depends_on(&["heading", "current_speed", "current_direction"]),
    V::real_output(
        "drift_angle_water",
        Some("rad"),
        "Water-related drift angle atan2(-v_y_water, v_x_water) (002 line 44)",
        |m| m.filter.drift_angle_through_water(m.heading, m.current[0], m.current[1]),
    )
    .depends_on(&["heading", "current_speed", "current_direction"]),
];

impl FmuModel for DgpsKalmanFmu {
    const MODEL_IDENTIFIER: &'static str = "DgpsKalman";
    const DESCRIPTION: &'static str = "4-state DGPS position/velocity Kalman filter with speed \
        over ground and drift-angle outputs (Artyszuk)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 600.0,
        step_size: 1.0,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.filter = DgpsKalman::new(self.params, self.x0)?;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.filter.step(self.z[0], self.z[1], h);
        Ok(())
    }
}

export_fmu!(DgpsKalmanFmu);
