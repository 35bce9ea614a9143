//! The distribution of a KPI over the runs: a histogram (one per group, overlaid on shared
//! bins) with its mean and 5 % / 95 % percentiles tagged above the bars.

use super::figure::{
    compact, figure, font, label_or, label_step_of, padded_range, render, runs_line, text_width,
    tick_label, ticks, typeset, with_legend, words, Entry, Mark, AXIS, FONT,
};
use super::stats::{distribution, BinRule, Bins, Distribution, MAX_BINS};
use super::{Frame, PlotOptions, PlotSummary};
use crate::campaign::table::Table;
use crate::error::Result;
use crate::plot::{color, drawing_error, Area};
use plotters::coord::types::{RangedCoordf64, RangedCoordu32};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Opacity of a group's bars where groups overlay.
const OVERLAY_ALPHA: f64 = 0.45;
/// The mean and percentile lines of a histogram without groups.
const STAT_INK: RGBColor = RGBColor(20, 20, 20);
/// The height of a row of line tags above the bars, in pixels.
const TAG_ROW: i32 = 19;

/// Draws the distribution of KPI `x` over the rows (e.g. the Monte-Carlo runs of a robustness
/// study): bars of the runs in each of the [`Bins`] (Freedman–Diaconis, or Sturges when the
/// interquartile range is 0), a solid line at the mean and dashed lines at the 5 % and 95 %
/// percentiles (see [`Stats`](super::Stats)), tagged above the bars, with their values in the
/// legend.
///
/// With `group`, each value of the group column gets its own semi-transparent histogram
/// (outlined in its colour) on the bins chosen for all rows, and its own mean and percentile
/// lines, so that the arms or variants of a study compare bin by bin.
pub fn histogram(
    table: &Table,
    x: &str,
    group: Option<&str>,
    opts: &PlotOptions,
) -> Result<PlotSummary> {
    let d = distribution(table, x, group)?;
    let x_label = label_or(&opts.x_label, x);
    let group_label = label_or(&opts.group_label, group.unwrap_or(""));
    let title = opts
        .title
        .clone()
        .unwrap_or_else(|| format!("Distribution of {x_label}"));
    let caption = [
        bins_caption(&d.bins, d.rows_used, d.groups.len()),
        runs_line(d.rows_used, d.rows_skipped),
    ];
    let (legend, notes) = histogram_legend(&d, group_label);
    render(opts, |root| {
        let body = figure(root, &title, &caption)?;
        let plot = with_legend(&body, &legend, &notes)?;
        Ok(PlotSummary {
            rows_used: d.rows_used,
            rows_skipped: d.rows_skipped,
            series: d.groups.len(),
            frame: draw_histogram(&plot, &d, x_label)?,
        })
    })
}

/// The caption's line on the bins: the rule, its numbers, and the percentiles' definition.
fn bins_caption(b: &Bins, n: usize, groups: usize) -> String {
    let (k, w) = (b.len(), compact(b.width()));
    let mut line = match b.rule {
        BinRule::FreedmanDiaconis => format!(
            "Bins: Freedman–Diaconis rule, width 2 IQR n^(-1/3) with n = {n}, rounded to {k} bins of {w}"
        ),
        BinRule::Sturges => format!(
            "Bins: Sturges' rule (the interquartile range is 0), ceil(log2 {n}) + 1 = {k} bins of {w}"
        ),
        BinRule::SingleValue => format!(
            "All runs have the value {}: one bin centred on it",
            compact((b.edges[0] + b.edges[1]) / 2.0)
        ),
    };
    if b.capped {
        line.push_str(&format!(" (capped at {MAX_BINS} bins)"));
    }
    if groups > 1 {
        line.push_str("; the groups share the bins");
    }
    line.push_str("; percentiles: linear interpolation (numpy's default)");
    line
}

/// The colour of group `i`'s bars and lines, and the opacity of its bars.
fn bar_style(i: usize, groups: usize) -> (RGBColor, RGBColor, f64) {
    match groups {
        1 => (color(0), STAT_INK, 1.0),
        _ => (color(i), color(i), OVERLAY_ALPHA),
    }
}

