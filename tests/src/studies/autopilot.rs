//! Autopilot and track keeping of the DDG-51 EKF thesis [Taylor2000, secs. 4.3.4, 5.2.3, 5.3.3]
//! (the checks named AT-6 to AT-9 and AT-11 in the report), through the master:
//!
//! * `autopilot_current.toml`: NomotoShip (DDG-51 first-order Nomoto) + SteeringGear (6/(s+6) in
//!   t') + Current (5 kn on the beam, decaying) + Sensors (noisy heading) + HeadingAutopilot:
//!   AT-6 (gear filters the noise) and AT-7 (current offset) [Taylor2000, sec. 5.2.3.1];
//! * `autopilot_track_change.toml`: the same loop with the autopilot's 90° track-change
//!   generator: AT-8 [Taylor2000, sec. 5.2.3.2];
//! * `autopilot_current_nonlinear.toml`, `autopilot_track_change_nonlinear.toml`: AT-7 and AT-8
//!   again on a nonlinear plant with sway and speed loss (ContainerShip standing in for the
//!   thesis's nonlinear plant, its reference [43], which is not given), the current as an initial
//!   sway velocity as the thesis applied it;
//! * `autopilot_track_offset.toml`: TrackController, sea state 4 (Waves, rudder-equivalent yaw
//!   disturbance), 5-kn beam current gust and a 2 L lateral offset to port: AT-9
//!   [Taylor2000, sec. 5.3.3];
//! * `identification_zigzag.toml`: ContainerShip + Manoeuvre (10/10 zig-zag) + Sensors +
//!   ParameterEkf; the identified linear model's 10° turning circle against the plant's
//!   (computed here with the models crate from the FMU's identified coefficients): AT-11
//!   [Taylor2000, sec. 4.3.4].

use crate::study::{after, col, last, max_abs, mean, series, std_dev, Check, Env, Report};
use models::hull::container_ship::{ContainerShip, L as CS_L, LIN_B, LIN_M};
use models::hull::nomoto::{NomotoInputs, NomotoModel, NomotoShip};
use models::hull::{DEG, KNOT};
use models::manoeuvre::{
    run as run_manoeuvre, turning_circle, ContainerShipRun, ManoeuvreGenerator, ManoeuvreKind,
    ManoeuvreShip, Sample,
};
use shipsim::plot::{Panel, Series};
use shipsim::results::ResultsTable;

/// DDG-51 length 466 ft [m] and speed 22 kn [m/s] of the time base t' = tU/L.
const L: f64 = 142.0368;
const U: f64 = 11.317777777777778;
const T_NOMOTO: f64 = 1.9287;
/// Rudder-equivalent wave yaw gain of systems/autopilot_track_offset.toml [rad per m].
const WAVE_YAW_GAIN: f64 = 0.0745;

/// Largest peak-to-peak of `v` over consecutive windows of `n` samples.
fn max_window_p2p(v: &[f64], n: usize) -> f64 {
    v.chunks(n)
        .filter(|c| c.len() == n)
        .map(|c| {
            c.iter().cloned().fold(f64::MIN, f64::max) - c.iter().cloned().fold(f64::MAX, f64::min)
        })
        .fold(0.0, f64::max)
}

/// Commanded (`cmd`) and actual rudder angle [deg].
fn rudder_panel(t: &ResultsTable, cmd: &str) -> Result<Panel, String> {
    Ok(Panel {
        y_label: "rudder [deg]".into(),
        series: vec![
            series(t, cmd, "commanded", 1.0 / DEG)?,
            series(t, "gear.rudder_angle", "actual", 1.0 / DEG)?,
        ],
    })
}

/// Commanded and actual heading [deg] of the heading autopilot.
fn heading_panel(t: &ResultsTable) -> Result<Panel, String> {
    Ok(Panel {
        y_label: "heading [deg]".into(),
        series: vec![
            series(t, "ap.heading_reference_used", "commanded", 1.0 / DEG)?,
            series(t, "ship.heading", "actual", 1.0 / DEG)?,
        ],
    })
}

/// Range (max − min) of the actual rudder over t0 ≤ t < t1 [deg].
fn rudder_sweep(t: &ResultsTable, t0: f64, t1: f64) -> Result<f64, String> {
    let (time, rud) = (t.time(), col(t, "gear.rudder_angle")?);
    let turn: Vec<f64> = (0..time.len())
        .filter(|&k| (t0..t1).contains(&time[k]))
        .map(|k| rud[k] / DEG)
        .collect();
    Ok(turn.iter().cloned().fold(f64::MIN, f64::max)
        - turn.iter().cloned().fold(f64::MAX, f64::min))
}

