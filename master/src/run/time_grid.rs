//! The communication points of a run.
//!
//! Communication points are computed from the integer step index k, never accumulated. When
//! t0 and h are whole numbers of nanoseconds (the usual case) t_k is the double nearest to
//! t0 + k*h taken exactly in nanoseconds, (t0_ns + k*h_ns)/1e9, which is how libcosim keeps its
//! clock (integer ns; `to_double_time_point`), otherwise t0 + k*h. Instance i steps at every k
//! divisible by its step multiple m_i, from t_k with size t_(k+m_i) - t_k, so that t + h is
//! exactly the next communication point (libcosim's `to_double_duration` rule). With both rules
//! shipsim hands every FMU bit-for-bit the times and step sizes libcosim does.
//!
//! A stop time off the grid ends the run in one of two ways ([`LastStep`]): at the last grid
//! point before it (the default, libcosim's way), or with a shorter last step to the stop time
//! itself (FMPy's way: `fmpy.simulation.simulateCS` sets the last communication point to the
//! stop time when the FMU declares canHandleVariableCommunicationStepSize, FMI 2.0, sec. 4.3.1).
//! Then t_n is the stop time and every other t_k is as above.

use crate::system::LastStep;

/// The communication points t_k (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeGrid {
    t0: f64,
    h: f64,
    /// (t0, h) in whole nanoseconds, when both are and t_n stays exact in an i64.
    ns: Option<(i64, i64)>,
    n_steps: u64,
    /// t_n: the grid point, or the stop time after a short last step.
    end: f64,
}

impl TimeGrid {
    /// The grid from t0 with base step h over `n_steps` steps.
    pub fn new(t0: f64, h: f64, n_steps: u64) -> TimeGrid {
        let whole_ns = |x: f64| {
            let n = (x * 1e9).round();
            (n.abs() < 1e15 && n / 1e9 == x).then_some(n as i64)
        };
        let ns = match (whole_ns(t0), whole_ns(h)) {
            (Some(a), Some(b)) if b > 0 && (n_steps as f64) * (b as f64) < 4e18 => Some((a, b)),
            _ => None,
        };
        let mut grid = TimeGrid {
            t0,
            h,
            ns,
            n_steps,
            end: 0.0,
        };
        grid.end = grid.on_grid(n_steps);
        grid
    }

    /// The same grid with its last step ending at `stop` (a short last step, [`LastStep`]).
    pub fn ending_at(self, stop: f64) -> TimeGrid {
        TimeGrid { end: stop, ..self }
    }

    /// The grid of a plan: with a short last step ([`LastStep::Short`]), t_n is its stop time.
    pub fn of(plan: &crate::system::Plan) -> TimeGrid {
        let grid = TimeGrid::new(plan.start_time, plan.step_size, plan.n_steps);
        match plan.off_grid {
            Some(o) if o.last_step == LastStep::Short => grid.ending_at(plan.stop_time),
            _ => grid,
        }
    }

    /// The number of base steps of the run.
    pub fn n_steps(&self) -> u64 {
        self.n_steps
    }

    /// t_k.
    #[inline]
    pub fn at(&self, k: u64) -> f64 {
        if k == self.n_steps {
            self.end
        } else {
            self.on_grid(k)
        }
    }

    /// t0 + k*h (see the module documentation).
    #[inline]
    fn on_grid(&self, k: u64) -> f64 {
        match self.ns {
            Some((t0, h)) => (t0 + k as i64 * h) as f64 / 1e9,
            None => self.t0 + k as f64 * self.h,
        }
    }

    /// Step size of an instance stepping at k with step multiple m: t_(k+m) - t_k, shortened to
    /// t_n - t_k at the end of the run if the FMU can take a variable step, else None (the last
    /// partial step is dropped).
    #[inline]
    pub fn step_size(&self, k: u64, m: u64, n_steps: u64, var_step: bool) -> Option<f64> {
        if k + m <= n_steps {
            Some(self.at(k + m) - self.at(k))
        } else if var_step {
            Some(self.at(n_steps) - self.at(k))
        } else {
            None
        }
    }
}
