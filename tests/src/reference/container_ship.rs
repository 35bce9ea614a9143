//! ContainerShip reference cases (models::hull::container_ship).

use models::hull::container_ship::{
    ContainerShip, ContainerShipInputs, ContainerShipOutputs, LinearContainerShip,
    LinearContainerShipInputs,
};
use std::io::Write;

const OUTPUTS: &str = "surge_velocity,sway_velocity,yaw_rate,roll_rate,roll,heading,x,y,\
rudder_angle,shaft_speed,speed,drift_angle,sway_velocity_prime,yaw_rate_prime,roll_rate_prime";

fn outputs(o: &ContainerShipOutputs) -> String {
    [
        o.u,
        o.v,
        o.r,
        o.p,
        o.roll,
        o.heading,
        o.x,
        o.y,
        o.rudder,
        o.shaft_rpm,
        o.speed,
        o.drift_angle,
        o.v_prime,
        o.r_prime,
        o.p_prime,
    ]
    .iter()
    .map(|v| format!("{v:?}"))
    .collect::<Vec<_>>()
    .join(",")
}

/// Inputs of the nonlinear case at time `t`.
pub fn nonlinear_inputs(t: f64) -> ContainerShipInputs {
    ContainerShipInputs {
        rudder_command: 0.3 * (0.05 * t).sin(),
        shaft_command_rpm: 80.0 - 10.0 * (0.01 * t).sin(),
        sway_force_ext: 1e5 * (0.1 * t).sin(),
        roll_moment_ext: 2e6 * (0.5 * t).sin(),
        yaw_moment_ext: -1e6 * (0.02 * t).cos(),
    }
}

/// Default parameters (straight course at the 80 rpm equilibrium); columns as in
/// `steering_gear::sine`: time, the inputs held from `time`, the outputs at `time`.
/// h = 0.1 s, 300 s.
pub fn nonlinear(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.1;
    let n = 3000;
    let mut ship = ContainerShip::at_equilibrium(80.0).expect("valid preset");
    writeln!(
        out,
        "time,rudder_command,shaft_speed_command,sway_force,roll_moment,yaw_moment,{OUTPUTS}"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let u = nonlinear_inputs(t);
        writeln!(
            out,
            "{t:?},{:?},{:?},{:?},{:?},{:?},{}",
            u.rudder_command,
            u.shaft_command_rpm,
            u.sway_force_ext,
            u.roll_moment_ext,
            u.yaw_moment_ext,
            outputs(&ship.outputs())
        )?;
        let next = (k + 1) as f64 * h;
        ship.step(&u, next - t);
    }
    Ok(())
}

/// `variant = 2` (linearised model at U0 = 7 m/s), rudder_command = 0.2 sin(0.03 t),
/// h = 0.25 s, 300 s.
pub fn linear(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.25;
    let n = 1200;
    let mut ship = LinearContainerShip::mss_default();
    writeln!(out, "time,rudder_command,{OUTPUTS}")?;
    for k in 0..=n {
        let t = k as f64 * h;
        let cmd = 0.2 * (0.03 * t).sin();
        writeln!(out, "{t:?},{cmd:?},{}", outputs(&ship.outputs()))?;
        let next = (k + 1) as f64 * h;
        ship.step(
            &LinearContainerShipInputs {
                rudder_command: cmd,
            },
            next - t,
        );
    }
    Ok(())
}
