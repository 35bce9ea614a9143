//! Where the step loop's wall time goes, per instance: in `fmi2DoStep`, in the exchange
//! (`fmi2SetXxx`/`fmi2GetXxx` with the gather of inputs, and the events' `fmi2SetXxx`), and in
//! the master's own work (recording, scheduling, progress, interruption checks).
//!
//! **Method: deterministic sampling.** Reading the clock around every FMI call (about 25 ns per
//! `Instant::now` here, about 3 reads per instance and macro step) would cost more than the
//! 1 % allowed when a whole macro step costs a few µs. So only the macro steps k with
//! `k % every == every / 2` are timed ([`Sampling`]; by default 1 in [`STRIDE`] = 127), in
//! full: one clock read at the start of the step and one after each FMI call or batch (a lap,
//! [`Probe::lap`]), the time since the previous read going to that call's instance and kind,
//! and the rest (everything between the calls and after them: event lookup, recording,
//! progress) to the master. The other steps run the same code with a probe that does nothing
//! ([`Off`]), monomorphized away; the loop compares k with the next sampled step once per
//! step. The default stride is a prime, co-prime with every step multiple below it, so an
//! instance stepping every m-th macro step (k % m == 0) is timed in the same proportion of the
//! sampled steps as of all steps (k ≡ 63 mod 127 visits every residue mod m equally, by the
//! Chinese remainder theorem): the per-macro-step means are unbiased for multi-rate systems.
//! The phase every / 2 keeps the cold first step out of the sample.
//!
//! Why 127 and not 61: a clock read also waits for the instructions before it (the vDSO reads
//! the TSC ordered), so in a step of real FMUs a read costs up to about twice its back-to-back
//! cost. Measured on `systems/dgps_trial.toml` (6 FMUs, 1.6 µs per macro step, 13 reads per
//! timed step), 1 in 61 cost 0.7-1.4 % of the step loop (the fastest and the median of 60
//! alternating runs each); 1 in 127 halves that, which keeps a 7-FMU system at 3 µs per macro
//! step below 1 %.
//!
//! **Limit: rare costly steps.** Work an FMU does on few steps (an estimator's update every
//! n-th step) is caught only by the sampled steps that fall on it: a run of a few thousand
//! steps has a few dozen sampled steps, so such work is missed or over-weighted by chance. The
//! sampled sum per macro step is then far from the step loop's measured time per macro step
//! (over all steps), and the table says so. `Sampling { every: 1 }` times every step
//! (`--profile-every 1`; about 10 % overhead, its shares are exact up to the clock-read
//! correction).
//!
//! Each lap's interval also holds about one clock read; the cost of a read is measured before
//! the loop (the fastest of 20 runs of 50 back-to-back reads) and subtracted once per lap
//! (per bucket total, clamped at zero). What a read costs beyond that (the wait for the
//! instructions before it) stays in the intervals: calls of a few ns (the trivial C test FMU)
//! come out up to twice their cost, calls of a µs and more are not affected measurably. A
//! sampled step also runs colder code than the steps around it (the timed copy of the step
//! runs 1 in 127 steps), so its sum per macro step can exceed the loop's mean for systems of
//! well under a µs per macro step. The instances' bookkeeping between two calls (the `k % m`
//! test, a few ns) counts to the following call. `fmi2DoStep` calls are counted in every step,
//! not sampled.
//!
//! The library prints nothing: the [`Profile`] comes back in [`super::Summary::profile`]; its
//! `Display` is the CLI's table and [`Profile::to_json`] its machine-readable form.

use std::time::{Duration, Instant};

/// The default sampling stride: 1 in 127 macro steps is timed (a prime).
pub const STRIDE: u64 = 127;

/// Which macro steps a profiled run times: k with `k % every == every / 2`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampling {
    /// 1 = every step. Choose a prime above the step multiples (multi-rate instances).
    pub every: u64,
}

