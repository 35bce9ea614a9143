//! Steering machine requirements through the master [Klugt1987, secs. 2.3, 6.5.2]:
//! the classification rule (35° port to 35° starboard within 30 s at 2.5 deg/s) and the RRS gear.

use crate::study::{col, max_abs, series, Check, Env, Report};
use models::hull::DEG;
use shipsim::plot::Panel;

/// Time from the hard-over order (t = 5 s) until the angle is within `eps` of +35°.
fn arrival(t: &[f64], angle: &[f64], eps: f64) -> Option<f64> {
    t.iter()
        .zip(angle)
        .find(|(_, a)| (**a - 35.0 * DEG).abs() < eps)
        .map(|(t, _)| t - 5.0)
}

pub fn run(env: &Env) -> Result<Report, String> {
    let file = "steering_gear_classification.toml";
    let table = env.run(file, &[], "classification.csv")?;
    let t = table.time();
    let slow = col(&table, "slow.rudder_angle")?;
    let fast = col(&table, "rrs.rudder_angle")?;
    let eps = 0.01 * DEG;
    let tau = 0.2;
    // Closed form of the exact piecewise solution (ramp at the rate limit, then the
    // exponential tail of the first-order servo): (70° − δ̇τ)/δ̇ + τ ln(δ̇τ/ε).
    let expected = |rate: f64| (70.0 * DEG - rate * tau) / rate + tau * (rate * tau / eps).ln();
    let t_slow = arrival(t, slow, eps).ok_or("slow gear never reached 35 deg")?;
    let t_fast = arrival(t, fast, eps).ok_or("RRS gear never reached 35 deg")?;
    let h = 0.01;
    let mut report = Report {
        id: "steering_gear".into(),
        title: "Steering machine: classification rule and RRS gear".into(),
        source: "van der Klugt (1987) §2.3, §6.5.2 (seed 003)".into(),
        systems: vec![file.into()],
        ..Default::default()
    };
    report.checks.push(Check::range(
        "35° port to 35° starboard, 2.5 deg/s gear",
        "within 30 s (classification rule)",
        t_slow,
        0.0,
        30.0,
        "s",
    ));
    report.checks.push(Check::abs(
        "same, against the closed-form solution [derived]",
        expected(2.5 * DEG),
        t_slow,
        h,
        "s",
    ));
    report.checks.push(Check::abs(
        "35° port to 35° starboard, 15 deg/s RRS gear [derived]",
        expected(15.0 * DEG),
        t_fast,
        h,
        "s",
    ));
    let peak = max_abs(col(&table, "rrs.rudder_rate")?);
    report.checks.push(Check::abs(
        "peak rudder rate of the RRS gear",
        15.0,
        peak / DEG,
        1e-9,
        "deg/s",
    ));
    let fig = env.figure(
        "classification.png",
        "Hard over 35 deg port to 35 deg starboard: 2.5 deg/s vs 15 deg/s gear",
        &[
            Panel {
                y_label: "rudder angle [deg]".into(),
                series: vec![
                    series(&table, "slow.rudder_angle", "2.5 deg/s", 1.0 / DEG)?,
                    series(&table, "rrs.rudder_angle", "15 deg/s", 1.0 / DEG)?,
                ],
            },
            Panel {
                y_label: "rudder rate [deg/s]".into(),
                series: vec![
                    series(&table, "slow.rudder_rate", "2.5 deg/s", 1.0 / DEG)?,
                    series(&table, "rrs.rudder_rate", "15 deg/s", 1.0 / DEG)?,
                ],
            },
        ],
    )?;
    report
        .figures
        .push(("Hard-over manoeuvre of two steering gears".into(), fig));
    report.notes.push(
        "Servo time constant τ_δ = 0.2 s (rule τ_δ ≤ 0.2/ω_n, eq. 6.37); arrival = first sample \
         within 0.01° of 35°, so the tolerance is one communication step (0.01 s)."
            .into(),
    );
    Ok(report)
}
