//! `Wind` FMU: mean wind plus gusts and the roll/yaw moments of 003 eqs. 2.19-2.20
//! (`models::disturbances::wind`). No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::disturbances::wind::{Wind, WindParams};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WindFmu {
    params: WindParams,
    speed: f64,
    heading: f64,
    model: Wind,
}

impl Default for WindFmu {
    fn default() -> Self {
        let params = WindParams::default();
        WindFmu {
            model: Wind::new(params.clone(), 0.0).expect("preset parameters are valid"),
            params,
            speed: 0.0,
            heading: 0.0,
        }
    }
}

type V = Variable<WindFmu>;

static VARIABLES: [V; 18] = [
    V::integer_parameter(
        "seed",
        false,
        "Seed of this instance's ChaCha8 streams",
        0,
        i32::MAX,
        |m| m.params.seed as i32,
        |m, v| m.params.seed = v as u64,
    ),
    V::real_parameter(
        "mean_wind_speed",
        Some("m/s"),
        true,
        "Mean true wind speed (the constant component of 003 section 2.4.2)",
        |m| m.params.mean_speed,
        |m, v| m.params.mean_speed = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "wind_direction",
        Some("rad"),
        true,
        "Mean direction the wind blows towards, earth frame of the heading",
        |m| m.params.direction,
        |m, v| m.params.direction = v,
    ),
    V::real_parameter(
        "gust_std",
        Some("m/s"),
        false,
        "Std of the first-order Gauss-Markov gust speed (spectrum 2 s^2 T/pi/(1 + w^2 T^2))",
        |m| m.params.gust_std,
        |m, v| m.params.gust_std = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "gust_time_constant",
        Some("s"),
        false,
        "Correlation time of the gust speed",
        |m| m.params.gust_time_constant,
        |m, v| m.params.gust_time_constant = v,
    )
    .with_range(Some(1e-6), None),
    V::real_parameter(
        "direction_std",
        Some("rad"),
        false,
        "Std of the first-order Gauss-Markov wind-direction variation",
        |m| m.params.direction_std,
        |m, v| m.params.direction_std = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "direction_time_constant",
        Some("s"),
        false,
        "Correlation time of the direction variation",
        |m| m.params.direction_time_constant,
        |m, v| m.params.direction_time_constant = v,
    )
    .with_range(Some(1e-6), None),
    V::real_parameter(
        "roll_coefficient",
        None,
        true,
        "c_w_phi of 003 eq. 2.19 [N.m/(m/s)^2]; not given in 003",
        |m| m.params.roll_coefficient,
        |m, v| m.params.roll_coefficient = v,
    ),
    V::real_parameter(
        "yaw_coefficient",
        None,
        true,
        "c_wR of 003 eq. 2.20 [N.m/(m/s)^2]; not given in 003",
        |m| m.params.yaw_coefficient,
        |m, v| m.params.yaw_coefficient = v,
    ),
    V::real_parameter(
        "internal_step",
        Some("s"),
        false,
        "Fixed grid of the gust processes (linear interpolation in between)",
        |m| m.params.internal_step,
        |m, v| m.params.internal_step = v,
    )
    .with_range(Some(1e-6), None),
    V::real_input(
        "ship_speed",
        Some("m/s"),
        "Ship speed along the heading",
        |m| m.speed,
        |m, v| m.speed = v,
    ),
    V::real_input(
        "heading",
        Some("rad"),
        "Ship heading",
        |m| m.heading,
        |m, v| m.heading = v,
    ),
    V::real_output(
        "true_wind_speed",
        Some("m/s"),
        "Mean plus gust wind speed",
        |m| m.model.true_speed(),
    ),
    V::real_output(
        "true_wind_direction",
        Some("rad"),
        "Mean plus varying direction (towards)",
        |m| m.model.true_direction(),
    ),
    V::real_output(
        "relative_wind_speed",
        Some("m/s"),
        "V_w: relative wind speed as measured on board",
        |m| m.model.relative().0,
    ),
    V::real_output(
        "relative_wind_angle",
        Some("rad"),
        "gamma in (-pi, pi]: 0 wind from astern, +pi/2 blowing towards starboard, pi head wind",
        |m| m.model.relative().1,
    ),
    V::real_output(
        "roll_moment",
        Some("N.m"),
        "K = c_w_phi V_w^2 sin(gamma) (003 eq. 2.19)",
        |m| m.model.roll_moment(),
    ),
    V::real_output(
        "yaw_moment",
        Some("N.m"),
        "N = c_wR V_w^2 sin(2 gamma) (003 eq. 2.20)",
        |m| m.model.yaw_moment(),
    ),
];

impl FmuModel for WindFmu {
    const MODEL_IDENTIFIER: &'static str = "Wind";
    const DESCRIPTION: &'static str =
        "Seeded wind: mean wind with Gauss-Markov gusts in speed and \
        direction, relative wind, roll and yaw moments of van der Klugt (1987) eqs. 2.19-2.20";
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

    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.model = Wind::new(self.params.clone(), start_time)?;
        self.model.set_inputs(self.speed, self.heading);
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        let p = &self.params;
        if !(p.mean_speed >= 0.0) {
            return Err(format!("mean_wind_speed = {} must be >= 0", p.mean_speed));
        }
        self.model.set_mean_and_coefficients(
            p.mean_speed,
            p.direction,
            p.roll_coefficient,
            p.yaw_coefficient,
        );
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.model.set_inputs(self.speed, self.heading);
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.model.set_inputs(self.speed, self.heading);
        self.model.advance_to(t + h);
        Ok(())
    }
}

export_fmu!(WindFmu);
