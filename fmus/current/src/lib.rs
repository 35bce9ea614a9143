//! `Current` FMU: currents and slowly varying disturbances of `models::disturbances::current`
//! (the 5-kn current of [Taylor2000, sec. 5.2.3.1], the N'/Y' design disturbances of
//! [Parsons1980, sec. 2.3 and 3.2-3.3], the bias of [Fossen1999, eq. (7)]). No physics here.

use fmi2_export::FmuModel;
use models::disturbances::current::{Current, CurrentParams};
use serde::{Deserialize, Serialize};
use std::cell::Cell;

/// Parameters, input and state of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CurrentFmu {
    params: CurrentParams,
    heading: f64,
    model: Current,
    /// `model.disturbance()` and `model.bias()`, computed by the first getter that needs them
    /// after the model changed (each of N', Y', N, Y, and of the five bias outputs, needs all
    /// of one); reset wherever the model changes. Not part of the state.
    #[serde(skip)]
    disturbance: Cell<Option<[f64; 2]>>,
    #[serde(skip)]
    bias: Cell<Option<[f64; 3]>>,
}

/// The value in `cell`, computed by `compute` if empty.
fn kept<T: Copy>(cell: &Cell<Option<T>>, compute: impl FnOnce() -> T) -> T {
    cell.get().unwrap_or_else(|| {
        let v = compute();
        cell.set(Some(v));
        v
    })
}

impl CurrentFmu {
    fn disturbance(&self) -> [f64; 2] {
        kept(&self.disturbance, || self.model.disturbance())
    }

    fn bias(&self) -> [f64; 3] {
        kept(&self.bias, || self.model.bias())
    }

    /// Forgets the kept values (the model is about to change).
    fn forget(&mut self) {
        self.disturbance.set(None);
        self.bias.set(None);
    }
}

impl Default for CurrentFmu {
    fn default() -> Self {
        let params = CurrentParams::default();
        CurrentFmu {
            model: Current::new(params.clone(), 0.0).expect("preset parameters are valid"),
            params,
            heading: 0.0,
            disturbance: Cell::new(None),
            bias: Cell::new(None),
        }
    }
}