/// The legend (bars, mean, percentiles) and its notes. Without groups the entries carry the
/// values; with groups the notes give each group's mean and percentiles.
fn histogram_legend(d: &Distribution, group_label: &str) -> (Vec<Entry>, Vec<String>) {
    let many = d.groups.len();
    let mut entries: Vec<Entry> = d
        .groups
        .iter()
        .enumerate()
        .map(|(i, g)| {
            let (color, _, alpha) = bar_style(i, many);
            Entry {
                label: match &g.group {
                    Some(v) => format!("{group_label} = {v} ({} runs)", g.stats.n),
                    None => format!("runs per bin ({} runs)", g.stats.n),
                },
                color,
                mark: Mark::Bar(alpha),
            }
        })
        .collect();
    let (mean, band, ink) = match &d.groups[..] {
        [one] => (
            format!("mean {}", compact(one.stats.mean)),
            format!(
                "5 % {} and 95 % {}",
                compact(one.stats.p05),
                compact(one.stats.p95)
            ),
            STAT_INK,
        ),
        _ => (
            "mean (group colour)".to_string(),
            "5 % and 95 % (group colour)".to_string(),
            RGBColor(110, 110, 110),
        ),
    };
    for (label, mark) in [(mean, Mark::Line), (band, Mark::Dashed)] {
        entries.push(Entry {
            label,
            color: ink,
            mark,
        });
    }
    let mut notes = Vec::new();
    for g in d.groups.iter().filter(|_| many > 1) {
        let (s, v) = (g.stats, g.group.as_deref().unwrap_or(""));
        notes.push(format!("{group_label} = {v}: mean {}", compact(s.mean)));
        notes.push(format!("5 % {}, 95 % {}", compact(s.p05), compact(s.p95)));
    }
    (entries, notes)
}

/// A line at a statistic of a group, and its tag above the bars.
struct Tag {
    value: f64,
    text: String,
    color: RGBColor,
    dashed: bool,
    group: usize,
}

fn tags(d: &Distribution) -> Vec<Tag> {
    let many = d.groups.len();
    let mut out = Vec::new();
    for (i, g) in d.groups.iter().enumerate() {
        let (_, color, _) = bar_style(i, many);
        for (value, text, dashed) in [
            (g.stats.p05, "5 %", true),
            (g.stats.mean, "mean", false),
            (g.stats.p95, "95 %", true),
        ] {
            out.push(Tag {
                value,
                text: text.to_string(),
                color,
                dashed,
                group: i,
            });
        }
    }
    out
}

/// The tags with their pixel columns `xs`, those of a group within 2 pixels of each other
/// merged into one ("5 %, mean, 95 %" when all runs are equal), solid if one of them is.
fn merge_tags(tags: Vec<Tag>, xs: &[i32]) -> (Vec<Tag>, Vec<i32>) {
    let (mut kept, mut kept_xs): (Vec<Tag>, Vec<i32>) = (Vec::new(), Vec::new());
    for (t, x) in tags.into_iter().zip(xs) {
        let same = kept
            .iter()
            .zip(&kept_xs)
            .position(|(k, kx)| k.group == t.group && (kx - x).abs() <= 2);
        match same {
            Some(k) => {
                kept[k].text = format!("{}, {}", kept[k].text, t.text);
                kept[k].dashed &= t.dashed;
            }
            None => {
                kept.push(t);
                kept_xs.push(*x);
            }
        }
    }
    (kept, kept_xs)
}

/// Rows for tags centred at `xs` (pixels) and `widths` wide: each tag goes to the first row
/// (from the top) where it clears the tags already there, taking them from left to right.
/// Returns each tag's row and the number of rows.
fn tag_rows(xs: &[i32], widths: &[i32]) -> (Vec<usize>, usize) {
    let mut order: Vec<usize> = (0..xs.len()).collect();
    order.sort_by_key(|&k| xs[k]);
    let mut ends: Vec<i32> = Vec::new();
    let mut rows = vec![0; xs.len()];
    for k in order {
        let left = xs[k] - widths[k] / 2;
        let row = ends
            .iter()
            .position(|e| left > *e + 4)
            .unwrap_or(ends.len());
        if row == ends.len() {
            ends.push(0);
        }
        ends[row] = left + widths[k];
        rows[k] = row;
    }
    (rows, ends.len())
}

