//! KPIs of a run, computed on the fly: a [`KpiRecorder`] is a [`Recorder`] that feeds every
//! recorded row into one accumulator per KPI and keeps no time series.
//!
//! Window statistics are over the recorded samples with `t0 <= t <= t1` (every base step when
//! the campaign records, see [`super::Campaign`]), after multiplying by the KPI's `scale`:
//!
//! | stat | value |
//! |---|---|
//! | `mean`, `variance`, `std` | sample mean; population variance (divided by n) and its root, by Welford's update |
//! | `rms` | sqrt(sum x² / n) |
//! | `min`, `max`, `max_abs` | extremes of x and of \|x\| |
//! | `final` | the last sample in the window |
//! | `time_above` | sum of t_(i+1) − t_i over consecutive window samples with x_i > threshold (outputs are held over a step) |
//! | `first_time` | the first sample time with x > above (or x < below); NaN if never |
//! | `settling_time` | from t0 to the first sample after which every sample has \|x − target\| ≤ band; NaN if the last sample is outside |
//!
//! A window with no sample gives NaN. A NaN in any recorded variable fails the run
//! ([`KpiRecorder::nan`] says where).
//!
//! Manoeuvring KPIs feed the streaming trackers of `models::manoeuvre` (IMO MSC.137(76)).

use super::manoeuvre::ManoeuvreKpi;
use crate::error::{Error, Result};
use crate::run::{ColumnInfo, Recorder, Row, Sample};

pub use super::manoeuvre::Manoeuvre;

/// A statistic over a time window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stat {
    Mean,
    Variance,
    Std,
    Rms,
    Min,
    Max,
    MaxAbs,
    Final,
    TimeAbove { threshold: f64 },
    FirstAbove(f64),
    FirstBelow(f64),
    Settling { target: f64, band: f64 },
}

/// A KPI declared in the campaign file.
#[derive(Debug, Clone, PartialEq)]
pub enum KpiSpec {
    Stat {
        name: String,
        variable: String,
        stat: Stat,
        window: (f64, f64),
        scale: f64,
    },
    Manoeuvre {
        name: String,
        manoeuvre: Manoeuvre,
        execute_time: f64,
        length: f64,
    },
}

/// One KPI value in the run table.
#[derive(Debug, Clone, PartialEq)]
pub enum KpiValue {
    Number(f64),
    /// "pass" or "fail" (IMO criteria); "" when not judged.
    Verdict(&'static str),
}

impl KpiSpec {
    pub fn name(&self) -> &str {
        match self {
            KpiSpec::Stat { name, .. } | KpiSpec::Manoeuvre { name, .. } => name,
        }
    }

    /// The run-table columns this KPI fills, in order.
    pub fn columns(&self) -> Vec<String> {
        let n = self.name();
        let suffixes: &[&str] = match self {
            KpiSpec::Stat { .. } => return vec![n.to_string()],
            KpiSpec::Manoeuvre {
                manoeuvre: Manoeuvre::TurningCircle { .. },
                ..
            } => &["advance", "transfer", "tactical_diameter", "imo"],
            KpiSpec::Manoeuvre {
                manoeuvre: Manoeuvre::ZigZag { .. },
                ..
            } => &["first_overshoot", "second_overshoot", "imo"],
        };
        suffixes.iter().map(|s| format!("{n}_{s}")).collect()
    }

    /// Whether column `j` of [`KpiSpec::columns`] is a verdict (pass/fail) column.
    pub fn is_verdict(&self, j: usize) -> bool {
        matches!(self, KpiSpec::Manoeuvre { .. }) && j + 1 == self.columns().len()
    }

    /// The recorded variables (`instance.variable`) the KPI reads.
    pub fn variables(&self) -> Vec<&str> {
        match self {
            KpiSpec::Stat { variable, .. } => vec![variable],
            KpiSpec::Manoeuvre {
                manoeuvre: Manoeuvre::TurningCircle { x, y, heading },
                ..
            } => vec![x, y, heading],
            KpiSpec::Manoeuvre {
                manoeuvre: Manoeuvre::ZigZag { heading, .. },
                ..
            } => vec![heading],
        }
    }

    /// The earliest time the KPI looks at.
    pub fn start(&self) -> f64 {
        match self {
            KpiSpec::Stat { window, .. } => window.0,
            KpiSpec::Manoeuvre { .. } => f64::NEG_INFINITY,
        }
    }
}

/// The running state of one window statistic.
#[derive(Debug, Clone, Copy)]
pub struct StatAccumulator {
    pub stat: Stat,
    pub window: (f64, f64),
    pub scale: f64,
    n: u64,
    mean: f64,
    m2: f64,
    sum_sq: f64,
    min: f64,
    max: f64,
    last: f64,
    prev: Option<(f64, f64)>,
    time_above: f64,
    first: Option<f64>,
    settled_since: Option<f64>,
}

impl StatAccumulator {
    pub fn new(stat: Stat, window: (f64, f64), scale: f64) -> StatAccumulator {
        StatAccumulator {
            stat,
            window,
            scale,
            n: 0,
            mean: 0.0,
            m2: 0.0,
            sum_sq: 0.0,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            last: f64::NAN,
            prev: None,
            time_above: 0.0,
            first: None,
            settled_since: None,
        }
    }

