//! DgpsKalman reference cases.
//!
//! `drift_angle` depends directly on the `heading` input: an importer samples it at t_k after
//! the step to t_k, before setting the inputs of row k, so row k (k >= 1) holds it for the
//! heading of row k - 1; row 0 holds it for the heading of row 0 (set before initialization
//! ends). The same holds for the ground- and water-related body velocities and drift angle,
//! which also read the current inputs. The other outputs depend on the filter state only.

use models::observers::dgps_kalman::{DgpsKalman, DgpsKalmanParams};
use std::io::Write;

/// A 7 m/s ship turning at 0.03 rad/s from t = 60 s, with deterministic "noise" of about 2 m
/// on the fixes; heading = course + 0.1 sin(0.02 t); a current of 0.3 + 0.1 sin(0.01 t) m/s
/// toward 1 + 0.2 cos(0.015 t) rad.
fn inputs(t: f64) -> [f64; 5] {
    let (u, r, t0) = (7.0, 0.03, 60.0);
    let (n, e, chi) = if t < t0 {
        (u * t, 0.0, 0.0)
    } else {
        let a = r * (t - t0);
        (u * t0 + u / r * a.sin(), u / r * (1.0 - a.cos()), a)
    };
    [
        n + 2.0 * (1.3 * t).sin(),
        e + 1.5 * (0.7 * t + 0.4).cos(),
        chi + 0.1 * (0.02 * t).sin(),
        0.3 + 0.1 * (0.01 * t).sin(),
        1.0 + 0.2 * (0.015 * t).cos(),
    ]
}

fn case(out: &mut dyn Write, params: DgpsKalmanParams, h: f64, n: usize) -> std::io::Result<()> {
    let mut f = DgpsKalman::new(params, [7.0, 0.0, 0.0, 0.0]).expect("valid preset");
    writeln!(
        out,
        "time,north_measured,east_measured,heading,current_speed,current_direction,\
         velocity_north_estimate,velocity_east_estimate,north_estimate,east_estimate,\
         speed_over_ground,course_over_ground,drift_angle,gain_velocity,gain_position,\
         surge_velocity_ground,sway_velocity_ground,surge_velocity_water,sway_velocity_water,\
         drift_angle_water"
    )?;
    let mut held = inputs(0.0);
    for k in 0..=n {
        let t = k as f64 * h;
        let u = inputs(t);
        let x = f.estimate();
        let (psi, cs, cd) = (held[2], held[3], held[4]);
        let g = f.body_velocity_over_ground(psi);
        let w = f.body_velocity_through_water(psi, cs, cd);
        let row = [
            u[0],
            u[1],
            u[2],
            u[3],
            u[4],
            x[0],
            x[1],
            x[2],
            x[3],
            f.speed_over_ground(),
            f.course_over_ground(),
            f.drift_angle(psi),
            f.steady_gain()[(0, 0)],
            f.steady_gain()[(2, 0)],
            g[0],
            g[1],
            w[0],
            w[1],
            f.drift_angle_through_water(psi, cs, cd),
        ];
        write!(out, "{t:?}")?;
        for v in row {
            write!(out, ",{v:?}")?;
        }
        writeln!(out)?;
        let next = (k + 1) as f64 * h;
        f.step(u[0], u[1], next - t);
        held = u;
    }
    Ok(())
}

/// Default parameters but `initial_velocity_north` = 7 m/s (steady-state form, S_p = 0.01, R = 4 m², Δt = 1 s); h = 1 s, 600 s.
pub fn steady(out: &mut dyn Write) -> std::io::Result<()> {
    case(out, DgpsKalmanParams::default(), 1.0, 600)
}

/// Full recursion from P₀ = 100 I with S_p = 0.1 (`full_recursion` = true,
/// `process_noise_level` = 0.1, `initial_velocity_north` = 7 m/s); h = 2 s (two filter cycles per step), 600 s.
pub fn full_recursion(out: &mut dyn Write) -> std::io::Result<()> {
    let p = DgpsKalmanParams {
        full_recursion: true,
        sp: 0.1,
        ..Default::default()
    };
    case(out, p, 2.0, 300)
}