impl Default for Sampling {
    fn default() -> Sampling {
        Sampling { every: STRIDE }
    }
}

impl Sampling {
    /// Whether macro step k is timed.
    pub fn sampled(&self, k: u64) -> bool {
        let every = self.every.max(1);
        k % every == every / 2
    }

    /// The first timed macro step from k on.
    pub fn next(&self, k: u64) -> u64 {
        let every = self.every.max(1);
        k + (every / 2 + every - k % every) % every
    }
}

/// What a lap's time is spent on.
#[derive(Clone, Copy, Debug)]
pub enum Lap {
    /// The master's own work since the last lap.
    Master,
    /// `fmi2DoStep` of instance i.
    DoStep(usize),
    /// Set inputs, events or get outputs of instance i.
    Exchange(usize),
}

/// A timer handed through a macro step: `lap` attributes the time since the previous lap.
pub trait Probe {
    fn lap(&mut self, to: Lap);
}

/// No timing (every step of an unprofiled run, the unsampled steps of a profiled one).
pub struct Off;

impl Probe for Off {
    #[inline(always)]
    fn lap(&mut self, _: Lap) {}
}

/// Raw sums of a profiled run, allocated before the loop.
#[derive(Debug, Clone)]
pub struct Accumulator {
    /// Per instance: [doStep, exchange] nanoseconds and laps.
    ns: Vec<[u64; 2]>,
    laps: Vec<[u64; 2]>,
    master_ns: u64,
    master_laps: u64,
    sampled_steps: u64,
    /// Cost of one clock read [ns].
    clock_read_ns: f64,
    pub sampling: Sampling,
}

impl Accumulator {
    /// For `n` instances; measures the cost of a clock read.
    pub fn new(n: usize, sampling: Sampling) -> Accumulator {
        Accumulator {
            sampling,
            ns: vec![[0; 2]; n],
            laps: vec![[0; 2]; n],
            master_ns: 0,
            master_laps: 0,
            sampled_steps: 0,
            clock_read_ns: clock_read_ns(),
        }
    }

    /// Starts timing one macro step.
    pub fn start(&mut self) -> Timer<'_> {
        self.sampled_steps += 1;
        Timer {
            last: Instant::now(),
            acc: self,
        }
    }
}

/// The timing probe of one sampled macro step.
pub struct Timer<'a> {
    last: Instant,
    acc: &'a mut Accumulator,
}

impl Probe for Timer<'_> {
    #[inline]
    fn lap(&mut self, to: Lap) {
        let now = Instant::now();
        let ns = now.duration_since(self.last).as_nanos() as u64;
        self.last = now;
        let a = &mut *self.acc;
        let (i, kind) = match to {
            Lap::Master => {
                a.master_ns += ns;
                a.master_laps += 1;
                return;
            }
            Lap::DoStep(i) => (i, 0),
            Lap::Exchange(i) => (i, 1),
        };
        a.ns[i][kind] += ns;
        a.laps[i][kind] += 1;
    }
}

/// The cost of one `Instant::now()` [ns]: the fastest of 20 runs of 50 back-to-back reads.
fn clock_read_ns() -> f64 {
    const READS: u32 = 50;
    let mut best = Duration::MAX;
    for _ in 0..20 {
        let t0 = Instant::now();
        let mut last = t0;
        for _ in 0..READS {
            last = std::hint::black_box(Instant::now());
        }
        best = best.min(last - t0);
    }
    best.as_nanos() as f64 / f64::from(READS)
}

/// One instance's cost over the sampled macro steps (corrected for the clock reads).
#[derive(Debug, Clone)]
pub struct InstanceCost {
    pub name: String,
    /// `fmi2DoStep` calls in the whole run (counted in every step).
    pub do_step_calls: u64,
    /// Time in `fmi2DoStep`, summed over the sampled steps.
    pub do_step: Duration,
    /// Time in the exchange (set inputs, events, get outputs), summed over the sampled steps.
    pub exchange: Duration,
}