    /// One sample (the raw value; the scale is applied here).
    #[inline]
    pub fn push(&mut self, t: f64, raw: f64) {
        if t < self.window.0 || t > self.window.1 {
            return;
        }
        let x = raw * self.scale;
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
        self.sum_sq += x * x;
        self.min = self.min.min(x);
        self.max = self.max.max(x);
        self.last = x;
        match self.stat {
            Stat::TimeAbove { threshold } => {
                if let Some((tp, xp)) = self.prev {
                    if xp > threshold {
                        self.time_above += t - tp;
                    }
                }
            }
            Stat::FirstAbove(a) if self.first.is_none() && x > a => self.first = Some(t),
            Stat::FirstBelow(b) if self.first.is_none() && x < b => self.first = Some(t),
            Stat::Settling { target, band } => {
                if (x - target).abs() > band {
                    self.settled_since = None;
                } else if self.settled_since.is_none() {
                    self.settled_since = Some(t);
                }
            }
            _ => {}
        }
        self.prev = Some((t, x));
    }

    /// The statistic (NaN for an empty window).
    pub fn value(&self) -> f64 {
        if self.n == 0 {
            return f64::NAN;
        }
        let n = self.n as f64;
        let t0 = self.window.0;
        match self.stat {
            Stat::Mean => self.mean,
            Stat::Variance => self.m2 / n,
            Stat::Std => (self.m2 / n).sqrt(),
            Stat::Rms => (self.sum_sq / n).sqrt(),
            Stat::Min => self.min,
            Stat::Max => self.max,
            Stat::MaxAbs => self.max.abs().max(self.min.abs()),
            Stat::Final => self.last,
            Stat::TimeAbove { .. } => self.time_above,
            Stat::FirstAbove(_) | Stat::FirstBelow(_) => self.first.unwrap_or(f64::NAN),
            Stat::Settling { .. } => self
                .settled_since
                .map_or(f64::NAN, |t| t - if t0.is_finite() { t0 } else { 0.0 }),
        }
    }
}

/// One KPI's accumulator, bound to recorded columns.
enum Accumulator {
    Stat { column: usize, acc: StatAccumulator },
    Manoeuvre(Box<ManoeuvreKpi>),
}

/// The KPIs of one run, as a [`Recorder`].
pub struct KpiRecorder<'a> {
    specs: &'a [KpiSpec],
    accumulators: Vec<Accumulator>,
    columns: Vec<ColumnInfo>,
    nan: Option<(String, f64)>,
}

impl<'a> KpiRecorder<'a> {
    pub fn new(specs: &'a [KpiSpec]) -> KpiRecorder<'a> {
        KpiRecorder {
            specs,
            accumulators: Vec::new(),
            columns: Vec::new(),
            nan: None,
        }
    }

    /// Where a recorded variable first was NaN: (column, time).
    pub fn nan(&self) -> Option<&(String, f64)> {
        self.nan.as_ref()
    }

    /// The KPI values, in the order of [`KpiSpec::columns`] over the specs.
    pub fn values(&self) -> Vec<KpiValue> {
        let mut out = Vec::new();
        for a in &self.accumulators {
            match a {
                Accumulator::Stat { acc, .. } => out.push(KpiValue::Number(acc.value())),
                Accumulator::Manoeuvre(m) => {
                    let (numbers, pass) = m.values();
                    out.extend(numbers.into_iter().map(KpiValue::Number));
                    out.push(KpiValue::Verdict(match pass {
                        Some(true) => "pass",
                        Some(false) => "fail",
                        None => "",
                    }));
                }
            }
        }
        out
    }
}

/// The KPI values of a run that did not produce them (a failed run): NaN and "".
pub fn missing_values(specs: &[KpiSpec]) -> Vec<KpiValue> {
    let mut out = Vec::new();
    for k in specs {
        for j in 0..k.columns().len() {
            out.push(if k.is_verdict(j) {
                KpiValue::Verdict("")
            } else {
                KpiValue::Number(f64::NAN)
            });
        }
    }
    out
}

impl Recorder for KpiRecorder<'_> {
    fn start(&mut self, columns: &[ColumnInfo], _expected_rows: u64) -> Result<()> {
        let find = |v: &str| {
            columns.iter().position(|c| c.name == v).ok_or_else(|| {
                Error::Other(format!("KPI variable '{v}' is not recorded by the run"))
            })
        };
        self.columns = columns.to_vec();
        self.accumulators.clear();
        for k in self.specs {
            self.accumulators.push(match k {
                KpiSpec::Stat {
                    variable,
                    stat,
                    window,
                    scale,
                    ..
                } => Accumulator::Stat {
                    column: find(variable)?,
                    acc: StatAccumulator::new(*stat, *window, *scale),
                },
                KpiSpec::Manoeuvre {
                    manoeuvre,
                    execute_time,
                    length,
                    ..
                } => {
                    let cols = k
                        .variables()
                        .into_iter()
                        .map(find)
                        .collect::<Result<Vec<_>>>()?;
                    let m = ManoeuvreKpi::new(manoeuvre, *execute_time, *length, &cols);
                    Accumulator::Manoeuvre(Box::new(m))
                }
            });
        }
        Ok(())
    }

    #[inline]
    fn record(&mut self, time: f64, row: &Row<'_>) -> Result<()> {
        for j in 0..row.len() {
            if matches!(row.get(j), Sample::Real(x) if x.is_nan()) {
                let name = self.columns[j].name.clone();
                let e = Error::Other(format!("'{name}' is NaN at t = {time} s"));
                self.nan = Some((name, time));
                return Err(e);
            }
        }
        for a in &mut self.accumulators {
            match a {
                Accumulator::Stat { column, acc } => acc.push(time, row.get(*column).as_f64()),
                Accumulator::Manoeuvre(m) => m.push(time, row),
            }
        }
        Ok(())
    }
}
