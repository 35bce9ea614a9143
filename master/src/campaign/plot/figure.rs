//! What the four charts share: the canvas and its checks, the title, the caption and the legend
//! beside the plot, text, and the numbers on axes.

use super::stats::{plain, widen, Aggregate, SeriesStats};
use super::{Frame, PlotOptions, PlotSummary};
use crate::error::{Error, Result};
use crate::plot::{color, create_parent_dir, drawing_error, register_font, Area};
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

pub(super) const FONT: &str = "sans-serif";
pub(super) const TEXT: RGBColor = RGBColor(30, 30, 30);
/// The colour of axes, the polar frame and tick marks.
pub(super) const AXIS: RGBColor = RGBColor(40, 40, 40);
/// Opacity of a 5–95 % band over its series colour.
pub(super) const BAND_ALPHA: f64 = 0.2;

// ---------------------------------------------------------------------------------------------
// Numbers on axes

/// A round step (1, 2, 2.5 or 5 times a power of ten) giving about `target` steps over `span`.
pub(super) fn nice_step(span: f64, target: f64) -> f64 {
    let raw = (span / target).max(f64::MIN_POSITIVE);
    let mag = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw * (1.0 - 1e-9))
        .unwrap_or(10.0 * mag)
}

/// The multiples of `step` within `lo..=hi` (to a millionth of a step).
pub(super) fn ticks(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let first = (lo / step - 1e-6).ceil() as i64;
    let last = (hi / step + 1e-6).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A tick value printed with as many decimals as its step needs.
pub(super) fn tick_label(v: f64, step: f64) -> String {
    let decimals = (0..8)
        .find(|d| {
            let s = step * 10f64.powi(*d);
            (s - s.round()).abs() < 1e-6 * s.max(1.0)
        })
        .unwrap_or(8) as usize;
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

/// A value with 3 significant digits (cell annotations).
pub(super) fn short_value(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        return format!("{v:.2e}");
    }
    let digits = if a == 0.0 {
        0
    } else {
        a.log10().floor() as i32
    };
    let decimals = (2 - digits).clamp(0, 4) as usize;
    format!("{v:.decimals$}")
}

/// A value as [`plain`] writes it when that is no longer than [`short_value`] (4 rather than
/// 4.00, 19.8 rather than 19.80; 1.17 rather than 1.169607).
pub(super) fn compact(v: f64) -> String {
    let (p, s) = (plain(v), short_value(v));
    if p.len() <= s.len() {
        p
    } else {
        s
    }
}

/// The data range of `values`, padded by `pad` of its span on both sides.
pub(super) fn padded_range(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let (lo, hi) = widen(lo, hi);
    let d = (hi - lo) * pad;
    (lo - d, hi + d)
}

/// The step between the 8 (at most) labels that plotters puts on an axis over `range`.
pub(super) fn label_step(range: (f64, f64)) -> f64 {
    label_step_of(range, 8)
}

/// The step between the `n` (at most) labels that plotters puts on an axis over `range`.
pub(super) fn label_step_of(range: (f64, f64), n: usize) -> f64 {
    let points = RangedCoordf64::from(range.0..range.1).key_points(n);
    let step = points
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    if step.is_finite() && step > 0.0 {
        step
    } else {
        range.1 - range.0
    }
}

// ---------------------------------------------------------------------------------------------
// Figure: canvas, title, caption, legend

pub(super) fn font(size: u32) -> TextStyle<'static> {
    (FONT, size).into_font().color(&TEXT)
}

pub(super) fn anchored(size: u32, h: HPos, v: VPos) -> TextStyle<'static> {
    font(size).pos(Pos::new(h, v))
}

/// Text with a hair space (U+200A) after each space. plotters 0.3.7 draws each glyph of the
/// embedded font without its left side bearing (plotters-rs/plotters#576), which closes up word
/// gaps ("of runs" reads "ofruns"); the hair space restores them.
pub(super) fn typeset(text: &str) -> String {
    text.replace(' ', " \u{200A}")
}

/// A text element, typeset.
pub(super) fn words(
    text: impl AsRef<str>,
    pos: (i32, i32),
    style: TextStyle<'static>,
) -> Text<'static, (i32, i32), String> {
    Text::new(typeset(text.as_ref()), pos, style)
}

