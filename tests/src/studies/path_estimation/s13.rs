//! S13 [Parsons1980, sec. 4.3.2, Table 15]: the WLS in the loop with a ship passing during the
//! second window.

use super::wls::{wls_seed, wls_stats, wls_table_checks, WlsStats};
use super::{within_seeds, SEEDS};
use crate::study::{fmt_num, series, Check, Env, Report, Spread};
use models::hull::tokyo_maru::L;
use shipsim::plot::Panel;

pub(super) const WLS_PS: &str = "path_control_wls_passing_ship.toml";
/// [Parsons1980, Table 15], updates 1, 2, 3 (rows: f22, f23, f25, f32, f33, f35, N′×10⁵, Y′×10⁵).
const TABLE_15: [[&str; 3]; 8] = [
    ["-1.9446", "-0.62936", "-1.9247"],
    ["3.2178", "-1.8532", "3.0732"],
    ["-1.0428", "-1.0017", "-1.0434"],
    ["0.33260", "0.18843", "0.30193"],
    ["-0.53544", "-1.7884", "-0.70178"],
    ["-0.16275", "-0.17338", "-0.16349"],
    ["-0.17504", "-8.2745", "0.11698"],
    ["6.6942", "67.778", "-6.9666"],
];

/// S13: the runs over the seeds, [Parsons1980, Table 15], the decisions of the Table 10 rule,
/// costs and offsets, figure and notes.
pub(super) fn s13(env: &Env, report: &mut Report) -> Result<(), String> {
    let mut runs = Vec::new();
    for seed in 1..=SEEDS {
        let t = env.run(WLS_PS, &wls_seed(seed), "s13.csv")?;
        runs.push(wls_stats(&t, 0.0, 5.0)?);
    }
    let c = &mut report.checks;
    let rejected = table_15_checks(&runs, c)?;
    let evaluations = decision_checks(&runs, c);
    let c1 = cost_and_offset_checks(&runs, c);
    figure(env, report)?;
    notes(&runs, &rejected, evaluations, &c1, &mut report.notes);
    Ok(())
}

/// [Parsons1980, Table 15]: update 1 over all seeds, update 3 over the seeds in which update 2 was
/// rejected; returns those seeds' runs.
fn table_15_checks(runs: &[WlsStats], c: &mut Vec<Check>) -> Result<Vec<WlsStats>, String> {
    // updates 1 and 3 (N′, Y′ as printed, ×10⁵ = ×10² · 1000)
    // update 1 over all seeds; update 3 over the seeds in which update 2 was rejected, as in
    // the report (no gain update at t′ = 10); update 2 is not compared (see the note)
    let mut t15 = TABLE_15;
    for row in t15.iter_mut() {
        row[1] = "";
        row[2] = "";
    }
    wls_table_checks(c, "S13", "Table 15", runs, &t15, &[0], ("×10⁵", 1000.0))?;
    let rejected: Vec<WlsStats> = runs
        .iter()
        .filter(|r| r.fits[1].3 == 0.0)
        .cloned()
        .collect();
    let mut t15 = TABLE_15;
    for row in t15.iter_mut() {
        row[0] = "";
        row[1] = "";
    }
    let n_rej = rejected.len();
    if n_rej > 0 {
        wls_table_checks(
            c,
            &format!("S13 ({n_rej} seeds with update 2 rejected)"),
            &format!("Table 15 (the {n_rej} seeds with update 2 rejected)"),
            &rejected,
            &t15,
            &[2],
            ("×10⁵", 1000.0),
        )?;
    }
    Ok(rejected)
}

