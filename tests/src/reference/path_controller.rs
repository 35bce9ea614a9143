//! PathController reference case.

use models::controllers::path::{
    Adaptation, Dither, PathController, PathControllerParams, PathInputs,
};
use std::io::Write;

/// Input names in the order of the CSV columns after `time`.
pub const INPUTS: [&str; 13] = [
    "heading",
    "yaw_rate",
    "drift_angle",
    "cross_track",
    "rudder_angle",
    "yaw_moment_prime",
    "sway_force_prime",
    "f22_estimate",
    "f23_estimate",
    "f25_estimate",
    "f32_estimate",
    "f33_estimate",
    "f35_estimate",
];

fn inputs_at(t: f64) -> [f64; 13] {
    [
        0.03 * (0.01 * t).sin(),
        2e-4 * (0.013 * t).cos(),
        0.02 * (0.007 * t).sin(),
        25.0 * (0.004 * t).cos(),
        0.1 * (0.02 * t).sin(),
        1e-3 * (0.003 * t).sin(),
        2e-3,
        -9.0,
        3.1591 + 0.1 * (0.001 * t).sin(),
        -1.0410,
        0.0,
        0.0,
        0.0,
    ]
}

/// Columns: `time`, the inputs of [`INPUTS`] set at `time` (held until the next row), then
/// `rudder_command`, `gain_yaw_moment`, `design_f23`, `gain_updates` as an importer samples them
/// before setting that row's inputs. Parameters (set by the Python test too): adaptation = 2,
/// dither_enabled, dither_start = 1, dither_window = 1, dither_cycle = 3 (ship lengths).
/// h = 0.5 s, 600 steps (6.4 ship lengths): two dither windows and two partial adaptations.
pub fn adaptive(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.5;
    let n = 600;
    let params = PathControllerParams {
        adaptation: Adaptation::Estimated,
        dither: Dither {
            enabled: true,
            start: 1.0,
            window: 1.0,
            cycle: 3.0,
            ..Dither::default()
        },
        ..Default::default()
    };
    let mut ctl = PathController::new(params).expect("valid design");
    let set = |u: &mut PathInputs, x: &[f64; 13]| {
        u.heading = x[0];
        u.yaw_rate = x[1];
        u.drift_angle = x[2];
        u.cross_track = x[3];
        u.rudder = x[4];
        u.yaw_moment_prime = x[5];
        u.sway_force_prime = x[6];
        u.estimates.copy_from_slice(&x[7..13]);
    };
    // The FMU's default depth_ratio input is the design depth.
    let mut u = PathInputs {
        depth_ratio: params.design_depth_ratio,
        ..PathInputs::default()
    };
    // FMPy applies the row-0 inputs in initialization mode: row 0's outputs see them
    set(&mut u, &inputs_at(0.0));
    ctl.start(&u);
    write!(out, "time")?;
    for name in INPUTS {
        write!(out, ",{name}")?;
    }
    writeln!(
        out,
        ",rudder_command,gain_yaw_moment,design_f23,gain_updates"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let x = inputs_at(t);
        write!(out, "{t:?}")?;
        for v in x {
            write!(out, ",{v:?}")?;
        }
        // outputs before this row's inputs are set: with the previous row's inputs
        writeln!(
            out,
            ",{:?},{:?},{:?},{:?}",
            ctl.command(&u),
            ctl.gains().c[5],
            ctl.coefficients().f23,
            ctl.updates() as f64
        )?;
        set(&mut u, &x);
        let next = (k + 1) as f64 * h;
        ctl.step(&u, next - t).expect("design solves");
    }
    Ok(())
}
