//! Adaptive path control of the *Tokyo Maru* in restricted water [Parsons1980, sec. 3], scenarios
//! S1-S7: TokyoMaru + SteeringGear + Current + Sensors + PathKalmanFilter + PathController through
//! the master.
//!
//! * Noise-free runs against [DERIVED] trajectories, within 2 %: the report's figures are lost,
//!   so its loop was re-simulated from its equations (plant and filter by forward Euler at Δt′,
//!   u_k = C x̂_k; the report text calls this the Appendix-A loop).
//! * Runs with the report's measurement noise [Parsons1980, Table 3] over 20 seeds against the
//!   numbers the report reads off its (noisy) figures: the printed value must lie within the
//!   spread of the seeds (min..max, widened by half a unit of the printed last digit).
//! * The co-simulation against that monolithic loop with the exchange delays of a Jacobi master,
//!   which explains the one quantity outside 2 % (the S1 rudder peak).
//!
//! S5 (ABC harbour, [Parsons1980, Fig. 5] lost) and S8 ([Parsons1980, Table 7], a covariance
//! analysis, not a simulation) are not run; the estimator scenarios (WLS S9-S13, MVE S14) are the
//! `path_estimation` study.

use super::path_common::{run_until, DT};
use crate::study::{col, half_digit, last, max_abs, overrides_text, Check, Env, Report, Spread};
use models::controllers::path::{path_gains, PathDesignModel};
use models::disturbances::current::{design_current_profile, passing_ship};
use models::hull::tokyo_maru::{TokyoMaruCoefficients, L, T_R, U};
use models::hull::DEG;
use shipsim::plot::{Panel, Series};
use shipsim::results::ResultsTable;

/// Half beam B/2 [m]: the initial offset of S1/S3.
const HALF_BEAM: f64 = 23.75;
const SEEDS: u64 = 20;
const CURRENT: &str = "path_control_current.toml";
const PASSING: &str = "path_control_passing_ship.toml";

/// Shaping-filter design [Parsons1980, Table 4] in controller and filter.
const SHAPING: &[&str] = &[
    "ctl.disturbance_model=1",
    "ctl.q_n=1.548e-8",
    "ctl.q_y=8.970e-8",
    "kf.disturbance_model=1",
];
const DEEP: &[&str] = &["ship.deep_water=true"];
const DEEP_OPTIMAL: &[&str] = &[
    "ship.deep_water=true",
    "ctl.design_depth_ratio=1e300",
    "kf.design_depth_ratio=1e300",
];
const DEEP_PARTIAL: &[&str] = &[
    "ship.deep_water=true",
    "kf.adapted_depth_ratio=1e300",
    "ctl.adaptation=2",
    "ctl.dither_enabled=true",
];

/// One scenario: id, caption, system file, overrides.
struct Scenario {
    id: &'static str,
    what: &'static str,
    file: &'static str,
    sets: &'static [&'static str],
}

const S1: Scenario = Scenario {
    id: "S1",
    what: "B/2 offset + 4x passing ship, shaping-filter design (Table 4)",
    file: PASSING,
    sets: SHAPING,
};
const S3: Scenario = Scenario {
    id: "S3",
    what: "B/2 offset + 4x passing ship, random-walk design (Table 5)",
    file: PASSING,
    sets: &[],
};
const S2: Scenario = Scenario {
    id: "S2",
    what: "design current, shaping-filter design (Table 4)",
    file: CURRENT,
    sets: SHAPING,
};
const S4: Scenario = Scenario {
    id: "S4",
    what: "design current, random-walk design (Table 5)",
    file: CURRENT,
    sets: &[],
};
const S6: Scenario = Scenario {
    id: "S6",
    what: "design current in deep water, Table 5 design (non-adapted)",
    file: CURRENT,
    sets: DEEP,
};
const S6O: Scenario = Scenario {
    id: "S6 optimal",
    what: "design current in deep water, Table 6 design (optimal at H/T = inf)",
    file: CURRENT,
    sets: DEEP_OPTIMAL,
};
const S7: Scenario = Scenario {
    id: "S7",
    what: "design current in deep water, Table 8 design (f23, f25 adapted)",
    file: CURRENT,
    sets: DEEP_PARTIAL,
};

/// The recorded signals of one run, on the t′ grid.
struct Run {
    tp: Vec<f64>,
    /// Lateral offset from the track [m].
    eta: Vec<f64>,
    heading_deg: Vec<f64>,
    rudder_deg: Vec<f64>,
    command_deg: Vec<f64>,
    n_hat: Vec<f64>,
    y_hat: Vec<f64>,
    table: ResultsTable,
}

impl Run {
    fn new(table: ResultsTable, eta_offset: f64) -> Result<Run, String> {
        let scale = |name: &str, s: f64, o: f64| -> Result<Vec<f64>, String> {
            Ok(col(&table, name)?.iter().map(|v| v * s + o).collect())
        };
        Ok(Run {
            tp: col(&table, "ship.time_prime")?.to_vec(),
            eta: scale("ship.cross_track", 1.0, eta_offset)?,
            heading_deg: scale("ship.heading", 1.0 / DEG, 0.0)?,
            rudder_deg: scale("gear.rudder_angle", 1.0 / DEG, 0.0)?,
            command_deg: scale("ctl.rudder_command", 1.0 / DEG, 0.0)?,
            n_hat: col(&table, "kf.yaw_moment_prime_estimate")?.to_vec(),
            y_hat: col(&table, "kf.sway_force_prime_estimate")?.to_vec(),
            table,
        })
    }

