//! Rudder roll stabilization [Klugt1987]: systems/rrs.toml with RRS off (course keeping only,
//! "ASA") and on, same seed; roll reduction 100(1 − σ²_on/σ²_off) [Klugt1987, eq. (5.7)]; a sweep
//! over steering-gear rate and wave direction for the trends of the MARIN and full-scale results
//! (named R3-R5 and R7 in the report) [Klugt1987, secs. 7.2.3, 7.4]; and a robustness run in
//! which the same autopilot and filters, designed on the control model, steer the thesis's
//! 22-knot simulation model (systems/rrs_simulation_plant.toml, [`simulation_plant`]).
//!
//! The thesis gives no sea state for its analog-model trials [Klugt1987, sec. 7.2.2, Table 7.1]:
//! as the issue prescribes, the open-loop roll is tuned to the reported variances (16 and 47 deg²)
//! by the wave roll gain, and the closed-loop reduction is the result compared.

use crate::study::{after, mean, series_window, variance, Check, Env, Report};
use models::hull::DEG;
use shipsim::plot::Panel;
use shipsim::results::ResultsTable;
const SYSTEM: &str = "rrs.toml";
/// The robustness system: plant = the 22-knot simulation model (RrsShip model 1,
/// [Klugt1987, Tables 2.1-2.2])
/// driven by the wave height; its wave connection gain (0.014670) is tuned for 16 deg² open loop.
const SYSTEM_SIM: &str = "rrs_simulation_plant.toml";
/// Statistics skip the start-up transient (filters, innovation process, adaptation).
const SETTLE: f64 = 200.0;
/// Wave roll gain for 47 deg² open loop ([Klugt1987, Table 7.1], exp. 2): the roll gain of
/// systems/rrs.toml
/// (0.034319, tuned for 16 deg² with the wind gusts' 0.31 deg² included) scaled by
/// √((47 − 0.31)/(16 − 0.31)).
const GAIN_EXP2: f64 = 0.059201;

/// Statistics of one run, in degrees.
#[derive(Clone, Debug)]
pub struct RunStats {
    pub roll_var: f64,
    pub heading_var: f64,
    pub rudder_var: f64,
    /// Time with the rudder rate limiter active after the settling time [s].
    pub rate_saturated: f64,
    /// Largest |Δ rudder_command|/Δt of the autopilot set point [deg/s].
    pub max_command_rate: f64,
    /// Mean roll (the wind heel) and mean rudder [deg].
    pub mean_roll: f64,
    pub mean_rudder: f64,
}

fn stats(t: &ResultsTable) -> Result<RunStats, String> {
    let deg2 =
        |c: &str| -> Result<f64, String> { Ok(variance(after(t, c, SETTLE)?) / (DEG * DEG)) };
    let sat = after(t, "gear.rate_saturated_time", SETTLE)?;
    let cmd = after(t, "autopilot.rudder_command", 0.0)?;
    let time = t.time();
    let mut max_rate: f64 = 0.0;
    let mut last = (time[0], cmd[0]);
    // the autopilot holds its set point over its 0.1 s sample: compare at changes only
    for (tk, ck) in time.iter().zip(cmd).skip(1) {
        if ck != &last.1 {
            max_rate = max_rate.max((ck - last.1).abs() / (tk - last.0));
            last = (*tk, *ck);
        }
    }
    let mean_deg = |c: &str| -> Result<f64, String> { Ok(mean(after(t, c, SETTLE)?) / DEG) };
    Ok(RunStats {
        mean_roll: mean_deg("ship.roll")?,
        mean_rudder: mean_deg("gear.rudder_angle")?,
        roll_var: deg2("ship.roll")?,
        heading_var: deg2("ship.heading")?,
        rudder_var: deg2("gear.rudder_angle")?,
        rate_saturated: sat.last().copied().unwrap_or(0.0) - sat.first().copied().unwrap_or(0.0),
        max_command_rate: max_rate / DEG,
    })
}

/// One off/on pair of systems/rrs.toml with extra overrides; returns (off, on, tables).
fn pair(
    env: &Env,
    tag: &str,
    sets: &[String],
) -> Result<(RunStats, RunStats, ResultsTable, ResultsTable), String> {
    pair_of(env, SYSTEM, tag, sets)
}

