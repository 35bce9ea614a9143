//! Robustness Monte-Carlo of the DDG-51 heading autopilot [Taylor2000, sec. 5.2.3.1]:
//! `campaigns/autopilot_robustness.toml`, a 20° heading step with ±20 % on the Nomoto gain K′
//! and time constant T′ and on the initial beam current, 200 runs by Latin hypercube; the
//! distributions of overshoot and settling time. In the report only (`cargo xtask report`).

use crate::study::{Check, Env, Report};
use shipsim::campaign::plot::{self, PlotOptions};
use shipsim::campaign::table::{ColumnData, Table};

fn column(t: &Table, name: &str) -> Result<Vec<f64>, String> {
    match t.column(name) {
        Some(ColumnData::Float(v)) => Ok(v.clone()),
        _ => Err(format!("no float column {name}")),
    }
}

fn min_max(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        })
}

/// Pearson's correlation coefficient.
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

pub fn run(env: &Env) -> Result<Report, String> {
    let result = env.campaign("autopilot_robustness.toml", "autopilot_current.toml")?;
    let (outcome, runs, derived) = (result.outcome, result.runs, result.derived);
    let settling = column(&runs, "settling_time")?;
    let overshoot = column(&derived, "overshoot_deg")?;
    let mut checks = vec![Check::holds(
        "every run completed",
        "200 Latin-hypercube runs",
        format!("{} ran, {} failed", outcome.ran, outcome.failed),
        outcome.ran == 200 && outcome.failed == 0,
    )];
    // The design: one sample in each of the 200 strata of every factor.
    let strata_ok = [
        ("k_prime", 1.632, 2.448),
        ("t_prime", 1.54296, 2.31444),
        ("current_kn", 4.0, 6.0),
    ]
    .iter()
    .all(|(f, lo, hi)| {
        let mut s: Vec<usize> = column(&runs, f)
            .unwrap_or_default()
            .iter()
            .map(|x| ((x - lo) / (hi - lo) * 200.0) as usize)
            .collect();
        s.sort_unstable();
        s == (0..200).collect::<Vec<_>>()
    });
    checks.push(Check::holds(
        "Latin hypercube: every factor has one run in each of its 200 strata",
        "K′ ±20 %, T′ ±20 %, current 5 kn ±20 %",
        format!("{strata_ok}"),
        strata_ok,
    ));
    let (s_lo, s_hi) = min_max(&settling);
    let (o_lo, o_hi) = min_max(&overshoot);
    checks.push(Check::holds(
        "robust: every perturbed hull settles into ±0.5° of the 20° step",
        "[DERIVED] the loop-shaped design of [Taylor2000, sec. 5.2.2] keeps its margins; the ±20 % test is ours",
        format!("settling {s_lo:.1}..{s_hi:.1} s, overshoot {o_lo:.2}..{o_hi:.2}°"),
        settling.iter().all(|t| t.is_finite() && *t < 150.0) && o_hi < 2.0,
    ));
    let mut figures = Vec::new();
    let mut h = PlotOptions::new(env.out_dir.join("settling_histogram.png"));
    h.title = Some("Settling time into ±0.5° over 200 perturbed hulls".into());
    h.x_label = Some("settling time [s]".into());
    plot::histogram(&runs, "settling_time", None, &h).map_err(|e| e.to_string())?;
    figures.push((
        "Distribution of the settling time of the 20° heading step (200 runs)".to_string(),
        h.path,
    ));
    let mut l = PlotOptions::new(env.out_dir.join("overshoot_t_prime.png"));
    l.title = Some("Heading overshoot against the hull's T′".into());
    l.x_label = Some("T′ (nominal 1.9287)".into());
    l.y_label = Some("overshoot [deg]".into());
    plot::line_band(&derived, "t_prime", "overshoot_deg", None, &l).map_err(|e| e.to_string())?;
    figures.push((
        "Overshoot of each run against T′ (one run per point)".to_string(),
        l.path,
    ));
    let corr = |f: &str, k: &[f64]| column(&derived, f).map(|v| correlation(&v, k));
    let note = format!(
        "Correlation of the overshoot with K′, T′ and the current: {:.2}, {:.2}, {:.2}; of the \
         settling time with T′: {:.2}. The autopilot is the nominal design in every run.",
        corr("k_prime", &overshoot)?,
        corr("t_prime", &overshoot)?,
        corr("current_kn", &overshoot)?,
        correlation(&column(&runs, "t_prime")?, &settling),
    );
    Ok(Report {
        id: "autopilot_robustness".into(),
        title: "Campaign: heading autopilot robustness (Monte Carlo)".into(),
        source: "[Taylor2000, sec. 5.2.3.1], the nominal autopilot on perturbed hulls".into(),
        systems: vec![
            "autopilot_current.toml` through `campaigns/autopilot_robustness.toml".into(),
        ],
        checks,
        figures,
        notes: vec![note],
    })
}
