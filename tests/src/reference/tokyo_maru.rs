//! TokyoMaru reference cases (models::hull::tokyo_maru).

use models::hull::tokyo_maru::{TokyoMaru, TokyoMaruInputs};
use std::io::Write;

const OUTPUTS: &str = "heading,yaw_rate,yaw_rate_prime,drift_angle,sway_velocity,cross_track,\
cross_track_prime,x,y,rudder_angle_actual,time_prime";

fn row(out: &mut dyn Write, t: f64, inputs: &[f64], ship: &TokyoMaru) -> std::io::Result<()> {
    let o = ship.outputs();
    write!(out, "{t:?}")?;
    for v in inputs {
        write!(out, ",{v:?}")?;
    }
    writeln!(
        out,
        ",{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
        o.heading,
        o.yaw_rate,
        o.yaw_rate_prime,
        o.drift_angle,
        o.sway_velocity,
        o.cross_track,
        o.cross_track_prime,
        o.x,
        o.y,
        o.rudder,
        o.time_prime
    )
}

/// Default parameters (H/T = 1.89, exact ZOH, actual rudder as input) with moment, force and
/// current inputs; h = 1 s, 600 s.
pub fn design_depth(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 1.0;
    let n = 600;
    let mut ship = TokyoMaru::design_depth();
    writeln!(
        out,
        "time,rudder_angle,yaw_moment_prime,sway_force_prime,current_lateral,{OUTPUTS}"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let u = TokyoMaruInputs {
            rudder: 0.1 * (0.02 * t).sin(),
            yaw_moment_prime: 1e-4 * (0.01 * t).sin(),
            sway_force_prime: 2e-3 * (0.015 * t).cos(),
            current_lateral: 0.3,
        };
        row(
            out,
            t,
            &[
                u.rudder,
                u.yaw_moment_prime,
                u.sway_force_prime,
                u.current_lateral,
            ],
            &ship,
        )?;
        let next = (k + 1) as f64 * h;
        ship.step(&u, next - t);
    }
    Ok(())
}

/// `deep_water = true`, `internal_steering_gear = true`, rudder_command = 0.1 sign(sin(0.02 t));
/// h = 0.5 s, 600 s.
pub fn gear_deep(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.5;
    let n = 1200;
    let mut ship = TokyoMaru::deep_water();
    ship.internal_steering_gear = true;
    writeln!(out, "time,rudder_command,{OUTPUTS}")?;
    for k in 0..=n {
        let t = k as f64 * h;
        let cmd = if (0.02 * t).sin() >= 0.0 { 0.1 } else { -0.1 };
        row(out, t, &[cmd], &ship)?;
        let next = (k + 1) as f64 * h;
        ship.step(
            &TokyoMaruInputs {
                rudder: cmd,
                ..Default::default()
            },
            next - t,
        );
    }
    Ok(())
}
