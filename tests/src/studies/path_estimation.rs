//! Parameter estimation in the adaptive path-control loop of the *Tokyo Maru* (Parsons & Cuong
//! 1980, seed 004; spec `adaptive_path_control.md` §4.3-§4.4): the estimators of §2.12 (WLS,
//! PathWlsEstimator) and §2.13 (MVE, PathEstimator) as FMUs feeding the PathController's partial
//! adaptation, the PathKalmanFilter following the controller's design, through the master.
//!
//! * S14 (Table 16, Figs. 28-31): MVE in the loop, truth at H/T = 1.89, everything initialised
//!   for deep water, three disturbance cases.
//! * S11 (Tables 12-13, Fig. 26): WLS in the loop, truth in deep water under a constant
//!   disturbance from the steady state of line 1145, three updates; and the 5.0-L windows of
//!   Table 12 (first update).
//! * S13 (Table 15): WLS with a ship passing during the second window.
//!
//! The report shows one realisation of unknown seed, so a printed number must lie within the
//! min..max of 40 noise seeds (`SEEDS`), widened by half a unit of its last digit; where a
//! printed value lies outside in every seed the check states its own tolerance and a note says
//! why. The [DERIVED] values of §4.4 (an independent implementation, 3 seeds) are compared by
//! range.
//! Model-level loops built from the same models replicate the master's exchange (noise-free:
//! equal to the master) and run the report's own loop structure, to separate co-simulation
//! effects from the reproduction. Not reproducible (notes): S9, S10 (the stepped bottom of
//! Fig. 25 is not given), S12 (the depth-to-coefficient rule behind Table 14 is unknown).

use super::path_common::{run_until, DT};
use crate::study::{
    col, constant_series, fmt_num, max_abs, overrides_text, series, Check, Env, Report, Spread,
};
use models::controllers::mve::{parameters_of, Mve, MveParams, SIGMA_TABLE_9};
use models::controllers::path::{
    Adaptation, Dither, PathController, PathControllerParams, PathInputs, UpdateDecision,
};
use models::controllers::wls::{WlsEstimator, WlsSchedule, WlsSettings};
use models::hull::tokyo_maru::{L, TABLE_2, T_R, U};
use models::hull::DEG;
use models::observers::path_kalman::PathKalmanFilter;
use models::observers::path_model::PathDesignModel;
use models::random::NoiseStream;
use shipsim::plot::{Panel, Series, Table};

const SEEDS: u64 = 40;
const MVE: &str = "path_control_mve.toml";
/// The S14 dither start (half a step early, see the system file).
const DITHER_START: f64 = -0.0025;
/// End of the first MVE cycle (dither in the first 2.5 L of every 6.25 L).
const CYCLE: f64 = 6.25;
const NAMES: [&str; 6] = ["f22", "f23", "f25", "f32", "f33", "f35"];

/// The printed values lie within the seeds' min..max, each widened by half a unit of its last
/// printed digit.
fn within_seeds(quantity: &str, printed: &[&str], spreads: &[Spread], unit: &str) -> Check {
    let mut pass = true;
    let mut ours = Vec::new();
    for (p, s) in printed.iter().zip(spreads) {
        pass &= s.covers(p);
        ours.push(format!("{} .. {}", fmt_num(s.min), fmt_num(s.max)));
    }
    Check {
        quantity: quantity.to_string(),
        published: format!("{} {unit}", printed.join(" / ")).trim().to_string(),
        ours: format!("{} {unit}", ours.join(" / ")).trim().to_string(),
        tolerance: format!(
            "printed within the {} seeds' range ±½ digit",
            spreads.iter().map(|s| s.n).min().unwrap_or(0)
        ),
        pass,
    }
}

// ------------------------------------------------------------------------------------------
// S14: MVE in the loop
// ------------------------------------------------------------------------------------------

/// One S14 disturbance case (Table 16 rows): caption, overrides, printed min/mean/max/final/RMS
/// (rows) of f22..f35 (columns).
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
            // f35: printed "−0.07987" (a negative RMS, spec §6 item 25): read as 0.07987
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

/// Table 16 statistics of a sequence of estimates against the truth `p`.
fn table_16_stats(est: &[[f64; 6]], fin: [f64; 6], p: [f64; 6]) -> [[f64; 6]; 5] {
    let n = est.len() as f64;
    let mut s = [[0.0; 6]; 5];
    for i in 0..6 {
        let v = est.iter().map(|e| e[i]);
        s[0][i] = v.clone().fold(f64::INFINITY, f64::min);
        s[1][i] = v.clone().sum::<f64>() / n;
        s[2][i] = v.clone().fold(f64::NEG_INFINITY, f64::max);
        s[3][i] = fin[i];
        // eq. 118: √Σ without 1/N
        s[4][i] = v.map(|x| (x - p[i]).powi(2)).sum::<f64>().sqrt();
    }
    s
}

