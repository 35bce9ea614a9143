//! The RRS polar: `campaigns/rrs_polar.toml` run as a campaign (540 runs: 9 wave directions ×
//! 3 significant wave heights × 10 seeds × RRS off/on, sharing a 200 s warm-up per seed and
//! wave height), its roll reduction as a polar plot and a table, and the trends of
//! [Klugt1987] checked over the seeds. In the report only (`cargo xtask report`); the test
//! suite runs the reduced campaign (master/tests/campaign.rs).

use crate::study::{Check, Env, Report};
use shipsim::campaign::execute;
use shipsim::campaign::plot::{self, PlotOptions, Stats};

/// The seed mean and 5–95 % spread of the roll reduction at (direction, H_s).
fn cell(agg: &plot::Aggregate, hs: f64, dir: f64) -> Result<Stats, String> {
    let series = agg
        .series
        .iter()
        .find(|s| s.group.as_deref().and_then(|g| g.parse::<f64>().ok()) == Some(hs))
        .ok_or(format!("no H_s = {hs} m in the table"))?;
    series
        .points
        .iter()
        .find(|(d, _)| *d == dir)
        .map(|(_, s)| *s)
        .ok_or(format!("no direction {dir} deg at H_s = {hs} m"))
}

pub fn run(env: &Env) -> Result<Report, String> {
    let result = env.campaign("rrs_polar.toml", "rrs.toml")?;
    let (outcome, runs, derived) = (result.outcome, result.runs, result.derived);
    let agg = plot::aggregate(&derived, "direction_deg", "roll_reduction", Some("hs"))
        .map_err(|e| e.to_string())?;
    let red = |hs: f64, dir: f64| cell(&agg, hs, dir);
    let mut checks = Vec::new();
    checks.push(Check::holds(
        "every run completed",
        "540 runs (9 directions x 3 H_s x 10 seeds x 2 arms)",
        format!("{} ran, {} failed", outcome.ran, outcome.failed),
        outcome.ran == 540 && outcome.failed == 0 && runs.rows() == 540,
    ));
    let (b90, q60) = (red(3.0, 90.0)?, red(3.0, 60.0)?);
    checks.push(Check::holds(
        "beam seas (90°, H_s = 3 m): seed spread covers the Table 7.1 study",
        "72.1 % in the Table 7.1 study (seed 1; thesis 78 %, [Klugt1987, Table 7.1])",
        format!(
            "mean {:.1} %, 5–95 % {:.1}..{:.1} %",
            b90.mean, b90.p05, b90.p95
        ),
        b90.p05 <= 72.1 && 72.1 <= b90.p95,
    ));
    checks.push(Check::holds(
        "quartering following seas (60°) clearly worse than beam seas, at every H_s",
        "following seas: RRS very difficult (R7) [Klugt1987, ch. 7]",
        format!("H_s = 3 m: {:.1} % at 60° vs {:.1} % at 90°", q60.mean, b90.mean),
        [2.0, 3.0, 4.0].iter().all(|hs| {
            matches!((red(*hs, 60.0), red(*hs, 90.0)), (Ok(a), Ok(b)) if a.mean < b.mean - 15.0)
        }),
    ));
    let (f30, h150) = (red(3.0, 30.0)?, red(3.0, 150.0)?);
    checks.push(Check::holds(
        "oblique seas (30°, 150°): little roll, little reduction",
        "γ = 120°: adaptive reduction small (R4)",
        format!(
            "H_s = 3 m: {:.1} % at 30°, {:.1} % at 150°",
            f30.mean, h150.mean
        ),
        f30.mean < 25.0 && h150.mean < 25.0,
    ));
    let mut figures = Vec::new();
    let mut polar = PlotOptions::new(env.out_dir.join("rrs_polar.png"));
    polar.title = Some("RRS roll reduction over wave direction (10 seeds per point)".into());
    polar.x_label = Some("wave direction γ [deg] (0 following, 90 beam)".into());
    polar.y_label = Some("roll reduction [%]".into());
    polar.group_label = Some("H_s [m]".into());
    plot::polar(
        &derived,
        "direction_deg",
        "roll_reduction",
        Some("hs"),
        &polar,
    )
    .map_err(|e| e.to_string())?;
    figures.push(("Roll reduction 100 (1 − σ²_φ,on / σ²_φ,off) over the wave direction, mean and 5–95 % band over 10 seeds".to_string(), polar.path));
    Ok(Report {
        id: "rrs_polar".into(),
        title: "Campaign: RRS roll reduction polar".into(),
        source: "[Klugt1987], experiment 1 of Table 7.1 swept over direction and sea state".into(),
        systems: vec!["rrs.toml` through `campaigns/rrs_polar.toml".into()],
        checks,
        figures,
        notes: vec![table_note(&agg), grouping_note(&outcome)],
    })
}

/// The polar as a Markdown table: mean [5–95 %] per direction and H_s.
fn table_note(agg: &plot::Aggregate) -> String {
    let mut s = String::from("Roll reduction [%], seed mean [5–95 %]:\n\n| γ [deg] |");
    for g in &agg.series {
        s += &format!(" H_s = {} m |", g.group.as_deref().unwrap_or("?"));
    }
    s += "\n|---|";
    s += &"---|".repeat(agg.series.len());
    let dirs: Vec<f64> = agg.series[0].points.iter().map(|p| p.0).collect();
    for d in dirs {
        s += &format!("\n| {d} |");
        for g in &agg.series {
            if let Some((_, st)) = g.points.iter().find(|p| p.0 == d) {
                s += &format!(" {:.1} [{:.1}, {:.1}] |", st.mean, st.p05, st.p95);
            }
        }
    }
    s
}

fn grouping_note(o: &execute::CampaignOutcome) -> String {
    let groups = o.groups.as_ref().map_or(0, Vec::len);
    format!(
        "Each of the {groups} (H_s, seeds) groups ran its first 200 s once and forked its 18 runs \
         (direction and roll mode set at 200 s, statistics from 300 s); {} runs (timings: \
         docs/bench.md).",
        o.ran
    )
}