    /// Index of the sample nearest to t′.
    fn at(&self, tp: f64) -> usize {
        ((tp / DT).round() as usize).min(self.tp.len() - 1)
    }

    fn window(&self, a: f64, b: f64) -> std::ops::Range<usize> {
        self.at(a)..self.at(b) + 1
    }

    /// (t′, value) of the extreme of `sign`·v over a ≤ t′ ≤ b.
    fn extreme(&self, v: &[f64], a: f64, b: f64, sign: f64) -> (f64, f64) {
        let mut best = (f64::NAN, f64::NEG_INFINITY);
        for i in self.window(a, b) {
            if sign * v[i] > best.1 {
                best = (self.tp[i], sign * v[i]);
            }
        }
        (best.0, sign * best.1)
    }

    fn mean(&self, v: &[f64], a: f64, b: f64) -> f64 {
        let w = self.window(a, b);
        let n = w.len() as f64;
        v[w].iter().sum::<f64>() / n
    }

    /// First t′ ≥ a where v changes sign (linear interpolation).
    fn zero_crossing(&self, v: &[f64], a: f64) -> f64 {
        for i in self.at(a)..v.len() - 1 {
            if v[i] * v[i + 1] <= 0.0 && v[i] != v[i + 1] {
                return self.tp[i] + DT * v[i] / (v[i] - v[i + 1]);
            }
        }
        f64::NAN
    }

    fn series(&self, v: &[f64], label: &str) -> Series {
        Series {
            label: label.to_string(),
            t: col(&self.table, "time")
                .map(|t| t.to_vec())
                .unwrap_or_else(|_| self.tp.iter().map(|tp| tp * L / U).collect()),
            y: v.to_vec(),
        }
    }
}

fn run_scenario(env: &Env, s: &Scenario, extra: &[String], csv: &str) -> Result<Run, String> {
    let mut sets: Vec<String> = s.sets.iter().map(|x| x.to_string()).collect();
    sets.extend_from_slice(extra);
    let table = env.run(s.file, &sets, csv)?;
    Run::new(table, if s.file == PASSING { HALF_BEAM } else { 0.0 })
}

fn noise_free(env: &Env, s: &Scenario, csv: &str) -> Result<Run, String> {
    run_scenario(env, s, &["sensors.noise_scale=0".to_string()], csv)
}

/// ±2 % of the value or ±1 % of the scenario's peak `scale`, whichever is larger (trajectory
/// points near a zero crossing, where a relative tolerance means nothing).
fn rel2(quantity: &str, published: f64, ours: f64, scale: f64, unit: &str) -> Check {
    let tol = (0.02 * published.abs()).max(0.01 * scale.abs());
    let mut c = Check::abs(quantity, published, ours, tol, unit);
    c.tolerance = format!("{} (max of 2%, 1% of the peak)", c.tolerance);
    c
}

/// The printed value lies within the seeds' min..max, widened by half a unit of its last digit.
fn within_seeds(quantity: &str, printed: &str, s: &Spread, unit: &str) -> Check {
    Check {
        quantity: quantity.to_string(),
        published: format!("{printed} {unit}").trim().to_string(),
        ours: format!("{s} {unit}").trim().to_string(),
        tolerance: format!(
            "printed value within the {SEEDS} seeds' range ±{}",
            half_digit(printed)
        ),
        pass: s.covers(printed),
    }
}

/// The report's loop as re-simulated for the [DERIVED] values ("Appendix-A loop": plant and filter
/// forward Euler at Δt′, u_k = C x̂_k [Parsons1980, sec. 3.1]), optionally with the exchange of the
/// co-simulation: the Jacobi master hands the filter the measurement of the previous step (the
/// Sensors output is a direct feedthrough of the hull's output, one exchange old) and the gear the
/// command of the previous step (the controller output is a direct feedthrough of the filter's
/// output), the first command is C x̂_0 (the filter's outputs in initialization mode follow its
/// initial_* parameters), the controller reads the gear's actual rudder and the gear is integrated
/// exactly (SteeringGear). Returns (t′, η m, δ deg).
fn appendix_a(
    truth: TokyoMaruCoefficients,
    design: PathDesignModel,
    eta0: f64,
    w: &dyn Fn(f64) -> (f64, f64),
    steps: usize,
    cosim: bool,
) -> Result<Vec<[f64; 3]>, String> {
    let g = path_gains(&design).map_err(|e| e.to_string())?;
    let (fs, gs, gams) = truth.eq11(T_R);
    let fe = design.f(false);
    let ge = design.g();
    let h = |x: &[f64; 7]| [x[0], x[1], x[3]];
    let mut x = [0.0, 0.0, 0.0, eta0 / L, 0.0];
    let mut xh = [0.0, 0.0, 0.0, eta0 / L, 0.0, 0.0, 0.0];
    let mut z_prev = [x[0], x[1], x[3]];
    // The first command: the controller sees the filter's initial estimate during the master's
    // initial exchange (outputs in Initialization Mode follow the parameters), so u_0 = C x̂_0.
    let mut u_prev: f64 = {
        let mut xc0 = xh;
        xc0[4] = x[4];
        (0..7).map(|j| g.c[j] * xc0[j]).sum()
    };
    let decay = (-DT / T_R).exp();
    let mut out = Vec::with_capacity(steps + 1);
    for k in 0..=steps {
        out.push([k as f64 * DT, x[3] * L, x[4] / DEG]);
        if k == steps {
            break;
        }
        let mut xc = xh;
        if cosim {
            xc[4] = x[4];
        }
        let u_now: f64 = (0..7).map(|j| g.c[j] * xc[j]).sum();
        let (u, z) = if cosim {
            (u_prev, z_prev)
        } else {
            (u_now, [x[0], x[1], x[3]])
        };
        let (n, y) = w(k as f64 * DT);
        let mut dx = [0.0; 5];
        for i in 0..5 {
            dx[i] = (0..5).map(|j| fs[(i, j)] * x[j]).sum::<f64>()
                + gs[i] * u
                + gams[(i, 0)] * n
                + gams[(i, 1)] * y;
        }
        let zh = h(&xh);
        let mut dxh = [0.0; 7];
        for i in 0..7 {
            dxh[i] = (0..7).map(|j| fe[(i, j)] * xh[j]).sum::<f64>()
                + ge[i] * u
                + (0..3).map(|j| g.k[(i, j)] * (z[j] - zh[j])).sum::<f64>();
        }
        z_prev = [x[0], x[1], x[3]];
        u_prev = u_now;
        let delta = x[4];
        for i in 0..5 {
            x[i] += DT * dx[i];
        }
        if cosim {
            x[4] = u + (delta - u) * decay;
        }
        for i in 0..7 {
            xh[i] += DT * dxh[i];
        }
    }
    Ok(out)
}

