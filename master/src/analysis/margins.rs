//! Stability margins from measured points of L(jω): the crossings are bracketed on the
//! frequency grid, then refined by more forks (secant steps in log ω) so that the margins are
//! those of measured points at the crossings, not of an interpolation between grid points.
//!
//! - gain crossover ω_c: |L| = 1; phase margin PM = 180° + ∠L(jω_c) (wrapped to ±180°);
//!   delay margin PM[rad]/ω_c (a pure delay that uses the phase margin up);
//! - phase crossover ω_180: ∠L = −180° (mod 360°); gain margin GM = −20·log10|L(jω_180)|;
//! - with several crossings, each is listed, and the one closest to −1 (the smallest |margin|,
//!   its sign kept, as MATLAB's `margin` does) is the margin; the delay margin is the least
//!   delay over the gain crossovers, (180° + ∠L) mod 360° of lag at each;
//! - the sensitivity peak is max |1/(1 + L)| over the measured points.

use super::fork::Work;
use super::{LoopPoint, Options};
use crate::error::Result;
use num_complex::Complex64;
use rayon::prelude::*;

/// Secant steps per crossing.
const REFINE_STEPS: usize = 4;
/// A crossing closer than this (dB for the gain, degrees for the phase) needs no more steps.
const CLOSE_ENOUGH: f64 = 1e-3;

/// The margins of a loop (None where the loop has no such crossing in the measured range).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Margins {
    pub gain_margin_db: Option<f64>,
    pub gain_margin_rad_s: Option<f64>,
    pub phase_margin_deg: Option<f64>,
    pub crossover_rad_s: Option<f64>,
    pub delay_margin_s: Option<f64>,
    pub sensitivity_peak: f64,
    pub sensitivity_peak_rad_s: f64,
    /// Every gain crossover (|L| = 1) with its phase margin [deg], in frequency order.
    pub gain_crossovers: Vec<Crossing>,
    /// Every phase crossover (angle L = -180 deg) with its gain margin [dB].
    pub phase_crossovers: Vec<Crossing>,
}

/// A crossing: its frequency [rad/s] and the margin there.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Crossing {
    pub omega: f64,
    pub margin: f64,
}

/// A quantity of L that is zero at a crossing.
type Measure = fn(Complex64) -> f64;

fn gain_db(l: Complex64) -> f64 {
    20.0 * l.norm().log10()
}

/// ∠L + 180°, wrapped to (−180°, 180°]: zero at a phase crossover.
fn phase_from_180(l: Complex64) -> f64 {
    let p = l.arg().to_degrees() + 180.0;
    let w = p.rem_euclid(360.0);
    match w > 180.0 {
        true => w - 360.0,
        false => w,
    }
}

/// Where f changes sign between neighbours (and is continuous there: both within ±90 for
/// the wrapped phase).
fn brackets(points: &[LoopPoint], f: fn(Complex64) -> f64, wrapped: bool) -> Vec<(f64, f64)> {
    points
        .windows(2)
        .filter(|w| {
            let (a, b) = (f(w[0].l), f(w[1].l));
            a.signum() != b.signum() && (!wrapped || (a.abs() < 90.0 && b.abs() < 90.0))
        })
        .map(|w| (w[0].omega, w[1].omega))
        .collect()
}

/// Secant steps in log ω on f between `lo` and `hi`: the measured points, the last one at the
/// crossing.
fn refine(
    work: &Work,
    opts: &Options,
    lo: LoopPoint,
    hi: LoopPoint,
    f: fn(Complex64) -> f64,
) -> Result<Vec<LoopPoint>> {
    let (mut a, mut b) = (lo, hi);
    let mut found = Vec::new();
    for _ in 0..REFINE_STEPS {
        let (fa, fb) = (f(a.l), f(b.l));
        if fa.abs().min(fb.abs()) < CLOSE_ENOUGH {
            break;
        }
        let (la, lb) = (a.omega.ln(), b.omega.ln());
        let w = (la - fa * (lb - la) / (fb - fa)).exp();
        let snapped = work.length(w).omega;
        if snapped == a.omega || snapped == b.omega {
            break;
        }
        let p = work
            .loop_points(&[w], opts.amplitude, false)?
            .pop()
            .expect("one frequency");
        match f(p.l).signum() == fa.signum() {
            true => a = p.clone(),
            false => b = p.clone(),
        }
        found.push(p);
    }
    Ok(found)
}

