//! A KPI against a direction on polar axes: rings, spokes, and each group's mean and band.

use super::figure::{
    anchored, label_or, nice_step, series_figure, spread, text_width, tick_label, ticks, words,
    AXIS, BAND_ALPHA, FONT,
};
use super::stats::{aggregate_by, widen, SeriesStats, Stats};
use super::{AngleUnit, Frame, Orientation, PlotOptions, PlotSummary};
use crate::campaign::table::Table;
use crate::error::Result;
use crate::plot::{color, drawing_error, Area};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Rings, spokes and grid lines.
const GRID: RGBColor = RGBColor(205, 205, 205);

/// Draws the mean of KPI `r` against the direction `angle` on polar axes: concentric rings
/// labelled with their radius, spokes every 30° labelled with their angle, one series per
/// value of `group` (mean points joined by a line interpolated linearly in angle and radius),
/// and the 5–95 % band shaded where a direction has two or more rows.
///
/// - Directions are taken modulo 360° (2π), so 0° and 360° pool; values equal to within
///   1e-9° are one direction.
/// - A series is closed when its directions go round the whole circle: no gap between
///   neighbouring directions (the one across 0° included) wider than 1.5 times their median
///   gap. Otherwise it is open, running from the end of its widest gap round to its start.
/// - The centre is radius 0, or the lowest value rounded down to a ring when a value is
///   negative; the radius labels run along the middle of the widest gap between directions.
pub fn polar(
    table: &Table,
    angle: &str,
    r: &str,
    group: Option<&str>,
    opts: &PlotOptions,
) -> Result<PlotSummary> {
    let unit = opts.angle_unit;
    let cols = [("angle", angle), ("radius", r)];
    let agg = aggregate_by(table, cols, group, |a| direction(a, unit))?;
    let (a_label, r_label) = (label_or(&opts.x_label, angle), label_or(&opts.y_label, r));
    let notes = [
        format!("radius: {r_label}"),
        format!("angle: {a_label}"),
        match opts.orientation {
            Orientation::Compass => "0 at the top, clockwise".to_string(),
            Orientation::Mathematical => "0 to the right, counter-clockwise".to_string(),
        },
    ];
    let title = format!("{r_label} over {a_label}");
    series_figure(&agg, opts, (title, r_label), group, &notes, |plot| {
        draw_polar(plot, &agg.series, opts)
    })
}

/// A direction in degrees in [0, 360), rounded to 1e-9°.
fn direction(a: f64, unit: AngleUnit) -> f64 {
    let deg = match unit {
        AngleUnit::Degrees => a,
        AngleUnit::Radians => a.to_degrees(),
    };
    let d = (deg.rem_euclid(360.0) * 1e9).round() / 1e9;
    if d >= 360.0 {
        0.0
    } else {
        d + 0.0 // no -0.0
    }
}

/// The gaps between neighbouring directions (ascending in [0, 360)): gap `k` runs from
/// direction `k` to the next, the last one across 0°.
fn gaps(angles: &[f64]) -> Vec<f64> {
    let m = angles.len();
    (0..m)
        .map(|k| {
            let next = if k + 1 < m {
                angles[k + 1]
            } else {
                angles[0] + 360.0
            };
            next - angles[k]
        })
        .collect()
}

fn widest_gap(angles: &[f64]) -> usize {
    let g = gaps(angles);
    (0..g.len()).fold(0, |best, k| if g[k] > g[best] { k } else { best })
}

fn goes_round(angles: &[f64]) -> bool {
    if angles.len() < 3 {
        return false;
    }
    let mut g = gaps(angles);
    g.sort_by(f64::total_cmp);
    let median = g[g.len() / 2];
    g[g.len() - 1] <= 1.5 * median + 1e-9
}

/// Polar axes in the coordinates of their drawing area.
struct PolarAxes {
    centre: (f64, f64),
    radius: f64,
    r: (f64, f64),
    orientation: Orientation,
}