/// Max |η_a − η_b| and max |δ_a − δ_b| between the loop and a run.
fn max_diff(loop_: &[[f64; 3]], r: &Run) -> (f64, f64) {
    let mut d = (0.0f64, 0.0f64);
    for (i, p) in loop_.iter().enumerate().take(r.eta.len()) {
        d.0 = d.0.max((p[1] - r.eta[i]).abs());
        d.1 = d.1.max((p[2] - r.rudder_deg[i]).abs());
    }
    d
}

pub fn run(env: &Env) -> Result<Report, String> {
    let mut report = Report {
        id: "path_control".into(),
        title: "Adaptive path control of the Tokyo Maru in restricted water (scenarios S1-S7)"
            .into(),
        source: "Parsons & Cuong (1980) §3, Figs. 6-23 (seed 004); spec adaptive_path_control.md \
                 §4.2 [DERIVED] trajectories"
            .into(),
        systems: vec![PASSING.into(), CURRENT.into()],
        ..Default::default()
    };
    let nf = NoiseFree::run(env)?;
    let c = &mut report.checks;
    let s1_rudder_peak = s1_checks(&nf.s1, c);
    s2_checks(&nf.s2, c);
    s4_checks(&nf.s4, c);
    deep_water_checks(&nf, c);
    s7_design_checks(&nf.s7, c)?;
    held_current_checks(env, c)?;
    let loops = appendix_a_checks(&nf, s1_rudder_peak, c)?;
    let passing = passing_ship_seeds(env, c)?;
    let s4_seed1 = design_current_seeds(env, c)?;
    figures(env, &nf, &passing.seed1, &s4_seed1, &mut report)?;
    notes(&loops, &passing, &mut report.notes);
    Ok(report)
}

/// The noise-free runs of every scenario, compared with the [DERIVED] trajectories.
struct NoiseFree {
    s1: Run,
    s3: Run,
    s2: Run,
    s4: Run,
    s6: Run,
    s6o: Run,
    s7: Run,
}

impl NoiseFree {
    fn run(env: &Env) -> Result<NoiseFree, String> {
        Ok(NoiseFree {
            s1: noise_free(env, &S1, "s1_noise_free.csv")?,
            s3: noise_free(env, &S3, "s3_noise_free.csv")?,
            s2: noise_free(env, &S2, "s2_noise_free.csv")?,
            s4: noise_free(env, &S4, "s4_noise_free.csv")?,
            s6: noise_free(env, &S6, "s6_noise_free.csv")?,
            s6o: noise_free(env, &S6O, "s6_optimal_noise_free.csv")?,
            s7: noise_free(env, &S7, "s7_noise_free.csv")?,
        })
    }
}

/// S1: return from B/2 (the passing ship at t′ = 20 acts only for t′ > 18). Returns max |δ| [deg].
fn s1_checks(s1: &Run, c: &mut Vec<Check>) -> f64 {
    let (t_os, os) = s1.extreme(&s1.eta, 3.0, 15.0, -1.0);
    c.push(Check::rel(
        "S1 overshoot (noise-free) [DERIVED]",
        1.86,
        -os,
        0.02,
        "m",
    ));
    c.push(Check::rel(
        "S1 t′ of the overshoot [DERIVED]",
        5.14,
        t_os,
        0.02,
        "",
    ));
    c.push(Check::rel(
        "S1 t′ where η crosses zero [DERIVED]",
        4.03,
        s1.zero_crossing(&s1.eta, 1.0),
        0.02,
        "",
    ));
    for (tp, v) in [
        (1.0, 22.98),
        (2.0, 15.82),
        (3.0, 6.30),
        (4.0, 0.08),
        (6.0, -1.32),
        (8.0, 0.24),
    ] {
        c.push(rel2(
            &format!("S1 η(t′ = {tp}) [DERIVED]"),
            v,
            s1.eta[s1.at(tp)],
            HALF_BEAM,
            "m",
        ));
    }
    let first_cmd = s1.command_deg.iter().find(|v| v.abs() > 0.0).copied();
    c.push(Check::rel(
        "S1 first rudder command C14·η′(0) [DERIVED]",
        11.38,
        first_cmd.unwrap_or(0.0),
        0.02,
        "deg",
    ));
    let (t_dm, dm) = {
        let hi = s1.extreme(&s1.rudder_deg, 0.0, 15.0, 1.0);
        let lo = s1.extreme(&s1.rudder_deg, 0.0, 15.0, -1.0);
        if hi.1 >= -lo.1 {
            hi
        } else {
            (lo.0, -lo.1)
        }
    };
    // The peak rudder lies 2.4 % above the report loop's: the Jacobi exchange (checked below).
    c.push(Check::rel(
        "S1 max |δ| [DERIVED 4.66 for the report's loop; 4.77 with the Jacobi exchange, see note]",
        4.66,
        dm,
        0.03,
        "deg",
    ));
    c.push(Check::abs(
        "S1 t′ of max |δ| [DERIVED]",
        0.24,
        t_dm,
        0.01,
        "",
    ));
    dm
}

