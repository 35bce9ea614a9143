//! Gauss-Markov noise processes generated on their own fixed internal time grid.
//!
//! A continuous linear SDE `ẋ = A x + B g n(t)` (n unit-intensity white noise, E[n(t)n(s)] =
//! δ(t−s)) is sampled **exactly** on the grid t_k = t0 + k·dt:
//! `x_(k+1) = Φ x_k + w_k`, `Φ = e^(A dt)`, `w_k ~ N(0, Q_d)`, `Q_d = P − Φ P Φᵀ` where P is the
//! stationary covariance (for the random walk, which has none, `Q_d = g² dt`). The samples therefore
//! have exactly the continuous process's statistics at the grid instants, whatever dt is.
//!
//! Between grid instants the output is **linearly interpolated** between x_k and x_(k+1) (the next
//! grid value is drawn in advance; it does not depend on any input). The output at time t thus
//! depends only on (seed, t0, dt, parameters, t), never on the communication step: the documented
//! hold of these processes is this linear interpolation on the internal grid (for dt ≪ the
//! correlation time it lowers the variance by a factor ≈ 1 − (ω dt)²/6, negligible for the
//! defaults). [`WhiteSequence`] instead holds each sample over its grid interval (zero-order hold),
//! which is what a white sequence means.
//!
//! Parameters may change while running (tunable FMU parameters, input-dependent encounter
//! frequency): the new Φ and Q_d apply from the next grid interval that is drawn.

use crate::integrate::due_passes;
use crate::math::{exp, exp_m1};
use crate::random::NoiseStream;

/// Time quantum of the disturbance models [s]: every time handed to `advance_to` is rounded to
/// a whole nanosecond first. Importers compute communication points differently (FMPy
/// `t0 + k h`, libcosim integer nanoseconds, an FMU's own `t + h`), which puts "the same" instant
/// a few ulps apart; after rounding they coincide, so outputs that are functions of time (the
/// sums of sinusoids, the interpolated processes, the histories of [Parsons1980]) are bit-identical across
/// importers whenever the communication points lie on a nanosecond grid. Exact for |t| < 9e6 s.
pub const TIME_QUANTUM: f64 = 1e-9;

/// `t` rounded to a whole [`TIME_QUANTUM`].
#[inline]
pub fn quantise_time(t: f64) -> f64 {
    (t * 1e9).round() / 1e9
}
use nalgebra::Matrix2;
use serde::{Deserialize, Serialize};

/// How a process starts at t0.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Start {
    /// Drawn from the stationary distribution (the process is stationary from t0 on).
    Stationary,
    /// A given value (for the second-order process: x1 = value, x2 = 0).
    Value(f64),
}

/// Grid bookkeeping shared by the processes: the index of the left grid point of `t`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Grid {
    t0: f64,
    dt: f64,
    k: u64,
}

impl Grid {
    fn time(&self, k: u64) -> f64 {
        self.t0 + k as f64 * self.dt
    }
    /// (grid step, passes of `advance_to(t)`): the grid points from the current one up to `t`,
    /// for the bound on the work of one step (+inf passes for a grid step that is not a
    /// positive number).
    fn passes_to(&self, t: f64) -> (f64, f64) {
        let passes = if self.dt > 0.0 {
            due_passes((t - self.time(self.k)) / self.dt)
        } else {
            f64::INFINITY
        };
        (self.dt, passes)
    }
    /// Fraction of the current interval at time `t`, clamped to [0, 1].
    fn frac(&self, t: f64) -> f64 {
        ((t - self.time(self.k)) / self.dt).clamp(0.0, 1.0)
    }
}

/// Second-order process `ẋ1 = x2`, `ẋ2 = −ω² x1 − 2 ζ ω x2 + g n(t)`.
///
/// * x1 is the low-pass output `g/(s² + 2ζωs + ω²)` ([Klugt1987, Fig. 2.10] with g = σ ω²), stationary
///   variance `g²/(4 ζ ω³)`;
/// * x2 is the band-pass output `g s/(s² + 2ζωs + ω²)` ([Fossen1999, eq. (10)] with g = σ_i = K_w),
///   stationary variance `g²/(4 ζ ω)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SecondOrderProcess {
    omega: f64,
    zeta: f64,
    gain: f64,
    phi: [[f64; 2]; 2],
    chol: [[f64; 2]; 2],
    grid: Grid,
    now: [f64; 2],
    next: [f64; 2],
    rng: NoiseStream,
}