fmi2_export::fmu! {
    CurrentFmu => "Current",
    description: "Seeded currents and slowly varying disturbances: constant or \
        ramped current (DDG-51 5 kn), Parsons & Cuong (1980) design lateral current, passing ship, \
        white/shaping-filter/random-walk N' and Y', Fossen & Strand (1999) bias",
    experiment: (0.0, 1200.0, 0.2349),
    documentation: "documentation.html",
    variables: {
        fixed int(0, i32::MAX) "seed" (params.seed as u64), "Seed of this instance's ChaCha8 streams";
        tunable real "current_speed_initial" ["m/s"] (params.speed_initial),
            "Current speed before current_start_time";
        tunable real "current_speed_final" ["m/s"] (params.speed_final),
            "Current speed after the ramp ([Taylor2000]: 5 kn = 2.5722 m/s)";
        tunable real "current_direction" ["rad"] (params.direction),
            "Direction the current flows towards (earth frame of heading; pi/2: onto the port beam of a ship heading 0)";
        tunable real "current_start_time" ["s"] (params.t_start),
            "Start of the change from the initial to the final speed";
        tunable real "current_ramp_duration" ["s"] (params.ramp_duration).min(0.0),
            "Duration of the linear change (0: step, the 'current gust' of [Taylor2000])";
        fixed real "reference_speed" ["m/s"] (params.ship_speed).min(1e-3),
            "Ship speed U of the [Parsons1980] nondimensionalisation t' = tU/L, N = N' rho L^3 U^2/2 (Tokyo Maru 12 kn)";
        fixed real "ship_length" ["m"] (params.ship_length).min(1e-3),
            "Ship length L of the [Parsons1980] nondimensionalisation (Tokyo Maru 290 m)";
        fixed real "water_density" (params.density).min(1.0),
            "Water density rho [kg/m3] for the dimensional N, Y (not given in [Parsons1980]: 1025)";
        fixed bool "design_current" (params.design_current),
            "[Parsons1980, Fig. 4] design lateral current: N' = design_n s(t'), Y' = design_y s(t')";
        fixed real "design_n" (params.design_n),
            "N' of the 1-kn lateral current at H/T = 1.89 ([Parsons1980, Tables 12-13]: 0.10262e-2)";
        fixed real "design_y" (params.design_y),
            "Y' of the 1-kn lateral current ([Parsons1980, Tables 12-13]: 0.23277e-2)";
        fixed real "design_t_constant" (params.design_t_constant),
            "End of the constant part, ship lengths t' ([Parsons1980]: 15; 18 in the WLS runs)";
        fixed real "design_t_ramp" (params.design_t_ramp),
            "End of the linear ramp, ship lengths t' ([Parsons1980]: 20)";
        fixed real "design_final_fraction" (params.design_final_fraction),
            "Level after the ramp as a fraction ([Parsons1980]: 0.5)";
        fixed real "passing_ship_factor" (params.passing_factor),
            "Magnitude factor of the [Parsons1980, Fig. 3] passing-ship surrogate (0 off, 1, or 4 as in [Parsons1980, Figs. 6-7, 11-12])";
        fixed real "passing_ship_time" (params.passing_time),
            "Beam-to-beam instant t'_p in ship lengths ([Parsons1980]: 7, or 20 in [Parsons1980, Figs. 6-7])";
        fixed real "white_sigma_n" (params.white_sigma[0]).min(0.0),
            "Per-sample std of white N' on the internal grid ([Parsons1980, sec. 5.3]: 2e-5)";
        fixed real "white_sigma_y" (params.white_sigma[1]).min(0.0),
            "Per-sample std of white Y' on the internal grid ([Parsons1980, sec. 5.3]: 5e-5)";
        fixed real "shaping_sigma_n" (params.shaping_sigma[0]).min(0.0),
            "Stationary std of the first-order shaping-filter N' ([Parsons1980, eq. (53)]: 8.798e-5)";
        fixed real "shaping_sigma_y" (params.shaping_sigma[1]).min(0.0),
            "Stationary std of the shaping-filter Y' ([Parsons1980, eq. (54)]: 21.178e-5)";
        fixed real "shaping_time_constant" (params.shaping_time_constant).min(1e-6),
            "T_N = T_Y in ship lengths ([Parsons1980, eqs. (39)-(40)]: 1)";
        fixed real "walk_q_n" (params.walk_q[0]).min(0.0),
            "Random-walk intensity q of N' per unit t' ([Parsons1980, eq. (67)]: 2e-8)";
        fixed real "walk_q_y" (params.walk_q[1]).min(0.0),
            "Random-walk intensity q of Y' per unit t' ([Parsons1980, eq. (68)]: 1.25e-7)";
        fixed real "bias_time_constant" ["s"] (params.bias_time_constant).min(1e-6),
            "[Fossen1999] bias time constant T ([Fossen1999, eq. (58)]: 1000 s)";
        fixed real "bias_psi_x" (params.bias_psi[0]).min(0.0),
            "[Fossen1999] bias noise amplitude Psi, surge, in N/sqrt(s); not given in [Fossen1999]";
        fixed real "bias_psi_y" (params.bias_psi[1]).min(0.0),
            "[Fossen1999] bias noise amplitude Psi, sway, in N/sqrt(s)";
        fixed real "bias_psi_n" (params.bias_psi[2]).min(0.0),
            "[Fossen1999] bias noise amplitude Psi, yaw, in N.m/sqrt(s)";
        fixed real "bias_initial_x" ["N"] (params.bias_initial[0]),
            "Initial earth-fixed bias force, x";
        fixed real "bias_initial_y" ["N"] (params.bias_initial[1]),
            "Initial earth-fixed bias force, y";
        fixed real "bias_initial_n" ["N.m"] (params.bias_initial[2]), "Initial bias yaw moment";
        fixed real "internal_step" ["s"] (params.internal_step).min(1e-6),
            "Fixed grid of the random processes (default dt' = 0.005 = 0.2349 s of [Parsons1980])";
        input real "heading" ["rad"] (heading), "Ship heading psi (for the body-frame outputs)";
        output real "current_north" ["m/s"] (|m| m.model.current_velocity()[0]),
            "Earth-fixed current velocity, first axis";
        output real "current_east" ["m/s"] (|m| m.model.current_velocity()[1]),
            "Earth-fixed current velocity, second axis";
        output real "current_surge" ["m/s"] (|m| m.model.current_body()[0]),
            "Current velocity along the ship, V cos(direction - heading)";
        output real "current_sway" ["m/s"] (|m| m.model.current_body()[1]),
            "Current velocity to starboard, V sin(direction - heading)";
        output real "n_prime" (|m| m.disturbance()[0]),
            "Total [Parsons1980] nondimensional yaw moment N'";
        output real "y_prime" (|m| m.disturbance()[1]),
            "Total [Parsons1980] nondimensional side force Y'";
        output real "yaw_moment" ["N.m"] (|m| m.model.dimensional(m.disturbance())[0]),
            "N = N' rho L^3 U^2/2";
        output real "side_force" ["N"] (|m| m.model.dimensional(m.disturbance())[1]),
            "Y = Y' rho L^2 U^2/2";
        output real "bias_x" ["N"] (|m| m.bias()[0]), "[Fossen1999] earth-fixed bias force, x";
        output real "bias_y" ["N"] (|m| m.bias()[1]), "[Fossen1999] earth-fixed bias force, y";
        output real "bias_n" ["N.m"] (|m| m.bias()[2]), "[Fossen1999] bias yaw moment";
        output real "bias_surge" ["N"] (|m| m.model.body(m.bias())[0]),
            "[Fossen1999] bias in the body frame, J(psi)^T b, surge";
        output real "bias_sway" ["N"] (|m| m.model.body(m.bias())[1]),
            "[Fossen1999] bias in the body frame, sway";
        output real "nondimensional_time" (|m| m.model.nondimensional_time()),
            "t' = (t - t0) U/L in ship lengths";
    }
}

