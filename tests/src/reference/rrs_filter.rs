//! RrsFilter reference case.

use models::observers::rrs_filter::{
    RollFilterParams, RrsFilter, RrsFilterInputs, SpeedFilterParams, YawFilterParams,
};
use std::io::Write;

/// Default parameters (T = 0.1 s, [Klugt1987, Table 2.4] at 11 m/s, roll (q1, q2) = (10, 0.001),
/// realised yaw filter with adaptive E[w3^2], L speed filter); analytic inputs; h = 0.25 s (3
/// samples per step), 300 s. Columns as in `steering_gear::sine`.
pub fn case(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.25;
    let n = 1200;
    let inputs = |t: f64| RrsFilterInputs {
        roll: 0.1 * (0.63 * t).sin() + 0.02,
        heading: 0.05 * (0.02 * t).sin() + 0.01 * (0.9 * t).sin(),
        speed: 11.0 + 4.0 * (0.01 * t).sin() + 0.5 * (1.7 * t).sin(),
        roll_rudder: 0.01 * (0.63 * t).cos(),
        course_rudder: 0.02 * (0.01 * t).cos(),
    };
    let mut f = RrsFilter::new(
        RollFilterParams::table_2_4(11.0, 10.0, 0.001),
        YawFilterParams::realised(11.0),
        SpeedFilterParams::realised(),
        0.1,
        11.0,
    )
    .expect("preset");
    writeln!(
        out,
        "time,roll_measured,heading_measured,speed_measured,roll_rudder,course_rudder,\
         roll_estimate,roll_rate_estimate,heel_offset_estimate,heading_estimate,\
         yaw_rate_estimate,yaw_bias_estimate,yaw_e_w3_used,yaw_k1,speed_estimate"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let u = inputs(t);
        let r = f.roll.state();
        let y = f.yaw.state();
        writeln!(
            out,
            "{t:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
            u.roll,
            u.heading,
            u.speed,
            u.roll_rudder,
            u.course_rudder,
            r[0],
            r[1],
            r[2],
            y[0],
            y[1],
            y[2],
            f.yaw.e_w3(),
            f.yaw.gains()[0],
            f.speed.estimate()
        )?;
        let next = (k + 1) as f64 * h;
        f.step(&u, next - t);
    }
    Ok(())
}