/// S2: shaping filter, design current: biased estimates, steady offsets.
fn s2_checks(s2: &Run, c: &mut Vec<Check>) {
    let (t_p, p) = s2.extreme(&s2.eta, 0.0, 12.0, 1.0);
    c.push(Check::rel("S2 startup peak [DERIVED]", 63.8, p, 0.02, "m"));
    c.push(Check::rel(
        "S2 t′ of the startup peak [DERIVED]",
        3.66,
        t_p,
        0.02,
        "",
    ));
    c.push(Check::rel(
        "S2 η(t′ = 15) [DERIVED]",
        53.98,
        s2.eta[s2.at(15.0)],
        0.02,
        "m",
    ));
    c.push(Check::rel(
        "S2 η(t′ = 40) [DERIVED]",
        27.00,
        s2.eta[s2.at(40.0)],
        0.02,
        "m",
    ));
    c.push(Check::rel(
        "S2 N̂′(t′ = 15) [DERIVED]",
        0.000716,
        s2.n_hat[s2.at(15.0)],
        0.02,
        "",
    ));
    c.push(Check::rel(
        "S2 Ŷ′(t′ = 15) [DERIVED]",
        0.000835,
        s2.y_hat[s2.at(15.0)],
        0.02,
        "",
    ));
}

/// S4: random walk, design current: integral action.
fn s4_checks(s4: &Run, c: &mut Vec<Check>) {
    let (t_p, p) = s4.extreme(&s4.eta, 0.0, 12.0, 1.0);
    c.push(Check::rel("S4 startup peak [DERIVED]", 34.81, p, 0.02, "m"));
    c.push(Check::rel(
        "S4 t′ of the startup peak [DERIVED]",
        2.33,
        t_p,
        0.02,
        "",
    ));
    let (t_r, r) = s4.extreme(&s4.eta, 15.0, 30.0, -1.0);
    c.push(Check::rel("S4 ramp peak [DERIVED]", -9.53, r, 0.02, "m"));
    c.push(Check::rel(
        "S4 t′ of the ramp peak [DERIVED]",
        20.18,
        t_r,
        0.02,
        "",
    ));
    let eta_pk = 34.81;
    let delta_pk = 15.65;
    for (tp, e, d) in [
        (1.0, 15.21, 15.65),
        (2.0, 33.51, -0.20),
        (3.0, 30.33, -5.72),
        (5.0, 1.76, 0.30),
        (10.0, 0.61, -0.20),
        (15.0, -0.03, 0.01),
        (17.5, -4.80, -2.59),
        (20.0, -9.51, -1.73),
        (25.0, 0.68, -0.29),
        (30.0, -0.05, 0.02),
    ] {
        let i = s4.at(tp);
        c.push(rel2(
            &format!("S4 η(t′ = {tp}) [DERIVED]"),
            e,
            s4.eta[i],
            eta_pk,
            "m",
        ));
        c.push(rel2(
            &format!("S4 δ(t′ = {tp}) [DERIVED]"),
            d,
            s4.rudder_deg[i],
            delta_pk,
            "deg",
        ));
    }
    c.push(Check::rel(
        "S4 N̂′(t′ = 15) [DERIVED]",
        0.001026,
        s4.n_hat[s4.at(15.0)],
        0.02,
        "",
    ));
    c.push(Check::rel(
        "S4 Ŷ′(t′ = 15) [DERIVED]",
        0.002328,
        s4.y_hat[s4.at(15.0)],
        0.02,
        "",
    ));
}

/// S6: deep water, non-adapted vs optimal; S7 partially adapted.
fn deep_water_checks(nf: &NoiseFree, c: &mut Vec<Check>) {
    let (s6, s6o, s7) = (&nf.s6, &nf.s6o, &nf.s7);
    for (r, name, pk, tpk, ramp, tramp, n15, d15) in [
        (
            s6,
            "S6 non-adapted",
            63.30,
            2.81,
            -18.87,
            20.53,
            0.001961,
            8.20,
        ),
        (
            s6o,
            "S6 optimal at ∞",
            50.01,
            2.44,
            -14.31,
            20.35,
            0.001026,
            7.53,
        ),
        (
            s7,
            "S7 partially adapted",
            53.07,
            2.46,
            -14.15,
            19.89,
            0.001261,
            f64::NAN,
        ),
    ] {
        let (t_p, p) = r.extreme(&r.eta, 0.0, 12.0, 1.0);
        c.push(Check::rel(
            &format!("{name}: startup peak [DERIVED]"),
            pk,
            p,
            0.02,
            "m",
        ));
        c.push(Check::rel(
            &format!("{name}: t′ of the startup peak [DERIVED]"),
            tpk,
            t_p,
            0.02,
            "",
        ));
        let (t_r, rr) = r.extreme(&r.eta, 15.0, 30.0, -1.0);
        c.push(Check::rel(
            &format!("{name}: ramp peak [DERIVED]"),
            ramp,
            rr,
            0.02,
            "m",
        ));
        c.push(Check::rel(
            &format!("{name}: t′ of the ramp peak [DERIVED]"),
            tramp,
            t_r,
            0.02,
            "",
        ));
        c.push(Check::rel(
            &format!("{name}: N̂′(t′ = 15) [DERIVED]"),
            n15,
            r.n_hat[r.at(15.0)],
            0.02,
            "",
        ));
        if d15.is_finite() {
            c.push(Check::rel(
                &format!("{name}: δ(t′ = 15) [DERIVED]"),
                d15,
                r.rudder_deg[r.at(15.0)],
                0.02,
                "deg",
            ));
        }
    }
    c.push(Check::rel(
        "S6 optimal: equilibrium rudder at half current, δ(t′ = 40) [DERIVED]",
        3.75,
        s6o.rudder_deg[s6o.at(40.0)],
        0.02,
        "deg",
    ));
}

