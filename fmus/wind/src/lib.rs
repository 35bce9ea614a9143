//! `Wind` FMU: mean wind plus gusts and the roll/yaw moments of [Klugt1987, eqs. (2.19)-(2.20)]
//! (`models::disturbances::wind`). No physics here.

use fmi2_export::FmuModel;
use models::disturbances::wind::{Wind, WindParams};
use models::error::check_non_negative;
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WindFmu {
    params: WindParams,
    speed: f64,
    heading: f64,
    model: Wind,
    /// The relative wind and the moments, computed once wherever the model changes (do_step,
    /// calculate_outputs, initialize, parameters_changed) instead of in each getter; `None`
    /// (after a deserialized restore) means compute them. Not part of the state.
    #[serde(skip)]
    kept: Option<Relative>,
}

/// The outputs derived from the relative wind.
#[derive(Clone, Copy, Debug)]
struct Relative {
    /// `Wind::relative`: (V_w, gamma).
    wind: (f64, f64),
    roll_moment: f64,
    yaw_moment: f64,
}

impl WindFmu {
    fn relative(&self) -> Relative {
        let wind = self.model.relative();
        Relative {
            wind,
            roll_moment: self.model.roll_moment_at(wind),
            yaw_moment: self.model.yaw_moment_at(wind),
        }
    }

    fn out(&self) -> Relative {
        self.kept.unwrap_or_else(|| self.relative())
    }

    fn keep_relative(&mut self) {
        self.kept = Some(self.relative());
    }
}

impl Default for WindFmu {
    fn default() -> Self {
        let params = WindParams::default();
        WindFmu {
            model: Wind::new(params.clone(), 0.0).expect("preset parameters are valid"),
            params,
            speed: 0.0,
            heading: 0.0,
            kept: None,
        }
    }
}

fmi2_export::fmu! {
    WindFmu => "Wind",
    description: "Seeded wind: mean wind with Gauss-Markov gusts in speed and \
        direction, relative wind, roll and yaw moments of van der Klugt (1987) eqs. 2.19-2.20",
    experiment: (0.0, 600.0, 0.1),
    documentation: "documentation.html",
    variables: {
        fixed int(0, i32::MAX) "seed" (params.seed as u64),
            "Seed of this instance's ChaCha8 streams";
        tunable real "mean_wind_speed" ["m/s"] (params.mean_speed).min(0.0),
            "Mean true wind speed (the constant component of [Klugt1987, sec. 2.4.2])";
        tunable real "wind_direction" ["rad"] (params.direction),
            "Mean direction the wind blows towards, earth frame of the heading";
        fixed real "gust_std" ["m/s"] (params.gust_std).min(0.0),
            "Std of the first-order Gauss-Markov gust speed (spectrum 2 s^2 T/pi/(1 + w^2 T^2))";
        fixed real "gust_time_constant" ["s"] (params.gust_time_constant).min(1e-6),
            "Correlation time of the gust speed";
        fixed real "direction_std" ["rad"] (params.direction_std).min(0.0),
            "Std of the first-order Gauss-Markov wind-direction variation";
        fixed real "direction_time_constant" ["s"] (params.direction_time_constant).min(1e-6),
            "Correlation time of the direction variation";
        tunable real "roll_coefficient" (params.roll_coefficient),
            "c_w_phi of [Klugt1987, eq. (2.19)], in N.m/(m/s)^2; not given in [Klugt1987]";
        tunable real "yaw_coefficient" (params.yaw_coefficient),
            "c_wR of [Klugt1987, eq. (2.20)], in N.m/(m/s)^2; not given in [Klugt1987]";
        fixed real "internal_step" ["s"] (params.internal_step).min(1e-6),
            "Fixed grid of the gust processes (linear interpolation in between)";
        input real "ship_speed" ["m/s"] (speed), "Ship speed along the heading";
        input real "heading" ["rad"] (heading), "Ship heading";
        output real "true_wind_speed" ["m/s"] (|m| m.model.true_speed()),
            "Mean plus gust wind speed";
        output real "true_wind_direction" ["rad"] (|m| m.model.true_direction()),
            "Mean plus varying direction (towards)";
        output real "relative_wind_speed" ["m/s"] (|m| m.out().wind.0),
            "V_w: relative wind speed as measured on board";
        output real "relative_wind_angle" ["rad"] (|m| m.out().wind.1),
            "gamma in (-pi, pi]: 0 wind from astern, +pi/2 blowing towards starboard, pi head wind";
        output real "roll_moment" ["N.m"] (|m| m.out().roll_moment),
            "K = c_w_phi V_w^2 sin(gamma) ([Klugt1987, eq. (2.19)])";
        output real "yaw_moment" ["N.m"] (|m| m.out().yaw_moment),
            "N = c_wR V_w^2 sin(2 gamma) ([Klugt1987, eq. (2.20)])";
    }
}

impl FmuModel for WindFmu {
    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.model = Wind::new(self.params.clone(), start_time)?;
        self.model.set_inputs(self.speed, self.heading);
        self.keep_relative();
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        let p = &self.params;
        check_non_negative("mean_wind_speed", p.mean_speed)?;
        self.model.set_mean_and_coefficients(
            p.mean_speed,
            p.direction,
            p.roll_coefficient,
            p.yaw_coefficient,
        );
        self.keep_relative();
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.model.set_inputs(self.speed, self.heading);
        self.keep_relative();
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.model.set_inputs(self.speed, self.heading);
        self.model.advance_to(t + h);
        self.keep_relative();
        Ok(())
    }

    fn internal_steps(&self, t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        self.model.internal_steps(t + h, each);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fmi2_export::testing::real_of as output;

    /// The outputs read from the relative wind and moments kept at each change equal the model's own
    /// functions bit for bit, and so do they when nothing is kept (a deserialized state).
    #[test]
    fn outputs_from_the_kept_relative_wind_equal_the_model() {
        let mut m = WindFmu::default();
        m.params.roll_coefficient = 2.35e-4;
        m.params.yaw_coefficient = 2.3e-5;
        m.params.direction = 1.2;
        m.speed = 11.0;
        m.initialize(0.0).unwrap();
        let check = |m: &WindFmu| {
            let (v, g) = m.model.relative();
            for (name, want) in [
                ("relative_wind_speed", v),
                ("relative_wind_angle", g),
                ("roll_moment", m.model.roll_moment()),
                ("yaw_moment", m.model.yaw_moment()),
            ] {
                assert_eq!(output(m, name).to_bits(), want.to_bits(), "{name}");
            }
        };
        check(&m);
        for k in 0..300 {
            m.heading = 0.01 * k as f64;
            m.calculate_outputs();
            check(&m);
            m.do_step(0.1 * k as f64, 0.1).unwrap();
            check(&m);
            if k == 150 {
                m.params.mean_speed = 14.0;
                m.parameters_changed().unwrap();
                check(&m);
            }
            let mut restored = m.clone();
            restored.kept = None;
            check(&restored);
        }
    }
}
