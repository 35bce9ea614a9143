//! Weighted Least-Squares (WLS) batch parameter estimator of [Parsons1980, sec. 4]:
//! p = [f22, f23, f25, f32, f33, f35, N′, Y′] fitted over a data window of measured
//! states z′ = [ψ′, r′, β′, η′] with the rudder δ′ known, for the path controller's adaptation.
//!
//! # Source
//! [Parsons1980, sec. 4.1]: model [Parsons1980, eq. (75)] (4 states, γ̃ at H/T = 1.89, p7, p8
//! constant over the window), Euler at Δt′, initial state = the Kalman estimate at the window
//! start, cost [Parsons1980, eq. (77)] J = ½ Σ (z′_k − x_m,k)ᵀ W (z′_k − x_m,k) with W = R⁻¹ [Parsons1980, Table 9].
//!
//! # Reading taken
//! The report minimises with DUD (Ralston & Jennrich 1978) with Cuong's unspecified stopping
//! rules; any minimiser of the same cost gives the same estimates (the evaluation counts differ). This
//! is Levenberg–Marquardt with a forward-difference Jacobian (one model run per parameter), so
//! the evaluation counts of [Parsons1980, Tables 11–15] are not comparable; the minimiser's result is.
//! Design-time computation (allocates; runs once per batch period).
//!
//! # In the loop
//! [`WlsEstimator`] is the estimator of [Parsons1980, Fig. 24] as the PathWlsEstimator FMU runs it: data windows
//! of length LW repeating every LU (from `window_start`), one sample per step, the fit when a
//! window is complete, warm-started from the last valid estimate [Parsons1980, sec. 4.2.1], the [Parsons1980, Table 10]
//! validity of the result. The per-step sample path does not allocate (the window buffers are
//! sized once, at the first sample); the fit, once per window, does.

use super::path::{validity, UpdateDecision, TABLE_10};
use super::ControlError;
use crate::error::{check_finite, check_positive};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Most samples one data window may hold (one per communication step): far above what a window
/// of the systems needs (2.5 ship lengths at Δt′ = 0.005 in `systems/path_control_wls.toml`: 502),
/// it bounds a window's buffers to 40 MB (issue 19).
pub const MAX_WINDOW_SAMPLES: usize = 1_000_000;

/// A data window: measured states z′_k (k = 0 … n−1, z′_0 at the window start) and rudder δ′_k.
#[derive(Clone, Debug, PartialEq)]
pub struct Window {
    pub z: Vec<[f64; 4]>,
    pub rudder: Vec<f64>,
    /// Model initial state x_m,0 (the Kalman estimate at the window start).
    pub x0: [f64; 4],
}

/// Settings of one WLS fit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WlsSettings {
    /// Euler step Δt′ (0.005).
    pub dt: f64,
    /// γ̃21, γ̃22, γ̃31, γ̃32 (H/T = 1.89).
    pub gamma: [f64; 4],
    /// Diagonal weight W = R⁻¹ ([Parsons1980, Table 9] r_jj: 1.2976e-9, 7.7215e-10, 8.2777e-10, 5.0651e-9).
    pub weight: [f64; 4],
    /// Largest number of cost evaluations (the report suggests such a guard, [Parsons1980, sec. 4.3.2]).
    pub max_evaluations: usize,
}

impl Default for WlsSettings {
    fn default() -> Self {
        let g = crate::hull::tokyo_maru::TokyoMaruCoefficients::at_depth_ratio(1.89);
        WlsSettings {
            dt: 0.005,
            gamma: [g.g21, g.g22, g.g31, g.g32],
            weight: [
                1.0 / 1.2976e-9,
                1.0 / 7.7215e-10,
                1.0 / 8.2777e-10,
                1.0 / 5.0651e-9,
            ],
            max_evaluations: 2000,
        }
    }
}

/// Result of a fit.
#[derive(Clone, Debug, PartialEq)]
pub struct WlsFit {
    pub p: [f64; 8],
    pub cost: f64,
    pub evaluations: usize,
}