pub fn run(env: &Env) -> Result<Report, String> {
    let mut report = Report {
        id: "autopilot".into(),
        title: "DDG-51 heading autopilot, track controller and EKF identification".into(),
        source: "DDG-51 EKF thesis (2000, seed 000), spec ddg51_ekf_autopilot.md §4.5, §4.7-4.11"
            .into(),
        systems: vec![
            "autopilot_current.toml".into(),
            "autopilot_track_change.toml".into(),
            "autopilot_current_nonlinear.toml".into(),
            "autopilot_track_change_nonlinear.toml".into(),
            "autopilot_track_offset.toml".into(),
            "identification_zigzag.toml".into(),
        ],
        ..Default::default()
    };
    current_rejection(env, &mut report)?;
    track_change(env, &mut report)?;
    current_rejection_nonlinear(env, &mut report)?;
    track_change_nonlinear(env, &mut report)?;
    track_offset(env, &mut report)?;
    identification(env, &mut report)?;
    Ok(report)
}

/// AT-6 and AT-7.
fn current_rejection(env: &Env, report: &mut Report) -> Result<(), String> {
    let t = env.run("autopilot_current.toml", &[], "autopilot_current.csv")?;
    let rud: Vec<f64> = after(&t, "gear.rudder_angle", 200.0)?
        .iter()
        .map(|v| v / DEG)
        .collect();
    let cmd: Vec<f64> = after(&t, "ap.rudder_command", 200.0)?
        .iter()
        .map(|v| v / DEG)
        .collect();
    let jitter = std_dev(&rud);
    let p2p5 = max_window_p2p(&rud, 100); // 5 s windows at 0.05 s
    report.checks.push(Check::range(
        "AT-6 actual-rudder steady jitter (std, t > 200 s), heading noise 0.05 deg",
        "< 0.1 deg (L2433-2437)",
        jitter,
        0.0,
        0.1,
        "deg",
    ));
    report.checks.push(Check::holds(
        "AT-6 gear filters the noisy command",
        "commanded rudder very noisy, actual smooth (Fig 5-9)",
        format!(
            "command std {:.3} deg, actual {:.3} deg (ratio {:.2}); largest 5 s peak-to-peak of the actual {:.3} deg",
            std_dev(&cmd),
            jitter,
            jitter / std_dev(&cmd),
            p2p5
        ),
        jitter < 0.5 * std_dev(&cmd),
    ));
    let y = col(&t, "ship.y")?;
    let peak = max_abs(y) / L;
    let predicted = 5.0 * KNOT * T_NOMOTO * L / U / L;
    report.checks.push(Check::rel(
        "AT-7 peak lateral offset = drift integral V T' L/U of the decaying current",
        predicted,
        peak,
        0.01,
        "L",
    ));
    // Not a check: the peak is set by the assumed current decay, not by the autopilot.
    report.notes.push(format!(
        "AT-7 peak lateral offset: thesis ≈ 0.3 L (L2351, L2367); ours {peak:.3} L, set by the \
         assumed sway decay (T' L/U), not by the autopilot: not reproducible on the first-order \
         Nomoto plant; see AT-7 on the nonlinear plant, where the current enters as the thesis applied it."
    ));
    let psi_max = max_abs(col(&t, "ship.heading")?) / DEG;
    report.checks.push(Check::holds(
        "AT-7 heading recovers",
        "ship returns to its commanded heading (Fig 5-8)",
        format!("|heading| <= {psi_max:.3} deg throughout (noise only)"),
        psi_max < 0.2,
    ));
    // Reading at the Sensors preset noise (not asserted).
    let t2 = env.run(
        "autopilot_current.toml",
        &["sensors.heading_sigma=0.001611".into()],
        "autopilot_current_preset_noise.csv",
    )?;
    let rud2: Vec<f64> = after(&t2, "gear.rudder_angle", 200.0)?
        .iter()
        .map(|v| v / DEG)
        .collect();
    report.notes.push(format!(
        "AT-6: the thesis gives no heading-noise level (spec §6 item 8). The jitter is linear in it: \
         with sigma = 0.05 deg (our choice, sampled every 1 s) the actual rudder's steady std is {jitter:.3} deg; \
         with the Sensors preset 0.092 deg (0.001611 rad, Parsons & Cuong Table 3) it is {:.3} deg, so \
         AT-6's 0.1 deg holds for heading noise below about {:.3} deg.",
        std_dev(&rud2),
        0.1 / jitter * 0.05
    ));
    report.notes.push(format!(
        "AT-7: the thesis applies the current as an initial sway velocity v'0 = 5/22 (L2347) that \
         decays with the hull's sway dynamics; the DDG-51 first-order Nomoto plant has no sway state and \
         the hull's sway time constant is not given (spec §6 items 1, 2, 6). We feed a beam current falling \
         linearly from 5 kn to 0 over 2 T' L/U (same drift integral as an exponential decay with \
         T' L/U = 24.2 s), so the ship is set {peak:.3} L off track against the thesis's ≈ 0.3 L; the \
         heading is unaffected by a kinematic current, so the thesis's heading excursion (Fig 5-8, +2..-4 deg) \
         is not reproduced either. A sway time constant of 16.6 s would give 0.3 L."
    ));
    current_rejection_figure(env, &t, report)
}