type HistogramChart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordu32>>;

/// The chart of a histogram: `x` over the data range, counts 0 to `y_top` (integers, so that
/// the axis has no fractional runs).
fn histogram_chart<'a, 'b>(
    area: &'a Area<'b>,
    x: (f64, f64),
    y_top: u32,
) -> Result<HistogramChart<'a, 'b>> {
    ChartBuilder::on(area)
        .margin_top(16)
        .margin_left(12)
        .margin_right(16)
        .x_label_area_size(56)
        .y_label_area_size(78)
        .build_cartesian_2d(x.0..x.1, 0..y_top)
        .map_err(drawing_error)
}

fn draw_histogram(area: &Area, d: &Distribution, x_label: &str) -> Result<Frame> {
    let b = &d.bins;
    let pad = if b.rule == BinRule::SingleValue {
        0.5
    } else {
        0.04
    };
    let xr = padded_range([b.edges[0], b.edges[b.len()]].into_iter(), pad);
    let tags = tags(d);
    // The chart's pixels along x do not depend on the count axis: lay the tags out on a probe
    // chart, then leave room above the tallest bar for their rows.
    let probe = histogram_chart(area, xr, 1)?;
    let (px, py) = probe.plotting_area().get_pixel_range();
    let xs: Vec<i32> = tags
        .iter()
        .map(|t| probe.backend_coord(&(t.value, 0)).0)
        .collect();
    let (tags, xs) = merge_tags(tags, &xs);
    let widths: Vec<i32> = tags
        .iter()
        .map(|t| text_width(area, &t.text, 13) as i32 + 8)
        .collect();
    let xs: Vec<i32> = xs
        .iter()
        .zip(&widths)
        .map(|(x, w)| (*x).clamp(px.start + w / 2, (px.end - w / 2).max(px.start + w / 2)))
        .collect();
    let (rows, n_rows) = tag_rows(&xs, &widths);
    let height = (py.end - py.start) as f64;
    let free = (height - (n_rows as i32 * TAG_ROW + 24) as f64).max(0.3 * height);
    let tallest = d.groups.iter().flat_map(|g| g.counts.iter()).max().copied();
    let tallest = tallest.unwrap_or(1).max(1) as u32;
    let y_top = ((tallest as f64 * height / free).ceil() as u32).max(tallest + 1);
    let mut chart = histogram_chart(area, xr, y_top)?;
    let n_labels = x_labels_that_fit(area, xr, px.end - px.start);
    let x_step = label_step_of(xr, n_labels);
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_desc(typeset(x_label))
        .y_desc("runs")
        .x_labels(n_labels)
        .y_labels(8)
        .x_label_formatter(&|v| tick_label(*v, x_step))
        .label_style(font(14))
        .axis_desc_style(font(17))
        .bold_line_style(RGBColor(225, 225, 225))
        // Counts are whole: no lines between the labelled ones (and `max_light_lines(0)` hangs
        // plotters 0.3.7).
        .light_line_style(TRANSPARENT)
        .axis_style(AXIS)
        .draw()
        .map_err(drawing_error)?;
    draw_bars(&mut chart, d)?;
    let (bx, by) = area.get_base_pixel();
    let base = chart.backend_coord(&(xr.0, 0)).1 - by;
    let placed: Vec<(i32, i32)> = xs
        .iter()
        .zip(&rows)
        .map(|(x, r)| (*x - bx, py.start - by + 4 + *r as i32 * TAG_ROW))
        .collect();
    draw_tags(area, &chart, &tags, &placed, base)?;
    let top_left = chart.backend_coord(&(xr.0, y_top));
    let bottom_right = chart.backend_coord(&(xr.1, 0));
    Ok(Frame::cartesian(
        top_left,
        bottom_right,
        xr,
        (0.0, y_top as f64),
    ))
}

