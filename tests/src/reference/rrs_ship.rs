//! RrsShip reference cases (models::hull::rrs_ship).

use models::hull::rrs_ship::{RrsShip, RrsShipInputs, U_22KN};
use std::io::Write;

fn case(
    out: &mut dyn Write,
    mut ship: RrsShip,
    speed: impl Fn(f64) -> f64,
    waves: bool,
) -> std::io::Result<()> {
    let h = 0.05;
    let n = 4000;
    write!(
        out,
        "time,rudder_angle,speed,roll_disturbance,yaw_disturbance,"
    )?;
    if waves {
        write!(out, "wave_elevation,")?;
    }
    writeln!(
        out,
        "roll,roll_rate,sway,yaw_rate,heading,x,y,wave_sway,wave_yaw,wave_roll"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let u = RrsShipInputs {
            rudder: 0.1 * (0.3 * t).sin(),
            speed: speed(t),
            roll_disturbance: 0.01 * (0.2 * t).sin(),
            yaw_disturbance: 0.005 * (0.1 * t).cos(),
            wave_elevation: if waves {
                0.5 * (0.64 * t).sin() + 0.3 * (0.9 * t).sin()
            } else {
                0.0
            },
        };
        write!(
            out,
            "{t:?},{:?},{:?},{:?},{:?},",
            u.rudder, u.speed, u.roll_disturbance, u.yaw_disturbance
        )?;
        if waves {
            write!(out, "{:?},", u.wave_elevation)?;
        }
        let o = ship.outputs();
        writeln!(
            out,
            "{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
            o.roll,
            o.roll_rate,
            o.sway,
            o.yaw_rate,
            o.heading,
            o.x,
            o.y,
            o.wave_sway,
            o.wave_yaw,
            o.wave_roll
        )?;
        let next = (k + 1) as f64 * h;
        ship.step(&u, next - t);
    }
    Ok(())
}

/// `model = 1` (22 kn simulation model) with wave height and disturbances; h = 0.05 s, 200 s.
pub fn simulation(out: &mut dyn Write) -> std::io::Result<()> {
    case(out, RrsShip::simulation_22kn(), |_| U_22KN, true)
}

/// `model = 2` (control model, [Klugt1987, Table 2.4]) with a slowly increasing speed; h = 0.05 s,
/// 200 s.
pub fn control(out: &mut dyn Write) -> std::io::Result<()> {
    case(out, RrsShip::control_model(), |t| 8.0 + 0.02 * t, false)
}
