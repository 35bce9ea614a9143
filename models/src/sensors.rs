//! Measurement noise and sampling: `y(t) = x(t_s) + s·σ·n_k`, a sample-and-hold of the true
//! signal plus Gaussian white noise, per channel.
//!
//! # Sampling (zero-order hold)
//! Channel c samples at `t_k = t0 + k·T_c` (k = 0, 1, ...) and holds the sample until the next
//! instant. The sample at `t_k` is the true value at `t_k`: when `t_k` is a communication point
//! the value set there (the outputs have direct feedthrough at sampling instants); when `t_k`
//! falls inside a step, the input held over that step. The noise `n_k` of sample k is the k-th
//! draw of the channel's own ChaCha8 stream, so the noise sequence does not depend on the
//! communication step (a sample skipped by a long step is still drawn), and channels are
//! independent. A sampling instant within 1e-9·T_c above a communication point counts as
//! reached (communication points computed by repeated addition land a few ulps off the grid).
//!
//! # Noise levels of the sources
//! * **[Parsons1980, Table 3]** (control loop) and **[Parsons1980, Table 9]** (parameter estimator):
//!   per-sample σ′ = √(r_jj/Δt′) [Parsons1980, eqs. (15)-(16)] at Δt′ = 0.005 (Δt = 0.2349 s for Tokyo Maru at
//!   12 kn, L = 290 m). Dimensional per-sample values: ψ σ′ rad; r σ′·U/L rad/s; η σ′·L m;
//!   v = −U β′ so σ_v = σ′_β·U m/s. [`per_sample_sigma`] computes σ′ from (σ, τ, Δt).
//!   **Reading taken, Table 3 β′ row**: [Parsons1980, Table 3] prints σ′ = 1.459e-3,
//!   but its own r_jj = 1.118e-8 gives √(r/Δt′) = 1.495e-3, as does σ = 0.01 m/s with
//!   [Parsons1980, eq. (15)];
//!   the printed value is taken as transposed digits and **1.495e-3** is used.
//! * **DGPS [Artyszuk2003, sec. 2]**: σ = 2 m per axis at 1 s ([`SensorParams::dgps_artyszuk2003`]).
//! * **DDG-51 [Taylor2000, sec. 5.2.3.1]**: "noisy measurements" of heading and y, level not given; use the [Parsons1980] compass
//!   channel (0.1° class) or set σ.
//! * **[Klugt1987]**: roll and speed noise levels not given (speed variance "1" in [Klugt1987, sec. 5.5.3] has no unit);
//!   default 0.
//!
//! A global `noise_scale` multiplies every σ ([Parsons1980] uses 1, 0.001 and 0).

use crate::error::{check_non_negative, check_positive};
use crate::integrate::due_passes;
use crate::random::{channel, NoiseStream};
use serde::{Deserialize, Serialize};

/// Number of channels.
pub const CHANNELS: usize = 9;

/// Channel names (FMU variable prefixes) and SI units, in order.
pub const CHANNEL_NAMES: [(&str, &str); CHANNELS] = [
    ("heading", "rad"),
    ("yaw_rate", "rad/s"),
    ("roll", "rad"),
    ("roll_rate", "rad/s"),
    ("north", "m"),
    ("east", "m"),
    ("cross_track", "m"),
    ("speed", "m/s"),
    ("sway_velocity", "m/s"),
];

/// The FMU parameter of each channel's sampling interval (`<name>_interval`), in order.
pub const CHANNEL_INTERVALS: [&str; CHANNELS] = [
    "heading_interval",
    "yaw_rate_interval",
    "roll_interval",
    "roll_rate_interval",
    "north_interval",
    "east_interval",
    "cross_track_interval",
    "speed_interval",
    "sway_velocity_interval",
];

/// Channel indices.
pub mod ch {
    pub const HEADING: usize = 0;
    pub const YAW_RATE: usize = 1;
    pub const ROLL: usize = 2;
    pub const ROLL_RATE: usize = 3;
    pub const NORTH: usize = 4;
    pub const EAST: usize = 5;
    pub const CROSS_TRACK: usize = 6;
    pub const SPEED: usize = 7;
    pub const SWAY_VELOCITY: usize = 8;
}

/// Reference conditions of [Parsons1980, Table 1]: Tokyo Maru, U = 12 kn, L = 290 m.
pub const TOKYO_MARU_U: f64 = 12.0 * 1852.0 / 3600.0;
pub const TOKYO_MARU_L: f64 = 290.0;
/// Simulation step Δt′ = 0.005 of [Parsons1980, sec. 2.2] → seconds.
pub const TOKYO_MARU_DT: f64 = 0.005 * TOKYO_MARU_L / TOKYO_MARU_U;