/// The current-rejection figure: offset, heading (measured and actual), rudder.
fn current_rejection_figure(
    env: &Env,
    t: &ResultsTable,
    report: &mut Report,
) -> Result<(), String> {
    let fig = env.figure(
        "autopilot_current.png",
        "Heading autopilot, 5-kn decaying beam current (AT-6, AT-7)",
        &[
            Panel {
                y_label: "lateral offset [L]".into(),
                series: vec![series(t, "ship.y", "y / L", 1.0 / L)?],
            },
            Panel {
                y_label: "heading [deg]".into(),
                series: vec![
                    series(t, "sensors.heading_measured", "measured", 1.0 / DEG)?,
                    series(t, "ship.heading", "actual", 1.0 / DEG)?,
                ],
            },
            rudder_panel(t, "ap.rudder_command")?,
        ],
    )?;
    report
        .figures
        .push(("Current rejection: offset, heading, rudder".into(), fig));
    Ok(())
}

/// AT-8: cross-track against the dead-reckoned path (commanded heading flown at U).
fn track_change(env: &Env, report: &mut Report) -> Result<(), String> {
    let t = env.run(
        "autopilot_track_change.toml",
        &[],
        "autopilot_track_change.csv",
    )?;
    let time = t.time();
    let psi_ref = col(&t, "ap.heading_reference_used")?;
    let (x, y) = (col(&t, "ship.x")?, col(&t, "ship.y")?);
    let (xd, yd) = dead_reckoning(time, psi_ref, U);
    // Cross-track on the first new leg (heading -90 deg: the track runs west; the normal is x).
    let leg: Vec<usize> = (0..time.len())
        .filter(|&k| (250.0..650.0).contains(&time[k]))
        .collect();
    let xte: Vec<f64> = leg.iter().map(|&k| (x[k] - xd[k]) / L).collect();
    let xte_end = *xte.last().unwrap();
    let heading = col(&t, "ship.heading")?;
    let steady: Vec<f64> = leg
        .iter()
        .filter(|&&k| time[k] > 400.0)
        .map(|&k| (heading[k] - psi_ref[k]) / DEG)
        .collect();
    let e_ss = max_abs(&steady);
    report.checks.push(Check::range(
        "AT-8 steady heading error on the leg (max |psi - psi_ref|, 400-650 s) / 90 deg",
        "< 1 % (L2509-2513)",
        e_ss / 90.0 * 100.0,
        0.0,
        1.0,
        "%",
    ));
    let sweep = rudder_sweep(&t, 40.0, 300.0)?;
    let _ = (y, yd);
    report.notes.push(format!(
        "AT-8: the ramp rate and leg length are not given; we use 1 deg/s and a 600 s leg. On the \
         first-order Nomoto plant the cross-track against the dead-reckoned path comes only from the \
         autopilot's ramp lag (type-1 loop, velocity constant 1 per t'), {xte_end:.3} L, against the \
         thesis's ≈ 3 L which it attributes to speed loss and sway on its nonlinear plant [43] (not \
         given, spec §6 item 2; see AT-8 on the nonlinear plant). The rudder sweep ({sweep:.1} deg) scales with the ramp rate \
         (steady turn rudder = r/K' = rate L/(U K')), so it is a reading, not a check."
    ));
    let fig = env.figure(
        "autopilot_track_change.png",
        "Heading autopilot, 90 deg track change (AT-8)",
        &[
            heading_panel(&t)?,
            Panel {
                y_label: "x (north) [L]".into(),
                series: vec![
                    series(&t, "ship.x", "actual", 1.0 / L)?,
                    Series {
                        label: "dead-reckoned".into(),
                        t: time.to_vec(),
                        y: xd.iter().map(|v| v / L).collect(),
                    },
                ],
            },
            rudder_panel(&t, "ap.rudder_command")?,
        ],
    )?;
    report.figures.push((
        "Track change: heading, along-track position, rudder".into(),
        fig,
    ));
    Ok(())
}

