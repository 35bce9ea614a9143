//! Loop analysis through the FMUs (issue 35, docs/loop-analysis.md): margins and frequency
//! responses measured by [`shipsim::analysis`] on three coupled systems, beside the sources.
//!
//! * **DDG-51 heading loop**, `autopilot_current.toml` broken at `ap.rudder_command ->
//!   gear.rudder_command`: the measured margins against the independent calculation of the
//!   same sampled loop (`tests/python/loop_reference.py`, numpy only, from the models' sources;
//!   its "measured: reference" row) within the 0.2 dB and 0.5°, and against the thesis's
//!   continuous design, 29.823 dB / 64.406° [Taylor2000, Fig. 5-5], only through the documented
//!   difference: the term-by-term table of loop_reference's docstring (gear, master sampling,
//!   the held gear angle, the Jacobi steps, the sensor's 1 s hold, the window's alias leakage).
//! * **Track loop (AT-2)**, `autopilot_track_offset.toml` at `ctl.rudder_command ->
//!   gear.rudder_command`, likewise; the thesis's 21.574 dB / 50.99° [Taylor2000, Fig. 5-16].
//!   Settings of both as `tests/python/test_loop_verification.py` uses them.
//! * **RRS roll loop**, `rrs.toml` at 11 m/s [Klugt1987]: the margins at `autopilot.rudder_command
//!   -> gear.rudder_command` with RRS on (`roll_mode = 1`, as the file sets it) and off, and the
//!   roll response to the wave roll moment (the connection `waves.roll_moment ->
//!   ship.roll_disturbance`, the rudder-equivalent w_φ of [Klugt1987, eq. (3.29)]) with RRS off
//!   and on: the band where the roll is reduced, against the thesis's account of where RRS
//!   reduces roll [Klugt1987, secs. 1.2, 6.3, 6.5.2, 7.4]. The thesis gives no margins and no
//!   band edge; it gives ω_n and z_n [Klugt1987, Table 2.4], which the RRS-off response measures.
//!
//! The RRS operating point (a clean measurement): the sea, the wind moments and the sensor noise
//! are off (a deterministic sinusoid at ω is the disturbance); the two adaptations that would
//! follow the injected sinusoid during a fork are frozen at the values they reach in the file's
//! own sea (the criterion weight q_φ [Klugt1987, sec. 6.4.2] and the yaw filter's E*[w3²]
//! [Klugt1987, sec. 5.5.4], means of the file's adaptive run after 200 s, as the `rrs` study
//! settles); the state at T = 300 s (the innovation process has converged, the loop is at rest)
//! is the operating point.

use crate::study::{after, fmt_num, mean, Check, Env, Report};
use nalgebra::{Complex, Matrix2, Vector2};
use shipsim::analysis::{
    self, Injection, LoopPoint, Margins, Options, OutputResponse, ResponsePoint,
};
use shipsim::fmu::Fmu;
use shipsim::results::ResultsTable;
use shipsim::run::{load_fmus, run_system, Output, RunOptions};
use shipsim::system::System;
use std::path::{Path, PathBuf};
use std::sync::Arc;

type C64 = Complex<f64>;

const HEADING_FILE: &str = "autopilot_current.toml";
const TRACK_FILE: &str = "autopilot_track_offset.toml";
const RRS_FILE: &str = "rrs.toml";
const HEADING_BREAK: &str = "ap.rudder_command -> gear.rudder_command";
const TRACK_BREAK: &str = "ctl.rudder_command -> gear.rudder_command";
const RRS_BREAK: &str = "autopilot.rudder_command -> gear.rudder_command";
const WAVE_ROLL: &str = "waves.roll_moment -> ship.roll_disturbance";

/// The sinusoid's amplitude [rad] (0.57°): far inside the rudder and rate limits.
const AMPLITUDE: f64 = 0.01;
/// Settling before each window [s]: the slowest closed-loop modes decay by e^-12 or more.
const SETTLE: f64 = 300.0;
/// The RRS operating point [s] and the time after which the adaptive run's means are taken.
const RRS_AT: f64 = 300.0;
const RRS_ADAPTED_FROM: f64 = 200.0;
/// [Klugt1987, Table 2.4] at U = 11 m/s: ω_n = 0.63 rad/s, z_n = 0.064 + 0.0038 U.
const OMEGA_N: f64 = 0.63;
const SPEED: f64 = 11.0;
const Z_N0: f64 = 0.064;
const Z_N1: f64 = 0.0038;
/// The RRS gear's time constant [s] (systems/rrs.toml) and the thesis's rule τ_δ ≤ 0.2/ω_n
/// [Klugt1987, eq. (6.37)].
const RRS_GEAR_TAU: f64 = 0.2;

/// One row of loop_reference's term-by-term table (its docstring, FINDINGS (c) and (d)):
/// gain margin [dB] at w180, phase margin [deg] at wc, delay margin [s], sensitivity peak at w_ms.
struct Row {
    label: &'static str,
    gm: f64,
    w180: f64,
    pm: f64,
    wc: f64,
    dm: f64,
    ms: f64,
    w_ms: f64,
}

const fn row(label: &'static str, v: [f64; 7]) -> Row {
    Row {
        label,
        gm: v[0],
        w180: v[1],
        pm: v[2],
        wc: v[3],
        dm: v[4],
        ms: v[5],
        w_ms: v[6],
    }
}

/// The heading loop: the continuous design [Taylor2000], each effect of the co-simulation added
/// in turn, the exact fundamental term, and the reference's simulation of the tool's measurement.
const HEADING_ROWS: [Row; 7] = [
    row(
        "continuous design [Taylor2000] (gear a/(s'+a), a = 6)",
        [29.823, 0.6172, 64.406, 0.07288, 15.42, 1.3038, 0.1429],
    ),
    row(
        "+ the file's gear, time_constant = 2.0916 s (= L/(6U))",
        [29.823, 0.6172, 64.406, 0.07288, 15.42, 1.3038, 0.1429],
    ),
    row(
        "+ master sampling h = 0.05 s: Tustin, gear + ship ZOH",
        [29.304, 0.5990, 64.302, 0.07288, 15.40, 1.3062, 0.1426],
    ),
    row(
        "+ ship fed the held gear angle (gear exact, ship RK4)",
        [28.813, 0.5823, 64.197, 0.07288, 15.37, 1.3086, 0.1424],
    ),
    row(
        "+ Jacobi: one step in the autopilot, one in the sensor",
        [27.107, 0.5271, 63.779, 0.07288, 15.27, 1.3182, 0.1416],
    ),
    row(
        "+ sensor sample-and-hold every 1 s (fundamental term)",
        [22.317, 0.3942, 61.999, 0.07287, 14.85, 1.3609, 0.1380],
    ),
    row(
        "measured (P = 4, settle 300 s, A = 0.01 rad): reference",
        [22.293, 0.3939, 61.996, 0.07287, 14.849, 1.3609, 0.1380],
    ),
];