fn mve_stats(t: &Table) -> Result<MveStats, String> {
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

fn seed_sets(case: &MveCase, seed: u64) -> Vec<String> {
    let mut v: Vec<String> = case.sets.iter().map(|s| s.to_string()).collect();
    v.push(format!("sensors.seed={seed}"));
    v.push(format!("est_sensors.seed={}", 1000 + seed));
    v.push(format!("current.seed={}", 2000 + seed));
    v
}

/// Result of a model-level loop: η′ at every exchange (absolute), the estimates after every
/// step, max |η′| in the first cycle (S14) and its t′, RMS(118) of the six estimates (S14), and
/// the estimator's fits (WLS: the step, the 8 parameters and the Table 10 code).
struct LoopRun {
    eta: Vec<f64>,
    estimates: Vec<[f64; 6]>,
    eta_max: f64,
    t_eta_max: f64,
    rms: [f64; 6],
    fits: Vec<(usize, [f64; 8], f64)>,
}

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

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// Per-sample noise σ′ of ψ′, r′, η′: Table 3 (the S14 control loop).
const SIGMA_TABLE_3: [f64; 3] = [1.611e-3, 7.563e-3, 9.549e-3];

/// The estimator of a model-level loop.
#[derive(Clone)]
enum LoopEstimator {
    Mve(Mve),
    Wls(WlsEstimator),
}

/// One model-level adaptive loop: plant (Euler at Δt′), steering gear, path Kalman filter,
/// estimator and path controller built from the models.
struct LoopSpec {
    /// Truth: depth ratio (∞ allowed), constant N′, Y′, initial state [ψ′, r′, β′, η′, δ′].
    depth_ratio: f64,
    forces: [f64; 2],
    x0: [f64; 5],
    /// Filter start x̂′ (7) and the controller.
    xhat0: [f64; 7],
    controller: PathControllerParams,
    estimator: LoopEstimator,
    steps: usize,
    /// Noise: a seed for one stream (None: noise-free); σ′ of the filter's ψ′, r′, η′; σ′ of the
    /// estimator's ψ′, r′, β′, η′; `shared`: the estimator's ψ′, r′, η′ are the filter's
    /// measurements (one set of instruments).
    noise: Option<u64>,
    sigma_filter: [f64; 3],
    sigma_estimator: [f64; 4],
    shared: bool,
    /// The filter re-designed with the controller's coefficients at each gain update.
    kf_update: bool,
    /// Replicate the master's Jacobi exchange (systems/path_control_*.toml): the master's step
    /// (whole ns; Δt′ = hU/L), the SteeringGear integrated exactly, Sensors outputs one exchange
    /// old (the first two exchanges both carry the initial state), the controller's output
    /// evaluated after its step from the previous exchange's inputs, the rudder reaching the
    /// estimator with the states it belongs to, the filter re-designed one step after the
    /// controller. Otherwise the report's loop (spec Appendix A): everything at Δt′ = 0.005 in
    /// one loop, plant and gear by Euler, no delays.
    exchange: bool,
}

fn run_loop(spec: LoopSpec) -> Result<LoopRun, String> {
    use models::hull::tokyo_maru::{TokyoMaru, TokyoMaruInputs, TokyoMaruIntegration};
    let params = spec.controller;
    let design = |c| PathDesignModel {
        coefficients: c,
        ..params.design
    };
    let mut ship = TokyoMaru::new(spec.depth_ratio).map_err(err)?;
    ship.integration = TokyoMaruIntegration::Euler {
        max_substep_prime: DT,
    };
    ship.set_state_prime(spec.x0);
    let mut delta = spec.x0[4];
    let (fs, gs, gam) = ship.coefficients().eq11(T_R);
    let mut x = spec.x0;
    let mut kf =
        PathKalmanFilter::new(design(params.initial_coefficients()), spec.xhat0).map_err(err)?;
    kf.dt_prime = DT;
    let mut est = spec.estimator.clone();
    let mut ctl = PathController::new(params).map_err(err)?;
    let mut rng = spec.noise.map(|s| NoiseStream::new(s, 0));
    let mut draw = |sigma: f64| rng.as_mut().map_or(0.0, |r| sigma * r.normal());
    let truth = parameters_of(&ship.coefficients());
    let state = |ship: &TokyoMaru| {
        let o = ship.outputs();
        [
            o.heading,
            o.yaw_rate_prime,
            o.drift_angle,
            o.cross_track_prime,
        ]
    };
    let mut run = LoopRun {
        eta: Vec::new(),
        estimates: Vec::new(),
        eta_max: 0.0,
        t_eta_max: 0.0,
        rms: [0.0; 6],
        fits: Vec::new(),
    };
    let h_ns: i64 = 234_881_209;
    let t_at = |k: usize| {
        if spec.exchange {
            (k as i64 * h_ns) as f64 / 1e9
        } else {
            k as f64 * DT * L / U
        }
    };
    let mut held = if spec.exchange {
        state(&ship)
    } else {
        [x[0], x[1], x[2], x[3]]
    };
    let mut held_rudder = delta;
    let mut inputs_prev: Option<PathInputs> = None;
    let mut updates = 0;
    let mut sq = [0.0; 6];
    for k in 0..spec.steps {
        let (t, t1) = (t_at(k), t_at(k + 1));
        let h = t1 - t;
        let hp = h * U / L;
        let xs = if spec.exchange {
            state(&ship)
        } else {
            [x[0], x[1], x[2], x[3]]
        };
        let rudder_now = if spec.exchange { delta } else { x[4] };
        run.eta.push(xs[3]);
        // measurements: one exchange old in the master, current in the report's loop
        let (zs, zr) = if spec.exchange {
            (held, held_rudder)
        } else {
            (xs, rudder_now)
        };
        let z = [
            zs[0] + draw(spec.sigma_filter[0]),
            zs[1] + draw(spec.sigma_filter[1]),
            zs[3] + draw(spec.sigma_filter[2]),
        ];
        let zm: [f64; 4] = if spec.shared {
            [z[0], z[1], zs[2] + draw(spec.sigma_estimator[2]), z[2]]
        } else {
            std::array::from_fn(|i| zs[i] + draw(spec.sigma_estimator[i]))
        };
        let xh = *kf.estimate();
        let p6 = match &est {
            LoopEstimator::Mve(m) => m.estimate(),
            LoopEstimator::Wls(w) => w.f(),
        };
        let inputs = PathInputs {
            heading: xh[0],
            yaw_rate: xh[1] * U / L,
            drift_angle: xh[2],
            cross_track: xh[3] * L,
            rudder: rudder_now,
            yaw_moment_prime: xh[5],
            sway_force_prime: xh[6],
            depth_ratio: 1.89,
            estimates: p6,
        };
        let u = match (&inputs_prev, spec.exchange) {
            (Some(prev), true) => ctl.command(prev),
            _ => {
                if k == 0 {
                    ctl.start(&inputs);
                }
                ctl.command(&inputs)
            }
        };
        // the steps from t_k
        match &mut est {
            LoopEstimator::Mve(m) => {
                if (hp - m.params.dt).abs() > 1e-12 * hp {
                    m.set_dt(hp).map_err(err)?;
                }
                if m.sample(zm, zr) {
                    let p = m.estimate();
                    for i in 0..6 {
                        sq[i] += (p[i] - truth[i]).powi(2);
                    }
                }
            }
            LoopEstimator::Wls(w) => {
                if w.sample(t * U / L, hp, zm, zr, [xh[0], xh[1], xh[2], xh[3]])
                    .map_err(err)?
                {
                    let code = match w.decision() {
                        UpdateDecision::None => 0.0,
                        UpdateDecision::F23F25 => 1.0,
                        UpdateDecision::All => 2.0,
                    };
                    run.fits.push((k, w.estimate(), code));
                }
            }
        }
        if spec.exchange {
            let d_next = u + (delta - u) * (-h / 10.0).exp();
            ship.step(
                &TokyoMaruInputs {
                    rudder: delta,
                    yaw_moment_prime: spec.forces[0],
                    sway_force_prime: spec.forces[1],
                    current_lateral: 0.0,
                },
                h,
            );
            held = xs;
            held_rudder = delta;
            delta = d_next;
        } else {
            let dx: [f64; 5] = std::array::from_fn(|i| {
                (0..5).map(|j| fs[(i, j)] * x[j]).sum::<f64>()
                    + gs[i] * u
                    + gam[(i, 0)] * spec.forces[0]
                    + gam[(i, 1)] * spec.forces[1]
            });
            for i in 0..5 {
                x[i] += dx[i] * DT;
            }
        }
        kf.step_prime(z, u, hp);
        ctl.step(&inputs, h).map_err(err)?;
        if spec.kf_update && ctl.updates() != updates {
            updates = ctl.updates();
            kf.set_design(design(*ctl.coefficients())).map_err(err)?;
        }
        run.estimates.push(match &est {
            LoopEstimator::Mve(m) => m.estimate(),
            LoopEstimator::Wls(w) => w.f(),
        });
        inputs_prev = Some(inputs);
        let tp = (k + 1) as f64 * DT;
        let e = if spec.exchange { state(&ship)[3] } else { x[3] }.abs();
        if tp <= CYCLE + 1e-9 && e > run.eta_max {
            run.eta_max = e;
            run.t_eta_max = tp;
        }
    }
    run.eta
        .push(if spec.exchange { state(&ship)[3] } else { x[3] });
    run.rms = sq.map(f64::sqrt);
    Ok(run)
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

fn s14(env: &Env, report: &mut Report) -> Result<(), String> {
    let truth = parameters_of(&TABLE_2[2]);
    let initial = parameters_of(&TABLE_2[4]);
    let mut all: Vec<Vec<MveStats>> = Vec::new();
    let mut seed1: Vec<Table> = Vec::new();
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
        all.push(v);
    }
    let sp = |c: usize, f: &dyn Fn(&MveStats) -> f64| -> Spread {
        Spread::over(&all[c], f)
    };
    let c = &mut report.checks;

    // ---- structure: ℓ = 10 and the two gain updates (ends of the dither windows)
    let n_est: Vec<usize> = all.iter().flatten().map(|s| s.estimates).collect();
    let n_upd: Vec<f64> = all.iter().flatten().map(|s| s.gain_updates).collect();
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

    // ---- Fig. 28: the offset after the first dither window
    let eta = sp(0, &|s| s.eta_max);
    let t_eta = sp(0, &|s| s.t_eta_max);
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
    // ---- Fig. 29 (the passing-ship run): f̂23 near its true value in about 3 L
    let near = sp(1, &|s| s.f23_near);
    let settle = sp(1, &|s| s.f23_settled);
    // the seed-mean trajectory of f̂23 (the noise averaged out), where it first comes within 10 %
    let n_rows = all[1].iter().map(|s| s.f23.len()).min().unwrap_or(0);
    let mean_f23: Vec<f64> = (0..n_rows)
        .map(|k| all[1].iter().map(|s| s.f23[k]).sum::<f64>() / all[1].len() as f64)
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

    // ---- Table 16, three cases
    for (ci, case) in MVE_CASES.iter().enumerate() {
        for (i, name) in NAMES.iter().enumerate() {
            let printed: Vec<&str> = (0..4).map(|r| case.table_16[r][i]).collect();
            let spreads: Vec<Spread> = (0..4).map(|r| sp(ci, &|s| s.stats[r][i])).collect();
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
                &[sp(ci, &|s| s.stats[4][i])],
                "",
            ));
        }
    }
    let rms25 = sp(0, &|s| s.stats[4][2]);
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
        .map(|i| sp(0, &|s| (s.stats[3][i] - truth[i]).abs()).mean / (initial[i] - truth[i]).abs())
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
    let r23: Vec<f64> = (0..3).map(|ci| sp(ci, &|s| s.stats[4][1]).mean).collect();
    c.push(Check::holds(
        "S14 disturbances do not degrade f̂23: seed-mean RMS(118) within 10 % of the undisturbed",
        "\"do not degrade the estimates and sometimes help\"",
        format!(
            "none {:.2}, passing ship {:.2}, white {:.2}",
            r23[0], r23[1], r23[2]
        ),
        r23[1] <= 1.1 * r23[0] && r23[2] <= 1.1 * r23[0],
    ));

    // ---- the same loop at model level
    // (a) noise-free: the master equals the exchange loop (the FMUs and the master add nothing)
    let nf = env.run(
        MVE,
        &[
            "sensors.noise_scale=0".to_string(),
            "est_sensors.noise_scale=0".to_string(),
        ],
        "s14_noise_free.csv",
    )?;
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
    let lsp = |v: &[LoopRun], f: &dyn Fn(&LoopRun) -> f64| -> Spread {
        Spread::over(&v, f)
    };
    let (k_eta, r_eta) = (lsp(&kept, &|r| r.eta_max), lsp(&redesigned, &|r| r.eta_max));
    let (k_rms, r_rms) = (lsp(&kept, &|r| r.rms[1]), lsp(&redesigned, &|r| r.rms[1]));
    let tl_eta = Spread::over(&test, |r| r.0);
    let tl_rms = Spread::over(&test, |r| r.1);
    let rms23 = sp(0, &|s| s.stats[4][1]);
    let t5_eta = Spread::over(&test500, |r| r.eta_max);
    let t5_t = Spread::over(&test500, |r| r.t_eta_max);
    c.push(Check::holds(
        "S14 max |η′| in the first cycle, model loop with the report's structure (filter \
         re-designed, no exchange delays), 20 seeds vs [DERIVED] (3 seeds): ranges overlap",
        "0.178-0.205, at t′ ≈ 3.9",
        format!(
            "{} at t′ {}..{}",
            t5_eta,
            fmt_num(t5_t.min),
            fmt_num(t5_t.max)
        ),
        t5_eta.max >= 0.178 && t5_eta.min <= 0.205,
    ));

    // ---- figures (seed 1): Figs. 28-31
    let time = seed1[0].time();
    let mut panels = vec![Panel {
        y_label: "η′ = η/L".into(),
        series: MVE_CASES
            .iter()
            .zip(&seed1)
            .map(|(cs, t)| series(t, "ship.cross_track", cs.id, 1.0 / L))
            .collect::<Result<_, _>>()?,
    }];
    for (i, name) in [(1usize, "f23"), (2, "f25"), (3, "f32")] {
        let mut s: Vec<Series> = MVE_CASES
            .iter()
            .zip(&seed1)
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

    // ---- notes
    let n = &mut report.notes;
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
        eta,
        fmt_num(t_eta.min),
        fmt_num(t_eta.max)
    ));
    n.push(format!(
        "S14 estimates: ℓ = 10 gives 199 estimates in 10 L from the first sample at t′ = 0 (the \
         report counts 200). Table 16 statistics over these; RMS(118) = √Σ (no 1/N). Fig. 29 \
         (passing-ship run): the seed-mean f̂23 comes within ±10 % of the truth at t′ = {}; in \
         single seeds f̂23 first comes within ±10 % at t′ = {} (median; {}..{}) and stays there, \
         to the end of the first cycle, from t′ = {} (median; {}..{}; 6.25: not within the first \
         cycle).",
        fmt_num(t_mean_near),
        fmt_num(near.median),
        fmt_num(near.min),
        fmt_num(near.max),
        fmt_num(settle.median),
        fmt_num(settle.min),
        fmt_num(settle.max)
    ));
    let r25: Vec<Spread> = (0..3).map(|ci| sp(ci, &|s| s.stats[4][2])).collect();
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
        fmt_num(d_eta),
        fmt_num(d_est),
        r_eta,
        k_eta,
        r_rms,
        k_rms,
        t5_eta,
        tl_eta,
        tl_rms,
        eta,
        rms23,
    ));
    n.push(
        "S14 estimator data: the rudder angle (\"known exactly\") reaches the PathEstimator \
         through a zero-noise channel of the estimator's Sensors instance, so that under the \
         Jacobi master it arrives on the same exchange as the sampled states it belongs to \
         (eq. 84 regresses z′_k on z′_(k−1) and δ′_(k−1))."
            .into(),
    );
    Ok(())
}