/// The dead-reckoned ("commanded") path: trapezoidal integral of `u` (cos, sin) ψ_ref from the
/// origin.
fn dead_reckoning(time: &[f64], psi_ref: &[f64], u: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut xd, mut yd) = (vec![0.0; time.len()], vec![0.0; time.len()]);
    for k in 1..time.len() {
        let h = time[k] - time[k - 1];
        xd[k] = xd[k - 1] + 0.5 * h * u * (psi_ref[k].cos() + psi_ref[k - 1].cos());
        yd[k] = yd[k - 1] + 0.5 * h * u * (psi_ref[k].sin() + psi_ref[k - 1].sin());
    }
    (xd, yd)
}

/// AT-6/AT-7 on the nonlinear stand-in plant: the current as the thesis applied it, an initial
/// sway velocity v'0 = 5/22.
fn current_rejection_nonlinear(env: &Env, report: &mut Report) -> Result<(), String> {
    let t = env.run(
        "autopilot_current_nonlinear.toml",
        &[],
        "autopilot_current_nonlinear.csv",
    )?;
    let time = t.time();
    let y = col(&t, "ship.y")?;
    let psi: Vec<f64> = col(&t, "ship.heading")?.iter().map(|v| v / DEG).collect();
    let peak = max_abs(y) / CS_L;
    report.checks.push(Check::range(
        "AT-7 (nonlinear plant) peak lateral offset, current as initial sway v'0 = 5/22",
        "≈ 0.3 L (L2351, L2367); band 0.5x-2x: a stand-in hull",
        peak,
        0.15,
        0.6,
        "L",
    ));
    let k_max = (0..time.len())
        .max_by(|&a, &b| psi[a].abs().total_cmp(&psi[b].abs()))
        .unwrap_or(0);
    let psi_end = max_abs(&psi[time.iter().position(|&tk| tk >= 300.0).unwrap_or(0)..]);
    report.checks.push(Check::holds(
        "AT-7 (nonlinear plant) heading: turned by the current, recovered by the autopilot",
        "first turned to the right, then back to the commanded heading (Fig 5-8: +2..-4 deg)",
        format!(
            "largest excursion {:+.2} deg at {:.0} s; |heading| <= {psi_end:.3} deg after 300 s",
            psi[k_max], time[k_max]
        ),
        psi[k_max] > 0.5 && psi_end < 0.2,
    ));
    let rud: Vec<f64> = after(&t, "gear.rudder_angle", 200.0)?
        .iter()
        .map(|v| v / DEG)
        .collect();
    let jitter = std_dev(&rud);
    report.checks.push(Check::range(
        "AT-6 (nonlinear plant) actual-rudder steady jitter (std, t > 200 s)",
        "< 0.1 deg (L2433-2437)",
        jitter,
        0.0,
        0.1,
        "deg",
    ));
    let y_end = y.last().copied().unwrap_or(0.0) / CS_L;
    report.notes.push(format!(
        "AT-7 on the nonlinear plant: the thesis's plant [43] is not given; the Son & Nomoto container \
         ship stands in for it (it reproduces the thesis's 20 % speed loss in a 10 deg turn, AT-12) with the \
         thesis's nondimensional autopilot and gear scaled to its L = 175 m and U = 8.377 m/s, and the \
         current applied as the thesis did, as an initial sway velocity v'0 = 5/22 (sign not stated; chosen \
         so that the ship is first turned to the right, as in Fig 5-8). The ship is set {peak:.3} L off its \
         track (thesis ≈ 0.3 L) and ends {:.3} L off it (the autopilot does not regulate y, as in Fig 5-7); \
         the heading excursion {:+.1} deg is larger than the thesis's +2..-4 deg: the container ship's Munk \
         moment per unit sway is larger relative to its yaw damping than the destroyer's. These are readings \
         on a different hull; the 0.5x-2x band of the check says only that the mechanism (sway decaying \
         through the hull, heading disturbed and recovered) has the thesis's size.",
        y_end.abs(),
        psi[k_max]
    ));
    let fig = env.figure(
        "autopilot_current_nonlinear.png",
        "Heading autopilot on the nonlinear plant: 5-kn current as initial sway (AT-7)",
        &[
            Panel {
                y_label: "lateral offset [L]".into(),
                series: vec![series(&t, "ship.y", "actual", 1.0 / CS_L)?],
            },
            Panel {
                y_label: "heading [deg]".into(),
                series: vec![series(&t, "ship.heading", "heading", 1.0 / DEG)?],
            },
            rudder_panel(&t, "ap.rudder_command")?,
        ],
    )?;
    report.figures.push((
        "Current rejection on the nonlinear plant: offset, heading, rudder".into(),
        fig,
    ));
    Ok(())
}

