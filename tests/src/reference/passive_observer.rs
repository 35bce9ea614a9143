//! PassiveObserver reference case.

use models::observers::passive_observer::{PassiveObserver, PassiveObserverParams};
use std::io::Write;

/// Default parameters (Northern Clipper, [Fossen1999, eq. (59)] gains, mass-normalised injection);
/// measured position/heading = slow LF motion + 0.9 rad/s wave motion, thrust of
/// [Fossen1999, eq. (61)] scaled by 100; h = 1 s (the paper's 1 Hz), 600 s. Columns as in
/// `steering_gear::sine`.
pub fn case(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 1.0;
    let n = 600;
    let inputs = |t: f64| {
        [
            0.02 * t + 3.0 * (0.9 * t).sin(),
            5.0 * (0.01 * t).sin() - 2.0 * (0.85 * t).cos(),
            0.1 + 0.01 * (0.9 * t).sin(),
            1e5 * (0.05 * t).sin(),
            1e5 * (0.1 * t).sin(),
            1e5 * (0.07 * t).sin(),
        ]
    };
    let mut o =
        PassiveObserver::new(PassiveObserverParams::northern_clipper(), [0.0; 3]).expect("preset");
    writeln!(
        out,
        "time,north_measured,east_measured,heading_measured,tau_surge,tau_sway,tau_yaw,\
         north_estimate,east_estimate,heading_estimate,surge_velocity_estimate,\
         north_wf_estimate,bias_north_estimate,bias_yaw_estimate"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let u = inputs(t);
        let (e, v, w, b) = (o.eta(), o.nu(), o.eta_w(), o.bias_force());
        writeln!(
            out,
            "{t:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
            u[0], u[1], u[2], u[3], u[4], u[5], e[0], e[1], e[2], v[0], w[0], b[0], b[2]
        )?;
        let next = (k + 1) as f64 * h;
        o.step([u[0], u[1], u[2]], [u[3], u[4], u[5]], next - t);
    }
    Ok(())
}