/// One off/on pair (same seeds) of `system` with extra overrides; returns (off, on, tables).
fn pair_of(
    env: &Env,
    system: &str,
    tag: &str,
    sets: &[String],
) -> Result<(RunStats, RunStats, ResultsTable, ResultsTable), String> {
    let mut off_sets = sets.to_vec();
    off_sets.push("autopilot.roll_mode=0".into());
    let off = env.run(system, &off_sets, &format!("{tag}_off.csv"))?;
    let mut on_sets = sets.to_vec();
    on_sets.push("autopilot.roll_mode=1".into());
    let on = env.run(system, &on_sets, &format!("{tag}_on.csv"))?;
    Ok((stats(&off)?, stats(&on)?, off, on))
}

fn reduction(off: &RunStats, on: &RunStats) -> f64 {
    100.0 * (1.0 - on.roll_var / off.roll_var)
}

fn rate_sets(rate_deg_s: f64) -> Vec<String> {
    let r = rate_deg_s * DEG;
    vec![
        format!("gear.rate_max={r}"),
        format!("autopilot.rate_max={r}"),
    ]
}

/// Off/on in beam seas at the system's defaults (experiment 1): the `cargo xtask demo` run.
pub fn demo(env: &Env) -> Result<(RunStats, RunStats, std::path::PathBuf), String> {
    let (off, on, toff, ton) = pair(env, "exp1", &[])?;
    let fig = overlay(env, &toff, &ton, "rrs_off_on.png", TITLE_EXP1)?;
    Ok((off, on, fig))
}

const TITLE_EXP1: &str =
    "RRS ship in beam seas, 15 deg/s gear, U = 11 m/s: RRS off (course keeping) vs on (400-600 s)";

fn overlay(
    env: &Env,
    off: &ResultsTable,
    on: &ResultsTable,
    name: &str,
    title: &str,
) -> Result<std::path::PathBuf, String> {
    env.figure(
        name,
        title,
        &[
            Panel {
                y_label: "roll [deg]".into(),
                series: vec![
                    series_window(off, "ship.roll", "RRS off", 1.0 / DEG, 400.0, 600.0)?,
                    series_window(on, "ship.roll", "RRS on", 1.0 / DEG, 400.0, 600.0)?,
                ],
            },
            Panel {
                y_label: "heading [deg]".into(),
                series: vec![
                    series_window(off, "ship.heading", "RRS off", 1.0 / DEG, 400.0, 600.0)?,
                    series_window(on, "ship.heading", "RRS on", 1.0 / DEG, 400.0, 600.0)?,
                ],
            },
            Panel {
                y_label: "rudder [deg]".into(),
                series: vec![
                    series_window(off, "gear.rudder_angle", "RRS off", 1.0 / DEG, 400.0, 600.0)?,
                    series_window(on, "gear.rudder_angle", "RRS on", 1.0 / DEG, 400.0, 600.0)?,
                ],
            },
        ],
    )
}

pub fn run(env: &Env) -> Result<Report, String> {
    let mut report = Report {
        id: "rrs".into(),
        title: "Rudder roll stabilization: Table 7.1 and the trends of R3-R5, R7".into(),
        source: "van der Klugt (1987) Table 7.1, §7.2-7.4 (seed 003; spec rrs_controller_results.md §4.2)"
            .into(),
        systems: vec![SYSTEM.into(), SYSTEM_SIM.into()],
        ..Default::default()
    };
    // Experiment 1: open loop tuned to 16 deg².
    let (off1, on1, toff1, ton1) = pair(env, "exp1", &[])?;
    // Experiment 2: the same sea with the roll gain scaled for 47 deg².
    let (off2, on2, _, _) = pair(env, "exp2", &[format!("waves.roll_gain={GAIN_EXP2}")])?;
    table_7_1_checks([&off1, &on1], [&off2, &on2], &mut report.checks);
    // Robustness: the same autopilot and filters on the 22-knot simulation model.
    let sim_fig = simulation_plant(env, &mut report, &off1, &on1)?;
    let by_rate = gear_rate_sweep(env, &mut report.checks)?;
    let by_dir = wave_direction_sweep(env, &mut report.checks)?;
    report.notes.push(sweep_note(&by_rate, &by_dir));
    experiment_notes([&off1, &on1], [&off2, &on2], &mut report.notes);
    let fig = overlay(env, &toff1, &ton1, "rrs_off_on.png", TITLE_EXP1)?;
    report.figures.push((
        "Experiment 1: roll, heading and rudder with RRS off and on".into(),
        fig,
    ));
    report.figures.push((
        "Robustness: the same autopilot on the 22-knot simulation model (Tables 2.1/2.2), RRS off and on"
            .into(),
        sim_fig,
    ));
    Ok(report)
}