const TRACK_ROWS: [Row; 7] = [
    row(
        "continuous design [Taylor2000]",
        [21.574, 0.5798, 50.990, 0.07581, 11.74, 1.2512, 0.1266],
    ),
    row(
        "+ the file's gear (= L/(6U))",
        [21.574, 0.5798, 50.990, 0.07581, 11.74, 1.2512, 0.1266],
    ),
    row(
        "+ master sampling h = 0.05 s: Tustin, gear + ship ZOH",
        [21.410, 0.5731, 50.882, 0.07581, 11.71, 1.2539, 0.1264],
    ),
    row(
        "+ ship fed the held gear angle (gear exact, ship RK4)",
        [21.251, 0.5665, 50.773, 0.07581, 11.69, 1.2567, 0.1262],
    ),
    row(
        "+ Jacobi: one step in the controller, one in the sensor",
        [20.648, 0.5420, 50.338, 0.07581, 11.59, 1.2678, 0.1255],
    ),
    row(
        "+ sensor sample-and-hold every 1 s (fundamental term)",
        [18.576, 0.4588, 48.480, 0.07579, 11.16, 1.3175, 0.1221],
    ),
    row(
        "measured (P = 8, settle 300 s, A = 0.01 rad): reference",
        [18.526, 0.4576, 48.516, 0.07582, 11.17, 1.3182, 0.1216],
    ),
];

/// A DDG-51 loop: its file, break, settings, window and the sources' numbers.
struct DdgLoop {
    id: &'static str,
    name: &'static str,
    file: &'static str,
    connection: &'static str,
    sets: &'static [&'static str],
    periods: u32,
    rows: &'static [Row; 7],
    /// The thesis's printed continuous-design margins and where.
    thesis: (f64, f64, &'static str),
}

const HEADING_SETS: &[&str] = &[
    "sensors.noise_scale=0",
    "current.current_speed_initial=0",
    "current.current_speed_final=0",
];
const TRACK_SETS: &[&str] = &[
    "sensors.noise_scale=0",
    "current.current_speed_initial=0",
    "current.current_speed_final=0",
    "waves.yaw_gain=0",
    "ctl.reference_mode=0",
];

const HEADING: DdgLoop = DdgLoop {
    id: "heading",
    name: "heading loop",
    file: HEADING_FILE,
    connection: HEADING_BREAK,
    sets: HEADING_SETS,
    periods: 4,
    rows: &HEADING_ROWS,
    thesis: (29.823, 64.406, "[Taylor2000, Fig. 5-5]"),
};

const TRACK: DdgLoop = DdgLoop {
    id: "track",
    name: "track loop (AT-2)",
    file: TRACK_FILE,
    connection: TRACK_BREAK,
    sets: TRACK_SETS,
    periods: 8,
    rows: &TRACK_ROWS,
    thesis: (21.574, 50.99, "[Taylor2000, Fig. 5-16]"),
};

// ------------------------------------------------------------------------------------------
// Running the analysis
// ------------------------------------------------------------------------------------------

fn strings(sets: &[&str]) -> Vec<String> {
    sets.iter().map(|s| s.to_string()).collect()
}

/// `systems/<file>` with the overrides, and its FMUs.
fn load(env: &Env, file: &str, sets: &[String]) -> Result<(System, Vec<Arc<Fmu>>), String> {
    let mut system = env.system(file)?;
    system.apply_overrides(sets).map_err(|e| e.to_string())?;
    let fmus = load_fmus(&system).map_err(|e| format!("{file}: {e}"))?;
    Ok((system, fmus))
}

/// Six significant digits, as test_loop_verification.py writes its frequencies.
fn six_digits(x: f64) -> f64 {
    format!("{x:.5e}").parse().unwrap_or(x)
}

/// The 30 frequencies of the DDG-51 loops: 0.02 ... 1.5 rad/s, log-spaced.
fn ddg_frequencies() -> Vec<f64> {
    analysis::log_space(0.02, 1.5, 30)
        .into_iter()
        .map(six_digits)
        .collect()
}

/// The RRS frequencies: 0.05 ... 5 rad/s, a decade below to eight times above ω_n, 8 % apart
/// (the RRS-off resonance's half-power width is 2 z_n ω_n = 0.13 rad/s).
fn rrs_frequencies() -> Vec<f64> {
    analysis::log_space(0.05, 5.0, 60)
}

fn options(frequencies: Vec<f64>, periods: u32, at: Option<f64>) -> Options {
    Options {
        at,
        frequencies: Some(frequencies),
        amplitude: AMPLITUDE,
        periods,
        settle: Some(SETTLE),
        ..Options::default()
    }
}

/// Copies a written plot to a name of its own in the study's folder (the report copies figures
/// by file name).
fn figure(env: &Env, written: &Path, name: &str) -> Result<PathBuf, String> {
    let dest = env.out_dir.join(name);
    std::fs::copy(written, &dest).map_err(|e| format!("copying {}: {e}", written.display()))?;
    Ok(dest)
}

fn plot<'a>(written: &'a analysis::Written, stem: &str) -> Result<&'a PathBuf, String> {
    written
        .plots
        .iter()
        .find(|p| p.file_stem().is_some_and(|s| s == stem))
        .ok_or_else(|| format!("no {stem} plot written"))
}

// ------------------------------------------------------------------------------------------
// The DDG-51 loops
// ------------------------------------------------------------------------------------------

fn some(x: Option<f64>, what: &str) -> Result<f64, String> {
    x.ok_or_else(|| format!("the loop has no {what} in the measured range"))
}

/// Measures a DDG-51 loop, checks it and writes its table and plots.
fn ddg_loop(env: &Env, l: &DdgLoop, report: &mut Report) -> Result<(), String> {
    let (system, fmus) = load(env, l.file, &strings(l.sets))?;
    let opts = options(ddg_frequencies(), l.periods, None);
    let (points, m) =
        analysis::loop_margins(&system, &fmus, l.connection, &opts).map_err(|e| e.to_string())?;
    let dir = env.out_dir.join(l.id);
    let written = analysis::write_margins(&dir, &points, &m, &format!("DDG-51 {}", l.name))
        .map_err(|e| e.to_string())?;
    let fig = figure(env, plot(&written, "bode")?, &format!("{}_bode.png", l.id))?;
    let (gm, pm) = (
        some(m.gain_margin_db, "gain margin")?,
        some(m.phase_margin_deg, "phase margin")?,
    );
    let reference = &l.rows[6];
    let ref_src = "[DERIVED] loop_reference.py, the sampled loop's measurement";
    let c = &mut report.checks;
    c.push(Check::abs(
        &format!("{}: gain margin", l.name),
        reference.gm,
        gm,
        0.2,
        "dB",
    ));
    c.push(Check::abs(
        &format!("{}: phase margin", l.name),
        reference.pm,
        pm,
        0.5,
        "deg",
    ));
    let rel = |q: &str, p: f64, o: f64, tol: f64, unit: &str| {
        Check::rel(&format!("{}: {q}", l.name), p, o, tol, unit)
    };
    c.push(rel(
        "crossover",
        reference.wc,
        some(m.crossover_rad_s, "crossover")?,
        0.005,
        "rad/s",
    ));
    c.push(rel(
        "phase crossover",
        reference.w180,
        some(m.gain_margin_rad_s, "phase crossover")?,
        0.01,
        "rad/s",
    ));
    c.push(rel(
        "delay margin",
        reference.dm,
        some(m.delay_margin_s, "delay margin")?,
        0.015,
        "s",
    ));
    c.push(rel(
        "sensitivity peak max 1/\\|1+L\\|",
        reference.ms,
        m.sensitivity_peak,
        0.01,
        "",
    ));
    for c in c.iter_mut().rev().take(6) {
        c.published = format!("{} ({ref_src})", c.published);
    }
    // The thesis's continuous design and the documented co-simulation terms (the rows of the
    // term-by-term table: each effect, then the window's alias leakage).
    let (tgm, tpm, cite) = l.thesis;
    let terms = |f: fn(&Row) -> f64, unit: &str, thesis: f64| -> (f64, String) {
        let steps: Vec<f64> = l.rows.windows(2).map(|w| f(&w[1]) - f(&w[0])).collect();
        let shown: Vec<String> = steps
            .iter()
            .zip(&l.rows[1..])
            .filter(|(d, _)| **d != 0.0)
            .map(|(d, r)| format!("{} ({})", signed(*d), short(r.label)))
            .collect();
        let sum: f64 = steps.iter().sum();
        (
            thesis + sum,
            format!(
                "{thesis} {unit} {cite} {} = {:.3} {unit}",
                shown.join(" "),
                thesis + sum
            ),
        )
    };
    let (gm_expected, gm_text) = terms(|r| r.gm, "dB", tgm);
    let (pm_expected, pm_text) = terms(|r| r.pm, "deg", tpm);
    report.checks.push(Check {
        published: gm_text,
        ..Check::abs(
            &format!(
                "{}: gain margin, the thesis's continuous design less the documented terms",
                l.name
            ),
            gm_expected,
            gm,
            0.2,
            "dB",
        )
    });
    report.checks.push(Check {
        published: pm_text,
        ..Check::abs(
            &format!(
                "{}: phase margin, the thesis's continuous design less the documented terms",
                l.name
            ),
            pm_expected,
            pm,
            0.5,
            "deg",
        )
    });
    report.notes.push(term_table(l, &m, points.len()));
    report.figures.push((
        format!(
            "DDG-51 {}: L(jω) at {}, measured through the FMUs (the crossings marked)",
            l.name, l.connection
        ),
        fig,
    ));
    Ok(())
}

