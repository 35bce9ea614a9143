//! PathWlsEstimator reference case.

use models::controllers::path::UpdateDecision;
use models::controllers::wls::{WlsEstimator, WlsSchedule, WlsSettings};
use models::hull::tokyo_maru::{TokyoMaruCoefficients, L, TABLE_2, T_R, U};
use std::io::Write;

/// The FMU's parameters for this case (set as start values by the Python test).
pub const WINDOW_START: f64 = 0.5;
pub const WINDOW_LENGTH: f64 = 1.0;
pub const UPDATE_CYCLE: f64 = 1.5;

/// The Tokyo Maru in deep water under the constant disturbance N′ = 0.0010262, Y′ = 0.0023277
/// (Euler at Δt′ = hU/L, internal steering gear) from the line-1145 equilibrium, under a ±0.5 rad
/// dither of period 0.5 L throughout, sampled every h = 0.25 s (exact in libcosim's integer-ns
/// clock) as the PathWlsEstimator's inputs; the measurements carry a deterministic perturbation
/// (1e-4 sin) so that the fits do not end at zero cost, the estimate inputs a smaller one. The FMU
/// runs with window_start = 0.5, window_length = 1.0, update_cycle = 1.5 (three fits in 870 steps,
/// 4.6 L) and its other defaults (first search from the [Parsons1980, Table 2] values at 1.89).
/// Columns: `time`, the inputs (set at `time`), then the outputs as sampled before that row's
/// inputs.
pub fn windows(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.25;
    let n = 870;
    let truth = TABLE_2[4];
    let (f, g, gam) = truth.eq11(T_R);
    let w = [0.0010262, 0.0023277];
    let mut x = [-0.1428, 0.0, -0.1428, 0.0, 0.1310];
    let g89 = TokyoMaruCoefficients::at_depth_ratio(1.89);
    let settings = WlsSettings {
        dt: 0.005,
        gamma: [g89.g21, g89.g22, g89.g31, g89.g32],
        weight: [1.2976e-9, 7.7215e-10, 8.2777e-10, 5.0651e-9].map(|r: f64| 1.0 / r),
        max_evaluations: 2000,
    };
    let schedule = WlsSchedule {
        window_start: WINDOW_START,
        window_length: WINDOW_LENGTH,
        update_cycle: UPDATE_CYCLE,
    };
    let p0 = [
        g89.f22, g89.f23, g89.f25, g89.f32, g89.f33, g89.f35, 0.0, 0.0,
    ];
    let mut est = WlsEstimator::new(settings, schedule, p0).expect("valid settings");
    writeln!(
        out,
        "time,heading,yaw_rate,drift_angle,cross_track,rudder_angle,heading_estimate,\
         yaw_rate_estimate,drift_angle_estimate,cross_track_estimate,f22_estimate,f23_estimate,\
         f25_estimate,f32_estimate,f33_estimate,f35_estimate,yaw_moment_prime_estimate,\
         sway_force_prime_estimate,estimate_valid,validity,evaluations,final_cost,\
         residual_sum_of_squares,updates,loading"
    )?;
    let ul = U / L;
    for k in 0..=n {
        let t = k as f64 * h;
        let kf = k as f64;
        let e = |i: f64, a: f64| a * (1.7 * kf + i).sin();
        let z = [
            x[0] + e(0.0, 1e-4),
            (x[1] + e(1.0, 1e-4)) * ul,
            x[2] + e(2.0, 1e-4),
            (x[3] + e(3.0, 1e-4)) * L,
        ];
        let xh = [
            x[0] + e(4.0, 2e-5),
            (x[1] + e(5.0, 2e-5)) * ul,
            x[2] + e(6.0, 2e-5),
            (x[3] + e(7.0, 2e-5)) * L,
        ];
        let rudder = x[4];
        write!(out, "{t:?}")?;
        for v in z.iter().chain([rudder].iter()).chain(xh.iter()) {
            write!(out, ",{v:?}")?;
        }
        for v in est.estimate() {
            write!(out, ",{v:?}")?;
        }
        let d = est.decision();
        let code = match d {
            UpdateDecision::None => 0.0,
            UpdateDecision::F23F25 => 1.0,
            UpdateDecision::All => 2.0,
        };
        writeln!(
            out,
            ",{},{code:?},{:?},{:?},{:?},{:?},{}",
            u8::from(d != UpdateDecision::None),
            est.evaluations() as f64,
            est.cost(),
            est.sum_of_squares(),
            est.updates() as f64,
            u8::from(est.loading())
        )?;
        // the FMU's do_step: one sample at the step start, t′ = t U/L, Δt′ = h U/L
        let step = (k + 1) as f64 * h - t;
        let prime = |v: &[f64; 4]| [v[0], v[1] * L / U, v[2], v[3] / L];
        est.sample(t * ul, step * ul, prime(&z), rudder, prime(&xh))
            .map_err(|e| std::io::Error::other(e.to_string()))?;
        // plant: Euler at Δt′ = h U/L with the dither command
        let dtp = h * ul;
        let u = if ((kf * dtp / 0.25).floor() as i64) % 2 == 0 {
            -0.5
        } else {
            0.5
        };
        let dx: [f64; 5] = std::array::from_fn(|i| {
            (0..5).map(|j| f[(i, j)] * x[j]).sum::<f64>()
                + g[i] * u
                + gam[(i, 0)] * w[0]
                + gam[(i, 1)] * w[1]
        });
        for i in 0..5 {
            x[i] += dx[i] * dtp;
        }
    }
    Ok(())
}