/// `text` broken at spaces into lines no wider than `width` pixels (a longer word stands alone).
fn wrap(area: &Area, text: &str, size: u32, width: u32) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ') {
        match lines.last_mut() {
            Some(line) if text_width(area, &format!("{line} {word}"), size) <= width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

pub(super) fn text_width(area: &Area, text: &str, size: u32) -> u32 {
    area.estimate_text_size(&typeset(text), &font(size))
        .map_or(text.chars().count() as u32 * size * 6 / 10, |(w, _)| w)
}

/// Checks the options and the output path, creating its folder; then calls `draw` on a white
/// canvas and writes the PNG.
pub(super) fn render(
    opts: &PlotOptions,
    draw: impl FnOnce(&Area) -> Result<PlotSummary>,
) -> Result<PlotSummary> {
    let path = opts.path.as_path();
    let (w, h) = opts.size;
    if !(400..=8000).contains(&w) || !(300..=8000).contains(&h) {
        return Err(Error::Other(format!(
            "plot {}: size {w}x{h} pixels is outside 400x300 ..= 8000x8000",
            path.display()
        )));
    }
    let png = path.extension().and_then(|e| e.to_str());
    if !png.is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        return Err(Error::Other(format!(
            "plot {}: the output must be a .png file",
            path.display()
        )));
    }
    let path = &crate::output_path::writable(path)?;
    create_parent_dir(path)?;
    std::fs::File::create(path)
        .map_err(|e| Error::io(format!("plot: cannot write {}", path.display()), e))?;
    register_font();
    let in_path = |e: Error| Error::Other(format!("plot {}: {e}", path.display()));
    let root = BitMapBackend::new(path, opts.size).into_drawing_area();
    root.fill(&WHITE).map_err(drawing_error).map_err(in_path)?;
    let summary = draw(&root).map_err(in_path)?;
    root.present().map_err(drawing_error).map_err(in_path)?;
    Ok(summary)
}

/// Draws the title and the caption lines and returns the area between them.
pub(super) fn figure<'a>(root: &Area<'a>, title: &str, caption: &[String]) -> Result<Area<'a>> {
    let body = root
        .titled(&typeset(title), font(22))
        .map_err(drawing_error)?;
    let (w, h) = body.dim_in_pixel();
    let caption: Vec<String> = caption
        .iter()
        .flat_map(|c| wrap(root, c, 14, w - 24))
        .collect();
    let foot_h = 10 + 18 * caption.len() as u32;
    let (body, foot) = body.split_vertically(h.saturating_sub(foot_h));
    for (i, line) in caption.iter().enumerate() {
        foot.draw(&words(line.as_str(), (12, 2 + 18 * i as i32), font(14)))
            .map_err(drawing_error)?;
    }
    Ok(body)
}

/// The caption's first line: runs used and skipped, runs per point, and the band's definition.
pub(super) fn caption(
    runs_per_point: (usize, usize),
    used: usize,
    skipped: usize,
    band: bool,
) -> Vec<String> {
    let mut first = match runs_per_point {
        (1, 1) => "One run per point".to_string(),
        (a, b) if a == b => format!("Mean of {a} runs per point"),
        (a, b) => format!("Mean of {a} to {b} runs per point"),
    };
    if band {
        first.push_str("; band: 5 to 95 % percentiles (linear interpolation, numpy's default)");
    }
    vec![first, runs_line(used, skipped)]
}

/// The caption's line of runs used and skipped.
pub(super) fn runs_line(used: usize, skipped: usize) -> String {
    match skipped {
        0 => format!("{used} runs"),
        s => format!("{used} runs; {s} skipped (a plotted value is not finite, as in failed runs)"),
    }
}

fn runs_per_point(series: &[SeriesStats]) -> (usize, usize) {
    let n = series.iter().flat_map(|s| s.points.iter().map(|p| p.1.n));
    (n.clone().min().unwrap_or(0), n.max().unwrap_or(0))
}

/// One legend line.
pub(super) struct Entry {
    pub(super) label: String,
    pub(super) color: RGBColor,
    pub(super) mark: Mark,
}

/// How a legend entry shows its colour.
#[derive(Clone, Copy)]
pub(super) enum Mark {
    /// A line with a marker: a series of means.
    Series,
    /// A swatch in the band's tint.
    Band,
    /// A bar filled with the colour at this opacity, outlined in the colour.
    Bar(f64),
    /// A plain line.
    Line,
    /// A dashed line.
    Dashed,
}

/// The legend's entries for `series` (labelled by `group_label = value`), and the band swatch.
fn entries(series: &[SeriesStats], group_label: &str, y_label: &str, band: bool) -> Vec<Entry> {
    let mut out: Vec<Entry> = series
        .iter()
        .enumerate()
        .map(|(i, s)| Entry {
            label: match &s.group {
                Some(g) => format!("{group_label} = {g}"),
                None => format!("mean {y_label}"),
            },
            color: color(i),
            mark: Mark::Series,
        })
        .collect();
    if band {
        let color = if series.len() == 1 {
            color(0)
        } else {
            RGBColor(120, 120, 120)
        };
        out.push(Entry {
            label: "5 to 95 % of runs".into(),
            color,
            mark: Mark::Band,
        });
    }
    out
}

/// The width of the legend panel at the right of the figure: the widest entry (the notes are
/// wrapped to it), at least 210 and at most 2/5 of the figure's width.
fn legend_width(area: &Area, entries: &[Entry]) -> u32 {
    let widest = entries
        .iter()
        .map(|e| text_width(area, &e.label, 15) + 44)
        .max()
        .unwrap_or(0);
    (widest + 36).max(210).min(area.dim_in_pixel().0 * 2 / 5)
}