/// The decisions of the [Parsons1980, Table 10] rule on the three updates, and the cost
/// evaluations they needed (seed medians).
fn decision_checks(runs: &[WlsStats], c: &mut Vec<Check>) -> (f64, f64, f64) {
    let dec = |u: usize, code: f64| runs.iter().filter(|r| r.fits[u].3 == code).count();
    let (rej2, part2, all2) = (dec(1, 0.0), dec(1, 1.0), dec(1, 2.0));
    c.push(Check::holds(
        "S13 update 2 (passing ship in the window): the fit fails the Table 10 check",
        "rejected (f̂23 = −1.8532, f̂22 = −0.62936, f̂33 = −1.7884 out of range)",
        format!(
            "no seed with all six in range; rejected in {rej2}, f23/f25 only in {part2} of {SEEDS}"
        ),
        all2 == 0 && rej2 > 0,
    ));
    let all1 = dec(0, 2.0);
    let ok3 = runs.iter().filter(|r| r.fits[2].3 > 0.0).count();
    c.push(Check::holds(
        "S13 updates 1 and 3 accepted (update 1 with all six in range)",
        "updates 1 and 3 accepted",
        format!("update 1 all in range in {all1}, update 3 accepted in {ok3} of {SEEDS}"),
        all1 == SEEDS as usize && ok3 == SEEDS as usize,
    ));
    let med = |u: usize| Spread::over(runs, |r| r.fits[u].1).median;
    let (e1, e2, e3) = (med(0), med(1), med(2));
    c.push(Check::holds(
        "S13 update 2 needs the most cost evaluations (seed medians)",
        "65 / 253 / 38",
        format!("{e1} / {e2} / {e3}"),
        e2 > e1 && e2 > e3,
    ));
    (e1, e2, e3)
}

/// The final costs relative to update 1, the cycle-1 offset (returned) and the rudder command.
fn cost_and_offset_checks(runs: &[WlsStats], c: &mut Vec<Check>) -> Spread {
    let ratio = |u: usize| Spread::over(runs, |r| r.fits[u].2 / r.fits[0].2);
    c.push(within_seeds(
        "Table 15 final cost of updates 2 / 3 relative to update 1 (0.3642/0.1022, 0.1031/0.1022)",
        &["3.564", "1.009"],
        &[ratio(1), ratio(2)],
        "",
    ));
    // cycle 1 (before the passing ship): the first dither's sign follows the noise-driven rudder
    // before the window, so |η′| is compared
    let c1 = Spread::over(runs, |r| r.max_offset[0].abs());
    c.push(Check::rel(
        "Table 15 |maximum offset η′| in cycle 1 (seed mean; update instant within LB, see S11 note)",
        0.0698,
        c1.mean,
        0.04,
        "",
    ));
    let max_cmd = runs.iter().fold(0.0f64, |m, r| m.max(r.max_command));
    c.push(Check::holds(
        "S13 rudder command within the gear's limit",
        "no limit in the report",
        format!("max |δ_c| {} rad (limit π)", fmt_num(max_cmd)),
        max_cmd < std::f64::consts::PI,
    ));
    c1
}

/// The S13 figure (seed 1): offset, passing-ship disturbance, f̂23.
fn figure(env: &Env, report: &mut Report) -> Result<(), String> {
    let t1 = env.run(WLS_PS, &wls_seed(1), "s13_seed1.csv")?;
    let ser = |name: &str, label: &str, scale: f64| series(&t1, name, label, scale);
    let f = env.figure(
        "s13_wls_passing_ship.png",
        "S13: WLS in the loop, deep water, ship passing at t' = 7, seed 1 (t' = t/46.98 s)",
        &[
            Panel {
                y_label: "η′ = η/L".into(),
                series: vec![ser("ship.cross_track", "η′", 1.0 / L)?],
            },
            Panel {
                y_label: "N′, Y′ ×10⁵".into(),
                series: vec![
                    ser("current.n_prime", "N′ (passing ship)", 1e5)?,
                    ser("current.y_prime", "Y′ (passing ship)", 1e5)?,
                ],
            },
            Panel {
                y_label: "f23".into(),
                series: vec![
                    ser("est.f23_estimate", "WLS estimate", 1.0)?,
                    ser("ctl.design_f23", "controller design", 1.0)?,
                ],
            },
        ],
    )?;
    report.figures.push((
        "S13 (Table 15): offset, passing-ship disturbance, f̂23, seed 1".into(),
        f,
    ));
    Ok(())
}