// ------------------------------------------------------------------------------------------
// S11: WLS in the loop
// ------------------------------------------------------------------------------------------

const WLS: &str = "path_control_wls.toml";
/// The constant disturbance of Tables 12-13 (N′, Y′).
const W_S11: [f64; 2] = [0.0010262, 0.0023277];
/// Per-sample σ′ of ψ′, r′, η′ of Table 9 (the S11 filter's noise, see the system file).
const SIGMA_TABLE_9_FILTER: [f64; 3] = [SIGMA_TABLE_9[0], SIGMA_TABLE_9[1], SIGMA_TABLE_9[3]];

/// Table 13, updates 1, 2, 3 (rows: f22, f23, f25, f32, f33, f35, N′×10², Y′×10²).
const TABLE_13: [[&str; 3]; 8] = [
    ["-2.0037", "-1.9258", "-1.9306"],
    ["3.2540", "3.1177", "3.1414"],
    ["-1.0424", "-1.0414", "-1.0405"],
    ["0.32363", "0.36511", "0.28817"],
    ["-0.65439", "-0.72306", "-0.59633"],
    ["-0.16388", "-0.16289", "-0.16275"],
    ["0.12987", "0.12561", "0.12541"],
    ["0.35415", "0.39149", "0.31570"],
];
const TABLE_13_OFFSET: [&str; 3] = ["0.1745", "0.4779", "0.1257"];
const P_NAMES: [&str; 8] = ["f22", "f23", "f25", "f32", "f33", "f35", "N′", "Y′"];