/// AT-8 on the nonlinear stand-in plant (sway and speed loss in the turn).
fn track_change_nonlinear(env: &Env, report: &mut Report) -> Result<(), String> {
    let t = env.run(
        "autopilot_track_change_nonlinear.toml",
        &[],
        "autopilot_track_change_nonlinear.csv",
    )?;
    let time = t.time();
    let psi_ref = col(&t, "ap.heading_reference_used")?;
    let (x, y) = (col(&t, "ship.x")?, col(&t, "ship.y")?);
    let u0 = ContainerShip::straight_line_speed(80.0);
    let (xd, yd) = dead_reckoning(time, psi_ref, u0);
    let at = |t0: f64| {
        time.iter()
            .position(|&tk| tk >= t0)
            .unwrap_or(time.len() - 1)
    };
    // First new leg runs west: the cross-track is the north offset; at the end of the leg.
    let k1 = at(740.0);
    let xte1 = (x[k1] - xd[k1]) / CS_L;
    // Second leg runs north again: the cross-track is the east offset, at the end of the run.
    let k2 = time.len() - 1;
    let xte2 = (y[k2] - yd[k2]) / CS_L;
    report.checks.push(Check::range(
        "AT-8 (nonlinear plant) cross-track from the dead-reckoned path after the first turn",
        "≈ 3 L (L2495-2507); band 0.5x-1.5x: a stand-in hull",
        xte1.abs(),
        1.5,
        4.5,
        "L",
    ));
    report.checks.push(Check::holds(
        "AT-8 (nonlinear plant) the cross-track shrinks on the second leg",
        "smaller after the second turn: the sway reverses (L2495-2507)",
        format!(
            "{:.2} L after the first turn, {:.2} L after the second",
            xte1.abs(),
            xte2.abs()
        ),
        xte2.abs() < xte1.abs(),
    ));
    let sweep = rudder_sweep(&t, 40.0, 300.0)?;
    report.checks.push(Check::range(
        "AT-8 (nonlinear plant) rudder sweep in the first turn (1 deg/s ramp)",
        "≈ 20 deg over ≈ 3 min (L2519-2536); band ±25 %",
        sweep,
        15.0,
        25.0,
        "deg",
    ));
    let speed = col(&t, "ship.speed")?;
    let loss = 100.0 * (1.0 - speed.iter().cloned().fold(f64::MAX, f64::min) / u0);
    let heading = col(&t, "ship.heading")?;
    let e_ss = max_abs(
        &(0..time.len())
            .filter(|&k| (500.0..740.0).contains(&time[k]))
            .map(|k| (heading[k] - psi_ref[k]) / DEG)
            .collect::<Vec<_>>(),
    );
    report.checks.push(Check::range(
        "AT-8 (nonlinear plant) steady heading error on the leg (500-740 s) / 90 deg",
        "< 1 % (L2509-2513)",
        e_ss / 90.0 * 100.0,
        0.0,
        1.0,
        "%",
    ));
    report.notes.push(format!(
        "AT-8 on the nonlinear plant (container ship standing in for [43], 1 deg/s ramps, 600 s leg): \
         the ship loses {loss:.1} % speed in the turn and sways outward, and ends the first turn \
         {:.2} L off the dead-reckoned track (thesis ≈ 3 L; 0.95 L on the first-order Nomoto plant, \
         where only the ramp lag acts) and {:.2} L behind it along the track; after the second turn \
         the cross-track is {:.2} L (the thesis: it shrinks as the sway reverses). The rudder sweeps \
         {sweep:.1} deg (thesis ≈ 20 deg).",
        xte1.abs(),
        ((y[k1] - yd[k1]) / CS_L).abs(),
        xte2.abs()
    ));
    track_change_nonlinear_figure(env, &t, &xd, report)
}