/// The effect a term-by-term row adds, in a few words.
fn short(label: &str) -> &str {
    match label {
        l if l.contains("master sampling") => "sampling",
        l if l.contains("held gear") => "held gear angle",
        l if l.contains("Jacobi") => "Jacobi steps",
        l if l.contains("sample-and-hold") => "1 s sensor hold",
        l if l.starts_with("measured") => "window's alias leakage",
        l => l,
    }
}

fn signed(x: f64) -> String {
    match x < 0.0 {
        true => format!("− {:.3}", -x),
        false => format!("+ {x:.3}"),
    }
}

/// The term-by-term table of loop_reference with the tool's row and each row's change.
fn term_table(l: &DdgLoop, m: &Margins, n: usize) -> String {
    let mut s = format!(
        "DDG-51 {}, break `{}`, `--set {}`, {} frequencies 0.02 ... 1.5 rad/s, amplitude {} rad, \
         {} periods, settle {} s, from the start (the zero state): term by term (each row adds \
         one effect; loop_reference.py, FINDINGS (c)/(d), computed from the models' sources, not \
         from the tool), Δ = the change of each row:\n\n\
         | | GM [dB] | ΔGM | ω180 [rad/s] | PM [°] | ΔPM | ωc [rad/s] | DM [s] | Ms | ω_Ms |\n\
         |---|---|---|---|---|---|---|---|---|---|",
        l.name,
        l.connection,
        l.sets.join(" --set "),
        ddg_frequencies().len(),
        AMPLITUDE,
        l.periods,
        SETTLE
    );
    for (i, r) in l.rows.iter().enumerate() {
        let (dg, dp) = match i {
            0 => (String::new(), String::new()),
            _ => (
                format!("{:+.3}", r.gm - l.rows[i - 1].gm),
                format!("{:+.3}", r.pm - l.rows[i - 1].pm),
            ),
        };
        s += &format!(
            "\n| {} | {:.3} | {dg} | {:.4} | {:.3} | {dp} | {:.5} | {} | {:.4} | {:.4} |",
            r.label,
            r.gm,
            r.w180,
            r.pm,
            r.wc,
            fmt_num(r.dm),
            r.ms,
            r.w_ms
        );
    }
    let o = |x: Option<f64>, d: usize| x.map_or("none".into(), |v| format!("{v:.d$}"));
    s += &format!(
        "\n| **measured: shipsim::analysis** ({n} points: the grid and the refinements; Ms the \
         largest over the points) | **{}** | {} | {} | **{}** | {} | {} | {} | {:.4} | {:.4} |",
        o(m.gain_margin_db, 3),
        m.gain_margin_db
            .map_or(String::new(), |g| format!("{:+.3}", g - l.rows[6].gm)),
        o(m.gain_margin_rad_s, 4),
        o(m.phase_margin_deg, 3),
        m.phase_margin_deg
            .map_or(String::new(), |p| format!("{:+.3}", p - l.rows[6].pm)),
        o(m.crossover_rad_s, 5),
        o(m.delay_margin_s, 3),
        m.sensitivity_peak,
        m.sensitivity_peak_rad_s
    );
    let (first, fundamental) = (&l.rows[0], &l.rows[5]);
    s += &format!(
        "\n\nEach row is a delay added at an unchanged crossover (the command held over the step, \
         the gear angle held into the ship, the Jacobi steps of the controller and the sensor, \
         the 1 s hold's mean delay of 9.55 steps): 0.5775 s in all, so the phase margin falls by \
         only {:.2}° (at ωc = {:.3} rad/s) while the phase crossover moves down from {:.3} to \
         {:.3} rad/s and the gain margin falls by {:.2} dB. The last reference row differs from \
         the fundamental term by the 1 s hold's aliases leaking into a window that is not a \
         whole number of sensor periods; the tool's refinement points are other windows, with \
         other leakage.\n",
        first.pm - fundamental.pm,
        first.wc,
        first.w180,
        fundamental.w180,
        first.gm - fundamental.gm
    );
    s
}

// ------------------------------------------------------------------------------------------
// The RRS loop
// ------------------------------------------------------------------------------------------

/// The gains the file's adaptations reach in its own sea: (q_φ, E*[w3²]), means after 200 s.
fn adapted(env: &Env) -> Result<(f64, f64), String> {
    let mut system = env.system(RRS_FILE)?;
    system.output.variables = Some(strings(&["autopilot.q_phi", "filter.yaw_e_w3_used"]));
    system.output.decimation = 1;
    std::fs::create_dir_all(&env.out_dir).map_err(|e| e.to_string())?;
    let out = env.out_dir.join("rrs_adaptive.csv");
    run_system(&system, Output::File(out.clone()), &RunOptions::default())
        .map_err(|e| format!("{RRS_FILE}: {e}"))?;
    let t = ResultsTable::read(&out).map_err(|e| e.to_string())?;
    let m = |c: &str| -> Result<f64, String> { Ok(mean(after(&t, c, RRS_ADAPTED_FROM)?)) };
    // four significant digits: the frozen values as the notes print them
    let four = |x: f64| fmt_num(x).parse::<f64>().map_err(|e| e.to_string());
    Ok((
        four(m("autopilot.q_phi")?)?,
        four(m("filter.yaw_e_w3_used")?)?,
    ))
}