/// Weighted residuals √W (z′_k − x_m,k) of [Parsons1980, eq. (75)] simulated with `p` (k = 1 … n−1).
fn residuals(p: &[f64; 8], w: &Window, s: &WlsSettings) -> DVector<f64> {
    let n = w.z.len();
    let sw: [f64; 4] = s.weight.map(f64::sqrt);
    let mut r = DVector::zeros(4 * n.saturating_sub(1));
    let mut x = w.x0;
    let [g21, g22, g31, g32] = s.gamma;
    for k in 0..n.saturating_sub(1) {
        let d = w.rudder[k];
        let dx = [
            x[1],
            p[0] * x[1] + p[1] * x[2] + p[2] * d + g21 * p[6] + g22 * p[7],
            p[3] * x[1] + p[4] * x[2] + p[5] * d + g31 * p[6] + g32 * p[7],
            x[0] - x[2],
        ];
        for i in 0..4 {
            x[i] += s.dt * dx[i];
        }
        for i in 0..4 {
            r[4 * k + i] = sw[i] * (w.z[k + 1][i] - x[i]);
        }
    }
    r
}

/// Σ_k |z′_k − x_m,k|² of [Parsons1980, eq. (75)] simulated with `p`: the unweighted sum of squares without ½,
/// the scale the report's printed J seems to have (our reading; the report does not say).
pub fn sum_of_squares(p: &[f64; 8], w: &Window, s: &WlsSettings) -> f64 {
    let unit = WlsSettings {
        weight: [1.0; 4],
        ..*s
    };
    residuals(p, w, &unit).norm_squared()
}

/// Minimises [Parsons1980, eq. (77)] from `p0` by Levenberg–Marquardt.
pub fn fit(w: &Window, s: &WlsSettings, p0: [f64; 8]) -> Result<WlsFit, ControlError> {
    if w.z.len() < 3 || w.rudder.len() != w.z.len() {
        return Err(ControlError(format!(
            "WLS window needs >= 3 samples with a rudder value each (got {} and {})",
            w.z.len(),
            w.rudder.len()
        )));
    }
    check_positive("dt", s.dt)?;
    let mut p = p0;
    let mut r = residuals(&p, w, s);
    let mut evals = 1;
    let mut cost = 0.5 * r.norm_squared();
    let mut lambda = 1e-3;
    let scale: [f64; 8] = p.map(|v| v.abs().max(1e-3));
    while evals < s.max_evaluations {
        // forward-difference Jacobian
        let mut jac = DMatrix::zeros(r.len(), 8);
        for j in 0..8 {
            let h = 1e-6 * scale[j];
            let mut pj = p;
            pj[j] += h;
            let rj = residuals(&pj, w, s);
            evals += 1;
            jac.set_column(j, &((rj - &r) / h));
        }
        let jtj = jac.transpose() * &jac;
        let jtr = jac.transpose() * &r;
        let mut improved = false;
        for _ in 0..20 {
            let mut a = jtj.clone();
            for i in 0..8 {
                a[(i, i)] += lambda * jtj[(i, i)].max(1e-300);
            }
            let Some(step) = a.lu().solve(&(-&jtr)) else {
                lambda *= 10.0;
                continue;
            };
            // Gauss–Newton / LM step s = −(JᵀJ + λD)⁻¹Jᵀr for r(p + s) ≈ r + J s
            let cand: [f64; 8] = std::array::from_fn(|i| p[i] + step[i]);
            let rc = residuals(&cand, w, s);
            evals += 1;
            let cc = 0.5 * rc.norm_squared();
            if cc < cost {
                let rel = (cost - cc) / cost.max(1e-300);
                p = cand;
                r = rc;
                cost = cc;
                lambda = (lambda / 10.0).max(1e-12);
                improved = true;
                if rel < 1e-14 || cost < 1e-30 {
                    return Ok(WlsFit {
                        p,
                        cost,
                        evaluations: evals,
                    });
                }
                break;
            }
            lambda *= 10.0;
            if evals >= s.max_evaluations {
                break;
            }
        }
        if !improved {
            break;
        }
    }
    Ok(WlsFit {
        p,
        cost,
        evaluations: evals,
    })
}

/// When the data windows are loaded [Parsons1980, Fig. 24], in ship lengths t′ from the start: windows of
/// length LW at `window_start + n·LU` (n = 0, 1, …); the fit runs when a window is complete.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WlsSchedule {
    pub window_start: f64,
    /// LW (2.5 L).
    pub window_length: f64,
    /// LU (5, 6 or 6.25 L).
    pub update_cycle: f64,
}