impl SecondOrderProcess {
    /// `omega > 0`, `zeta > 0`, `dt > 0` (checked by the callers' parameter validation).
    pub fn new(
        omega: f64,
        zeta: f64,
        gain: f64,
        dt: f64,
        t0: f64,
        start: Start,
        rng: NoiseStream,
    ) -> Self {
        let mut p = SecondOrderProcess {
            omega,
            zeta,
            gain,
            phi: [[1.0, 0.0], [0.0, 1.0]],
            chol: [[0.0; 2]; 2],
            grid: Grid { t0, dt, k: 0 },
            now: [0.0; 2],
            next: [0.0; 2],
            rng,
        };
        p.discretise();
        p.now = match start {
            Start::Stationary => {
                let (v1, v2) = p.stationary_variances();
                [v1.sqrt() * p.rng.normal(), v2.sqrt() * p.rng.normal()]
            }
            Start::Value(v) => [v, 0.0],
        };
        p.next = p.draw_next();
        p
    }

    /// Stationary variances of x1 and x2 (they are uncorrelated).
    pub fn stationary_variances(&self) -> (f64, f64) {
        let g2 = self.gain * self.gain;
        let w = self.omega;
        (
            g2 / (4.0 * self.zeta * w * w * w),
            g2 / (4.0 * self.zeta * w),
        )
    }

    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Changes ω, ζ, g; applies from the next grid interval drawn.
    pub fn set_params(&mut self, omega: f64, zeta: f64, gain: f64) {
        if omega != self.omega || zeta != self.zeta || gain != self.gain {
            self.omega = omega;
            self.zeta = zeta;
            self.gain = gain;
            self.discretise();
        }
    }

    fn discretise(&mut self) {
        let (w, z, dt) = (self.omega, self.zeta, self.grid.dt);
        let a = Matrix2::new(0.0, 1.0, -w * w, -2.0 * z * w) * dt;
        let phi = a.exp();
        let (v1, v2) = self.stationary_variances();
        let p = Matrix2::new(v1, 0.0, 0.0, v2);
        let q = p - phi * p * phi.transpose();
        let l11 = q[(0, 0)].max(0.0).sqrt();
        let l21 = if l11 > 0.0 { q[(1, 0)] / l11 } else { 0.0 };
        let l22 = (q[(1, 1)] - l21 * l21).max(0.0).sqrt();
        self.phi = [[phi[(0, 0)], phi[(0, 1)]], [phi[(1, 0)], phi[(1, 1)]]];
        self.chol = [[l11, 0.0], [l21, l22]];
    }

    fn draw_next(&mut self) -> [f64; 2] {
        let (n1, n2) = (self.rng.normal(), self.rng.normal());
        let (x, f, l) = (self.now, self.phi, self.chol);
        [
            f[0][0] * x[0] + f[0][1] * x[1] + l[0][0] * n1,
            f[1][0] * x[0] + f[1][1] * x[1] + l[1][0] * n1 + l[1][1] * n2,
        ]
    }

    /// (grid step, passes) of [`advance_to`](Self::advance_to)`(t)` (see `Grid::passes_to`).
    pub fn grid_passes(&self, t: f64) -> (f64, f64) {
        self.grid.passes_to(t)
    }

    /// Advances the grid so that `t` lies in the current interval (never goes back).
    pub fn advance_to(&mut self, t: f64) {
        while self.grid.time(self.grid.k + 1) < t {
            self.now = self.next;
            self.grid.k += 1;
            self.next = self.draw_next();
        }
    }

    /// (x1, x2) at time `t` (call [`advance_to`](Self::advance_to) first): linear interpolation
    /// on the internal grid.
    pub fn value(&self, t: f64) -> [f64; 2] {
        let f = self.grid.frac(t);
        [
            self.now[0] + f * (self.next[0] - self.now[0]),
            self.now[1] + f * (self.next[1] - self.now[1]),
        ]
    }
}