/// [Klugt1987, Table 7.1]: the two experiments (off, on) against the thesis, and the wind heel.
fn table_7_1_checks([off1, on1]: [&RunStats; 2], [off2, on2]: [&RunStats; 2], c: &mut Vec<Check>) {
    c.push(Check::abs(
        "exp. 1: open-loop (ASA) roll variance, tuned",
        16.0,
        off1.roll_var,
        0.5,
        "deg²",
    ));
    c.push(Check::range(
        "exp. 1: roll reduction 100(1 − σ²_on/σ²_off), 15 deg/s",
        "78 % (16 → 3.5 deg²); issue: 60-78 %",
        reduction(off1, on1),
        60.0,
        78.0,
        "%",
    ));
    c.push(Check::rel(
        "exp. 1: rudder variance with RRS",
        41.0,
        on1.rudder_var,
        0.3,
        "deg²",
    ));
    c.push(Check::abs(
        "exp. 2: open-loop (ASA) roll variance, tuned",
        47.0,
        off2.roll_var,
        1.5,
        "deg²",
    ));
    c.push(Check::range(
        "exp. 2: roll reduction, 15 deg/s",
        "68 % (47 → 15 deg²); issue: 60-78 %",
        reduction(off2, on2),
        60.0,
        78.0,
        "%",
    ));
    c.push(Check::rel(
        "exp. 2: rudder variance with RRS",
        74.0,
        on2.rudder_var,
        0.3,
        "deg²",
    ));
    c.push(Check::holds(
        "course keeping deteriorates with RRS (σ²_ψ on > off)",
        "σ²_ψ 0.07 → 0.47 and 0.17 → 0.30 deg²",
        format!(
            "{:.3} → {:.3} and {:.3} → {:.3} deg²",
            off1.heading_var, on1.heading_var, off2.heading_var, on2.heading_var
        ),
        on1.heading_var > off1.heading_var && on2.heading_var > off2.heading_var,
    ));
    c.push(Check::holds(
        "the constant wind heel is left alone by the roll loop (roll filter removes the offset)",
        "a constant roll angle must not be counteracted (it would need constant rudder and turn \
         the ship): the roll filter rejects it (§4.4, §6.3.1)",
        format!(
            "mean heel {:.2}° off / {:.2}° on; mean rudder {:.2}° off / {:.2}° on",
            off1.mean_roll, on1.mean_roll, off1.mean_rudder, on1.mean_rudder
        ),
        off1.mean_roll > 1.0
            && (on1.mean_roll - off1.mean_roll).abs() < 0.1 * off1.mean_roll
            && (on1.mean_rudder - off1.mean_rudder).abs() < 0.2,
    ));
}

/// Off/on pairs of a sweep: (gear rate [deg/s] or wave direction γ [deg], off, on).
type Sweep = Vec<(f64, RunStats, RunStats)>;

/// The roll reduction of the sweep's pair at `key` (NaN if there is none).
fn reduction_at(sweep: &Sweep, key: f64) -> f64 {
    sweep
        .iter()
        .find(|x| x.0 == key)
        .map(|(_, off, on)| reduction(off, on))
        .unwrap_or(f64::NAN)
}