/// Per-sample standard deviation of the white sequence equivalent to exponentially correlated
/// noise (RMS σ, correlation time τ) sampled every Δt: `√(2 σ² τ / Δt)` [Parsons1980, eqs. (15)-(16)].
/// Any consistent units ([Parsons1980] uses nondimensional τ′ = τU/L and Δt′).
pub fn per_sample_sigma(sigma: f64, tau: f64, dt: f64) -> f64 {
    (2.0 * sigma * sigma * tau / dt).sqrt()
}

/// One channel: per-sample standard deviation and sampling interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChannelParams {
    pub sigma: f64,
    pub interval: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorParams {
    pub channels: [ChannelParams; CHANNELS],
    pub noise_scale: f64,
    pub seed: u64,
}

impl SensorParams {
    /// [Parsons1980, Table 3] (control loop) for ψ, r, η, v at Δt = 0.2349 s; DGPS of [Artyszuk2003] for north/east;
    /// roll, roll rate and speed noise-free (no source value), sampled at 0.1, 0.1 and 1 s.
    pub fn tokyo_maru_table3() -> Self {
        let (u, l, dt) = (TOKYO_MARU_U, TOKYO_MARU_L, TOKYO_MARU_DT);
        let c = |sigma, interval| ChannelParams { sigma, interval };
        SensorParams {
            channels: [
                c(1.611e-3, dt),
                c(7.563e-3 * u / l, dt),
                c(0.0, 0.1),
                c(0.0, 0.1),
                c(2.0, 1.0),
                c(2.0, 1.0),
                c(9.549e-3 * l, dt),
                c(0.0, 1.0),
                c(1.495e-3 * u, dt),
            ],
            noise_scale: 1.0,
            seed: 1,
        }
    }

    /// DGPS of [Artyszuk2003, sec. 2]: north and east σ = 2 m at 1 s, everything else noise-free at 1 s.
    pub fn dgps_artyszuk2003() -> Self {
        let mut p = Self::tokyo_maru_table3();
        for (i, c) in p.channels.iter_mut().enumerate() {
            c.interval = 1.0;
            c.sigma = if i == ch::NORTH || i == ch::EAST {
                2.0
            } else {
                0.0
            };
        }
        p
    }

    pub fn validate(&self) -> Result<(), String> {
        for (c, (name, _)) in self.channels.iter().zip(CHANNEL_NAMES) {
            check_non_negative(&format!("{name}_sigma"), c.sigma)?;
            check_positive(&format!("{name}_interval"), c.interval)?;
        }
        check_non_negative("noise_scale", self.noise_scale)?;
        Ok(())
    }
}

impl Default for SensorParams {
    fn default() -> Self {
        Self::tokyo_maru_table3()
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct ChannelState {
    k: u64,
    noise: f64,
    held: f64,
    rng: NoiseStream,
}

/// The sensor block (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sensors {
    params: SensorParams,
    t0: f64,
    time: f64,
    input: [f64; CHANNELS],
    state: [ChannelState; CHANNELS],
}

impl Sensors {
    /// Takes sample 0 of every channel at `t0` from `input`.
    pub fn new(params: SensorParams, t0: f64, input: [f64; CHANNELS]) -> Result<Self, String> {
        params.validate()?;
        let state = std::array::from_fn(|i| {
            let mut rng = NoiseStream::new(params.seed, channel::SENSORS + i as u64);
            let noise = rng.normal();
            ChannelState {
                k: 0,
                noise,
                held: 0.0,
                rng,
            }
        });
        let mut s = Sensors {
            params,
            t0,
            time: t0,
            input,
            state,
        };
        for i in 0..CHANNELS {
            s.state[i].held = s.measure(i, input[i]);
        }
        Ok(s)
    }

    fn measure(&self, i: usize, x: f64) -> f64 {
        x + self.params.noise_scale * self.params.channels[i].sigma * self.state[i].noise
    }

    fn instant(&self, i: usize, k: u64) -> f64 {
        self.t0 + k as f64 * self.params.channels[i].interval
    }

    fn reached(&self, i: usize, k: u64, t: f64) -> bool {
        self.instant(i, k) <= t + 1e-9 * self.params.channels[i].interval
    }

    pub fn params(&self) -> &SensorParams {
        &self.params
    }

    /// Changes σ and the noise scale (tunable; the sampling grid and the streams are kept).
    pub fn set_noise(&mut self, sigmas: [f64; CHANNELS], noise_scale: f64) {
        for i in 0..CHANNELS {
            self.params.channels[i].sigma = sigmas[i];
        }
        self.params.noise_scale = noise_scale;
    }