impl WlsSchedule {
    pub fn validate(&self) -> Result<(), ControlError> {
        check_positive("window_length", self.window_length)?;
        check_positive("update_cycle", self.update_cycle)?;
        if self.window_length > self.update_cycle {
            return Err(ControlError(format!(
                "parameter window_length = {} must not exceed update_cycle = {}",
                self.window_length, self.update_cycle
            )));
        }
        check_finite("window_start", self.window_start)?;
        Ok(())
    }

    /// For a sample at t′ with step Δt′: whether it lies in a window and whether it is the
    /// window's first or last. Half a step of tolerance at both ends, so that rounding of t′ on
    /// the grid never moves a window by a sample.
    fn position(&self, t: f64, dt: f64) -> Option<(bool, bool)> {
        let s = t - self.window_start;
        let n = ((s + 0.5 * dt) / self.update_cycle).floor();
        if n < 0.0 {
            return None;
        }
        let r = s - n * self.update_cycle;
        let end = self.window_length - 0.5 * dt;
        if r >= -0.5 * dt && r < end {
            Some((r < 0.5 * dt, r + dt >= end))
        } else {
            None
        }
    }
}

/// The batch estimator in a loop: sampling, windows, fits and the validity of the estimates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WlsEstimator {
    pub settings: WlsSettings,
    pub schedule: WlsSchedule,
    /// Current estimate p̂ = [f22, f23, f25, f32, f33, f35, N′, Y′] (the last fit, valid or not).
    p: [f64; 8],
    /// The last valid estimate (the start of the next search).
    p_valid: [f64; 8],
    z: Vec<[f64; 4]>,
    rudder: Vec<f64>,
    x0: [f64; 4],
    evaluations: usize,
    cost: f64,
    sum_of_squares: f64,
    updates: u32,
    loading: bool,
}

impl WlsEstimator {
    /// Starts from `p0` (the estimate before the first fit and the first fit's initial point).
    pub fn new(
        settings: WlsSettings,
        schedule: WlsSchedule,
        p0: [f64; 8],
    ) -> Result<Self, ControlError> {
        schedule.validate()?;
        check_positive("dt", settings.dt)?;
        for (i, w) in settings.weight.iter().enumerate() {
            check_positive(["w_psi", "w_r", "w_beta", "w_eta"][i], *w)?;
        }
        if settings.max_evaluations < 10 {
            return Err(ControlError(format!(
                "parameter max_evaluations = {} must be >= 10",
                settings.max_evaluations
            )));
        }
        Ok(WlsEstimator {
            settings,
            schedule,
            p: p0,
            p_valid: p0,
            z: Vec::new(),
            rudder: Vec::new(),
            x0: [0.0; 4],
            evaluations: 0,
            cost: 0.0,
            sum_of_squares: 0.0,
            updates: 0,
            loading: false,
        })
    }

