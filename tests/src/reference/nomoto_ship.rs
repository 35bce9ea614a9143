//! NomotoShip reference cases (models::hull::nomoto).

use models::hull::nomoto::{NomotoInputs, NomotoShip};
use std::io::Write;

fn case(
    out: &mut dyn Write,
    mut ship: NomotoShip,
    h: f64,
    n: usize,
    input: impl Fn(f64) -> NomotoInputs,
) -> std::io::Result<()> {
    writeln!(
        out,
        "time,rudder_angle,current_speed,current_direction,yaw_disturbance,sway_velocity,sway_velocity_prime,\
         yaw_rate,yaw_rate_prime,heading,x,y,speed_over_ground,time_prime"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let u = input(t);
        let o = ship.outputs();
        writeln!(
            out,
            "{t:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
            u.rudder,
            u.current_speed,
            u.current_direction,
            u.yaw_disturbance,
            o.sway_velocity,
            o.v_prime,
            o.yaw_rate,
            o.r_prime,
            o.heading,
            o.x,
            o.y,
            o.speed_over_ground,
            o.time_prime
        )?;
        let next = (k + 1) as f64 * h;
        ship.step(&u, next - t);
    }
    Ok(())
}

/// `model = 1` (DDG-51 Nomoto), rudder 0.1 sin(0.05 t), current 0.5 m/s toward 1 rad,
/// rudder-equivalent disturbance 0.02 sin(0.4 t); h = 0.1 s, 300 s.
pub fn ddg51(out: &mut dyn Write) -> std::io::Result<()> {
    case(out, NomotoShip::ddg51(), 0.1, 3000, |t| NomotoInputs {
        rudder: 0.1 * (0.05 * t).sin(),
        current_speed: 0.5,
        current_direction: 1.0,
        yaw_disturbance: 0.02 * (0.4 * t).sin(),
    })
}

/// `model = 2` (Esso Osaka sway-yaw), rudder 0.1 sin(0.02 t); h = 0.5 s, 600 s.
pub fn esso_osaka(out: &mut dyn Write) -> std::io::Result<()> {
    case(out, NomotoShip::esso_osaka(), 0.5, 1200, |t| NomotoInputs {
        rudder: 0.1 * (0.02 * t).sin(),
        ..Default::default()
    })
}