    /// Sets the true values at the current time; a channel whose sampling instant is the
    /// current time re-takes that sample with the new value (same noise draw).
    pub fn set_inputs(&mut self, input: [f64; CHANNELS]) {
        self.input = input;
        for i in 0..CHANNELS {
            let k = self.state[i].k;
            if (self.instant(i, k) - self.time).abs() <= 1e-9 * self.params.channels[i].interval {
                self.state[i].held = self.measure(i, input[i]);
            }
        }
    }

    /// The sampling work of [`advance_to`](Self::advance_to)`(t)`: `each(name, interval,
    /// passes)` per channel, `name` its interval parameter (for the bound on the work of one
    /// FMU step; +inf passes for an interval that is not a positive number).
    pub fn internal_steps(&self, t: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        for (i, name) in CHANNEL_INTERVALS.iter().enumerate() {
            let interval = self.params.channels[i].interval;
            let passes = if interval > 0.0 {
                due_passes((t - self.instant(i, self.state[i].k)) / interval)
            } else {
                f64::INFINITY
            };
            each(name, interval, passes);
        }
    }

    /// Advances to `t` with the inputs held, taking every sample due in (time, t].
    pub fn advance_to(&mut self, t: f64) {
        for i in 0..CHANNELS {
            let mut due = false;
            while self.reached(i, self.state[i].k + 1, t) {
                let st = &mut self.state[i];
                st.k += 1;
                st.noise = st.rng.normal();
                due = true;
            }
            if due {
                self.state[i].held = self.measure(i, self.input[i]);
            }
        }
        self.time = t;
    }