/// Where the step loop's time went: per instance and the master, over the sampled macro steps
/// (module doc: the method). Shares are of the sampled total, so they sum to 100 %.
#[derive(Debug, Clone)]
pub struct Profile {
    /// Every `stride`-th macro step was timed.
    pub stride: u64,
    pub sampled_steps: u64,
    pub macro_steps: u64,
    /// Wall time of the whole step loop (all steps, measured, not sampled).
    pub loop_wall: Duration,
    /// The cost of one clock read, subtracted per lap [ns].
    pub clock_read_ns: f64,
    /// Clock reads made by the profile in the run.
    pub clock_reads: u64,
    pub instances: Vec<InstanceCost>,
    /// The master's own work, summed over the sampled steps.
    pub master: Duration,
}

impl Profile {
    /// The profile of a run from its accumulator, the instances' names and doStep counts.
    pub fn new(
        acc: &Accumulator,
        instances: impl IntoIterator<Item = (String, u64)>,
        macro_steps: u64,
        loop_wall: Duration,
    ) -> Profile {
        let c = acc.clock_read_ns;
        let net = |ns: u64, laps: u64| {
            Duration::from_nanos((ns as f64 - laps as f64 * c).max(0.0).round() as u64)
        };
        let instances = instances
            .into_iter()
            .zip(acc.ns.iter().zip(&acc.laps))
            .map(|((name, do_step_calls), (ns, laps))| InstanceCost {
                name,
                do_step_calls,
                do_step: net(ns[0], laps[0]),
                exchange: net(ns[1], laps[1]),
            })
            .collect();
        let laps: u64 = acc.laps.iter().flatten().sum::<u64>() + acc.master_laps;
        Profile {
            stride: acc.sampling.every.max(1),
            sampled_steps: acc.sampled_steps,
            macro_steps,
            loop_wall,
            clock_read_ns: c,
            // One read at the start of each sampled step and one per lap.
            clock_reads: laps + acc.sampled_steps,
            instances,
            master: net(acc.master_ns, acc.master_laps),
        }
    }

    /// The sampled total: instances and master.
    pub fn total(&self) -> Duration {
        self.instances
            .iter()
            .map(|i| i.do_step + i.exchange)
            .sum::<Duration>()
            + self.master
    }

    /// `d` (a sampled sum) as a percentage of the sampled total.
    pub fn share(&self, d: Duration) -> f64 {
        100.0 * d.as_secs_f64() / self.total().as_secs_f64().max(1e-300)
    }

    /// `d` (a sampled sum) per macro step [µs].
    pub fn us_per_step(&self, d: Duration) -> f64 {
        d.as_secs_f64() * 1e6 / self.sampled_steps.max(1) as f64
    }

    /// The step loop's measured time per macro step, over all steps [µs].
    pub fn loop_us_per_step(&self) -> f64 {
        self.loop_wall.as_secs_f64() * 1e6 / self.macro_steps.max(1) as f64
    }

    /// The profile's own clock reads as a fraction of the step loop's wall time (an estimate
    /// of its overhead: reads times the cost of one).
    pub fn overhead(&self) -> f64 {
        self.clock_reads as f64 * self.clock_read_ns * 1e-9
            / self.loop_wall.as_secs_f64().max(1e-300)
    }

    /// The instance with the largest share (doStep and exchange), if any.
    pub fn most_expensive(&self) -> Option<&InstanceCost> {
        self.instances.iter().max_by_key(|i| i.do_step + i.exchange)
    }