/// The track change on the nonlinear plant: heading, offset from dead reckoning, speed, rudder.
fn track_change_nonlinear_figure(
    env: &Env,
    t: &ResultsTable,
    xd: &[f64],
    report: &mut Report,
) -> Result<(), String> {
    let (time, x) = (t.time(), col(t, "ship.x")?);
    let fig = env.figure(
        "autopilot_track_change_nonlinear.png",
        "Heading autopilot on the nonlinear plant, 90 deg track change (AT-8)",
        &[
            heading_panel(t)?,
            Panel {
                y_label: "north offset from dead reckoning [L]".into(),
                series: vec![Series {
                    label: "x - x_dr".into(),
                    t: time.to_vec(),
                    y: (0..time.len()).map(|k| (x[k] - xd[k]) / CS_L).collect(),
                }],
            },
            Panel {
                y_label: "speed [m/s]".into(),
                series: vec![series(t, "ship.speed", "speed", 1.0)?],
            },
            rudder_panel(t, "ap.rudder_command")?,
        ],
    )?;
    report.figures.push((
        "Track change on the nonlinear plant: heading, offset, speed, rudder".into(),
        fig,
    ));
    Ok(())
}

/// AT-9 (sea state 4 as a rudder-equivalent yaw disturbance, see the notes).
fn track_offset(env: &Env, report: &mut Report) -> Result<(), String> {
    let t = env.run(
        "autopilot_track_offset.toml",
        &[],
        "autopilot_track_offset.csv",
    )?;
    let time = t.time();
    let (y, yr) = (
        col(&t, "ship.y")?,
        col(&t, "ctl.cross_track_reference_used")?,
    );
    let (osc, dist) = steady_leg(&t)?;
    report.checks.push(Check::range(
        "AT-9 oscillation about the track on the steady leg (t > 900 s, SS4 + 5-kn current, noisy y)",
        "< 20 yd (L2792; with SS4)",
        osc,
        0.0,
        20.0,
        "yd",
    ));
    let psi = after(&t, "ship.heading", 1200.0)?;
    let psi_mean = mean(psi) / DEG;
    let crab = -(5.0 / 22.0_f64).asin() / DEG;
    report.checks.push(Check::abs(
        "AT-9 steady heading offset into the current (current to starboard: negative)",
        crab,
        psi_mean,
        0.2,
        "deg",
    ));
    let pre: Vec<f64> = (0..time.len())
        .filter(|&k| time[k] < 300.0)
        .map(|k| y[k])
        .collect();
    let during: Vec<f64> = (0..time.len())
        .filter(|&k| (300.0..900.0).contains(&time[k]))
        .map(|k| y[k] - yr[k])
        .collect();
    // Sweep of the (assumed) wave level: calm water and ten times the system's yaw gain.
    let at_wave_level = |gain: f64, tag: &str| -> Result<(f64, f64), String> {
        steady_leg(&env.run(
            "autopilot_track_offset.toml",
            &[format!("waves.yaw_gain={gain}")],
            &format!("autopilot_track_offset_{tag}.csv"),
        )?)
    };
    let (osc_calm, _) = at_wave_level(0.0, "calm")?;
    let (osc_10, dist_10) = at_wave_level(10.0 * WAVE_YAW_GAIN, "waves_x10")?;
    report.checks.push(Check::holds(
        "AT-9 the wave disturbance acts on the loop (SS4 vs calm water, same noise)",
        "waves move the ship about the track (Figs 5-22 to 5-24)",
        format!(
            "rudder-equivalent wave yaw std {dist:.2} deg; largest deviation {osc:.3} yd in SS4, \
             {osc_calm:.3} yd calm, {osc_10:.3} yd at ten times the wave level ({dist_10:.1} deg)"
        ),
        dist > 1.0 && osc_10 > osc && osc > osc_calm,
    ));
    report.notes.push(format!(
        "AT-9: sea state 4 is the Waves FMU's SS4 preset (Pierson-Moskowitz, Hs 1.875 m, Tp 8.84 s; the \
         thesis gives Hs 1.25-2.5 m and no spectrum or filter, spec §2.18, §6 item 7), head-quartering \
         from the port bow. How the thesis's wave disturbance enters its hull is not given: here the wave \
         yaw moment (003 eq. 2.24) enters the Nomoto model as a rudder-equivalent disturbance with an \
         assumed level ({dist:.2} deg std). That wave-frequency disturbance (encounter periods of a few seconds) is \
         filtered by the hull (T = 24.2 s): the track oscillation stays at {osc:.3} yd ({osc_calm:.3} yd \
         calm, {osc_10:.3} yd at a {dist_10:.1} deg disturbance), far inside the 20 yd. The thesis's \
         oscillations of up to 20 yd come from the low-frequency content its unspecified filter kept \
         (\"filtered to preserve only the low-frequency components\"), which is not reproducible: the \
         check is the criterion, not the thesis's amplitude. The 5-kn gust is a step at 60 s into the \
         kinematics; cross-track noise sigma = 0.05 m. The noise level is not given; C_y's \
         high-frequency gain (20 000 rad per L) makes the loop very sensitive to it: at the Sensors \
         preset 2.77 m the rudder saturates throughout and the track is lost; 0.28 m gives ≈ 68 m \
         deviations. Readings: current-gust peak {:.1} m ({:.3} L), largest deviation during the \
         offset manoeuvre {:.1} m, steady heading {psi_mean:.2} deg (crab angle asin(5/22) = {crab:.2} deg).",
        max_abs(&pre),
        max_abs(&pre) / L,
        max_abs(&during)
    ));
    track_offset_figure(env, &t, report)
}