/// Gear-rate sweep at beam seas (R3, R5, R7: 6-7 deg/s too slow, 15 much better, 22 a little
/// better).
fn gear_rate_sweep(env: &Env, c: &mut Vec<Check>) -> Result<Sweep, String> {
    let mut by_rate = Vec::new();
    for rate in [7.0, 15.0, 22.0] {
        let (off, on, _, _) = pair(env, &format!("rate{rate}"), &rate_sets(rate))?;
        by_rate.push((rate, off, on));
    }
    let red = |r: f64| reduction_at(&by_rate, r);
    c.push(Check::holds(
        "7 deg/s gear clearly worse than 15 deg/s (beam seas)",
        "rates of 3-7 deg/s generally too low; 15 deg/s considerably better (R3)",
        format!("{:.1} % vs {:.1} %", red(7.0), red(15.0)),
        red(7.0) < red(15.0) - 10.0,
    ));
    c.push(Check::holds(
        "22 deg/s gear at least as good as 15 deg/s",
        "+5-10 % roll reduction from 15 to 22 deg/s (R5, ship 2)",
        format!(
            "{:.1} % vs {:.1} % (+{:.1} points)",
            red(22.0),
            red(15.0),
            red(22.0) - red(15.0)
        ),
        red(22.0) >= red(15.0),
    ));
    let (_, _, slow) = &by_rate[0];
    c.push(Check::holds(
        "AGC keeps the commanded rudder rate within the gear's limit (7 deg/s gear)",
        "with AGC |dδ_g/dt| ≤ δ̇_max (§5.3, eq. 5.3)",
        format!("max |dδ_g/dt| = {:.3} deg/s", slow.max_command_rate),
        slow.max_command_rate <= 7.0 * (1.0 + 1e-9),
    ));
    Ok(by_rate)
}

/// Wave-direction sweep with the 15 deg/s gear (γ: 0 following, 90 beam, 180 head).
fn wave_direction_sweep(env: &Env, c: &mut Vec<Check>) -> Result<Sweep, String> {
    let mut by_dir = Vec::new();
    for gamma in [30.0, 60.0, 90.0, 120.0, 150.0] {
        let sets = vec![format!("waves.wave_direction={}", gamma * DEG)];
        let (off, on, _, _) = pair(env, &format!("dir{gamma}"), &sets)?;
        by_dir.push((gamma, off, on));
    }
    let dred = |g: f64| reduction_at(&by_dir, g);
    c.push(Check::holds(
        "quartering following seas (60°) give clearly less reduction than beam seas",
        "following seas (low encounter frequency): RRS very difficult (R7, day 4)",
        format!("{:.1} % at 60° vs {:.1} % at 90°", dred(60.0), dred(90.0)),
        dred(60.0) < dred(90.0) - 20.0,
    ));
    c.push(Check::holds(
        "small roll in oblique seas: little rudder action, little reduction",
        "γ = 120°: adaptive reduction small but roll < 4°, adaptation nearly off (R4)",
        format!(
            "open-loop σ²_φ at 30/150° = {:.2}/{:.2} deg², reduction {:.1}/{:.1} %",
            by_dir[0].1.roll_var,
            by_dir[4].1.roll_var,
            dred(30.0),
            dred(150.0)
        ),
        by_dir[0].1.roll_var < 4.0 && by_dir[4].1.roll_var < 4.0,
    ));
    Ok(by_dir)
}

/// The sweeps in full (a note).
fn sweep_note(by_rate: &Sweep, by_dir: &Sweep) -> String {
    let mut sweep = String::from("Sweep (same sea, seed 1): gear rate at beam seas — ");
    for (r, off, on) in by_rate {
        sweep.push_str(&format!(
            "{r} deg/s: {:.1} % (rate-limited {:.0} s); ",
            reduction(off, on),
            on.rate_saturated
        ));
    }
    sweep.push_str("wave direction with the 15 deg/s gear — ");
    for (g, off, on) in by_dir {
        sweep.push_str(&format!(
            "{g}°: σ²_φ {:.2} → {:.2} deg² ({:.1} %); ",
            off.roll_var,
            on.roll_var,
            reduction(off, on)
        ));
    }
    sweep
}