/// S7 really ran the [Parsons1980, Table 8] design (±1.5 in the last printed digit, as far as the
/// recomputed gains agree with the printed ones).
fn s7_design_checks(s7: &Run, c: &mut Vec<Check>) -> Result<(), String> {
    c.push(Check::abs(
        "S7 controller gain c13 (β′) after the adaptation = Table 8",
        1.8986,
        last(&s7.table, "ctl.gain_drift_angle")?,
        1.5e-4,
        "",
    ));
    c.push(Check::abs(
        "S7 controller design f23 = Table 2 at ∞",
        3.1591,
        last(&s7.table, "ctl.design_f23")?,
        1e-12,
        "",
    ));
    Ok(())
}

/// The equilibrium of [Parsons1980, sec. 4.2.2] (ψ′ = β′ = −0.1428, δ′ = 0.1310, N̂′ = 0.001992):
/// [Parsons1980, Table 5] design in deep water, full current held.
fn held_current_checks(env: &Env, c: &mut Vec<Check>) -> Result<(), String> {
    let u9 = {
        let mut sets = vec![
            "sensors.noise_scale=0".to_string(),
            "current.design_t_constant=1e9".to_string(),
            "current.design_t_ramp=2e9".to_string(),
        ];
        sets.extend(DEEP.iter().map(|s| s.to_string()));
        // the slow mode of the non-adapted loop settles within ~100 ship lengths
        let table = run_until(env, CURRENT, &sets, "s6_held_current.csv", 100.0)?;
        Run::new(table, 0.0)?
    };
    let e = u9.tp.len() - 1;
    c.push(Check::rel(
        "S6 held current: equilibrium N̂′ (report 0.00199, Fig. 20) [DERIVED 0.001992]",
        0.001992,
        u9.n_hat[e],
        0.02,
        "",
    ));
    c.push(Check::rel(
        "S6 held current: equilibrium Ŷ′ [DERIVED]",
        0.003437,
        u9.y_hat[e],
        0.02,
        "",
    ));
    c.push(Check::rel(
        "S6 held current: ψ′ = β′ (line 1145: −0.1428)",
        -0.1428,
        u9.heading_deg[e] * DEG,
        0.02,
        "rad",
    ));
    c.push(Check::rel(
        "S6 held current: δ′ (line 1145: 0.1310)",
        0.1310,
        u9.rudder_deg[e] * DEG,
        0.02,
        "rad",
    ));
    Ok(())
}

/// The Appendix-A loop: peak rudder of the report's loop and of the loop with the Jacobi
/// exchange [deg], max |Δη| [m] between our S4 and the report's loop.
struct AppendixA {
    peak_report: f64,
    peak_jacobi: f64,
    de4: f64,
}

/// The co-simulation against the Appendix-A loop, with and without the Jacobi exchange.
fn appendix_a_checks(nf: &NoiseFree, dm: f64, c: &mut Vec<Check>) -> Result<AppendixA, String> {
    let (s1, s4) = (&nf.s1, &nf.s4);
    let truth189 = TokyoMaruCoefficients::at_depth_ratio(1.89);
    let rw = PathDesignModel::random_walk(1.89);
    let sf = PathDesignModel::shaping_filter(1.89);
    let passing = |tp: f64| passing_ship(tp - 20.0, 4.0);
    let current = |tp: f64| {
        let s = design_current_profile(tp, 15.0, 20.0, 0.5);
        (0.0010262 * s, 0.0023277 * s)
    };
    let a1 = appendix_a(truth189, sf, HALF_BEAM, &passing, 3000, false)?;
    let a1c = appendix_a(truth189, sf, HALF_BEAM, &passing, 3000, true)?;
    let peak = |v: &[[f64; 3]]| max_abs(&v.iter().map(|p| p[2]).collect::<Vec<_>>());
    c.push(Check::rel(
        "S1 max |δ|, Appendix-A loop (the report's discretisation) [DERIVED]",
        4.66,
        peak(&a1),
        0.02,
        "deg",
    ));
    c.push(Check::abs(
        "S1 max |δ|, Appendix-A loop with the Jacobi exchange, vs ours",
        peak(&a1c),
        dm,
        1e-6,
        "deg",
    ));
    let (de, dd) = max_diff(&a1c, s1);
    c.push(Check::abs(
        "S1 max |η_ours − η_loop with the Jacobi exchange| (t′ ≤ 15)",
        0.0,
        de,
        1e-6,
        "m",
    ));
    c.push(Check::abs(
        "S1 max |δ_ours − δ_loop with the Jacobi exchange| (t′ ≤ 15)",
        0.0,
        dd,
        1e-6,
        "deg",
    ));
    let a4c = appendix_a(truth189, rw, 0.0, &current, 8000, true)?;
    let (de, dd) = max_diff(&a4c, s4);
    c.push(Check::abs(
        "S4 max |η_ours − η_loop with the Jacobi exchange| (t′ ≤ 40)",
        0.0,
        de,
        1e-6,
        "m",
    ));
    c.push(Check::abs(
        "S4 max |δ_ours − δ_loop with the Jacobi exchange| (t′ ≤ 40)",
        0.0,
        dd,
        1e-6,
        "deg",
    ));
    let a4 = appendix_a(truth189, rw, 0.0, &current, 8000, false)?;
    let (de4, _) = max_diff(&a4, s4);
    Ok(AppendixA {
        peak_report: peak(&a1),
        peak_jacobi: peak(&a1c),
        de4,
    })
}

