//! The adaptive loop of the path-estimation scenarios built from the models, without the master:
//! either with the master's exchange replicated (noise-free it equals the master run, which shows
//! that the FMUs and the master add nothing) or in the report's own loop structure (everything
//! at Δt′ in one loop, no exchange delays), to separate co-simulation effects from the
//! reproduction.

use super::{err, CYCLE, DT};
use models::controllers::mve::{parameters_of, Mve};
use models::controllers::path::{PathController, PathControllerParams, PathInputs, UpdateDecision};
use models::controllers::wls::WlsEstimator;
use models::hull::tokyo_maru::{TokyoMaru, TokyoMaruInputs, TokyoMaruIntegration, L, T_R, U};
use models::observers::path_kalman::PathKalmanFilter;
use models::observers::path_model::PathDesignModel;
use models::random::NoiseStream;
use nalgebra::{SMatrix, SVector};

/// The master's step [ns] (Δt′ = hU/L, rounded down to whole ns as in the system files).
const H_NS: i64 = 234_881_209;

/// Result of a model-level loop: η′ at every exchange (absolute), the estimates after every
/// step, max |η′| in the first cycle (S14) and its t′, RMS(118) of the six estimates (S14), and
/// the estimator's fits (WLS: the step, the 8 parameters and the [Parsons1980, Table 10] code).
pub(super) struct LoopRun {
    pub eta: Vec<f64>,
    pub estimates: Vec<[f64; 6]>,
    pub eta_max: f64,
    pub t_eta_max: f64,
    pub rms: [f64; 6],
    pub fits: Vec<(usize, [f64; 8], f64)>,
}

/// The estimator of a model-level loop.
#[derive(Clone)]
pub(super) enum LoopEstimator {
    Mve(Mve),
    Wls(WlsEstimator),
}

impl LoopEstimator {
    /// The six f estimates the controller reads.
    fn f(&self) -> [f64; 6] {
        match self {
            LoopEstimator::Mve(m) => m.estimate(),
            LoopEstimator::Wls(w) => w.f(),
        }
    }
}

/// One model-level adaptive loop: plant (Euler at Δt′), steering gear, path Kalman filter,
/// estimator and path controller built from the models.
pub(super) struct LoopSpec {
    /// Truth: depth ratio (∞ allowed), constant N′, Y′, initial state [ψ′, r′, β′, η′, δ′].
    pub depth_ratio: f64,
    pub forces: [f64; 2],
    pub x0: [f64; 5],
    /// Filter start x̂′ (7) and the controller.
    pub xhat0: [f64; 7],
    pub controller: PathControllerParams,
    pub estimator: LoopEstimator,
    pub steps: usize,
    /// Noise: a seed for one stream (None: noise-free); σ′ of the filter's ψ′, r′, η′; σ′ of the
    /// estimator's ψ′, r′, β′, η′; `shared`: the estimator's ψ′, r′, η′ are the filter's
    /// measurements (one set of instruments).
    pub noise: Option<u64>,
    pub sigma_filter: [f64; 3],
    pub sigma_estimator: [f64; 4],
    pub shared: bool,
    /// The filter re-designed with the controller's coefficients at each gain update.
    pub kf_update: bool,
    /// Replicate the master's Jacobi exchange (systems/path_control_*.toml): the master's step
    /// (whole ns; Δt′ = hU/L), the SteeringGear integrated exactly, Sensors outputs one exchange
    /// old (the first two exchanges both carry the initial state), the controller's output
    /// evaluated after its step from the previous exchange's inputs, the rudder reaching the
    /// estimator with the states it belongs to, the filter re-designed one step after the
    /// controller. Otherwise the report's loop (as re-simulated for the [DERIVED] values):
    /// everything at Δt′ = 0.005 in one loop, plant and gear by Euler, no delays.
    pub exchange: bool,
}

/// Runs the loop for `spec.steps` steps.
pub(super) fn run_loop(spec: LoopSpec) -> Result<LoopRun, String> {
    let mut lp = Loop::new(spec)?;
    for k in 0..lp.spec.steps {
        lp.step(k)?;
    }
    Ok(lp.finish())
}

/// What one step measures: the filter's ψ′, r′, η′, the estimator's ψ′, r′, β′, η′ and the
/// rudder angle that goes with them.
struct Measurements {
    filter: [f64; 3],
    estimator: [f64; 4],
    rudder: f64,
}