/// The experiments in full, the plant and the autopilot (notes).
fn experiment_notes([off1, on1]: [&RunStats; 2], [off2, on2]: [&RunStats; 2], n: &mut Vec<String>) {
    n.push(format!(
        "Experiment 1 in full: σ²_φ {:.2} → {:.2} deg², σ²_ψ {:.3} → {:.3} deg², σ²_δ {:.3} → {:.1} deg², \
         rate limiter active {:.1} s of 1000 s. Experiment 2: σ²_φ {:.1} → {:.1}, σ²_δ {:.1} (thesis 74), \
         rate limiter {:.1} s.",
        off1.roll_var,
        on1.roll_var,
        off1.heading_var,
        on1.heading_var,
        off1.rudder_var,
        on1.rudder_var,
        on1.rate_saturated,
        off2.roll_var,
        on2.roll_var,
        on2.rudder_var,
        on2.rate_saturated
    ));
    n.push(
        "Plant: the control model of Table 2.4 (ship model 2) at 11 m/s; the wave disturbance is \
         rudder-equivalent (eq. 3.29) with the sin γ / sin 2γ scaling of eqs. 2.23-2.24 on a \
         Bretschneider-ITTC sea (T̄ = 7.7 s, peak near ω_n), plus a 10 m/s beam wind with gusts \
         (eqs. 2.19-2.20; coefficients chosen for a 1.6° heel, the thesis gives none) on the \
         ship's second disturbance channel. The thesis's analog wave filter and sea state are not \
         given, so only the open-loop roll is tuned; heading variances come from the wind yaw \
         moment (sin 2γ = 0 for waves at beam seas) and are compared in trend only. Rudder \
         variances are a consequence of the controller, not tuned: ±30 % states that they are of \
         the published size."
            .into(),
    );
    n.push(
        "Autopilot: AGC and on-line criterion adaptation on (q_φ from 10, target roll variance \
         4 deg²); with the adaptation off and q_φ fixed at 30 the reductions are 71.5 % and 69.3 %."
            .into(),
    );
}

