//! Pacing to the wall clock: each communication point t_k has an absolute deadline,
//! start + (t_k - t_0)/X for a real-time factor X, computed from k and never from a sum of
//! sleeps, so a paced run does not drift. A point reached after its deadline is late: it is
//! counted (an overrun) and the run goes on at once, never skipping a step; the next deadline
//! is still start + (t_(k+1) - t_0)/X, so the run catches up if it can.
//!
//! The lateness of a point is the wall time at which the run has it (stepped and waited for)
//! minus its deadline: the oversleep of the wait when on time (tens of microseconds), the
//! overrun when late. [`Histogram`] keeps it in bounded memory.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A log-spaced histogram of durations from 100 ns to 1000 s, 100 bins per decade (each bin
/// 2.3 % wide), with the exact maximum: percentiles within 2.3 % in 1,000 counters, whatever
/// the run's length.
#[derive(Debug, Clone)]
pub struct Histogram {
    bins: Vec<u64>,
    count: u64,
    max: Duration,
}

const BINS_PER_DECADE: f64 = 100.0;
const DECADES: usize = 10;
const FLOOR_S: f64 = 1e-7;

impl Default for Histogram {
    fn default() -> Histogram {
        Histogram {
            bins: vec![0; DECADES * BINS_PER_DECADE as usize + 1],
            count: 0,
            max: Duration::ZERO,
        }
    }
}

impl Histogram {
    pub fn add(&mut self, d: Duration) {
        let s = d.as_secs_f64().max(FLOOR_S);
        let i = ((s / FLOOR_S).log10() * BINS_PER_DECADE) as usize;
        let last = self.bins.len() - 1;
        self.bins[i.min(last)] += 1;
        self.count += 1;
        self.max = self.max.max(d);
    }

    pub fn count(&self) -> u64 {
        self.count
    }

    pub fn max(&self) -> Duration {
        self.max
    }

    /// The `q`-quantile (0..=1): the upper edge of the bin that holds it (at most the
    /// maximum); zero when empty.
    pub fn quantile(&self, q: f64) -> Duration {
        if self.count == 0 {
            return Duration::ZERO;
        }
        let rank = ((q * self.count as f64).ceil() as u64).clamp(1, self.count);
        let mut seen = 0;
        for (i, n) in self.bins.iter().enumerate() {
            seen += n;
            if seen >= rank {
                let edge = FLOOR_S * 10f64.powf((i + 1) as f64 / BINS_PER_DECADE);
                return Duration::from_secs_f64(edge).min(self.max);
            }
        }
        self.max
    }

    /// `median m, p99 p, max x` in milliseconds.
    pub fn describe_ms(&self) -> String {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        format!(
            "median {:.3} ms, p99 {:.3} ms, max {:.3} ms",
            ms(self.quantile(0.5)),
            ms(self.quantile(0.99)),
            ms(self.max)
        )
    }
}

/// The deadlines of a paced run and what they measured.
#[derive(Debug)]
pub struct Pacer {
    start: Instant,
    t0: f64,
    factor: f64,
    pub lateness: Histogram,
    pub overruns: u64,
    /// The worst overrun so far.
    pub worst: Duration,
}

/// How a wait ended.
#[derive(Debug, PartialEq)]
pub enum Waited {
    /// On time, or late by the lateness recorded.
    Done,
    /// The interrupt flag was set while waiting.
    Interrupted,
}

/// Sleep in slices of at most this, so that Ctrl-C stops a slow pace at once.
const SLICE: Duration = Duration::from_millis(50);
/// The end of a wait is spun (yielding) rather than slept: the OS's sleep overshoots by
/// tens of microseconds.
const SPIN: Duration = Duration::from_micros(200);

impl Pacer {
    /// Deadlines from now, for simulated times from `t0` at `factor` times real time.
    pub fn new(t0: f64, factor: f64) -> Pacer {
        Pacer {
            start: Instant::now(),
            t0,
            factor,
            lateness: Histogram::default(),
            overruns: 0,
            worst: Duration::ZERO,
        }
    }

    /// The wall-clock deadline of simulated time `t`.
    pub fn deadline(&self, t: f64) -> Instant {
        self.start + Duration::from_secs_f64(((t - self.t0) / self.factor).max(0.0))
    }

    /// Waits for the deadline of `t` (returns at once when past it, counting an overrun) and
    /// records the lateness. True when the point was late.
    pub fn wait(&mut self, t: f64, interrupt: Option<&AtomicBool>) -> (Waited, bool) {
        let deadline = self.deadline(t);
        let now = Instant::now();
        let late = now > deadline;
        if late {
            let by = now - deadline;
            self.overruns += 1;
            self.worst = self.worst.max(by);
            self.lateness.add(by);
            return (Waited::Done, true);
        }
        loop {
            if interrupt.is_some_and(|f| f.load(Ordering::Relaxed)) {
                return (Waited::Interrupted, false);
            }
            let now = Instant::now();
            if now >= deadline {
                break;
            }
            let left = deadline - now;
            if left > SPIN {
                std::thread::sleep((left - SPIN).min(SLICE));
            } else {
                std::thread::yield_now();
            }
        }
        self.lateness.add(Instant::now() - deadline);
        (Waited::Done, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn histogram_quantiles_within_a_bin() {
        let mut h = Histogram::default();
        for i in 1..=1000u64 {
            h.add(Duration::from_micros(i));
        }
        let med = h.quantile(0.5).as_secs_f64();
        assert!((med - 500e-6).abs() / 500e-6 < 0.03, "{med}");
        let p99 = h.quantile(0.99).as_secs_f64();
        assert!((p99 - 990e-6).abs() / 990e-6 < 0.03, "{p99}");
        assert_eq!(h.max(), Duration::from_micros(1000));
        h.add(Duration::from_secs(5000));
        assert_eq!(h.count(), 1001);
        assert_eq!(Histogram::default().quantile(0.5), Duration::ZERO);
    }

    /// 40 deadlines 5 ms apart take 200 ms, not 40 sleeps' worth plus their overshoot; a
    /// late point is counted and the next deadline is still on the grid.
    #[test]
    fn deadlines_are_absolute() {
        let mut p = Pacer::new(0.0, 1.0);
        for k in 1..=40 {
            std::thread::sleep(Duration::from_micros(500));
            assert_eq!(p.wait(k as f64 * 0.005, None).0, Waited::Done);
        }
        // Never before the last deadline; the upper bound leaves room for a loaded machine
        // (the full suite runs tests in parallel), where a point may also come late.
        let el = p.start.elapsed().as_secs_f64();
        assert!((0.2..0.3).contains(&el), "{el}");
        let before = p.overruns;
        std::thread::sleep(Duration::from_millis(12));
        assert!(p.wait(0.205, None).1);
        assert_eq!(p.overruns, before + 1);
        let mut fast = Pacer::new(0.0, 10.0);
        fast.wait(1.0, None);
        let el = fast.start.elapsed().as_secs_f64();
        assert!((0.1..0.2).contains(&el), "{el}");
    }
}