/// A model-level loop between two steps.
struct Loop {
    spec: LoopSpec,
    /// The plant of the exchange loop (TokyoMaru's own Euler) and its gear angle.
    ship: TokyoMaru,
    delta: f64,
    /// The plant of the report's loop: state [ψ′, r′, β′, η′, δ′] and the F, g, Γ of
    /// [Parsons1980, eq. (11)].
    x: [f64; 5],
    fs: SMatrix<f64, 5, 5>,
    gs: SMatrix<f64, 5, 1>,
    gam: SMatrix<f64, 5, 2>,
    kf: PathKalmanFilter,
    est: LoopEstimator,
    ctl: PathController,
    rng: Option<NoiseStream>,
    truth: [f64; 6],
    /// The exchange loop's Sensors outputs (one exchange old).
    held: [f64; 4],
    held_rudder: f64,
    /// The controller's inputs of the previous exchange.
    inputs_prev: Option<PathInputs>,
    /// Gain updates of the controller seen so far, Σ(f̂ − f)² per parameter (MVE).
    updates: u32,
    sq: [f64; 6],
    run: LoopRun,
}

impl Loop {
    fn new(spec: LoopSpec) -> Result<Loop, String> {
        let params = spec.controller;
        let mut ship = TokyoMaru::new(spec.depth_ratio).map_err(err)?;
        ship.integration = TokyoMaruIntegration::Euler {
            max_substep_prime: DT,
        };
        ship.set_state_prime(spec.x0);
        let (fs, gs, gam) = ship.coefficients().eq11(T_R);
        let mut kf =
            PathKalmanFilter::new(design(&params, params.initial_coefficients()), spec.xhat0)
                .map_err(err)?;
        kf.dt_prime = DT;
        let x = spec.x0;
        let held = if spec.exchange {
            states(&ship)
        } else {
            [x[0], x[1], x[2], x[3]]
        };
        Ok(Loop {
            delta: spec.x0[4],
            held_rudder: spec.x0[4],
            truth: parameters_of(&ship.coefficients()),
            ship,
            x,
            fs,
            gs,
            gam,
            kf,
            est: spec.estimator.clone(),
            ctl: PathController::new(params).map_err(err)?,
            rng: spec.noise.map(|s| NoiseStream::new(s, 0)),
            held,
            inputs_prev: None,
            updates: 0,
            sq: [0.0; 6],
            run: LoopRun {
                eta: Vec::new(),
                estimates: Vec::new(),
                eta_max: 0.0,
                t_eta_max: 0.0,
                rms: [0.0; 6],
                fits: Vec::new(),
            },
            spec,
        })
    }

    /// Time [s] of step k: the master's whole-ns steps, or k Δt′ L/U.
    fn time(&self, k: usize) -> f64 {
        if self.spec.exchange {
            (k as i64 * H_NS) as f64 / 1e9
        } else {
            k as f64 * DT * L / U
        }
    }

    /// ψ′, r′, β′, η′ of the plant now.
    fn states(&self) -> [f64; 4] {
        if self.spec.exchange {
            states(&self.ship)
        } else {
            [self.x[0], self.x[1], self.x[2], self.x[3]]
        }
    }

    /// One step from t_k: measure, command, estimate, advance the plant, the filter and the
    /// controller, record.
    fn step(&mut self, k: usize) -> Result<(), String> {
        let (t, t1) = (self.time(k), self.time(k + 1));
        let h = t1 - t;
        let hp = h * U / L;
        let xs = self.states();
        let rudder_now = if self.spec.exchange {
            self.delta
        } else {
            self.x[4]
        };
        self.run.eta.push(xs[3]);
        let z = self.measure(xs, rudder_now);
        let xh = *self.kf.estimate();
        let inputs = PathInputs {
            heading: xh[0],
            yaw_rate: xh[1] * U / L,
            drift_angle: xh[2],
            cross_track: xh[3] * L,
            rudder: rudder_now,
            yaw_moment_prime: xh[5],
            sway_force_prime: xh[6],
            depth_ratio: 1.89,
            estimates: self.est.f(),
        };
        let u = self.command(k, &inputs);
        self.estimate(k, t, hp, &z, xh)?;
        self.advance_plant(u, h, xs);
        self.kf.step_prime(z.filter, u, hp);
        self.ctl.step(&inputs, h).map_err(err)?;
        if self.spec.kf_update && self.ctl.updates() != self.updates {
            self.updates = self.ctl.updates();
            let params = self.spec.controller;
            self.kf
                .set_design(design(&params, *self.ctl.coefficients()))
                .map_err(err)?;
        }
        self.run.estimates.push(self.est.f());
        self.inputs_prev = Some(inputs);
        self.record_first_cycle_peak(k);
        Ok(())
    }

    /// The measurements of step k: one exchange old in the master, current in the report's loop.
    fn measure(&mut self, xs: [f64; 4], rudder_now: f64) -> Measurements {
        let (zs, zr) = if self.spec.exchange {
            (self.held, self.held_rudder)
        } else {
            (xs, rudder_now)
        };
        let (sf, se) = (self.spec.sigma_filter, self.spec.sigma_estimator);
        let z = [
            zs[0] + self.draw(sf[0]),
            zs[1] + self.draw(sf[1]),
            zs[3] + self.draw(sf[2]),
        ];
        let zm: [f64; 4] = if self.spec.shared {
            [z[0], z[1], zs[2] + self.draw(se[2]), z[2]]
        } else {
            std::array::from_fn(|i| zs[i] + self.draw(se[i]))
        };
        Measurements {
            filter: z,
            estimator: zm,
            rudder: zr,
        }
    }