/// The RRS settings of the analysis (see the module docs) with the frozen adaptations.
fn rrs_sets(q_phi: f64, e_w3: f64, roll_mode: u8) -> Vec<String> {
    let mut s = strings(&[
        "waves.significant_wave_height=0",
        "wind.roll_coefficient=0",
        "wind.yaw_coefficient=0",
        "sensors.noise_scale=0",
        "autopilot.adaptation_enabled=false",
        "filter.yaw_adaptive=false",
    ]);
    s.push(format!("autopilot.q_phi_initial={q_phi}"));
    s.push(format!("filter.yaw_e_w3={e_w3}"));
    s.push(format!("autopilot.roll_mode={roll_mode}"));
    s
}

/// One gain crossover of a measured loop.
struct GainCrossing {
    omega: f64,
    /// ∠L wrapped to (−180°, 180°].
    phase_deg: f64,
}

impl GainCrossing {
    /// The phase lag that brings L to −1: (∠L + 180°) mod 360°, in [0°, 360°).
    fn lag_deg(&self) -> f64 {
        (self.phase_deg + 180.0).rem_euclid(360.0)
    }

    /// The phase margin as the angle between L and −1 on the unit circle (either direction).
    fn margin_deg(&self) -> f64 {
        let lag = self.lag_deg();
        lag.min(360.0 - lag)
    }

    /// The delay that uses the lag up.
    fn delay_s(&self) -> f64 {
        self.lag_deg().to_radians() / self.omega
    }
}

/// Every crossing of |L| = 1 and of the negative real axis between neighbouring points (linear
/// in log ω): the gain crossovers, and the phase crossovers as (ω, gain margin [dB]).
fn crossings(points: &[LoopPoint]) -> (Vec<GainCrossing>, Vec<(f64, f64)>) {
    let (mut gains, mut phases) = (Vec::new(), Vec::new());
    for w in points.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let at = |s: f64| (a.omega.ln() + s * (b.omega.ln() - a.omega.ln())).exp();
        let (ga, gb) = (20.0 * a.l.norm().log10(), 20.0 * b.l.norm().log10());
        if ga.signum() != gb.signum() {
            let s = ga / (ga - gb);
            let phase = a.l.arg() + s * (b.l / a.l).arg();
            let p = phase.to_degrees();
            gains.push(GainCrossing {
                omega: at(s),
                phase_deg: p - 360.0 * ((p - 180.0) / 360.0).ceil(),
            });
        }
        if a.l.im.signum() != b.l.im.signum() {
            let s = a.l.im / (a.l.im - b.l.im);
            if a.l.re + s * (b.l.re - a.l.re) < 0.0 {
                phases.push((at(s), -(ga + s * (gb - ga))));
            }
        }
    }
    (gains, phases)
}

/// The measured RRS loop at the break, RRS on or off.
struct RrsLoop {
    points: Vec<LoopPoint>,
    margins: Margins,
    gains: Vec<GainCrossing>,
    phases: Vec<(f64, f64)>,
}

impl RrsLoop {
    fn phase_margin(&self) -> Option<&GainCrossing> {
        self.gains
            .iter()
            .min_by(|a, b| a.margin_deg().total_cmp(&b.margin_deg()))
    }

    fn delay_margin(&self) -> Option<&GainCrossing> {
        self.gains
            .iter()
            .min_by(|a, b| a.delay_s().total_cmp(&b.delay_s()))
    }

    fn gain_margin(&self) -> Option<(f64, f64)> {
        self.phases
            .iter()
            .copied()
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// L at a grid frequency (exactly as the response's fork snapped it).
    fn at(&self, omega: f64) -> Option<C64> {
        self.points.iter().find(|p| p.omega == omega).map(|p| p.l)
    }

    fn linearity(&self) -> (f64, f64) {
        largest_change(
            self.points
                .iter()
                .map(|p| (p.gain_change_db, p.phase_change_deg)),
        )
    }
}

fn largest_change(v: impl Iterator<Item = (Option<f64>, Option<f64>)>) -> (f64, f64) {
    v.fold((0.0f64, 0.0f64), |(g, p), (dg, dp)| {
        (
            g.max(dg.map_or(0.0, f64::abs)),
            p.max(dp.map_or(0.0, f64::abs)),
        )
    })
}

fn rrs_loop(env: &Env, sets: &[String]) -> Result<RrsLoop, String> {
    let (system, fmus) = load(env, RRS_FILE, sets)?;
    let opts = options(rrs_frequencies(), 4, Some(RRS_AT));
    let (points, margins) =
        analysis::loop_margins(&system, &fmus, RRS_BREAK, &opts).map_err(|e| e.to_string())?;
    let (gains, phases) = crossings(&points);
    Ok(RrsLoop {
        points,
        margins,
        gains,
        phases,
    })
}

/// The roll response to the wave roll moment (the sinusoid on the connection).
fn roll_response(
    env: &Env,
    sets: &[String],
    freqs: Vec<f64>,
) -> Result<Vec<ResponsePoint>, String> {
    let (system, fmus) = load(env, RRS_FILE, sets)?;
    let opts = options(freqs, 4, Some(RRS_AT));
    analysis::frequency_response(
        &system,
        &fmus,
        &Injection::Connection(WAVE_ROLL.into()),
        &["ship.roll".to_string()],
        &opts,
    )
    .map_err(|e| e.to_string())
}

/// φ/w_φ of the control model with the rudder still, ω_n²/(s² + 2 z_n ω_n s + ω_n²) [Klugt1987,
/// eq. (3.29), Table 2.4], behind the zero-order hold of the step h, as the sequence published at
/// the communication points answers the held injection: C (zI − Φ)⁻¹ Γ, z = e^{jωh}.
fn roll_zoh(omega: f64, h: f64) -> C64 {
    let (w, z) = (OMEGA_N, Z_N0 + Z_N1 * SPEED);
    let a = Matrix2::new(0.0, 1.0, -w * w, -2.0 * z * w);
    let b = Vector2::new(0.0, w * w);
    let phi = (a * h).exp();
    let gamma = a.try_inverse().expect("invertible") * (phi - Matrix2::identity()) * b;
    let zz = C64::from_polar(1.0, omega * h);
    let det = (zz - phi[(0, 0)]) * (zz - phi[(1, 1)]) - phi[(0, 1)] * phi[(1, 0)];
    ((zz - phi[(1, 1)]) * gamma[0] + phi[(0, 1)] * gamma[1]) / det
}

fn ratio(p: &ResponsePoint) -> C64 {
    p.outputs[0].ratio
}

fn db(x: C64) -> f64 {
    20.0 * x.norm().log10()
}

/// Where 20 log10 |r| changes sign between neighbours, by linear interpolation in log ω.
fn zero_crossings(w: &[f64], v: &[f64]) -> Vec<f64> {
    (1..w.len())
        .filter(|&k| v[k - 1].signum() != v[k].signum())
        .map(|k| {
            let s = v[k - 1] / (v[k - 1] - v[k]);
            (w[k - 1].ln() + s * (w[k].ln() - w[k - 1].ln())).exp()
        })
        .collect()
}

/// The measured natural frequency and damping of the RRS-off roll response: where its phase,
/// less the half-step lag of the hold, crosses −90°, and 1/(2|φ/w_φ|) there.
fn natural_frequency(points: &[ResponsePoint], h: f64) -> Result<(f64, f64), String> {
    let phase = |p: &ResponsePoint| ratio(p).arg().to_degrees() + (p.omega * h / 2.0).to_degrees();
    points
        .windows(2)
        .find(|w| (phase(&w[0]) + 90.0).signum() != (phase(&w[1]) + 90.0).signum())
        .map(|w| {
            let (pa, pb) = (phase(&w[0]), phase(&w[1]));
            let s = (-90.0 - pa) / (pb - pa);
            let omega = w[0].omega + s * (w[1].omega - w[0].omega);
            let gain = ratio(&w[0]).norm() + s * (ratio(&w[1]).norm() - ratio(&w[0]).norm());
            (omega, 1.0 / (2.0 * gain))
        })
        .ok_or_else(|| "the RRS-off roll phase does not cross -90° near ω_n".to_string())
}

/// The off, on and on/off responses as one table and Bode plot.
fn combined(off: &[ResponsePoint], on: &[ResponsePoint]) -> Vec<ResponsePoint> {
    let out =
        |name: &str, ratio: C64, distortion: f64, o: Option<&OutputResponse>| OutputResponse {
            name: name.into(),
            ratio,
            distortion,
            gain_change_db: o.and_then(|o| o.gain_change_db),
            phase_change_deg: o.and_then(|o| o.phase_change_deg),
        };
    off.iter()
        .zip(on)
        .map(|(a, b)| ResponsePoint {
            omega: a.omega,
            outputs: vec![
                out(
                    "roll/w_phi, RRS off",
                    ratio(a),
                    a.outputs[0].distortion,
                    Some(&a.outputs[0]),
                ),
                out(
                    "roll/w_phi, RRS on",
                    ratio(b),
                    b.outputs[0].distortion,
                    Some(&b.outputs[0]),
                ),
                out(
                    "on/off",
                    ratio(b) / ratio(a),
                    a.outputs[0].distortion.max(b.outputs[0].distortion),
                    None,
                ),
            ],
        })
        .collect()
}

/// The reduction band and its neighbours from the on/off ratio.
struct Band {
    omega: Vec<f64>,
    ratio: Vec<C64>,
    /// Every crossing of |on/off| = 1.
    edges: Vec<f64>,
    /// The band (lo, hi) around the deepest reduction.
    main: (f64, f64),
    deepest: usize,
}

fn band(off: &[ResponsePoint], on: &[ResponsePoint]) -> Result<Band, String> {
    let omega: Vec<f64> = off.iter().map(|p| p.omega).collect();
    let r: Vec<C64> = off
        .iter()
        .zip(on)
        .map(|(a, b)| ratio(b) / ratio(a))
        .collect();
    let v: Vec<f64> = r.iter().map(|x| db(*x)).collect();
    let edges = zero_crossings(&omega, &v);
    let deepest = (0..v.len())
        .min_by(|a, b| v[*a].total_cmp(&v[*b]))
        .ok_or("no RRS frequencies")?;
    let w = omega[deepest];
    let lo = edges
        .iter()
        .copied()
        .filter(|e| *e < w)
        .fold(f64::NAN, f64::max);
    let hi = edges
        .iter()
        .copied()
        .filter(|e| *e > w)
        .fold(f64::NAN, f64::min);
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(format!(
            "the roll reduction band around {w} rad/s is not closed in the measured range"
        ));
    }
    Ok(Band {
        omega,
        ratio: r,
        edges,
        main: (lo, hi),
        deepest,
    })
}