/// The passing-ship scenarios (S1, S3) over the seeds: seed 1's runs, the largest deviation
/// during the passing [m] and the largest rudder then [deg].
struct PassingSeeds {
    seed1: Vec<Run>,
    deviation: [Spread; 2],
    rudder: [Spread; 2],
}

/// The report's noisy figures of S1 and S3 over the seeds: overshoot and the passing ship.
fn passing_ship_seeds(env: &Env, c: &mut Vec<Check>) -> Result<PassingSeeds, String> {
    let mut seed1: Vec<Run> = Vec::new();
    let mut passing_stats: Vec<[Vec<f64>; 4]> = Vec::new();
    for sc in [&S1, &S3] {
        let mut st: [Vec<f64>; 4] = Default::default();
        for seed in 1..=SEEDS {
            let r = run_scenario(
                env,
                sc,
                &[format!("sensors.seed={seed}")],
                &format!("{}_noisy.csv", sc.id),
            )?;
            let (t, v) = r.extreme(&r.eta, 3.0, 10.0, -1.0);
            st[0].push(-v);
            st[1].push(t);
            let (_, hi) = r.extreme(&r.eta, 17.0, 25.0, 1.0);
            let (_, lo) = r.extreme(&r.eta, 17.0, 25.0, -1.0);
            st[2].push(hi.max(-lo));
            let (_, dh) = r.extreme(&r.rudder_deg, 17.0, 25.0, 1.0);
            let (_, dl) = r.extreme(&r.rudder_deg, 17.0, 25.0, -1.0);
            st[3].push(dh.max(-dl));
            if seed == 1 {
                seed1.push(r);
            }
        }
        passing_stats.push(st);
    }
    for (i, (name, os, t_os)) in [("S1", "1.6", "5.3"), ("S3", "1.7", "5.6")]
        .into_iter()
        .enumerate()
    {
        let st = &passing_stats[i];
        c.push(within_seeds(
            &format!("{name} overshoot (Fig. {})", if i == 0 { 6 } else { 11 }),
            os,
            &Spread::of(&st[0]),
            "m",
        ));
        c.push(within_seeds(
            &format!("{name} t′ of the overshoot"),
            t_os,
            &Spread::of(&st[1]),
            "",
        ));
    }
    let (p1, p3) = (
        Spread::of(&passing_stats[0][2]),
        Spread::of(&passing_stats[1][2]),
    );
    c.push(Check::holds(
        "passing ship (4x, surrogate of the lost Fig. 3): the random-walk design deviates less",
        "S1 6.2 m > S3 3.5 m",
        format!("S1 {:.2} m > S3 {:.2} m (seed means)", p1.mean, p3.mean),
        p3.mean < p1.mean,
    ));
    Ok(PassingSeeds {
        seed1,
        deviation: [p1, p3],
        rudder: [
            Spread::of(&passing_stats[0][3]),
            Spread::of(&passing_stats[1][3]),
        ],
    })
}

/// The numbers the report reads off its noisy design-current figures: (quantity, printed value,
/// scenario (S2, S4, S6, S6 optimal, S7), statistic (startup peak, ramp peak, mean η at full and
/// half current, mean N̂′ at full and half current), unit).
const CURRENT_FIGURES: [(&str, &str, usize, usize, &str); 14] = [
    (
        "S2 steady offset, full current (mean η, 10 ≤ t′ ≤ 15; Fig. 8)",
        "54",
        0,
        2,
        "m",
    ),
    (
        "S2 steady offset, half current (mean η, 30 ≤ t′ ≤ 40)",
        "27",
        0,
        3,
        "m",
    ),
    (
        "S2 N̂′ on the full-current plateau (Fig. 10)",
        "0.00072",
        0,
        4,
        "",
    ),
    ("S4 startup peak (Fig. 13)", "34.5", 1, 0, "m"),
    ("S4 peak during the ramp (\"about 9 m\")", "9", 1, 1, "m"),
    ("S4 N̂′, full current (Fig. 15)", "0.00103", 1, 4, ""),
    ("S4 N̂′, half current", "0.000515", 1, 5, ""),
    ("S6 non-adapted startup peak (Fig. 18)", "63.5", 2, 0, "m"),
    ("S6 non-adapted ramp peak", "18.5", 2, 1, "m"),
    ("S6 optimal-at-∞ startup peak (Fig. 18)", "50.2", 3, 0, "m"),
    ("S6 optimal-at-∞ ramp peak", "13.8", 3, 1, "m"),
    (
        "S7 partially adapted startup peak (Fig. 21)",
        "53.2",
        4,
        0,
        "m",
    ),
    ("S7 partially adapted ramp peak", "13.9", 4, 1, "m"),
    (
        "S7 mean N̂′ over the first 15 L (Fig. 23)",
        "0.00126",
        4,
        4,
        "",
    ),
];