    /// A noise sample of σ (0 in a noise-free loop).
    fn draw(&mut self, sigma: f64) -> f64 {
        self.rng.as_mut().map_or(0.0, |r| sigma * r.normal())
    }

    /// The rudder command: in the master from the previous exchange's inputs (the controller's
    /// output is evaluated after its step), in the report's loop from this step's.
    fn command(&mut self, k: usize, inputs: &PathInputs) -> f64 {
        match (&self.inputs_prev, self.spec.exchange) {
            (Some(prev), true) => self.ctl.command(prev),
            _ => {
                if k == 0 {
                    self.ctl.start(inputs);
                }
                self.ctl.command(inputs)
            }
        }
    }

    /// The estimator's step from t_k (MVE: Σ(f̂ − f)² at each estimate; WLS: the fits).
    fn estimate(
        &mut self,
        k: usize,
        t: f64,
        hp: f64,
        z: &Measurements,
        xh: SVector<f64, 7>,
    ) -> Result<(), String> {
        match &mut self.est {
            LoopEstimator::Mve(m) => {
                if (hp - m.params.dt).abs() > 1e-12 * hp {
                    m.set_dt(hp).map_err(err)?;
                }
                if m.sample(z.estimator, z.rudder) {
                    let p = m.estimate();
                    for i in 0..6 {
                        self.sq[i] += (p[i] - self.truth[i]).powi(2);
                    }
                }
            }
            LoopEstimator::Wls(w) => {
                if w.sample(
                    t * U / L,
                    hp,
                    z.estimator,
                    z.rudder,
                    [xh[0], xh[1], xh[2], xh[3]],
                )
                .map_err(err)?
                {
                    let code = match w.decision() {
                        UpdateDecision::None => 0.0,
                        UpdateDecision::F23F25 => 1.0,
                        UpdateDecision::All => 2.0,
                    };
                    self.run.fits.push((k, w.estimate(), code));
                }
            }
        }
        Ok(())
    }

    /// Plant and gear over one step: TokyoMaru and the exact first-order gear (exchange), or
    /// [Parsons1980, eq. (11)] with the gear by Euler at Δt′ (the report's loop).
    fn advance_plant(&mut self, u: f64, h: f64, xs: [f64; 4]) {
        let forces = self.spec.forces;
        if self.spec.exchange {
            let d_next = u + (self.delta - u) * (-h / 10.0).exp();
            self.ship.step(
                &TokyoMaruInputs {
                    rudder: self.delta,
                    yaw_moment_prime: forces[0],
                    sway_force_prime: forces[1],
                    current_lateral: 0.0,
                },
                h,
            );
            self.held = xs;
            self.held_rudder = self.delta;
            self.delta = d_next;
        } else {
            let (fs, gs, gam, x) = (&self.fs, &self.gs, &self.gam, &self.x);
            let dx: [f64; 5] = std::array::from_fn(|i| {
                (0..5).map(|j| fs[(i, j)] * x[j]).sum::<f64>()
                    + gs[i] * u
                    + gam[(i, 0)] * forces[0]
                    + gam[(i, 1)] * forces[1]
            });
            for i in 0..5 {
                self.x[i] += dx[i] * DT;
            }
        }
    }

    /// Max |η′| in the first cycle and its t′ (after step k).
    fn record_first_cycle_peak(&mut self, k: usize) {
        let tp = (k + 1) as f64 * DT;
        let e = self.states()[3].abs();
        if tp <= CYCLE + 1e-9 && e > self.run.eta_max {
            self.run.eta_max = e;
            self.run.t_eta_max = tp;
        }
    }

    fn finish(mut self) -> LoopRun {
        let eta = self.states()[3];
        self.run.eta.push(eta);
        self.run.rms = self.sq.map(f64::sqrt);
        self.run
    }
}

/// ψ′, r′, β′, η′ of the TokyoMaru model.
fn states(ship: &TokyoMaru) -> [f64; 4] {
    let o = ship.outputs();
    [
        o.heading,
        o.yaw_rate_prime,
        o.drift_angle,
        o.cross_track_prime,
    ]
}

/// The controller's design model with the coefficients `c`.
fn design(
    params: &PathControllerParams,
    c: models::hull::tokyo_maru::TokyoMaruCoefficients,
) -> PathDesignModel {
    PathDesignModel {
        coefficients: c,
        ..params.design
    }
}