/// The steady leg of a track-offset run (t > 900 s): the largest deviation from the track [yd]
/// and the std of the rudder-equivalent wave yaw disturbance [deg].
fn steady_leg(t: &ResultsTable) -> Result<(f64, f64), String> {
    let time = t.time();
    let (y, yr) = (col(t, "ship.y")?, col(t, "ctl.cross_track_reference_used")?);
    let dev: Vec<f64> = (0..time.len())
        .filter(|&k| time[k] > 900.0)
        .map(|k| y[k] - yr[k])
        .collect();
    Ok((
        max_abs(&dev) / 0.9144,
        std_dev(after(t, "waves.yaw_moment", 900.0)?) / DEG,
    ))
}

/// The lateral offset: track, heading, rudder.
fn track_offset_figure(env: &Env, t: &ResultsTable, report: &mut Report) -> Result<(), String> {
    let fig = env.figure(
        "autopilot_track_offset.png",
        "Track controller: SS4, 5-kn gust and 2 L offset to port (AT-9)",
        &[
            Panel {
                y_label: "cross-track [L]".into(),
                series: vec![
                    series(t, "ctl.cross_track_reference_used", "desired", 1.0 / L)?,
                    series(t, "ship.y", "actual", 1.0 / L)?,
                ],
            },
            Panel {
                y_label: "heading [deg]".into(),
                series: vec![series(t, "ship.heading", "heading", 1.0 / DEG)?],
            },
            rudder_panel(t, "ctl.rudder_command")?,
        ],
    )?;
    report
        .figures
        .push(("Lateral offset: track, heading, rudder".into(), fig));
    Ok(())
}

/// The linear sway-yaw model with a 5 deg/s rate-limited rudder (as the AT-11 model test).
struct LinearRun {
    ship: NomotoShip,
    rudder: f64,
}

impl ManoeuvreShip for LinearRun {
    fn sample(&self) -> Sample {
        let o = self.ship.outputs();
        Sample {
            t: o.time,
            x: o.x,
            y: o.y,
            psi: o.heading,
            r: o.yaw_rate,
            speed: o.speed_over_ground,
            roll: 0.0,
            drift: o.sway_velocity.atan2(self.ship.speed),
            rudder: self.rudder,
            rudder_command: 0.0,
        }
    }
    fn advance(&mut self, cmd: f64, h: f64) {
        let target = cmd.clamp(-35.0 * DEG, 35.0 * DEG);
        let d = (target - self.rudder).clamp(-5.0 * DEG * h, 5.0 * DEG * h);
        let mid = self.rudder + 0.5 * d;
        self.rudder += d;
        self.ship.step(
            &NomotoInputs {
                rudder: mid,
                ..Default::default()
            },
            h,
        );
    }
}

