//! Current reference case: `models::disturbances::current` with the parameters the Python test
//! gives the `Current` FMU (see [`params`]), heading input 0.2 sin(0.01 t).

use models::disturbances::current::{Current, CurrentParams, KNOT};
use std::io::Write;

/// The case's parameters (the Python test sets the same start values).
pub fn params() -> CurrentParams {
    CurrentParams {
        seed: 6,
        speed_final: 5.0 * KNOT,
        direction: std::f64::consts::FRAC_PI_2,
        t_start: 30.0,
        design_current: true,
        passing_factor: 4.0,
        passing_time: 20.0,
        white_sigma: [2e-5, 0.0],
        shaping_sigma: [0.0, 21.178e-5],
        walk_q: [0.0, 1.25e-7],
        bias_psi: [10.0, 0.0, 0.0],
        bias_initial: [0.0, 0.0, 1.0e5],
        ..CurrentParams::default()
    }
}

/// 1200 s at h = 0.5 s (t' up to 25.5: the 4x passing ship at t' = 20 on the ramp of
/// [Parsons1980, Fig. 4]).
pub fn disturbances_parsons1980(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.5;
    let n = 2400;
    let heading = |t: f64| 0.2 * (0.01 * t).sin();
    let mut c = Current::new(params(), 0.0).expect("valid parameters");
    c.set_heading(heading(0.0));
    writeln!(
        out,
        "time,heading,current_sway,n_prime,y_prime,yaw_moment,side_force,bias_surge,bias_n"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let psi = heading(t);
        let [n_p, y_p] = c.disturbance();
        let [nd, yd] = c.disturbance_dimensional();
        writeln!(
            out,
            "{t:?},{psi:?},{:?},{n_p:?},{y_p:?},{nd:?},{yd:?},{:?},{:?}",
            c.current_body()[1],
            c.bias_body()[0],
            c.bias()[2]
        )?;
        c.set_heading(psi);
        c.advance_to((k + 1) as f64 * h);
    }
    Ok(())
}