    /// One sample at t′ (ship lengths since the start) of a step of Δt′ = `dt`: measured
    /// z′ = [ψ′, r′, β′, η′], rudder δ′, and the control-loop filter's estimate x̂′ (its first
    /// value in a window is the model's initial state). Returns whether a fit was made.
    pub fn sample(
        &mut self,
        t: f64,
        dt: f64,
        z: [f64; 4],
        rudder: f64,
        xhat: [f64; 4],
    ) -> Result<bool, ControlError> {
        let Some((first, last)) = self.schedule.position(t, dt) else {
            self.loading = false;
            return Ok(false);
        };
        // One sample per step: a window of LW needs LW/Δt′ of them. Refused above
        // MAX_WINDOW_SAMPLES before anything is allocated (a tiny step or ship speed asked
        // for 2.9e9 samples, 23 GB, and aborted the process: issue 19).
        let samples = (self.schedule.window_length / dt).ceil() + 2.0;
        let too_many = samples.is_nan() || samples > MAX_WINDOW_SAMPLES as f64;
        if too_many || self.z.len() >= MAX_WINDOW_SAMPLES {
            return Err(ControlError(format!(
                "a data window of window_length = {} ship lengths at one sample per step of \
                 {dt} ship lengths needs {samples:e} samples, more than the limit of \
                 {MAX_WINDOW_SAMPLES:e}: shorten window_length or take longer steps \
                 (h * ship_speed / ship_length)",
                self.schedule.window_length
            )));
        }
        if self.z.capacity() == 0 {
            let n = samples as usize;
            let cannot = |e| ControlError(format!("cannot allocate a window of {n} samples: {e}"));
            self.z.try_reserve_exact(n).map_err(cannot)?;
            self.rudder.try_reserve_exact(n).map_err(cannot)?;
        }
        if first || self.z.is_empty() {
            self.z.clear();
            self.rudder.clear();
            self.x0 = xhat;
        }
        self.loading = true;
        self.z.push(z);
        self.rudder.push(rudder);
        if !last {
            return Ok(false);
        }
        self.loading = false;
        self.settings.dt = dt;
        let w = Window {
            z: std::mem::take(&mut self.z),
            rudder: std::mem::take(&mut self.rudder),
            x0: self.x0,
        };
        let r = fit(&w, &self.settings, self.p_valid);
        let ss = match &r {
            Ok(f) => sum_of_squares(&f.p, &w, &self.settings),
            Err(_) => f64::NAN,
        };
        // give the buffers back (keeps their capacity)
        self.z = w.z;
        self.rudder = w.rudder;
        self.z.clear();
        self.rudder.clear();
        let r = r?;
        self.p = r.p;
        self.evaluations = r.evaluations;
        self.cost = r.cost;
        self.sum_of_squares = ss;
        if self.decision() != UpdateDecision::None {
            self.p_valid = r.p;
        }
        self.updates += 1;
        Ok(true)
    }

    /// p̂ = [f22, f23, f25, f32, f33, f35, N′, Y′].
    pub fn estimate(&self) -> [f64; 8] {
        self.p
    }

    /// The six coefficient estimates.
    pub fn f(&self) -> [f64; 6] {
        std::array::from_fn(|i| self.p[i])
    }

    /// [Parsons1980, Table 10] branch of the current estimate (None: f̂23 or f̂25 out of range).
    pub fn decision(&self) -> UpdateDecision {
        validity(&self.f(), &TABLE_10)
    }

    /// Cost evaluations, [Parsons1980, eq. (77)] cost and the unweighted Σ|e|² of the last fit.
    pub fn evaluations(&self) -> usize {
        self.evaluations
    }

    pub fn cost(&self) -> f64 {
        self.cost
    }

    pub fn sum_of_squares(&self) -> f64 {
        self.sum_of_squares
    }

    /// Number of fits so far.
    pub fn updates(&self) -> u32 {
        self.updates
    }