/// AT-11 through the FMUs.
fn identification(env: &Env, report: &mut Report) -> Result<(), String> {
    let t = env.run(
        "identification_zigzag.toml",
        &[],
        "identification_zigzag.csv",
    )?;
    let n = [
        last(&t, "kf.neg_y_v_mean")?,
        last(&t, "kf.m_minus_y_r_mean")?,
        last(&t, "kf.neg_n_v_mean")?,
        last(&t, "kf.mxg_minus_n_r_mean")?,
    ];
    let plant = ContainerShip::at_equilibrium(80.0).map_err(|e| format!("{e:?}"))?;
    let u0 = plant.outputs().u;
    let gen = ManoeuvreGenerator::new(
        ManoeuvreKind::TurningCircle { rudder: 10.0 * DEG },
        0.0,
        0.0,
    );
    let mut p = ContainerShipRun {
        ship: plant,
        shaft_command_rpm: 80.0,
    };
    let tp = turning_circle(&run_manoeuvre(&mut p, &mut gen.clone(), 0.5, 3000.0), 0.0)
        .map_err(|e| format!("{e:?}"))?;
    let model = NomotoModel::SwayYaw {
        m: [[LIN_M[0][0], LIN_M[0][1]], [LIN_M[1][0], LIN_M[1][1]]],
        n: [[n[0], n[1]], [n[2], n[3]]],
        b: [LIN_B[0], LIN_B[1]],
    };
    let mut lin = LinearRun {
        ship: NomotoShip::new(model, CS_L, u0).map_err(|e| format!("{e:?}"))?,
        rudder: 0.0,
    };
    let tl = turning_circle(&run_manoeuvre(&mut lin, &mut gen.clone(), 0.5, 3000.0), 0.0)
        .map_err(|e| format!("{e:?}"))?;
    let tact = tl.tactical_diameter / tp.tactical_diameter - 1.0;
    let steady = tl.steady_diameter / tp.steady_diameter - 1.0;
    report.checks.push(Check::range(
        "AT-11 identified vs plant 10° tactical diameter (identified tighter: negative)",
        "≈ -15 % (L1790); model-level test -15.1 %",
        100.0 * tact,
        -20.0,
        0.0,
        "%",
    ));
    report.checks.push(Check::range(
        "AT-12 plant speed loss in the 10° turn",
        "≈ 20 % (L1776)",
        100.0 * tp.speed_loss,
        18.0,
        23.0,
        "%",
    ));
    report.notes.push(format!(
        "AT-11: ContainerShip stands in for the thesis's nonlinear plant [43] (not given). Coefficients \
         identified through the FMUs (mean of the last 67 %): -Y_v' {:.5}, m'-Y_r' {:.5}, -N_v' {:.6}, \
         m'x_G'-N_r' {:.6} (Nomoto T' {:.3}, K' {:.3}); 10° turn: plant tactical {:.0} m, steady {:.0} m; \
         identified {:+.1} % tactical, {:+.1} % steady (the model test: -15.1 % / -24.0 %; the steady \
         diameter is outside 20 % for the reason given there: no linear model matches the plant's \
         nonlinear steady r'/delta at all rudder angles). The FMU run differs from the model test in the \
         rudder fed to the filter (the actual angle at the communication point, not the step average) and \
         in u0 rounded to 8.37667 m/s in the filter parameters.",
        n[0],
        n[1],
        n[2],
        n[3],
        last(&t, "kf.nomoto_time_constant_prime")?,
        last(&t, "kf.nomoto_gain_prime")?,
        tp.tactical_diameter,
        tp.steady_diameter,
        100.0 * tact,
        100.0 * steady
    ));
    identification_figure(env, &t, report)
}

/// The identification run: zig-zag and the estimates.
fn identification_figure(env: &Env, t: &ResultsTable, report: &mut Report) -> Result<(), String> {
    let fig = env.figure(
        "identification_zigzag.png",
        "10/10 zig-zag on ContainerShip feeding ParameterEkf (AT-11)",
        &[
            Panel {
                y_label: "heading, rudder [deg]".into(),
                series: vec![
                    series(t, "ship.heading", "heading", 1.0 / DEG)?,
                    series(t, "ship.rudder_angle", "rudder", 1.0 / DEG)?,
                ],
            },
            Panel {
                y_label: "estimate / mean".into(),
                series: vec![
                    series(t, "kf.neg_y_v_estimate", "-Y_v' x100", 100.0)?,
                    series(t, "kf.m_minus_y_r_estimate", "m'-Y_r' x100", 100.0)?,
                    series(t, "kf.neg_n_v_estimate", "-N_v' x100", 100.0)?,
                    series(t, "kf.mxg_minus_n_r_estimate", "m'x_G'-N_r' x100", 100.0)?,
                ],
            },
        ],
    )?;
    report
        .figures
        .push(("Identification run: zig-zag and estimates".into(), fig));
    Ok(())
}
