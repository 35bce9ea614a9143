//! RrsAutopilot reference case.

use models::controllers::rrs::{RrsAutopilot, RrsAutopilotParams, RrsInputs};
use std::io::Write;

/// Input names in the order of the CSV columns after `time`.
pub const INPUTS: [&str; 7] = [
    "roll",
    "roll_rate",
    "sway_rudder",
    "heading_error",
    "yaw_rate",
    "yaw_offset",
    "speed",
];

fn inputs_at(t: f64) -> [f64; 7] {
    // roll growing from 2 to 12 deg amplitude near the natural frequency: the AGC and the
    // criterion adaptation both act
    let amp = (2.0 + 10.0 * t / 300.0).to_radians();
    [
        amp * (0.63 * t).sin(),
        0.63 * amp * (0.63 * t).cos(),
        0.05 * (0.2 * t).sin(),
        0.02 * (0.01 * t).sin(),
        0.002 * (0.05 * t).cos(),
        -0.001,
        11.0 - 3.0 * t / 300.0,
    ]
}

/// Columns: `time`, the inputs of [`INPUTS`] set at `time` (held until the next row), then the
/// outputs `rudder_command`, `attenuation`, `q_phi`, `roll_gain_1` as an importer samples them
/// before setting that row's inputs (row 0: after initialization, with the row-0 inputs, which
/// FMPy applies in initialization mode). Parameters (set by the Python test too):
/// adaptation_enabled = true, q_phi_initial = 40, rate_max = 0.12 rad/s (about the 7 deg/s of the
/// March 1983 trials). h = 0.1 s, 3000 steps.
pub fn adaptive(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.1;
    let n = 3000;
    let mut p = RrsAutopilotParams::default();
    p.adaptation.enabled = true;
    p.adaptation.q_initial = 40.0;
    p.rate_max = 0.12;
    let mut ap = RrsAutopilot::new(p).expect("valid parameters");
    let set = |u: &mut RrsInputs, x: &[f64; 7]| {
        u.roll = x[0];
        u.roll_rate = x[1];
        u.sway_rudder = x[2];
        u.heading_error = x[3];
        u.yaw_rate = x[4];
        u.yaw_offset = x[5];
        u.speed = x[6];
    };
    let mut u = RrsInputs::default();
    set(&mut u, &inputs_at(0.0));
    write!(out, "time")?;
    for name in INPUTS {
        write!(out, ",{name}")?;
    }
    writeln!(out, ",rudder_command,attenuation,q_phi,roll_gain_1")?;
    for k in 0..=n {
        let t = k as f64 * h;
        let x = inputs_at(t);
        write!(out, "{t:?}")?;
        for v in x {
            write!(out, ",{v:?}")?;
        }
        let o = ap.outputs(&u);
        writeln!(
            out,
            ",{:?},{:?},{:?},{:?}",
            o.rudder_command,
            o.attenuation,
            ap.q_phi(),
            ap.roll_gains(u.speed)[0]
        )?;
        set(&mut u, &x);
        let next = (k + 1) as f64 * h;
        ap.step(&u, next - t);
    }
    Ok(())
}