/// The value of f's crossing between the two closest points around it: the crossing
/// frequency and `g` there, both by linear interpolation in log ω.
fn crossing(
    a: &LoopPoint,
    b: &LoopPoint,
    f: fn(Complex64) -> f64,
    g: impl Fn(&LoopPoint) -> f64,
) -> (f64, f64) {
    let (fa, fb) = (f(a.l), f(b.l));
    let s = match fb == fa {
        true => 0.0,
        false => fa / (fa - fb),
    };
    let w = (a.omega.ln() + s * (b.omega.ln() - a.omega.ln())).exp();
    (w, g(a) + s * (g(b) - g(a)))
}

/// Measures L on the grid, refines every crossing and computes the margins.
pub fn measure(work: &Work, freqs: &[f64], opts: &Options) -> Result<(Vec<LoopPoint>, Margins)> {
    let points = work.loop_points(freqs, opts.amplitude, opts.linearity)?;
    refine_all(work, points, opts)
}

/// Refines every crossing of measured grid `points` (measured here or elsewhere: a Dask
/// worker's points are the same bits) and computes the margins.
pub fn refine_all(
    work: &Work,
    mut points: Vec<LoopPoint>,
    opts: &Options,
) -> Result<(Vec<LoopPoint>, Margins)> {
    sort(&mut points);
    // What crosses zero at a crossing, and whether it is a wrapped phase.
    let kinds: [(Measure, bool); 2] = [(gain_db, false), (phase_from_180, true)];
    let mut refined = Vec::new();
    for (f, wrapped) in kinds {
        let found: Vec<Vec<LoopPoint>> = brackets(&points, f, wrapped)
            .par_iter()
            .map(|(lo, hi)| {
                let at = |w: f64| {
                    points
                        .iter()
                        .find(|p| p.omega == w)
                        .cloned()
                        .expect("a grid point")
                };
                refine(work, opts, at(*lo), at(*hi), f)
            })
            .collect::<Result<_>>()?;
        refined.extend(found.into_iter().flatten());
    }
    points.extend(refined);
    sort(&mut points);
    let margins = margins(&points);
    Ok((points, margins))
}

fn sort(points: &mut Vec<LoopPoint>) {
    points.sort_by(|a, b| a.omega.total_cmp(&b.omega));
    points.dedup_by(|a, b| a.omega == b.omega);
}

