//! S14 [Parsons1980, sec. 5.3, Table 16, Figs. 28-31]: the MVE in the loop, truth at H/T = 1.89,
//! everything initialised for deep water, three disturbance cases; and the same loop at model
//! level.

use super::model_loop::{run_loop, LoopEstimator, LoopRun, LoopSpec};
use super::{err, noise_free_sets, within_seeds, CYCLE, DT, SEEDS};
use crate::study::{
    col, constant_series, fmt_num, overrides_text, series, Check, Env, Report, Spread,
};
use models::controllers::mve::{parameters_of, Mve, MveParams, SIGMA_TABLE_9};
use models::controllers::path::{
    Adaptation, Dither, PathController, PathControllerParams, PathInputs,
};
use models::hull::tokyo_maru::{L, TABLE_2, T_R, U};
use models::observers::path_kalman::PathKalmanFilter;
use models::observers::path_model::PathDesignModel;
use models::random::NoiseStream;
use shipsim::plot::{Panel, Series};
use shipsim::results::ResultsTable;

pub(super) const MVE: &str = "path_control_mve.toml";
/// The S14 dither start (half a step early, see the system file).
const DITHER_START: f64 = -0.0025;
const NAMES: [&str; 6] = ["f22", "f23", "f25", "f32", "f33", "f35"];