/// The S13 notes: setup, update 2 (not compared), update 3 in the seeds with update 2 rejected,
/// cycle 1.
fn notes(
    runs: &[WlsStats],
    rejected: &[WlsStats],
    (e1, e2, e3): (f64, f64, f64),
    c1: &Spread,
    n: &mut Vec<String>,
) {
    let sp2 = |i: usize| Spread::over(runs, |r| r.fits[1].0[i]);
    let off = |cy: usize, end: bool| {
        Spread::over(runs, |r| {
            if end {
                r.end_offset[cy]
            } else {
                r.max_offset[cy]
            }
        })
    };
    n.push(format!(
        "S13 setup: systems/{WLS_PS}: the S11 loop started on the track (x = x̂ = 0) with the \
         ship passing beam-to-beam at t′ = 7 (the spec's Ricker surrogate of the lost Fig. 3, 1x), \
         LU = 5 L, windows [2.45, 4.95) + 5n, 15 L, {SEEDS} seeds. Update 2 (window 7.45-9.95, \
         the end of the passing): f̂22 {}, f̂23 {}, f̂32 {}, f̂33 {} (printed −0.62936, −1.8532, \
         0.18843, −1.7884): corrupted as in the report, but the numbers depend on the waveform of \
         the disturbance, which the surrogate only matches in peak and RMS, so they are not \
         compared; nor are the offsets after t′ = 5: max |η′| in cycles 2 / 3 {} / {} (printed \
         0.1394 / −0.2154), at the cycle ends {} / {} (−0.0953 / 0.1511). Cost evaluations \
         (medians) {e1} / {e2} / {e3}.",
        sp2(0),
        sp2(1),
        sp2(3),
        sp2(4),
        off(1, false),
        off(2, false),
        off(1, true),
        off(2, true),
    ));
    if !rejected.is_empty() {
        let u3 = |i: usize| Spread::over(rejected, |r| r.fits[2].0[i]);
        n.push(format!(
            "S13 update 3 in the {} seeds with update 2 rejected: f̂23 {} (median {}), f̂32 {} \
             (median {}), f̂33 {} (median {}) (printed 3.0732, 0.30193, −0.70178): f̂23 is near the \
             truth, the β-equation parameters f̂32, f̂33 are biased. Cause (investigated with \
             refits of the recorded windows, which reproduce the FMU's fits to 1e-7): the fit starts \
             from the filter's estimate x̂ (spec §2.12), whose drift angle β̂ is off by about \
             0.0013 rad (sd; mean +0.0006) at the window start, an error that follows the update-1 \
             f̂33 through the filter's re-design (correlation −0.97). In this window the ship enters \
             off the track after the passing ship and β stays near β0 ≈ 0.017 (sd 0.0023, against \
             0.024 in S11 update 3), so the f33 and Y′ columns of the Jacobian are nearly collinear \
             (cosine −0.9989) and 1e-3 rad of β0 error moves f̂33 by about 1.3. With the true state \
             as x0 the same windows give medians f̂32 0.32, f̂33 −0.645; the filter designed at the \
             true coefficients gives 0.314 / −0.589. Not a defect: a property of the scenario and of \
             the report's method; the printed pair sits at about the 25th / 75th percentiles of the \
             seeds, both close in 2 of 24 (8 %), a plausible but fortunate realisation. The passing \
             ship itself does not reach the window (|N′|, |Y′| < 1e-27).",
            rejected.len(),
            u3(1),
            fmt_num(u3(1).median),
            u3(3),
            fmt_num(u3(3).median),
            u3(4),
            fmt_num(u3(4).median),
        ));
    }
    n.push(format!(
        "S13 cycle 1: |max η′| {} (printed 0.0698, also the offset at the cycle end); the sign of \
         the first dither is opposite to the rudder just before the window, which on the track \
         is noise, so the sign of the offset differs between seeds.",
        c1
    ));
}