/// The design-current scenarios over the seeds: startup peak, ramp peak, mean offsets and N̂′ on
/// the plateaus. Returns seed 1 of S4.
fn design_current_seeds(env: &Env, c: &mut Vec<Check>) -> Result<Run, String> {
    let mut seed1 = None;
    let mut cur_stats: Vec<[Vec<f64>; 6]> = Vec::new();
    for sc in [&S2, &S4, &S6, &S6O, &S7] {
        let mut st: [Vec<f64>; 6] = Default::default();
        for seed in 1..=SEEDS {
            let r = run_scenario(
                env,
                sc,
                &[format!("sensors.seed={seed}")],
                &format!("{}_noisy.csv", sc.id.replace(' ', "_")),
            )?;
            let (_, hi) = r.extreme(&r.eta, 0.0, 12.0, 1.0);
            st[0].push(hi);
            let (_, lo) = r.extreme(&r.eta, 15.0, 30.0, -1.0);
            let (_, hi2) = r.extreme(&r.eta, 15.0, 30.0, 1.0);
            st[1].push((-lo).max(hi2));
            st[2].push(r.mean(&r.eta, 10.0, 15.0));
            st[3].push(r.mean(&r.eta, 30.0, 40.0));
            st[4].push(r.mean(&r.n_hat, 10.0, 15.0));
            st[5].push(r.mean(&r.n_hat, 30.0, 40.0));
            if seed == 1 && sc.id == "S4" {
                seed1 = Some(r);
            }
        }
        cur_stats.push(st);
    }
    for (quantity, printed, i, j, unit) in CURRENT_FIGURES {
        c.push(within_seeds(
            quantity,
            printed,
            &Spread::of(&cur_stats[i][j]),
            unit,
        ));
    }
    seed1.ok_or_else(|| "no S4 run".to_string())
}

/// Cross-track, heading, rudder (and N̂′ with `with_n`) of the runs, one curve per (run, label).
fn trajectory_figure(
    env: &Env,
    name: &str,
    title: &str,
    runs: &[(&Run, &str)],
    with_n: bool,
) -> Result<std::path::PathBuf, String> {
    let mut panels = vec![
        Panel {
            y_label: "cross-track η [m]".into(),
            series: runs.iter().map(|(r, l)| r.series(&r.eta, l)).collect(),
        },
        Panel {
            y_label: "heading ψ [deg]".into(),
            series: runs
                .iter()
                .map(|(r, l)| r.series(&r.heading_deg, l))
                .collect(),
        },
        Panel {
            y_label: "rudder δ [deg]".into(),
            series: runs
                .iter()
                .map(|(r, l)| r.series(&r.rudder_deg, l))
                .collect(),
        },
    ];
    if with_n {
        panels.push(Panel {
            y_label: "N̂′ (filter)".into(),
            series: runs.iter().map(|(r, l)| r.series(&r.n_hat, l)).collect(),
        });
    }
    env.figure(name, title, &panels)
}

/// [Parsons1980, Figs. 6-23]: cross-track, heading, rudder (and N̂′) of the noise-free runs and
/// seed 1.
fn figures(
    env: &Env,
    nf: &NoiseFree,
    seed1: &[Run],
    s4_seed1: &Run,
    report: &mut Report,
) -> Result<(), String> {
    let NoiseFree {
        s1,
        s3,
        s2,
        s4,
        s6,
        s6o,
        s7,
    } = nf;
    let f1 = trajectory_figure(
        env,
        "offset_and_passing_ship.png",
        "Tokyo Maru from B/2 off the track, 4x passing ship at t' = 20 (t' = t/46.98 s)",
        &[
            (s1, "S1 shaping filter, noise-free"),
            (s3, "S3 random walk, noise-free"),
            (&seed1[0], "S1 noise seed 1"),
            (&seed1[1], "S3 noise seed 1"),
        ],
        false,
    )?;
    report.figures.push((
        "S1/S3 (Figs. 6-7, 11-12): cross-track, heading, rudder".into(),
        f1,
    ));
    let f2 = trajectory_figure(
        env,
        "design_current.png",
        "Design lateral current at H/T = 1.89 (t' = t/46.98 s)",
        &[
            (s2, "S2 shaping filter (Table 4)"),
            (s4, "S4 random walk (Table 5)"),
            (s4_seed1, "S4 noise seed 1"),
        ],
        true,
    )?;
    report.figures.push((
        "S2/S4 (Figs. 8-10, 13-15): cross-track, heading, rudder, N̂′".into(),
        f2,
    ));
    let f3 = trajectory_figure(
        env,
        "deep_water.png",
        "Design lateral current in deep water (t' = t/46.98 s)",
        &[
            (s6, "S6 Table 5 (non-adapted)"),
            (s6o, "S6 Table 6 (optimal at inf)"),
            (s7, "S7 Table 8 (f23, f25 adapted)"),
        ],
        true,
    )?;
    report.figures.push((
        "S6/S7 (Figs. 18-23): cross-track, heading, rudder, N̂′".into(),
        f3,
    ));
    Ok(())
}

