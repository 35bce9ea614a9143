//! DpController reference case.

use models::controllers::dp::{body_error, DpController, DpInputs, DpParams};
use std::io::Write;

/// Default gains (Northern Clipper, ω_b = 0.05 rad/s, ζ = 0.9, r = 10) plus the
/// [Fossen1999, eq. (61)] test input scaled to 1e5; estimates and set points are slow sinusoids and
/// ramps, all zero at t = 0 (so row 0 is the same whether an importer samples before or after
/// setting the first inputs); h = 1 s, 600 s. Columns as in `steering_gear::sine`: the outputs of
/// row k (τ and the error, both with direct feedthrough) were computed with the inputs of row
/// k − 1, held over the step.
pub fn case(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 1.0;
    let n = 600;
    let inputs = |t: f64| DpInputs {
        eta: [
            3.0 * (0.02 * t).sin(),
            2.0 * (0.013 * t).sin(),
            0.3 * (0.01 * t).sin(),
        ],
        nu: [
            0.1 * (0.03 * t).sin(),
            0.02 * (0.05 * t).sin(),
            1e-3 * (0.05 * t).sin(),
        ],
        setpoint: [0.01 * t, -0.005 * t, 0.001 * t],
    };
    let mut p = DpParams::northern_clipper();
    p.test_amplitude = [1e5, 1e5, 1e7];
    let mut c = DpController::new(p, 0.0).expect("preset");
    writeln!(
        out,
        "time,north_estimate,east_estimate,heading_estimate,surge_velocity_estimate,\
         sway_velocity_estimate,yaw_rate_estimate,north_setpoint,east_setpoint,heading_setpoint,\
         tau_surge,tau_sway,tau_yaw,error_surge,error_sway,error_yaw"
    )?;
    let mut held = DpInputs::default();
    for k in 0..=n {
        let t = k as f64 * h;
        let u = inputs(t);
        let (tau, e) = (c.tau(&held), body_error(held.eta, held.setpoint));
        write!(out, "{t:?}")?;
        for v in u.eta.iter().chain(&u.nu).chain(&u.setpoint) {
            write!(out, ",{v:?}")?;
        }
        writeln!(
            out,
            ",{:?},{:?},{:?},{:?},{:?},{:?}",
            tau[0], tau[1], tau[2], e[0], e[1], e[2]
        )?;
        let next = (k + 1) as f64 * h;
        c.step(&u, next - t);
        c.set_time(next);
        held = u;
    }
    Ok(())
}