/// First-order process `ẋ = −x/T + g n(t)` (first-order Markov / shaping filter, stationary
/// variance `g² T/2`), or the random walk `ẋ = g n(t)` when `T` is infinite (or ≤ 0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FirstOrderProcess {
    time_constant: f64,
    gain: f64,
    phi: f64,
    /// Standard deviation of the noise added per grid step.
    step_std: f64,
    grid: Grid,
    now: f64,
    next: f64,
    rng: NoiseStream,
}

impl FirstOrderProcess {
    pub fn new(
        time_constant: f64,
        gain: f64,
        dt: f64,
        t0: f64,
        start: Start,
        rng: NoiseStream,
    ) -> Self {
        let mut p = FirstOrderProcess {
            time_constant,
            gain,
            phi: 1.0,
            step_std: 0.0,
            grid: Grid { t0, dt, k: 0 },
            now: 0.0,
            next: 0.0,
            rng,
        };
        p.discretise();
        p.now = match (start, p.stationary_variance()) {
            (Start::Stationary, Some(v)) => v.sqrt() * p.rng.normal(),
            (Start::Stationary, None) => 0.0,
            (Start::Value(v), _) => v,
        };
        p.next = p.draw_next();
        p
    }

    fn is_walk(&self) -> bool {
        !(self.time_constant.is_finite() && self.time_constant > 0.0)
    }

    /// `g² T / 2`, or None for the random walk.
    pub fn stationary_variance(&self) -> Option<f64> {
        (!self.is_walk()).then(|| self.gain * self.gain * self.time_constant / 2.0)
    }

    pub fn set_params(&mut self, time_constant: f64, gain: f64) {
        if time_constant != self.time_constant || gain != self.gain {
            self.time_constant = time_constant;
            self.gain = gain;
            self.discretise();
        }
    }

    fn discretise(&mut self) {
        let dt = self.grid.dt;
        if self.is_walk() {
            self.phi = 1.0;
            self.step_std = self.gain.abs() * dt.sqrt();
        } else {
            let phi = exp(-dt / self.time_constant);
            let v = self.gain * self.gain * self.time_constant / 2.0;
            self.phi = phi;
            // 1 − φ² without cancellation: −expm1(−2 dt/T)
            self.step_std = (v * -exp_m1(-2.0 * dt / self.time_constant)).sqrt();
        }
    }

    fn draw_next(&mut self) -> f64 {
        self.phi * self.now + self.step_std * self.rng.normal()
    }

    /// (grid step, passes) of [`advance_to`](Self::advance_to)`(t)` (see `Grid::passes_to`).
    pub fn grid_passes(&self, t: f64) -> (f64, f64) {
        self.grid.passes_to(t)
    }

    pub fn advance_to(&mut self, t: f64) {
        while self.grid.time(self.grid.k + 1) < t {
            self.now = self.next;
            self.grid.k += 1;
            self.next = self.draw_next();
        }
    }

    /// Value at `t`, linearly interpolated on the internal grid.
    pub fn value(&self, t: f64) -> f64 {
        self.now + self.grid.frac(t) * (self.next - self.now)
    }
}

/// A white Gaussian sequence with per-sample standard deviation σ on the grid t_k = t0 + k·dt,
/// each sample held over [t_k, t_(k+1)) (zero-order hold). Its equivalent continuous intensity
/// is σ² dt [Parsons1980, eqs. (16) and (64)].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WhiteSequence {
    sigma: f64,
    grid: Grid,
    now: f64,
    rng: NoiseStream,
}

impl WhiteSequence {
    pub fn new(sigma: f64, dt: f64, t0: f64, mut rng: NoiseStream) -> Self {
        let now = sigma * rng.normal();
        WhiteSequence {
            sigma,
            grid: Grid { t0, dt, k: 0 },
            now,
            rng,
        }
    }

    /// (grid step, passes) of [`advance_to`](Self::advance_to)`(t)` (see `Grid::passes_to`).
    pub fn grid_passes(&self, t: f64) -> (f64, f64) {
        self.grid.passes_to(t)
    }

    /// Advances so that the held sample is the one of the last grid instant ≤ t. A grid
    /// instant within 1e-9·dt above `t` counts as reached (communication points computed by
    /// repeated addition land a few ulps off the grid).
    pub fn advance_to(&mut self, t: f64) {
        let eps = 1e-9 * self.grid.dt;
        while self.grid.time(self.grid.k + 1) <= t + eps {
            self.grid.k += 1;
            self.now = self.sigma * self.rng.normal();
        }
    }