/// Solves A y = b (Gaussian elimination with partial pivoting; small dense systems).
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Result<Vec<f64>, String> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .ok_or("empty system")?;
        if a[p][c].abs() < 1e-300 {
            return Err("singular equilibrium system".into());
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r][c] / a[c][c];
            for k in c..n {
                a[r][k] -= f * a[c][k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut y = vec![0.0; n];
    for r in (0..n).rev() {
        y[r] = (b[r] - (r + 1..n).map(|k| a[r][k] * y[k]).sum::<f64>()) / a[r][r];
    }
    Ok(y)
}

/// The steady state of line 1145 (spec U9): truth at ∞ under the constant N′, Y′, Table 5 filter
/// and controller (design 1.89, random walk, ε = 0 in the filter). The plant fixes ψ′ = β′, δ′
/// (r′ = 0); the filter's stationarity with u = C x̂′ = δ′ fixes x̂′ and η′. Returns the plant
/// state [ψ′, r′, β′, η′, δ′] and x̂′.
fn line_1145_equilibrium() -> Result<([f64; 5], [f64; 7]), String> {
    use models::controllers::path::path_gains;
    let c = TABLE_2[4];
    let [n, y] = W_S11;
    let beta_delta = solve(
        vec![vec![c.f23, c.f25], vec![c.f33, c.f35]],
        vec![-(c.g21 * n + c.g22 * y), -(c.g31 * n + c.g32 * y)],
    )?;
    let (beta, delta) = (beta_delta[0], beta_delta[1]);
    let d = PathDesignModel::random_walk(1.89);
    let g = path_gains(&d).map_err(err)?;
    let k = d.kalman_gain().map_err(err)?;
    let (fe, ge) = (d.f(false), d.g());
    // unknowns [x̂′ (7), η′]: (F_e + G_e C − K H) x̂′ + K(:, η′) η′ = −K(:, ψ′) ψ′;  C x̂′ = δ′
    let mut a = vec![vec![0.0; 8]; 8];
    let mut b = vec![0.0; 8];
    for i in 0..7 {
        for j in 0..7 {
            let kh = match j {
                0 => k[(i, 0)],
                1 => k[(i, 1)],
                3 => k[(i, 2)],
                _ => 0.0,
            };
            a[i][j] = fe[(i, j)] + ge[i] * g.c[j] - kh;
        }
        a[i][7] = k[(i, 2)];
        b[i] = -k[(i, 0)] * beta;
    }
    for j in 0..7 {
        a[7][j] = g.c[j];
    }
    b[7] = delta;
    let v = solve(a, b)?;
    let xhat: [f64; 7] = std::array::from_fn(|i| v[i]);
    Ok(([beta, 0.0, beta, v[7], delta], xhat))
}

/// S11 at model level (see [`LoopSpec`]).
fn s11_loop(noise: Option<u64>, exchange: bool) -> Result<LoopRun, String> {
    let (x0, xhat0) = line_1145_equilibrium()?;
    let c = TABLE_2[2];
    let controller = PathControllerParams {
        design_depth_ratio: 1.89,
        adaptation: Adaptation::Estimated,
        dither: Dither {
            enabled: true,
            amplitude: 0.5,
            period: 0.5,
            window: 2.5,
            cycle: 6.0,
            start: 3.4475,
        },
        ..Default::default()
    };
    let wls = WlsEstimator::new(
        WlsSettings {
            max_evaluations: 5000,
            ..WlsSettings::default()
        },
        WlsSchedule {
            window_start: 3.445,
            window_length: 2.5,
            update_cycle: 6.0,
        },
        [c.f22, c.f23, c.f25, c.f32, c.f33, c.f35, 0.0, 0.0],
    )
    .map_err(err)?;
    run_loop(LoopSpec {
        depth_ratio: f64::INFINITY,
        forces: W_S11,
        x0,
        xhat0,
        controller,
        estimator: LoopEstimator::Wls(wls),
        steps: 3600,
        noise,
        sigma_filter: SIGMA_TABLE_9_FILTER,
        sigma_estimator: SIGMA_TABLE_9,
        shared: true,
        kf_update: true,
        exchange,
    })
}

/// The fits and cycle offsets of one S11 run.
#[derive(Clone, Debug, Default)]
struct WlsStats {
    /// Per fit: p̂ (N′, Y′ ×10²), evaluations, Σ|e|² ×10², Table 10 code, row.
    fits: Vec<([f64; 8], f64, f64, f64, usize)>,
    /// Max |η′| and η′ at the end of each cycle of `lu`.
    max_offset: Vec<f64>,
    end_offset: Vec<f64>,
    /// Max |δ_c|.
    max_command: f64,
}

fn wls_stats(t: &Table, eta_offset: f64, lu: f64) -> Result<WlsStats, String> {
    let tp = col(t, "ship.time_prime")?;
    let eta = col(t, "ship.cross_track")?;
    let upd = col(t, "est.updates")?;
    let names = [
        "f22_estimate",
        "f23_estimate",
        "f25_estimate",
        "f32_estimate",
        "f33_estimate",
        "f35_estimate",
        "yaw_moment_prime_estimate",
        "sway_force_prime_estimate",
    ];
    let p: Vec<&[f64]> = names
        .iter()
        .map(|n| col(t, &format!("est.{n}")))
        .collect::<Result<_, _>>()?;
    let (ev, ss, va) = (
        col(t, "est.evaluations")?,
        col(t, "est.residual_sum_of_squares")?,
        col(t, "est.validity")?,
    );
    let mut s = WlsStats {
        max_command: max_abs(col(t, "ctl.rudder_command")?),
        ..Default::default()
    };
    for k in 1..tp.len() {
        if upd[k] > upd[k - 1] {
            let mut v: [f64; 8] = std::array::from_fn(|i| p[i][k]);
            v[6] *= 100.0;
            v[7] *= 100.0;
            s.fits.push((v, ev[k], ss[k] * 100.0, va[k], k));
        }
    }
    let n_cycles = (tp[tp.len() - 1] / lu + 1e-6).floor() as usize;
    for c in 0..n_cycles {
        let (a, b) = (c as f64 * lu - 1e-6, (c + 1) as f64 * lu + 1e-6);
        let mut m = 0.0f64;
        let mut end = 0.0;
        for k in 0..tp.len() {
            if tp[k] >= a && tp[k] <= b {
                let e = (eta[k] + eta_offset) / L;
                if e.abs() > m.abs() {
                    m = e;
                }
                end = e;
            }
        }
        s.max_offset.push(m);
        s.end_offset.push(end);
    }
    Ok(s)
}

fn s11(env: &Env, report: &mut Report) -> Result<(), String> {
    let (x_eq, xhat_eq) = line_1145_equilibrium()?;
    let eta_eq = x_eq[3] * L;
    let c = &mut report.checks;
    // ---- noise-free: the equilibrium holds until the first dither; the first fit is exact
    let nf = env.run(
        WLS,
        &[
            "sensors.noise_scale=0".to_string(),
            "est_sensors.noise_scale=0".to_string(),
        ],
        "s11_noise_free.csv",
    )?;
    let tp = col(&nf, "ship.time_prime")?;
    let eta = col(&nf, "ship.cross_track")?;
    let n_hat = col(&nf, "kf.yaw_moment_prime_estimate")?;
    let y_hat = col(&nf, "kf.sway_force_prime_estimate")?;
    let pre = tp.iter().position(|&t| t >= 3.44).unwrap_or(0);
    let drift = eta[..pre]
        .iter()
        .fold(0.0f64, |m, e| m.max((e + eta_eq - x_eq[3] * L).abs()))
        / L;
    c.push(Check::abs(
        "S11 noise-free: max |η′ − η′_eq| before the first dither (the line-1145 steady state as the \
         system's operating point)",
        0.0,
        drift,
        1e-12,
        "",
    ));
    c.push(Check::abs(
        "S11 steady state N̂′ of the filter (line 1145, U9)",
        0.001992,
        n_hat[pre],
        1e-6,
        "",
    ));
    c.push(Check::abs(
        "S11 steady state Ŷ′ of the filter (line 1145, U9)",
        0.003437,
        y_hat[pre],
        1e-6,
        "",
    ));
    c.push(Check::abs(
        "S11 steady state δ′ (line 1145: 0.1310)",
        0.1310,
        x_eq[4],
        1e-4,
        "rad",
    ));
    let nfs = wls_stats(&nf, eta_eq, 6.0)?;
    let deep = TABLE_2[4];
    let g89 = TABLE_2[2];
    // N̂′, Ŷ′ of a perfect fit: Γ(1.89)⁻¹ Γ(∞) w (the γ̃ are those of 1.89)
    let det = g89.g21 * g89.g32 - g89.g22 * g89.g31;
    let gw = [
        deep.g21 * W_S11[0] + deep.g22 * W_S11[1],
        deep.g31 * W_S11[0] + deep.g32 * W_S11[1],
    ];
    let nw = [
        (g89.g32 * gw[0] - g89.g22 * gw[1]) / det,
        (-g89.g31 * gw[0] + g89.g21 * gw[1]) / det,
    ];
    let f1 = nfs.fits.first().ok_or("S11 noise-free: no fit")?;
    let dp = (0..6).fold(0.0f64, |m, i| {
        m.max((f1.0[i] - parameters_of(&deep)[i]).abs())
    });
    c.push(Check::abs(
        "S11 noise-free update 1: max |f̂ − f(∞)| (the fit recovers the truth)",
        0.0,
        dp,
        1e-6,
        "",
    ));
    c.push(Check::abs(
        "S11 noise-free update 1: N̂′ = [Γ(1.89)⁻¹Γ(∞)w]₁ ×10²",
        nw[0] * 100.0,
        f1.0[6],
        1e-6,
        "",
    ));
    c.push(Check::abs(
        "S11 noise-free update 1: Ŷ′ = [Γ(1.89)⁻¹Γ(∞)w]₂ ×10²",
        nw[1] * 100.0,
        f1.0[7],
        1e-6,
        "",
    ));
    // the master equals the model-level loop with its exchange
    let lp = s11_loop(None, true)?;
    let d_eta = (0..lp.eta.len()).fold(0.0f64, |m, k| {
        m.max(((eta[k] + eta_eq) / L - lp.eta[k]).abs())
    });
    c.push(Check::abs(
        "S11 noise-free: max |η′_master − η′_model| (exchange replicated at model level; the master \
         runs in deviations from the operating point, see note)",
        0.0,
        d_eta,
        1e-7,
        "",
    ));
    let d_fit = nfs.fits.iter().zip(&lp.fits).fold(0.0f64, |m, (a, b)| {
        (0..6).fold(m, |m, i| m.max((a.0[i] - b.1[i]).abs()))
    });
    c.push(Check::holds(
        "S11 noise-free: the fits of master and model-level loop",
        "equal",
        format!(
            "{} and {} fits, max |Δf̂| {}",
            nfs.fits.len(),
            lp.fits.len(),
            fmt_num(d_fit)
        ),
        nfs.fits.len() == 3 && lp.fits.len() == 3 && d_fit < 1e-6,
    ));

    // ---- the reference noise, SEEDS seeds
    let mut runs = Vec::new();
    for seed in 1..=SEEDS {
        let t = env.run(WLS, &wls_seed(seed), "s11.csv")?;
        runs.push(wls_stats(&t, eta_eq, 6.0)?);
    }
    wls_table_checks(
        c,
        "S11",
        "Table 13",
        &runs,
        &TABLE_13,
        &[0, 1, 2],
        ("×10²", 1.0),
    )?;
    let accepted: Vec<usize> = (0..3)
        .map(|u| runs.iter().filter(|r| r.fits[u].3 > 0.0).count())
        .collect();
    let all_in: Vec<usize> = (0..3)
        .map(|u| runs.iter().filter(|r| r.fits[u].3 == 2.0).count())
        .collect();
    c.push(Check::holds(
        "S11 every update accepted by the Table 10 rule (f̂23, f̂25 in range), every seed",
        "3 accepted updates",
        format!("accepted {accepted:?} of {SEEDS}; all six in range {all_in:?}"),
        accepted.iter().all(|&a| a == SEEDS as usize),
    ));
    let offs: Vec<Spread> = (0..3)
        .map(|cy| Spread::over(&runs, |r| r.max_offset[cy]))
        .collect();
    for (cy, printed) in TABLE_13_OFFSET.iter().enumerate() {
        let p: f64 = printed.parse().unwrap_or(f64::NAN);
        if cy == 2 {
            c.push(within_seeds(
                "Table 13 maximum offset η′ in cycle 3",
                &[printed],
                &[offs[cy]],
                "",
            ));
        } else {
            c.push(Check::rel(
                &format!(
                    "Table 13 maximum offset η′ in cycle {} (seed mean; the update instant within \
                     LB, see note)",
                    cy + 1
                ),
                p,
                offs[cy].mean,
                0.04,
                "",
            ));
        }
    }
    let max_cmd = runs.iter().fold(0.0f64, |m, r| m.max(r.max_command));
    c.push(Check::holds(
        "S11 rudder command within the gear's limit (the report's loop is linear)",
        "no limit in the report",
        format!(
            "max |δ_c| {} rad over the seeds (limit π)",
            fmt_num(max_cmd)
        ),
        max_cmd < std::f64::consts::PI,
    ));
    // the cost scale: ratios of the final costs between the updates (the printed J's
    // normalisation is unknown, spec §6 item 13)
    let ratio = |u: usize| Spread::over(&runs, |r| r.fits[u].2 / r.fits[0].2);
    c.push(within_seeds(
        "Table 13 final cost of updates 2 / 3 relative to update 1 (0.1012/0.1059, 0.1035/0.1059)",
        &["0.956", "0.977"],
        &[ratio(1), ratio(2)],
        "",
    ));
    let costs: Vec<Spread> = (0..3)
        .map(|u| Spread::over(&runs, |r| r.fits[u].2))
        .collect();
    let evals: Vec<Spread> = (0..3)
        .map(|u| Spread::over(&runs, |r| r.fits[u].1))
        .collect();

    // ---- Table 12: 5.0-L windows (first update only)
    let mut t12 = Vec::new();
    for (col_i, period) in [(1usize, "0.5"), (2, "2.5")] {
        let mut v = Vec::new();
        for seed in 1..=SEEDS {
            let mut sets = wls_seed(seed);
            sets.extend(
                [
                    "ctl.dither_window=5.0",
                    "ctl.dither_start=0.9475",
                    "est.window_start=0.945",
                    "est.window_length=5.0",
                ]
                .map(String::from),
            );
            sets.push(format!("ctl.dither_period={period}"));
            let t = run_until(env, WLS, &sets, "s11_window_5.csv", 6.0)?;
            v.push(wls_stats(&t, eta_eq, 6.0)?);
        }
        let printed: [[&str; 3]; 8] = std::array::from_fn(|i| [TABLE_12[i][col_i], "", ""]);
        wls_table_checks(
            c,
            &format!("S11 5.0/{period}"),
            &format!("Table 12 window 5.0 / dither {period}"),
            &v,
            &printed,
            &[0],
            ("×10²", 1.0),
        )?;
        let end = Spread::over(&v, |r| r.end_offset[0]);
        c.push(Check::rel(
            &format!(
                "Table 12 window 5.0 / dither {period}: offset η′ at the end of the cycle (seed \
                 mean; see note)"
            ),
            TABLE_12_OFFSET[col_i - 1],
            end.mean,
            0.04,
            "",
        ));
        t12.push((period, end, v));
    }

    // ---- the alternative reading: Table 3 noise in the filter (first update)
    let mut t3 = Vec::new();
    for seed in 1..=SEEDS {
        let mut sets = wls_seed(seed);
        sets.extend(
            [
                "sensors.heading_sigma=0.001611",
                "sensors.yaw_rate_sigma=0.00016099627586206898",
                "sensors.cross_track_sigma=2.76921",
            ]
            .map(String::from),
        );
        let t = run_until(env, WLS, &sets, "s11_table_3.csv", 6.0)?;
        t3.push(wls_stats(&t, eta_eq, 6.0)?);
    }
    let t3_f23 = Spread::over(&t3, |r| r.fits[0].0[1]);
    let t3_f32 = Spread::over(&t3, |r| r.fits[0].0[3]);
    let t3_all = t3.iter().filter(|r| r.fits[0].3 == 2.0).count();
    let t3_rej = t3.iter().filter(|r| r.fits[0].3 == 0.0).count();

    // ---- the report's loop (no exchange delays) with the same settings
    let lr: Vec<LoopRun> = (1..=SEEDS)
        .map(|s| s11_loop(Some(s), false))
        .collect::<Result<_, _>>()?;
    let rep_offs: Vec<Spread> = (0..3)
        .map(|cy| {
            Spread::over(&lr, |r| {
                let b = ((cy + 1) * 1200).min(r.eta.len() - 1);
                max_abs(&r.eta[cy * 1200..=b])
            })
        })
        .collect();

    // ---- figure (seed 1)
    let t1 = env.run(WLS, &wls_seed(1), "s11_seed1.csv")?;
    let time = t1.time();
    // the plant's deviations from the operating point, made absolute
    let absolute = |name: &str, label: &str, scale: f64, off: f64| -> Result<Series, String> {
        Ok(Series {
            label: label.into(),
            t: time.to_vec(),
            y: col(&t1, name)?.iter().map(|v| (v + off) * scale).collect(),
        })
    };
    let deep_p = parameters_of(&TABLE_2[4]);
    let f = env.figure(
        "s11_wls.png",
        "S11: WLS in the loop, truth H/T = inf, constant disturbance, seed 1 (t' = t/46.98 s)",
        &[
            Panel {
                y_label: "η′ = η/L".into(),
                series: vec![absolute("ship.cross_track", "η′", 1.0 / L, eta_eq)?],
            },
            Panel {
                y_label: "rudder δ [deg]".into(),
                series: vec![absolute("gear.rudder_angle", "δ", 1.0 / DEG, x_eq[4])?],
            },
            Panel {
                y_label: "f23".into(),
                series: vec![
                    series(&t1, "est.f23_estimate", "WLS estimate", 1.0)?,
                    series(&t1, "ctl.design_f23", "controller design", 1.0)?,
                    constant_series(time, deep_p[1], "true (H/T = inf)"),
                ],
            },
            Panel {
                y_label: "f32".into(),
                series: vec![
                    series(&t1, "est.f32_estimate", "WLS estimate", 1.0)?,
                    constant_series(time, deep_p[3], "true (H/T = inf)"),
                ],
            },
        ],
    )?;
    report.figures.push((
        "S11 (Fig. 26, Table 13): offset, rudder, f̂23, f̂32, seed 1".into(),
        f,
    ));

    // ---- notes
    let n = &mut report.notes;
    n.push(format!(
        "S11 setup: systems/{WLS}: TokyoMaru in deep water, SteeringGear, Sensors (Table 9, one \
         set of instruments for filter and estimator), PathKalmanFilter and PathController \
         (Table 5 design, random walk, at 1.89; the filter following the controller), \
         PathWlsEstimator (windows of 2.5 L at the end of 6-L cycles, first search from the 1.89 \
         values), 18 L, {SEEDS} seeds (sensors.seed = est_sensors.seed = N). Equilibrium of \
         line 1145 solved from the models: ψ′ = β′ = {:.6}, δ′ = {:.6}, η′ = {:.3e}, N̂′ = \
         {:.6}, Ŷ′ = {:.6}; the system file runs the plant in deviations from it (exact for the \
         linear plant under the constant disturbance), which is why the noise-free master and \
         the model-level loop (absolute values) agree to rounding carried through the fits ({} \
         in η′, {} in the f̂'s) instead of to 1e-15.",
        x_eq[0],
        x_eq[4],
        x_eq[3],
        xhat_eq[5],
        xhat_eq[6],
        fmt_num(d_eta),
        fmt_num(d_fit)
    ));
    n.push(format!(
        "S11 offsets: maximum η′ per cycle over the seeds {} / {} / {} (Table 13: 0.1745 / \
         0.4779 / 0.1257); the report's loop without exchange delays gives {} / {} / {}. The \
         first two lie 1.5-3 % below the printed values in every seed, in both structures; the \
         printed 0.1745 is also the offset at the end of cycle 1 (Table 12), so the ship was \
         still drifting at t′ = 6: here the controller applies the estimates at the end of its \
         dither window (t′ = 5.95) and closes the loop then, where the report updates at t′ = 6 \
         after the batch period LB, whose rudder is not stated. Cycle 3 lies within the seeds.",
        offs[0],
        offs[1],
        offs[2],
        rep_offs[0],
        rep_offs[1],
        rep_offs[2],
    ));
    n.push(format!(
        "S11 cost and evaluations: final Σ|e|² ×10² (W = I, no ½) of updates 1-3: {} / {} / {}, \
         at the level of the Table 9 noise alone (Σσ′² × 499 samples = 0.0795); the printed \
         J×10² = 0.1059 / 0.1012 / 0.1035 (0.2092 / 0.2095 with 5.0-L windows) are about 1.3 \
         times that, with W = R⁻¹ as printed eq. 77 gives about 2e5: the report's normalisation \
         is unknown (spec §6 item 13), so only the ratios between updates are compared. Cost \
         evaluations (Levenberg-Marquardt, 9 per Jacobian): {} / {} / {}; the report's DUD \
         needed 113 / 22 / 19 (warm starts are cheap for DUD, not for a finite-difference \
         Jacobian).",
        costs[0],
        costs[1],
        costs[2],
        evals[0],
        evals[1],
        evals[2],
    ));
    for (period, end, _) in &t12 {
        n.push(format!(
            "S11 with 5.0-L windows, dither period {period} (Table 12; windows from t′ = 0.95, \
             one update at t′ = 6, run to t′ = 6): offset at the end of the cycle {} (the \
             control loop closes at 5.95, see the offsets note).",
            end
        ));
    }
    n.push(format!(
        "S11 noise: the report does not say which noise the control loop had in the WLS runs; \
         one set of instruments with the Table 9 noise is taken. With the Table 3 noise in the \
         filter (the variant in the system file, {SEEDS} seeds) the drift-angle estimate at the \
         window start, the model's initial state, is much poorer, and so is the β equation of the \
         first fit: update 1 gives f̂23 {} and f̂32 {} (Table 13: 3.2540, 0.32363; with the \
         Table 9 noise {} and {}), all six in range in {t3_all} of {SEEDS} seeds (Table 9: all) \
         and rejected in {t3_rej}. Rudder: after the first update the deep-water \
         design's feedforward on the filter's N̂′, Ŷ′ (still the 1.89 equilibrium values) \
         commands up to {} rad (the report's loop is linear; the gear limit is set to its \
         largest value, π).",
        t3_f23,
        t3_f32,
        Spread::over(&runs, |r| r.fits[0].0[1]),
        Spread::over(&runs, |r| r.fits[0].0[3]),
        fmt_num(max_cmd)
    ));
    Ok(())
}

// ------------------------------------------------------------------------------------------
// S13: WLS with a ship passing during the second window
// ------------------------------------------------------------------------------------------

const WLS_PS: &str = "path_control_wls_passing_ship.toml";
/// Table 15, updates 1, 2, 3 (rows: f22, f23, f25, f32, f33, f35, N′×10⁵, Y′×10⁵).
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

fn s13(env: &Env, report: &mut Report) -> Result<(), String> {
    let mut runs = Vec::new();
    for seed in 1..=SEEDS {
        let t = env.run(WLS_PS, &wls_seed(seed), "s13.csv")?;
        runs.push(wls_stats(&t, 0.0, 5.0)?);
    }
    let c = &mut report.checks;
    // updates 1 and 3 (N′, Y′ as printed, ×10⁵ = ×10² · 1000)
    // update 1 over all seeds; update 3 over the seeds in which update 2 was rejected, as in
    // the report (no gain update at t′ = 10); update 2 is not compared (see the note)
    let mut t15 = TABLE_15;
    for row in t15.iter_mut() {
        row[1] = "";
        row[2] = "";
    }
    wls_table_checks(c, "S13", "Table 15", &runs, &t15, &[0], ("×10⁵", 1000.0))?;
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
    let med = |u: usize| Spread::over(&runs, |r| r.fits[u].1).median;
    let (e1, e2, e3) = (med(0), med(1), med(2));
    c.push(Check::holds(
        "S13 update 2 needs the most cost evaluations (seed medians)",
        "65 / 253 / 38",
        format!("{e1} / {e2} / {e3}"),
        e2 > e1 && e2 > e3,
    ));
    let ratio = |u: usize| Spread::over(&runs, |r| r.fits[u].2 / r.fits[0].2);
    c.push(within_seeds(
        "Table 15 final cost of updates 2 / 3 relative to update 1 (0.3642/0.1022, 0.1031/0.1022)",
        &["3.564", "1.009"],
        &[ratio(1), ratio(2)],
        "",
    ));
    // cycle 1 (before the passing ship): the first dither's sign follows the noise-driven rudder
    // before the window, so |η′| is compared
    let c1 = Spread::over(&runs, |r| r.max_offset[0].abs());
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
    let sp2 = |i: usize| Spread::over(&runs, |r| r.fits[1].0[i]);
    let off = |cy: usize, end: bool| {
        Spread::over(&runs, |r| {
            if end {
                r.end_offset[cy]
            } else {
                r.max_offset[cy]
            }
        })
    };
    // figure (seed 1)
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
    let n = &mut report.notes;
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
        let u3 = |i: usize| Spread::over(&rejected, |r| r.fits[2].0[i]);
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
    Ok(())
}

/// Table 12, the columns 2.5/0.5 (= Table 13 update 1), 5.0/0.5, 5.0/2.5 (rows as Table 13).
const TABLE_12: [[&str; 3]; 8] = [
    ["-2.0037", "-1.9722", "-1.9505"],
    ["3.2540", "3.2007", "3.1544"],
    ["-1.0424", "-1.0415", "-1.0406"],
    ["0.32362", "0.33157", "0.31412"],
    ["-0.65439", "-0.66466", "-0.63414"],
    ["-0.16388", "-0.16076", "-0.16169"],
    ["0.12987", "0.12824", "0.12648"],
    ["0.35415", "0.35960", "0.34070"],
];
/// Table 12 offset η′ at the end of the cycle, 5.0/0.5 and 5.0/2.5.
const TABLE_12_OFFSET: [f64; 2] = [1.273, 2.422];

fn wls_seed(seed: u64) -> Vec<String> {
    vec![
        format!("sensors.seed={seed}"),
        format!("est_sensors.seed={seed}"),
    ]
}

/// One check per parameter: the printed values of the updates `updates` (a row of `printed`
/// per parameter, "" = not compared) within the seeds' ranges; N′, Y′ in the printed scale
/// `ny` = (label, factor from ×10²).
fn wls_table_checks(
    c: &mut Vec<Check>,
    id: &str,
    table: &str,
    runs: &[WlsStats],
    printed: &[[&str; 3]; 8],
    updates: &[usize],
    ny: (&str, f64),
) -> Result<(), String> {
    let (ny_label, ny_scale) = ny;
    let n_fits: Vec<usize> = runs.iter().map(|r| r.fits.len()).collect();
    let need = updates.iter().max().map_or(0, |m| m + 1);
    c.push(Check::holds(
        &format!("{id}: fits in every seed (at least one per update compared)"),
        &format!(">= {need} fit(s)"),
        format!(
            "{}..{}",
            n_fits.iter().min().unwrap_or(&0),
            n_fits.iter().max().unwrap_or(&0)
        ),
        n_fits.iter().all(|&n| n >= need),
    ));
    if n_fits.iter().any(|&n| n < need) {
        return Err(format!("{id}: a run without {need} fits"));
    }
    for (i, name) in P_NAMES.iter().enumerate() {
        let (scale, name) = if i >= 6 {
            (ny_scale, format!("{name}{ny_label}"))
        } else {
            (1.0, name.to_string())
        };
        let mut ps = Vec::new();
        let mut ss = Vec::new();
        for &u in updates {
            if printed[i][u].is_empty() {
                continue;
            }
            ps.push(printed[i][u]);
            ss.push(Spread::over(runs, |r| r.fits[u].0[i] * scale));
        }
        let label = if updates.len() > 1 {
            format!(
                "{table} {name}: updates {}",
                updates
                    .iter()
                    .map(|u| (u + 1).to_string())
                    .collect::<Vec<_>>()
                    .join(" / ")
            )
        } else {
            format!("{table} {name}: update {}", updates[0] + 1)
        };
        c.push(within_seeds(&label, &ps, &ss, ""));
    }
    Ok(())
}

pub fn run(env: &Env) -> Result<Report, String> {
    let mut report = Report {
        id: "path_estimation".into(),
        title: "Parameter estimation in the adaptive path control of the Tokyo Maru (S11, S13, \
                S14)"
            .into(),
        source: "Parsons & Cuong (1980) §4-5, Tables 12, 13, 15, 16, Figs. 26, 28-31 (seed 004); \
                 spec adaptive_path_control.md §4.3-4.4 [DERIVED] values"
            .into(),
        systems: vec![MVE.into(), WLS.into(), WLS_PS.into()],
        ..Default::default()
    };
    s14(env, &mut report)?;
    s11(env, &mut report)?;
    s13(env, &mut report)?;
    let n = &mut report.notes;
    n.push(
        "Not run: S9 and S10 (Table 11, stepped bottom): the levels and step times of Fig. 25 \
         are not given, apart from a change at t′ = 3 and deep water in the first cycle (spec \
         §6 item 4). The 5.0-L windows of Table 11 (one 6-L update period) span t′ = 3, so their \
         data depend on the unknown second depth; for the 0.5/0.5 column the update cycle, the \
         window's position in it and the initial state are not stated; S9 gives no numbers \
         (\"accurate to three significant figures in all 12 update periods\"). A stepped bottom \
         is otherwise a set of depth_ratio events on TokyoMaru."
            .into(),
    );
    n.push(
        "Not run: S12 (Table 14, sloping bottom): the \"true\" coefficients of Table 14 are not \
         reproduced by piecewise-linear interpolation of Table 2 in H/T (f23 off by up to 0.096 \
         at H/T ≈ 2.19), nor by splines, polynomial fits or interpolation of the underlying \
         stability derivatives (about 1 %), and f25 moves away from its deep-water value beyond \
         H/T = 2.5 (spec §3 Table 14 notes, §6 items 5 and 20): the plant of the report cannot be \
         built, and the table's point (WLS cannot follow coefficients that vary within the \
         window) would be shown with another truth than the report's."
            .into(),
    );
    n.push(
        "Runtime: the study runs 3 x 40 S14 runs (2000 steps), 40 S11 runs (3600 steps), \
         2 x 40 + 40 short S11 variants (1200 steps), 40 S13 runs (3000 steps) and the model-level \
         loops; a shipsim run of S14 or S11 (fits included) takes 0.05-0.1 s."
            .into(),
    );
    Ok(report)
}