/// The most labels (2 to 8) along `range` whose widest label, 12 pixels apart, fits `width`.
fn x_labels_that_fit(area: &Area, range: (f64, f64), width: i32) -> usize {
    (2..=8)
        .rev()
        .find(|&n| {
            let step = label_step_of(range, n);
            let widest = ticks(range.0, range.1, step)
                .iter()
                .map(|v| text_width(area, &tick_label(*v, step), 14) as i32)
                .max()
                .unwrap_or(0);
            let count = ((range.1 - range.0) / step).floor() as i32 + 1;
            count * (widest + 12) <= width
        })
        .unwrap_or(2)
}

/// Each group's bars: without groups solid, with white lines between bins; with groups
/// semi-transparent, each outlined by its steps.
fn draw_bars(chart: &mut HistogramChart, d: &Distribution) -> Result<()> {
    let e = &d.bins.edges;
    let many = d.groups.len();
    for (i, g) in d.groups.iter().enumerate() {
        let (color, _, alpha) = bar_style(i, many);
        let bars = g.counts.iter().enumerate().filter(|(_, c)| **c > 0);
        chart
            .draw_series(bars.map(|(k, c)| {
                Rectangle::new(
                    [(e[k], 0), (e[k + 1], *c as u32)],
                    color.mix(alpha).filled(),
                )
            }))
            .map_err(drawing_error)?;
        if many == 1 {
            let between = (1..g.counts.len()).map(|k| {
                let h = g.counts[k - 1].max(g.counts[k]) as u32;
                PathElement::new(vec![(e[k], 0), (e[k], h)], WHITE.stroke_width(1))
            });
            chart.draw_series(between).map_err(drawing_error)?;
        } else {
            chart
                .draw_series(
                    outlines(e, &g.counts)
                        .into_iter()
                        .map(|steps| PathElement::new(steps, color.stroke_width(2))),
                )
                .map_err(drawing_error)?;
        }
    }
    Ok(())
}

/// The outlines of the runs of non-empty bins, each up from the base, along the bins' tops and
/// back down (not along the base under another group's bars).
fn outlines(edges: &[f64], counts: &[usize]) -> Vec<Vec<(f64, u32)>> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < counts.len() {
        if counts[k] == 0 {
            k += 1;
            continue;
        }
        let mut path = vec![(edges[k], 0)];
        while k < counts.len() && counts[k] > 0 {
            let c = counts[k] as u32;
            path.extend([(edges[k], c), (edges[k + 1], c)]);
            k += 1;
        }
        path.push((edges[k], 0));
        out.push(path);
    }
    out
}

/// The lines from the bars' base (`base`, area pixels) up to their tags, dashed ones first,
/// then the tags at `placed` (the top middle of each, area pixels) on white.
fn draw_tags(
    area: &Area,
    chart: &HistogramChart,
    tags: &[Tag],
    placed: &[(i32, i32)],
    base: i32,
) -> Result<()> {
    let (bx, _) = area.get_base_pixel();
    for dashed in [true, false] {
        for (t, (_, y)) in tags.iter().zip(placed).filter(|(t, _)| t.dashed == dashed) {
            let x = chart.backend_coord(&(t.value, 0)).0 - bx;
            let line = vec![(x, base), (x, y + TAG_ROW - 2)];
            let style = t.color.stroke_width(2);
            if dashed {
                area.draw(&DashedPathElement::new(line, 7, 5, style))
            } else {
                area.draw(&PathElement::new(line, style))
            }
            .map_err(drawing_error)?;
        }
    }
    for (t, (x, y)) in tags.iter().zip(placed) {
        let half = text_width(area, &t.text, 13) as i32 / 2 + 4;
        let bg = Rectangle::new(
            [(x - half, y + 1), (x + half, y + TAG_ROW - 2)],
            WHITE.mix(0.9).filled(),
        );
        area.draw(&bg).map_err(drawing_error)?;
        let style = (FONT, 13)
            .into_font()
            .color(&t.color)
            .pos(Pos::new(HPos::Center, VPos::Center));
        area.draw(&words(&t.text, (*x, y + TAG_ROW / 2), style))
            .map_err(drawing_error)?;
    }
    Ok(())
}