impl Band {
    /// Every interval where |on/off| < 1: (from, to, deepest |on/off| in it); None = beyond the
    /// measured range.
    fn bands(&self) -> Vec<(Option<f64>, Option<f64>, f64)> {
        let below: Vec<bool> = self.ratio.iter().map(|r| r.norm() < 1.0).collect();
        let mut out = Vec::new();
        let mut k = 0;
        while k < below.len() {
            if !below[k] {
                k += 1;
                continue;
            }
            let start = k;
            while k < below.len() && below[k] {
                k += 1;
            }
            let from = self.edges.iter().copied().rfind(|e| *e < self.omega[start]);
            let to = self.edges.iter().copied().find(|e| *e > self.omega[k - 1]);
            let deepest = self.ratio[start..k]
                .iter()
                .map(|r| r.norm())
                .fold(1.0, f64::min);
            out.push((
                from.filter(|_| start > 0),
                to.filter(|_| k < below.len()),
                deepest,
            ));
        }
        out
    }

    /// The largest |on/off| over grid points below (`below`) or above the main band, and where.
    fn amplification(&self, below: bool) -> (f64, f64) {
        self.omega
            .iter()
            .zip(&self.ratio)
            .filter(|(w, _)| match below {
                true => **w < self.main.0,
                false => **w > self.main.1,
            })
            .map(|(w, r)| (r.norm(), *w))
            .fold((0.0, f64::NAN), |a, b| if b.0 > a.0 { b } else { a })
    }
}

pub fn run(env: &Env) -> Result<Report, String> {
    let mut report = Report {
        id: "loop_analysis".into(),
        title: "Loop analysis: margins and responses measured through the FMUs".into(),
        source:
            "[Taylor2000, Figs. 5-5, 5-16]; [Klugt1987, Table 2.4, secs. 1.2, 6.3, 6.5.2, 7.4]; \
                 the independent sampled-loop calculation tests/python/loop_reference.py (issue 35)"
                .into(),
        systems: vec![HEADING_FILE.into(), TRACK_FILE.into(), RRS_FILE.into()],
        ..Default::default()
    };
    ddg_loop(env, &HEADING, &mut report)?;
    ddg_loop(env, &TRACK, &mut report)?;
    rrs(env, &mut report)?;
    Ok(report)
}