impl PolarAxes {
    /// The pixel `rho` pixels from the centre in direction `deg`.
    fn at(&self, deg: f64, rho: f64) -> (i32, i32) {
        let (s, c) = deg.to_radians().sin_cos();
        let (dx, dy) = match self.orientation {
            Orientation::Compass => (rho * s, -rho * c),
            Orientation::Mathematical => (rho * c, -rho * s),
        };
        (
            (self.centre.0 + dx).round() as i32,
            (self.centre.1 + dy).round() as i32,
        )
    }
    /// The pixel of the data point (direction `deg`, value `r`), clamped to the axes.
    fn point(&self, deg: f64, r: f64) -> (i32, i32) {
        let f = ((r - self.r.0) / (self.r.1 - self.r.0)).clamp(0.0, 1.0);
        self.at(deg, f * self.radius)
    }
}

fn draw_polar(area: &Area, series: &[SeriesStats], opts: &PlotOptions) -> Result<Frame> {
    let values = series
        .iter()
        .flat_map(|s| s.points.iter())
        .flat_map(|p| [p.1.p05, p.1.mean, p.1.p95]);
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let (lo, hi) = widen(if lo >= 0.0 { 0.0 } else { lo }, hi);
    let step = nice_step(hi - lo, 5.0);
    let r = ((lo / step).floor() * step, (hi / step).ceil() * step);
    let labels = angle_labels(opts.angle_unit);
    let label_w = labels
        .iter()
        .map(|l| text_width(area, l, 14))
        .max()
        .unwrap_or(0) as f64;
    let (w, h) = area.dim_in_pixel();
    let radius = ((w as f64 - 2.0 * label_w - 40.0).min(h as f64 - 70.0) / 2.0).max(20.0);
    let axes = PolarAxes {
        centre: (w as f64 / 2.0, h as f64 / 2.0),
        radius,
        r,
        orientation: opts.orientation,
    };
    let mut all: Vec<f64> = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .collect();
    all.sort_by(f64::total_cmp);
    all.dedup();
    let k = widest_gap(&all);
    let middle = all[k] + gaps(&all)[k] / 2.0;
    let label_dir = ((middle - 15.0) / 30.0).round() * 30.0 + 15.0;
    draw_polar_grid(area, &axes, &labels)?;
    draw_ring_labels(area, &axes, step, label_dir)?;
    for (i, s) in series.iter().enumerate() {
        draw_polar_series(area, &axes, s, color(i))?;
    }
    let (bx, by) = area.get_base_pixel();
    Ok(Frame::Polar {
        centre: (
            bx + axes.centre.0.round() as i32,
            by + axes.centre.1.round() as i32,
        ),
        radius_px: radius,
        r,
    })
}

/// The labels of the spokes at 0°, 30°, … 330°.
fn angle_labels(unit: AngleUnit) -> Vec<String> {
    const PI: [&str; 12] = [
        "0", "π/6", "π/3", "π/2", "2π/3", "5π/6", "π", "7π/6", "4π/3", "3π/2", "5π/3", "11π/6",
    ];
    (0..12)
        .map(|k| match unit {
            AngleUnit::Degrees => format!("{}°", 30 * k),
            AngleUnit::Radians => PI[k].to_string(),
        })
        .collect()
}

fn draw_polar_grid(area: &Area, axes: &PolarAxes, labels: &[String]) -> Result<()> {
    for (k, label) in labels.iter().enumerate() {
        let deg = 30.0 * k as f64;
        let spoke = PathElement::new(
            vec![axes.at(deg, 0.0), axes.at(deg, axes.radius)],
            GRID.stroke_width(1),
        );
        area.draw(&spoke).map_err(drawing_error)?;
        let (x, y) = axes.at(deg, axes.radius + 8.0);
        let (dx, dy) = (x as f64 - axes.centre.0, y as f64 - axes.centre.1);
        let side = |d: f64| {
            if d > 0.3 * axes.radius {
                1
            } else if d < -0.3 * axes.radius {
                -1
            } else {
                0
            }
        };
        let h = [HPos::Right, HPos::Center, HPos::Left][(side(dx) + 1) as usize];
        let v = [VPos::Bottom, VPos::Center, VPos::Top][(side(dy) + 1) as usize];
        area.draw(&words(label.as_str(), (x, y), anchored(14, h, v)))
            .map_err(drawing_error)?;
    }
    let step = nice_step(axes.r.1 - axes.r.0, 5.0);
    for v in ticks(axes.r.0, axes.r.1, step).into_iter().skip(1) {
        let rho = (v - axes.r.0) / (axes.r.1 - axes.r.0) * axes.radius;
        let outer = v >= axes.r.1 - 1e-6 * step;
        let style = if outer {
            AXIS.stroke_width(1)
        } else {
            GRID.stroke_width(1)
        };
        let centre = axes.at(0.0, 0.0);
        area.draw(&Circle::new(centre, rho.round() as u32, style))
            .map_err(drawing_error)?;
    }
    Ok(())
}