/// Robustness run (systems/rrs_simulation_plant.toml): the autopilot and the roll/yaw filters,
/// designed on the control model of [Klugt1987, Table 2.4] (evaluated at the plant's 22 kn),
/// steer the thesis's 22-knot simulation model [Klugt1987, Fig. 2.5, Tables 2.1-2.2] driven by
/// the wave height
/// through its own wave filters; wind as in rrs.toml; same seeds, RRS off and on. Pushes the
/// checks and notes to `report`; `ctrl_off`/`ctrl_on` are experiment 1 on the control model (same
/// sea, same tuned 16 deg²) for the comparison. Returns the overlay figure.
///
/// The thesis gives no roll reduction for this model: its digital simulations (PSI, the model
/// used is not named) appear only as [Klugt1987, sec. 7.2.1, Fig. 7.2] ("a reasonable roll
/// reduction"). What it does report at 15 deg/s is 78 % and 68 % on the analog model
/// [Klugt1987, Table 7.1], "up to 60 %" on the MARIN simulator with ship 2 [Klugt1987, sec. 7.2.3]
/// and ≈ 60 % on the scale model and at full scale [Klugt1987, secs. 7.3-7.4]. The band checked
/// is therefore
/// the 60-78 % for beam seas, 15 deg/s: from the thesis's typical ≈ 60 % on plants that
/// differ from the control model to its best laboratory figure. The second check is the thesis's
/// own criterion for the control model [Klugt1987, sec. 7.2]: results on a plant with dynamics
/// outside the
/// control model must agree with those on the model itself. "Agree" is ±10 points: the seed
/// spread of one plant is ±3 points (waves.seed 1-8, both systems: control model 69.3-73.8 %,
/// simulation model 71.2-75.0 %, measured when this run was added), while the thesis's platforms
/// at 15 deg/s spread over 18 points (60-78 %).
fn simulation_plant(
    env: &Env,
    report: &mut Report,
    ctrl_off: &RunStats,
    ctrl_on: &RunStats,
) -> Result<std::path::PathBuf, String> {
    let (off, on, toff, ton) = pair_of(env, SYSTEM_SIM, "simplant", &[])?;
    let red = reduction(&off, &on);
    let red_ctrl = reduction(ctrl_off, ctrl_on);
    let c = &mut report.checks;
    c.push(Check::abs(
        "simulation plant (Tables 2.1/2.2, 22 kn): open-loop (ASA) roll variance, tuned",
        16.0,
        off.roll_var,
        0.5,
        "deg²",
    ));
    c.push(Check::range(
        "simulation plant: roll reduction with the control-model autopilot, 15 deg/s",
        "no figure for this model (digital simulations, Fig. 7.2: \"a reasonable roll \
         reduction\"); 15 deg/s: 78/68 % analog, ≤ 60 % MARIN ship 2, ≈ 60 % full scale; \
         issue: 60-78 %",
        red,
        60.0,
        78.0,
        "%",
    ));
    c.push(Check::holds(
        "simulation plant: reduction agrees with the control-model run (±10 points)",
        "MARIN runs with dynamics outside the control model should agree with the laboratory \
         simulations if the control model is sufficiently accurate (§7.2)",
        format!("{red:.1} % vs {red_ctrl:.1} % on the control model (exp. 1, same sea)"),
        (red - red_ctrl).abs() <= 10.0,
    ));
    c.push(Check::holds(
        "simulation plant: course keeping and heel rejection survive the mismatch",
        "course-keeping deterioration small (σ_ψ² ≤ 0.47 deg² in Table 7.1; ≤ 1 deg² here); \
         constant heel not counteracted (§4.4, §6.3.1)",
        format!(
            "σ_ψ² {:.3} → {:.3} deg²; mean heel {:.2}° off / {:.2}° on",
            off.heading_var, on.heading_var, off.mean_roll, on.mean_roll
        ),
        on.heading_var <= 1.0
            && off.mean_roll > 1.0
            && (on.mean_roll - off.mean_roll).abs() < 0.1 * off.mean_roll,
    ));
    report.notes.push(format!(
        "Simulation plant (systems/{SYSTEM_SIM}), readings: σ²_φ {:.2} → {:.2} deg² ({red:.1} %; \
         control model {:.2} → {:.2}, {red_ctrl:.1} %); σ²_ψ {:.3} → {:.3} deg² (control model \
         {:.3} → {:.3}); σ²_δ {:.3} → {:.1} deg² (control model {:.1}; thesis exp. 1: 41); rate \
         limiter active {:.1} s of 1000 s with RRS (control model {:.1} s); largest commanded \
         rudder rate {:.2} deg/s; mean heel {:.2}° / {:.2}°, mean rudder {:.2}° / {:.2}° off / on.",
        off.roll_var,
        on.roll_var,
        ctrl_off.roll_var,
        ctrl_on.roll_var,
        off.heading_var,
        on.heading_var,
        ctrl_off.heading_var,
        ctrl_on.heading_var,
        off.rudder_var,
        on.rudder_var,
        ctrl_on.rudder_var,
        on.rate_saturated,
        ctrl_on.rate_saturated,
        on.max_command_rate,
        off.mean_roll,
        on.mean_roll,
        off.mean_rudder,
        on.mean_rudder
    ));
    report.notes.push(format!(
        "Model mismatch of the robustness run: the filters and the innovation process use \
         Table 2.4 at 22 kn (ω_n 0.63, z_n 0.107, k_dp −0.179, k_vp 2.38, k_dv 0.113, τ_v \
         6.9 s, τ_r 1.15 s, k_vr −0.46, no yaw-to-sway coupling) while the plant is Table 2.1 \
         (ω_n 0.64, z_n 0.094, k_dp −0.17, k_vp 3.7, k_dv 0.08, τ_v 9 s, τ_r 1.3 s, k_vr −0.7, \
         k_rv 0.13), an independent identification of the same design at the same speed. The \
         DC gains agree within 5 %, but at 0.63 rad/s the plant's |φ/δ| is 0.888 against \
         0.822, with 7° more phase lead [derived from the tables]; its roll is less damped, \
         and its sway state (the v_δ that the roll controller feeds back from the filter's \
         open-loop submodel) has another scale and time constant. The waves enter through \
         the Table 2.2 wave-height filters (roll directly and through sway, plus some yaw even \
         at beam seas) instead of the rudder-equivalent w_φ of eq. 3.29. Their unit is \
         unknown, so the elevation is scaled by a connection gain tuned for 16 deg² open loop \
         (wind included), on the same sea (seed 1) as the control-model run. The plant's \
         larger rudder effect at resonance and lower damping (more to gain from added damping) \
         are the likely reasons why the reduction differs from the design-model run by \
         {:+.1} points.",
        red - red_ctrl
    ));
    overlay(
        env,
        &toff,
        &ton,
        "rrs_simulation_plant_off_on.png",
        "22-kn simulation model, control-model autopilot, 15 deg/s: RRS off vs on (400-600 s)",
    )
}