impl FmuModel for CurrentFmu {
    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.forget();
        self.model = Current::new(self.params.clone(), start_time)?;
        self.model.set_heading(self.heading);
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.forget();
        let p = &self.params;
        self.model.set_current_profile(
            p.speed_initial,
            p.speed_final,
            p.direction,
            p.t_start,
            p.ramp_duration,
        )
    }

    fn calculate_outputs(&mut self) {
        self.forget();
        self.model.set_heading(self.heading);
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.forget();
        self.model.set_heading(self.heading);
        self.model.advance_to(t + h);
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

    /// With every disturbance on, the outputs read through the kept disturbance and bias equal
    /// the model's own functions bit for bit, after steps, input changes and parameter changes,
    /// and so do they when nothing is kept (a deserialized state).
    #[test]
    fn outputs_from_the_kept_values_equal_the_model() {
        let mut m = CurrentFmu::default();
        let p = &mut m.params;
        p.design_current = true;
        p.passing_factor = 1.0;
        p.white_sigma = [2e-5, 5e-5];
        p.shaping_sigma = [8.798e-5, 21.178e-5];
        p.walk_q = [2e-8, 1.25e-7];
        p.bias_psi = [1e3, 2e3, 3e4];
        p.bias_initial = [1e4, -2e4, 5e5];
        m.initialize(0.0).unwrap();
        let check = |m: &CurrentFmu| {
            let c = &m.model;
            let (d, dd, b, bb) = (
                c.disturbance(),
                c.disturbance_dimensional(),
                c.bias(),
                c.bias_body(),
            );
            for (name, want) in [
                ("n_prime", d[0]),
                ("y_prime", d[1]),
                ("yaw_moment", dd[0]),
                ("side_force", dd[1]),
                ("bias_x", b[0]),
                ("bias_y", b[1]),
                ("bias_n", b[2]),
                ("bias_surge", bb[0]),
                ("bias_sway", bb[1]),
            ] {
                assert_eq!(output(m, name).to_bits(), want.to_bits(), "{name}");
            }
        };
        check(&m);
        let mut nonzero = 0;
        for k in 0..400 {
            m.heading = 0.01 * k as f64;
            m.calculate_outputs();
            check(&m);
            m.do_step(0.5 * k as f64, 0.5).unwrap();
            check(&m);
            nonzero += usize::from(output(&m, "n_prime") != 0.0 && output(&m, "bias_sway") != 0.0);
            if k == 200 {
                m.params.speed_final = 1.0;
                m.parameters_changed().unwrap();
                check(&m);
            }
            let mut restored = m.clone();
            restored.forget();
            check(&restored);
        }
        assert!(nonzero > 300);
    }
}
