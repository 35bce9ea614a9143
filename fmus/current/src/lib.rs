//! `Current` FMU: currents and slowly varying disturbances of `models::disturbances::current`
//! (000's 5-kn current, 004's N'/Y' design disturbances, 001's bias). No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::disturbances::current::{Current, CurrentParams};
use serde::{Deserialize, Serialize};

/// Parameters, input and state of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CurrentFmu {
    params: CurrentParams,
    heading: f64,
    model: Current,
}

impl Default for CurrentFmu {
    fn default() -> Self {
        let params = CurrentParams::default();
        CurrentFmu {
            model: Current::new(params.clone(), 0.0).expect("preset parameters are valid"),
            params,
            heading: 0.0,
        }
    }
}

type V = Variable<CurrentFmu>;

macro_rules! real {
    ($name:literal, $unit:expr, $tun:expr, $desc:literal, $($f:tt)+) => {
        V::real_parameter($name, $unit, $tun, $desc, |m| m.params.$($f)+, |m, v| m.params.$($f)+ = v)
    };
}

static VARIABLES: [V; 47] = [
    V::integer_parameter(
        "seed",
        false,
        "Seed of this instance's ChaCha8 streams",
        0,
        i32::MAX,
        |m| m.params.seed as i32,
        |m, v| m.params.seed = v as u64,
    ),
    real!("current_speed_initial", Some("m/s"), true, "Current speed before current_start_time", speed_initial),
    real!("current_speed_final", Some("m/s"), true, "Current speed after the ramp (000: 5 kn = 2.5722 m/s)", speed_final),
    real!("current_direction", Some("rad"), true, "Direction the current flows towards (earth frame of heading; pi/2: onto the port beam of a ship heading 0)", direction),
    real!("current_start_time", Some("s"), true, "Start of the change from the initial to the final speed", t_start),
    real!("current_ramp_duration", Some("s"), true, "Duration of the linear change (0: step, 000's 'current gust')", ramp_duration)
        .with_range(Some(0.0), None),
    real!("reference_speed", Some("m/s"), false, "Ship speed U of the 004 nondimensionalisation t' = tU/L, N = N' rho L^3 U^2/2 (Tokyo Maru 12 kn)", ship_speed)
        .with_range(Some(1e-3), None),
    real!("ship_length", Some("m"), false, "Ship length L of the 004 nondimensionalisation (Tokyo Maru 290 m)", ship_length)
        .with_range(Some(1e-3), None),
    real!("water_density", None, false, "Water density rho [kg/m3] for the dimensional N, Y (not given in 004: 1025)", density)
        .with_range(Some(1.0), None),
    V::boolean_parameter(
        "design_current",
        false,
        "004 Fig. 4 design lateral current: N' = design_n s(t'), Y' = design_y s(t')",
        |m| m.params.design_current,
        |m, v| m.params.design_current = v,
    ),
    real!("design_n", None, false, "N' of the 1-kn lateral current at H/T = 1.89 (004 Tables 12-13: 0.10262e-2)", design_n),
    real!("design_y", None, false, "Y' of the 1-kn lateral current (004 Tables 12-13: 0.23277e-2)", design_y),
    real!("design_t_constant", None, false, "End of the constant part, ship lengths t' (004: 15; 18 in the WLS runs)", design_t_constant),
    real!("design_t_ramp", None, false, "End of the linear ramp, ship lengths t' (004: 20)", design_t_ramp),
    real!("design_final_fraction", None, false, "Level after the ramp as a fraction (004: 0.5)", design_final_fraction),
    real!("passing_ship_factor", None, false, "Magnitude factor of the 004 Fig. 3 passing-ship surrogate (0 off, 1, or 4 as in Figs. 6-7, 11-12)", passing_factor),
    real!("passing_ship_time", None, false, "Beam-to-beam instant t'_p in ship lengths (004: 7, or 20 in Figs. 6-7)", passing_time),
    real!("white_sigma_n", None, false, "Per-sample std of white N' on the internal grid (004 L 1664: 2e-5)", white_sigma[0])
        .with_range(Some(0.0), None),
    real!("white_sigma_y", None, false, "Per-sample std of white Y' on the internal grid (004 L 1664: 5e-5)", white_sigma[1])
        .with_range(Some(0.0), None),
    real!("shaping_sigma_n", None, false, "Stationary std of the first-order shaping-filter N' (004 eq. 53: 8.798e-5)", shaping_sigma[0])
        .with_range(Some(0.0), None),
    real!("shaping_sigma_y", None, false, "Stationary std of the shaping-filter Y' (004 eq. 54: 21.178e-5)", shaping_sigma[1])
        .with_range(Some(0.0), None),
    real!("shaping_time_constant", None, false, "T_N = T_Y in ship lengths (004 eqs. 39-40: 1)", shaping_time_constant)
        .with_range(Some(1e-6), None),
    real!("walk_q_n", None, false, "Random-walk intensity q of N' per unit t' (004 eq. 67: 2e-8)", walk_q[0])
        .with_range(Some(0.0), None),
    real!("walk_q_y", None, false, "Random-walk intensity q of Y' per unit t' (004 eq. 68: 1.25e-7)", walk_q[1])
        .with_range(Some(0.0), None),
    real!("bias_time_constant", Some("s"), false, "001 bias time constant T (001 eq. 58: 1000 s)", bias_time_constant)
        .with_range(Some(1e-6), None),
    real!("bias_psi_x", None, false, "001 bias noise amplitude Psi, surge [N/sqrt(s)]; not given in 001", bias_psi[0])
        .with_range(Some(0.0), None),
    real!("bias_psi_y", None, false, "001 bias noise amplitude Psi, sway [N/sqrt(s)]", bias_psi[1])
        .with_range(Some(0.0), None),
    real!("bias_psi_n", None, false, "001 bias noise amplitude Psi, yaw [N.m/sqrt(s)]", bias_psi[2])
        .with_range(Some(0.0), None),
    real!("bias_initial_x", Some("N"), false, "Initial earth-fixed bias force, x", bias_initial[0]),
    real!("bias_initial_y", Some("N"), false, "Initial earth-fixed bias force, y", bias_initial[1]),
    real!("bias_initial_n", Some("N.m"), false, "Initial bias yaw moment", bias_initial[2]),
    real!("internal_step", Some("s"), false, "Fixed grid of the random processes (default dt' = 0.005 = 0.2349 s of 004)", internal_step)
        .with_range(Some(1e-6), None),
    V::real_input("heading", Some("rad"), "Ship heading psi (for the body-frame outputs)", |m| m.heading, |m, v| m.heading = v),
    V::real_output("current_north", Some("m/s"), "Earth-fixed current velocity, first axis", |m| m.model.current_velocity()[0]),
    V::real_output("current_east", Some("m/s"), "Earth-fixed current velocity, second axis", |m| m.model.current_velocity()[1]),
    V::real_output("current_surge", Some("m/s"), "Current velocity along the ship, V cos(direction - heading)", |m| m.model.current_body()[0]),
    V::real_output("current_sway", Some("m/s"), "Current velocity to starboard, V sin(direction - heading)", |m| m.model.current_body()[1]),
    V::real_output("n_prime", None, "Total 004 nondimensional yaw moment N'", |m| m.model.disturbance()[0]),
    V::real_output("y_prime", None, "Total 004 nondimensional side force Y'", |m| m.model.disturbance()[1]),
    V::real_output("yaw_moment", Some("N.m"), "N = N' rho L^3 U^2/2", |m| m.model.disturbance_dimensional()[0]),
    V::real_output("side_force", Some("N"), "Y = Y' rho L^2 U^2/2", |m| m.model.disturbance_dimensional()[1]),
    V::real_output("bias_x", Some("N"), "001 earth-fixed bias force, x", |m| m.model.bias()[0]),
    V::real_output("bias_y", Some("N"), "001 earth-fixed bias force, y", |m| m.model.bias()[1]),
    V::real_output("bias_n", Some("N.m"), "001 bias yaw moment", |m| m.model.bias()[2]),
    V::real_output("bias_surge", Some("N"), "001 bias in the body frame, J(psi)^T b, surge", |m| m.model.bias_body()[0]),
    V::real_output("bias_sway", Some("N"), "001 bias in the body frame, sway", |m| m.model.bias_body()[1]),
    V::real_output("nondimensional_time", None, "t' = (t - t0) U/L in ship lengths", |m| m.model.nondimensional_time()),
];

impl FmuModel for CurrentFmu {
    const MODEL_IDENTIFIER: &'static str = "Current";
    const DESCRIPTION: &'static str =
        "Seeded currents and slowly varying disturbances: constant or \
        ramped current (DDG-51 5 kn), Parsons & Cuong (1980) design lateral current, passing ship, \
        white/shaping-filter/random-walk N' and Y', Fossen & Strand (1999) bias";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 1200.0,
        step_size: 0.2349,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.model = Current::new(self.params.clone(), start_time)?;
        self.model.set_heading(self.heading);
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
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
        self.model.set_heading(self.heading);
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.model.set_heading(self.heading);
        self.model.advance_to(t + h);
        Ok(())
    }
}

export_fmu!(CurrentFmu);
