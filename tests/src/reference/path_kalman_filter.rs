//! PathKalmanFilter reference case.

use models::hull::tokyo_maru::{L, U};
use models::observers::path_kalman::{PathKalmanConfig, PathKalmanFilter};
use std::io::Write;

/// Default parameters (random-walk design at H/T = 1.89, [Parsons1980, Table 5] gains); measured
/// heading, yaw rate and cross-track and a square-wave rudder command as functions of time;
/// h = 0.25 s (two Euler sub-steps, as ceil(0.25 / 0.2349) = 2), 300 s. Columns as in
/// `steering_gear::sine` (inputs at `time`, outputs sampled before the step).
pub fn case(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.25;
    let n = 1200;
    let inputs = |t: f64| {
        let cmd = if (t / 60.0).floor() as i64 % 2 == 0 {
            0.05
        } else {
            -0.05
        };
        [
            0.02 * (0.03 * t).sin(),
            0.0006 * (0.03 * t).cos(),
            5.0 + 0.02 * t,
            cmd,
        ]
    };
    let design = PathKalmanConfig::default().design().expect("preset");
    let mut f = PathKalmanFilter::new(design, [0.0; 7]).expect("preset");
    writeln!(
        out,
        "time,heading_measured,yaw_rate_measured,cross_track_measured,rudder_command,\
         heading_estimate,yaw_rate_estimate,drift_angle_estimate,cross_track_estimate,\
         yaw_moment_prime_estimate,sway_force_prime_estimate,innovation_cross_track"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let u = inputs(t);
        let x = *f.estimate();
        writeln!(
            out,
            "{t:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
            u[0],
            u[1],
            u[2],
            u[3],
            x[0],
            x[1] * (U / L),
            x[2],
            x[3] * L,
            x[5],
            x[6],
            f.innovation()[2] * L
        )?;
        let next = (k + 1) as f64 * h;
        f.step(u[0], u[1], u[2], u[3], next - t);
    }
    Ok(())
}