/// The margins of measured, sorted points.
pub fn margins(points: &[LoopPoint]) -> Margins {
    let mut m = Margins::default();
    for w in points.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if gain_db(a.l).signum() != gain_db(b.l).signum() {
            let (omega, pm) = crossing(a, b, gain_db, |p| phase_from_180(p.l));
            m.gain_crossovers.push(Crossing { omega, margin: pm });
        }
        let (pa, pb) = (phase_from_180(a.l), phase_from_180(b.l));
        if pa.signum() != pb.signum() && pa.abs() < 90.0 && pb.abs() < 90.0 {
            let (omega, g) = crossing(a, b, phase_from_180, |p| gain_db(p.l));
            m.phase_crossovers.push(Crossing { omega, margin: -g });
        }
    }
    // The margin that limits: the crossing closest to -1 (the smallest |margin|, its sign
    // kept, as MATLAB's `margin` reports it).
    let closest = |c: &[Crossing]| {
        c.iter()
            .min_by(|x, y| x.margin.abs().total_cmp(&y.margin.abs()))
            .cloned()
    };
    if let Some(c) = closest(&m.gain_crossovers) {
        m.phase_margin_deg = Some(c.margin);
        m.crossover_rad_s = Some(c.omega);
    }
    if let Some(c) = closest(&m.phase_crossovers) {
        m.gain_margin_db = Some(c.margin);
        m.gain_margin_rad_s = Some(c.omega);
    }
    // A delay only lags: at each gain crossover it takes (180 deg + angle L) mod 360 deg of lag
    // to reach -1; the delay margin is the least such delay over the crossovers.
    m.delay_margin_s = m
        .gain_crossovers
        .iter()
        .map(|c| c.margin.rem_euclid(360.0).to_radians() / c.omega)
        .min_by(f64::total_cmp);
    let peak = points
        .iter()
        .map(|p| (1.0 / (1.0 + p.l).norm(), p.omega))
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    m.sensitivity_peak = peak.0;
    m.sensitivity_peak_rad_s = peak.1;
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// L(jω) = K/(jω (jω + 1)(jω + 2)): the textbook loop, GM = 20 log10(6/K) at ω = √2,
    /// and for K = 1: ω_c = 0.4457 rad/s, PM = 53.4°.
    fn point(w: f64, k: f64) -> LoopPoint {
        let s = Complex64::new(0.0, w);
        LoopPoint {
            omega: w,
            l: k / (s * (s + 1.0) * (s + 2.0)),
            distortion: 0.0,
            gain_change_db: None,
            phase_change_deg: None,
        }
    }

    #[test]
    fn margins_of_a_known_loop_on_a_fine_grid() {
        let points: Vec<LoopPoint> = super::super::log_space(0.01, 10.0, 4000)
            .into_iter()
            .map(|w| point(w, 1.0))
            .collect();
        let m = margins(&points);
        assert!(
            (m.gain_margin_db.unwrap() - 20.0 * 6f64.log10()).abs() < 1e-3,
            "{m:?}"
        );
        assert!(
            (m.gain_margin_rad_s.unwrap() - 2f64.sqrt()).abs() < 1e-3,
            "{m:?}"
        );
        assert!((m.crossover_rad_s.unwrap() - 0.4457).abs() < 1e-3, "{m:?}");
        assert!((m.phase_margin_deg.unwrap() - 53.41).abs() < 0.02, "{m:?}");
        let dm = m.phase_margin_deg.unwrap().to_radians() / m.crossover_rad_s.unwrap();
        assert_eq!(m.delay_margin_s, Some(dm));
        assert!(m.sensitivity_peak > 1.0);
    }

    /// Three gain crossovers, one of them with L above the real axis (the RRS roll loop's
    /// shape): the phase margin is the crossing nearest -1, the delay margin the least lag to
    /// -1 over all three, both positive for this stable loop.
    #[test]
    fn several_crossovers_give_the_nearest_margin_and_the_least_delay() {
        let p = |w: f64, gain: f64, phase_deg: f64| LoopPoint {
            omega: w,
            l: Complex64::from_polar(gain, phase_deg.to_radians()),
            distortion: 0.0,
            gain_change_db: None,
            phase_change_deg: None,
        };
        let points = [
            p(0.09, 1.1, -129.5),
            p(0.11, 0.9, -129.5),
            p(0.52, 0.9, 31.0),
            p(0.55, 1.1, 31.0),
            p(0.75, 1.1, -116.3),
            p(0.78, 0.9, -116.3),
        ];
        let m = margins(&points);
        assert_eq!(m.gain_crossovers.len(), 3);
        assert!((m.phase_margin_deg.unwrap() - 50.5).abs() < 1e-9, "{m:?}");
        assert!((m.crossover_rad_s.unwrap() - 0.1).abs() < 0.002, "{m:?}");
        let roll = m.gain_crossovers[2];
        let dm = 63.7f64.to_radians() / roll.omega;
        assert!((m.delay_margin_s.unwrap() - dm).abs() < 1e-9, "{m:?}");
        let upper = m.gain_crossovers[1];
        assert!((upper.margin + 149.0).abs() < 1e-9 && upper.omega > 0.52);
    }
}