    /// Measured (sampled, noisy) value of channel `i`.
    pub fn measured(&self, i: usize) -> f64 {
        self.state[i].held
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{correlation, mean_variance};

    #[test]
    fn per_sample_sigmas_reproduce_parsons1980_tables_3_and_9() {
        let d = std::f64::consts::PI / 180.0;
        let ul = TOKYO_MARU_U / TOKYO_MARU_L;
        let tau = |s: f64| s * ul; // τ′ = τ U/L
        let dt = 0.005;
        assert!((TOKYO_MARU_DT - 0.2349).abs() < 1e-4);
        let rel = |a: f64, b: f64| (a / b - 1.0).abs();
        // [Parsons1980, Table 3], τ = 0.1 s
        assert!(rel(per_sample_sigma(0.1 * d, tau(0.1), dt), 1.611e-3) < 1e-3);
        assert!(rel(per_sample_sigma(0.01 * d / ul, tau(0.1), dt), 7.563e-3) < 1e-3);
        assert!(rel(per_sample_sigma(3.0 / TOKYO_MARU_L, tau(0.1), dt), 9.549e-3) < 1e-3);
        // β′ row: 0.01 m/s → β′ = v/U; gives 1.495e-3, not the printed 1.459e-3
        let b = per_sample_sigma(0.01 / TOKYO_MARU_U, tau(0.1), dt);
        assert!(rel(b, 1.495e-3) < 1e-3, "{b}");
        assert!(rel(b, 1.459e-3) > 0.02);
        // [Parsons1980, Table 9], τ = 0.01 s
        assert!(rel(per_sample_sigma(0.1 * d, tau(0.01), dt), 5.0943e-4) < 1e-3);
        assert!(
            rel(
                per_sample_sigma(1.0 / TOKYO_MARU_L, tau(0.01), dt),
                1.0065e-3
            ) < 1e-3
        );
        assert!(rel(per_sample_sigma(0.08 * d, tau(0.01), dt), 4.0688e-4) < 4e-3);
        // "dimensionally about 93 percent of σ_j": √(2·0.1/0.2349) = 0.923
        assert!((per_sample_sigma(1.0, 0.1, TOKYO_MARU_DT) - 0.9227).abs() < 1e-3);
    }

    fn run(
        p: SensorParams,
        truth: impl Fn(f64) -> [f64; CHANNELS],
        h: f64,
        n: usize,
    ) -> Vec<[f64; CHANNELS]> {
        let mut s = Sensors::new(p, 0.0, truth(0.0)).unwrap();
        let mut out = Vec::with_capacity(n);
        for k in 1..=n {
            s.advance_to(k as f64 * h);
            s.set_inputs(truth(k as f64 * h));
            out.push(std::array::from_fn(|i| s.measured(i)));
        }
        out
    }

    #[test]
    fn noise_levels_of_table_3_and_dgps() {
        let p = SensorParams::tokyo_maru_table3();
        let sig = p.channels.map(|c| c.sigma);
        let zero = |_t: f64| [0.0; CHANNELS];
        // sample every channel at its own interval: step = 0.2349/… use h = interval of each
        for i in [
            ch::HEADING,
            ch::YAW_RATE,
            ch::CROSS_TRACK,
            ch::NORTH,
            ch::SWAY_VELOCITY,
        ] {
            let h = p.channels[i].interval;
            let rec = run(p.clone(), zero, h, 100_000);
            let x: Vec<f64> = rec.iter().map(|r| r[i]).collect();
            let (m, v) = mean_variance(&x);
            assert!(m.abs() < 0.02 * sig[i], "{i}: mean {m}");
            assert!(
                (v.sqrt() / sig[i] - 1.0).abs() < 0.01,
                "{i}: {} vs {}",
                v.sqrt(),
                sig[i]
            );
        }
        // DGPS: σ 2 m at 1 s, north and east independent
        let rec = run(SensorParams::dgps_artyszuk2003(), zero, 1.0, 100_000);
        let n: Vec<f64> = rec.iter().map(|r| r[ch::NORTH]).collect();
        let e: Vec<f64> = rec.iter().map(|r| r[ch::EAST]).collect();
        let (_, v) = mean_variance(&n);
        assert!((v.sqrt() - 2.0).abs() < 0.02, "{}", v.sqrt());
        assert!(correlation(&n, &e).abs() < 0.05);
        // dimensional [Parsons1980, Table 3] values
        assert!((sig[ch::YAW_RATE] - 1.6100e-4).abs() < 1e-7);
        assert!((sig[ch::CROSS_TRACK] - 2.7692).abs() < 1e-3);
    }

    #[test]
    fn zero_order_hold_sampling_and_step_independence() {
        let mut p = SensorParams::dgps_artyszuk2003();
        p.channels[ch::HEADING] = ChannelParams {
            sigma: 0.01,
            interval: 0.5,
        };
        let truth = |t: f64| {
            let mut x = [0.0; CHANNELS];
            x[ch::NORTH] = 3.0 * t;
            x[ch::HEADING] = 0.1 * t;
            x
        };
        // fine steps of 0.1 s: the north measurement holds for 1 s and equals the truth at the
        // sample instant plus the noise
        let fine = run(p.clone(), truth, 0.1, 1000);
        let coarse = run(p.clone(), truth, 1.0, 100);
        for k in 0..100 {
            // same sample at t = k+1 in both runs
            assert_eq!(fine[10 * k + 9][ch::NORTH], coarse[k][ch::NORTH]);
            assert_eq!(fine[10 * k + 9][ch::HEADING], coarse[k][ch::HEADING]);
            // held over the second
            for j in 0..9 {
                assert_eq!(
                    fine[10 * k + j][ch::NORTH],
                    if k == 0 {
                        fine[0][ch::NORTH]
                    } else {
                        coarse[k - 1][ch::NORTH]
                    }
                );
            }
            let err = coarse[k][ch::NORTH] - 3.0 * (k + 1) as f64;
            assert!(err.abs() < 10.0);
        }
        // a step of 2.5 s skips samples but draws their noise: samples at t = 10 agree
        let skip = run(p.clone(), truth, 2.5, 40);
        assert_eq!(skip[3][ch::NORTH], coarse[9][ch::NORTH]);
        assert_eq!(skip[3][ch::HEADING], coarse[9][ch::HEADING]);
    }

    #[test]
    fn seeds_bit_identical_and_independent_and_snapshot() {
        let zero = |_t: f64| [0.0; CHANNELS];
        let mk = |seed| SensorParams {
            seed,
            ..SensorParams::dgps_artyszuk2003()
        };
        let a = run(mk(3), zero, 1.0, 100_000);
        let b = run(mk(3), zero, 1.0, 100_000);
        let c = run(mk(4), zero, 1.0, 100_000);
        assert!(a
            .iter()
            .zip(&b)
            .all(|(x, y)| x.iter().zip(y).all(|(u, v)| u.to_bits() == v.to_bits())));
        let xa: Vec<f64> = a.iter().map(|r| r[ch::NORTH]).collect();
        let xc: Vec<f64> = c.iter().map(|r| r[ch::NORTH]).collect();
        assert!(correlation(&xa, &xc).abs() < 0.05);
        let mut s = Sensors::new(mk(3), 0.0, [0.0; CHANNELS]).unwrap();
        s.advance_to(10.0);
        let snap = s.clone();
        let go = |s: &mut Sensors| -> Vec<u64> {
            (11..50)
                .map(|k| {
                    s.advance_to(k as f64);
                    s.measured(ch::EAST).to_bits()
                })
                .collect()
        };
        let first = go(&mut s);
        let mut again = snap;
        assert_eq!(first, go(&mut again));
    }
}
