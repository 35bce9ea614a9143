//! Manoeuvring KPIs of a run: the streaming trackers of `models::manoeuvre` fed from the
//! recorded columns, judged against the IMO MSC.137(76) criteria.

use crate::run::Row;
use models::hull::DEG;
use models::manoeuvre::{imo, Sample, TurningCircleTracker, ZigZagMetrics, ZigZagTracker};

/// A ready-made manoeuvring KPI.
#[derive(Debug, Clone, PartialEq)]
pub enum Manoeuvre {
    /// Advance, transfer and tactical diameter; IMO: advance < 4.5 L, tactical diameter < 5 L.
    TurningCircle {
        x: String,
        y: String,
        heading: String,
    },
    /// First and second overshoot angles; IMO limits by check angle (10/10, 20/20) and L/U.
    ZigZag {
        heading: String,
        check_angle: f64,
        rudder_sign: f64,
        speed: f64,
    },
}

// Both trackers are a few hundred bytes; the KPI is boxed as a whole (kpi.rs).
#[allow(clippy::large_enum_variant)]
enum Tracker {
    Turning(TurningCircleTracker),
    ZigZag(ZigZagTracker),
}

/// One manoeuvring KPI bound to its recorded columns.
pub struct ManoeuvreKpi {
    tracker: Tracker,
    /// Columns of x, y, heading (turning circle) or heading (zig-zag).
    columns: Vec<usize>,
    length: f64,
    speed: f64,
    check_angle: f64,
}

impl ManoeuvreKpi {
    /// The KPI of `manoeuvre` executed at `execute_time` (s) by a ship of `length` (m);
    /// `columns` are the recorded columns of its variables (x, y, heading for a turning
    /// circle; heading for a zig-zag: the campaign's `KpiSpec::variables`).
    pub fn new(
        manoeuvre: &Manoeuvre,
        execute_time: f64,
        length: f64,
        columns: &[usize],
    ) -> ManoeuvreKpi {
        let (tracker, speed, check_angle) = match manoeuvre {
            Manoeuvre::TurningCircle { .. } => (
                Tracker::Turning(TurningCircleTracker::new(execute_time)),
                f64::NAN,
                f64::NAN,
            ),
            Manoeuvre::ZigZag {
                check_angle,
                rudder_sign,
                speed,
                ..
            } => (
                Tracker::ZigZag(ZigZagTracker::new(execute_time, *rudder_sign, *check_angle)),
                *speed,
                *check_angle,
            ),
        };
        ManoeuvreKpi {
            tracker,
            columns: columns.to_vec(),
            length,
            speed,
            check_angle,
        }
    }

    #[inline]
    pub fn push(&mut self, t: f64, row: &Row<'_>) {
        let v = |j: usize| row.get(self.columns[j]).as_f64();
        match &mut self.tracker {
            Tracker::Turning(tr) => tr.push(&Sample {
                t,
                x: v(0),
                y: v(1),
                psi: v(2),
                ..Sample::default()
            }),
            Tracker::ZigZag(tr) => tr.push(&Sample {
                t,
                psi: v(0),
                ..Sample::default()
            }),
        }
    }

    /// The KPI's metrics and its IMO verdict (None: not judged), in the order of its columns
    /// (advance, transfer, tactical diameter; first and second overshoot; the verdict last);
    /// NaN and None where the run did not reach the event a metric needs.
    pub fn values(&self) -> (Vec<f64>, Option<bool>) {
        match &self.tracker {
            Tracker::Turning(tr) => match tr.finish() {
                Ok(m) => {
                    let pass = imo::check_turning(&m, self.length).ok().map(|c| c.pass);
                    (vec![m.advance, m.transfer, m.tactical_diameter], pass)
                }
                Err(_) => (vec![f64::NAN; 3], None),
            },
            Tracker::ZigZag(tr) => match tr.finish() {
                Ok(m) => {
                    let pass = self.zigzag_pass(&m);
                    (vec![m.first_overshoot, m.second_overshoot], pass)
                }
                Err(_) => (vec![f64::NAN; 2], None),
            },
        }
    }

    /// The IMO yaw-checking verdict: the 10°/10° limits (by L/U) for a 10° check angle, the
    /// 20°/20° limit for 20°, none for other tests.
    fn zigzag_pass(&self, m: &ZigZagMetrics) -> Option<bool> {
        let is = |deg: f64| (self.check_angle - deg * DEG).abs() < 1e-9;
        if is(10.0) {
            imo::check_zigzag_10_10(m, self.length, self.speed)
                .ok()
                .map(|c| c.pass)
        } else if is(20.0) {
            Some(imo::check_zigzag_20_20(m).pass)
        } else {
            None
        }
    }
}
