//! `SteeringGear` FMU: the steering machine of `models::steering_gear` as an FMI 2.0
//! co-simulation FMU. No physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::steering_gear::{ServoOrder, SteeringGear, SteeringGearParams};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Parameters, input and state of one steering-gear instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SteeringGearFmu {
    params: SteeringGearParams,
    initial_angle: f64,
    command: f64,
    gear: SteeringGear,
}

impl Default for SteeringGearFmu {
    fn default() -> Self {
        let params = SteeringGearParams::rrs_klugt1987();
        SteeringGearFmu {
            gear: SteeringGear::new(params.clone(), 0.0).expect("preset parameters are valid"),
            params,
            initial_angle: 0.0,
            command: 0.0,
        }
    }
}

fmi2_export::fmu! {
    SteeringGearFmu => "SteeringGear",
    description: "Steering machine with rudder-angle and rudder-rate limits \
        and first- or second-order servo (van der Klugt 1987 Fig. 2.8 and section 6.5.2; \
        DDG-51 6/(s+6) gear; Parsons-Cuong T_r gear)",
    experiment: (0.0, 30.0, 0.01),
    // rudder_angle and rate_saturated_time are state; the others declare rudder_command.
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        tunable real "angle_max" ["rad"] (params.angle_max).range(0.0, PI),
            "Rudder-angle limit delta_max on the set point and the actual angle ([Klugt1987, Fig. 2.8])";
        tunable real "rate_max" ["rad/s"] (params.rate_max).min(0.0),
            "Rudder-rate limit (max rudder speed), used when rate_limited ([Klugt1987, Fig. 2.8, eq. (6.33)])";
        tunable bool "rate_limited" (params.rate_limited),
            "Rate limiter present (true: the RRS gear of [Klugt1987]; false: the first-order gears of [Taylor2000] and [Parsons1980])";
        tunable real "time_constant" ["s"] (params.time_constant).min(0.0),
            "Servo time constant tau_delta of the first-order servo ([Klugt1987, eq. (6.35)]; [Taylor2000]: L/(6U); [Parsons1980]: T_r = 10 s)";
        fixed int "servo_order" (params.order => { 1: ServoOrder::First, 2: ServoOrder::Second }),
            "1: first-order servo ([Klugt1987, Fig. 2.8, eq. (6.35)]); 2: second-order main servo ([Klugt1987, eqs. (6.41)-(6.42)])";
        tunable real "omega0" ["rad/s"] (params.omega0).min(0.0),
            "Natural frequency omega0 of the second-order servo ([Klugt1987, eq. (6.42)]; >= 10 omega_n, [Klugt1987, eq. (6.43)])";
        tunable real "zeta0" (params.zeta0).min(0.0),
            "Relative damping z0 of the second-order servo ([Klugt1987, eq. (6.44)]: z0 >= 1)";
        fixed real "max_substep" ["s"] (params.max_substep).min(0.0),
            "Largest RK4 sub-step of the second-order servo (the first-order servo is integrated exactly)";
        fixed real "initial_angle" ["rad"] (initial_angle), "Rudder angle at the start time";
        input real "rudder_command" ["rad"] (command),
            "Set-point rudder angle delta_g from the autopilot (positive: starboard turn)";
        output real "rudder_angle" ["rad"] (|m| m.gear.angle()), "Actual rudder angle delta_w";
        output real "rudder_rate" ["rad/s"] (|m| m.gear.rate()).depends_on(&["rudder_command"]),
            "Actual rudder speed d(delta_w)/dt";
        output real "limited_command" ["rad"] (|m| m.gear.limited_command()).depends_on(&["rudder_command"]),
            "Set point after the angle limiter, sat(delta_g, +-angle_max)";
        output bool "command_saturated" (|m| SteeringGear::command_saturated(m.command, &m.gear.params))
            .depends_on(&["rudder_command"]),
            "The set point exceeds angle_max (angle limiter active)";
        output bool "rate_saturated" (|m| m.gear.rate_saturated()).depends_on(&["rudder_command"]),
            "The rate limiter is active";
        output real "rate_saturated_time" ["s"] (|m| m.gear.rate_saturated_time()),
            "Total time the rate limiter has been active since the start (exact, for the RRS statistics of [Klugt1987])";
    }
}

impl FmuModel for SteeringGearFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.gear = SteeringGear::new(self.params.clone(), self.initial_angle)
            .map_err(|e| e.to_string())?;
        self.gear.set_command(self.command);
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.params.validate().map_err(|e| e.to_string())?;
        self.gear.params = self.params.clone();
        self.gear.set_command(self.command);
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.gear.set_command(self.command);
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.gear.step(self.command, h);
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let p = &self.gear.params;
        if p.order == ServoOrder::Second {
            each("max_substep", p.max_substep, passes(h, p.max_substep));
        }
    }
}
