//! Mariner reference case (models::hull::mariner).

use models::hull::mariner::{Mariner, MarinerInputs, U0_DEFAULT};
use std::io::Write;

/// Default parameters (trimmed straight course at 15 kn), rudder_command = trim + 0.3 sin(0.04 t);
/// columns as in `steering_gear::sine`. h = 0.1 s, 300 s.
pub fn trimmed(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.1;
    let n = 3000;
    let trim = Mariner::trim_input(U0_DEFAULT);
    let mut ship = Mariner::trimmed(U0_DEFAULT).expect("valid preset");
    writeln!(
        out,
        "time,rudder_command,surge_velocity,surge_perturbation,sway_velocity,yaw_rate,heading,x,y,\
         rudder_angle,speed,drift_angle,surge_perturbation_prime,sway_velocity_prime,yaw_rate_prime"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let cmd = trim + 0.3 * (0.04 * t).sin();
        let o = ship.outputs();
        writeln!(
            out,
            "{t:?},{cmd:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
            o.u,
            o.delta_u,
            o.v,
            o.r,
            o.heading,
            o.x,
            o.y,
            o.rudder,
            o.speed,
            o.drift_angle,
            o.u_prime,
            o.v_prime,
            o.r_prime
        )?;
        let next = (k + 1) as f64 * h;
        ship.step(
            &MarinerInputs {
                rudder_command: cmd,
            },
            next - t,
        );
    }
    Ok(())
}