/// The RRS loop and the roll response, RRS off and on.
fn rrs(env: &Env, report: &mut Report) -> Result<(), String> {
    let (q_phi, e_w3) = adapted(env)?;
    let (off_sets, on_sets) = (rrs_sets(q_phi, e_w3, 0), rrs_sets(q_phi, e_w3, 1));
    let h = env.system(RRS_FILE)?.step_size;
    let loop_on = rrs_loop(env, &on_sets)?;
    let loop_off = rrs_loop(env, &off_sets)?;
    let resp_off = roll_response(env, &off_sets, rrs_frequencies())?;
    let resp_on = roll_response(env, &on_sets, rrs_frequencies())?;
    let near: Vec<f64> = (0..7).map(|i| 0.60 + 0.01 * f64::from(i)).collect();
    let fine_off = roll_response(env, &off_sets, near.clone())?;
    let fine_on = roll_response(env, &on_sets, near)?;
    // |on/off| measured at ω_n itself (0.63 rad/s, snapped to its window)
    let at_n = fine_off
        .iter()
        .zip(&fine_on)
        .min_by(|a, b| {
            (a.0.omega - OMEGA_N)
                .abs()
                .total_cmp(&(b.0.omega - OMEGA_N).abs())
        })
        .map(|(a, b)| (a.omega, (ratio(b) / ratio(a)).norm()))
        .ok_or("no frequencies near ω_n")?;
    let b = band(&resp_off, &resp_on)?;

    // Figures and tables.
    let dir = env.out_dir.join("rrs_loop");
    let w = analysis::write_margins(&dir, &loop_on.points, &loop_on.margins, "RRS on, 11 m/s")
        .map_err(|e| e.to_string())?;
    let loop_bode = figure(env, plot(&w, "bode")?, "rrs_loop_bode.png")?;
    let loop_nyquist = figure(env, plot(&w, "nyquist")?, "rrs_loop_nyquist.png")?;
    analysis::write_margins(
        &env.out_dir.join("rrs_loop_off"),
        &loop_off.points,
        &loop_off.margins,
        "RRS off, 11 m/s",
    )
    .map_err(|e| e.to_string())?;
    let w = analysis::write_response(
        &env.out_dir.join("rrs_roll_response"),
        &combined(&resp_off, &resp_on),
        "roll response to the wave roll moment w_phi, 11 m/s",
    )
    .map_err(|e| e.to_string())?;
    let resp_bode = figure(env, plot(&w, "bode")?, "rrs_roll_response_bode.png")?;

    rrs_model_checks(report, &resp_off, &fine_off, h)?;
    rrs_consistency_checks(report, &loop_on, &loop_off, &resp_off, &resp_on, &b)?;
    rrs_thesis_checks(report, &loop_on, &resp_off, &b, at_n)?;
    report.notes.push(rrs_settings_note(q_phi, e_w3));
    report.notes.push(rrs_loop_table(&loop_on, &loop_off));
    report
        .notes
        .push(rrs_band_note(&b, &resp_off, &resp_on, at_n));
    report.figures.push((
        format!("RRS loop L(jω) at {RRS_BREAK}, RRS on, 11 m/s (the tool's margins in the title: see the crossing table)"),
        loop_bode,
    ));
    report.figures.push((
        "RRS loop, RRS on: Nyquist plot near −1 (the roll resonance's loop around the origin stays right of −1)".into(),
        loop_nyquist,
    ));
    report.figures.push((
        "Roll response to the wave roll moment w_φ, RRS off and on, and their ratio: the reduction band".into(),
        resp_bode,
    ));
    Ok(())
}

/// RRS off: the response is the control model's roll with the rudder still (roll does not reach
/// yaw in it); ω_n and z_n of Table 2.4 measured back.
fn rrs_model_checks(
    report: &mut Report,
    off: &[ResponsePoint],
    fine: &[ResponsePoint],
    h: f64,
) -> Result<(), String> {
    let err = off
        .iter()
        .chain(fine)
        .map(|p| (ratio(p) / roll_zoh(p.omega, h) - 1.0).norm())
        .fold(0.0, f64::max);
    let n = off.len() + fine.len();
    report.checks.push(Check {
        tolerance: "< 1e-6".into(),
        pass: err < 1e-6,
        ..Check::holds(
            &format!("RRS off: roll/w_φ at {n} frequencies = ω_n²/(s² + 2z_nω_n s + ω_n²) behind the step's hold, largest relative error"),
            "[DERIVED] Table 2.4 at 11 m/s, exact ZOH discretisation",
            format!("{err:.1e}"),
            true,
        )
    });
    let (w_n, zeta) = natural_frequency(fine, h)?;
    report.checks.push(Check::abs(
        "roll natural frequency ω_n: RRS-off phase (less the hold's ωh/2) at −90°",
        OMEGA_N,
        w_n,
        0.005,
        "rad/s",
    ));
    let z = Z_N0 + Z_N1 * SPEED;
    report.checks.push(Check {
        published: format!("{} (0.064 + 0.0038 U, Table 2.4)", fmt_num(z)),
        ..Check::rel(
            "roll damping z_n at 11 m/s: 1/(2 \\|φ/w_φ\\|) at ω_n",
            z,
            zeta,
            0.01,
            "",
        )
    });
    Ok(())
}

/// The loop at the break and the responses are one linear system: roll_on/roll_off =
/// (1 + L_off)/(1 + L_on), L_off the course loop alone (roll does not reach yaw in the control
/// model, and with RRS off nothing returns from roll to the rudder).
fn rrs_consistency_checks(
    report: &mut Report,
    on: &RrsLoop,
    off: &RrsLoop,
    resp_off: &[ResponsePoint],
    resp_on: &[ResponsePoint],
    b: &Band,
) -> Result<(), String> {
    let (mut ddb, mut ddeg) = (0.0f64, 0.0f64);
    for (k, w) in b.omega.iter().enumerate() {
        let (lon, loff) = (on.at(*w), off.at(*w));
        let (Some(lon), Some(loff)) = (lon, loff) else {
            return Err(format!("{w} rad/s is not a point of both loops"));
        };
        let q = b.ratio[k] / ((1.0 + loff) / (1.0 + lon));
        ddb = ddb.max(db(q).abs());
        ddeg = ddeg.max(q.arg().to_degrees().abs());
    }
    report.checks.push(Check {
        tolerance: "0.01 dB, 0.05°".into(),
        pass: ddb <= 0.01 && ddeg <= 0.05,
        ..Check::holds(
            &format!("roll on/off = (1 + L_off)/(1 + L_on) at the {} frequencies (responses against loops), largest difference", b.omega.len()),
            "[DERIVED] one linear loop, two measurements",
            format!("{ddb:.1e} dB, {ddeg:.1e}°"),
            true,
        )
    });
    let changes = [
        on.linearity(),
        off.linearity(),
        largest_change(
            resp_off
                .iter()
                .chain(resp_on)
                .map(|p| (p.outputs[0].gain_change_db, p.outputs[0].phase_change_deg)),
        ),
    ];
    let (g, p) = changes
        .iter()
        .fold((0.0f64, 0.0f64), |(g, p), c| (g.max(c.0), p.max(c.1)));
    report.checks.push(Check {
        tolerance: "< 1e-6 dB, 1e-6°".into(),
        pass: g < 1e-6 && p < 1e-6,
        ..Check::holds(
            "RRS: linear at 0.01 rad (AGC at A = 1, no rate or angle limit): change at twice the amplitude",
            "small-signal loop (docs/loop-analysis.md)",
            format!("{g:.1e} dB, {p:.1e}°"),
            true,
        )
    });
    Ok(())
}