/// The notes: setup, the Jacobi exchange, the scenarios, and what is not run.
fn notes(loops: &AppendixA, passing: &PassingSeeds, n: &mut Vec<String>) {
    let [p1, p3] = passing.deviation;
    n.push(format!(
        "Setup: one communication step = Δt′ = 0.005 ({:.5} s, t′ = tU/L with U = 12 kn, L = 290 m); \
         TokyoMaru forward Euler at Δt′ as the report (integration = 2); SteeringGear first-order \
         T_r = 10 s ([DERIVED] 0.212874), unlimited, integrated exactly; PathKalmanFilter Euler at \
         Δt′; Jacobi master. Noise: Sensors with the Table 3 per-sample σ′ (ψ 1.611e-3 rad, r \
         7.563e-3·U/L rad/s, η 9.549e-3·L m), seeds 1-{SEEDS}; noise_scale = 0 for the [DERIVED] runs.",
        DT * L / U
    ));
    n.push(format!(
        "Jacobi exchange: the Sensors output and the PathController output are direct feedthroughs, \
         so the filter sees the measurement and the gear the command of the previous exchange (one \
         Δt′ = 0.005 L each), where the report's loop (spec Appendix A) uses both at once. The \
         Appendix-A loop re-run here with exactly these delays equals our co-simulation to < 1e-6 \
         (checks above), so the master and FMUs add nothing else. The delays change the peaks by \
         < 0.5 % and trajectory points by < 1.7 % (our S4 vs the report's loop: max |Δη| = {:.3} m), \
         but the S1 rudder peak, which comes 0.24 L after a command step, by +2.4 % ({:.3}° vs \
         4.66°; +3.1 % with the Table 5 gains of S3): that check is held to 3 % for this reason; \
         the Appendix-A loop without the delays gives {:.3}° (within 2 % of 4.66°).",
        loops.de4,
        loops.peak_jacobi,
        loops.peak_report
    ));
    for sc in [&S1, &S3, &S2, &S4, &S6, &S6O, &S7] {
        n.push(format!(
            "{}: {}: systems/{} with {}.",
            sc.id,
            sc.what,
            sc.file,
            overrides_text(sc.sets)
        ));
    }
    n.push(
        "Initialization: in Initialization Mode the FMUs' outputs follow their parameters and \
         start values (export layer), so the master's initial exchange gives the controller the \
         filter's initial estimate and the first command at t′ = 0 is C14·η′(0) = 11.38°."
            .into(),
    );
    n.push(
        "S1/S3 initial offset: the TokyoMaru FMU has no initial-state parameters. η enters nothing \
         in the plant, so η(0) = B/2 is applied exactly as a shifted track: the connection \
         ship.cross_track → sensors.cross_track carries offset 23.75 m, the filter starts at 23.75 m \
         and the offset from the track is ship.cross_track + 23.75 m."
            .into(),
    );
    n.push(
        "S7 (Table 8 design): the PathKalmanFilter takes f23, f25 at H/T = ∞ by adapted_depth_ratio; \
         the PathController has no such parameter, so the design goes the adaptive way: estimate \
         inputs f23 = 3.1591, f25 = −1.0410 (the others at 1.89) are applied by the Table 10 rule \
         at the end of a zero-amplitude dither window of one step at t′ = 0 (x̂(0) = 0, so that \
         step's command is 0 either way). The resulting c13 and f23 are checked against Table 8/2."
            .into(),
    );
    n.push(format!(
        "Passing ship (S1/S3 at t′ = 20, 4x): Fig. 3 is lost; the Current FMU uses the spec's Ricker \
         surrogate, which matches only the printed peaks and RMS. Maximum deviations over the seeds: \
         S1 {:.2}-{:.2} m (report 6.2 m), S3 {:.2}-{:.2} m (report 3.5 m); not asserted, only the \
         ordering. Maximum rudder in S3 during the passing: {:.1}-{:.1}° (report: 35°, beyond the \
         linear model's validity); S1 {:.1}-{:.1}°.",
        p1.min, p1.max, p3.min, p3.max,
        passing.rudder[1].min, passing.rudder[1].max,
        passing.rudder[0].min, passing.rudder[0].max,
    ));
    n.push(
        "S6 N̂′: the report's \"about 0.00199\" (Fig. 20, \"equilibrium\") is the equilibrium of the \
         non-adapted loop under the full current, reached only after ~100 L (0.001961 at t′ = 15, \
         still settling); it is checked on a run with the full current held to t′ = 100, which also \
         gives the line-1145 equilibrium ψ′ = β′ = −0.1428, δ′ = 0.1310."
            .into(),
    );
    n.push(
        "Tolerances: [DERIVED] values ±2 % (times of peaks too); trajectory points ±2 % or ±1 % of \
         the scenario's peak (S1 23.75 m; S4 34.81 m, 15.65°), whichever is larger: near a zero \
         crossing a relative tolerance means nothing, and the spec prints two decimals. Noisy runs: the report shows one realisation of unknown \
         seed, so its printed number must lie within the min-max of 20 seeds, widened by half a \
         unit of the printed last digit; \"about\" values (54, 27, 9 m) by ±0.5 m."
            .into(),
    );
    n.push(
        "Not run: S5 (ABC harbour; Fig. 5 is lost and needs a strip-theory reconstruction) and S8 \
         (Table 7, a stationary covariance analysis, not a simulation). The estimator scenarios \
         (WLS S9-S13, MVE S14) are in the path-estimation study. Not run either: the MVE runs over a \
         varying bottom, S15/S16 (Table 18): the report's depth-to-coefficient rule is not given (between \
         H/T = 2.5 and 10 there are no coefficients at all; within 1.3-2.5 no simple interpolation \
         reproduces its Table 14 truth, spec §6)."
            .into(),
    );
}