    /// True while a window is being loaded.
    pub fn loading(&self) -> bool {
        self.loading
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::tokyo_maru::{TABLE_2, T_R};
    use nalgebra::SVector;

    /// Noise-free window from the Euler model of [Parsons1980, eq. (11)] with the true coefficients (the
    /// measured β′ is earth-relative, as the model's): the fit recovers the truth.
    ///
    /// [Parsons1980, Tables 12, 13] set-up [Parsons1980, sec. 4.2.2]: truth at H/T = ∞ under the constant disturbance
    /// N′ = 0.10262e-2, Y′ = 0.23277e-2, estimator started from the 1.89 values, window 2.5 L
    /// (500 samples), dither 0.5 L. The γ̃ are those of 1.89 while the truth has the ∞ γ's, so
    /// p7, p8 absorb Γ(∞)w through Γ(1.89): N̂′, Ŷ′ are the solution of Γ(1.89)[N̂′, Ŷ′] =
    /// Γ(∞)[N′, Y′] (biased by the γ errors, as derived here), and the six f's are recovered exactly.
    #[test]
    fn recovers_the_truth_under_a_constant_disturbance() {
        let truth = TABLE_2[4];
        let (f, g, gam) = truth.eq11(T_R);
        let w_true = SVector::<f64, 2>::new(0.10262e-2, 0.23277e-2);
        // start at the line-1145 equilibrium, then dither
        let mut x = SVector::<f64, 5>::new(-0.1428, 0.0, -0.1428, 0.0, 0.1310);
        let dt = 0.005;
        let mut z = Vec::new();
        let mut rudder = Vec::new();
        for k in 0..500 {
            let t = k as f64 * dt;
            let u = if ((t / 0.25).floor() as i64) % 2 == 0 {
                -0.5
            } else {
                0.5
            };
            z.push([x[0], x[1], x[2], x[3]]);
            rudder.push(x[4]);
            x += (f * x + g * u + gam * w_true) * dt;
        }
        let w = Window {
            x0: z[0],
            z,
            rudder,
        };
        let s = WlsSettings::default();
        let c = TABLE_2[2];
        let p0 = [c.f22, c.f23, c.f25, c.f32, c.f33, c.f35, 0.0, 0.0];
        let r = fit(&w, &s, p0).unwrap();
        eprintln!(
            "WLS: {:?} cost {:.3e} after {} evaluations",
            r.p, r.cost, r.evaluations
        );
        let want = [
            truth.f22, truth.f23, truth.f25, truth.f32, truth.f33, truth.f35,
        ];
        for i in 0..6 {
            assert!(
                (r.p[i] - want[i]).abs() < 1e-6 * want[i].abs().max(1.0),
                "p{} = {}",
                i + 1,
                r.p[i]
            );
        }
        // N̂′, Ŷ′ = Γ(1.89)⁻¹ Γ(∞) w
        let g89 = nalgebra::Matrix2::new(c.g21, c.g22, c.g31, c.g32);
        let ginf = nalgebra::Matrix2::new(truth.g21, truth.g22, truth.g31, truth.g32);
        let nw = g89.try_inverse().unwrap() * ginf * w_true;
        assert!((r.p[6] - nw[0]).abs() < 1e-8 && (r.p[7] - nw[1]).abs() < 1e-8);
        assert!(r.cost < 1e-12);
    }

    /// The estimator in a loop: windows of LW = 2.5 L every LU = 6 L from t′ = 3.45 on the
    /// Δt′ = 0.005 grid hold exactly 500 samples, the fit comes with the last one, recovers the
    /// noise-free truth (deep water under the constant disturbance) and is valid [Parsons1980, Table 10].
    #[test]
    fn estimator_windows_and_fit_in_a_loop() {
        let truth = TABLE_2[4];
        let (f, g, gam) = truth.eq11(T_R);
        let w_true = SVector::<f64, 2>::new(0.10262e-2, 0.23277e-2);
        let mut x = SVector::<f64, 5>::new(-0.1428, 0.0, -0.1428, 0.0, 0.1310);
        let c = TABLE_2[2];
        let p0 = [c.f22, c.f23, c.f25, c.f32, c.f33, c.f35, 0.0, 0.0];
        let schedule = WlsSchedule {
            window_start: 3.45,
            window_length: 2.5,
            update_cycle: 6.0,
        };
        let mut est = WlsEstimator::new(WlsSettings::default(), schedule, p0).unwrap();
        let dt = 0.005;
        let mut fits = Vec::new();
        let mut loaded = 0;
        for k in 0..2400 {
            let t = k as f64 * dt;
            let u = if ((t / 0.25).floor() as i64) % 2 == 0 {
                -0.5
            } else {
                0.5
            };
            let xs = [x[0], x[1], x[2], x[3]];
            if est.sample(t, dt, xs, x[4], xs).unwrap() {
                fits.push(k);
            }
            if est.loading() {
                loaded += 1;
            }
            x += (f * x + g * u + gam * w_true) * dt;
        }
        // windows [3.45, 5.95) and [9.45, 11.95): the fits at the samples of t′ = 5.945, 11.945
        assert_eq!(fits, vec![1189, 2389]);
        assert_eq!(loaded, 2 * 499);
        assert_eq!(est.updates(), 2);
        let want = [
            truth.f22, truth.f23, truth.f25, truth.f32, truth.f33, truth.f35,
        ];
        for i in 0..6 {
            assert!((est.f()[i] - want[i]).abs() < 1e-6 * want[i].abs().max(1.0));
        }
        assert_eq!(est.decision(), UpdateDecision::All);
        assert!(est.cost() < 1e-12 && est.sum_of_squares() < 1e-20);
        assert!(est.evaluations() > 9);
    }

    #[test]
    fn short_window_is_an_error() {
        let w = Window {
            z: vec![[0.0; 4]; 2],
            rudder: vec![0.0; 2],
            x0: [0.0; 4],
        };
        assert!(fit(&w, &WlsSettings::default(), [0.0; 8]).is_err());
    }
}