    /// The profile as JSON: per instance and for the master µs per macro step and shares [%].
    pub fn to_json(&self) -> serde_json::Value {
        let cost = |d: Duration| (self.us_per_step(d), self.share(d));
        let instances: Vec<serde_json::Value> = self
            .instances
            .iter()
            .map(|i| {
                let (ds_us, ds_share) = cost(i.do_step);
                let (ex_us, ex_share) = cost(i.exchange);
                let (us, share) = cost(i.do_step + i.exchange);
                serde_json::json!({
                    "name": i.name,
                    "do_step_calls": i.do_step_calls,
                    "do_step_us": ds_us,
                    "do_step_share": ds_share,
                    "exchange_us": ex_us,
                    "exchange_share": ex_share,
                    "us": us,
                    "share": share,
                })
            })
            .collect();
        let (master_us, master_share) = cost(self.master);
        serde_json::json!({
            "method": format!("sampled: 1 in {} macro steps timed in full", self.stride),
            "stride": self.stride,
            "sampled_steps": self.sampled_steps,
            "macro_steps": self.macro_steps,
            "loop_wall_s": self.loop_wall.as_secs_f64(),
            "loop_us_per_step": self.loop_us_per_step(),
            "sampled_us_per_step": self.us_per_step(self.total()),
            "clock_read_ns": self.clock_read_ns,
            "clock_reads": self.clock_reads,
            "overhead_share": 100.0 * self.overhead(),
            "instances": instances,
            "master_us": master_us,
            "master_share": master_share,
        })
    }
}

impl std::fmt::Display for Profile {
    /// A table: per instance doStep calls, then doStep, get/set and total in µs per macro step
    /// and % of the step loop; the master; the sum; the measured loop and the overhead.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let w = self
            .instances
            .iter()
            .map(|i| i.name.len())
            .chain([20])
            .max()
            .unwrap_or(20);
        writeln!(
            f,
            "profile (sampled: {} of {} macro steps timed in full, 1 in {}; µs per macro step and % of the step loop)",
            self.sampled_steps, self.macro_steps, self.stride
        )?;
        writeln!(
            f,
            "{:<w$} {:>12}  {:>16}  {:>16}  {:>16}",
            "instance", "doStep calls", "doStep", "get/set", "total"
        )?;
        let cell = |d: Duration| format!("{:>8.3} {:>5.1} %", self.us_per_step(d), self.share(d));
        for i in &self.instances {
            writeln!(
                f,
                "{:<w$} {:>12}  {}  {}  {}",
                i.name,
                i.do_step_calls,
                cell(i.do_step),
                cell(i.exchange),
                cell(i.do_step + i.exchange)
            )?;
        }
        let blank = " ".repeat(16);
        writeln!(
            f,
            "{:<w$} {:>12}  {blank}  {blank}  {}",
            "master (own work)",
            "",
            cell(self.master)
        )?;
        writeln!(
            f,
            "{:<w$} {:>12}  {blank}  {blank}  {}",
            "sum",
            "",
            cell(self.total())
        )?;
        let covered = self.us_per_step(self.total()) / self.loop_us_per_step().max(1e-300);
        write!(
            f,
            "step loop measured over all {} macro steps: {:.3} µs per macro step, of which the sample's sum is {:.0} %; the profile's {} clock reads ({:.1} ns each, subtracted) cost about {:.2} % of it",
            self.macro_steps,
            self.loop_us_per_step(),
            100.0 * covered,
            self.clock_reads,
            self.clock_read_ns,
            100.0 * self.overhead()
        )?;
        if self.stride > 1 && covered < 0.9 {
            write!(
                f,
                "\nthe sample misses {:.0} % of the step loop: work done on few steps (rarer than 1 in {}) falls between the sampled steps; `--profile-every 1` times every step (about 10 % overhead)",
                100.0 * (1.0 - covered),
                self.stride
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_is_the_first_sampled_step_from_k_on() {
        for every in [1, 2, 61, 127] {
            let s = Sampling { every };
            for k in 0..500 {
                let expected = (k..).find(|&j| s.sampled(j)).unwrap();
                assert_eq!(s.next(k), expected, "every {every}, k = {k}");
            }
        }
        let s = Sampling::default();
        assert_eq!((s.next(0), s.next(64)), (63, 190));
        assert_eq!(Sampling { every: 1 }.next(5), 5);
    }
}