/// Draws a boxed legend at the top of `area`, and `notes` under it (as many lines as fit).
fn draw_legend(area: &Area, entries: &[Entry], notes: &[String]) -> Result<()> {
    let (w, h) = area.dim_in_pixel();
    let (x0, y0, row) = (8, 24, 24);
    let box_h = 10 + row * entries.len() as i32;
    let x1 = w as i32 - 12;
    area.draw(&Rectangle::new(
        [(x0, y0), (x1, y0 + box_h)],
        AXIS.stroke_width(1),
    ))
    .map_err(drawing_error)?;
    for (k, e) in entries.iter().enumerate() {
        let y = y0 + 17 + row * k as i32;
        draw_mark(area, e, (x0 + 8, y))?;
        let label = words(
            e.label.as_str(),
            (x0 + 44, y),
            anchored(15, HPos::Left, VPos::Center),
        );
        area.draw(&label).map_err(drawing_error)?;
    }
    let notes: Vec<String> = notes
        .iter()
        .flat_map(|n| wrap(area, n, 14, w - 20))
        .collect();
    for (k, note) in notes.iter().enumerate() {
        let y = y0 + box_h + 22 + 20 * k as i32;
        if y + 10 > h as i32 {
            break;
        }
        area.draw(&words(
            note.as_str(),
            (x0, y),
            anchored(14, HPos::Left, VPos::Center),
        ))
        .map_err(drawing_error)?;
    }
    Ok(())
}

/// An entry's mark, 28 pixels wide from `(x, y)` (the middle of its left side).
fn draw_mark(area: &Area, e: &Entry, (x, y): (i32, i32)) -> Result<()> {
    let line = vec![(x, y), (x + 28, y)];
    match e.mark {
        Mark::Series => {
            area.draw(&PathElement::new(line, e.color.stroke_width(2)))
                .map_err(drawing_error)?;
            area.draw(&Circle::new((x + 14, y), 4, e.color.filled()))
                .map_err(drawing_error)
        }
        Mark::Band => {
            let style = e.color.mix(BAND_ALPHA * 1.5).filled();
            area.draw(&Rectangle::new([(x, y - 7), (x + 28, y + 7)], style))
                .map_err(drawing_error)
        }
        Mark::Bar(alpha) => {
            let corners = [(x + 4, y - 7), (x + 24, y + 7)];
            area.draw(&Rectangle::new(corners, e.color.mix(alpha).filled()))
                .map_err(drawing_error)?;
            area.draw(&Rectangle::new(corners, e.color.stroke_width(1)))
                .map_err(drawing_error)
        }
        Mark::Line => area
            .draw(&PathElement::new(line, e.color.stroke_width(2)))
            .map_err(drawing_error),
        Mark::Dashed => area
            .draw(&DashedPathElement::new(line, 6, 5, e.color.stroke_width(2)))
            .map_err(drawing_error),
    }
}

/// Splits off the legend panel at the right and draws it; returns the plotting part.
pub(super) fn with_legend<'a>(
    body: &Area<'a>,
    entries: &[Entry],
    notes: &[String],
) -> Result<Area<'a>> {
    let (w, _) = body.dim_in_pixel();
    let (plot, side) = body.split_horizontally(w - legend_width(body, entries));
    draw_legend(&side, entries, notes)?;
    Ok(plot)
}

pub(super) fn label_or<'a>(label: &'a Option<String>, column: &'a str) -> &'a str {
    label.as_deref().unwrap_or(column)
}

/// Whether a series has a design point with two or more runs (a band to draw).
pub(super) fn spread(s: &SeriesStats) -> bool {
    s.points.iter().any(|p| p.1.n > 1)
}

/// The figure of [`super::line_band()`] and [`super::polar()`]: title (`labels.0` unless the
/// options give one), caption, legend (series of KPI `labels.1` per `group`, the band, then
/// `notes`), and `draw` for the plot beside the legend.
pub(super) fn series_figure(
    agg: &Aggregate,
    opts: &PlotOptions,
    labels: (String, &str),
    group: Option<&str>,
    notes: &[String],
    draw: impl FnOnce(&Area) -> Result<Frame>,
) -> Result<PlotSummary> {
    let band = agg.series.iter().any(spread);
    let group_label = label_or(&opts.group_label, group.unwrap_or(""));
    let legend = entries(&agg.series, group_label, labels.1, band);
    let title = opts.title.clone().unwrap_or(labels.0);
    let per_point = runs_per_point(&agg.series);
    let caption = caption(per_point, agg.rows_used, agg.rows_skipped, band);
    render(opts, |root| {
        let body = figure(root, &title, &caption)?;
        let plot = with_legend(&body, &legend, notes)?;
        Ok(PlotSummary {
            rows_used: agg.rows_used,
            rows_skipped: agg.rows_skipped,
            series: agg.series.len(),
            frame: draw(&plot)?,
        })
    })
}
