//! ParameterEkf reference case.

use models::hull::nomoto::esso_osaka_assumed_m_b;
use models::hull::nomoto::{NomotoInputs, NomotoShip};
use models::hull::DEG;
use models::manoeuvre::{ManoeuvreGenerator, ManoeuvreKind};
use models::observers::parameter_ekf::{ParameterEkf, ParameterEkfParams};
use std::io::Write;

/// The FMU's default parameters (Esso Osaka preset, [Taylor2000, Table 4.1] noise,
/// x̂₀ = 0.5 × [Taylor2000, Table 2.3],
/// n₀ = 80 rpm, sample interval 1 s). Inputs: the Esso Osaka linear model (`NomotoShip`) in a
/// 10/10 zig-zag executed at 0 with the rudder stepped (held over each step), its u = U, v and
/// r at `time` and n = 80 rpm + 0.5 sin(0.1 t); h = 0.5 s (an update every second step),
/// 900 s. Columns as in `steering_gear::sine` (outputs depend on the state only).
pub fn case(out: &mut dyn Write) -> std::io::Result<()> {
    let (h, n) = (0.5, 1800);
    let (m, b) = esso_osaka_assumed_m_b();
    let mut ship = NomotoShip::esso_osaka();
    let (l, u) = (ship.length, ship.speed);
    let c = [0.0244, 0.0138, 1.4578e-3, 8.093e-4].map(|x: f64| 0.5 * x);
    let params = ParameterEkfParams::table_4_1(l, u, 80.0, m, b, c);
    let mut f = ParameterEkf::new(params, 0.0).expect("valid preset");
    let mut gen = ManoeuvreGenerator::new(
        ManoeuvreKind::ZigZag {
            rudder: 10.0 * DEG,
            check: 10.0 * DEG,
        },
        0.0,
        0.0,
    );
    writeln!(
        out,
        "time,surge_velocity_measured,sway_velocity_measured,yaw_rate_measured,\
         shaft_speed_measured,rudder_angle,surge_velocity_estimate,sway_velocity_estimate,\
         yaw_rate_estimate,shaft_speed_estimate,neg_y_v_estimate,m_minus_y_r_estimate,\
         neg_n_v_estimate,mxg_minus_n_r_estimate,neg_y_v_mean,m_minus_y_r_mean,neg_n_v_mean,\
         mxg_minus_n_r_mean,neg_y_v_std,neg_n_v_std,nomoto_time_constant_prime,\
         nomoto_gain_prime,innovation_sway,innovation_yaw_rate,update_count"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let o = ship.outputs();
        let delta = gen.command(t, o.heading, o.yaw_rate);
        let z = [u, o.sway_velocity, o.yaw_rate, 80.0 + 0.5 * (0.1 * t).sin()];
        let s = f.dimensional_states();
        let p = f.coefficients();
        let a = f.averaged_coefficients();
        let (tn, kn) = f.identified_nomoto();
        let cov = f.covariance();
        let inn = f.innovation();
        let row = [
            z[0],
            z[1],
            z[2],
            z[3],
            delta,
            s[0],
            s[1],
            s[2],
            s[3],
            p[0],
            p[1],
            p[2],
            p[3],
            a[0],
            a[1],
            a[2],
            a[3],
            cov[(4, 4)].max(0.0).sqrt(),
            cov[(6, 6)].max(0.0).sqrt(),
            tn,
            kn,
            inn[1],
            inn[2],
            f.updates() as f64,
        ];
        write!(out, "{t:?}")?;
        for v in row {
            write!(out, ",{v:?}")?;
        }
        writeln!(out)?;
        let next = (k + 1) as f64 * h;
        f.step(t, next - t, z, delta);
        ship.step(
            &NomotoInputs {
                rudder: delta,
                ..Default::default()
            },
            next - t,
        );
    }
    Ok(())
}
