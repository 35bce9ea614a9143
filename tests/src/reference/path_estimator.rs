//! PathEstimator reference case.

use models::controllers::mve::{parameters_of, Mve, MveParams};
use models::hull::tokyo_maru::{TokyoMaruCoefficients, L, TABLE_2, T_R, U};
use std::io::Write;

/// The Tokyo Maru at H/T = 1.89 (Euler, Δt′ = 0.005, internal steering gear) under a ±0.5 rad
/// dither of period 0.5 L, noise-free, sampled every h = 0.25 s (Δt′ = 0.00532; a step exact in
/// libcosim's integer-ns clock, unlike the report's 0.2349 s) as the PathEstimator's inputs;
/// 600 steps (3.2 L, 59 estimates) from the deep-water estimate (the
/// FMU's default `initial_depth_ratio` = 1e300). Columns: `time`, the inputs `heading`,
/// `yaw_rate`, `drift_angle`, `cross_track`, `rudder_angle` (set at `time`), then the six
/// estimates as sampled before that row's inputs.
pub fn dither(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.25;
    let n = 600;
    let (f, g, _) = TABLE_2[2].eq11(T_R);
    let mut x = [0.0f64; 5];
    let mut mve = Mve::new(
        MveParams::default(),
        parameters_of(&TokyoMaruCoefficients::at_depth_ratio(1e300)),
    )
    .expect("valid settings");
    writeln!(
        out,
        "time,heading,yaw_rate,drift_angle,cross_track,rudder_angle,\
         f22_estimate,f23_estimate,f25_estimate,f32_estimate,f33_estimate,f35_estimate"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let inputs = [x[0], x[1] * U / L, x[2], x[3] * L, x[4]];
        write!(out, "{t:?}")?;
        for v in inputs {
            write!(out, ",{v:?}")?;
        }
        for v in mve.estimate() {
            write!(out, ",{v:?}")?;
        }
        writeln!(out)?;
        // the FMU's do_step: Δt′ = h U/L, one sample at the step start
        let step = (k + 1) as f64 * h - t;
        let dt = step * U / L;
        if (dt - mve.params.dt).abs() > 1e-12 * dt {
            mve.set_dt(dt).expect("valid step");
        }
        mve.sample(
            [inputs[0], inputs[1] * L / U, inputs[2], inputs[3] / L],
            inputs[4],
        );
        // plant: Euler at Δt′ = h U/L with the dither command
        let dtp = h * U / L;
        let tp = k as f64 * dtp;
        let u = if ((tp / 0.25).floor() as i64) % 2 == 0 {
            -0.5
        } else {
            0.5
        };
        let dx: [f64; 5] =
            std::array::from_fn(|i| (0..5).map(|j| f[(i, j)] * x[j]).sum::<f64>() + g[i] * u);
        for i in 0..5 {
            x[i] += dx[i] * dtp;
        }
    }
    Ok(())
}