/// The thesis's account of where RRS reduces roll, against the measured band.
fn rrs_thesis_checks(
    report: &mut Report,
    on: &RrsLoop,
    off: &[ResponsePoint],
    b: &Band,
    (w_n, r_n): (f64, f64),
) -> Result<(), String> {
    let c = &mut report.checks;
    let peak = off
        .iter()
        .max_by(|x, y| ratio(x).norm().total_cmp(&ratio(y).norm()))
        .ok_or("no RRS-off points")?;
    let step = (b.omega[1] / b.omega[0]).ln();
    c.push(Check::holds(
        "RRS off: the largest roll at the roll natural frequency",
        "\"the largest roll motions will occur around the natural frequency\" [Klugt1987, sec. 6.5.2, before eq. (6.32)]",
        format!("peak {:.2} dB at {:.3} rad/s (grid)", db(ratio(peak)), peak.omega),
        (peak.omega / OMEGA_N).ln().abs() <= step,
    ));
    let (lo, hi) = b.main;
    c.push(Check::holds(
        "RRS on: roll reduced (\\|on/off\\| < 1) in a band around ω_n",
        "roll reduction \"if the peak of the wave spectrum approaches the natural roll frequency\" [Klugt1987, sec. 7.4, Fig. 7.22]",
        format!("{lo:.3} ... {hi:.3} rad/s"),
        lo < OMEGA_N && OMEGA_N < hi,
    ));
    c.push(Check::range(
        &format!(
            "variance reduction 100(1 − \\|on/off\\|²) of a wave moment at ω_n ({w_n:.4} rad/s)"
        ),
        "> 60 % near the natural roll frequency [Klugt1987, sec. 7.4]",
        100.0 * (1.0 - r_n * r_n),
        60.0,
        100.0,
        "%",
    ));
    let (amp_hi, w_hi) = b.amplification(false);
    // |on/off| never falls from the deepest point to the largest amplification above the band
    let top = b.omega.iter().position(|w| *w == w_hi).unwrap_or(b.deepest);
    let rising = (b.deepest + 1..=top).all(|k| b.ratio[k].norm() >= b.ratio[k - 1].norm());
    c.push(Check::holds(
        "above the deepest reduction \\|on/off\\| rises through 1: less reduction, then amplification",
        "\"If the disturbances are of a higher frequency, the potential roll reduction is reduced\" [Klugt1987, sec. 7.4]",
        format!(
            "min {:.2} at {:.3} rad/s, 1 at {hi:.3} rad/s, max {amp_hi:.2} at {w_hi:.3} rad/s",
            b.ratio[b.deepest].norm(),
            b.omega[b.deepest]
        ),
        rising && amp_hi > 1.0,
    ));
    let (amp_lo, w_lo) = b.amplification(true);
    let first = b.ratio[0].norm();
    let none_below = b
        .omega
        .iter()
        .zip(&b.ratio)
        .filter(|(w, _)| **w < lo)
        .all(|(_, r)| r.norm() >= 1.0);
    c.push(Check::holds(
        "below the band no reduction: \\|on/off\\| ≥ 1, → 1 at low frequency",
        "\"not capable of reducing low-frequency roll motions\" [Klugt1987, sec. 1.2]; \"It is not possible to reduce low-frequency roll motions\" [sec. 6.3]",
        format!(
            "≥ 1 below {lo:.3} rad/s (max {amp_lo:.3} at {w_lo:.3}), {first:.4} at {:.2} rad/s",
            b.omega[0]
        ),
        none_below && (first - 1.0).abs() < 0.01,
    ));
    let gm = on.gain_margin();
    let pm = on.phase_margin();
    let dm = on.delay_margin();
    let (Some((_, gm)), Some(pm), Some(dm)) = (gm, pm, dm) else {
        return Err("the RRS loop has no gain or phase crossing in the measured range".into());
    };
    let rule = 0.2 / OMEGA_N;
    c.push(Check::holds(
        "RRS on: margins at the rudder command, every crossing (table below)",
        &format!(
            "[Klugt1987] gives none; the gear rule τ_δ ≤ 0.2/ω_n = {rule:.3} s [eq. (6.37), sec. 6.5.2] must lie inside the delay margin"
        ),
        format!(
            "GM {gm:.2} dB, PM {:.1}° at {:.3} rad/s, DM {:.2} s at {:.3} rad/s",
            pm.margin_deg(),
            pm.omega,
            dm.delay_s(),
            dm.omega
        ),
        gm > 0.0 && pm.margin_deg() > 0.0 && dm.delay_s() > rule,
    ));
    // The tool's margins are the limiting crossings of this table (its nearest-to-−1 rule).
    let m = &on.margins;
    let same = |x: Option<f64>, y: f64, tol: f64| x.is_some_and(|x| (x - y).abs() <= tol);
    c.push(Check::holds(
        "RRS on: shipsim::analysis's margins are the limiting crossings",
        "the crossing nearest −1 for GM and PM, the least lag-to-−1 over the crossovers for DM",
        {
            let f = |x: Option<f64>, d: usize| x.map_or("none".into(), |v| format!("{v:.d$}"));
            format!(
                "tool: GM {} dB, PM {}°, DM {} s",
                f(m.gain_margin_db, 2),
                f(m.phase_margin_deg, 1),
                f(m.delay_margin_s, 2)
            )
        },
        same(m.gain_margin_db, gm, 0.01)
            && same(m.phase_margin_deg, pm.margin_deg(), 0.05)
            && same(m.delay_margin_s, dm.delay_s(), 0.01),
    ));
    Ok(())
}

fn rrs_settings_note(q_phi: f64, e_w3: f64) -> String {
    format!(
        "RRS operating point: `systems/rrs.toml` (11 m/s, the 15 deg/s gear of τ = {RRS_GEAR_TAU} s, \
         Jacobi, h = 0.05 s, sensors, filter and autopilot every 0.1 s) with `--set {}`; the \
         adaptations frozen at their means in the file's own sea after {RRS_ADAPTED_FROM} s (one \
         run of the file as it is, to four digits): q_φ = {q_phi}, E*[w3²] = {e_w3}; the state at {RRS_AT} s \
         (the innovation process converged, the loop at rest) is the operating point. Wave height, \
         wind moments and sensor noise are zero: the sea's random moment would add noise to the \
         correlation, and the injected sinusoid on `{WAVE_ROLL}` is the deterministic wave moment \
         at ω (w_φ, the rudder-equivalent roll disturbance, in rad). {} frequencies 0.05 ... 5 \
         rad/s (and 0.60 ... 0.66 for ω_n), amplitude {AMPLITUDE} rad, 4 periods, settle {SETTLE} s.",
        rrs_sets(q_phi, e_w3, 1)
            .iter()
            .filter(|s| !s.starts_with("autopilot.roll_mode"))
            .cloned()
            .collect::<Vec<_>>()
            .join(" --set "),
        rrs_frequencies().len()
    )
}