    pub fn value(&self) -> f64 {
        self.now
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{correlation, mean_variance};

    fn sample_second(p: &mut SecondOrderProcess, dt: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
        let (mut a, mut b) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for k in 0..n {
            let t = k as f64 * dt;
            p.advance_to(t);
            let v = p.value(t);
            a.push(v[0]);
            b.push(v[1]);
        }
        (a, b)
    }

    #[test]
    fn second_order_variances_match_the_analytic_values_within_3_percent() {
        // Wave model of [Fossen1999, sec. 6]: ζ = 0.1, ω0 = 0.8976 rad/s, σ = 1:
        // std(x2) = 1.669 σ (derived here from the stationary variance σ²/(4ζω0)).
        let mut p = SecondOrderProcess::new(
            0.8976,
            0.1,
            1.0,
            0.5,
            0.0,
            Start::Stationary,
            NoiseStream::new(1, 0),
        );
        let (v1a, v2a) = p.stationary_variances();
        assert!((v2a.sqrt() - 1.669).abs() < 1e-3);
        // 200 h at the 0.5 s grid: relative std of the variance estimate ≈ 0.5 %.
        let (x1, x2) = sample_second(&mut p, 0.5, 1_440_000);
        let (_, v1) = mean_variance(&x1);
        let (_, v2) = mean_variance(&x2);
        assert!((v1 / v1a - 1.0).abs() < 0.03, "x1 variance {v1} vs {v1a}");
        assert!((v2 / v2a - 1.0).abs() < 0.03, "x2 variance {v2} vs {v2a}");
    }

    #[test]
    fn first_order_variance_and_correlation_time() {
        // Bias of [Fossen1999, eq. (58)]: T = 1000 s; 1e6 grid steps of 10 s = 10^4 correlation times.
        let mut p = FirstOrderProcess::new(
            1000.0,
            0.02,
            10.0,
            0.0,
            Start::Stationary,
            NoiseStream::new(5, 0),
        );
        let va = p.stationary_variance().unwrap();
        let n = 1_000_000;
        let mut x = Vec::with_capacity(n);
        for k in 0..n {
            let t = k as f64 * 10.0;
            p.advance_to(t);
            x.push(p.value(t));
        }
        let (_, v) = mean_variance(&x);
        assert!((v / va - 1.0).abs() < 0.03, "{v} vs {va}");
        // lag-100 (1000 s) autocorrelation = e^-1
        let r = correlation(&x[..n - 100], &x[100..]);
        assert!((r - exp(-1.0f64)).abs() < 0.02, "{r}");
    }

    #[test]
    fn random_walk_increment_variance() {
        let g = 0.3;
        let mut p = FirstOrderProcess::new(
            f64::INFINITY,
            g,
            0.25,
            0.0,
            Start::Value(1.0),
            NoiseStream::new(9, 0),
        );
        assert_eq!(p.value(0.0), 1.0);
        let n = 200_000;
        let mut inc = Vec::with_capacity(n);
        let mut prev = p.value(0.0);
        for k in 1..=n {
            let t = k as f64 * 1.0; // increments over 1 s: variance g² · 1
            p.advance_to(t);
            let v = p.value(t);
            inc.push(v - prev);
            prev = v;
        }
        let (_, v) = mean_variance(&inc);
        assert!((v / (g * g) - 1.0).abs() < 0.03, "{v}");
    }

    #[test]
    fn output_does_not_depend_on_the_query_times() {
        let mk = || {
            SecondOrderProcess::new(
                0.7,
                0.2,
                2.0,
                0.1,
                3.0,
                Start::Stationary,
                NoiseStream::new(11, 4),
            )
        };
        let (mut a, mut b) = (mk(), mk());
        // a queried every 0.013 s, b every 0.37 s; compare on b's times
        let mut ta = 3.0;
        for k in 0..=300 {
            let tb = 3.0 + k as f64 * 0.37;
            while ta + 0.013 <= tb {
                ta += 0.013;
                a.advance_to(ta);
                let _ = a.value(ta);
            }
            a.advance_to(tb);
            b.advance_to(tb);
            let (va, vb) = (a.value(tb), b.value(tb));
            assert!((va[0] - vb[0]).abs() < 1e-12 && (va[1] - vb[1]).abs() < 1e-12);
        }
    }
}