fn draw_ring_labels(area: &Area, axes: &PolarAxes, step: f64, deg: f64) -> Result<()> {
    for v in ticks(axes.r.0, axes.r.1, step) {
        let rho = (v - axes.r.0) / (axes.r.1 - axes.r.0) * axes.radius;
        if rho == 0.0 && v == 0.0 {
            continue;
        }
        let text = tick_label(v, step);
        let (x, y) = axes.at(deg, rho);
        let half = text_width(area, &text, 13) as i32 / 2 + 3;
        let bg = Rectangle::new(
            [(x - half, y - 9), (x + half, y + 8)],
            WHITE.mix(0.85).filled(),
        );
        area.draw(&bg).map_err(drawing_error)?;
        let style = (FONT, 13)
            .into_font()
            .color(&RGBColor(70, 70, 70))
            .pos(Pos::new(HPos::Center, VPos::Center));
        area.draw(&words(text, (x, y), style))
            .map_err(drawing_error)?;
    }
    Ok(())
}

/// The series' points in drawing order (closed: back to the first; open: from the end of the
/// widest gap), each as (direction, stats).
fn polar_order(s: &SeriesStats) -> Vec<(f64, Stats)> {
    let angles: Vec<f64> = s.points.iter().map(|p| p.0).collect();
    let m = angles.len();
    if goes_round(&angles) {
        let mut v = s.points.clone();
        v.push(s.points[0]);
        return v;
    }
    let start = (widest_gap(&angles) + 1) % m;
    (0..m).map(|k| s.points[(start + k) % m]).collect()
}

/// The path through `values` at the directions of `order`, linear in angle and radius between
/// neighbours (at most 2° per piece).
fn polar_path(
    axes: &PolarAxes,
    order: &[(f64, Stats)],
    value: impl Fn(&Stats) -> f64,
) -> Vec<(i32, i32)> {
    let mut path = vec![axes.point(order[0].0, value(&order[0].1))];
    for pair in order.windows(2) {
        let ((a0, s0), (a1, s1)) = (pair[0], pair[1]);
        let d = (a1 - a0).rem_euclid(360.0);
        let pieces = (d / 2.0).ceil().max(1.0) as usize;
        for p in 1..=pieces {
            let f = p as f64 / pieces as f64;
            let (v0, v1) = (value(&s0), value(&s1));
            path.push(axes.point(a0 + f * d, v0 + f * (v1 - v0)));
        }
    }
    path
}

fn draw_polar_series(
    area: &Area,
    axes: &PolarAxes,
    s: &SeriesStats,
    color: RGBColor,
) -> Result<()> {
    let order = polar_order(s);
    if spread(s) {
        let mut band = polar_path(axes, &order, |st| st.p95);
        band.extend(polar_path(axes, &order, |st| st.p05).into_iter().rev());
        area.draw(&Polygon::new(band, color.mix(BAND_ALPHA).filled()))
            .map_err(drawing_error)?;
    }
    let mean = polar_path(axes, &order, |st| st.mean);
    area.draw(&PathElement::new(mean, color.stroke_width(2)))
        .map_err(drawing_error)?;
    for (deg, st) in &s.points {
        area.draw(&Circle::new(axes.point(*deg, st.mean), 4, color.filled()))
            .map_err(drawing_error)?;
    }
    Ok(())
}