fn rrs_loop_table(on: &RrsLoop, off: &RrsLoop) -> String {
    let mut s = format!(
        "RRS loop at `{RRS_BREAK}`, every crossing of the measured points (linear in log ω \
         between the closest points, the tool's refinements included): the phase lag to −1 is \
         (∠L + 180°) mod 360°, the phase margin the angle to −1 either way, the delay margin the \
         lag over ω.\n\n\
         | RRS | crossing | ω [rad/s] | ∠L [°] | \\|L\\| [dB] | phase margin [°] | lag to −1 [°] | delay [s] | gain margin [dB] |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    for (name, l) in [("on", on), ("off", off)] {
        let mut rows: Vec<(f64, String)> = l
            .gains
            .iter()
            .map(|g| {
                (
                    g.omega,
                    format!(
                        "| {name} | gain | {:.4} | {:.1} | 0 | {:.1} | {:.1} | {:.2} | |",
                        g.omega,
                        g.phase_deg,
                        g.margin_deg(),
                        g.lag_deg(),
                        g.delay_s()
                    ),
                )
            })
            .collect();
        rows.extend(l.phases.iter().map(|(w, gm)| {
            (
                *w,
                format!(
                    "| {name} | phase | {w:.4} | 180 | {:.2} | | | | {gm:.2} |",
                    -gm
                ),
            )
        }));
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, r) in rows {
            s += &format!("\n{r}");
        }
    }
    let summary = |name: &str, l: &RrsLoop| {
        let m = &l.margins;
        let o = |x: Option<f64>, d: usize| x.map_or("none".into(), |v| format!("{v:.d$}"));
        format!(
            "RRS {name}: smallest phase margin {}, delay margin {}, gain margin {}; \
             shipsim::analysis reports GM {} dB at {} rad/s, PM {}° at {} rad/s, DM {} s, \
             Ms {:.3} at {:.3} rad/s.",
            l.phase_margin().map_or("none".into(), |g| format!(
                "{:.1}° at {:.4} rad/s",
                g.margin_deg(),
                g.omega
            )),
            l.delay_margin().map_or("none".into(), |g| format!(
                "{:.2} s at {:.4} rad/s",
                g.delay_s(),
                g.omega
            )),
            l.gain_margin()
                .map_or("none".into(), |(w, g)| format!("{g:.2} dB at {w:.4} rad/s")),
            o(m.gain_margin_db, 2),
            o(m.gain_margin_rad_s, 4),
            o(m.phase_margin_deg, 2),
            o(m.crossover_rad_s, 4),
            o(m.delay_margin_s, 2),
            m.sensitivity_peak,
            m.sensitivity_peak_rad_s
        )
    };
    s += &format!(
        "\n\n{} {} With RRS on the loop crosses |L| = 1 three times: the course loop's crossover, \
         then the roll resonance lifts |L| above 1 with L in the upper half plane, far from −1, \
         and the roll loop's own crossover. The tool lists every crossing and reports the one \
         nearest −1 (the middle one, with L on the far side of −1, is 149° away), and the least \
         delay that reaches −1 over all three; the loop is stable (the forks settle, and the \
         Nyquist curve's crossings of the negative real axis lie right of −1).\n",
        summary("on", on),
        summary("off", off)
    );
    s
}

fn rrs_band_note(
    b: &Band,
    off: &[ResponsePoint],
    on: &[ResponsePoint],
    (w_n, r_n): (f64, f64),
) -> String {
    let edges: Vec<String> = b.edges.iter().map(|e| format!("{e:.3}")).collect();
    let peak = |v: &[ResponsePoint]| {
        v.iter()
            .map(|p| (db(ratio(p)), p.omega))
            .fold((f64::MIN, 0.0), |a, x| if x.0 > a.0 { x } else { a })
    };
    let (poff, woff) = peak(off);
    let (pon, won) = peak(on);
    let (amp_lo, w_lo) = b.amplification(true);
    let (amp_hi, w_hi) = b.amplification(false);
    let edge = |e: Option<f64>, open: &str| e.map_or(open.to_string(), |v| format!("{v:.3}"));
    let bands: Vec<String> = b
        .bands()
        .iter()
        .map(|(from, to, deepest)| {
            format!(
                "{} ... {} rad/s (deepest {:.3} = {:.2} dB)",
                edge(*from, "below 0.05"),
                edge(*to, "beyond 5"),
                deepest,
                20.0 * deepest.log10()
            )
        })
        .collect();
    let mut s = format!(
        "Roll response to the wave roll moment (w_φ → φ): |on/off| = 1 at {} rad/s. Roll is \
         reduced in {}. The main band: {:.3} ... {:.3} rad/s, deepest {:.3} ({:.1} dB) at {:.3} \
         rad/s, {:.3} at ω_n (measured at {w_n:.4} rad/s: a variance reduction of {:.0} % for a narrow sea \
         at ω_n). Roll is amplified below it (up to {amp_lo:.3} = {:+.2} dB at {w_lo:.3} rad/s) \
         and above it (up to {amp_hi:.2} = {:+.2} dB at {w_hi:.3} rad/s). The RRS-off roll peaks \
         at {poff:.1} dB ({woff:.3} rad/s on the grid), the RRS-on roll at {pon:.1} dB ({won:.3} \
         rad/s): the roll controller adds damping and moves the resonance up. The thesis states \
         where RRS works (near ω_n), that low-frequency roll cannot be reduced (the roll filter \
         removes it from the roll signal) and that higher-frequency disturbances give less \
         reduction; it prints no band edges and no frequency response of the stabilized roll, \
         and its remark that RRS can make roll worse [sec. 5.2.2] concerns the rudder-rate \
         limit, not the linear loop. The amplification on both sides of the band is the \
         waterbed effect of feedback, which the measurement shows and the thesis does not \
         quantify.\n\n\
         | ω [rad/s] | RRS off [dB] | RRS on [dB] | on/off [dB] | on/off phase [°] |\n\
         |---|---|---|---|---|",
        edges.join(", "),
        bands.join("; "),
        b.main.0,
        b.main.1,
        b.ratio[b.deepest].norm(),
        db(b.ratio[b.deepest]),
        b.omega[b.deepest],
        r_n,
        100.0 * (1.0 - r_n * r_n),
        20.0 * amp_lo.log10(),
        20.0 * amp_hi.log10(),
    );
    for (k, (a, o)) in off.iter().zip(on).enumerate().step_by(2) {
        s += &format!(
            "\n| {:.4} | {:.2} | {:.2} | {:+.2} | {:+.1} |",
            a.omega,
            db(ratio(a)),
            db(ratio(o)),
            db(b.ratio[k]),
            b.ratio[k].arg().to_degrees()
        );
    }
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zoh_second_order_is_the_continuous_one_at_low_frequency() {
        // at ω → 0 the gain is 1; at ω_n the continuous |G| = 1/(2 z_n), the ZOH's within 1e-3
        assert!((roll_zoh(1e-7, 0.05) - 1.0).norm() < 1e-6);
        let z = Z_N0 + Z_N1 * SPEED;
        assert!((roll_zoh(OMEGA_N, 0.05).norm() * 2.0 * z - 1.0).abs() < 1e-3);
    }

    #[test]
    fn crossing_phases_wrap_into_the_half_open_interval() {
        let p = |w: f64, l: C64| LoopPoint {
            omega: w,
            l,
            distortion: 0.0,
            gain_change_db: None,
            phase_change_deg: None,
        };
        // |L| from 2 to 0.5 at +31°: lag to −1 is 211°, margin 149°
        let l = C64::from_polar(1.0, 31f64.to_radians());
        let (g, ph) = crossings(&[p(0.5, l * 2.0), p(0.6, l * 0.5)]);
        assert_eq!(ph.len(), 0);
        assert!((g[0].phase_deg - 31.0).abs() < 1e-9);
        assert!((g[0].lag_deg() - 211.0).abs() < 1e-9);
        assert!((g[0].margin_deg() - 149.0).abs() < 1e-9);
        // crossing the negative real axis between two points of |L| = 0.2693: GM 11.40 dB (the
        // gain in dB interpolated in log ω); none on the positive real axis
        let (_, ph) = crossings(&[p(1.0, C64::new(-0.25, 0.1)), p(1.1, C64::new(-0.25, -0.1))]);
        assert!((ph[0].1 + 20.0 * C64::new(-0.25, 0.1).norm().log10()).abs() < 1e-12);
        let (_, ph) = crossings(&[p(1.0, C64::new(0.25, 0.1)), p(1.1, C64::new(0.25, -0.1))]);
        assert!(ph.is_empty());
    }
}