/// One S14 disturbance case ([Parsons1980, Table 16] rows): caption, overrides, printed
/// min/mean/max/final/RMS (rows) of f22..f35 (columns).
struct MveCase {
    id: &'static str,
    what: &'static str,
    sets: &'static [&'static str],
    table_16: [[&'static str; 6]; 5],
}

const MVE_CASES: [MveCase; 3] = [
    MveCase {
        id: "none",
        what: "no disturbance",
        sets: &[],
        table_16: [
            [
                "-1.9685", "2.5224", "-1.0450", "0.16221", "-0.66132", "-0.16216",
            ],
            [
                "-1.9168", "5.2404", "-0.89901", "0.24378", "-0.64976", "-0.16170",
            ],
            [
                "-1.8915", "5.8801", "-0.84419", "0.32722", "-0.63519", "-0.16147",
            ],
            [
                "-1.9325", "5.4886", "-0.90793", "0.18731", "-0.66132", "-0.16166",
            ],
            [
                "2.1461", "12.8305", "0.43412", "1.17259", "1.72961", "0.07969",
            ],
        ],
    },
    MveCase {
        id: "passing ship",
        what: "passing ship (Fig. 3 surrogate, 1x) beam-to-beam at t′ = 7",
        sets: &[
            "current.passing_ship_factor=1",
            "current.passing_ship_time=7",
        ],
        table_16: [
            [
                "-1.9685", "2.5227", "-1.0450", "0.16221", "-0.66388", "-0.16216",
            ],
            [
                "-1.9127", "5.2805", "-0.89817", "0.23505", "-0.65139", "-0.16172",
            ],
            [
                "-1.8915", "5.9401", "-0.84419", "0.32722", "-0.63519", "-0.16148",
            ],
            [
                "-1.9020", "5.9162", "-0.92556", "0.19843", "-0.66257", "-0.16176",
            ],
            // f35: [Parsons1980, Table 16] prints "−0.07987", a negative RMS: read as 0.07987
            [
                "2.0896", "12.8430", "0.43989", "1.11448", "1.75410", "0.07987",
            ],
        ],
    },
    MveCase {
        id: "white noise",
        what: "white N′, Y′ (σ_N = 2e-5, σ_Y = 5e-5 per sample)",
        sets: &["current.white_sigma_n=2e-5", "current.white_sigma_y=5e-5"],
        table_16: [
            [
                "-1.9702", "2.4553", "-1.04570", "0.16100", "-0.66127", "-0.16216",
            ],
            [
                "-1.9175", "5.2358", "-0.90398", "0.24352", "-0.64974", "-0.16170",
            ],
            [
                "-1.8918", "5.8529", "-0.85260", "0.32655", "-0.63527", "-0.16147",
            ],
            [
                "-1.9320", "5.5226", "-0.91279", "0.18707", "-0.66127", "-0.16166",
            ],
            [
                "2.1570", "13.5175", "0.47312", "1.16839", "1.72925", "0.07966",
            ],
        ],
    },
];

/// Statistics of one S14 run.
#[derive(Clone, Debug, Default)]
struct MveStats {
    /// Max |η′| in the first cycle (t′ ≤ 6.25) and its t′.
    eta_max: f64,
    t_eta_max: f64,
    /// t′ from which f̂23 stays within ±10 % of its truth to the end of the first cycle (6.25 if
    /// it is outside at the end), and t′ where it first comes within ±10 % (6.25: not in the
    /// first cycle).
    f23_settled: f64,
    f23_near: f64,
    /// f̂23 at every exchange of the first cycle.
    f23: Vec<f64>,
    /// Over the estimates (the rows where an estimate changed): min, mean, max, final, RMS(118).
    stats: [[f64; 6]; 5],
    estimates: usize,
    gain_updates: f64,
}

/// [Parsons1980, Table 16] statistics of a sequence of estimates against the truth `p`.
fn table_16_stats(est: &[[f64; 6]], fin: [f64; 6], p: [f64; 6]) -> [[f64; 6]; 5] {
    let n = est.len() as f64;
    let mut s = [[0.0; 6]; 5];
    for i in 0..6 {
        let v = est.iter().map(|e| e[i]);
        s[0][i] = v.clone().fold(f64::INFINITY, f64::min);
        s[1][i] = v.clone().sum::<f64>() / n;
        s[2][i] = v.clone().fold(f64::NEG_INFINITY, f64::max);
        s[3][i] = fin[i];
        // [Parsons1980, eq. (118)]: √Σ without 1/N
        s[4][i] = v.map(|x| (x - p[i]).powi(2)).sum::<f64>().sqrt();
    }
    s
}

/// The statistics of one S14 run through the master.
fn mve_stats(t: &ResultsTable) -> Result<MveStats, String> {
    let tp = col(t, "ship.time_prime")?;
    let eta = col(t, "ship.cross_track")?;
    let cols: Vec<&[f64]> = NAMES
        .iter()
        .map(|n| col(t, &format!("est.{n}_estimate")))
        .collect::<Result<_, _>>()?;
    let row = |k: usize| -> [f64; 6] { std::array::from_fn(|i| cols[i][k]) };
    let truth = parameters_of(&TABLE_2[2]);
    let mut s = MveStats::default();
    let mut est = Vec::new();
    let mut settled = 0.0;
    let mut near = CYCLE;
    for k in 0..tp.len() {
        if tp[k] <= CYCLE + 1e-9 {
            s.f23.push(row(k)[1]);
            let e = (eta[k] / L).abs();
            if e > s.eta_max {
                s.eta_max = e;
                s.t_eta_max = tp[k];
            }
            if (row(k)[1] - truth[1]).abs() > 0.1 * truth[1] {
                settled = tp[k] + DT;
            } else if near == CYCLE {
                near = tp[k];
            }
        }
        if k > 0 && row(k) != row(k - 1) {
            est.push(row(k));
        }
    }
    s.f23_settled = settled.min(CYCLE);
    s.f23_near = near;
    s.estimates = est.len();
    if est.is_empty() {
        return Err("S14: the estimator made no estimate".into());
    }
    s.stats = table_16_stats(&est, row(tp.len() - 1), truth);
    s.gain_updates = *col(t, "ctl.gain_updates")?.last().unwrap_or(&0.0);
    Ok(s)
}

/// The overrides of one S14 case and seed.
fn seed_sets(case: &MveCase, seed: u64) -> Vec<String> {
    let mut v: Vec<String> = case.sets.iter().map(|s| s.to_string()).collect();
    v.push(format!("sensors.seed={seed}"));
    v.push(format!("est_sensors.seed={}", 1000 + seed));
    v.push(format!("current.seed={}", 2000 + seed));
    v
}

/// Per-sample noise σ′ of ψ′, r′, η′: [Parsons1980, Table 3] (the S14 control loop).
const SIGMA_TABLE_3: [f64; 3] = [1.611e-3, 7.563e-3, 9.549e-3];

/// The PathController settings of S14 (`dither_start`: see systems/path_control_mve.toml).
fn s14_controller(dither_start: f64) -> PathControllerParams {
    PathControllerParams {
        design_depth_ratio: 1e300,
        adaptation: Adaptation::Estimated,
        dither: Dither {
            enabled: true,
            start: dither_start,
            ..Dither::default()
        },
        ..Default::default()
    }
}

/// S14 at model level: the master's structure (`exchange`) or the report's loop.
fn s14_loop(noise: Option<u64>, kf_update: bool, exchange: bool) -> Result<LoopRun, String> {
    let deep = TABLE_2[4];
    run_loop(LoopSpec {
        depth_ratio: 1.89,
        forces: [0.0; 2],
        x0: [0.0; 5],
        xhat0: [0.0; 7],
        controller: s14_controller(DITHER_START),
        estimator: LoopEstimator::Mve(
            Mve::new(MveParams::default(), parameters_of(&deep)).map_err(err)?,
        ),
        steps: 2000,
        noise,
        sigma_filter: SIGMA_TABLE_3,
        sigma_estimator: SIGMA_TABLE_9,
        shared: false,
        kf_update,
        exchange,
    })
}

/// The S14 loop of the test in `models/src/controllers/mve.rs` (no exchange delays, the filter
/// re-designed with the controller, Euler at Δt′ = 0.005, one ChaCha8 stream: stream 0 of the
/// seed, as the test's `ChaCha8Rng::seed_from_u64`). Returns max |η′| in the first cycle and the
/// RMS(118) of f̂23 and the t′ of that maximum.
fn test_loop(seed: u64) -> Result<(f64, f64, f64), String> {
    let truth = TABLE_2[2];
    let deep = TABLE_2[4];
    let (fs, gs, _) = truth.eq11(T_R);
    let mut rng = NoiseStream::new(seed, 0);
    let params = s14_controller(0.0);
    let mut ctl = PathController::new(params).map_err(err)?;
    let design = |c| PathDesignModel {
        coefficients: c,
        ..params.design
    };
    let mut kf = PathKalmanFilter::new(design(deep), [0.0; 7]).map_err(err)?;
    let mut mve = Mve::new(MveParams::default(), parameters_of(&deep)).map_err(err)?;
    let h = DT * L / U;
    let mut x = [0.0f64; 5];
    let (mut eta_max, mut t_max) = (0.0f64, 0.0);
    let mut sq23 = 0.0;
    let mut updates = 0;
    for k in 0..2000 {
        let xh = *kf.estimate();
        let inputs = PathInputs {
            heading: xh[0],
            yaw_rate: xh[1] * U / L,
            drift_angle: xh[2],
            cross_track: xh[3] * L,
            rudder: xh[4],
            yaw_moment_prime: xh[5],
            sway_force_prime: xh[6],
            depth_ratio: 1.89,
            estimates: mve.estimate(),
        };
        if k == 0 {
            ctl.start(&inputs);
        }
        let u = ctl.command(&inputs);
        let z: [f64; 3] = [
            x[0] + SIGMA_TABLE_3[0] * rng.normal(),
            x[1] + SIGMA_TABLE_3[1] * rng.normal(),
            x[3] + SIGMA_TABLE_3[2] * rng.normal(),
        ];
        let zm: [f64; 4] = std::array::from_fn(|i| x[i] + SIGMA_TABLE_9[i] * rng.normal());
        if mve.sample(zm, x[4]) {
            sq23 += (mve.estimate()[1] - truth.f23).powi(2);
        }
        let dx: [f64; 5] =
            std::array::from_fn(|i| (0..5).map(|j| fs[(i, j)] * x[j]).sum::<f64>() + gs[i] * u);
        for i in 0..5 {
            x[i] += dx[i] * DT;
        }
        kf.step_prime(z, u, DT);
        ctl.step(&inputs, h).map_err(err)?;
        if ctl.updates() != updates {
            updates = ctl.updates();
            kf.set_design(design(*ctl.coefficients())).map_err(err)?;
        }
        let tp = (k + 1) as f64 * DT;
        if tp <= CYCLE + 1e-9 && x[3].abs() > eta_max {
            eta_max = x[3].abs();
            t_max = tp;
        }
    }
    Ok((eta_max, sq23.sqrt(), t_max))
}

/// S14: the runs through the master over the seeds, [Parsons1980, Table 16, Figs. 28-31], the
/// same loop at model level, figure and notes.
pub(super) fn s14(env: &Env, report: &mut Report) -> Result<(), String> {
    let runs = MveRuns::run(env)?;
    let c = &mut report.checks;
    structure_checks(&runs, c);
    let first = first_cycle_checks(&runs, c);
    table_16_checks(&runs, c);
    identification_checks(&runs, c);
    let model = model_level(env, c)?;
    figure(env, &runs, report)?;
    notes(&runs, &first, &model, &mut report.notes);
    Ok(())
}

/// The S14 runs through the master: the statistics of every case and seed, the tables of seed 1.
struct MveRuns {
    cases: Vec<Vec<MveStats>>,
    seed1: Vec<ResultsTable>,
}

impl MveRuns {
    fn run(env: &Env) -> Result<MveRuns, String> {
        let mut cases: Vec<Vec<MveStats>> = Vec::new();
        let mut seed1: Vec<ResultsTable> = Vec::new();
        for case in &MVE_CASES {
            let mut v = Vec::new();
            for seed in 1..=SEEDS {
                let csv = format!("s14_{}.csv", case.id.replace(' ', "_"));
                let t = env.run(MVE, &seed_sets(case, seed), &csv)?;
                v.push(mve_stats(&t)?);
                if seed == 1 {
                    seed1.push(t);
                }
            }
            cases.push(v);
        }
        Ok(MveRuns { cases, seed1 })
    }

    /// The spread of `f` over the seeds of case `c`.
    fn sp(&self, c: usize, f: impl Fn(&MveStats) -> f64) -> Spread {
        Spread::over(&self.cases[c], f)
    }
}

/// ℓ = 10 and the two gain updates (ends of the dither windows).
fn structure_checks(runs: &MveRuns, c: &mut Vec<Check>) {
    let n_est: Vec<usize> = runs.cases.iter().flatten().map(|s| s.estimates).collect();
    let n_upd: Vec<f64> = runs
        .cases
        .iter()
        .flatten()
        .map(|s| s.gain_updates)
        .collect();
    c.push(Check::holds(
        "S14 estimates in 10 L (ℓ = 10 samples) in every run: 199 by counting (one per ℓ samples after the first ℓ)",
        "200 (Table 16): one more than counting gives, see the notes",
        format!(
            "{}..{}",
            n_est.iter().min().unwrap_or(&0),
            n_est.iter().max().unwrap_or(&0)
        ),
        n_est.iter().all(|&n| n == 199),
    ));
    c.push(Check::holds(
        "S14 gain updates at the ends of the dither windows (t′ = 2.5, 8.75), every run",
        "2 (f̂'s in the Table 10 ranges)",
        format!(
            "{}..{}",
            n_upd.iter().cloned().fold(f64::INFINITY, f64::min),
            n_upd.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        ),
        n_upd.iter().all(|&n| n == 2.0),
    ));
}

/// The first cycle: the peak offset [Parsons1980, Fig. 28] and when f̂23 comes near its truth
/// [Parsons1980, Fig. 29].
struct FirstCycle {
    eta: Spread,
    t_eta: Spread,
    /// t′ where the seed-mean f̂23 first comes within ±10 % (passing-ship case).
    t_mean_near: f64,
    near: Spread,
    settle: Spread,
}

fn first_cycle_checks(runs: &MveRuns, c: &mut Vec<Check>) -> FirstCycle {
    let truth = parameters_of(&TABLE_2[2]);
    // ---- [Parsons1980, Fig. 28]: the offset after the first dither window
    let eta = runs.sp(0, |s| s.eta_max);
    let t_eta = runs.sp(0, |s| s.t_eta_max);
    c.push(within_seeds(
        "S14 max |η′| in the first cycle (Fig. 28; OCR \"0.01738\")",
        &["0.1738"],
        &[eta],
        "",
    ));
    c.push(within_seeds(
        "S14 t′ of the max |η′| (Fig. 28)",
        &["3.8"],
        &[t_eta],
        "",
    ));
    // ---- [Parsons1980, Fig. 29] (the passing-ship run): f̂23 near its true value in about 3 L
    let near = runs.sp(1, |s| s.f23_near);
    let settle = runs.sp(1, |s| s.f23_settled);
    // the seed-mean trajectory of f̂23 (the noise averaged out), where it first comes within 10 %
    let ship_runs = &runs.cases[1];
    let n_rows = ship_runs.iter().map(|s| s.f23.len()).min().unwrap_or(0);
    let mean_f23: Vec<f64> = (0..n_rows)
        .map(|k| ship_runs.iter().map(|s| s.f23[k]).sum::<f64>() / ship_runs.len() as f64)
        .collect();
    let t_mean_near = mean_f23
        .iter()
        .position(|v| (v - truth[1]).abs() <= 0.1 * truth[1])
        .map_or(CYCLE, |k| k as f64 * DT);
    c.push(Check::abs(
        "S14 passing ship: t′ where the seed-mean f̂23 first comes within ±10 % of 5.7359 (Fig. 29 \
         \"nears its true value in ≈3 L\")",
        3.0,
        t_mean_near,
        1.0,
        "",
    ));
    FirstCycle {
        eta,
        t_eta,
        t_mean_near,
        near,
        settle,
    }
}

/// [Parsons1980, Table 16], three cases: min / mean / max / final and RMS(118) of every estimate.
fn table_16_checks(runs: &MveRuns, c: &mut Vec<Check>) {
    for (ci, case) in MVE_CASES.iter().enumerate() {
        for (i, name) in NAMES.iter().enumerate() {
            let printed: Vec<&str> = (0..4).map(|r| case.table_16[r][i]).collect();
            let spreads: Vec<Spread> = (0..4).map(|r| runs.sp(ci, |s| s.stats[r][i])).collect();
            c.push(within_seeds(
                &format!("Table 16 {}: {name} min / mean / max / final", case.id),
                &printed,
                &spreads,
                "",
            ));
        }
        for (i, name) in NAMES.iter().enumerate() {
            if i == 2 {
                continue; // f25: at or below the seeds' low end, see the [DERIVED] check and note
            }
            c.push(within_seeds(
                &format!("Table 16 {}: {name} RMS(118)", case.id),
                &[case.table_16[4][i]],
                &[runs.sp(ci, |s| s.stats[4][i])],
                "",
            ));
        }
    }
}

/// Which parameters the MVE identifies, and that the disturbances do not degrade f̂23.
fn identification_checks(runs: &MveRuns, c: &mut Vec<Check>) {
    let truth = parameters_of(&TABLE_2[2]);
    let initial = parameters_of(&TABLE_2[4]);
    let rms25 = runs.sp(0, |s| s.stats[4][2]);
    c.push(Check::range(
        "S14 RMS(118) of f̂25, seed median, no disturbance [DERIVED] (printed 0.43412, see note)",
        "0.57-1.18 (3 seeds)",
        rms25.median,
        0.57,
        1.18,
        "",
    ));
    // "f22, f33 and f35 ... slow and generally ineffective"; f23, f25 identified
    let rel_err: Vec<f64> = (0..6)
        .map(|i| {
            runs.sp(0, |s| (s.stats[3][i] - truth[i]).abs()).mean / (initial[i] - truth[i]).abs()
        })
        .collect();
    c.push(Check::holds(
        "S14 final |f̂ − f| / |f(∞) − f(1.89)| (seed means): f22, f33, f35 slow, f23, f25 identified",
        "f22, f33, f35 \"slow and generally ineffective\"",
        format!(
            "f22 {:.2}, f33 {:.2}, f35 {:.2}; f23 {:.2}, f25 {:.2}",
            rel_err[0], rel_err[4], rel_err[5], rel_err[1], rel_err[2]
        ),
        rel_err[0] > 0.5
            && rel_err[4] > 0.5
            && rel_err[5] > 0.5
            && rel_err[1] < 0.2
            && rel_err[2] < 0.5,
    ));
    let r23: Vec<f64> = (0..3)
        .map(|ci| runs.sp(ci, |s| s.stats[4][1]).mean)
        .collect();
    c.push(Check::holds(
        "S14 disturbances do not degrade f̂23: seed-mean RMS(118) within 10 % of the undisturbed",
        "\"do not degrade the estimates and sometimes help\"",
        format!(
            "none {:.2}, passing ship {:.2}, white {:.2}",
            r23[0], r23[1], r23[2]
        ),
        r23[1] <= 1.1 * r23[0] && r23[2] <= 1.1 * r23[0],
    ));
}

/// The S14 loop at model level: how far it is from the master, and what the filter's re-design,
/// the report's loop structure and the model test's loop give over the seeds.
struct ModelLevel {
    /// Noise-free: max |Δη′| and max |Δf̂| between the master and the exchange loop.
    d_eta: f64,
    d_est: f64,
    /// Max |η′| in the first cycle and RMS(118) of f̂23: filter kept / re-designed.
    k_eta: Spread,
    r_eta: Spread,
    k_rms: Spread,
    r_rms: Spread,
    /// The model test's loop: max |η′|, RMS(118) of f̂23.
    tl_eta: Spread,
    tl_rms: Spread,
    /// The report's structure: max |η′| and its t′.
    t5_eta: Spread,
    t5_t: Spread,
}

fn model_level(env: &Env, c: &mut Vec<Check>) -> Result<ModelLevel, String> {
    // (a) noise-free: the master equals the exchange loop (the FMUs and the master add nothing)
    let nf = env.run(MVE, &noise_free_sets(), "s14_noise_free.csv")?;
    let lp = s14_loop(None, true, true)?;
    let m_eta = col(&nf, "ship.cross_track")?;
    let m_est: Vec<&[f64]> = NAMES
        .iter()
        .map(|n| col(&nf, &format!("est.{n}_estimate")))
        .collect::<Result<_, _>>()?;
    let (mut d_eta, mut d_est) = (0.0f64, 0.0f64);
    for k in 0..lp.eta.len() {
        d_eta = d_eta.max((m_eta[k] / L - lp.eta[k]).abs());
    }
    for k in 0..lp.estimates.len() {
        for i in 0..6 {
            d_est = d_est.max((m_est[i][k + 1] - lp.estimates[k][i]).abs());
        }
    }
    c.push(Check::abs(
        "S14 noise-free: max |η′_master − η′_model| (exchange replicated at model level)",
        0.0,
        d_eta,
        1e-9,
        "",
    ));
    c.push(Check::abs(
        "S14 noise-free: max |f̂_master − f̂_model| over all estimates",
        0.0,
        d_est,
        1e-9,
        "",
    ));
    // (b) what the filter's re-design does (same noise), and the model test's loop
    let mut kept = Vec::new();
    let mut redesigned = Vec::new();
    let mut test = Vec::new();
    let mut test500 = Vec::new();
    for seed in 1..=SEEDS {
        kept.push(s14_loop(Some(seed), false, true)?);
        redesigned.push(s14_loop(Some(seed), true, true)?);
        test.push(test_loop(seed)?);
        test500.push(s14_loop(Some(seed), true, false)?);
    }
    let m = ModelLevel {
        d_eta,
        d_est,
        k_eta: Spread::over(&kept, |r| r.eta_max),
        r_eta: Spread::over(&redesigned, |r| r.eta_max),
        k_rms: Spread::over(&kept, |r| r.rms[1]),
        r_rms: Spread::over(&redesigned, |r| r.rms[1]),
        tl_eta: Spread::over(&test, |r| r.0),
        tl_rms: Spread::over(&test, |r| r.1),
        t5_eta: Spread::over(&test500, |r| r.eta_max),
        t5_t: Spread::over(&test500, |r| r.t_eta_max),
    };
    c.push(Check::holds(
        "S14 max |η′| in the first cycle, model loop with the report's structure (filter \
         re-designed, no exchange delays), 20 seeds vs [DERIVED] (3 seeds): ranges overlap",
        "0.178-0.205, at t′ ≈ 3.9",
        format!(
            "{} at t′ {}..{}",
            m.t5_eta,
            fmt_num(m.t5_t.min),
            fmt_num(m.t5_t.max)
        ),
        m.t5_eta.max >= 0.178 && m.t5_eta.min <= 0.205,
    ));
    Ok(m)
}

/// [Parsons1980, Figs. 28-31] (seed 1): the cross-track and the estimates of f23, f25, f32.
fn figure(env: &Env, runs: &MveRuns, report: &mut Report) -> Result<(), String> {
    let truth = parameters_of(&TABLE_2[2]);
    let time = runs.seed1[0].time();
    let mut panels = vec![Panel {
        y_label: "η′ = η/L".into(),
        series: MVE_CASES
            .iter()
            .zip(&runs.seed1)
            .map(|(cs, t)| series(t, "ship.cross_track", cs.id, 1.0 / L))
            .collect::<Result<_, _>>()?,
    }];
    for (i, name) in [(1usize, "f23"), (2, "f25"), (3, "f32")] {
        let mut s: Vec<Series> = MVE_CASES
            .iter()
            .zip(&runs.seed1)
            .map(|(cs, t)| series(t, &format!("est.{name}_estimate"), cs.id, 1.0))
            .collect::<Result<_, _>>()?;
        s.push(constant_series(time, truth[i], "true (H/T = 1.89)"));
        panels.push(Panel {
            y_label: format!("{name} estimate"),
            series: s,
        });
    }
    let f = env.figure(
        "s14_mve.png",
        "S14: MVE in the loop, truth H/T = 1.89, initialised for deep water, seed 1 (t' = t/46.98 s)",
        &panels,
    )?;
    report.figures.push((
        "S14 (Figs. 28-31): cross-track and the estimates of f23, f25, f32, seed 1".into(),
        f,
    ));
    Ok(())
}

/// The S14 notes: setup, cases, and what the checks do not say.
fn notes(runs: &MveRuns, first: &FirstCycle, m: &ModelLevel, n: &mut Vec<String>) {
    n.push(format!(
        "S14 setup: systems/{MVE} (TokyoMaru at H/T = 1.89, Euler at Δt′ = 0.005; SteeringGear \
         T_r = 10 s; Sensors with Table 3 noise for the filter and an independent Sensors with \
         Table 9 noise for the estimator; PathKalmanFilter, PathEstimator (MVE) and PathController \
         initialised for H/T = ∞, the filter following the controller's design; dither ±0.5 rad, period 0.5 L, in the first 2.5 L of every \
         6.25 L; Table 10 rule at the end of each window). {SEEDS} seeds per case (sensors.seed = \
         N, est_sensors.seed = 1000 + N, current.seed = 2000 + N); 10 L per run."
    ));
    for case in &MVE_CASES {
        n.push(format!(
            "S14 {}: {}: systems/{MVE} with {}.",
            case.id,
            case.what,
            overrides_text(case.sets)
        ));
    }
    n.push(format!(
        "S14 max |η′| (Fig. 28): the OCR prints \"0.01738\", read as 0.1738 (≈ one beam, spec §6 \
         item 39). Ours: {} at t′ {}..{} (first cycle, t′ ≤ 6.25; later the offset at the end of \
         the second window can be larger in some seeds). The peak is sensitive to the length of \
         the dither window: one step more (a 501-step window, which t′ accumulated in floating \
         point gives when the window ends exactly on the grid) raises it by about 2 %; see the \
         system file on dither_start. The control-loop noise of the report's adaptive runs is not \
         stated (Table 3 assumed).",
        first.eta,
        fmt_num(first.t_eta.min),
        fmt_num(first.t_eta.max)
    ));
    n.push(format!(
        "S14 estimates: ℓ = 10 gives 199 estimates in 10 L from the first sample at t′ = 0 (the \
         report counts 200). Table 16 statistics over these; RMS(118) = √Σ (no 1/N). Fig. 29 \
         (passing-ship run): the seed-mean f̂23 comes within ±10 % of the truth at t′ = {}; in \
         single seeds f̂23 first comes within ±10 % at t′ = {} (median; {}..{}) and stays there, \
         to the end of the first cycle, from t′ = {} (median; {}..{}; 6.25: not within the first \
         cycle).",
        fmt_num(first.t_mean_near),
        fmt_num(first.near.median),
        fmt_num(first.near.min),
        fmt_num(first.near.max),
        fmt_num(first.settle.median),
        fmt_num(first.settle.min),
        fmt_num(first.settle.max)
    ));
    let r25: Vec<Spread> = (0..3).map(|ci| runs.sp(ci, |s| s.stats[4][2])).collect();
    n.push(format!(
        "S14 RMS(118) of f̂25: the printed 0.43412 / 0.43989 / 0.47312 (no disturbance / passing \
         ship / white noise) lie at or below the low end of the {SEEDS} seeds ({} / {} / {}; \
         medians {} / {} / {}), as they lie below the spec's independent implementation \
         (0.57-1.18, 3 seeds): the report's f̂25 settles faster (Fig. 30: \"≈1 L\") than ours \
         in most seeds; a reading of the MVE (§2.13) that differs from the report's program \
         cannot be excluded. The printed minimum, mean, maximum and final f̂25 are within the \
         seeds' ranges.",
        r25[0],
        r25[1],
        r25[2],
        fmt_num(r25[0].median),
        fmt_num(r25[1].median),
        fmt_num(r25[2].median),
    ));
    n.push(format!(
        "S14 model level: the loop of systems/{MVE} re-built from the models with the master's \
         exchange (run_loop in this study) equals the noise-free master run to {} in η′ and \
         {} in the estimates. The PathKalmanFilter follows the controller's design \
         (follow_design_inputs), as the gain calculation of Fig. 1 updates C, K and the filter \
         model together; with the same noise ({SEEDS} seeds, one stream) the model loop gives max \
         |η′| {} with the filter re-designed and {} with the filter kept at its deep-water model; \
         RMS(118) of f̂23 {} and {}. In the report's own structure (plant, filter and gear in one \
         loop without exchange delays, 500-step windows) the peak is {}. The S14 test of \
         models/src/controllers/mve.rs (the report's structure, but its windows end one step late, \
         see the max |η′| note) gives {} and RMS f̂23 {}; the master: {} and {}.",
        fmt_num(m.d_eta),
        fmt_num(m.d_est),
        m.r_eta,
        m.k_eta,
        m.r_rms,
        m.k_rms,
        m.t5_eta,
        m.tl_eta,
        m.tl_rms,
        first.eta,
        runs.sp(0, |s| s.stats[4][1]),
    ));
    n.push(
        "S14 estimator data: the rudder angle (\"known exactly\") reaches the PathEstimator \
         through a zero-noise channel of the estimator's Sensors instance, so that under the \
         Jacobi master it arrives on the same exchange as the sampled states it belongs to \
         (eq. 84 regresses z′_k on z′_(k−1) and δ′_(k−1))."
            .into(),
    );
}
