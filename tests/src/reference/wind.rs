//! Wind reference case: `models::disturbances::wind` with default gusts, seed 4,
//! roll_coefficient 2e3, yaw_coefficient 5e3, wind_direction 1.0 rad; inputs ship_speed =
//! 5 + 0.01 t, heading = 0.5 sin(0.02 t).

use models::disturbances::wind::{Wind, WindParams};
use std::io::Write;

pub fn inputs(t: f64) -> (f64, f64) {
    (5.0 + 0.01 * t, 0.5 * (0.02 * t).sin())
}

/// 300 s at h = 0.1 s.
pub fn gusts(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.1;
    let n = 3000;
    let p = WindParams {
        seed: 4,
        roll_coefficient: 2.0e3,
        yaw_coefficient: 5.0e3,
        direction: 1.0,
        ..WindParams::default()
    };
    let mut w = Wind::new(p, 0.0).expect("valid parameters");
    let (u0, psi0) = inputs(0.0);
    w.set_inputs(u0, psi0);
    writeln!(
        out,
        "time,ship_speed,heading,true_wind_speed,relative_wind_speed,relative_wind_angle,roll_moment,yaw_moment"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let (u, psi) = inputs(t);
        let (vr, g) = w.relative();
        writeln!(
            out,
            "{t:?},{u:?},{psi:?},{:?},{vr:?},{g:?},{:?},{:?}",
            w.true_speed(),
            w.roll_moment(),
            w.yaw_moment()
        )?;
        w.set_inputs(u, psi);
        w.advance_to((k + 1) as f64 * h);
    }
    Ok(())
}
